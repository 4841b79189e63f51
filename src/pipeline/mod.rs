//! **The front door: the whole pipeline in one call per job.** Reads a part
//! file ([`Part::read`]) and a cell file ([`Cell::read`]), slices a part with
//! its tool axes and process ([`slice_part`] → [`SlicedPart`]), plans it in a
//! cell (slice → tool axes → `R_Z` optimisation → joint trajectory → program
//! model: [`plan_part`] → [`PlannedPart`]), writes its robot program
//! ([`PlannedPart::write_programs`]) and checks a program file against a
//! cell ([`check_program`]). Every function returns the crate's [`Error`](crate::Error),
//! whose messages name the file, field, layer or point. Lengths in mm,
//! angles in rad, speeds in mm/s; part-frame geometry; joints in the robot's
//! controller convention. The stage modules stay public for callers that
//! need one step.
//!
//! ```no_run
//! use waam_slicer::{Cell, Part, PlanOptions};
//! # fn main() -> Result<(), waam_slicer::Error> {
//! let part = Part::read("parts/hemisphere.toml")?;
//! let cell = Cell::read("parts/cells/robowam_part_carried.toml")?;
//! let planned = waam_slicer::plan_part(&part, &cell, &PlanOptions::default())?;
//! assert!(planned.is_feasible());
//! let files = planned.write_programs("out/hemisphere")?;
//! let report = waam_slicer::check_program(&files[0], &cell)?;
//! assert!(report.problems.is_empty());
//! # Ok(()) }
//! ```

mod check;
mod fitted;
mod options;
mod place;
mod planned;
pub(crate) mod program;
mod sliced;
pub mod summary;

use std::path::Path as FsPath;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

pub use check::check_program;
pub use fitted::FittedPart;
pub use options::DEFAULT_MAX_POINTS;
pub use options::{AxisOverrides, ParseOptionError, PlanOptions, RzLaw, SliceOverrides};
pub use place::{place_part, placement_bounds, PlaceRequest, PlacedCell, DEFAULT_HALF_BOX_MM};
pub use planned::{plan_part, plan_part_with, program_name, PlanTimes, PlannedPart};
pub use sliced::{slice_part, slice_part_with, SliceTimes, SlicedPart};

use crate::io::cell_file::{parse_cell_file, CellFile, CellFileError};
use crate::io::part_file::{parse_part, read_part_file, PartFileError};
use crate::robot::{RobotModel, Vendor};

pub use crate::io::part_file::Part;

impl Part {
    /// Reads and validates a part file (TOML, see `parts/README.md`).
    ///
    /// # Errors
    /// [`PartFileError`] naming the file and the field.
    pub fn read(path: impl AsRef<FsPath>) -> Result<Part, PartFileError> {
        read_part_file(path.as_ref())
    }

    /// Parses and validates part-file text; `origin` names it in errors, and
    /// relative paths in it (an STL substrate) are resolved from the folder
    /// of `origin`.
    ///
    /// # Errors
    /// [`PartFileError`] naming `origin` and the field.
    pub fn from_toml_str(text: &str, origin: &str) -> Result<Part, PartFileError> {
        let base = FsPath::new(origin)
            .parent()
            .map(FsPath::to_path_buf)
            .unwrap_or_default();
        parse_part(text, origin, &base)
    }
}

/// A robot cell as a cell file describes it: the robot and its layout (part
/// carried under a fixed torch, or torch carried over a positioner), with the
/// file's name and source. Robot base frame, mm.
#[derive(Debug, Clone, PartialEq)]
pub struct Cell {
    /// Name of the cell (the file's `name`).
    pub name: String,
    /// Where its numbers come from (the file's `source`).
    pub source: String,
    /// The file it was read from, as given (or the origin passed to
    /// [`Cell::from_toml_str`]).
    pub file: String,
    /// The robot, the deposition point or positioner, the torch: what the
    /// optimiser, the trajectory and the program stages take.
    pub layout: crate::robot::CellLayout,
    /// The file's `[placement]` table (bounds of [`place_part`]), if any.
    pub placement: Option<crate::io::cell_file::PlacementSpec>,
    /// The file's `[program]` table: home, interlayer dwell, interpass wait,
    /// payload updates, transit check, coordination, and each vendor's
    /// emitter options (defaults where absent).
    pub program: crate::program::ProgramSettings,
    /// The file's `[[keep_out]]` boxes (robot base frame, mm), checked
    /// against the arm, the positioner and the part along every motion
    /// ([`crate::program::cell_check`]).
    pub keep_out: Vec<crate::program::cell_check::KeepOut>,
    /// The file's text as read (a placed copy keeps its other keys).
    pub text: String,
}

