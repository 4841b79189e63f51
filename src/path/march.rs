//! The layer loop shared by every strategy: columns of constant `v` start on
//! the substrate and advance layer by layer; each layer's points are computed
//! in parallel (rayon, order preserved), then cut by the end plane, split
//! where points are missing, decimated, and their seams aligned.

use super::distance_map::fill_deltas;
use super::index::{SegmentId, SegmentIndex};
use super::strategy::{constant_distance, iso_parametric, normal_to_guide, planar_z, Step};
use super::*;
use crate::geometry::{Substrate, Tube};
use crate::math::{Point3, RootFailure};
use rayon::prelude::*;
use std::f64::consts::TAU;

/// Builds the deposition path of `tube` on `substrate` [SPEC §3].
///
/// # Errors
/// [`PathError`] naming the option, layer or point: invalid options, a
/// `Delta` larger than the part, a substrate that misses the tube, a failed
/// root find, too many points, an end plane beyond the evaluable range.
pub fn slice(tube: &Tube, substrate: &Substrate, opts: &SliceOptions) -> Result<Path, PathError> {
    let mut path = slice_positions(tube, substrate, opts)?;
    fill_deltas(&mut path);
    Ok(path)
}

/// [`slice`] without the last step, the local distances of the points
/// (`PathPoint::delta` is `None`, or the root find's value on a spiral):
/// for callers that compute the distance map themselves and fill the
/// distances from it ([`apply_deltas`](super::distance_map::apply_deltas)),
/// instead of measuring every point twice.
///
/// # Errors
/// As [`slice`].
pub(crate) fn slice_positions(
    tube: &Tube,
    substrate: &Substrate,
    opts: &SliceOptions,
) -> Result<Path, PathError> {
    opts.validate()?;
    let length_mm = tube.arc_length(tube.range().t_max);
    if opts.delta_mm >= length_mm {
        return Err(PathError::DeltaTooLarge {
            delta_mm: opts.delta_mm,
            length_mm,
        });
    }
    let grid = grid_size(tube, opts);
    let first = substrate.first_layer(tube, grid)?;
    if opts.strategy == Strategy::Spiral {
        return spiral_path(tube, first, opts, length_mm);
    }
    let mut march = March::new(tube, opts, &first, grid);
    for n in 1.. {
        if let Some(stop) = march.layer(n)? {
            march.report.stop = stop;
            break;
        }
    }
    march.finish(length_mm)
}

/// The layer loop's state: each column's profile angle and cursor in `t`,
/// and the layers computed so far (per column, `t` and position).
struct March<'a> {
    tube: &'a Tube,
    opts: &'a SliceOptions,
    /// Each column's profile angle `v` (rad).
    vs: Vec<f64>,
    /// Each column's `t` on the first layer.
    t_first: Vec<f64>,
    /// Highest `t` a root find may reach.
    t_hi: f64,
    /// Planar and perpendicular slices may leave the part: open layers.
    open_layers_allowed: bool,
    /// Each computed layer: per column, its t and position (computed once).
    raw: Vec<Vec<Option<(f64, Point3)>>>,
    /// Each column's last `t`.
    cursor: Vec<f64>,
    /// Each column's last step in t (first guess of the next root find).
    last_step: Vec<Option<f64>>,
    /// Columns that may still have points.
    alive: Vec<bool>,
    report: SliceReport,
    /// Highest Z of the first layer (mm; planar slices).
    z_base: f64,
    /// Lowest guide arc length of the first layer (mm; perpendicular slices).
    s_base: f64,
    /// Columns (points a layer of the computation grid).
    grid: usize,
    /// Points computed so far, the grid's of every layer.
    total_points: usize,
}

