//! Compression of one planned WAAM bead into few controller moves.
//!
//! A bead is planned as a dense sequence of controller poses (torch position
//! `p` in mm and orientation `q` in the robot's base frame, plus extra axis
//! values such as positioner joints in rad). Writing every planned point as a
//! move makes long, slow robot programs; the controller follows the same path
//! within a few hundredths of a millimetre with far fewer linear and circular
//! moves. [`compress`] picks, greedily from the start of the bead, the longest
//! linear or circular move whose interpolated path stays within
//! [`CompressOptions::path_tolerance_mm`] and
//! [`CompressOptions::orientation_tolerance_deg`] of the planned points,
//! measured in the *part frame* through a caller-supplied map (see
//! [`tool_z_map`] for the identity-like case). [`interpolate`] is the
//! controller model and [`move_deviation`] the acceptance measure, both public
//! so that a program checker can reuse exactly the same model.
//!
//! A move from kept point `i` to `j` is acceptable when (1) every planned
//! point strictly between them lies within the path tolerance of the move's
//! part-frame curve, with its torch axis within the orientation tolerance of
//! the curve's axis at the closest curve parameter, and (2) every sample of
//! the curve (every [`CompressOptions::sample_step_mm`] along the path, and
//! every 0.5° of axis turning) lies within the path tolerance of the planned
//! polyline `i..=j`, with its axis within the orientation tolerance of the
//! planned axis interpolated there. From each kept point the search gallops
//! and then bisects for the farthest acceptable linear and circular end
//! (acceptability is not monotone in `j`, so the result may be slightly
//! short of the true optimum), counts positions — a circular move writes
//! two (via and end), a linear one one — and takes the circular move only
//! where it reaches farther than two linear moves would, and never passes
//! a must-keep point. A check costs O(points + samples of the move)
//! thanks to nearest-point queries that follow the path and skip segments
//! by distance bounds; 100 000 points take a few tenths of a second in a
//! release build.

use nalgebra::{Point3, Vector3};

pub use crate::program::pose::{arc_length, interpolate, tool_z_map, ControllerPose};
pub(crate) use crate::program::pose::{Arc3, MovePath};

mod error;
pub use error::CompressError;

/// Default [`CompressOptions::path_tolerance_mm`] (mm).
pub const DEFAULT_PATH_TOLERANCE_MM: f64 = 0.05;
/// Default [`CompressOptions::orientation_tolerance_deg`] (degrees).
pub const DEFAULT_ORIENTATION_TOLERANCE_DEG: f64 = 0.5;
/// Default [`CompressOptions::sample_step_mm`] (mm along the part-frame path).
pub const DEFAULT_SAMPLE_STEP_MM: f64 = 0.5;
/// Default [`CompressOptions::min_samples_per_move`].
pub const DEFAULT_MIN_SAMPLES_PER_MOVE: usize = 8;
/// Default [`CompressOptions::max_radius_mm`] (mm).
pub const DEFAULT_MAX_RADIUS_MM: f64 = 5000.0;
/// Default [`CompressOptions::max_arc_angle_deg`] (degrees).
pub const DEFAULT_MAX_ARC_ANGLE_DEG: f64 = 180.0;
/// Smallest arc radius (mm) the compressor programs as a circular move.
pub const MIN_ARC_RADIUS_MM: f64 = 0.5;
/// Upper bound on curve samples of one move (memory and time guard).
pub const MAX_SAMPLES_PER_MOVE: usize = 1 << 20;

/// Torch-axis change (degrees) allowed between two consecutive curve samples.
const ORIENTATION_SAMPLE_STEP_DEG: f64 = 0.5;
/// Resample a move when its sample gaps exceed the wanted step by this factor.
const SAMPLE_GAP_SLACK: f64 = 1.5;
/// Lets a length that is an integer multiple of the step round down stably.
const SAMPLE_COUNT_ROUNDING: f64 = 1e-6;
/// Golden-section steps when refining a planned point's closest parameter.
const GOLDEN_ITERATIONS: usize = 20;
/// Slack (mm) on the distance bounds used to skip polyline segments.
const SKIP_SLACK_MM: f64 = 1e-6;
/// Squared segment length (mm²) below which a segment is a point.
const MIN_SEGMENT_LENGTH_SQ_MM2: f64 = 1e-24;
/// Controller path length (mm) below which the via is picked by index.
const MIN_CONTROLLER_LENGTH_MM: f64 = 1e-9;
/// Norm below which a torch axis returned by the map is invalid.
const MIN_AXIS_NORM: f64 = 1e-9;
/// Allowed deviation of an orientation quaternion's norm from 1.
const UNIT_QUATERNION_TOLERANCE: f64 = 1e-6;
/// Slack (rad) on the arc sweep limit, for arcs of exactly the limit.
const ARC_SWEEP_SLACK_RAD: f64 = 1e-9;

/// Tolerances and limits of [`compress`].
#[derive(Clone, Debug, PartialEq)]
pub struct CompressOptions {
    /// Largest allowed distance (mm, part frame) between the interpolated path
    /// and the planned path, both ways (see [`move_deviation`]).
    pub path_tolerance_mm: f64,
    /// Largest allowed angle (degrees) between interpolated and planned torch
    /// axes.
    pub orientation_tolerance_deg: f64,
    /// Curve sampling step (mm along the planned part-frame path); the torch
    /// axis is also sampled at least every 0.5°.
    pub sample_step_mm: f64,
    /// Fewest sample intervals of one move's curve (at least 2).
    pub min_samples_per_move: usize,
    /// Largest radius (mm, controller frame) of a circular move.
    pub max_radius_mm: f64,
    /// Largest sweep (degrees) of a circular move, in (0, 360). The default
    /// of 180° keeps arcs within what every common controller accepts in
    /// one circular instruction and keeps the circle fit well conditioned.
    pub max_arc_angle_deg: f64,
    /// Whether circular moves may be used at all.
    pub allow_circular: bool,
    /// If set, a move from point `i` may end at most at point `i + n`.
    pub max_points_per_move: Option<usize>,
    /// Largest angle (deg) between a planned point's full controller
    /// orientation and the move's slerp at that point's share of the move
    /// (by the controller's travel, or by turning where the tool point is
    /// still); `None`: not checked. The map's axis leaves the rotation
    /// about the torch free; the robot's joints follow the whole rotation,
    /// so a program thinner checks it.
    pub rotation_tolerance_deg: Option<f64>,
}

impl Default for CompressOptions {
    fn default() -> Self {
        Self {
            path_tolerance_mm: DEFAULT_PATH_TOLERANCE_MM,
            orientation_tolerance_deg: DEFAULT_ORIENTATION_TOLERANCE_DEG,
            sample_step_mm: DEFAULT_SAMPLE_STEP_MM,
            min_samples_per_move: DEFAULT_MIN_SAMPLES_PER_MOVE,
            max_radius_mm: DEFAULT_MAX_RADIUS_MM,
            max_arc_angle_deg: DEFAULT_MAX_ARC_ANGLE_DEG,
            allow_circular: true,
            max_points_per_move: None,
            rotation_tolerance_deg: None,
        }
    }
}

impl CompressOptions {
    /// Checks every field; the error names the first invalid one.
    pub fn validate(&self) -> Result<(), CompressError> {
        positive_finite("path_tolerance_mm", self.path_tolerance_mm)?;
        positive_finite("orientation_tolerance_deg", self.orientation_tolerance_deg)?;
        positive_finite("sample_step_mm", self.sample_step_mm)?;
        if self.orientation_tolerance_deg > 180.0 {
            return Err(invalid_option(
                "orientation_tolerance_deg",
                "must be at most 180",
            ));
        }
        if !(2..=MAX_SAMPLES_PER_MOVE).contains(&self.min_samples_per_move) {
            return Err(invalid_option(
                "min_samples_per_move",
                "must be at least 2 and at most MAX_SAMPLES_PER_MOVE",
            ));
        }
        if !(self.max_radius_mm.is_finite() && self.max_radius_mm >= MIN_ARC_RADIUS_MM) {
            return Err(invalid_option(
                "max_radius_mm",
                "must be finite and at least MIN_ARC_RADIUS_MM",
            ));
        }
        if !(self.max_arc_angle_deg > 0.0 && self.max_arc_angle_deg < 360.0) {
            return Err(invalid_option("max_arc_angle_deg", "must be in (0, 360)"));
        }
        if self.max_points_per_move == Some(0) {
            return Err(invalid_option("max_points_per_move", "must be at least 1"));
        }
        Ok(())
    }
}

fn invalid_option(field: &'static str, reason: &'static str) -> CompressError {
    CompressError::InvalidOption { field, reason }
}

fn positive_finite(field: &'static str, value: f64) -> Result<(), CompressError> {
    if value.is_finite() && value > 0.0 {
        Ok(())
    } else {
        Err(invalid_option(field, "must be finite and positive"))
    }
}

/// One programmed move, starting where the previous move ended (the first
/// move starts at input pose 0). Indices refer to the input poses.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Move {
    /// Linear move to pose `to`.
    Linear {
        /// Target pose index.
        to: usize,
    },
    /// Circular move through the position of pose `via` to pose `to`.
    Circular {
        /// Via (circle) point index; only its position is used.
        via: usize,
        /// Target pose index.
        to: usize,
    },
}

