//! **Stage 9 — the closed loop: replan the remaining layers from a measured
//! layer.** Takes a part and its cell (or a part already planned there), a
//! [`Measured`] top of layer `K` (scan points or height errors, part frame,
//! mm) and returns a [`ReplannedPart`]: layers `K+1..` with the travel speed
//! (mm/s) and bead height (mm) of every point, their joints optimised in
//! the cell and a program that continues the build's layer numbering from
//! the cell's state (home, the payload of the layers already deposited).
//! A client of the front door ([`crate::pipeline`]); SPEC §9 "Closed loop",
//! issue 29.
//!
//! Two corrections, in this order, per point of the layers after `K`:
//! 1. **speed** — the bead height `h` that brings the top back to the
//!    nominal layer is the distance from the nominal point to the measured
//!    top below it; the travel speed that lays it comes from the process's
//!    law `ln h = a ln v + b` ([`BeadHeightLaw`](crate::process::BeadHeightLaw),
//!    anchored by default so that the nominal speed lays `Delta`);
//! 2. **geometry** — where that speed leaves the process window
//!    (`travel_speed_min_mm_s..travel_speed_max_mm_s`), the point is put at
//!    the nearest height the window allows, at constant local distance from
//!    the layer below as it will stand (the constant-distance march, SPEC
//!    §3.1.4, started from the measured layer instead of the substrate);
//!    the next layer is built on that one, and so on until a layer lands on
//!    its nominal layer at every point: from there on the nominal layers
//!    and speed are kept. Where the wall stands half a layer high or more,
//!    the layers may instead aim at a later nominal layer (layer `K+1` at
//!    nominal `K+2`, ..), when that rejoins in fewer layers: the skipped
//!    nominal layers are named ([`ReplannedPart::skipped`]) and the layers
//!    after them renumbered so that the build's numbering has no gap.
//!
//! The predicted error of a layer is its predicted top minus its nominal top
//! along the column (mm, + high); "before" is what the nominal plan would
//! leave (under the law a nominal bead lays the nominal height, so the
//! measured error stays), "after" what the replan leaves.
//!
//! Not yet handled: the arc-off transits of the resumed program are checked
//! against the beads it lays, not against the layers `0..=K` already on the
//! part.

mod rebuild;
pub mod scan;
pub mod summary;

pub use scan::{HeightError, Measured, Outlier, ScanEstimate};

use std::path::{Path as FsPath, PathBuf};
use std::time::Instant;

use serde::Serialize;

use crate::math::{Point3, Vector3};
use crate::optimise::{
    layer_points, optimise_with, trajectory_inputs, LayerPoints, OptimiseOptions, Plan, Transition,
};
use crate::pipeline::{
    program_name, slice_part_with, Cell, Control, Part, PlanOptions, PlanTimes, PlannedPart,
    ProgramFormat, RzLaw, SlicedPart,
};
use crate::process::{PointProcess, ResolvedHeightLaw};
use crate::program::cell_check::{check_cell, CellClearance, CellScene};
use crate::program::{
    build_program_with, check_vendor, LayerRefusal, Program, ProgramError, TravelSpeed,
};
use crate::robot::trajectory::{joint_trajectory_without_measures, TrajectoryOptions};
use crate::robot::CellLayout;
use crate::Error;
use rebuild::Window;
use summary::{
    CorrectionSummary, HeightLawSummary, OutlierSummary, PayloadSummary, ReplanDetails,
    ReplanSummary, ScanSummary,
};

/// Options of the closed loop: how a scan is read and when it is refused.
/// Plain data; [`ReplanOptions::validate`] names the field.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct ReplanOptions {
    /// A scan row farther than this from layer `K`'s planned top is an
    /// outlier: named in the summary, not used (mm). `None`: `max(3 Delta, 3 mm)`.
    pub outlier_distance_mm: Option<f64>,
    /// Half-width of the window along the layer over which the scan is
    /// fitted (a weighted local line) into a point's error (mm; 0: each
    /// point's own neighbours). A wider window averages more noise away but
    /// blurs an error that changes over a few mm.
    pub smoothing_mm: f64,
    /// A scan whose median height error is more than this fraction of
    /// `Delta` is refused as a scan of another layer (relative).
    pub max_median_error_rel: f64,
    /// A scan whose median offset across the wall (along the surface
    /// normal) is more than this is refused as a scan of another part (mm).
    /// `None`: `Delta`.
    pub max_wall_offset_mm: Option<f64>,
    /// Fewest scan rows that must lie within the outlier distance, as a
    /// fraction of the rows (relative); fewer: a scan of another part.
    pub min_inlier_fraction: f64,
    /// Fewest points of layer `K` with scan data of their own, as a fraction
    /// (relative); fewer: refused, too little of the layer was seen.
    pub min_coverage: f64,
    /// Whether the rebuilt layers may rejoin a later nominal layer than
    /// `K+1` (skipping nominal layers) when that rejoins in fewer layers.
    /// At most as many nominal layers are skipped as the highest point of
    /// the measured top stands above its nominal, in layers, rounded (none
    /// while the wall is nowhere half a layer high, so that the speed
    /// correction of layer `K+1` stays as it is). `false`: always aim at
    /// `K+1, K+2, ..`.
    pub skip_nominal_layers: bool,
}