impl<'a> March<'a> {
    /// The loop's start on the first layer `first`, of `grid` columns.
    fn new(
        tube: &'a Tube,
        opts: &'a SliceOptions,
        first: &[crate::geometry::CurvePoint],
        grid: usize,
    ) -> Self {
        let range = tube.range();
        let vs: Vec<f64> = first.iter().map(|p| p.v).collect();
        let t_first: Vec<f64> = first.iter().map(|p| p.t).collect();
        let t_hi = match opts.end {
            EndRule::WholeLayers => range.t_max,
            EndRule::Truncate(_) | EndRule::EvaluableRange => range.eval_max(),
        };
        let open_layers_allowed =
            matches!(opts.strategy, Strategy::Planar | Strategy::Perpendicular);
        let raw: Vec<Vec<Option<(f64, Point3)>>> =
            vec![first.iter().map(|p| Some((p.t, p.position))).collect()];
        let cursor = t_first.clone();
        let report = SliceReport {
            grid_points: grid,
            ..SliceReport::default()
        };
        let z_base = first.iter().map(|p| p.position.z).fold(f64::MIN, f64::max);
        let s_base = t_first
            .iter()
            .map(|&t| tube.arc_length(t))
            .fold(f64::MAX, f64::min);
        Self {
            tube,
            opts,
            vs,
            t_first,
            t_hi,
            open_layers_allowed,
            raw,
            cursor,
            last_step: vec![None; grid],
            alive: vec![true; grid],
            report,
            z_base,
            s_base,
            grid,
            total_points: grid,
        }
    }

    /// Computes layer `n` against the last one and keeps it, or says why
    /// the generation stops.
    fn layer(&mut self, n: usize) -> Result<Option<StopReason>, PathError> {
        let opts = self.opts;
        if opts.max_layers.is_some_and(|m| n >= m) {
            return Ok(Some(StopReason::MaxLayers));
        }
        let below = self.raw.last().expect("first layer present");
        let (index, hints) = below_index(below);
        let steps = self.root_finds(n, &index, &hints);
        let (mut layer, ended) = self.collect_steps(n, steps)?;
        if let Some(stop) = self.end_rules(n, &ended)? {
            return Ok(Some(stop));
        }
        for &i in &ended {
            self.alive[i] = false;
        }
        if layer.iter().all(Option::is_none) {
            return Ok(Some(
                if self.open_layers_allowed && opts.strategy == Strategy::Perpendicular {
                    StopReason::ReachedEnd
                } else {
                    StopReason::NoMorePoints
                },
            ));
        }
        if let EndRule::Truncate(plane) = opts.end {
            let inside = layer.iter().zip(&self.vs).any(|(t, &v)| {
                t.is_some_and(|t| (self.tube.point(t, v) - plane.point).dot(&plane.normal) <= 0.0)
            });
            if !inside {
                return Ok(Some(StopReason::PastEndPlane));
            }
        }
        let positions = self.positions(n, &mut layer, &index, &hints)?;
        self.keep(n, &layer, &positions)?;
        Ok(None)
    }

    /// Each column's next step on layer `n`, in parallel (order kept).
    fn root_finds(
        &self,
        n: usize,
        index: &SegmentIndex,
        hints: &[Option<SegmentId>],
    ) -> Vec<Result<Step, RootFailure>> {
        let (tube, opts) = (self.tube, self.opts);
        let layer_t = match opts.strategy {
            Strategy::Perpendicular => tube.t_at_arc_length(self.s_base + n as f64 * opts.delta_mm),
            _ => f64::NAN,
        };
        let z = self.z_base + n as f64 * opts.delta_mm;
        (0..self.grid)
            .into_par_iter()
            .map(|i| {
                if !self.alive[i] {
                    return Ok(Step::End);
                }
                let (v, t0) = (self.vs[i], self.cursor[i]);
                match opts.strategy {
                    Strategy::Constant => match hints[i] {
                        Some(h) => constant_distance::next_t(
                            tube,
                            index,
                            h,
                            v,
                            t0,
                            opts.delta_mm,
                            self.t_hi,
                            self.last_step[i],
                        ),
                        None => Ok(Step::End),
                    },
                    Strategy::Iso => iso_parametric::next_t(tube, v, t0, opts.delta_mm, self.t_hi),
                    Strategy::Planar => planar_z::next_t(tube, v, t0, z, self.t_hi),
                    Strategy::Perpendicular => {
                        Ok(normal_to_guide::step(layer_t, self.t_first[i], self.t_hi))
                    }
                    Strategy::Spiral => Ok(Step::End),
                }
            })
            .collect()
    }

