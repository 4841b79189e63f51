//! Guide curves `Mg(t)` (part frame, mm) behind one trait, [`GuideCurve`]:
//! point and first three derivatives at `t`, curvature, arc length and its
//! inverse [SPEC §2; thesis eq. 2.22–2.26].

mod arc;
mod expr;
mod helix;
mod line;
mod pipe;
mod spline;

pub use arc::CircleArc;
pub use expr::{
    ExprCurve, Expression, MAX_EXPRESSION_LEN, MAX_EXPRESSION_NESTING, MAX_EXPRESSION_TOKENS,
    MAX_PARAMETER_USES,
};
pub use helix::Helix;
pub use line::Line;
pub use pipe::{PipeRun, PipeSegment};
pub use spline::CubicSpline;

use crate::math::{self, Point3, Vector3};

/// Newton on the arc length stops when `|arc_length - s|` is below this
/// fraction of `max(|s|, 1 mm)` (relative).
const ARC_LENGTH_REL_TOL: f64 = 1e-12;

/// A regular parametric curve `Mg(t)` in the part frame (mm), the spine of a tube.
///
/// `t` is the curve's own parameter (mm for lines, splines and pipe runs, rad
/// for arcs and helices, free for expression curves). Implementations must be
/// evaluable a little outside the part's `t` range so that paths can be
/// generated past the end of the part and truncated (SPEC §3.5).
pub trait GuideCurve: std::fmt::Debug + Send + Sync {
    /// Position `Mg(t)` (mm).
    fn point(&self, t: f64) -> Point3;
    /// First derivative `dMg/dt` (mm per parameter unit).
    fn d1(&self, t: f64) -> Vector3;
    /// Second derivative `d²Mg/dt²`.
    fn d2(&self, t: f64) -> Vector3;
    /// Third derivative `d³Mg/dt³` (used for the Frenet torsion).
    fn d3(&self, t: f64) -> Vector3;

    /// Curvature `kappa(t) = |Mg' x Mg''| / |Mg'|³` (1/mm).
    fn curvature(&self, t: f64) -> f64 {
        let d1 = self.d1(t);
        let n = d1.norm();
        self.d1(t).cross(&self.d2(t)).norm() / (n * n * n)
    }

    /// Arc length `s = ∫_{t0}^{t1} |Mg'(τ)| dτ` (mm, negative when `t1 < t0`)
    /// [eq. 2.26]. The default integrates numerically (Gauss–Legendre).
    fn arc_length(&self, t0: f64, t1: f64) -> f64 {
        let span = (t1 - t0).abs();
        if span == 0.0 {
            return 0.0;
        }
        // Panels scaled to the parameter span; 8-point rule per panel.
        let panels = 64;
        math::gauss_legendre(|t| self.d1(t).norm(), t0, t1, panels)
    }

    /// The parameter `t` reached after an arc length `s` (mm) from `t0`
    /// (the inverse of [`GuideCurve::arc_length`]). The default uses Newton
    /// steps safeguarded by bisection.
    fn param_at_arc_length(&self, t0: f64, s: f64) -> f64 {
        default_param_at_arc_length(self, t0, s)
    }
}

/// Newton on `arc_length(t0, t) - s` with a bisection safeguard.
fn default_param_at_arc_length<C: GuideCurve + ?Sized>(c: &C, t0: f64, s: f64) -> f64 {
    if s == 0.0 {
        return t0;
    }
    let speed0 = c.d1(t0).norm().max(f64::MIN_POSITIVE);
    // Bracket: grow the step until the arc length passes s.
    let dir = s.signum();
    let mut lo = t0;
    let mut hi = t0 + s / speed0;
    let mut grow = 0;
    while (c.arc_length(t0, hi) - s) * dir < 0.0 && grow < 60 {
        lo = hi;
        hi = t0 + (hi - t0) * 2.0;
        grow += 1;
    }
    let mut t = 0.5 * (lo + hi);
    for _ in 0..100 {
        let f = c.arc_length(t0, t) - s;
        if f.abs() < ARC_LENGTH_REL_TOL * s.abs().max(1.0) {
            break;
        }
        if (f * dir) < 0.0 {
            lo = t;
        } else {
            hi = t;
        }
        let newton = t - f / c.d1(t).norm();
        let inside = if lo < hi {
            newton > lo && newton < hi
        } else {
            newton > hi && newton < lo
        };
        t = if inside { newton } else { 0.5 * (lo + hi) };
    }
    t
}

#[cfg(test)]
mod tests;
