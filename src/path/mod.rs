//! **Stage 2 — deposition paths.** Takes a validated [`Tube`](crate::geometry::Tube) and its
//! [`Substrate`](crate::geometry::Substrate) (part frame, mm) and returns a [`Path`]: layers of points
//! carrying `(t, v)`, position and the local distance to the layer below.
//! Four strategies (SPEC §3.1): planar Z slices, slices perpendicular to the
//! guide, iso-parametric layers, and the core method — **constant local
//! interlayer distance**, a bracketed 1-D root find per point against the
//! layer below [thesis §2.3, eq. 2.20–2.27]. Also the distance map (SPEC §3.2),
//! truncation by an end plane (§3.5) and seams (§3.3).

pub mod corners;
pub mod distance_map;
mod estimate;
pub mod index;
mod march;
pub mod smooth;
pub mod strategy;

pub use corners::Corner;
pub use distance_map::{distance_map, spiral_distance_map, DistanceMap, DistanceStats};
pub use estimate::{estimate_work, WorkEstimate, BYTES_PER_POINT};
pub use march::slice;
pub(crate) use march::slice_positions;

use crate::geometry::Plane;
use crate::math::Point3;
use serde::{Deserialize, Serialize};

/// Slicing strategy (SPEC §3.1).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Strategy {
    /// Constant local interlayer distance (the core method).
    #[default]
    Constant,
    /// Iso-parametric layers: `Delta` between points of the same `v`.
    Iso,
    /// Layers perpendicular to the guide, `Delta` apart along its arc length.
    Perpendicular,
    /// Planar slices `Z = z0 + k Delta` (part frame).
    Planar,
    /// One continuous spiral at constant distance to the turn below.
    Spiral,
}

impl Strategy {
    /// The name used in files and on the command line.
    pub fn name(self) -> &'static str {
        match self {
            Strategy::Constant => "constant",
            Strategy::Iso => "iso",
            Strategy::Perpendicular => "perpendicular",
            Strategy::Planar => "planar",
            Strategy::Spiral => "spiral",
        }
    }
}

/// How to discretise a layer.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Discretisation {
    /// A fixed number of points per layer, uniform in `v`.
    Points(usize),
    /// Max chord error (sagitta, mm): computed on a fine grid, output decimated.
    ChordError(f64),
    /// Max distance between consecutive points (mm): fine grid, output decimated.
    MaxSpacing(f64),
}

/// Where the path ends.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum EndRule {
    /// Whole layers only: stop before the first layer with a point past
    /// `t_max` (the thesis's rule).
    WholeLayers,
    /// Generate past the end and keep points with `(M - P)·p <= 0` for the
    /// plane (P, outward p) (SPEC §3.5); stop when a layer has no point left.
    Truncate(Plane),
    /// Keep going while every point stays within the tube's evaluable range
    /// (for comparisons such as the thesis's 16-layer iso path).
    EvaluableRange,
}

/// Options of [`slice`](fn@slice). Plain data; [`SliceOptions::validate`] names the field.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SliceOptions {
    /// Strategy.
    pub strategy: Strategy,
    /// Target interlayer distance `Delta` (mm, > 0).
    pub delta_mm: f64,
    /// Discretisation of each layer.
    pub discretisation: Discretisation,
    /// Where the path ends.
    pub end: EndRule,
    /// Upper bound on the number of layers (the first layer included).
    pub max_layers: Option<usize>,
    /// Rotate each closed layer so it starts at the point closest to the end
    /// of the layer below (SPEC §3.3).
    pub align_seams: bool,
    /// Extra rotation of the start of layer `k` by `k × stagger` (rad of `v`);
    /// not applied to a layer whose seam is put on a corner.
    pub stagger_rad: f64,
    /// A vertex of a layer turning more than this is a corner (rad, in
    /// (0, π)), where it also turns more than [`SEAM_CORNER_OVER_MEDIAN`]
    /// times the layer's median turning ([`Layer::corners`]). Default
    /// [`SEAM_CORNER_RAD`].
    pub corner_threshold_rad: f64,
    /// Start and end each closed layer that has corners at its sharpest one
    /// ([`corners::corner_seam_start`]), so that the bead turns no corner at
    /// its ends; layers without corners keep `align_seams` and the stagger.
    /// Default on.
    pub seams_on_corners: bool,
    /// Spiral only: profile angle `v` where the spiral starts (rad).
    pub spiral_start_rad: f64,
    /// Spiral only: travel toward decreasing `v` instead of increasing.
    pub spiral_reverse: bool,
    /// Constant strategy only: bound the turning angle of every layer
    /// (SPEC §3.4); `None` leaves the layers as the root finds give them.
    pub smoothing: Option<smooth::Smoothing>,
}