impl Default for ReplanOptions {
    fn default() -> Self {
        Self {
            outlier_distance_mm: None,
            smoothing_mm: 0.5,
            max_median_error_rel: 0.5,
            max_wall_offset_mm: None,
            min_inlier_fraction: 0.5,
            min_coverage: 0.5,
            skip_nominal_layers: true,
        }
    }
}

impl ReplanOptions {
    /// Checks every field.
    ///
    /// # Errors
    /// [`ReplanError::InvalidOption`] naming the field.
    pub fn validate(&self) -> Result<(), ReplanError> {
        let bad = |field: &'static str, value: f64| {
            Err(ReplanError::InvalidOption {
                field,
                reason: format!("got {value}"),
            })
        };
        if let Some(d) = self.outlier_distance_mm {
            if !(d.is_finite() && d > 0.0) {
                return bad("outlier_distance_mm (must be > 0)", d);
            }
        }
        if let Some(d) = self.max_wall_offset_mm {
            if !(d.is_finite() && d > 0.0) {
                return bad("max_wall_offset_mm (must be > 0)", d);
            }
        }
        if !(self.smoothing_mm.is_finite() && self.smoothing_mm >= 0.0) {
            return bad("smoothing_mm (must be >= 0)", self.smoothing_mm);
        }
        if !(self.max_median_error_rel.is_finite() && self.max_median_error_rel > 0.0) {
            return bad(
                "max_median_error_rel (must be > 0)",
                self.max_median_error_rel,
            );
        }
        for (field, v) in [
            (
                "min_inlier_fraction (must be in [0, 1])",
                self.min_inlier_fraction,
            ),
            ("min_coverage (must be in [0, 1])", self.min_coverage),
        ] {
            if !(0.0..=1.0).contains(&v) {
                return bad(field, v);
            }
        }
        Ok(())
    }
}

/// Errors of the closed loop; each names the file, row, layer or point. A
/// refused scan says which distance gave it away.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum ReplanError {
    /// The scan file cannot be read.
    #[error("scan {file}, line {line}: {reason}")]
    ScanFile {
        /// The file.
        file: String,
        /// 1-based line (0: the file as a whole).
        line: usize,
        /// What is wrong (names the column).
        reason: String,
    },
    /// An option is invalid.
    #[error("replan option `{field}`: {reason}")]
    InvalidOption {
        /// The option.
        field: &'static str,
        /// What is wrong.
        reason: String,
    },
    /// No layer remains after the measured one.
    #[error("after layer {after_layer}: the plan has {layers} layers (0..{layers}), none remains to replan")]
    NothingToReplan {
        /// The measured layer.
        after_layer: usize,
        /// Layers in the plan.
        layers: usize,
    },
    /// The path cannot be replanned column by column.
    #[error("cannot replan this path: {reason}")]
    Unsupported {
        /// Why.
        reason: String,
    },
    /// Too few scan points lie near layer `K`: a scan of another part.
    #[error("the scan is not of layer {after_layer} of this part: {outside} of {total} rows lie more than {limit_mm:.3} mm from its planned top (median distance {median_distance_mm:.3} mm)")]
    WrongPart {
        /// The measured layer.
        after_layer: usize,
        /// Rows farther than the outlier distance.
        outside: usize,
        /// Rows in the scan.
        total: usize,
        /// The outlier distance (mm).
        limit_mm: f64,
        /// Median distance of all rows to the planned top (mm).
        median_distance_mm: f64,
    },
    /// The scan lies beside the wall: a scan of another part.
    #[error("the scan is not of layer {after_layer} of this part: it lies {median_mm:+.3} mm across the wall (along the surface normal) from the planned top on median, more than {limit_mm:.3} mm")]
    WallOffset {
        /// The measured layer.
        after_layer: usize,
        /// Median offset across the wall (mm).
        median_mm: f64,
        /// The limit (mm).
        limit_mm: f64,
    },
    /// The scan lies a layer or more above or below layer `K`.
    #[error("the scan is not of layer {after_layer}: its median height error is {median_error_mm:+.3} mm, more than {limit_mm:.3} mm{hint}")]
    WrongLayer {
        /// The measured layer.
        after_layer: usize,
        /// Median height error (mm).
        median_error_mm: f64,
        /// The limit (mm).
        limit_mm: f64,
        /// Which planned layer the scan fits, when found.
        hint: String,
    },
    /// A height-error row is for another layer.
    #[error("scan row {row} is for layer {scan_layer}, but the replan is after layer {after_layer}: a scan of another layer")]
    ScanOfAnotherLayer {
        /// Row (0-based).
        row: usize,
        /// Its layer.
        scan_layer: usize,
        /// The measured layer.
        after_layer: usize,
    },
    /// A height-error row names a point the layer does not have.
    #[error("scan row {row}: point {point}, but layer {after_layer} has {points} points")]
    ScanPoint {
        /// Row (0-based).
        row: usize,
        /// Its point.
        point: usize,
        /// Points of the layer.
        points: usize,
        /// The measured layer.
        after_layer: usize,
    },
    /// Too little of layer `K` was scanned.
    #[error("the scan covers {covered} of the {points} points of layer {after_layer}, fewer than {:.0} %", 100.0 * min_fraction)]
    TooLittleCoverage {
        /// The measured layer.
        after_layer: usize,
        /// Points with data.
        covered: usize,
        /// Points of the layer.
        points: usize,
        /// The fraction asked for.
        min_fraction: f64,
    },
    /// A rebuilt point cannot be placed.
    #[error("layer {layer}, point {point}: no point at {height_mm:.3} mm from the layer below ({reason})")]
    NoRoot {
        /// Layer.
        layer: usize,
        /// Point (column of the measured layer).
        point: usize,
        /// The bead height asked for (mm).
        height_mm: f64,
        /// Why.
        reason: &'static str,
    },
    /// The planned part given is not the part given.
    #[error("the plan is of part `{planned}`, not `{part}`")]
    PartMismatch {
        /// The plan's part.
        planned: String,
        /// The part given.
        part: String,
    },
}

