//! The typed content of `replan`'s `summary.json`: the remaining layers'
//! plan summary ([`PlanSummary`]) with a `replan` object (the scan, the law,
//! the window and the corrections per layer). Lengths in mm, speeds in mm/s.

use serde::Serialize;

use super::{ErrorStats, ReplanTimes};
use crate::pipeline::summary::PlanSummary;

/// `replan`'s `summary.json`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ReplanSummary {
    /// The plan of the remaining layers.
    #[serde(flatten)]
    pub plan: PlanSummary,
    /// What the replan measured and corrected.
    pub replan: ReplanDetails,
}

/// What the replan measured and corrected.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ReplanDetails {
    /// The measured layer, K.
    pub after_layer: usize,
    /// The first replanned layer, K + 1.
    pub first_layer: usize,
    /// The resumed program's name (`null` when the plan is refused).
    pub program: Option<String>,
    /// The scan.
    pub scan: ScanSummary,
    /// The bead-height law `ln h = a ln v + b`.
    pub law: HeightLawSummary,
    /// The process's travel-speed window (mm/s).
    pub speed_window_mm_s: [f64; 2],
    /// The bead heights that window gives (mm).
    pub height_window_mm: [f64; 2],
    /// The first layer back on its nominal layer (the build's numbering).
    pub rejoined_at_layer: Option<usize>,
    /// The nominal layer it lands on: `rejoined_at_layer` plus the nominal
    /// layers skipped.
    pub rejoined_at_nominal_layer: Option<usize>,
    /// Nominal layers never laid (empty: none): the wall already stood a
    /// layer high over part of layer K, so the rebuilt layers rejoin a later
    /// nominal layer, and the layers after them are renumbered (nominal
    /// layer `l + skipped` is laid as layer `l`).
    pub nominal_layers_skipped: Vec<usize>,
    /// Nominal layers from this one on no longer fit below the part's end.
    pub layers_dropped_from: Option<usize>,
    /// Layers whose speed or geometry was corrected.
    pub corrected_layers: usize,
    /// The payload the resumed program starts with (part-carried cells).
    pub resume_payload: Option<PayloadSummary>,
    /// Per remaining layer.
    pub layers: Vec<CorrectionSummary>,
    /// Run time of each step (s).
    pub run_time_s: ReplanTimes,
}

/// The scan of layer K.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ScanSummary {
    /// Rows used.
    pub rows_used: usize,
    /// Rows left out as outliers.
    pub outliers: usize,
    /// The distance beyond which a row is an outlier (mm).
    pub outlier_distance_mm: f64,
    /// The first outliers (at most 100).
    pub outliers_listed: Vec<OutlierSummary>,
    /// Planned points of layer K the scan covers.
    pub covered_points: usize,
    /// Planned points of layer K.
    pub points: usize,
    /// Median height error (mm, along the build direction).
    pub median_error_mm: f64,
    /// Median offset across the wall (mm).
    pub median_wall_offset_mm: f64,
    /// The measured error over the layer (mm).
    pub measured_error: ErrorStats,
}

/// A scan row left out.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct OutlierSummary {
    /// Its row in the scan file (from 1 after the header).
    pub row: usize,
    /// Its position (part frame, mm).
    pub position_mm: [f64; 3],
    /// Its distance to layer K's planned top (mm).
    pub distance_mm: f64,
}

/// The bead-height law `ln h = a ln v + b` (h mm, v mm/s).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct HeightLawSummary {
    /// The exponent `a`.
    pub a: f64,
    /// The constant `b`.
    pub b: f64,
    /// `b` was set so that the nominal speed lays Delta.
    pub b_anchored_at_nominal: bool,
}

/// A payload: mass and centre of gravity (flange frame).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PayloadSummary {
    /// Mass (kg).
    pub mass_kg: f64,
    /// Centre of gravity (mm).
    pub cog_mm: [f64; 3],
}

/// One remaining layer's correction.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CorrectionSummary {
    /// The layer (the build's numbering).
    pub layer: usize,
    /// The nominal layer it stands for (`layer` plus the layers skipped).
    pub nominal_layer: usize,
    /// Its speed or geometry was corrected.
    pub corrected: bool,
    /// Points whose speed was clamped to the window.
    pub clamped_points: usize,
    /// Slowest speed (mm/s).
    pub speed_min_mm_s: f64,
    /// Fastest speed (mm/s).
    pub speed_max_mm_s: f64,
    /// Lowest bead height (mm).
    pub height_min_mm: f64,
    /// Highest bead height (mm).
    pub height_max_mm: f64,
    /// The predicted error before the correction (mm).
    pub error_before: ErrorStats,
    /// The predicted error after it (mm).
    pub error_after: ErrorStats,
}
