//! Integration tests of the path stage (SPEC §3) on the sample parts.

#[path = "../common/mod.rs"]
mod common;

mod cli;
mod corners;
mod discretisation;
mod smoothing;
mod spiral;
mod strategies;
