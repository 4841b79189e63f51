//! Planar slicing [SPEC §3.1.1; thesis eq. 2.3, 2.12–2.14]: layer `k` is the
//! tube ∩ plane `Z = z_k` (part frame), found on each iso-`v` line.

use super::{forward_root, Step};
use crate::geometry::Tube;
use crate::math::{tol, RootFailure};

/// Floor of the first step in `t` (parameter units): a column already at the
/// slice height still moves forward.
const MIN_FIRST_STEP: f64 = 1e-9;
/// Residual (mm of height) at which Brent's method stops on the slice plane.
const Z_RESIDUAL_MM: f64 = 1e-11;

/// Next `t` of the column `v` on the plane `Z = z` (mm): the first crossing
/// above `t_below`. A column already above `z` is skipped (it meets a later
/// plane); a column that never reaches `z` before `t_hi` ends.
pub fn next_t(tube: &Tube, v: f64, t_below: f64, z: f64, t_hi: f64) -> Result<Step, RootFailure> {
    let z0 = tube.point(t_below, v).z;
    if z0 >= z {
        return Ok(Step::Skip);
    }
    let speed = tube.surface(t_below, v).d_dt.norm();
    // First step: half the height still to climb (in arc length), so that a
    // column turning down again is not jumped over.
    let step = ((z - z0) / speed).max(MIN_FIRST_STEP) * 0.5;
    let x_tol = tol::PARAM_FINE * (1.0 + t_below.abs());
    match forward_root(
        |t| tube.point(t, v).z - z,
        t_below,
        z0 - z,
        step,
        t_hi,
        x_tol,
        Z_RESIDUAL_MM,
    )? {
        Some((t, evaluations, residual)) => Ok(Step::Point {
            t,
            evaluations,
            residual,
        }),
        None => Ok(Step::End),
    }
}