impl SliceOptions {
    /// Options with the given strategy and `Delta`, 500 points per layer,
    /// whole layers, seams aligned, and on the sharpest corner of a layer
    /// that has corners above [`SEAM_CORNER_RAD`].
    pub fn new(strategy: Strategy, delta_mm: f64) -> Self {
        Self {
            strategy,
            delta_mm,
            discretisation: Discretisation::Points(500),
            end: EndRule::WholeLayers,
            max_layers: None,
            align_seams: true,
            stagger_rad: 0.0,
            corner_threshold_rad: SEAM_CORNER_RAD,
            seams_on_corners: true,
            spiral_start_rad: 0.0,
            spiral_reverse: false,
            smoothing: None,
        }
    }

    /// Checks every field.
    ///
    /// # Errors
    /// [`PathError::InvalidOption`] naming the field.
    pub fn validate(&self) -> Result<(), PathError> {
        let bad =
            |field: &'static str, reason: String| Err(PathError::InvalidOption { field, reason });
        if !(self.delta_mm.is_finite() && self.delta_mm > 0.0) {
            return bad(
                "delta_mm",
                format!("must be positive and finite, got {}", self.delta_mm),
            );
        }
        match self.discretisation {
            Discretisation::Points(n) if !(3..=MAX_POINTS_PER_LAYER).contains(&n) => {
                return bad(
                    "points",
                    format!("must be in 3..={MAX_POINTS_PER_LAYER}, got {n}"),
                )
            }
            Discretisation::ChordError(e) if !(e.is_finite() && e > 0.0) => {
                return bad("chord_mm", format!("must be positive and finite, got {e}"))
            }
            Discretisation::MaxSpacing(d) if !(d.is_finite() && d > 0.0) => {
                return bad(
                    "max_spacing_mm",
                    format!("must be positive and finite, got {d}"),
                )
            }
            _ => {}
        }
        if let Some(sm) = self.smoothing {
            if !(sm.max_turn_rad.is_finite() && sm.max_turn_rad > 0.0) {
                return bad(
                    "smoothing.max_turn",
                    format!("must be positive, got {}", sm.max_turn_rad),
                );
            }
            if !(sm.tolerance.is_finite() && sm.tolerance > 0.0 && sm.tolerance < 1.0) {
                return bad(
                    "smoothing.tolerance",
                    format!("must be in (0, 1), got {}", sm.tolerance),
                );
            }
        }
        if !self.spiral_start_rad.is_finite() {
            return bad("spiral_start", "must be finite".into());
        }
        if !self.stagger_rad.is_finite() {
            return bad("stagger", "must be finite".into());
        }
        let c = self.corner_threshold_rad;
        if !(c > 0.0 && c < std::f64::consts::PI) {
            return bad(
                "corner_threshold",
                format!("must be in (0, 180) deg, got {} deg", c.to_degrees()),
            );
        }
        if self.max_layers == Some(0) {
            return bad("max_layers", "must be at least 1".into());
        }
        if let EndRule::Truncate(p) = self.end {
            if !p.point.coords.iter().all(|c| c.is_finite()) {
                return bad("end_plane.point", "must be finite".into());
            }
        }
        Ok(())
    }
}

/// Most points a layer may have (computation grid included).
pub const MAX_POINTS_PER_LAYER: usize = 200_000;
/// Most points a whole path may have.
pub const MAX_POINTS_PER_PATH: usize = 50_000_000;

/// One point of a deposition path (part frame).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PathPoint {
    /// Guide parameter `t`.
    pub t: f64,
    /// Profile angle `v` (rad, in `[0, 2π)`).
    pub v: f64,
    /// Position `M(t, v)` (mm).
    pub position: Point3,
    /// Local distance to the layer below (mm); `None` on the first layer.
    pub delta: Option<f64>,
}

