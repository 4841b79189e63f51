//! Integration tests of the program stage (SPEC §8): golden files per
//! emitter, read-back and validation of our FANUC output, corrupted files,
//! cutting a build into groups within each controller's memory budget,
//! refusal of infeasible plans.

mod abb_controller;
mod api;
mod budget;
mod cell_collision;
mod cells;
mod circular;
mod contract;
mod corner_splits;
mod cycle;
mod fanuc_controller;
mod feed;
mod fixture;
mod formats;
mod golden;
mod kuka_controller;
mod parts;
mod rapid_grammar;
mod setup;
#[path = "../common/mod.rs"]
mod shared;
mod split;
mod strokes;
mod thinning;
mod tool_frames;
mod transit_wall;
mod validate;
