//! The per-point rules of each slicing strategy (SPEC §3.1): given a column
//! (fixed profile angle `v`) and where it stands on the layer below, the `t`
//! of its next point. The layer loop that drives them is in `path::march`.

/// The secant guess of [`forward_root`] is pushed past the root by this
/// fraction of the first step (relative), so that a root exactly at the guess
/// is still bracketed.
const SECANT_NUDGE_REL: f64 = 1e-9;
/// Residual tolerance of the iso-parametric and spiral steps' Brent search,
/// relative to Delta (`× delta_mm` gives mm).
pub(crate) const RESIDUAL_REL: f64 = 1e-11;

pub mod constant_distance;
pub mod iso_parametric;
pub mod normal_to_guide;
pub mod planar_z;
pub mod spiral;

/// Outcome of one column step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Step {
    /// The next point of the column is at this `t`.
    Point {
        /// Guide parameter.
        t: f64,
        /// Function evaluations spent.
        evaluations: usize,
        /// |residual| of the root find (mm).
        residual: f64,
    },
    /// The column has no point on this layer but may have one later
    /// (e.g. still inside the substrate); its position does not change.
    Skip,
    /// The column has no more points (it left the part or the search range).
    End,
}

/// Finds the first `t` in `(t0, t_hi]` where `g(t)` (with `g(t0) = g0 < 0`) turns
/// non-negative, stepping forward by `step0` (growing ×1.6 while `g` stays
/// well below zero), then refines with Brent. `Ok(None)` if `g` stays
/// negative up to `t_hi`.
pub(crate) fn forward_root(
    mut g: impl FnMut(f64) -> f64,
    t0: f64,
    g0: f64,
    step0: f64,
    t_hi: f64,
    x_tol: f64,
    y_tol: f64,
) -> Result<Option<(f64, usize, f64)>, crate::math::RootFailure> {
    let mut evaluations = 0;
    let mut ta = t0;
    let mut ga = g0;
    let mut gb;
    let mut step = step0;
    let mut tb = (t0 + step).min(t_hi);
    loop {
        gb = g(tb);
        evaluations += 1;
        if !gb.is_finite() {
            return Err(crate::math::RootFailure::NonFinite);
        }
        if gb >= 0.0 {
            break;
        }
        if tb >= t_hi {
            return Ok(None);
        }
        // Secant extrapolation toward the root, overshooting slightly so the
        // next point brackets it; at least ×1.6 growth when far off.
        let slope = (gb - ga) / (tb - ta);
        let secant = if slope > 0.0 {
            -gb / slope * 1.02 + SECANT_NUDGE_REL * step0
        } else {
            f64::INFINITY
        };
        let grow = step * 1.6;
        step = if secant.is_finite() && secant < grow {
            secant
        } else {
            grow
        };
        ta = tb;
        ga = gb;
        tb = (tb + step).min(t_hi);
        if evaluations > 400 {
            return Err(crate::math::RootFailure::NotConverged);
        }
    }
    let r = crate::math::brent_bracketed(&mut g, (ta, ga), (tb, gb), x_tol, y_tol)?;
    Ok(Some((
        r.x,
        evaluations + r.iterations + 1,
        r.residual.abs(),
    )))
}