impl Cell {
    /// Reads and validates a cell file (TOML, `parts/cells/`).
    ///
    /// # Errors
    /// [`CellFileError`] naming the file and the key; a file describing a
    /// robot only (no `[part_carried]` or `[torch_carried]` table) is refused.
    pub fn read(path: impl AsRef<FsPath>) -> Result<Cell, CellFileError> {
        let path = path.as_ref();
        let shown = path.display().to_string();
        // Read once: the text is kept (a placed copy rewrites it).
        let text = std::fs::read_to_string(path).map_err(|source| CellFileError::Io {
            path: shown.clone(),
            source,
        })?;
        Self::from_toml_str(&text, &shown)
    }

    /// Parses and validates cell-file text; `origin` names it in errors.
    ///
    /// # Errors
    /// As [`Cell::read`].
    pub fn from_toml_str(text: &str, origin: &str) -> Result<Cell, CellFileError> {
        let mut cell = Self::from_file(parse_cell_file(text, origin)?, origin)?;
        cell.text = text.to_string();
        Ok(cell)
    }

    /// The cell of a read cell file (its `text` left empty).
    ///
    /// # Errors
    /// [`CellFileError::Invalid`] when the file describes no cell.
    pub fn from_file(file: CellFile, origin: &str) -> Result<Cell, CellFileError> {
        let layout = file.cell.ok_or_else(|| CellFileError::Invalid {
            path: origin.to_string(),
            key: "part_carried".into(),
            reason: "no [part_carried] or [torch_carried] section: a robot, not a cell".into(),
        })?;
        Ok(Cell {
            name: file.name,
            source: file.source,
            file: origin.to_string(),
            layout,
            placement: file.placement,
            program: file.program,
            keep_out: file.keep_out,
            text: String::new(),
        })
    }

    /// The robot arm.
    pub fn robot(&self) -> &RobotModel {
        self.layout.robot()
    }

    /// The program format of the robot's controller.
    pub fn native_format(&self) -> Vendor {
        self.robot().vendor
    }
}

/// A progress callback: `(stage, fraction of the run done)`.
type ProgressFn = dyn Fn(&str, f64) + Send + Sync;

/// How a long run reports progress and is cancelled by a host program.
/// Cloning shares the same callback and flag.
#[derive(Clone, Default)]
pub struct Control {
    progress: Option<Arc<ProgressFn>>,
    cancel: Option<Arc<AtomicBool>>,
}

impl std::fmt::Debug for Control {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Control")
            .field("progress", &self.progress.is_some())
            .field("cancel", &self.cancel.is_some())
            .finish()
    }
}

impl PartialEq for Control {
    /// Two controls are equal when they share the same callback and flag.
    fn eq(&self, other: &Self) -> bool {
        let same_progress = match (&self.progress, &other.progress) {
            (Some(a), Some(b)) => Arc::ptr_eq(a, b),
            (None, None) => true,
            _ => false,
        };
        let same_cancel = match (&self.cancel, &other.cancel) {
            (Some(a), Some(b)) => Arc::ptr_eq(a, b),
            (None, None) => true,
            _ => false,
        };
        same_progress && same_cancel
    }
}

impl Control {
    /// Reports progress to `f(stage, fraction)`: the stage's name
    /// (`slicing`, `tool axes`, `optimising`, `program`) and the fraction of
    /// the whole run done (0..=1).
    pub fn with_progress(mut self, f: impl Fn(&str, f64) + Send + Sync + 'static) -> Self {
        self.progress = Some(Arc::new(f));
        self
    }

    /// Stops the run at the next stage or layer once `flag` is set; the run
    /// then returns [`Error::Cancelled`](crate::Error::Cancelled).
    pub fn with_cancel(mut self, flag: Arc<AtomicBool>) -> Self {
        self.cancel = Some(flag);
        self
    }

    /// The same control for a part of a run that spans `lo..=hi` of the
    /// whole (fractions 0..=1): its reports of `f` arrive as `lo + f (hi - lo)`.
    /// Shares the cancel flag.
    pub fn within(&self, lo: f64, hi: f64) -> Self {
        let progress = self.progress.clone().map(|f| {
            Arc::new(move |stage: &str, x: f64| f(stage, lo + x.clamp(0.0, 1.0) * (hi - lo)))
                as Arc<ProgressFn>
        });
        Self {
            progress,
            cancel: self.cancel.clone(),
        }
    }

    /// Reports `fraction` of the run done in `stage`.
    pub fn report(&self, stage: &str, fraction: f64) {
        if let Some(f) = &self.progress {
            f(stage, fraction.clamp(0.0, 1.0));
        }
    }

    /// `true` once the host asked to stop.
    pub fn is_cancelled(&self) -> bool {
        self.cancel
            .as_ref()
            .is_some_and(|c| c.load(Ordering::Relaxed))
    }

    /// [`Error::Cancelled`](crate::Error::Cancelled) naming `stage` once the host asked to stop.
    ///
    /// # Errors
    /// [`Error::Cancelled`](crate::Error::Cancelled).
    pub fn check(&self, stage: &'static str) -> Result<(), crate::Error> {
        if self.is_cancelled() {
            Err(crate::Error::Cancelled { stage })
        } else {
            Ok(())
        }
    }
}