impl Move {
    /// Target pose index.
    pub fn to(&self) -> usize {
        match *self {
            Move::Linear { to } | Move::Circular { to, .. } => to,
        }
    }

    /// Via pose index of a circular move.
    pub fn via(&self) -> Option<usize> {
        match *self {
            Move::Linear { .. } => None,
            Move::Circular { via, .. } => Some(via),
        }
    }
}

/// Worst deviations of one or more moves from the planned path.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Deviation {
    /// Largest part-frame distance (mm) of the two checks of [`move_deviation`].
    pub path_error_mm: f64,
    /// Largest torch-axis angle (degrees) of the two checks.
    pub orientation_error_deg: f64,
}

/// Running worst errors in cheap units: mm, and the chord `|a - b|` between
/// unit axes (`2 sin(angle / 2)`, monotone in the angle, no trigonometry).
#[derive(Clone, Copy, Debug, Default)]
struct Worst {
    path_mm: f64,
    axis_chord: f64,
}

impl Worst {
    fn include(&mut self, path_mm: f64, axis: &Vector3<f64>, planned_axis: &Vector3<f64>) {
        self.path_mm = max_keep_nan(self.path_mm, path_mm);
        self.axis_chord = max_keep_nan(self.axis_chord, (axis - planned_axis).norm());
    }

    fn deviation(&self) -> Deviation {
        Deviation {
            path_error_mm: self.path_mm,
            orientation_error_deg: chord_to_deg(self.axis_chord),
        }
    }
}

/// The tolerances in the units of [`Worst`].
#[derive(Clone, Copy, Debug)]
struct Limits {
    path_mm: f64,
    axis_chord: f64,
}

impl Limits {
    fn new(opts: &CompressOptions) -> Self {
        Self {
            path_mm: opts.path_tolerance_mm,
            axis_chord: deg_to_chord(opts.orientation_tolerance_deg),
        }
    }

    fn admit(&self, worst: &Worst) -> bool {
        worst.path_mm <= self.path_mm && worst.axis_chord <= self.axis_chord
    }
}

/// Maximum that keeps a NaN (so a numerical failure never passes a check).
fn max_keep_nan(a: f64, b: f64) -> f64 {
    if a.is_nan() || b.is_nan() {
        f64::NAN
    } else {
        a.max(b)
    }
}

/// Chord between unit vectors `angle_deg` apart.
fn deg_to_chord(angle_deg: f64) -> f64 {
    2.0 * (0.5 * angle_deg.to_radians()).sin()
}

/// Angle (degrees) between unit vectors whose difference has length `chord`.
fn chord_to_deg(chord: f64) -> f64 {
    2.0 * (0.5 * chord).clamp(0.0, 1.0).asin().to_degrees()
}

/// Result of [`compress`].
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Compressed {
    /// Moves in order; the first starts at pose 0, the last ends at the last
    /// pose. Empty for a one-point bead.
    pub moves: Vec<Move>,
    /// Worst path error (mm, part frame) over all moves, as [`move_deviation`]
    /// measures it. Moves between adjacent points are always taken, so this
    /// can exceed the tolerance only where adjacent points alone do.
    pub max_path_error_mm: f64,
    /// Worst torch-axis error (degrees) over all moves.
    pub max_orientation_error_deg: f64,
}

impl Compressed {
    /// Input indices the program contains, in order: 0, then each move's via
    /// (if any) and target.
    pub fn programmed_indices(&self) -> Vec<usize> {
        let mut out = vec![0];
        for mv in &self.moves {
            out.extend(mv.via());
            out.push(mv.to());
        }
        out
    }

    fn push(&mut self, mv: Move, dev: &Deviation) {
        self.moves.push(mv);
        self.max_path_error_mm = max_keep_nan(self.max_path_error_mm, dev.path_error_mm);
        self.max_orientation_error_deg =
            max_keep_nan(self.max_orientation_error_deg, dev.orientation_error_deg);
    }
}

/// Whether the compressor may program a circular move through these three
/// positions (mm, base frame): not collinear, radius within
/// [`MIN_ARC_RADIUS_MM`]..=`max_radius_mm`, sweep at most `max_arc_angle_deg`.
pub fn circular_move_allowed(
    a: &Point3<f64>,
    via: &Point3<f64>,
    b: &Point3<f64>,
    opts: &CompressOptions,
) -> bool {
    Arc3::through(a, via, b).is_some_and(|arc| {
        arc.radius >= MIN_ARC_RADIUS_MM
            && arc.radius <= opts.max_radius_mm
            && arc.sweep <= opts.max_arc_angle_deg.to_radians() + ARC_SWEEP_SLACK_RAD
    })
}

/// Measures one move from pose `from` to `mv.to()` as [`compress`] does, in
/// the part frame given by `map`. The path error is the larger of (1) the
/// distance (mm) of each planned point strictly between the ends to the
/// interpolated curve and (2) the distance of each curve sample to the
/// planned polyline; the orientation error (degrees) compares the torch axis
/// at (1) the closest curve parameter with the planned axis, and at (2) each
/// sample with the planned axis interpolated along the polyline. A collinear
/// via is measured as a linear move; the arc limits of
/// [`circular_move_allowed`] are not applied.
pub fn move_deviation(
    poses: &[ControllerPose],
    from: usize,
    mv: Move,
    map: &impl Fn(&ControllerPose) -> (Point3<f64>, Vector3<f64>),
    opts: &CompressOptions,
) -> Result<Deviation, CompressError> {
    opts.validate()?;
    let to = mv.to();
    if from >= to || to >= poses.len() {
        return Err(CompressError::InvalidMove {
            reason: "need from < to < number of poses",
        });
    }
    if mv.via().is_some_and(|v| v <= from || v >= to) {
        return Err(CompressError::InvalidMove {
            reason: "via must lie strictly between from and to",
        });
    }
    let sub = &poses[from..=to];
    validate_poses(sub, from)?;
    let planned = Planned::build(sub, map, from)?;
    let mut checker = Checker::new(sub, &planned, map, opts, from);
    checker.evaluate(0, to - from, mv.via().map(|v| v - from))
}

/// Compresses one bead into the fewest moves found by a greedy forward
/// search (see the module docs). `poses` are the planned controller poses;
/// `keep` is empty or marks poses that must be move targets (the first and
/// last always are); `map` turns a controller pose into the deposition point
/// (mm) and unit torch axis in the part frame. Errors on invalid options,
/// an empty bead, non-finite or inconsistent poses, or invalid map output.
pub fn compress(
    poses: &[ControllerPose],
    keep: &[bool],
    map: &impl Fn(&ControllerPose) -> (Point3<f64>, Vector3<f64>),
    opts: &CompressOptions,
) -> Result<Compressed, CompressError> {
    opts.validate()?;
    if poses.is_empty() {
        return Err(CompressError::EmptyBead);
    }
    let next_keep = next_keep_indices(keep, poses.len())?;
    validate_poses(poses, 0)?;
    let planned = Planned::build(poses, map, 0)?;
    let mut checker = Checker::new(poses, &planned, map, opts, 0);
    let mut out = Compressed::default();
    let mut i = 0;
    while i + 1 < poses.len() {
        let span_limit = opts
            .max_points_per_move
            .map_or(usize::MAX, |m| i.saturating_add(m));
        let limit = next_keep[i].min(span_limit);
        let (mv, dev) = checker.best_move(i, limit)?;
        out.push(mv, &dev);
        i = mv.to();
    }
    Ok(out)
}

/// For each index, the next index after it that must be kept (or the last).
fn next_keep_indices(keep: &[bool], n: usize) -> Result<Vec<usize>, CompressError> {
    if !keep.is_empty() && keep.len() != n {
        return Err(CompressError::KeepLengthMismatch {
            expected: n,
            found: keep.len(),
        });
    }
    let mut next = vec![n - 1; n];
    for k in (0..n.saturating_sub(1)).rev() {
        let after = k + 1;
        next[k] = if keep.get(after).copied().unwrap_or(false) {
            after
        } else {
            next[after]
        };
    }
    Ok(next)
}

fn validate_poses(poses: &[ControllerPose], offset: usize) -> Result<(), CompressError> {
    let expected = poses.first().map_or(0, |p| p.ext.len());
    for (k, pose) in poses.iter().enumerate() {
        let index = offset + k;
        let bad = |reason| Err(CompressError::InvalidPose { index, reason });
        if !pose.p.coords.iter().all(|v| v.is_finite()) {
            return bad("non-finite position");
        }
        if !pose.q.coords.iter().all(|v| v.is_finite()) {
            return bad("non-finite orientation");
        }
        if (pose.q.coords.norm() - 1.0).abs() > UNIT_QUATERNION_TOLERANCE {
            return bad("orientation quaternion is not unit");
        }
        if pose.ext.len() != expected {
            return Err(CompressError::ExtLengthMismatch {
                index,
                expected,
                found: pose.ext.len(),
            });
        }
        if !pose.ext.iter().all(|v| v.is_finite()) {
            return bad("non-finite extra axis value");
        }
    }
    Ok(())
}

