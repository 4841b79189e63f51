//! The crate-level error: one variant per stage, each wrapping that stage's own
//! error enum (which names the file, field, layer or point at fault).

use crate::fit::FitError;
use crate::geometry::GeometryError;
use crate::io::cell_file::CellFileError;
use crate::io::joints_csv::JointsCsvError;
use crate::io::part_file::PartFileError;
use crate::io::path_csv::PathCsvError;
use crate::optimise::OptimiseError;
use crate::path::PathError;
use crate::process::ProcessError;
use crate::program::ProgramError;
use crate::robot::RobotError;
use crate::toolaxis::ToolAxisError;

mod replan;
pub use replan::ReplanError;

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
    /// A mesh could not be fitted as a tube (unreadable, not a tube).
    #[error(transparent)]
    Fit(#[from] FitError),
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
    /// Slicing failed (bad option, no root, too many points).
    #[error(transparent)]
    Path(#[from] PathError),
    /// A path CSV could not be read.
    #[error(transparent)]
    PathCsv(#[from] PathCsvError),
    /// The 3-D report could not be built or written.
    #[error(transparent)]
    Report(#[from] crate::report::ReportError),
    /// A joints CSV could not be read.
    #[error(transparent)]
    JointsCsv(#[from] JointsCsvError),
    /// The closed loop refused a scan or cannot replan the path.
    #[error(transparent)]
    Replan(#[from] ReplanError),
    /// A stage failed on a part read from a file: the file, then the stage's
    /// error (which names the field, layer or point).
    #[error("{file}: {source}")]
    InPart {
        /// The part file.
        file: String,
        /// The stage's error.
        source: Box<Error>,
    },
    /// The run's estimated size is over the budget: refused before any work.
    #[error("{file}: about {points} points ({layers} layers x {points_per_layer} points, ~{megabytes:.0} MB of path) would be computed, over the budget of {budget}: check Delta and the points per layer, or raise the budget (CLI --max-points, API SliceOverrides::max_points)")]
    OverBudget {
        /// The part file.
        file: String,
        /// Layers estimated.
        layers: u64,
        /// Points per layer estimated.
        points_per_layer: u64,
        /// Points estimated.
        points: u64,
        /// Memory of the path estimated (MB).
        megabytes: f64,
        /// The budget (points).
        budget: u64,
    },
    /// A file could not be written.
    #[error("{path}: cannot write: {source}")]
    Io {
        /// The file.
        path: String,
        /// The system's error.
        #[source]
        source: std::sync::Arc<std::io::Error>,
    },
    /// The host program asked to stop (see [`Control`](crate::pipeline::Control)).
    #[error("cancelled during {stage}")]
    Cancelled {
        /// The stage running when the request was seen.
        stage: &'static str,
    },
}

/// What kind of failure an [`Error`] is, for a host that reacts by kind
/// (the CLI's exit code, Python's exception class) without reading messages.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum ErrorKind {
    /// The input is wrong (a part or cell file's field, an option, a
    /// program file that does not read back): the message names the file,
    /// field, layer or point. Fix the input.
    Input,
    /// A program was asked of a plan that has an infeasible layer, or that
    /// the program stage refused: an answer about the part in the cell, not
    /// a fault of the input.
    Infeasible,
    /// The host asked to stop ([`Control`](crate::pipeline::Control)).
    Cancelled,
    /// A file could not be read or written (missing, permissions, disk).
    Io,
}

impl Error {
    /// The kind of this error ([`ErrorKind`]); an error wrapped with its
    /// part file ([`Error::InPart`]) has its source's kind.
    pub fn kind(&self) -> ErrorKind {
        match self {
            Error::InPart { source, .. } => source.kind(),
            Error::Cancelled { .. } | Error::Optimise(OptimiseError::Cancelled { .. }) => {
                ErrorKind::Cancelled
            }
            Error::Program(
                ProgramError::InfeasibleLayer { .. } | ProgramError::Infeasible { .. },
            ) => ErrorKind::Infeasible,
            Error::Program(ProgramError::Io { .. })
            | Error::PartFile(PartFileError::Io { .. })
            | Error::Io { .. }
            | Error::CellFile(CellFileError::Io { .. })
            | Error::Report(crate::report::ReportError::Io { .. })
            | Error::Fit(FitError::StlIo { .. }) => ErrorKind::Io,
            _ => ErrorKind::Input,
        }
    }
}
