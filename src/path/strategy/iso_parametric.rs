//! Iso-parametric layers [SPEC §3.1.3; thesis eq. 2.4–2.6, 2.16]: `Delta` is
//! the distance between points of the same `v` on consecutive layers. Solved
//! numerically for any tube (a 1-D root find on the chord along the iso-`v`
//! line); on the sphere and the torus it reproduces the closed forms of the
//! thesis (checked in the integration tests).

use super::{forward_root, Step, RESIDUAL_REL};
use crate::geometry::Tube;
use crate::math::{tol, RootFailure};

/// Next `t` of the column `v`: the first `t > t_below` with
/// `|M(t, v) − M(t_below, v)| = Delta`.
pub fn next_t(
    tube: &Tube,
    v: f64,
    t_below: f64,
    delta_mm: f64,
    t_hi: f64,
) -> Result<Step, RootFailure> {
    let p0 = tube.point(t_below, v);
    let speed = tube.surface(t_below, v).d_dt.norm();
    let x_tol = tol::PARAM_FINE * (1.0 + t_below.abs());
    match forward_root(
        |t| (tube.point(t, v) - p0).norm() - delta_mm,
        t_below,
        -delta_mm,
        0.9 * delta_mm / speed,
        t_hi,
        x_tol,
        RESIDUAL_REL * delta_mm,
    )? {
        Some((t, evaluations, residual)) => Ok(Step::Point {
            t,
            evaluations,
            residual,
        }),
        None => Ok(Step::End),
    }
}