/// Finite point and normalised axis, or `None` if the map output is invalid.
fn checked_output(p: Point3<f64>, a: Vector3<f64>) -> Option<(Point3<f64>, Vector3<f64>)> {
    let norm = a.norm();
    let finite = p.coords.iter().chain(a.iter()).all(|v| v.is_finite());
    (finite && norm > MIN_AXIS_NORM).then(|| (p, a / norm))
}

/// Angle between two unit vectors, degrees (accurate for small angles).
fn angle_deg(a: &Vector3<f64>, b: &Vector3<f64>) -> f64 {
    a.cross(b).norm().atan2(a.dot(b)).to_degrees()
}

/// Normalised linear interpolation of unit axes (nearer end if degenerate).
fn nlerp(a: &Vector3<f64>, b: &Vector3<f64>, t: f64) -> Vector3<f64> {
    let v = a * (1.0 - t) + b * t;
    let norm = v.norm();
    if norm > MIN_AXIS_NORM {
        v / norm
    } else if t < 0.5 {
        *a
    } else {
        *b
    }
}

fn cumulative(steps: impl Iterator<Item = f64>) -> Vec<f64> {
    let mut acc = 0.0;
    let mut out = vec![0.0];
    for step in steps {
        acc += step;
        out.push(acc);
    }
    out
}

/// Planned part-frame points and axes with cumulative measures.
struct Planned {
    pts: Vec<Point3<f64>>,
    axes: Vec<Vector3<f64>>,
    /// Cumulative part-frame polyline length, mm.
    cum: Vec<f64>,
    /// Cumulative planned torch-axis turning, degrees.
    ang_cum: Vec<f64>,
    /// Cumulative controller-frame TCP path length, mm.
    ctrl_cum: Vec<f64>,
}

impl Planned {
    fn build<F>(poses: &[ControllerPose], map: &F, offset: usize) -> Result<Self, CompressError>
    where
        F: Fn(&ControllerPose) -> (Point3<f64>, Vector3<f64>),
    {
        let mut pts = Vec::with_capacity(poses.len());
        let mut axes = Vec::with_capacity(poses.len());
        for (k, pose) in poses.iter().enumerate() {
            let (p, a) = map(pose);
            let (p, a) = checked_output(p, a)
                .ok_or(CompressError::InvalidMapOutput { index: offset + k })?;
            pts.push(p);
            axes.push(a);
        }
        let cum = cumulative(pts.windows(2).map(|w| (w[1] - w[0]).norm()));
        let ang_cum = cumulative(axes.windows(2).map(|w| angle_deg(&w[0], &w[1])));
        let ctrl_cum = cumulative(poses.windows(2).map(|w| (w[1].p - w[0].p).norm()));
        Ok(Self {
            pts,
            axes,
            cum,
            ang_cum,
            ctrl_cum,
        })
    }
}

/// A polyline range `lo..=hi` (`lo < hi`) with what nearest-point queries
/// need: cumulative lengths and chord-direction bounds.
#[derive(Clone, Copy)]
struct Polyline<'a> {
    pts: &'a [Point3<f64>],
    cum: &'a [f64],
    lo: usize,
    hi: usize,
    bounds: &'a ChordBounds,
}

/// Coordinates of a polyline range along its chord direction with running
/// extremes, giving cheap lower bounds on distances to whole tails of the
/// range. Tight for paths that advance along the chord (lines, arcs up to
/// 180°), still valid (just weak) for any other path.
#[derive(Debug, Default)]
struct ChordBounds {
    origin: Point3<f64>,
    dir: Vector3<f64>,
    lo: usize,
    /// `suffix_min[k - lo]`: smallest coordinate of points `k..=hi`.
    suffix_min: Vec<f64>,
    /// `prefix_max[k - lo]`: largest coordinate of points `lo..=k`.
    prefix_max: Vec<f64>,
}

impl ChordBounds {
    fn rebuild(&mut self, pts: &[Point3<f64>], lo: usize, hi: usize) {
        let chord = pts[hi] - pts[lo];
        let len_sq = chord.norm_squared();
        self.origin = pts[lo];
        self.dir = if len_sq > MIN_SEGMENT_LENGTH_SQ_MM2 {
            chord / len_sq.sqrt()
        } else {
            Vector3::zeros()
        };
        self.lo = lo;
        let coords = pts[lo..=hi]
            .iter()
            .map(|p| (p - self.origin).dot(&self.dir));
        self.prefix_max.clear();
        self.prefix_max
            .extend(coords.scan(f64::NEG_INFINITY, |m, u| {
                *m = u.max(*m);
                Some(*m)
            }));
        self.suffix_min.clear();
        let coords = pts[lo..=hi]
            .iter()
            .rev()
            .map(|p| (p - self.origin).dot(&self.dir));
        self.suffix_min.extend(coords.scan(f64::INFINITY, |m, u| {
            *m = u.min(*m);
            Some(*m)
        }));
        self.suffix_min.reverse();
    }

    fn coordinate(&self, x: &Point3<f64>) -> f64 {
        (x - self.origin).dot(&self.dir)
    }

    /// Lower bound of the distance from coordinate `xu` to segments `seg..`.
    fn ahead(&self, xu: f64, seg: usize) -> f64 {
        self.suffix_min[seg - self.lo] - xu
    }

    /// Lower bound of the distance from coordinate `xu` to segments `..=seg`.
    fn behind(&self, xu: f64, seg: usize) -> f64 {
        xu - self.prefix_max[seg + 1 - self.lo]
    }
}

impl Polyline<'_> {
    /// Index in `from..to` where `cum` is about `value`, assuming the mean
    /// segment length of that range (a start for [`partition_from`]).
    fn estimate_index(&self, from: usize, to: usize, value: f64) -> usize {
        let (first, last) = (self.cum[from], self.cum[to - 1]);
        let mean = (last - first) / (to - from) as f64;
        let offset = (value - first) / mean;
        if offset.is_finite() && offset > 0.0 {
            from + offset.min((to - from) as f64) as usize
        } else {
            from
        }
    }
}

/// First index in `from..to` whose value fails `pred` (or `to`), for a `pred`
/// that holds on a prefix of `values[from..to]`: galloping from `guess`, so
/// the cost is logarithmic in the distance between `guess` and the answer.
fn partition_from(
    values: &[f64],
    from: usize,
    to: usize,
    guess: usize,
    pred: impl Fn(f64) -> bool,
) -> usize {
    if from >= to {
        return to;
    }
    let g = guess.clamp(from, to - 1);
    let (mut lo, mut hi) = (from, g);
    let mut step = 1;
    if pred(values[g]) {
        (lo, hi) = (g + 1, to);
        while g + step < to {
            if !pred(values[g + step]) {
                hi = g + step;
                break;
            }
            lo = g + step + 1;
            step *= 2;
        }
    } else {
        while g >= from + step {
            if pred(values[g - step]) {
                lo = g - step + 1;
                break;
            }
            hi = g - step;
            step *= 2;
        }
    }
    lo + values[lo..hi].partition_point(|&v| pred(v))
}

/// Closest point on segment `seg` (from `pts[seg]` to `pts[seg + 1]`).
#[derive(Clone, Copy, Debug)]
struct Nearest {
    dist: f64,
    seg: usize,
    /// Fraction along the segment, in [0, 1].
    t: f64,
}

fn project_on_segment(pts: &[Point3<f64>], seg: usize, x: &Point3<f64>) -> Nearest {
    let a = pts[seg];
    let ab = pts[seg + 1] - a;
    let len_sq = ab.norm_squared();
    let t = if len_sq > MIN_SEGMENT_LENGTH_SQ_MM2 {
        ((x - a).dot(&ab) / len_sq).clamp(0.0, 1.0)
    } else {
        0.0
    };
    Nearest {
        dist: (x - (a + ab * t)).norm(),
        seg,
        t,
    }
}

/// Exact nearest point of `x` on the polyline range, starting at segment
/// `guess`. Segments are skipped using the bound `|x - X| >= d - (arc length
/// between X and the last visited closest point)`, and whole tails are cut by
/// the chord-direction bounds, so a query costs O(1) on well-behaved paths
/// and O(log n) hops at worst on nearly any path.
fn nearest_on_polyline(poly: Polyline<'_>, x: &Point3<f64>, guess: usize) -> Nearest {
    let xu = poly.bounds.coordinate(x);
    let first = project_on_segment(poly.pts, guess.clamp(poly.lo, poly.hi - 1), x);
    let best = scan_forward(poly, x, xu, first, first);
    scan_backward(poly, x, xu, first, best)
}

fn scan_forward(
    poly: Polyline<'_>,
    x: &Point3<f64>,
    xu: f64,
    mut current: Nearest,
    mut best: Nearest,
) -> Nearest {
    loop {
        let g = current.seg;
        if g + 1 >= poly.hi || poly.bounds.ahead(xu, g + 1) >= best.dist {
            return best;
        }
        // Segment g' > g cannot beat `best` while cum[g' + 1] <= thresh.
        let thresh = poly.cum[g] + (current.dist - best.dist) - SKIP_SLACK_MM;
        let (from, to) = (g + 2, poly.hi + 1);
        let guess = poly.estimate_index(from, to, thresh);
        let end = partition_from(poly.cum, from, to, guess, |c| c <= thresh);
        if end == to || poly.bounds.ahead(xu, end - 1) >= best.dist {
            return best;
        }
        current = project_on_segment(poly.pts, end - 1, x);
        if current.dist < best.dist {
            best = current;
        }
    }
}