    /// The steps of layer `n` as each column's `t` (`None`: no point) and
    /// the columns that ended, counted in the report; a failed root find
    /// names its layer and point.
    #[allow(clippy::type_complexity)]
    fn collect_steps(
        &mut self,
        n: usize,
        steps: Vec<Result<Step, RootFailure>>,
    ) -> Result<(Vec<Option<f64>>, Vec<usize>), PathError> {
        let mut layer = vec![None; self.grid];
        let mut ended = Vec::new();
        for (i, s) in steps.into_iter().enumerate() {
            match s {
                Ok(Step::Point {
                    t,
                    evaluations,
                    residual,
                }) => {
                    layer[i] = Some(t);
                    if evaluations > 0 {
                        self.report.root_finds += 1;
                        self.report.evaluations += evaluations;
                        self.report.max_residual_mm = self.report.max_residual_mm.max(residual);
                    }
                }
                Ok(Step::Skip) => {}
                Ok(Step::End) => {
                    if self.alive[i] {
                        ended.push(i);
                    }
                }
                Err(e) => {
                    return Err(PathError::NoRoot {
                        layer: n,
                        point: i,
                        v: self.vs[i],
                        t_lo: self.cursor[i],
                        t_hi: self.t_hi,
                        delta_mm: self.opts.delta_mm,
                        reason: failure_reason(e),
                    })
                }
            }
        }
        Ok((layer, ended))
    }

    /// The end rules where columns `ended` on layer `n` of a strategy whose
    /// layers stay whole: stop at the end or the evaluable range; with an
    /// end plane, a column must have ended beyond it.
    fn end_rules(&self, n: usize, ended: &[usize]) -> Result<Option<StopReason>, PathError> {
        if ended.is_empty() || self.open_layers_allowed {
            return Ok(None);
        }
        match self.opts.end {
            EndRule::WholeLayers => Ok(Some(StopReason::ReachedEnd)),
            EndRule::EvaluableRange => Ok(Some(StopReason::EvaluableRange)),
            EndRule::Truncate(plane) => {
                for &i in ended {
                    let p = self.tube.point(self.cursor[i], self.vs[i]);
                    if (p - plane.point).dot(&plane.normal) <= 0.0 {
                        return Err(PathError::ExtensionTooShort {
                            layer: n,
                            point: i,
                            t_eval_max: self.t_hi,
                        });
                    }
                }
                Ok(None)
            }
        }
    }

    /// Positions of the new points, computed once (reused as the layer
    /// below and in the output); a whole constant-distance layer's turning
    /// is reported and, with smoothing, bounded (its `t` updated).
    fn positions(
        &mut self,
        n: usize,
        layer: &mut [Option<f64>],
        index: &SegmentIndex,
        hints: &[Option<SegmentId>],
    ) -> Result<Vec<Option<Point3>>, PathError> {
        let (tube, opts) = (self.tube, self.opts);
        let mut positions: Vec<Option<Point3>> = layer
            .par_iter()
            .zip(&self.vs)
            .map(|(t, &v)| t.map(|t| tube.point(t, v)))
            .collect();
        if opts.strategy == Strategy::Constant && layer.iter().all(Option::is_some) {
            let pts: Vec<Point3> = positions.iter().map(|p| p.expect("all present")).collect();
            let before = super::smooth::turning_angles(&pts, true)
                .into_iter()
                .fold(0.0, f64::max);
            self.report.max_turn_before_rad = self.report.max_turn_before_rad.max(before);
            let mut after = before;
            if let Some(sm) = opts.smoothing {
                after = self.smooth(n, &sm, layer, &pts, index, hints)?;
                positions = layer
                    .par_iter()
                    .zip(&self.vs)
                    .map(|(t, &v)| t.map(|t| tube.point(t, v)))
                    .collect();
            }
            self.report.max_turn_after_rad = self.report.max_turn_after_rad.max(after);
        }
        Ok(positions)
    }

