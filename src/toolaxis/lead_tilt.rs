//! Tool axis from lead and tilt angles [SPEC §4; thesis eq. 2.30–2.32].
//!
//! The thesis rotates `b` by `theta_T = atan2(sqrt(tan² theta_t + tan² theta_n), 1)`
//! about `k = (tan theta_t, −tan theta_n, 0)/norm` in the `(t, n, b)` frame
//! and takes the third row of the Rodrigues matrix. Written out, that row is
//! `cos theta_T (tan theta_n, tan theta_t, 1)`, i.e.
//!
//! ```text
//! T = normalise( b + tan(theta_n) t + tan(theta_t) n )
//! ```
//!
//! so that `T` projected on the feed plane `(t, b)` makes the angle `theta_n`
//! with `b`, and projected on the normal plane `(n, b)` the angle `theta_t`.
//! [`tool_axis`] uses this closed form; [`tool_axis_rodrigues`] is the literal
//! eq. 2.30–2.32 (tests check they agree). Angles in rad, vectors unit, part
//! frame.

use super::LocalFrame;
use crate::math::{Matrix3, Vector3};

/// Tool axis `T` of a frame for lead `theta_n` and tilt `theta_t` (rad,
/// |.| < π/2): `normalise(b + tan(theta_n) t + tan(theta_t) n)` (eq. 2.32).
pub fn tool_axis(frame: &LocalFrame, lead_rad: f64, tilt_rad: f64) -> Vector3 {
    if lead_rad == 0.0 && tilt_rad == 0.0 {
        return frame.build;
    }
    (frame.build + frame.tangent * lead_rad.tan() + frame.normal * tilt_rad.tan()).normalize()
}

/// Rodrigues rotation matrix of angle `theta` (rad) about the unit axis `k`.
pub fn rodrigues(k: &Vector3, theta: f64) -> Matrix3 {
    let (s, c) = theta.sin_cos();
    let kx = Matrix3::new(0.0, -k.z, k.y, k.z, 0.0, -k.x, -k.y, k.x, 0.0);
    Matrix3::identity() + kx * s + kx * kx * (1.0 - c)
}

/// The tool axis in local `(t, n, b)` coordinates, literally as eq. 2.30–2.32:
/// `theta_T` (eq. 2.30), axis `k` (eq. 2.31), and `T = [0 0 1] · R(k, theta_T)`
/// (the third row of the Rodrigues matrix, eq. 2.32). `(0, 0)` gives
/// `(0, 0, 1)`.
pub fn tool_axis_rodrigues(lead_rad: f64, tilt_rad: f64) -> Vector3 {
    let (tn, tt) = (lead_rad.tan(), tilt_rad.tan());
    let norm = (tt * tt + tn * tn).sqrt();
    if norm == 0.0 {
        return Vector3::z();
    }
    let theta_t = norm.atan2(1.0);
    let k = Vector3::new(tt / norm, -tn / norm, 0.0);
    let r = rodrigues(&k, theta_t);
    r.row(2).transpose()
}

/// Lead and tilt `(theta_n, theta_t)` (rad) of a direction `tool` relative to a
/// frame: the angles of its projections on the feed and normal planes with
/// `b` — the inverse of [`tool_axis`] for `tool · b > 0`.
pub fn lead_tilt_of(frame: &LocalFrame, tool: &Vector3) -> (f64, f64) {
    let b = tool.dot(&frame.build);
    (
        tool.dot(&frame.tangent).atan2(b),
        tool.dot(&frame.normal).atan2(b),
    )
}
