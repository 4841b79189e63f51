//! Continuous spiral deposition (beyond the thesis; SPEC §3.3): one helical
//! pass with no arc start or stop between layers. Points keep the columns of
//! constant `v` of the layered strategies; the point of column `i` on turn `k`
//! is at distance `Delta` from the turn below (found by a bracketed 1-D root
//! find as in the constant-distance method), after a first turn whose distance
//! to the substrate ramps from 0 to `Delta`, and before a last turn that ramps
//! back down to 0 so the top edge closes on itself.
//!
//! "The turn below" of spiral point `m` is the stretch of the sequence
//! (substrate curve, then spiral) centred on the point one turn earlier,
//! half a turn either side; it never includes the points of the current turn.
//! Points are computed in batches of half a turn, in parallel within a batch
//! (a point only depends on points at least half a turn earlier).

use super::{forward_root, RESIDUAL_REL};
use crate::geometry::{CurvePoint, Tube};
use crate::math::{tol, Point3, RootFailure};
use crate::path::index::SegmentIndex;
use rayon::prelude::*;

/// One computed spiral point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SpiralPoint {
    /// Guide parameter.
    pub t: f64,
    /// Profile angle (rad).
    pub v: f64,
    /// Position (part frame, mm).
    pub position: Point3,
    /// Distance to the turn below reached by the root find (mm).
    pub delta: f64,
}

/// Why the spiral stopped.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SpiralEnd {
    /// The next turn would pass the end; a ramp-down turn closes the spiral.
    RampDown,
    /// The turn limit was reached (no ramp down).
    MaxTurns,
}

/// Result of the spiral march.
#[derive(Debug, Clone, PartialEq)]
pub struct Spiral {
    /// The points in deposition order.
    pub points: Vec<SpiralPoint>,
    /// Points per turn.
    pub per_turn: usize,
    /// How it ended.
    pub end: SpiralEnd,
    /// Root finds and evaluations.
    pub evaluations: usize,
    /// Largest |residual| (mm).
    pub max_residual_mm: f64,
}

/// A failed spiral point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SpiralFailure {
    /// Index of the point in the spiral.
    pub point: usize,
    /// Why.
    pub reason: RootFailure,
}

/// Builds the spiral over the substrate curve `first` (the columns, in travel
/// order). `t_hi` bounds the search; `max_turns` caps the number of turns.
///
/// Returns `Ok(None)` if not even one full turn above the ramp fits.
pub fn march_spiral(
    tube: &Tube,
    first: &[CurvePoint],
    delta_mm: f64,
    t_hi: f64,
    max_turns: Option<usize>,
) -> Result<Option<Spiral>, SpiralFailure> {
    let n = first.len();
    let half = n / 2;
    // The sequence S: the substrate curve (turn "-1"), then the spiral points.
    let mut s_pos: Vec<Point3> = first.iter().map(|p| p.position).collect();
    let mut s_t: Vec<f64> = first.iter().map(|p| p.t).collect();
    let mut out: Vec<SpiralPoint> = Vec::new();
    let mut evaluations = 0;
    let mut max_residual: f64 = 0.0;
    let limit = max_turns.map(|k| k * n);
    let ramp_up = |m: usize| delta_mm * (m as f64 / n as f64).min(1.0);
    let mut end = SpiralEnd::MaxTurns;
    let mut m = 0;
    'batches: while limit.is_none_or(|l| m < l) {
        let b1 = limit.map_or(m + half, |l| (m + half).min(l));
        let batch = compute_batch(tube, first, &s_pos, &s_t, m, b1, delta_mm, t_hi, &|k| {
            ramp_up(k)
        })?;
        for (k, r) in batch.into_iter().enumerate() {
            match r {
                Some(p) => {
                    evaluations += p.1;
                    max_residual = max_residual.max(p.2);
                    push(&mut out, &mut s_pos, &mut s_t, p.0);
                }
                None => {
                    // Point m + k cannot be placed below t_hi: ramp down the last turn.
                    let stop = m + k;
                    if stop < 2 * n {
                        return Ok(None);
                    }
                    let m0 = stop - n;
                    out.truncate(m0);
                    s_pos.truncate(m0 + n);
                    s_t.truncate(m0 + n);
                    let ramp_down = |j: usize| delta_mm * (1.0 - (j - m0) as f64 / n as f64);
                    let mut j = m0;
                    while j < m0 + n {
                        let b = (j + half).min(m0 + n);
                        let batch = compute_batch(
                            tube, first, &s_pos, &s_t, j, b, delta_mm, t_hi, &ramp_down,
                        )?;
                        for r in batch {
                            match r {
                                Some(p) => {
                                    evaluations += p.1;
                                    max_residual = max_residual.max(p.2);
                                    push(&mut out, &mut s_pos, &mut s_t, p.0);
                                }
                                None => break 'batches,
                            }
                        }
                        j = b;
                    }
                    end = SpiralEnd::RampDown;
                    break 'batches;
                }
            }
        }
        m = b1;
    }
    Ok(Some(Spiral {
        points: out,
        per_turn: n,
        end,
        evaluations,
        max_residual_mm: max_residual,
    }))
}