    /// Smooths the whole layer `n` (points `pts`, parameters `layer`,
    /// updated) against the layer below (SPEC §3.4); returns its largest
    /// turning after (rad).
    fn smooth(
        &self,
        n: usize,
        sm: &super::smooth::Smoothing,
        layer: &mut [Option<f64>],
        pts: &[Point3],
        index: &SegmentIndex,
        hints: &[Option<SegmentId>],
    ) -> Result<f64, PathError> {
        let opts = self.opts;
        let mut ts: Vec<f64> = layer.iter().map(|t| t.expect("all present")).collect();
        let hint_list: Vec<SegmentId> = hints
            .iter()
            .map(|h| {
                h.unwrap_or(SegmentId {
                    polyline: 0,
                    segment: 0,
                })
            })
            .collect();
        let out = super::smooth::smooth_layer(
            self.tube,
            &self.vs,
            &mut ts,
            true,
            index,
            &hint_list,
            opts.delta_mm,
            sm,
        );
        // Past the end plane the extension may fold (the torus curls
        // back): only the kinks of the points that will be kept count.
        let kept_ok = || match opts.end {
            EndRule::Truncate(plane) => {
                let angles = super::smooth::turning_angles(pts, true);
                pts.iter()
                    .zip(angles)
                    .filter(|(p, _)| (*p - plane.point).dot(&plane.normal) <= 0.0)
                    .all(|(_, a)| a <= sm.max_turn_rad)
            }
            _ => false,
        };
        if !out.met && kept_ok() {
            // Nothing to fix where the layer is kept.
        } else if !out.met {
            return Err(PathError::SmoothingInfeasible {
                layer: n,
                bound_deg: sm.max_turn_rad.to_degrees(),
                tolerance_pct: 100.0 * sm.tolerance,
                before_deg: out.max_turn_before_rad.to_degrees(),
                reached_deg: out.max_turn_after_rad.to_degrees(),
            });
        }
        for (slot, t) in layer.iter_mut().zip(&ts) {
            *slot = Some(*t);
        }
        Ok(out.max_turn_after_rad)
    }

    /// Keeps layer `n` (each column's `t` and position): the columns'
    /// cursors move on, and the path's point count is checked.
    fn keep(
        &mut self,
        n: usize,
        layer: &[Option<f64>],
        positions: &[Option<Point3>],
    ) -> Result<(), PathError> {
        for (i, t) in layer.iter().enumerate() {
            if let Some(t) = t {
                self.last_step[i] = Some(*t - self.cursor[i]);
                self.cursor[i] = *t;
            }
        }
        self.total_points += self.grid;
        if self.total_points > MAX_POINTS_PER_PATH {
            return Err(PathError::TooManyPoints {
                limit: MAX_POINTS_PER_PATH,
                layer: n,
            });
        }
        let with_positions: Vec<Option<(f64, Point3)>> = layer
            .iter()
            .zip(positions)
            .map(|(t, p)| t.zip(*p))
            .collect();
        self.raw.push(with_positions);
        Ok(())
    }

    /// The path from the layers computed (at least two, else `Delta` is
    /// larger than the part, of guide length `length_mm`).
    fn finish(self, length_mm: f64) -> Result<Path, PathError> {
        let opts = self.opts;
        if self.raw.len() < 2 {
            return Err(PathError::DeltaTooLarge {
                delta_mm: opts.delta_mm,
                length_mm,
            });
        }
        let mut report = self.report;
        let mut layers = assemble(&self.vs, self.raw, opts, &mut report);
        align_seams(&mut layers, opts);
        Ok(Path {
            strategy: opts.strategy,
            delta_mm: opts.delta_mm,
            layers,
            report,
            spiral: None,
        })
    }
}

fn failure_reason(e: RootFailure) -> &'static str {
    match e {
        RootFailure::NotBracketed => "not bracketed",
        RootFailure::NonFinite => "non-finite distance",
        RootFailure::NotConverged => "not converged",
    }
}

