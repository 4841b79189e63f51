//! Command-line arguments of the `waam` example.

use clap::{Parser, Subcommand};
use std::path::PathBuf;

/// Plans wire-arc additive manufacturing of tubes: reads a part file, reports
/// its geometry (more stages to come: slice, plan, check).
#[derive(Debug, Parser)]
#[command(name = "waam", version, about)]
pub struct Args {
    /// What to do.
    #[command(subcommand)]
    pub command: Command,
    /// Print nothing but errors.
    #[arg(long, global = true)]
    pub quiet: bool,
}

/// Sub-commands.
#[derive(Debug, Subcommand)]
pub enum Command {
    /// List the sample parts (and cells) with one line each.
    Parts {
        /// Folder holding the part files.
        #[arg(long, default_value = "parts")]
        dir: PathBuf,
    },
    /// Read a part file and print its geometry: guide, profile, range, first layer.
    Geometry {
        /// The part file (TOML).
        part: PathBuf,
        /// Points on the first layer.
        #[arg(long, default_value_t = 360)]
        points: usize,
    },
}
