//! Integration tests of the tool-axis (SPEC §4) and process (SPEC §5) stages
//! on the sample parts.

#[path = "../common/mod.rs"]
mod common;

mod collision;
mod frames;
mod process;
mod rules;