/// One layer: a polyline of points, closed (a loop) or open (where the layer
/// leaves the part or is cut by the end plane).
#[derive(Debug, Clone, PartialEq)]
pub struct Layer {
    /// Slice number: 0 is the first layer on the substrate. An open slice
    /// cut in several pieces gives several layers with the same number.
    pub slice: usize,
    /// The points, in deposition order.
    pub points: Vec<PathPoint>,
    /// Whether the last point joins the first.
    pub closed: bool,
}

/// A seam of a closed layer turning more than this is a corner (rad, 10°),
/// where it also turns more than [`SEAM_CORNER_OVER_MEDIAN`] times the
/// layer's median turning; also the default corner threshold of
/// [`SliceOptions::corner_threshold_rad`]. The sample parts' smooth seams
/// turn 0.1–1° at 400 points a layer; the corners constant-distance layers
/// grow (SPEC §3.4), onto which the seams are put (§3.3), turn 10–113°.
pub const SEAM_CORNER_RAD: f64 = 10.0 * std::f64::consts::PI / 180.0;

/// A corner seam turns more than this many times the layer's median turning
/// (unitless): on a coarse layer every smooth step turns a lot.
pub const SEAM_CORNER_OVER_MEDIAN: f64 = 4.0;

impl Layer {
    /// Whether per-point quantities along the bead (the tangent's central
    /// difference, eq. 2.34; the tool axis's rate smoothing) wrap across the
    /// seam: a closed layer whose seam is not a corner. The bead runs from
    /// the first point to the last; it does not turn the seam's corner (the
    /// layer's start and end are one step apart and the arc is lit at
    /// neither across it), so a wrapped central difference there would give
    /// the first and last points a tangent, and a build direction, half way
    /// round the corner, belonging to neither end of the bead. A closed layer
    /// whose seam turns more than [`SEAM_CORNER_RAD`] and
    /// [`SEAM_CORNER_OVER_MEDIAN`] times its median turning takes one-sided
    /// differences at its ends, as an open layer does.
    pub fn bead_wraps(&self) -> bool {
        if !self.closed || self.points.len() < 3 {
            return self.closed;
        }
        let positions: Vec<Point3> = self.points.iter().map(|p| p.position).collect();
        let turns = smooth::turning_angles(&positions, true);
        let n = turns.len();
        turns[0].max(turns[n - 1]) <= corners::corner_bar_rad(&turns, SEAM_CORNER_RAD)
    }
}

/// Why the generation stopped (`summary.json`: its snake_case name).
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum StopReason {
    /// The next layer would pass `t_max` (whole layers only).
    ReachedEnd,
    /// Every point of the next layer is beyond the end plane.
    PastEndPlane,
    /// The next layer would leave the tube's evaluable range.
    EvaluableRange,
    /// No point of the next layer exists (e.g. a planar slice above the part).
    NoMorePoints,
    /// `max_layers` reached.
    MaxLayers,
}

/// What the slicer did, for reports. `Default` is an empty report (for paths
/// built elsewhere).
#[derive(Debug, Clone, PartialEq)]
pub struct SliceReport {
    /// Root finds run.
    pub root_finds: usize,
    /// Function evaluations inside root finds.
    pub evaluations: usize,
    /// Largest |residual| of a root find (mm).
    pub max_residual_mm: f64,
    /// Points removed by the end plane.
    pub truncated_points: usize,
    /// Points per layer of the computation grid.
    pub grid_points: usize,
    /// Why generation stopped.
    pub stop: StopReason,
    /// Largest turning angle between consecutive segments of a computed
    /// layer before smoothing (rad; over whole computed layers).
    pub max_turn_before_rad: f64,
    /// The same after smoothing (equal to the above without smoothing).
    pub max_turn_after_rad: f64,
}

/// What makes a path a spiral.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SpiralInfo {
    /// Points per turn.
    pub per_turn: usize,
    /// Index (in the spiral layer) of the first point of the ramp-down turn,
    /// if the spiral closes with one.
    pub ramp_down_from: Option<usize>,
}

impl Default for SliceReport {
    fn default() -> Self {
        Self {
            root_finds: 0,
            evaluations: 0,
            max_residual_mm: 0.0,
            truncated_points: 0,
            grid_points: 0,
            stop: StopReason::NoMorePoints,
            max_turn_before_rad: 0.0,
            max_turn_after_rad: 0.0,
        }
    }
}

