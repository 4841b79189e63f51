//! The two corrections: per point of the layers after the measured one, the
//! bead height that brings the top back to the nominal layer, within the
//! heights the speed window can lay (speed correction); where it cannot,
//! the point at constant local distance (the nearest height the window
//! allows) from the layer below as it will stand — the constant-distance
//! march [SPEC §3.1.4] started from the measured layer (geometry
//! correction) — until a layer lands on the nominal one everywhere.
//!
//! The march may aim at a later nominal layer ([`rebuild`]'s `skip`): the
//! `i`-th layer laid after `K` then aims at nominal layer `K + skip + i`,
//! and the nominal layers `K+1..=K+skip` are never laid (a wall that stands
//! a layer high over part of its length is already, there, the next layer).
//! Part frame, mm, mm/s.

use rayon::prelude::*;

use super::ReplanError;
use crate::geometry::Tube;
use crate::math::Point3;
use crate::path::index::{SegmentId, SegmentIndex};
use crate::path::strategy::{constant_distance, Step};
use crate::path::Path;
use crate::process::ResolvedHeightLaw;
use crate::toolaxis::LocalFrame;

/// Newton steps that put the measured top of a column back on the tube's
/// surface (the error is along `b`, tangent to it).
const NEWTON_STEPS: usize = 8;

/// The heights (mm) and speeds (mm/s) the process window allows.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Window {
    pub law: ResolvedHeightLaw,
    pub speed_min_mm_s: f64,
    pub speed_max_mm_s: f64,
}

impl Window {
    /// Lowest bead height (mm): at the fastest speed.
    pub fn height_min_mm(&self) -> f64 {
        self.law.height_mm(self.speed_max_mm_s)
    }
    /// Highest bead height (mm): at the slowest speed.
    pub fn height_max_mm(&self) -> f64 {
        self.law.height_mm(self.speed_min_mm_s)
    }
    /// The speed that lays `h` (mm/s), within the window.
    pub fn speed_for(&self, h: f64) -> f64 {
        self.law
            .speed_mm_s(h)
            .clamp(self.speed_min_mm_s, self.speed_max_mm_s)
    }
}

/// One layer as replanned, its points in the path's order.
#[derive(Debug, Clone, PartialEq)]
pub(super) struct RebuiltLayer {
    /// Layer index in the replanned path (the build's numbering: `K + i`
    /// for the `i`-th layer laid after `K`).
    pub layer: usize,
    /// The nominal layer it aims at and takes its point order from (`layer
    /// + skip`).
    pub nominal: usize,
    /// Guide parameter of each point.
    pub t: Vec<f64>,
    /// Position of each point (part frame, mm).
    pub position: Vec<Point3>,
    /// Bead height asked for at each point (mm).
    pub height_mm: Vec<f64>,
    /// Travel speed at each point (mm/s).
    pub speed_mm_s: Vec<f64>,
    /// Whether the point's height was clamped to the window (geometry
    /// correction).
    pub clamped: Vec<bool>,
    /// Predicted top minus nominal top (mm, + high) after the layer.
    pub error_after_mm: Vec<f64>,
}

/// One rebuilt point: its guide parameter, its bead height (mm) and
/// whether the height was clamped to the window.
type Solved = (f64, f64, bool);

/// The layers rebuilt from the measured top, aiming at the nominal layers
/// `skip` layers further on.
#[derive(Debug, Clone, PartialEq)]
pub(super) struct Rebuilt {
    /// Nominal layers skipped: the `i`-th layer laid after `K` aims at
    /// nominal layer `K + skip + i`.
    pub skip: usize,
    /// The rebuilt layers, in order, the last one the first back on its
    /// nominal layer at every point when [`Rebuilt::rejoined`].
    pub layers: Vec<RebuiltLayer>,
    /// The first layer (replanned numbering) that no longer fits below the
    /// part's end, if the rebuild stopped there.
    pub ended_at: Option<usize>,
}

impl Rebuilt {
    /// Whether the last rebuilt layer lands on its nominal layer at every
    /// point.
    pub fn rejoined(&self) -> bool {
        self.layers
            .last()
            .is_some_and(|l| l.clamped.iter().all(|c| !c))
    }

