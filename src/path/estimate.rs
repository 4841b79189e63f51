//! **Work estimate before slicing.** Takes the same [`Tube`], [`Substrate`]
//! and [`SliceOptions`] as [`slice`](super::slice) and returns, in
//! milliseconds, an upper estimate of the layers and computed points the
//! slice would take and of the memory its point arrays would hold
//! ([`WorkEstimate`]), so that a host program can refuse or confirm a run
//! (`--delta 0.01` instead of `1`) before it starts.
//!
//! The bound: every strategy but the planar one advances each column (a
//! curve `t ↦ M(t, v)` at fixed `v`) by at least `Delta` of its arc length
//! per layer, because the distance from a new point to the layer below is
//! at most the distance to its own column's point there, which is at most
//! the column's arc between them. So a column of length `L` carries at most
//! `L / Delta + 1` layers. With whole layers the path ends when its shortest
//! column does (the inner side of a bend, which the constant strategy
//! climbs fastest); when layers are generated past the end (end plane,
//! evaluable range) it may go on until its longest column ends. Perpendicular
//! layers are `Delta` apart along the guide; planar ones `Delta` apart in Z.

use std::f64::consts::TAU;

use crate::geometry::{Plane, Substrate, Tube};
use crate::path::{EndRule, PathPoint, SliceOptions, Strategy, MAX_POINTS_PER_PATH};

/// Columns sampled around the profile (`v` values).
const COLUMNS: usize = 24;
/// Steps along each column when measuring its length.
const STEPS: usize = 256;

/// What a slice would cost, from [`estimate_work`]. All counts are upper
/// estimates (see the module doc) for the computation grid, which is what
/// the slicer holds in memory: with a chord or spacing tolerance the
/// written layers are decimated to fewer points.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WorkEstimate {
    /// Layers (slices) the path would have at most, the first included;
    /// for a spiral, turns.
    pub layers: u64,
    /// Points computed per layer (the grid; [`Discretisation::Points`](crate::path::Discretisation::Points) gives it exactly).
    pub points_per_layer: u64,
    /// `layers × points_per_layer`: root finds and positions computed.
    pub points: u64,
    /// Memory of the slicer's point arrays at the end of the slice (bytes):
    /// per grid point one computed `(t, position)` and one [`PathPoint`].
    /// The distance map, tool axes, plan and files add more per point.
    pub bytes: u64,
    /// Whether `points` is beyond what [`slice`](super::slice) accepts at
    /// all ([`MAX_POINTS_PER_PATH`]): such a run fails after doing that
    /// much work.
    pub over_path_limit: bool,
}

/// Bytes the slicer holds per grid point: the raw `(t, position)` of each
/// computed layer and the path point made from it.
pub const BYTES_PER_POINT: u64 = (std::mem::size_of::<Option<(f64, crate::math::Point3)>>()
    + std::mem::size_of::<PathPoint>()) as u64;

/// Estimates the layers, points and memory of `slice(tube, substrate, opts)`
/// without slicing: a few hundred evaluations of the tube (milliseconds),
/// whatever `Delta` and the point count. See the module doc for the bound.
///
/// The start of each column is the substrate's first layer at that `v`
/// when it can be found cheaply, else the tube's `t_min` (a longer column:
/// still an upper estimate). Options are not validated here: a `Delta` that
/// is not positive and finite gives `u64::MAX` layers.
pub fn estimate_work(tube: &Tube, substrate: &Substrate, opts: &SliceOptions) -> WorkEstimate {
    let range = tube.range();
    let t_end = match (opts.strategy, opts.end) {
        (_, EndRule::WholeLayers) => range.t_max,
        (Strategy::Spiral, EndRule::Truncate(_)) => range.t_max,
        _ => range.eval_max(),
    };
    let whole_layers = matches!(opts.end, EndRule::WholeLayers)
        || (opts.strategy == Strategy::Spiral && !matches!(opts.end, EndRule::EvaluableRange));
    let starts: Vec<(f64, f64)> = match substrate.first_layer(tube, COLUMNS) {
        Ok(first) => first.iter().map(|p| (p.v, p.t)).collect(),
        Err(_) => (0..COLUMNS)
            .map(|i| (TAU * i as f64 / COLUMNS as f64, range.t_min))
            .collect(),
    };
    let delta = opts.delta_mm;
    let span_mm = match opts.strategy {
        Strategy::Perpendicular => {
            let s0 = starts
                .iter()
                .map(|&(_, t)| tube.arc_length(t))
                .fold(f64::INFINITY, f64::min);
            tube.arc_length(t_end) - s0
        }
        Strategy::Planar => {
            let z0 = starts
                .iter()
                .map(|&(v, t)| tube.point(t, v).z)
                .fold(f64::NEG_INFINITY, f64::max);
            let z1 = starts
                .iter()
                .flat_map(|&(v, t)| column(tube, v, t, t_end).map(|p| p.z))
                .fold(f64::NEG_INFINITY, f64::max);
            z1 - z0
        }
        _ => {
            let plane = match opts.end {
                EndRule::Truncate(p) if opts.strategy != Strategy::Spiral => Some(p),
                _ => None,
            };
            let lengths = starts
                .iter()
                .map(|&(v, t)| column_length(tube, v, t, t_end, plane.as_ref()));
            if whole_layers {
                lengths.fold(f64::INFINITY, f64::min)
            } else {
                lengths.fold(0.0, f64::max)
            }
        }
    };
    let layers_f = if delta.is_finite() && delta > 0.0 && span_mm.is_finite() {
        (span_mm.max(0.0) / delta).floor() + 1.0
    } else {
        f64::INFINITY
    };
    let layers_f = match opts.max_layers {
        Some(m) => layers_f.min(m as f64),
        None => layers_f,
    };
    let points_per_layer = super::march::grid_size(tube, opts) as u64;
    let points_f = layers_f * points_per_layer as f64;
    WorkEstimate {
        layers: saturate(layers_f),
        points_per_layer,
        points: saturate(points_f),
        bytes: saturate(points_f * BYTES_PER_POINT as f64),
        over_path_limit: points_f > MAX_POINTS_PER_PATH as f64,
    }
}

fn saturate(x: f64) -> u64 {
    if x.is_nan() || x >= u64::MAX as f64 {
        u64::MAX
    } else {
        x.max(0.0) as u64
    }
}

/// `STEPS + 1` points of the column at `v` from `t0` to `t1` (part frame, mm).
fn column(tube: &Tube, v: f64, t0: f64, t1: f64) -> impl Iterator<Item = crate::math::Point3> + '_ {
    (0..=STEPS).map(move |k| tube.point(t0 + (t1 - t0) * k as f64 / STEPS as f64, v))
}

/// Polyline length of the column at `v` from `t0` to `t1` (mm); with an
/// end plane, only up to one step past the last sample kept by it (a point
/// beyond every kept sample is cut, so no layer climbs further there).
fn column_length(tube: &Tube, v: f64, t0: f64, t1: f64, plane: Option<&Plane>) -> f64 {
    if t1 <= t0 {
        return 0.0;
    }
    let pts: Vec<_> = column(tube, v, t0, t1).collect();
    let last = match plane {
        Some(p) => pts
            .iter()
            .rposition(|m| (m - p.point).dot(&p.normal) <= 0.0)
            .map_or(0, |i| (i + 1).min(STEPS)),
        None => STEPS,
    };
    pts[..=last].windows(2).map(|w| (w[1] - w[0]).norm()).sum()
}