/// The spiral strategy: columns in travel order from the start angle, one
/// open layer, ramp up over the first turn and down over the last
/// (see [`spiral`](super::strategy::spiral)). The end plane is not applied: the
/// spiral closes with its ramp-down turn below `t_max` (cutting it by a plane
/// would add arc starts).
fn spiral_path(
    tube: &Tube,
    mut first: Vec<crate::geometry::CurvePoint>,
    opts: &SliceOptions,
    length_mm: f64,
) -> Result<Path, PathError> {
    use super::strategy::spiral::{march_spiral, SpiralEnd};
    let n = first.len();
    let start = ((opts.spiral_start_rad.rem_euclid(TAU) / TAU) * n as f64).round() as usize % n;
    first.rotate_left(start);
    if opts.spiral_reverse {
        first[1..].reverse();
    }
    let range = tube.range();
    let t_hi = match opts.end {
        EndRule::EvaluableRange => range.eval_max(),
        _ => range.t_max,
    };
    let spiral = march_spiral(tube, &first, opts.delta_mm, t_hi, opts.max_layers).map_err(|f| {
        PathError::SpiralRoot {
            point: f.point,
            turn: f.point / n,
            v: first[f.point % n].v,
            reason: failure_reason(f.reason),
        }
    })?;
    let Some(spiral) = spiral else {
        return Err(PathError::DeltaTooLarge {
            delta_mm: opts.delta_mm,
            length_mm,
        });
    };
    let ramp_down_from =
        (spiral.end == SpiralEnd::RampDown).then(|| spiral.points.len().saturating_sub(n));
    let points: Vec<PathPoint> = spiral
        .points
        .iter()
        .map(|p| PathPoint {
            t: p.t,
            v: p.v,
            position: p.position,
            delta: Some(p.delta),
        })
        .collect();
    let report = SliceReport {
        root_finds: points.len(),
        evaluations: spiral.evaluations,
        max_residual_mm: spiral.max_residual_mm,
        grid_points: n,
        stop: match spiral.end {
            SpiralEnd::RampDown => StopReason::ReachedEnd,
            SpiralEnd::MaxTurns => StopReason::MaxLayers,
        },
        ..SliceReport::default()
    };
    Ok(Path {
        strategy: Strategy::Spiral,
        delta_mm: opts.delta_mm,
        layers: vec![Layer {
            slice: 0,
            points,
            closed: false,
        }],
        report,
        spiral: Some(SpiralInfo {
            per_turn: n,
            ramp_down_from,
        }),
    })
}

/// Computation grid: the requested points, or a fine grid for chord / spacing
/// tolerances (output is decimated to the tolerance).
pub(super) fn grid_size(tube: &Tube, opts: &SliceOptions) -> usize {
    let r = tube.range();
    let (mut a_min, mut a_max) = (f64::MAX, 0.0_f64);
    for i in 0..=64 {
        let a = tube.radius(r.t_min + (r.t_max - r.t_min) * i as f64 / 64.0);
        a_min = a_min.min(a);
        a_max = a_max.max(a);
    }
    let perimeter = TAU * a_max;
    let n = match opts.discretisation {
        Discretisation::Points(n) => return n,
        Discretisation::ChordError(e) => {
            // Fine spacing with a sagitta of 1/50 of the tolerance on the tightest
            // circle, so that decimation lands within a few % of the ideal count.
            let h = (8.0 * a_min * e / 50.0).sqrt();
            perimeter / h
        }
        Discretisation::MaxSpacing(d) => 4.0 * perimeter / d,
    };
    (n.ceil() as usize).clamp(64, 20_000)
}

/// Index over the valid points of the layer below, and for each column the
/// segment next to its point there.
fn below_index(below: &[Option<(f64, Point3)>]) -> (SegmentIndex, Vec<Option<SegmentId>>) {
    let runs = runs(below);
    let mut hints = vec![None; below.len()];
    let mut polylines = Vec::with_capacity(runs.len());
    for (k, (cols, closed)) in runs.iter().enumerate() {
        let pts = cols
            .iter()
            .map(|&i| below[i].expect("run holds valid points").1)
            .collect();
        for (j, &i) in cols.iter().enumerate() {
            let seg = if !closed && j + 1 == cols.len() && j > 0 {
                j - 1
            } else {
                j
            };
            hints[i] = Some(SegmentId {
                polyline: k,
                segment: seg,
            });
        }
        polylines.push((pts, *closed));
    }
    (SegmentIndex::new(polylines), hints)
}