    /// The layers laid until the nominal ones are rejoined (`None`: never).
    pub fn layers_to_rejoin(&self) -> Option<usize> {
        self.rejoined().then_some(self.layers.len())
    }
}

/// For every layer from `k` on, the column (point index of layer `k`) of
/// each of its points, matched by profile angle `v`.
pub(super) fn columns(path: &Path, k: usize) -> Result<Vec<Vec<usize>>, ReplanError> {
    let base = &path.layers[k];
    let n = base.points.len();
    let mut by_v: Vec<(u64, usize)> = base
        .points
        .iter()
        .enumerate()
        .map(|(i, p)| (p.v.to_bits(), i))
        .collect();
    by_v.sort_unstable();
    let mut out = Vec::with_capacity(path.layers.len() - k);
    for (l, layer) in path.layers.iter().enumerate().skip(k) {
        if !layer.closed || layer.points.len() != n {
            return Err(ReplanError::Unsupported {
                reason: format!(
                    "layer {l} is {} with {} points, layer {k} closed with {n}: replanning needs closed layers on one grid of columns (constant strategy, a number of points, no end plane)",
                    if layer.closed { "closed" } else { "open" },
                    layer.points.len()
                ),
            });
        }
        let cols = layer
            .points
            .iter()
            .enumerate()
            .map(|(m, p)| {
                by_v.binary_search_by_key(&p.v.to_bits(), |e| e.0)
                    .map(|i| by_v[i].1)
                    .map_err(|_| ReplanError::Unsupported {
                        reason: format!(
                            "layer {l}, point {m}: its profile angle v = {:.6} rad is on no column of layer {k} (replanning needs every layer on the same columns)",
                            p.v
                        ),
                    })
            })
            .collect::<Result<Vec<_>, _>>()?;
        out.push(cols);
    }
    Ok(out)
}

/// The guide parameter of each column's measured top: layer `k`'s point
/// moved by `error_mm` along its build direction, back on the surface.
pub(super) fn measured_t(
    tube: &Tube,
    path: &Path,
    frames: &[Vec<LocalFrame>],
    k: usize,
    error_mm: &[f64],
) -> Vec<f64> {
    let range = tube.range();
    path.layers[k]
        .points
        .iter()
        .zip(&frames[k])
        .zip(error_mm)
        .map(|((p, f), &e)| {
            let target = p.position + f.build * e;
            let mut t = p.t;
            for _ in 0..NEWTON_STEPS {
                let sp = tube.surface(t, p.v);
                let slope = sp.d_dt.dot(&f.build);
                if !(slope.abs() > 1e-12) {
                    break;
                }
                let step = (target - sp.position).dot(&f.build) / slope;
                let next = (t + step).clamp(range.eval_min(), range.eval_max());
                if !next.is_finite() {
                    break;
                }
                let done = (next - t).abs() < 1e-13 * (1.0 + t.abs());
                t = next;
                if done {
                    break;
                }
            }
            t
        })
        .collect()
}

/// Signed local distance (mm) from the predicted point `M(t, v)` to the
/// nominal layer (`nominal`, its polyline): + where the predicted top is
/// further along the tube (high). The local distance, as the slicer
/// measures a layer's height, not the distance along the column (which is
/// longer where the column leans from the build direction, on a bend).
fn signed_error(
    tube: &Tube,
    nominal: &SegmentIndex,
    hint: SegmentId,
    v: f64,
    t: f64,
    t_nom: f64,
) -> f64 {
    if t == t_nom {
        return 0.0;
    }
    let d = nominal
        .nearest_hinted(&tube.point(t, v), Some(hint))
        .map_or_else(
            || (tube.point(t, v) - tube.point(t_nom, v)).norm(),
            |n| n.distance,
        );
    if t > t_nom {
        d
    } else {
        -d
    }
}