/// Statistics of an error field over a layer (mm).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct ErrorStats {
    /// Smallest (mm).
    pub min_mm: f64,
    /// Largest (mm).
    pub max_mm: f64,
    /// Largest absolute value (mm).
    pub max_abs_mm: f64,
    /// Mean (mm).
    pub mean_mm: f64,
    /// Root mean square (mm).
    pub rms_mm: f64,
}

impl ErrorStats {
    /// The statistics of `v` (zeros for an empty slice).
    pub fn of(v: &[f64]) -> Self {
        if v.is_empty() {
            return Self {
                min_mm: 0.0,
                max_mm: 0.0,
                max_abs_mm: 0.0,
                mean_mm: 0.0,
                rms_mm: 0.0,
            };
        }
        let n = v.len() as f64;
        let min = v.iter().copied().fold(f64::INFINITY, f64::min);
        let max = v.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        Self {
            min_mm: min,
            max_mm: max,
            max_abs_mm: min.abs().max(max.abs()),
            mean_mm: v.iter().sum::<f64>() / n,
            rms_mm: (v.iter().map(|x| x * x).sum::<f64>() / n).sqrt(),
        }
    }
}

/// What the replan did to one remaining layer.
#[derive(Debug, Clone, PartialEq)]
pub struct LayerCorrection {
    /// Layer index (the build's numbering).
    pub layer: usize,
    /// The nominal layer it stands for: `layer` plus the nominal layers
    /// skipped ([`ReplannedPart::skipped`]).
    pub nominal_layer: usize,
    /// Whether its points or speeds differ from the nominal plan's.
    pub corrected: bool,
    /// Per point: the travel speed (mm/s).
    pub speed_mm_s: Vec<f64>,
    /// Per point: the bead height asked for (mm).
    pub height_mm: Vec<f64>,
    /// Per point: its height was clamped to the window (geometry correction).
    pub clamped: Vec<bool>,
    /// Per point: predicted top minus nominal top with the nominal plan (mm).
    pub error_before_mm: Vec<f64>,
    /// Per point: predicted top minus nominal top after the replan (mm).
    pub error_after_mm: Vec<f64>,
}

/// Wall-clock time of each replanning step (s).
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize)]
pub struct ReplanTimes {
    /// Slicing the nominal part (0 when a plan was given) (s).
    pub slice: f64,
    /// Reading the scan into errors (s).
    pub scan: f64,
    /// Rebuilding the layers (s).
    pub rebuild: f64,
    /// Distance map, tool axes and process of the new path (s).
    pub tool_axes: f64,
    /// Optimisation of the remaining layers (s).
    pub optimise: f64,
    /// Joint trajectory and program model (s).
    pub program: f64,
    /// Everything (s).
    pub total: f64,
}

/// The remaining layers replanned from a measured layer.
#[derive(Debug, Clone)]
pub struct ReplannedPart {
    /// The plan of the remaining layers: `planned.sliced.path` is the whole
    /// path with the corrected layers (part frame, mm; each corrected point's
    /// `delta` is its bead height), `planned.layers` and `planned.plan` the
    /// layers after `after_layer` only, `planned.program` the program that
    /// resumes the build, `planned.point_speeds_mm_s` every point's speed.
    pub planned: PlannedPart,
    /// The measured layer `K`.
    pub after_layer: usize,
    /// The scan as read: per-point error of layer `K`, outliers.
    pub scan: ScanEstimate,
    /// Per remaining layer, in order.
    pub corrections: Vec<LayerCorrection>,
    /// The height law used, both coefficients resolved.
    pub law: ResolvedHeightLaw,
    /// Whether `b` was anchored at the nominal speed and `Delta`.
    pub law_anchored: bool,
    /// The process window `[min, max]` (mm/s).
    pub speed_window_mm_s: [f64; 2],
    /// The bead heights the window can lay `[min, max]` (mm).
    pub height_window_mm: [f64; 2],
    /// The first layer that lands on its nominal layer at every point
    /// (`None`: none of the remaining layers does).
    pub rejoined_at: Option<usize>,
    /// The nominal layers never laid, `K+1..=K+s` (empty: none): the
    /// rebuilt layers rejoin nominal layer `rejoined_at + s`, and every
    /// layer from there on is the nominal layer `s` further on, renumbered
    /// so that the build's numbering runs on without a gap.
    pub skipped: Vec<usize>,
    /// The first nominal layer dropped because the rebuilt layers reach the
    /// part's end before it (a wall still too high near the top); `None`:
    /// every layer is kept.
    pub dropped_from: Option<usize>,
    /// The payload in effect when the resumed program starts (kg, and its
    /// centre of gravity in the flange frame, mm): the substrate and the
    /// layers `0..=K`. `None` in a torch-carried cell or without payload updates.
    pub resume_payload: Option<(f64, Point3)>,
    /// Run times (s).
    pub times: ReplanTimes,
}