fn push(out: &mut Vec<SpiralPoint>, s_pos: &mut Vec<Point3>, s_t: &mut Vec<f64>, p: SpiralPoint) {
    s_pos.push(p.position);
    s_t.push(p.t);
    out.push(p);
}

/// A placed point with the evaluations spent and the |residual| (mm).
type Placed = (SpiralPoint, usize, f64);

/// Points `b0..b1` of the spiral; `None` for a point that cannot be placed.
#[allow(clippy::too_many_arguments)]
fn compute_batch(
    tube: &Tube,
    first: &[CurvePoint],
    s_pos: &[Point3],
    s_t: &[f64],
    b0: usize,
    b1: usize,
    delta_mm: f64,
    t_hi: f64,
    target: &(dyn Fn(usize) -> f64 + Sync),
) -> Result<Vec<Option<Placed>>, SpiralFailure> {
    let n = first.len();
    let half = n / 2;
    // Window of S used by this batch: from half a turn before the first point
    // below to the last point computed.
    let lo = b0.saturating_sub(half);
    let index = SegmentIndex::new(vec![(s_pos[lo..].to_vec(), false)]);
    let results: Vec<Result<Option<Placed>, SpiralFailure>> = (b0..b1)
        .into_par_iter()
        .map(|m| {
            let col = m % n;
            let v = first[col].v;
            // S-index of the point one turn below is m; the turn below is S[m - half, m + half].
            let t_below = s_t[m];
            let goal = target(m);
            if goal <= 0.0 {
                let position = tube.point(t_below, v);
                return Ok(Some((
                    SpiralPoint {
                        t: t_below,
                        v,
                        position,
                        delta: 0.0,
                    },
                    0,
                    0.0,
                )));
            }
            let seg_lo = m.saturating_sub(half).max(lo) - lo;
            let seg_hi = (m + half).min(s_pos.len() - 1) - lo;
            let dist = |t: f64| {
                index
                    .nearest_in_range(&tube.point(t, v), 0, seg_lo, seg_hi)
                    .map_or(f64::INFINITY, |nr| nr.distance)
            };
            let d0 = dist(t_below);
            let speed = tube.surface(t_below, v).d_dt.norm();
            let step0 = 0.9 * (goal - d0).max(0.05 * delta_mm) / speed;
            let x_tol = tol::PARAM_FINE * (1.0 + t_below.abs());
            if d0 >= goal {
                // Already far enough (only on the ramp): stay on the point below.
                let position = tube.point(t_below, v);
                return Ok(Some((
                    SpiralPoint {
                        t: t_below,
                        v,
                        position,
                        delta: d0,
                    },
                    1,
                    0.0,
                )));
            }
            match forward_root(
                |t| dist(t) - goal,
                t_below,
                d0 - goal,
                step0,
                t_hi,
                x_tol,
                RESIDUAL_REL * delta_mm,
            ) {
                Ok(Some((t, ev, res))) => {
                    let position = tube.point(t, v);
                    Ok(Some((
                        SpiralPoint {
                            t,
                            v,
                            position,
                            delta: goal,
                        },
                        ev,
                        res,
                    )))
                }
                Ok(None) => Ok(None),
                Err(reason) => Err(SpiralFailure { point: m, reason }),
            }
        })
        .collect();
    results.into_iter().collect()
}
