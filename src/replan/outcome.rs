//! **Stage 9 — what the closed loop returns**: the remaining layers
//! replanned ([`ReplannedPart`]), what was done to each of them
//! ([`LayerCorrection`], [`ErrorStats`], mm), its run times, and how it is
//! written (program, `joints.csv`, report, `summary.json`).

use std::path::{Path as FsPath, PathBuf};

use serde::Serialize;

use super::summary::{
    CorrectionSummary, HeightLawSummary, OutlierSummary, PayloadSummary, ReplanDetails,
    ReplanSummary, ScanSummary,
};
use super::ScanEstimate;
use crate::math::Point3;
use crate::pipeline::{program_name, PlannedPart};
use crate::process::ResolvedHeightLaw;
use crate::Error;

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
    /// resumes the build, each point of `planned.layers` at its corrected speed.
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