/// Splits a cyclic column layer into runs of present points: one closed run
/// if all are present, else open runs, each starting after a gap.
pub(crate) fn runs<T>(layer: &[Option<T>]) -> Vec<(Vec<usize>, bool)> {
    let n = layer.len();
    if layer.iter().all(Option::is_some) {
        return vec![((0..n).collect(), true)];
    }
    let Some(gap) = layer.iter().position(Option::is_none) else {
        return Vec::new();
    };
    let mut out = Vec::new();
    let mut current = Vec::new();
    for k in 1..=n {
        let i = (gap + k) % n;
        if layer[i].is_some() {
            current.push(i);
        } else if !current.is_empty() {
            out.push((std::mem::take(&mut current), false));
        }
    }
    if !current.is_empty() {
        out.push((current, false));
    }
    out
}

/// Output layers: truncation, splitting into polylines, decimation. Each
/// computed layer is freed once assembled (the path is not held twice).
fn assemble(
    vs: &[f64],
    raw: Vec<Vec<Option<(f64, Point3)>>>,
    opts: &SliceOptions,
    report: &mut SliceReport,
) -> Vec<Layer> {
    let mut layers = Vec::new();
    for (slice, cols) in raw.into_iter().enumerate() {
        let mut pts: Vec<Option<PathPoint>> = cols
            .iter()
            .zip(vs)
            .map(|(tp, &v)| {
                tp.map(|(t, position)| PathPoint {
                    t,
                    v,
                    position,
                    delta: None,
                })
            })
            .collect();
        if let EndRule::Truncate(plane) = opts.end {
            for p in pts.iter_mut() {
                if p.is_some_and(|q| (q.position - plane.point).dot(&plane.normal) > 0.0) {
                    *p = None;
                    report.truncated_points += 1;
                }
            }
        }
        for (run, closed) in runs(&pts) {
            if run.len() < 2 {
                // A single point is no bead (a slice touching the part's top).
                continue;
            }
            let points: Vec<PathPoint> = run.iter().map(|&i| pts[i].expect("valid")).collect();
            let points = decimate(points, closed, opts.discretisation);
            layers.push(Layer {
                slice,
                points,
                closed,
            });
        }
    }
    layers
}

/// Keeps a subset of points so that the chord error / spacing tolerance holds.
fn decimate(points: Vec<PathPoint>, closed: bool, d: Discretisation) -> Vec<PathPoint> {
    let (chord, spacing) = match d {
        Discretisation::Points(_) => return points,
        Discretisation::ChordError(e) => (e, f64::INFINITY),
        Discretisation::MaxSpacing(s) => (f64::INFINITY, s),
    };
    let n = points.len();
    if n < 4 {
        return points;
    }
    let end = if closed { n } else { n - 1 };
    let at = |k: usize| points[k % n].position;
    let mut keep = vec![0usize];
    let mut i = 0;
    while i < end {
        let mut j = i + 1;
        while j < end {
            let cand = j + 1;
            let (a, b) = (at(i), at(cand));
            let ok = (b - a).norm() <= spacing
                && ((i + 1)..cand)
                    .all(|k| super::index::point_segment_distance(&at(k), &a, &b).0 <= chord);
            if !ok {
                break;
            }
            j = cand;
        }
        if j < n {
            keep.push(j);
        }
        i = j;
    }
    if !closed && *keep.last().expect("non-empty") != n - 1 {
        keep.push(n - 1);
    }
    keep.dedup();
    keep.into_iter()
        .filter(|&k| k < n)
        .map(|k| points[k])
        .collect()
}