/// A deposition path: layers in order.
#[derive(Debug, Clone, PartialEq)]
pub struct Path {
    /// Strategy that made it.
    pub strategy: Strategy,
    /// Target interlayer distance `Delta` (mm).
    pub delta_mm: f64,
    /// The layers, first on the substrate.
    pub layers: Vec<Layer>,
    /// What the slicer did.
    pub report: SliceReport,
    /// Set for spirals: the path is one open layer winding up the tube.
    pub spiral: Option<SpiralInfo>,
}

impl Path {
    /// Number of points.
    pub fn num_points(&self) -> usize {
        self.layers.iter().map(|l| l.points.len()).sum()
    }

    /// Number of slices (layers counted once even when cut in pieces).
    pub fn num_slices(&self) -> usize {
        self.layers.last().map_or(0, |l| l.slice + 1)
    }

    /// Total path length (mm), closing segments of closed layers included.
    pub fn length_mm(&self) -> f64 {
        self.layers
            .iter()
            .map(|l| {
                let n = l.points.len();
                let open: f64 = l
                    .points
                    .windows(2)
                    .map(|w| (w[1].position - w[0].position).norm())
                    .sum();
                if l.closed && n > 1 {
                    open + (l.points[0].position - l.points[n - 1].position).norm()
                } else {
                    open
                }
            })
            .sum()
    }
}

/// Errors of the path stage; each names the layer, point or option.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum PathError {
    /// An option is invalid.
    #[error("slicing option `{field}`: {reason}")]
    InvalidOption {
        /// The option.
        field: &'static str,
        /// What is wrong.
        reason: String,
    },
    /// `Delta` is larger than the part: not even a second layer fits.
    #[error("Delta = {delta_mm} mm is larger than the part: no second layer fits (guide length {length_mm:.3} mm)")]
    DeltaTooLarge {
        /// The requested Delta (mm).
        delta_mm: f64,
        /// The guide length of the part (mm).
        length_mm: f64,
    },
    /// The first layer could not be built.
    #[error("first layer: {0}")]
    FirstLayer(#[from] crate::geometry::GeometryError),
    /// A root find failed.
    #[error("layer {layer}, point {point} (v = {v:.4} rad): no t in [{t_lo:.6}, {t_hi:.6}] reaches delta = {delta_mm} mm ({reason})")]
    NoRoot {
        /// Layer.
        layer: usize,
        /// Point.
        point: usize,
        /// Profile angle (rad).
        v: f64,
        /// Bracket low end.
        t_lo: f64,
        /// Bracket high end.
        t_hi: f64,
        /// Target distance (mm).
        delta_mm: f64,
        /// Why.
        reason: &'static str,
    },
    /// The path would exceed the point limit.
    #[error("the path would exceed {limit} points (at layer {layer}); raise Delta or lower the point count")]
    TooManyPoints {
        /// The limit.
        limit: usize,
        /// Layer reached.
        layer: usize,
    },
    /// The end plane is past the evaluable range of the tube.
    #[error("layer {layer}, point {point}: the end plane is beyond the tube's evaluable range (t > {t_eval_max:.6}); raise range.extend_after")]
    ExtensionTooShort {
        /// Layer.
        layer: usize,
        /// Point.
        point: usize,
        /// Highest evaluable t.
        t_eval_max: f64,
    },
    /// Smoothing could not meet the turning-angle bound within the distance tolerance.
    #[error("layer {layer}: smoothing cannot bring the turning angle below {bound_deg:.3} deg while keeping distances within {tolerance_pct} % of Delta (reached {reached_deg:.3} deg, from {before_deg:.3} deg)")]
    SmoothingInfeasible {
        /// Layer.
        layer: usize,
        /// Requested bound (deg).
        bound_deg: f64,
        /// Distance tolerance (% of Delta).
        tolerance_pct: f64,
        /// Angle before smoothing (deg).
        before_deg: f64,
        /// Best angle reached (deg).
        reached_deg: f64,
    },
    /// A spiral point could not be placed.
    #[error("spiral point {point} (turn {turn}, v = {v:.4} rad): root find failed ({reason})")]
    SpiralRoot {
        /// Point index along the spiral.
        point: usize,
        /// Turn number.
        turn: usize,
        /// Profile angle (rad).
        v: f64,
        /// Why.
        reason: &'static str,
    },
}