impl ReplannedPart {
    /// `true` when every remaining layer is feasible and the program was built.
    pub fn is_feasible(&self) -> bool {
        self.planned.is_feasible()
    }

    /// Writes `joints.csv` of the remaining layers (with their speeds and
    /// bead heights, see [`crate::io::joints_csv`]).
    ///
    /// # Errors
    /// I/O errors of `w`.
    pub fn write_joints_csv(&self, w: &mut dyn std::io::Write) -> std::io::Result<()> {
        self.planned.write_joints_csv(w)
    }

    /// Writes the resumed program into `dir` (see
    /// [`PlannedPart::write_programs`]); returns the written paths.
    ///
    /// # Errors
    /// As [`PlannedPart::write_programs`].
    pub fn write_programs(&self, dir: impl AsRef<FsPath>) -> Result<Vec<PathBuf>, Error> {
        self.planned.write_programs(dir)
    }

    /// Writes the 3-D report (`report.html`, see [`crate::report`])
    /// atomically to `dest`: layer `K` as measured (each point moved by its
    /// error along `b`; the distance colour, distance − Delta, is then its
    /// height error in mm) and the remaining layers as replanned, coloured
    /// by their corrected travel speeds (mm/s) or bead heights. The path
    /// only: the robot is not animated (the plan's layers start at `K+1`).
    ///
    /// # Errors
    /// [`Error::Report`] naming the input or the file.
    pub fn write_report(
        &self,
        dest: &FsPath,
        substrate: Option<&crate::geometry::Substrate>,
    ) -> Result<(), Error> {
        let full = &self.planned.sliced;
        let k = self.after_layer;
        let delta = full.path.delta_mm;
        let mut measured = full.path.layers[k].clone();
        for ((p, f), e) in measured
            .points
            .iter_mut()
            .zip(&full.axes.frames[k])
            .zip(&self.scan.error_mm)
        {
            p.position += f.build * *e;
            p.delta = Some(delta + e);
        }
        let mut layers = vec![measured];
        layers.extend(full.path.layers[k + 1..].iter().cloned());
        let path = crate::path::Path {
            strategy: full.path.strategy,
            delta_mm: delta,
            layers,
            report: Default::default(),
            spiral: None,
        };
        let points: Vec<Vec<Option<(f64, bool)>>> = path
            .layers
            .iter()
            .map(|l| {
                l.points
                    .iter()
                    .map(|p| p.delta.map(|d| (d, false)))
                    .collect()
            })
            .collect();
        let map = crate::path::DistanceMap {
            per_layer: full.map.per_layer[k..].to_vec(),
            overall: full.map.overall,
            points,
        };
        let frames = full.axes.frames[k..].to_vec();
        let mut process = full.process_plan.clone();
        process.points = process.points[k..].to_vec();
        let title = format!(
            "{}: layers {}.. replanned from the scan of layer {k} (drawn as measured)",
            full.part_name,
            k + 1
        );
        let mut input = crate::report::ReportInput::new(&title, &path, &frames, &map, delta);
        input.substrate = substrate;
        input.process = Some(&process);
        crate::report::write_report(dest, &input)?;
        Ok(())
    }

    /// The content of `replan`'s `summary.json`: the plan's summary
    /// ([`PlannedPart::summary`], of the remaining layers) with a `replan`
    /// object: the scan (rows used, outliers named with their row, position
    /// and distance, median error), the law and window, and per remaining
    /// layer the predicted error before and after (mm), speeds and heights.
    pub fn summary(&self) -> ReplanSummary {
        let outliers_listed = self
            .scan
            .outliers
            .iter()
            .take(100)
            .map(|o| OutlierSummary {
                row: o.row,
                position_mm: o.position_mm.coords.into(),
                distance_mm: o.distance_mm,
            })
            .collect();
        let layers = self
            .corrections
            .iter()
            .map(|c| {
                let min = |v: &[f64]| v.iter().copied().fold(f64::INFINITY, f64::min);
                let max = |v: &[f64]| v.iter().copied().fold(0.0, f64::max);
                CorrectionSummary {
                    layer: c.layer,
                    nominal_layer: c.nominal_layer,
                    corrected: c.corrected,
                    clamped_points: c.clamped.iter().filter(|x| **x).count(),
                    speed_min_mm_s: min(&c.speed_mm_s),
                    speed_max_mm_s: max(&c.speed_mm_s),
                    height_min_mm: min(&c.height_mm),
                    height_max_mm: max(&c.height_mm),
                    error_before: ErrorStats::of(&c.error_before_mm),
                    error_after: ErrorStats::of(&c.error_after_mm),
                }
            })
            .collect();
        ReplanSummary {
            plan: self.planned.summary(),
            replan: ReplanDetails {
                after_layer: self.after_layer,
                first_layer: self.after_layer + 1,
                program: self
                    .planned
                    .refusal()
                    .is_none()
                    .then(|| program_name_for(&self.planned.sliced.part_name, self.after_layer)),
                scan: ScanSummary {
                    rows_used: self.scan.inliers,
                    outliers: self.scan.outlier_count,
                    outlier_distance_mm: self.scan.outlier_distance_mm,
                    outliers_listed,
                    covered_points: self.scan.covered_points,
                    points: self.scan.error_mm.len(),
                    median_error_mm: self.scan.median_error_mm,
                    median_wall_offset_mm: self.scan.median_wall_offset_mm,
                    measured_error: ErrorStats::of(&self.scan.error_mm),
                },
                law: HeightLawSummary {
                    a: self.law.a,
                    b: self.law.b,
                    b_anchored_at_nominal: self.law_anchored,
                },
                speed_window_mm_s: self.speed_window_mm_s,
                height_window_mm: self.height_window_mm,
                rejoined_at_layer: self.rejoined_at,
                rejoined_at_nominal_layer: self.rejoined_at.map(|l| l + self.skipped.len()),
                nominal_layers_skipped: self.skipped.clone(),
                layers_dropped_from: self.dropped_from,
                corrected_layers: self.corrections.iter().filter(|c| c.corrected).count(),
                resume_payload: self.resume_payload.map(|(mass_kg, c)| PayloadSummary {
                    mass_kg,
                    cog_mm: c.coords.into(),
                }),
                layers,
                run_time_s: self.times,
            },
        }
    }
}

