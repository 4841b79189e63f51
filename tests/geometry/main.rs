//! Integration tests of the geometry stage (SPEC §2) and of part files.

#[path = "../common/mod.rs"]
mod common;

mod frames;
mod part_files;
mod substrates;
mod surfaces;
