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

/// Strategy names on the command line.
#[derive(Debug, Clone, Copy, clap::ValueEnum)]
pub enum StrategyArg {
    /// Constant local interlayer distance.
    Constant,
    /// Iso-parametric.
    Iso,
    /// Perpendicular to the guide.
    Perpendicular,
    /// Planar Z slices.
    Planar,
    /// Continuous spiral.
    Spiral,
}

/// Sub-commands.
#[derive(Debug, Subcommand)]
pub enum Command {
    /// Slice a part: writes path.csv and summary.json in --out.
    Slice {
        /// The part file (TOML).
        part: PathBuf,
        /// Strategy (default: the part file's).
        #[arg(long, value_enum)]
        strategy: Option<StrategyArg>,
        /// Interlayer distance Delta in mm (default: the part file's).
        #[arg(long)]
        delta: Option<f64>,
        /// Points per layer.
        #[arg(long, conflicts_with = "chord")]
        points: Option<usize>,
        /// Max chord error in mm.
        #[arg(long)]
        chord: Option<f64>,
        /// Output folder (default out/<part name>).
        #[arg(long)]
        out: Option<PathBuf>,
    },
    /// Plan a part in a cell: slice, tool axes, R_Z optimisation, joints;
    /// writes joints.csv and summary.json in --out (exit 2 if infeasible).
    Plan(PlanArgs),
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

/// Arguments of `plan`.
#[derive(Debug, clap::Args)]
pub struct PlanArgs {
    /// The part file (TOML).
    pub part: PathBuf,
    /// The cell file (TOML, parts/cells/).
    #[arg(long)]
    pub cell: PathBuf,
    /// Interlayer distance Delta in mm (default: the part file's).
    #[arg(long)]
    pub delta: Option<f64>,
    /// Points per layer.
    #[arg(long, conflicts_with = "chord")]
    pub points: Option<usize>,
    /// Max chord error in mm.
    #[arg(long)]
    pub chord: Option<f64>,
    /// R_Z law: fixed:DEG, poly:N (max degree), spline, point.
    #[arg(long, default_value = "poly:4")]
    pub rz: String,
    /// Output folder (default out/<part name>).
    #[arg(long)]
    pub out: Option<PathBuf>,
}