/// The resumed program's name: the part's, then `_FROM_` and the first
/// replanned layer (e.g. `ELBOW_FROM_11`), controller-safe.
pub fn program_name_for(part_name: &str, after_layer: usize) -> String {
    program_name(&format!("{part_name}_from_{}", after_layer + 1))
}

/// Replans the layers of `part` after `after_layer` from its measured top:
/// slices the part as [`plan_part`](crate::plan_part) would (with `opts`),
/// reads `measured`, corrects the speeds and geometry, optimises the
/// remaining layers in `cell` and builds the program that resumes the
/// build. [`replan_planned`] does the same from a plan already made and
/// re-optimises only the corrected layers (the fast path during a dwell).
///
/// # Errors
/// As [`replan_part_with`].
pub fn replan_part(
    part: &Part,
    cell: &Cell,
    measured: &Measured,
    after_layer: usize,
    opts: &PlanOptions,
) -> Result<ReplannedPart, Error> {
    replan_part_with(
        part,
        cell,
        measured,
        after_layer,
        opts,
        &ReplanOptions::default(),
    )
}

/// [`replan_part`] with the scan options of `replan`.
///
/// # Errors
/// Bad input ([`Error::InPart`], [`Error::Optimise`], a program format the
/// cell's robot cannot run); [`Error::Replan`]: a refused scan (another
/// layer, another part, too little coverage: the message names the
/// distance), nothing left after `after_layer`, a path that is not on one
/// grid of closed layers.
pub fn replan_part_with(
    part: &Part,
    cell: &Cell,
    measured: &Measured,
    after_layer: usize,
    opts: &PlanOptions,
    replan: &ReplanOptions,
) -> Result<ReplannedPart, Error> {
    let t0 = Instant::now();
    let format = opts.format.unwrap_or_else(|| cell.native_format());
    check_vendor(&cell.layout, format.vendor(), format.emitter())?;
    replan.validate()?;
    let sliced = slice_part_with(part, &opts.slice, &Control::default())?;
    let radius = sliced
        .path
        .layers
        .iter()
        .flat_map(|l| &l.points)
        .map(|p| p.position.coords.norm())
        .fold(0.0, f64::max);
    cell.layout.check_reach(radius).map_err(|e| Error::InPart {
        file: cell.file.clone(),
        source: Box::new(e.into()),
    })?;
    let optimise = OptimiseOptions {
        travel_speed_mm_s: sliced.process.travel_speed_mm_s,
        ..opts.optimise
    };
    optimise.validate()?;
    let t_slice = t0.elapsed().as_secs_f64();
    let mut r = replan_core(
        part,
        cell,
        sliced,
        None,
        optimise,
        opts.rz(),
        format,
        measured,
        after_layer,
        replan,
    )?;
    r.times.slice = t_slice;
    r.times.total = t0.elapsed().as_secs_f64();
    Ok(r)
}

/// Replans the layers of `planned` (a plan of `part`) after `after_layer`
/// from its measured top: as [`replan_part`], with the plan's slicing,
/// options, cell and format, reusing its layer plans where the layers are
/// unchanged (only the corrected layers are optimised again).
///
/// # Errors
/// As [`replan_part_with`]; [`ReplanError::PartMismatch`] when `planned` is
/// not a plan of `part`.
pub fn replan_planned(
    part: &Part,
    planned: &PlannedPart,
    measured: &Measured,
    after_layer: usize,
    replan: &ReplanOptions,
) -> Result<ReplannedPart, Error> {
    let t0 = Instant::now();
    replan.validate()?;
    if planned.sliced.part_name != part.name {
        return Err(ReplanError::PartMismatch {
            planned: planned.sliced.part_name.clone(),
            part: part.name.clone(),
        }
        .into());
    }
    let mut r = replan_core(
        part,
        &planned.cell,
        planned.sliced.clone(),
        Some((&planned.layers, &planned.plan)),
        planned.optimise,
        planned.rz,
        planned.format,
        measured,
        after_layer,
        replan,
    )?;
    r.times.total = t0.elapsed().as_secs_f64();
    Ok(r)
}