fn scan_backward(
    poly: Polyline<'_>,
    x: &Point3<f64>,
    xu: f64,
    mut current: Nearest,
    mut best: Nearest,
) -> Nearest {
    loop {
        let g = current.seg;
        if g <= poly.lo || poly.bounds.behind(xu, g - 1) >= best.dist {
            return best;
        }
        // Segment g' < g cannot beat `best` while cum[g'] >= thresh.
        let thresh = poly.cum[g + 1] - (current.dist - best.dist) + SKIP_SLACK_MM;
        let guess = poly.estimate_index(poly.lo, g, thresh);
        let end = partition_from(poly.cum, poly.lo, g, guess, |c| c < thresh);
        if end == poly.lo || poly.bounds.behind(xu, end - 1) >= best.dist {
            return best;
        }
        current = project_on_segment(poly.pts, end - 1, x);
        if current.dist < best.dist {
            best = current;
        }
    }
}

/// Densely sampled part-frame curve of one move.
#[derive(Default)]
struct Samples {
    s: Vec<f64>,
    p: Vec<Point3<f64>>,
    a: Vec<Vector3<f64>>,
    /// Cumulative chord length through the samples, mm.
    cum: Vec<f64>,
}

impl Samples {
    fn clear(&mut self) {
        self.s.clear();
        self.p.clear();
        self.a.clear();
        self.cum.clear();
    }

    fn push(&mut self, s: f64, p: Point3<f64>, a: Vector3<f64>) {
        let step = self.p.last().map_or(0.0, |last| (p - last).norm());
        let total = self.cum.last().copied().unwrap_or(0.0) + step;
        self.s.push(s);
        self.p.push(p);
        self.a.push(a);
        self.cum.push(total);
    }

    /// Largest gap between consecutive samples relative to the wanted steps.
    fn max_gap_ratio(&self, step_mm: f64) -> f64 {
        let gaps = self.p.windows(2).zip(self.a.windows(2));
        gaps.map(|(p, a)| {
            let by_length = (p[1] - p[0]).norm() / step_mm;
            by_length.max((a[1] - a[0]).norm() / deg_to_chord(ORIENTATION_SAMPLE_STEP_DEG))
        })
        .fold(0.0, f64::max)
    }

    fn polyline<'a>(&'a self, bounds: &'a ChordBounds) -> Polyline<'a> {
        Polyline {
            pts: &self.p,
            cum: &self.cum,
            lo: 0,
            hi: self.p.len() - 1,
            bounds,
        }
    }
}

#[derive(Clone, Copy, PartialEq, Eq)]
enum Kind {
    Linear = 0,
    Circular = 1,
}

/// Evaluates candidate moves of one bead against the planned path.
struct Checker<'a, F> {
    poses: &'a [ControllerPose],
    planned: &'a Planned,
    map: &'a F,
    opts: &'a CompressOptions,
    limits: Limits,
    /// Added to local indices in error values.
    index_offset: usize,
    scratch: ControllerPose,
    samples: Samples,
    sample_bounds: ChordBounds,
    planned_bounds: ChordBounds,
    /// Span of the last acceptable move of each [`Kind`], a search start.
    last_span: [usize; 2],
    /// Cumulative controller travel (mm) and turning (rad) from the first
    /// pose, for [`CompressOptions::rotation_tolerance_deg`] (empty without).
    controller_cum: (Vec<f64>, Vec<f64>),
}