/// The layers after `k` rebuilt from the measured top (`t_measured` per
/// column of layer `k`) until one lands on its nominal layer at every
/// point (that one included), and the first layer that no longer fits
/// below the part's end (`t_max`), if the rebuild stopped there (a wall
/// still too high near the top: the part is finished one or more layers
/// early). The `i`-th layer laid aims at nominal layer `k + skip + i`
/// (each point the nominal point where the window lays it, else the
/// nearest height the window allows); the rebuild stops without rejoining
/// when the nominal layers run out. `cols` from [`columns`].
#[allow(clippy::too_many_arguments)]
pub(super) fn rebuild(
    tube: &Tube,
    path: &Path,
    k: usize,
    cols: &[Vec<usize>],
    t_measured: &[f64],
    window: &Window,
    skip: usize,
) -> Result<Rebuilt, ReplanError> {
    let n = t_measured.len();
    let vs: Vec<f64> = path.layers[k].points.iter().map(|p| p.v).collect();
    let t_hi = tube.range().t_max;
    let (h_lo, h_hi) = (window.height_min_mm(), window.height_max_mm());
    let mut t_below = t_measured.to_vec();
    let mut out = Vec::new();
    for (nominal, layer) in path.layers.iter().enumerate().skip(k + 1 + skip) {
        let offset = nominal - skip;
        let col_of = &cols[nominal - k];
        // nominal t per column
        let mut t_nom = vec![0.0; n];
        for (m, &c) in col_of.iter().enumerate() {
            t_nom[c] = layer.points[m].t;
        }
        let below: Vec<Point3> = (0..n).map(|c| tube.point(t_below[c], vs[c])).collect();
        let index = SegmentIndex::new(vec![(below, true)]);
        let solved: Vec<Result<Option<Solved>, ReplanError>> = (0..n)
            .into_par_iter()
            .map(|c| {
                let hint = SegmentId {
                    polyline: 0,
                    segment: c,
                };
                let target = if t_nom[c] > t_below[c] {
                    let d = index
                        .nearest_hinted(&tube.point(t_nom[c], vs[c]), Some(hint))
                        .map_or(f64::INFINITY, |near| near.distance);
                    if (h_lo..=h_hi).contains(&d) {
                        return Ok(Some((t_nom[c], d, false)));
                    }
                    d.clamp(h_lo, h_hi)
                } else {
                    h_lo
                };
                let fail = |reason: &'static str| ReplanError::NoRoot {
                    layer: offset,
                    point: c,
                    height_mm: target,
                    reason,
                };
                match constant_distance::next_t(
                    tube, &index, hint, vs[c], t_below[c], target, t_hi, None,
                ) {
                    Ok(Step::Point { t, .. }) => Ok(Some((t, target, true))),
                    // the column passes the end of the part
                    Ok(_) => Ok(None),
                    Err(_) => Err(fail("root find failed")),
                }
            })
            .collect();
        let solved: Vec<Option<(f64, f64, bool)>> = solved.into_iter().collect::<Result<_, _>>()?;
        let Some(solved) = solved.into_iter().collect::<Option<Vec<_>>>() else {
            return Ok(Rebuilt {
                skip,
                layers: out,
                ended_at: Some(offset),
            });
        };
        // the nominal layer in column order, to measure the error after
        let nominal_index = SegmentIndex::new(vec![(
            (0..n).map(|c| tube.point(t_nom[c], vs[c])).collect(),
            true,
        )]);
        // back to the layer's own point order
        let mut rl = RebuiltLayer {
            layer: offset,
            nominal,
            t: Vec::with_capacity(n),
            position: Vec::with_capacity(n),
            height_mm: Vec::with_capacity(n),
            speed_mm_s: Vec::with_capacity(n),
            clamped: Vec::with_capacity(n),
            error_after_mm: Vec::with_capacity(n),
        };
        for &c in col_of {
            let (t, h, clamped) = solved[c];
            rl.t.push(t);
            rl.position.push(tube.point(t, vs[c]));
            rl.height_mm.push(h);
            rl.speed_mm_s.push(window.speed_for(h));
            rl.clamped.push(clamped);
            let hint = SegmentId {
                polyline: 0,
                segment: c,
            };
            rl.error_after_mm
                .push(signed_error(tube, &nominal_index, hint, vs[c], t, t_nom[c]));
        }
        let rejoined = rl.clamped.iter().all(|c| !c);
        out.push(rl);
        if rejoined {
            break;
        }
        for (c, s) in solved.iter().enumerate() {
            t_below[c] = s.0;
        }
    }
    Ok(Rebuilt {
        skip,
        layers: out,
        ended_at: None,
    })
}
