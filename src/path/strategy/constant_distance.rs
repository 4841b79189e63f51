//! Constant local interlayer distance [SPEC §3.1.4; thesis §2.3, eq. 2.20–2.27]:
//! keep `v`, find `t` such that the distance from `M(t, v)` to the polyline of
//! the layer below equals `Delta`, moving forward from the column's point on
//! that layer (where the distance is zero).

use super::{forward_root, Step};
use crate::geometry::Tube;
use crate::math::{tol, Point3, RootFailure};
use crate::path::index::{SegmentId, SegmentIndex};

/// Floor of the across-layer part of the surface's `t` derivative, as a
/// fraction of the whole (relative): keeps the first step finite where the
/// column runs along the layer below.
const MIN_ACROSS_FRACTION: f64 = 1e-3;
/// Residual at which Brent's method stops, relative to Delta (× `delta_mm`
/// gives mm).
const BRENT_RESIDUAL_REL: f64 = 1e-10;
/// A point whose exact distance to the layer below is within this fraction
/// of Delta is accepted without the fallback search (relative).
const ACCEPT_RESIDUAL_REL: f64 = 1e-9;

/// Next `t` of the column at profile angle `v` whose point on the layer below
/// is at `t_below`; `hint` is a segment of the layer below next to that point
/// (speeds up nearest-segment queries; the result is confirmed exactly).
/// `last_step` is the column's previous step in `t`, if any: layers change
/// slowly, so it is the first guess (else one is made from `dM/dt`).
#[allow(clippy::too_many_arguments)]
pub fn next_t(
    tube: &Tube,
    below: &SegmentIndex,
    hint: SegmentId,
    v: f64,
    t_below: f64,
    delta_mm: f64,
    t_hi: f64,
    last_step: Option<f64>,
) -> Result<Step, RootFailure> {
    let step0 = match last_step {
        Some(dt) if dt.is_finite() && dt > 0.0 => 0.999 * dt,
        _ => {
            // From the rate at which the distance grows: the part of dM/dt
            // across the layer below (the layer is tilted on overhangs).
            let d_dt = tube.surface(t_below, v).d_dt;
            let along = below.segment_direction(hint);
            let across = (d_dt - along * d_dt.dot(&along))
                .norm()
                .max(MIN_ACROSS_FRACTION * d_dt.norm());
            0.999 * delta_mm / across
        }
    };
    // The local search always descends from the column's own segment, so the
    // function is deterministic (a bracket found stays a bracket); the exact
    // query (any segment) confirms the root, and is used throughout if the
    // local descent stopped at a local minimum.
    // The foot segment of the last local query: where the exact query
    // starts (near the answer, it prunes most of the layer at once; the
    // start only orders the search, the answer is the nearest segment).
    let foot = std::cell::Cell::new(hint);
    let local = |p: &Point3| {
        let n = below.nearest_from(p, hint);
        foot.set(n.id);
        n.distance
    };
    let exact = |p: &Point3| {
        below
            .nearest_hinted(p, Some(foot.get()))
            .map_or(f64::INFINITY, |n| n.distance)
    };
    let x_tol = tol::PARAM * (1.0 + t_below.abs());
    let solve = |dist: &dyn Fn(&Point3) -> f64| {
        forward_root(
            |t| dist(&tube.point(t, v)) - delta_mm,
            t_below,
            -delta_mm,
            step0,
            t_hi,
            x_tol,
            BRENT_RESIDUAL_REL * delta_mm,
        )
    };
    let Some((t, evaluations, _)) = solve(&local)? else {
        return Ok(Step::End);
    };
    let residual = (exact(&tube.point(t, v)) - delta_mm).abs();
    if residual <= ACCEPT_RESIDUAL_REL * delta_mm {
        return Ok(Step::Point {
            t,
            evaluations,
            residual,
        });
    }
    match solve(&exact)? {
        Some((t, more, residual)) => Ok(Step::Point {
            t,
            evaluations: evaluations + more,
            residual,
        }),
        None => Ok(Step::End),
    }
}