impl<'a, F> Checker<'a, F>
where
    F: Fn(&ControllerPose) -> (Point3<f64>, Vector3<f64>),
{
    fn new(
        poses: &'a [ControllerPose],
        planned: &'a Planned,
        map: &'a F,
        opts: &'a CompressOptions,
        index_offset: usize,
    ) -> Self {
        Self {
            poses,
            planned,
            map,
            opts,
            limits: Limits::new(opts),
            index_offset,
            scratch: poses[0].clone(),
            samples: Samples::default(),
            sample_bounds: ChordBounds::default(),
            planned_bounds: ChordBounds::default(),
            last_span: [1; 2],
            controller_cum: match opts.rotation_tolerance_deg {
                Some(_) => (
                    cumulative(poses.windows(2).map(|w| (w[1].p - w[0].p).norm())),
                    cumulative(poses.windows(2).map(|w| w[0].q.angle_to(&w[1].q))),
                ),
                None => (Vec::new(), Vec::new()),
            },
        }
    }

    /// The longest acceptable move from `i` ending at most at `limit`.
    fn best_move(&mut self, i: usize, limit: usize) -> Result<(Move, Deviation), CompressError> {
        let linear = self.farthest(i, limit, Kind::Linear)?.unwrap_or(i + 1);
        let circular = if self.opts.allow_circular && linear < limit {
            self.farthest(i, limit, Kind::Circular)?
        } else {
            None
        };
        // a circular move writes two positions (via and end): it must reach
        // farther than two linear moves would
        let mv = match circular.map(|j| (j, self.circular_via(i, j))) {
            Some((to, Some(via)))
                if to > linear && to > self.two_linear_reach(linear, limit)? =>
            {
                Move::Circular { via, to }
            }
            _ => Move::Linear { to: linear },
        };
        let dev = self.evaluate(i, mv.to(), mv.via())?;
        Ok((mv, dev))
    }

    /// Where a second linear move from `linear` (ending at most at `limit`)
    /// reaches: what two linear moves from the same start cover.
    fn two_linear_reach(&mut self, linear: usize, limit: usize) -> Result<usize, CompressError> {
        Ok(self
            .farthest(linear, limit, Kind::Linear)?
            .unwrap_or(linear))
    }

    /// Farthest acceptable end of a `kind` move from `i`: a galloping search
    /// from the span last found for this kind, then bisection; every returned
    /// end was checked. A linear move to `i + 1` is returned even if it fails
    /// the tolerances.
    fn farthest(
        &mut self,
        i: usize,
        limit: usize,
        kind: Kind,
    ) -> Result<Option<usize>, CompressError> {
        let first = i + if kind == Kind::Linear { 1 } else { 2 };
        if first > limit {
            return Ok(None);
        }
        if !self.acceptable(i, first, kind)? {
            return Ok((kind == Kind::Linear).then_some(first));
        }
        let guess = self.last_span[kind as usize];
        let (mut good, bad) = self.gallop(i, first, limit, kind, guess)?;
        if let Some(mut bad) = bad {
            while bad - good > 1 {
                let mid = good + (bad - good) / 2;
                if self.acceptable(i, mid, kind)? {
                    good = mid;
                } else {
                    bad = mid;
                }
            }
        }
        self.last_span[kind as usize] = good - i;
        Ok(Some(good))
    }

    /// Brackets the farthest acceptable end: `(good, bad)` with `good`
    /// acceptable and `bad` (if any) not. Probes `i + guess` first (spans of
    /// neighbouring moves are similar), then grows the span by 25 %, 50 %,
    /// 100 %, …; if the first probe fails, tries 3/4 of it once.
    fn gallop(
        &mut self,
        i: usize,
        first: usize,
        limit: usize,
        kind: Kind,
        guess: usize,
    ) -> Result<(usize, Option<usize>), CompressError> {
        let (mut good, mut bad) = (first, None::<usize>);
        let (mut span, mut growth_quarters) = (guess.max(1), 1);
        loop {
            let upper = bad.map_or(limit, |b| b - 1);
            if good >= upper {
                return Ok((good, bad));
            }
            let candidate = i.saturating_add(span).clamp(good + 1, upper);
            if self.acceptable(i, candidate, kind)? {
                good = candidate;
                if bad.is_some() {
                    return Ok((good, bad));
                }
                let reached = good - i;
                span = reached.saturating_add(reached.saturating_mul(growth_quarters).div_ceil(4));
                growth_quarters = growth_quarters.saturating_mul(2);
            } else {
                let retry = bad.is_none() && good == first;
                bad = Some(candidate);
                if !retry {
                    return Ok((good, bad));
                }
                span = (candidate - i) * 3 / 4;
            }
        }
    }

    fn acceptable(&mut self, i: usize, j: usize, kind: Kind) -> Result<bool, CompressError> {
        let via = match kind {
            Kind::Linear => None,
            Kind::Circular => match self.circular_via(i, j) {
                Some(v) => Some(v),
                None => return Ok(false),
            },
        };
        if !self.rotation_follows(i, j) {
            return Ok(false);
        }
        let worst = self.measure(i, j, via, true)?;
        Ok(self.limits.admit(&worst))
    }

    /// `true` when every planned orientation between `i` and `j` is within
    /// [`CompressOptions::rotation_tolerance_deg`] of the move's slerp
    /// (always without that option).
    fn rotation_follows(&self, i: usize, j: usize) -> bool {
        let Some(tol) = self.opts.rotation_tolerance_deg else {
            return true;
        };
        let poses = self.poses;
        let (cl, ct) = &self.controller_cum;
        let (len, turn) = (cl[j] - cl[i], ct[j] - ct[i]);
        // The controller moves position and orientation on one time
        // fraction; a planned pose is reached at the fraction its position
        // gives, or (where the tool centre barely moves, e.g. the flange of
        // a part turned about J6 under a fixed torch, whose path length is
        // rounding noise) the fraction its turning gives: either will do.
        let follows = |k: usize, s: f64| {
            let expected = poses[i].q.slerp(&poses[j].q, s);
            expected.angle_to(&poses[k].q).to_degrees() <= tol
        };
        ((i + 1)..j).all(|k| {
            let by_length = len > f64::EPSILON && follows(k, (cl[k] - cl[i]) / len);
            let by_turn = turn > 0.0 && follows(k, (ct[k] - ct[i]) / turn);
            by_length || by_turn || (len <= f64::EPSILON && turn <= 0.0 && follows(k, 0.0))
        })
    }

    /// The via for a circular move `i -> j`, if that arc is allowed.
    fn circular_via(&self, i: usize, j: usize) -> Option<usize> {
        if j < i + 2 {
            return None;
        }
        let via = self.pick_via(i, j);
        let p = |k: usize| &self.poses[k].p;
        circular_move_allowed(p(i), p(via), p(j), self.opts).then_some(via)
    }

    /// Planned point strictly between `i` and `j` nearest the middle of the
    /// controller-frame path length (index middle if that length is zero).
    fn pick_via(&self, i: usize, j: usize) -> usize {
        let cum = &self.planned.ctrl_cum;
        if cum[j] - cum[i] <= MIN_CONTROLLER_LENGTH_MM {
            return i + (j - i) / 2;
        }
        let target = 0.5 * (cum[i] + cum[j]);
        let k = i + 1 + cum[i + 1..j].partition_point(|&c| c < target);
        let before = k - 1;
        if k >= j || (before > i && target - cum[before] <= cum[k] - target) {
            before
        } else {
            k
        }
    }

    /// Deviation of the move `i -> j` (via `via`) from the planned path.
    fn evaluate(
        &mut self,
        i: usize,
        j: usize,
        via: Option<usize>,
    ) -> Result<Deviation, CompressError> {
        Ok(self.measure(i, j, via, false)?.deviation())
    }

    /// Worst errors of the move `i -> j`; with `early_exit` it stops as soon
    /// as a tolerance is exceeded (the result then only shows that).
    fn measure(
        &mut self,
        i: usize,
        j: usize,
        via: Option<usize>,
        early_exit: bool,
    ) -> Result<Worst, CompressError> {
        let poses = self.poses;
        let path = MovePath::new(&poses[i], via.map(|v| &poses[v].p), &poses[j]);
        self.sample(&path, i, j)?;
        let mut worst = Worst::default();
        self.check_points(&path, i, j, early_exit, &mut worst)?;
        if !early_exit || self.limits.admit(&worst) {
            self.check_samples(i, j, early_exit, &mut worst);
        }
        Ok(worst)
    }

    /// Part-frame point and unit axis of the curve at `s`.
    fn eval_curve(
        &mut self,
        path: &MovePath<'_>,
        s: f64,
        start: usize,
    ) -> Result<(Point3<f64>, Vector3<f64>), CompressError> {
        path.pose_into(s, &mut self.scratch);
        let (p, a) = (self.map)(&self.scratch);
        checked_output(p, a).ok_or(CompressError::InvalidMapOutput {
            index: self.index_offset + start,
        })
    }

    fn sample(&mut self, path: &MovePath<'_>, i: usize, j: usize) -> Result<(), CompressError> {
        let planned = self.planned;
        let length = planned.cum[j] - planned.cum[i];
        let turning = planned.ang_cum[j] - planned.ang_cum[i];
        let wanted = (length / self.opts.sample_step_mm).max(turning / ORIENTATION_SAMPLE_STEP_DEG);
        let count = self.sample_count(wanted);
        self.fill_samples(path, i, count)?;
        let ratio = self.samples.max_gap_ratio(self.opts.sample_step_mm);
        if ratio > SAMPLE_GAP_SLACK && count < MAX_SAMPLES_PER_MOVE {
            let denser = self.sample_count(count as f64 * ratio);
            self.fill_samples(path, i, denser)?;
        }
        Ok(())
    }

    fn sample_count(&self, wanted: f64) -> usize {
        let wanted = (wanted - SAMPLE_COUNT_ROUNDING).ceil();
        let count = if wanted.is_finite() && wanted > 0.0 {
            wanted.min(MAX_SAMPLES_PER_MOVE as f64) as usize
        } else if wanted > 0.0 {
            MAX_SAMPLES_PER_MOVE
        } else {
            0
        };
        count.clamp(self.opts.min_samples_per_move, MAX_SAMPLES_PER_MOVE)
    }

    fn fill_samples(
        &mut self,
        path: &MovePath<'_>,
        start: usize,
        count: usize,
    ) -> Result<(), CompressError> {
        self.samples.clear();
        for m in 0..=count {
            let s = m as f64 / count as f64;
            let (p, a) = self.eval_curve(path, s, start)?;
            self.samples.push(s, p, a);
        }
        Ok(())
    }

    /// Check 1: planned points strictly inside the move against the curve.
    fn check_points(
        &mut self,
        path: &MovePath<'_>,
        i: usize,
        j: usize,
        early_exit: bool,
        worst: &mut Worst,
    ) -> Result<(), CompressError> {
        let planned = self.planned;
        let last = self.samples.p.len() - 1;
        self.sample_bounds.rebuild(&self.samples.p, 0, last);
        let mut guess = 0;
        for k in (i + 1)..j {
            let target = planned.pts[k];
            let poly = self.samples.polyline(&self.sample_bounds);
            let near = nearest_on_polyline(poly, &target, guess);
            guess = near.seg;
            let (dist, axis) = self.closest_on_curve(path, &near, &target, i)?;
            worst.include(dist, &axis, &planned.axes[k]);
            if early_exit && !self.limits.admit(worst) {
                break;
            }
        }
        Ok(())
    }

    /// Distance and axis at the curve parameter closest to `target`: the
    /// projection on the sample chords mapped back onto the curve, refined by
    /// golden-section search only when that is out of tolerance.
    fn closest_on_curve(
        &mut self,
        path: &MovePath<'_>,
        near: &Nearest,
        target: &Point3<f64>,
        start: usize,
    ) -> Result<(f64, Vector3<f64>), CompressError> {
        let g = near.seg;
        let last = self.samples.s.len() - 1;
        let s = &self.samples.s;
        let chord_s = s[g] + near.t * (s[g + 1] - s[g]);
        let bracket = (s[g.saturating_sub(1)], s[(g + 2).min(last)]);
        let mut best = ((self.samples.p[g] - target).norm(), self.samples.a[g]);
        let end = (
            (self.samples.p[g + 1] - target).norm(),
            self.samples.a[g + 1],
        );
        if end.0 < best.0 {
            best = end;
        }
        let (p, a) = self.eval_curve(path, chord_s, start)?;
        if (p - target).norm() < best.0 {
            best = ((p - target).norm(), a);
        }
        if best.0 > self.opts.path_tolerance_mm {
            let s_min = self.golden_section(path, bracket, target, start)?;
            let (p, a) = self.eval_curve(path, s_min, start)?;
            if (p - target).norm() < best.0 {
                best = ((p - target).norm(), a);
            }
        }
        Ok(best)
    }

    /// Parameter in `bracket` minimising the distance of the curve to `target`.
    fn golden_section(
        &mut self,
        path: &MovePath<'_>,
        bracket: (f64, f64),
        target: &Point3<f64>,
        start: usize,
    ) -> Result<f64, CompressError> {
        let inv_phi = (5f64.sqrt() - 1.0) / 2.0;
        let (mut lo, mut hi) = bracket;
        let mut c = hi - inv_phi * (hi - lo);
        let mut d = lo + inv_phi * (hi - lo);
        let mut fc = (self.eval_curve(path, c, start)?.0 - target).norm();
        let mut fd = (self.eval_curve(path, d, start)?.0 - target).norm();
        for _ in 0..GOLDEN_ITERATIONS {
            if fc < fd {
                (hi, d, fd) = (d, c, fc);
                c = hi - inv_phi * (hi - lo);
                fc = (self.eval_curve(path, c, start)?.0 - target).norm();
            } else {
                (lo, c, fc) = (c, d, fd);
                d = lo + inv_phi * (hi - lo);
                fd = (self.eval_curve(path, d, start)?.0 - target).norm();
            }
        }
        Ok(if fc < fd { c } else { d })
    }

    /// Check 2: curve samples against the planned polyline `i..=j`.
    fn check_samples(&mut self, i: usize, j: usize, early_exit: bool, worst: &mut Worst) {
        let planned = self.planned;
        self.planned_bounds.rebuild(&planned.pts, i, j);
        let poly = Polyline {
            pts: &planned.pts,
            cum: &planned.cum,
            lo: i,
            hi: j,
            bounds: &self.planned_bounds,
        };
        let mut guess = i;
        for (x, axis) in self.samples.p.iter().zip(&self.samples.a) {
            let near = nearest_on_polyline(poly, x, guess);
            guess = near.seg;
            let g = near.seg;
            let planned_axis = nlerp(&planned.axes[g], &planned.axes[g + 1], near.t);
            worst.include(near.dist, axis, &planned_axis);
            if early_exit && !self.limits.admit(worst) {
                return;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::UnitQuaternion;
    use std::f64::consts::PI;
    use std::f64::consts::TAU;
    use std::time::Instant;

    const TOL_MM: f64 = DEFAULT_PATH_TOLERANCE_MM;
    const TOL_DEG: f64 = DEFAULT_ORIENTATION_TOLERANCE_DEG;
    /// Allowance for the tests' own sampling of closed-form curves.
    const CHECK_SLACK_MM: f64 = 1e-3;

    fn pose(x: f64, y: f64, z: f64) -> ControllerPose {
        ControllerPose::new(Point3::new(x, y, z), UnitQuaternion::identity(), vec![])
    }

    fn defaults() -> CompressOptions {
        CompressOptions::default()
    }

    /// Points on a circle of radius `r` about the origin in the XY plane.
    fn circle_poses(r: f64, per_turn: usize, count: usize) -> Vec<ControllerPose> {
        (0..count)
            .map(|k| {
                let t = TAU * k as f64 / per_turn as f64;
                pose(r * t.cos(), r * t.sin(), 0.0)
            })
            .collect()
    }

    /// Deterministic xorshift generator for noise.
    struct Rng(u64);

    impl Rng {
        fn uniform(&mut self, lo: f64, hi: f64) -> f64 {
            self.0 ^= self.0 << 13;
            self.0 ^= self.0 >> 7;
            self.0 ^= self.0 << 17;
            lo + (hi - lo) * (self.0 >> 11) as f64 / (1u64 << 53) as f64
        }
    }

    /// Independent distance from `x` to a polyline (brute force).
    fn dist_to_polyline(poly: &[Point3<f64>], x: &Point3<f64>) -> f64 {
        if poly.len() == 1 {
            return (x - poly[0]).norm();
        }
        poly.windows(2)
            .map(|w| {
                let d = w[1] - w[0];
                let l2 = d.dot(&d);
                let t = if l2 > 0.0 {
                    ((x - w[0]).dot(&d) / l2).clamp(0.0, 1.0)
                } else {
                    0.0
                };
                (x - (w[0] + d * t)).norm()
            })
            .fold(f64::INFINITY, f64::min)
    }

    /// Both-way check of a densely sampled curve against planned points.
    fn assert_curve_matches(curve: &[Point3<f64>], planned: &[Point3<f64>], what: &str) {
        for (k, x) in planned.iter().enumerate() {
            let d = dist_to_polyline(curve, x);
            assert!(
                d <= TOL_MM + CHECK_SLACK_MM,
                "{what}: planned {k} is {d} mm off"
            );
        }
        for x in curve {
            let d = dist_to_polyline(planned, x);
            assert!(
                d <= TOL_MM + CHECK_SLACK_MM,
                "{what}: curve point {x} is {d} mm off"
            );
        }
    }

    /// Start index of each move.
    fn starts(c: &Compressed) -> Vec<usize> {
        std::iter::once(0)
            .chain(c.moves.iter().map(Move::to))
            .collect()
    }

    fn max_span(c: &Compressed) -> usize {
        let s = starts(c);
        s.windows(2).map(|w| w[1] - w[0]).max().unwrap_or(0)
    }

    #[test]
    fn collinear_points_give_one_linear_move() {
        let poses: Vec<_> = (0..200).map(|k| pose(k as f64 * 0.7, 2.0, 1.0)).collect();
        let c = compress(&poses, &[], &tool_z_map, &defaults()).expect("valid");
        assert_eq!(c.moves, vec![Move::Linear { to: 199 }]);
        assert!(c.max_path_error_mm < 1e-9 && c.max_orientation_error_deg < 1e-9);
    }

    #[test]
    fn circle_gives_few_arcs_that_stay_on_the_circle() {
        let (r, per_turn) = (40.0, 400);
        let poses = circle_poses(r, per_turn, per_turn + per_turn / 10 + 1);
        let c = compress(&poses, &[], &tool_z_map, &defaults()).expect("valid");
        assert!(c.moves.len() <= 4, "{:?}", c.moves);
        assert!(c.max_path_error_mm <= TOL_MM);
        let dt = TAU / per_turn as f64;
        for (start, mv) in starts(&c).into_iter().zip(&c.moves) {
            let (a, b) = (start as f64 * dt, mv.to() as f64 * dt);
            let n = 4000;
            let curve: Vec<_> = match mv {
                Move::Circular { via, .. } => {
                    assert!(start < *via && *via < mv.to());
                    (0..=n)
                        .map(|m| {
                            let t = a + (b - a) * m as f64 / n as f64;
                            Point3::new(r * t.cos(), r * t.sin(), 0.0)
                        })
                        .collect()
                }
                Move::Linear { to } => vec![poses[start].p, poses[*to].p],
            };
            let planned: Vec<_> = poses[start..=mv.to()].iter().map(|p| p.p).collect();
            assert_curve_matches(&curve, &planned, "circle move");
        }
    }

    #[test]
    fn circle_without_arcs_needs_about_the_chord_count() {
        let (r, per_turn) = (40.0, 400);
        let count = per_turn + per_turn / 10 + 1;
        let poses = circle_poses(r, per_turn, count);
        let opts = CompressOptions {
            allow_circular: false,
            ..defaults()
        };
        let c = compress(&poses, &[], &tool_z_map, &opts).expect("valid");
        assert!(c.moves.iter().all(|m| matches!(m, Move::Linear { .. })));
        let chord_angle = 2.0 * (1.0 - TOL_MM / r).acos();
        let expected = TAU * (count - 1) as f64 / per_turn as f64 / chord_angle;
        let got = c.moves.len() as f64;
        assert!(
            (got - expected).abs() <= 0.25 * expected,
            "{got} vs {expected}"
        );
        for (start, mv) in starts(&c).into_iter().zip(&c.moves) {
            let planned: Vec<_> = poses[start..=mv.to()].iter().map(|p| p.p).collect();
            assert_curve_matches(&[poses[start].p, poses[mv.to()].p], &planned, "chord");
        }
    }

    /// Helix-like path whose torch axis tilts about X by 1° per point, up and
    /// down in ramps of `ramp` points (a triangle wave).
    fn twisting_helix(count: usize, ramp: usize) -> (Vec<ControllerPose>, Vec<f64>) {
        let (radius, step) = (300.0, 0.5);
        let mut theta = Vec::with_capacity(count);
        let poses = (0..count)
            .map(|k| {
                let phase = k % (2 * ramp);
                let deg = ramp as f64 - (phase as f64 - ramp as f64).abs();
                theta.push(deg);
                let t = k as f64 * step / radius;
                let q = UnitQuaternion::from_axis_angle(&Vector3::x_axis(), deg.to_radians());
                let p = Point3::new(radius * t.cos(), radius * t.sin(), 0.01 * k as f64);
                ControllerPose::new(p, q, vec![])
            })
            .collect();
        (poses, theta)
    }

    /// Lower bound (degrees) of the orientation error of move i -> j for any
    /// interpolation that turns at constant rate along the shortest rotation:
    /// the model axis at s is within s·Θ of axis i and (1-s)·Θ of axis j, so
    /// for each interior k, err >= (∠(k,i) + ∠(k,j) - Θ) / 2.
    fn orientation_lower_bound(poses: &[ControllerPose], i: usize, j: usize) -> f64 {
        let axis = |k: usize| poses[k].q * Vector3::z();
        let theta = poses[i].q.angle_to(&poses[j].q).to_degrees();
        ((i + 1)..j)
            .map(|k| (axis(k).angle(&axis(i)) + axis(k).angle(&axis(j))).to_degrees())
            .map(|sum| (sum - theta) / 2.0)
            .fold(0.0, f64::max)
    }

    #[test]
    fn twisting_orientation_binds_the_span() {
        // At a reversal k (peak or trough of the wave) between ramps, any move
        // i -> j with i, j on the two adjacent ramps has the lower bound
        // |θ_k - θ_nearer end| >= 1° > 0.5°: every reversal must be a target,
        // so no move spans more than one ramp (`ramp` points). With ramp = 1
        // (0°,1°,0°,1°…) this is the bound 0.5°/1° + 1 => every point is kept.
        for ramp in [1, 10] {
            let (poses, _) = twisting_helix(401, ramp);
            let c = compress(&poses, &[], &tool_z_map, &defaults()).expect("valid");
            let targets = starts(&c);
            for k in (ramp..poses.len() - 1).step_by(ramp) {
                assert!(
                    targets.contains(&k),
                    "ramp {ramp}: reversal {k} not a target"
                );
            }
            assert!(max_span(&c) <= ramp, "ramp {ramp}: span {}", max_span(&c));
            assert!(c.max_orientation_error_deg <= TOL_DEG);
            for w in targets.windows(2) {
                let lb = orientation_lower_bound(&poses, w[0], w[1]);
                assert!(lb <= TOL_DEG + 1e-9, "move {w:?} bound {lb}");
            }
            if ramp == 1 {
                assert_eq!(c.moves.len(), poses.len() - 1);
            }
            let loose = CompressOptions {
                orientation_tolerance_deg: 45.0,
                ..defaults()
            };
            let l = compress(&poses, &[], &tool_z_map, &loose).expect("valid");
            assert!(
                2 * l.moves.len() < c.moves.len(),
                "{} vs {}",
                l.moves.len(),
                c.moves.len()
            );
        }
    }

    #[test]
    fn both_checks_are_needed() {
        // Check 2: three points 60° apart on a circle of radius 40. The arc
        // through them passes every planned point exactly, but bulges about
        // 5.4 mm away from the planned polyline (the chords).
        let sparse = circle_poses(40.0, 6, 3);
        let c = compress(&sparse, &[], &tool_z_map, &defaults()).expect("valid");
        assert_eq!(
            c.moves,
            vec![Move::Linear { to: 1 }, Move::Linear { to: 2 }]
        );
        let arc = Move::Circular { via: 1, to: 2 };
        let d = move_deviation(&sparse, 0, arc, &tool_z_map, &defaults()).expect("valid");
        let bulge = 40.0 * (1.0 - (PI / 6.0).cos());
        assert!((d.path_error_mm - bulge).abs() < 0.01, "{d:?} vs {bulge}");
        // Check 1: a there-and-back spike of 1 mm at x = 10 mm. The straight
        // line stays on the planned polyline, but misses the spike's tip.
        let mut spike: Vec<_> = (0..=20).map(|k| pose(k as f64, 0.0, 0.0)).collect();
        spike.insert(11, pose(10.0, 1.0, 0.0));
        spike.insert(12, pose(10.0, 0.0, 0.0));
        let c = compress(&spike, &[], &tool_z_map, &defaults()).expect("valid");
        assert!(starts(&c).contains(&11), "{:?}", c.moves);
        let whole = Move::Linear {
            to: spike.len() - 1,
        };
        let d = move_deviation(&spike, 0, whole, &tool_z_map, &defaults()).expect("valid");
        assert!((d.path_error_mm - 1.0).abs() < 1e-9, "{d:?}");
    }

    fn noisy_line(amplitude: f64, seed: u64) -> Vec<ControllerPose> {
        let mut rng = Rng(seed);
        (0..300)
            .map(|k| {
                let y = rng.uniform(-amplitude, amplitude);
                let z = rng.uniform(-amplitude, amplitude);
                pose(k as f64, y, z)
            })
            .collect()
    }

    #[test]
    fn small_noise_compresses_large_noise_does_not() {
        let quiet = noisy_line(0.01, 0x9e37_79b9_7f4a_7c15);
        let c = compress(&quiet, &[], &tool_z_map, &defaults()).expect("valid");
        assert!(c.moves.len() <= 3, "{} moves", c.moves.len());
        let loud = noisy_line(0.2, 0x9e37_79b9_7f4a_7c15);
        let c = compress(&loud, &[], &tool_z_map, &defaults()).expect("valid");
        let programmed = c.programmed_indices().len();
        assert!(
            programmed * 10 >= loud.len() * 9,
            "{programmed} of {}",
            loud.len()
        );
        assert!(c.max_path_error_mm <= TOL_MM);
    }

    #[test]
    fn must_keep_points_are_targets() {
        let line: Vec<_> = (0..100).map(|k| pose(k as f64, 0.0, 0.0)).collect();
        let mut keep = vec![false; line.len()];
        keep[30] = true;
        keep[70] = true;
        let c = compress(&line, &keep, &tool_z_map, &defaults()).expect("valid");
        let want = [30, 70, 99].map(|to| Move::Linear { to });
        assert_eq!(c.moves, want);
        let circle = circle_poses(40.0, 400, 401);
        let mut keep = vec![false; circle.len()];
        for k in [57, 58, 200, 333] {
            keep[k] = true;
        }
        let c = compress(&circle, &keep, &tool_z_map, &defaults()).expect("valid");
        let targets = starts(&c);
        assert!(
            [57, 58, 200, 333].iter().all(|k| targets.contains(k)),
            "{targets:?}"
        );
    }

    #[test]
    fn one_and_two_point_beads() {
        let one = [pose(1.0, 2.0, 3.0)];
        let c = compress(&one, &[], &tool_z_map, &defaults()).expect("valid");
        assert!(c.moves.is_empty());
        assert_eq!(c.programmed_indices(), vec![0]);
        let two = [pose(0.0, 0.0, 0.0), pose(5.0, 0.0, 0.0)];
        let c = compress(&two, &[true, true], &tool_z_map, &defaults()).expect("valid");
        assert_eq!(c.moves, vec![Move::Linear { to: 1 }]);
        assert_eq!(
            compress(&[], &[], &tool_z_map, &defaults()),
            Err(CompressError::EmptyBead)
        );
    }

    #[test]
    fn duplicate_points_are_handled() {
        let xs = [0.0, 0.0, 0.0, 1.0, 1.0, 2.0, 2.0, 2.0];
        let poses: Vec<_> = xs.iter().map(|&x| pose(x, 0.0, 0.0)).collect();
        let c = compress(&poses, &[], &tool_z_map, &defaults()).expect("valid");
        assert_eq!(c.moves, vec![Move::Linear { to: 7 }]);
        let same = vec![pose(3.0, 3.0, 3.0); 6];
        let c = compress(&same, &[], &tool_z_map, &defaults()).expect("valid");
        assert_eq!(c.moves, vec![Move::Linear { to: 5 }]);
        assert_eq!(c.max_path_error_mm, 0.0);
        let mut corner = vec![pose(0.0, 0.0, 0.0); 3];
        corner.extend(vec![pose(10.0, 0.0, 0.0); 3]);
        corner.extend(vec![pose(10.0, 10.0, 0.0); 3]);
        let c = compress(&corner, &[], &tool_z_map, &defaults()).expect("valid");
        assert!(
            starts(&c).contains(&3) || starts(&c).contains(&5),
            "{:?}",
            c.moves
        );
        assert!(c.max_path_error_mm <= TOL_MM);
    }

    #[test]
    fn invalid_input_is_an_error() {
        let good: Vec<_> = (0..5).map(|k| pose(k as f64, 0.0, 0.0)).collect();
        let run = |poses: &[ControllerPose]| compress(poses, &[], &tool_z_map, &defaults());
        let mut bad = good.clone();
        bad[2].p.y = f64::NAN;
        assert!(matches!(
            run(&bad),
            Err(CompressError::InvalidPose { index: 2, .. })
        ));
        let mut bad = good.clone();
        let nan = nalgebra::Quaternion::new(f64::NAN, 0.0, 0.0, 0.0);
        bad[1].q = UnitQuaternion::new_unchecked(nan);
        assert!(matches!(
            run(&bad),
            Err(CompressError::InvalidPose { index: 1, .. })
        ));
        let mut bad: Vec<_> = good
            .iter()
            .map(|p| ControllerPose {
                ext: vec![0.0],
                ..p.clone()
            })
            .collect();
        bad[3].ext = vec![0.0, 1.0];
        assert!(matches!(
            run(&bad),
            Err(CompressError::ExtLengthMismatch { index: 3, .. })
        ));
        bad[3].ext = vec![f64::INFINITY];
        assert!(matches!(
            run(&bad),
            Err(CompressError::InvalidPose { index: 3, .. })
        ));
        let nan_map = |p: &ControllerPose| (Point3::new(f64::NAN, 0.0, 0.0), p.q * Vector3::z());
        let r = compress(&good, &[], &nan_map, &defaults());
        assert_eq!(r, Err(CompressError::InvalidMapOutput { index: 0 }));
        let r = compress(&good, &[true], &tool_z_map, &defaults());
        assert!(matches!(
            r,
            Err(CompressError::KeepLengthMismatch {
                expected: 5,
                found: 1
            })
        ));
    }

    #[test]
    fn invalid_options_name_the_field() {
        let cases: [(&str, CompressOptions); 6] = [
            (
                "path_tolerance_mm",
                CompressOptions {
                    path_tolerance_mm: 0.0,
                    ..defaults()
                },
            ),
            (
                "orientation_tolerance_deg",
                CompressOptions {
                    orientation_tolerance_deg: f64::NAN,
                    ..defaults()
                },
            ),
            (
                "sample_step_mm",
                CompressOptions {
                    sample_step_mm: -1.0,
                    ..defaults()
                },
            ),
            (
                "min_samples_per_move",
                CompressOptions {
                    min_samples_per_move: 1,
                    ..defaults()
                },
            ),
            (
                "max_radius_mm",
                CompressOptions {
                    max_radius_mm: f64::INFINITY,
                    ..defaults()
                },
            ),
            (
                "max_points_per_move",
                CompressOptions {
                    max_points_per_move: Some(0),
                    ..defaults()
                },
            ),
        ];
        let poses = [pose(0.0, 0.0, 0.0), pose(1.0, 0.0, 0.0)];
        for (name, opts) in cases {
            let err = compress(&poses, &[], &tool_z_map, &opts).expect_err(name);
            assert!(matches!(err, CompressError::InvalidOption { field, .. } if field == name));
            assert!(err.to_string().contains(name));
        }
        assert_eq!(defaults().validate(), Ok(()));
    }

    #[test]
    fn max_points_per_move_limits_the_span() {
        let poses: Vec<_> = (0..50).map(|k| pose(k as f64, 0.0, 0.0)).collect();
        let opts = CompressOptions {
            max_points_per_move: Some(7),
            ..defaults()
        };
        let c = compress(&poses, &[], &tool_z_map, &opts).expect("valid");
        assert_eq!(max_span(&c), 7);
        assert_eq!(c.moves.len(), 7);
    }

    /// Positioner turning the part about Z by `ext[0]`: part point Rz(-ext)·p.
    fn turntable_map(pose: &ControllerPose) -> (Point3<f64>, Vector3<f64>) {
        let rz = UnitQuaternion::from_axis_angle(&Vector3::z_axis(), -pose.ext[0]);
        (rz * pose.p, rz * (pose.q * Vector3::z()))
    }

    /// Own closed form of a linear move in the turntable cell, part frame.
    fn turntable_curve(a: &ControllerPose, b: &ControllerPose) -> Vec<Point3<f64>> {
        let n = 4000;
        (0..=n)
            .map(|m| {
                let s = m as f64 / n as f64;
                let phi = a.ext[0] + s * (b.ext[0] - a.ext[0]);
                let p = a.p + (b.p - a.p) * s;
                Point3::new(
                    phi.cos() * p.x + phi.sin() * p.y,
                    -phi.sin() * p.x + phi.cos() * p.y,
                    p.z,
                )
            })
            .collect()
    }

    fn assert_turntable_moves(poses: &[ControllerPose], c: &Compressed) {
        let part: Vec<_> = poses.iter().map(|p| turntable_map(p).0).collect();
        for (start, mv) in starts(c).into_iter().zip(&c.moves) {
            assert!(mv.via().is_none());
            let curve = turntable_curve(&poses[start], &poses[mv.to()]);
            assert_curve_matches(&curve, &part[start..=mv.to()], "turntable move");
        }
    }

    #[test]
    fn non_identity_map_is_used() {
        // Torch fixed in space, part turning 1.1 turns: the part-frame path is
        // a circle of radius 40 that one ext-linear move reproduces exactly.
        let n = 441;
        let turning: Vec<_> = (0..n)
            .map(|k| {
                let phi = TAU * k as f64 / 400.0;
                ControllerPose::new(
                    Point3::new(40.0, 0.0, 5.0),
                    UnitQuaternion::identity(),
                    vec![phi],
                )
            })
            .collect();
        let c = compress(&turning, &[], &turntable_map, &defaults()).expect("valid");
        assert_eq!(c.moves, vec![Move::Linear { to: n - 1 }]);
        assert_turntable_moves(&turning, &c);
        // Torch moving out 40 -> 50 mm linearly while the part turns with a
        // quadratic schedule: straight in the base frame (one move with the
        // identity map) but a spiral whose radius is not linear in the turn
        // angle in the part frame, so the map forces more moves.
        let spiral: Vec<_> = (0..n)
            .map(|k| {
                let f = k as f64 / (n - 1) as f64;
                let p = Point3::new(40.0 + 10.0 * f, 0.0, 5.0);
                ControllerPose::new(p, UnitQuaternion::identity(), vec![PI * f * f])
            })
            .collect();
        let identity = compress(&spiral, &[], &tool_z_map, &defaults()).expect("valid");
        assert_eq!(identity.moves.len(), 1);
        let c = compress(&spiral, &[], &turntable_map, &defaults()).expect("valid");
        assert!(
            c.moves.len() > 1 && c.moves.len() < n / 10,
            "{} moves",
            c.moves.len()
        );
        assert_turntable_moves(&spiral, &c);
    }

    /// The part held on the flange and turned about the flange axis (J6)
    /// under a fixed torch: the flange's position is constant but for
    /// rounding noise (1e-13 mm, as forward kinematics gives it) while its
    /// orientation turns. The full-rotation check must take each planned
    /// pose's fraction from the turning, not from the noise: one move for
    /// 100° of turn (the torch point on a circle of radius 45 mm).
    #[test]
    fn a_turn_in_place_is_one_move_despite_position_noise() {
        let n = 140;
        let step = 100f64.to_radians() / (n - 1) as f64;
        let poses: Vec<_> = (0..n)
            .map(|k| {
                let noise = if k % 3 == 0 { 1e-13 } else { -2e-13 };
                ControllerPose::new(
                    Point3::new(noise, -noise, 0.5 * noise),
                    UnitQuaternion::from_axis_angle(&Vector3::z_axis(), step * k as f64),
                    vec![],
                )
            })
            .collect();
        // the fixed torch at (45, 0, 0) seen from the turned part
        let map = |pose: &ControllerPose| {
            let inv = pose.q.inverse();
            (inv * Point3::new(45.0, 0.0, 0.0), inv * -Vector3::z())
        };
        let opts = CompressOptions {
            rotation_tolerance_deg: Some(DEFAULT_ORIENTATION_TOLERANCE_DEG),
            ..defaults()
        };
        let c = compress(&poses, &[], &map, &opts).expect("valid");
        assert_eq!(c.moves, vec![Move::Linear { to: n - 1 }]);
        // the move sweeps the radius-45 circle the planned points lie on: the
        // error left is the planned polyline's sagitta, 45 (1 - cos(step/2))
        let sagitta = 45.0 * (1.0 - (0.5 * step).cos());
        assert!(
            (c.max_path_error_mm - sagitta).abs() < 1e-6,
            "{} against {sagitta}",
            c.max_path_error_mm
        );
    }

    #[test]
    fn interpolate_follows_the_controller_model() {
        let ext = |v: f64| vec![v, -v];
        let a = ControllerPose::new(
            Point3::new(40.0, 0.0, 0.0),
            UnitQuaternion::identity(),
            ext(0.0),
        );
        let via = ControllerPose::new(
            Point3::new(0.0, 40.0, 0.0),
            UnitQuaternion::identity(),
            ext(9.0),
        );
        let rz90 = UnitQuaternion::from_axis_angle(&Vector3::z_axis(), PI / 2.0);
        let b = ControllerPose::new(Point3::new(-40.0, 0.0, 0.0), rz90, ext(2.0));
        let mid = interpolate(&a, Some(&via), &b, 0.5);
        assert!((mid.p - Point3::new(0.0, 40.0, 0.0)).norm() < 1e-9);
        let rz45 = UnitQuaternion::from_axis_angle(&Vector3::z_axis(), PI / 4.0);
        assert!(mid.q.angle_to(&rz45) < 1e-9);
        assert!((mid.ext[0] - 1.0).abs() < 1e-12 && (mid.ext[1] + 1.0).abs() < 1e-12);
        let quarter = interpolate(&a, Some(&via), &b, 0.25);
        let c45 = 40.0 * (PI / 4.0).cos();
        assert!((quarter.p - Point3::new(c45, c45, 0.0)).norm() < 1e-9);
        let on_line = ControllerPose {
            p: Point3::new(0.0, 0.0, 0.0),
            ..via.clone()
        };
        let lin = interpolate(&a, Some(&on_line), &b, 0.25);
        assert!((lin.p - Point3::new(20.0, 0.0, 0.0)).norm() < 1e-9);
        assert!((interpolate(&a, None, &b, 1.0).p - b.p).norm() < 1e-12);
    }

    #[test]
    fn move_deviation_reproduces_the_compressor_measure() {
        let (poses, _) = twisting_helix(201, 10);
        let c = compress(&poses, &[], &tool_z_map, &defaults()).expect("valid");
        let mut worst = Deviation::default();
        for (start, mv) in starts(&c).into_iter().zip(&c.moves) {
            let d = move_deviation(&poses, start, *mv, &tool_z_map, &defaults()).expect("valid");
            worst.path_error_mm = worst.path_error_mm.max(d.path_error_mm);
            worst.orientation_error_deg = worst.orientation_error_deg.max(d.orientation_error_deg);
        }
        assert!((worst.path_error_mm - c.max_path_error_mm).abs() < 1e-9);
        assert!((worst.orientation_error_deg - c.max_orientation_error_deg).abs() < 1e-9);
        let over = move_deviation(&poses, 0, Move::Linear { to: 40 }, &tool_z_map, &defaults());
        assert!(over.expect("valid").orientation_error_deg > TOL_DEG);
        let bad = move_deviation(
            &poses,
            5,
            Move::Circular { via: 5, to: 9 },
            &tool_z_map,
            &defaults(),
        );
        assert!(matches!(bad, Err(CompressError::InvalidMove { .. })));
    }

    #[test]
    fn long_wavy_bead_compresses_in_reasonable_time() {
        let n = 100_000;
        let poses: Vec<_> = (0..n)
            .map(|k| {
                let x = 0.5 * k as f64;
                let p = Point3::new(x, 4.0 * (x / 30.0).sin(), 2.0 * (x / 55.0).sin());
                let tilt = (10.0 * (x / 200.0).sin()).to_radians();
                let q = UnitQuaternion::from_axis_angle(&Vector3::y_axis(), tilt);
                ControllerPose::new(p, q, vec![])
            })
            .collect();
        let t0 = Instant::now();
        let c = compress(&poses, &[], &tool_z_map, &defaults()).expect("valid");
        eprintln!(
            "100k wavy points: {} moves ({} circular) in {:?}, max {:.4} mm / {:.4} deg",
            c.moves.len(),
            c.moves.iter().filter(|m| m.via().is_some()).count(),
            t0.elapsed(),
            c.max_path_error_mm,
            c.max_orientation_error_deg
        );
        assert!(c.moves.len() < n / 10);
        assert!(c.max_path_error_mm <= TOL_MM && c.max_orientation_error_deg <= TOL_DEG);
    }
}
