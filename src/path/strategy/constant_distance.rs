//! Constant local interlayer distance [SPEC §3.1.4; thesis §2.3, eq. 2.20–2.27]:
//! keep `v`, find `t` such that the distance from `M(t, v)` to the polyline of
//! the layer below equals `Delta`, moving forward from the column's point on
//! that layer (where the distance is zero).

use super::{forward_root, Step};
use crate::geometry::Tube;
use crate::math::RootFailure;
use crate::path::index::{SegmentId, SegmentIndex};

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
                .max(1e-3 * d_dt.norm());
            0.999 * delta_mm / across
        }
    };
    // Always descend from the column's own segment, so that the function is
    // deterministic (a bracket found stays a bracket).
    let delta_at = |t: f64| below.nearest_from(&tube.point(t, v), hint).distance;
    let x_tol = 1e-12 * (1.0 + t_below.abs());
    let found = forward_root(
        |t| delta_at(t) - delta_mm,
        t_below,
        -delta_mm,
        step0,
        t_hi,
        x_tol,
        1e-10 * delta_mm,
    )?;
    let Some((t, evaluations, _)) = found else {
        return Ok(Step::End);
    };
    // Confirm with the exact nearest segment (the local descent could have
    // stopped at a local minimum); redo the root find with exact queries if not.
    let p = tube.point(t, v);
    let local = below.nearest_from(&p, hint);
    let exact = below
        .nearest_hinted(&p, Some(local.id))
        .map_or(f64::INFINITY, |n| n.distance);
    if (exact - delta_mm).abs() <= 1e-9 * delta_mm {
        return Ok(Step::Point {
            t,
            evaluations,
            residual: (exact - delta_mm).abs(),
        });
    }
    let exact_delta = |t: f64| {
        below
            .nearest(&tube.point(t, v))
            .map_or(f64::INFINITY, |n| n.distance)
            - delta_mm
    };
    match forward_root(
        exact_delta,
        t_below,
        -delta_mm,
        step0,
        t_hi,
        x_tol,
        1e-10 * delta_mm,
    )? {
        Some((t, more, residual)) => Ok(Step::Point {
            t,
            evaluations: evaluations + more,
            residual,
        }),
        None => Ok(Step::End),
    }
}