/// Rotates closed layers so each starts on its sharpest corner where it has
/// corners and `seams_on_corners` is set (SPEC §3.3, §3.4); the others but
/// the first so each starts next to the end of the layer below, then by the
/// stagger angle.
fn align_seams(layers: &mut [Layer], opts: &SliceOptions) {
    for k in 0..layers.len() {
        if !layers[k].closed {
            continue;
        }
        let n = layers[k].points.len();
        if opts.seams_on_corners {
            let positions: Vec<Point3> = layers[k].points.iter().map(|p| p.position).collect();
            if let Some(start) =
                super::corners::corner_seam_start(&positions, opts.corner_threshold_rad)
            {
                layers[k].points.rotate_left(start);
                continue;
            }
        }
        if k == 0 {
            // the first layer keeps the substrate's start
            continue;
        }
        let mut start = 0;
        if opts.align_seams {
            let end = layers[k - 1]
                .points
                .last()
                .expect("layers are non-empty")
                .position;
            start = (0..n)
                .min_by(|&a, &b| {
                    let da = (layers[k].points[a].position - end).norm();
                    let db = (layers[k].points[b].position - end).norm();
                    da.total_cmp(&db)
                })
                .unwrap_or(0);
        }
        let slice = layers[k].slice as f64;
        let shift = ((opts.stagger_rad * slice / TAU).rem_euclid(1.0) * n as f64).round() as usize;
        layers[k].points.rotate_left((start + shift) % n);
    }
}

#[cfg(test)]
mod tests {
    use super::{runs, Layer, PathPoint};
    use crate::math::Point3;

    /// A closed layer through `pts` (mm), in order.
    fn layer(pts: Vec<Point3>) -> Layer {
        Layer {
            slice: 1,
            points: pts
                .into_iter()
                .map(|position| PathPoint {
                    t: 0.0,
                    v: 0.0,
                    position,
                    delta: None,
                })
                .collect(),
            closed: true,
        }
    }

    /// A lens (two arcs of radius 10 mm whose centres are 6 mm either side
    /// of its axis), `n` points a side, starting at one of its two corners
    /// (the arcs' tangents there 2·asin(0.6) ≈ 73.7° apart).
    fn lens(n: usize) -> Vec<Point3> {
        let (r, d) = (10.0_f64, 6.0_f64);
        let half = (d / r).acos(); // half the arc's angle
        let arc = |cy: f64, from: f64, to: f64| {
            (0..n).map(move |i| {
                let a = from + (to - from) * i as f64 / n as f64;
                Point3::new(r * a.cos(), cy + r * a.sin(), 0.0)
            })
        };
        let top = std::f64::consts::FRAC_PI_2;
        // from the corner (+8, 0) over the upper arc, back over the lower one
        arc(-d, top - half, top + half)
            .chain(arc(d, -top - half, -top + half))
            .collect()
    }

    #[test]
    fn a_corner_at_the_seam_does_not_wrap_the_bead() {
        let pts = lens(100);
        // the corner's turning: the arcs' tangents' angle, plus half a
        // step of each arc (2·acos(0.6) over 100 steps)
        let turns = crate::path::smooth::turning_angles(&pts, true);
        let step = 2.0 * 0.6_f64.acos() / 100.0;
        assert!(
            (turns[0] - 2.0 * 0.6_f64.asin() - step).abs() < 1e-9,
            "{}",
            turns[0]
        );
        assert!(!layer(pts.clone()).bead_wraps());
        // the same lens started mid-arc: both corners inside the bead
        let mut mid = pts.clone();
        mid.rotate_left(50);
        assert!(layer(mid).bead_wraps());
        // a circle, wherever it starts, and an open layer
        let circle: Vec<Point3> = (0..200)
            .map(|i| {
                let a = std::f64::consts::TAU * i as f64 / 200.0;
                Point3::new(10.0 * a.cos(), 10.0 * a.sin(), 0.0)
            })
            .collect();
        assert!(layer(circle).bead_wraps());
        let mut open = layer(pts);
        open.closed = false;
        assert!(!open.bead_wraps());
    }

    #[test]
    fn runs_split_cyclically() {
        assert_eq!(runs(&[Some(1), Some(2)]), vec![(vec![0, 1], true)]);
        let r = runs(&[Some(1), None, Some(3), Some(4), None, Some(6)]);
        assert_eq!(r, vec![(vec![2, 3], false), (vec![5, 0], false)]);
    }
}