/// The replan from a nominal slice (and its plan, to reuse).
#[allow(clippy::too_many_arguments)]
fn replan_core(
    part: &Part,
    cell: &Cell,
    sliced: SlicedPart,
    nominal: Option<(&[LayerPoints], &Plan)>,
    optimise: OptimiseOptions,
    rz: RzLaw,
    format: ProgramFormat,
    measured: &Measured,
    k: usize,
    ropts: &ReplanOptions,
) -> Result<ReplannedPart, Error> {
    let mut times = ReplanTimes::default();
    let path = &sliced.path;
    let nlayers = path.layers.len();
    if path.spiral.is_some() {
        return Err(ReplanError::Unsupported {
            reason: "a spiral path has no layers to replan one by one".into(),
        }
        .into());
    }
    if k + 1 >= nlayers {
        return Err(ReplanError::NothingToReplan {
            after_layer: k,
            layers: nlayers,
        }
        .into());
    }
    let t = Instant::now();
    let cols = rebuild::columns(path, k)?;
    let frames = &sliced.axes.frames;
    let scan = scan::estimate(path, frames, k, measured, ropts)?;
    times.scan = t.elapsed().as_secs_f64();

    let t = Instant::now();
    let v_nom = optimise.travel_speed_mm_s;
    let process = &sliced.process.clone();
    let law = process.bead_height_law.anchored(v_nom, path.delta_mm);
    let window = Window {
        law,
        speed_min_mm_s: process.travel_speed_min_mm_s,
        speed_max_mm_s: process.travel_speed_max_mm_s,
    };
    let t_meas = rebuild::measured_t(&part.tube, path, frames, k, &scan.error_mm);
    let chosen = rebuild_fewest(part, path, k, &cols, &t_meas, &window, &scan, ropts)?;
    let (rebuilt, ended_at, s) = (chosen.layers, chosen.ended_at, chosen.skip);
    if ended_at == Some(k + 1) {
        return Err(ReplanError::NoRoot {
            layer: k + 1,
            point: 0,
            height_mm: window.height_min_mm(),
            reason: "the measured wall is already at the part's end: nothing remains to lay",
        }
        .into());
    }
    // a wall still too high near the top: the layers from `ended_at` on no
    // longer fit below the part's end and are dropped; the nominal layers
    // K+1..=K+s are skipped, the others renumbered (nominal l + s is layer l)
    let end = ended_at.unwrap_or(nlayers - s);
    let rejoined_at = rebuilt
        .last()
        .filter(|l| l.clamped.iter().all(|c| !c))
        .map(|l| l.layer);
    let mut new_path = path.clone();
    new_path.layers.truncate(end + s);
    new_path.layers.drain(k + 1..k + 1 + s);
    for l in &mut new_path.layers[k + 1..] {
        l.slice -= s;
    }
    // Per remaining layer: before / after errors, speeds, heights.
    let corrections: Vec<LayerCorrection> = (k + 1..end)
        .map(|l| {
            let before: Vec<f64> = cols[l + s - k].iter().map(|&c| scan.error_mm[c]).collect();
            match rebuilt.iter().find(|r| r.layer == l) {
                Some(r) => LayerCorrection {
                    layer: l,
                    nominal_layer: r.nominal,
                    corrected: true,
                    speed_mm_s: r.speed_mm_s.clone(),
                    height_mm: r.height_mm.clone(),
                    clamped: r.clamped.clone(),
                    error_before_mm: before,
                    error_after_mm: r.error_after_mm.clone(),
                },
                None => {
                    let pts = &new_path.layers[l].points;
                    LayerCorrection {
                        layer: l,
                        nominal_layer: l + s,
                        corrected: false,
                        speed_mm_s: vec![v_nom; pts.len()],
                        height_mm: pts
                            .iter()
                            .map(|p| p.delta.unwrap_or(path.delta_mm))
                            .collect(),
                        clamped: vec![false; pts.len()],
                        error_before_mm: before,
                        error_after_mm: vec![0.0; pts.len()],
                    }
                }
            }
        })
        .collect();
    // The new path: the corrected layers' points, their heights as deltas.
    for r in &rebuilt {
        for (m, p) in new_path.layers[r.layer].points.iter_mut().enumerate() {
            p.t = r.t[m];
            p.position = r.position[m];
            p.delta = Some(r.height_mm[m]);
        }
    }
    times.rebuild = t.elapsed().as_secs_f64();

    let t = Instant::now();
    let map = crate::path::distance_map(&new_path);
    let axes = crate::toolaxis::tool_axes(
        &new_path,
        Some(&part.tube),
        Some(&part.substrate),
        &sliced.tool_axis,
    )
    .map_err(|e| Error::InPart {
        file: part.file.clone(),
        source: Box::new(e.into()),
    })?;
    let mut process_plan = sliced.process_plan.clone();
    process_plan.points.truncate(end + s);
    process_plan.points.drain(k + 1..k + 1 + s);
    for r in &rebuilt {
        process_plan.points[r.layer] = r
            .speed_mm_s
            .iter()
            .map(|&v| PointProcess {
                travel_speed_mm_s: v,
                bead: process.bead_at(v),
            })
            .collect();
    }
    let speeds: Vec<Vec<f64>> = process_plan
        .points
        .iter()
        .map(|l| l.iter().map(|p| p.travel_speed_mm_s).collect())
        .collect();
    process_plan.estimates = crate::process::estimate::estimate(
        &new_path,
        &speeds,
        process.wire_diameter_mm,
        process.wire_feed_speed_mm_s,
        process.density_kg_m3,
    );
    let all_layers = layer_points(&new_path, &axes.frames);
    let remaining: Vec<LayerPoints> = all_layers[k + 1..].to_vec();
    times.tool_axes = t.elapsed().as_secs_f64();

    // Optimise: the corrected layers at their fastest speed (the joint-speed
    // bound holds at every slower one), the others at the nominal speed or
    // as the nominal plan has them when their points are unchanged.
    let t = Instant::now();
    let r_count = rebuilt.len();
    let fastest = rebuilt
        .iter()
        .flat_map(|r| r.speed_mm_s.iter().copied())
        .fold(v_nom, f64::max);
    let never = |_: usize, _: usize| true;
    let corrected_opts = OptimiseOptions {
        travel_speed_mm_s: fastest,
        ..optimise
    };
    let mut plan_layers =
        optimise_with(&cell.layout, &remaining[..r_count], &corrected_opts, &never)?.layers;
    let rest = &remaining[r_count..];
    let reused: Option<Vec<_>> = nominal.and_then(|(layers, plan)| {
        rest.iter()
            .map(|lp| {
                // the nominal layer it stands for (renumbered after a skip)
                let i = layers.iter().position(|n| n.layer == lp.layer + s)?;
                let same = layers[i].points.len() == lp.points.len()
                    && layers[i].points.iter().zip(&lp.points).all(|(a, b)| {
                        (a.position_mm - b.position_mm).norm() <= 1e-9
                            && (a.tool_axis.into_inner() - b.tool_axis.into_inner()).norm() <= 1e-9
                    });
                let pl = plan.layers.get(i).filter(|p| p.layer == lp.layer + s)?;
                same.then(|| renumbered(pl, lp.layer))
            })
            .collect()
    });
    match reused {
        Some(mut r) => plan_layers.append(&mut r),
        None if !rest.is_empty() => {
            plan_layers.append(&mut optimise_with(&cell.layout, rest, &optimise, &never)?.layers)
        }
        None => {}
    }
    let plan = Plan {
        transitions: transitions(&cell.layout, &plan_layers),
        layers: plan_layers,
        time_s: t.elapsed().as_secs_f64(),
    };
    times.optimise = plan.time_s;

    // The program that resumes the build.
    let t = Instant::now();
    let point_speeds: Vec<Vec<f64>> = corrections.iter().map(|c| c.speed_mm_s.clone()).collect();
    let name = program_name_for(&part.name, k);
    let resume_payload = resume_payload(cell, &sliced, k);
    let checked = resumed_program(
        &name,
        cell,
        &remaining,
        &plan,
        &point_speeds,
        v_nom,
        resume_payload,
        &process_plan.layer_masses_kg(&new_path, process),
    );
    times.program = t.elapsed().as_secs_f64();
    let (program, clearance, cell_check_s) = match checked {
        Ok((p, c, s)) => (Ok(p), Some(c), s),
        Err(e) => (Err(e), None, 0.0),
    };

    let sliced = SlicedPart {
        path: new_path,
        map,
        axes,
        process_plan,
        ..sliced
    };
    let planned = PlannedPart {
        times: PlanTimes {
            slice: 0.0,
            tool_axes: times.tool_axes,
            optimise: times.optimise,
            program: times.program,
            cell_check: cell_check_s,
        },
        sliced,
        cell: cell.clone(),
        layers: remaining,
        optimise,
        rz,
        format,
        plan,
        program,
        point_speeds_mm_s: Some(point_speeds),
        clearance,
    };
    Ok(ReplannedPart {
        planned,
        after_layer: k,
        scan,
        corrections,
        law,
        law_anchored: process.bead_height_law.b.is_none(),
        speed_window_mm_s: [window.speed_min_mm_s, window.speed_max_mm_s],
        height_window_mm: [window.height_min_mm(), window.height_max_mm()],
        rejoined_at,
        skipped: (k + 1..=k + s).collect(),
        dropped_from: ended_at,
        resume_payload,
        times,
    })
}

