//! Circle-arc guide (torus, SPEC §2.2; thesis eq. 2.10).

use super::GuideCurve;
use crate::math::{Point3, UnitVector3, Vector3};

/// Circle `Mg(t) = centre + R (cos t · radial0 + sin t · tangent0)` in the part
/// frame; `t` in rad. `radial0` points from the centre to `Mg(0)`, `tangent0`
/// is the direction of travel at `t = 0` (the two are orthonormal).
#[derive(Debug, Clone, PartialEq)]
pub struct CircleArc {
    /// Centre of the circle (part frame, mm).
    pub centre: Point3,
    /// Radius `R` (mm, > 0).
    pub radius: f64,
    /// Unit vector from the centre to `Mg(0)`.
    pub radial0: UnitVector3,
    /// Unit direction of travel at `t = 0`, perpendicular to `radial0`.
    pub tangent0: UnitVector3,
}

impl CircleArc {
    fn dir(&self, t: f64) -> (Vector3, Vector3) {
        let (s, c) = t.sin_cos();
        let e1 = self.radial0.into_inner();
        let e2 = self.tangent0.into_inner();
        (e1 * c + e2 * s, -e1 * s + e2 * c)
    }
}

impl GuideCurve for CircleArc {
    fn point(&self, t: f64) -> Point3 {
        self.centre + self.dir(t).0 * self.radius
    }
    fn d1(&self, t: f64) -> Vector3 {
        self.dir(t).1 * self.radius
    }
    fn d2(&self, t: f64) -> Vector3 {
        -self.dir(t).0 * self.radius
    }
    fn d3(&self, t: f64) -> Vector3 {
        -self.dir(t).1 * self.radius
    }
    fn curvature(&self, _t: f64) -> f64 {
        1.0 / self.radius
    }
    fn arc_length(&self, t0: f64, t1: f64) -> f64 {
        self.radius * (t1 - t0)
    }
    fn param_at_arc_length(&self, t0: f64, s: f64) -> f64 {
        t0 + s / self.radius
    }
}
