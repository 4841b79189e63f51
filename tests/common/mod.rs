//! Helpers shared by the integration tests.
#![allow(dead_code)]

use std::path::PathBuf;
use waam_slicer::io::part_file::{read_part_file, Part};

/// Path of a file in `parts/`.
pub fn part_path(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("parts")
        .join(name)
}

/// Reads a sample part, panicking with the error message if it fails.
pub fn load_part(name: &str) -> Part {
    read_part_file(&part_path(name)).unwrap_or_else(|e| panic!("{e}"))
}

/// Every sample part file.
pub const SAMPLE_PARTS: [&str; 8] = [
    "hemisphere.toml",
    "nozzle.toml",
    "half-catenoid.toml",
    "quarter-torus.toml",
    "general-tube.toml",
    "torus-on-cylinder.toml",
    "elbow.toml",
    "helix.toml",
];