/// The rebuild that rejoins the nominal layers in the fewest layers: the
/// march aimed at `K+1, K+2, ..` and, when `ropts` allows it and the wall
/// stands half a layer high or more somewhere, the marches aimed `s` nominal
/// layers further on, `s` up to the highest point's height in layers
/// (rounded). A skip is taken only when it rejoins in strictly fewer layers
/// (or the march without it never rejoins); a march with a skip that fails
/// or does not rejoin is left aside.
#[allow(clippy::too_many_arguments)]
fn rebuild_fewest(
    part: &Part,
    path: &crate::path::Path,
    k: usize,
    cols: &[Vec<usize>],
    t_meas: &[f64],
    window: &Window,
    scan: &ScanEstimate,
    ropts: &ReplanOptions,
) -> Result<rebuild::Rebuilt, ReplanError> {
    let mut best = rebuild::rebuild(&part.tube, path, k, cols, t_meas, window, 0)?;
    if !ropts.skip_nominal_layers {
        return Ok(best);
    }
    let highest = scan.error_mm.iter().copied().fold(0.0, f64::max);
    let room = path.layers.len().saturating_sub(k + 2);
    let max_skip = ((highest / path.delta_mm).round() as usize).min(room);
    for skip in 1..=max_skip {
        let Ok(r) = rebuild::rebuild(&part.tube, path, k, cols, t_meas, window, skip) else {
            continue;
        };
        if let Some(j) = r.layers_to_rejoin() {
            if best.layers_to_rejoin().is_none_or(|b| j < b) {
                best = r;
            }
        }
    }
    Ok(best)
}

