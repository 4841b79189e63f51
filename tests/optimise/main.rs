//! Integration tests of the optimisation stage (SPEC §7, thesis chapter 4).

#[path = "../common/mod.rs"]
mod common;

mod circle;
mod cli;
mod determinism;
mod hose;
mod objectives;
mod parts;
mod place;
mod place_cells;
mod place_table;
mod spiral;
mod subsample;
mod support;
mod torch_carried;
