//! The crate-level error: one variant per stage, each wrapping that stage's own
//! error enum (which names the file, field, layer or point at fault).

use crate::geometry::GeometryError;
use crate::io::cell_file::CellFileError;
use crate::io::part_file::PartFileError;
use crate::optimise::OptimiseError;
use crate::process::ProcessError;
use crate::program::ProgramError;
use crate::robot::RobotError;
use crate::toolaxis::ToolAxisError;

/// Any error of the library.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// Building or evaluating the tube geometry failed.
    #[error(transparent)]
    Geometry(#[from] GeometryError),
    /// A part file could not be read.
    #[error(transparent)]
    PartFile(#[from] PartFileError),
    /// The robot stage failed (invalid model or cell, unreachable or singular pose).
    #[error(transparent)]
    Robot(#[from] RobotError),
    /// A cell file could not be read.
    #[error(transparent)]
    CellFile(#[from] CellFileError),
    /// The tool-axis stage failed (invalid option or torch, degenerate point).
    #[error(transparent)]
    ToolAxis(#[from] ToolAxisError),
    /// The process stage failed (invalid parameter or option).
    #[error(transparent)]
    Process(#[from] ProcessError),
    /// The optimisation stage was given bad input.
    #[error(transparent)]
    Optimise(#[from] OptimiseError),
    /// Writing, reading back or checking a robot program failed.
    #[error(transparent)]
    Program(#[from] ProgramError),
}