/// A nominal layer's plan as the replanned layer `layer` (renumbered after
/// skipped nominal layers).
fn renumbered(plan: &crate::optimise::LayerPlan, layer: usize) -> crate::optimise::LayerPlan {
    let mut p = plan.clone();
    p.layer = layer;
    for v in &mut p.violations {
        v.layer = layer;
    }
    p
}

/// Arc-off moves between consecutive planned layers (as the optimiser
/// reports them for a whole plan).
fn transitions(cell: &CellLayout, plans: &[crate::optimise::LayerPlan]) -> Vec<Transition> {
    let robot = cell.robot();
    plans
        .windows(2)
        .filter_map(|w| {
            let last = w[0].points.last()?.joints?;
            let first = w[1].points.first()?.joints?;
            let start_limit = robot
                .limits
                .iter()
                .zip(&first)
                .filter(|(l, _)| !l.is_unlimited())
                .map(|(l, q)| (q - l.lower_rad).min(l.upper_rad - q))
                .fold(f64::INFINITY, f64::min);
            Some(Transition {
                from_layer: w[0].layer,
                to_layer: w[1].layer,
                joint_change_rad: std::array::from_fn(|j| first[j] - last[j]),
                branch_change: w[0].configuration.chosen != w[1].configuration.chosen,
                start_limit_distance_rad: start_limit,
            })
        })
        .collect()
}

/// The payload on the flange when layer `k` is done (part-carried cell with
/// payload updates): the substrate and fixture plus the layers `0..=k`,
/// each at the mean of its points (flange frame). Mass in kg, centre in mm.
fn resume_payload(cell: &Cell, sliced: &SlicedPart, k: usize) -> Option<(f64, Point3)> {
    let CellLayout::PartCarried(c) = &cell.layout else {
        return None;
    };
    let common = &cell.program.common;
    if common.payload_every_layers == 0 {
        return None;
    }
    let masses = sliced
        .process_plan
        .layer_masses_kg(&sliced.path, &sliced.process);
    let mut mass = common.payload_base_kg;
    let mut moment = Vector3::from(common.payload_base_cog_mm) * common.payload_base_kg;
    for (l, m) in masses.iter().enumerate().take(k + 1) {
        let pts = &sliced.path.layers[l].points;
        if pts.is_empty() {
            continue;
        }
        let centre = pts.iter().map(|p| p.position.coords).sum::<Vector3>() / pts.len() as f64;
        moment += (c.flange_from_part * Point3::from(centre)).coords * *m;
        mass += m;
    }
    let cog = if mass > 0.0 {
        Point3::from(moment / mass)
    } else {
        Point3::from(common.payload_base_cog_mm)
    };
    Some((mass, cog))
}

/// The program of the remaining layers: per-point speeds, the payload of
/// the deposited layers as its base, refused (as data) when a layer is
/// infeasible.
#[allow(clippy::too_many_arguments)]
fn resumed_program(
    name: &str,
    cell: &Cell,
    layers: &[LayerPoints],
    plan: &Plan,
    speeds: &[Vec<f64>],
    v_nom: f64,
    payload: Option<(f64, Point3)>,
    layer_masses_kg: &[f64],
) -> Result<(Program, CellClearance, f64), ProgramError> {
    let infeasible: Vec<_> = plan.infeasible_layers().collect();
    if let Some(first) = infeasible.first() {
        return Err(ProgramError::InfeasibleLayer {
            layer: first.layer,
            count: infeasible.len(),
            status: LayerRefusal::Infeasible(first.status.clone()),
        });
    }
    for (lp, pl) in layers.iter().zip(&plan.layers) {
        if let Some(m) = pl.points.iter().position(|p| p.joints.is_none()) {
            return Err(ProgramError::InfeasibleLayer {
                layer: lp.layer,
                count: 1,
                status: LayerRefusal::NoJointSolution { point: m },
            });
        }
    }
    let inputs = trajectory_inputs(layers, plan);
    let traj = joint_trajectory_without_measures(
        &cell.layout,
        &inputs,
        v_nom,
        &TrajectoryOptions::default(),
    )
    .map_err(|source| ProgramError::Trajectory { source })?;
    let mut common = cell.program.common;
    if let Some((mass, cog)) = payload {
        common.payload_base_kg = mass;
        common.payload_base_cog_mm = [cog.x, cog.y, cog.z];
    }
    let flat: Vec<f64> = speeds.iter().flatten().copied().collect();
    let mut program = build_program_with(
        name,
        &cell.layout,
        &inputs,
        &traj,
        &TravelSpeed::PerPoint(flat),
        &common,
    )?;
    if common.payload_every_layers > 0 {
        let masses: Vec<f64> = layers
            .iter()
            .map(|l| layer_masses_kg.get(l.layer).copied().unwrap_or(0.0))
            .collect();
        program.set_payloads(&common, &masses)?;
    }
    // the whole cell along every motion; the part's model holds the
    // remaining layers only (the wall below layer K+1 is not in the scene)
    let t = Instant::now();
    let scene = CellScene {
        keep_out: cell.keep_out.clone(),
        clearance_mm: common.collision_clearance_mm,
        transits: true,
    };
    let clearance = check_cell(&program, &traj, layers, &scene)?;
    Ok((program, clearance, t.elapsed().as_secs_f64()))
}
