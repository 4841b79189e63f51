//! Circular helix guide (helical tube, one of our sample parts).

use super::GuideCurve;
use crate::math::{Point3, UnitVector3, Vector3};

/// Helix `Mg(t) = centre + r (cos t · radial0 + sin t · (axis × radial0)) + (pitch / 2π) t · axis`
/// in the part frame; `t` in rad. Right-handed about `axis` for a positive pitch.
#[derive(Debug, Clone, PartialEq)]
pub struct Helix {
    /// A point on the helix axis, at the height of `t = 0` (part frame, mm).
    pub centre: Point3,
    /// Unit axis of the helix.
    pub axis: UnitVector3,
    /// Unit vector from the axis to `Mg(0)`, perpendicular to `axis`.
    pub radial0: UnitVector3,
    /// Radius of the helix (mm, > 0).
    pub radius: f64,
    /// Rise per turn along `axis` (mm; negative for a left-handed helix).
    pub pitch: f64,
}

impl Helix {
    fn rise(&self) -> f64 {
        self.pitch / std::f64::consts::TAU
    }
    fn basis(&self) -> (Vector3, Vector3, Vector3) {
        let a = self.axis.into_inner();
        let e1 = self.radial0.into_inner();
        (e1, a.cross(&e1), a)
    }
}

impl GuideCurve for Helix {
    fn point(&self, t: f64) -> Point3 {
        let (e1, e2, a) = self.basis();
        let (s, c) = t.sin_cos();
        self.centre + (e1 * c + e2 * s) * self.radius + a * (self.rise() * t)
    }
    fn d1(&self, t: f64) -> Vector3 {
        let (e1, e2, a) = self.basis();
        let (s, c) = t.sin_cos();
        (-e1 * s + e2 * c) * self.radius + a * self.rise()
    }
    fn d2(&self, t: f64) -> Vector3 {
        let (e1, e2, _) = self.basis();
        let (s, c) = t.sin_cos();
        -(e1 * c + e2 * s) * self.radius
    }
    fn d3(&self, t: f64) -> Vector3 {
        let (e1, e2, _) = self.basis();
        let (s, c) = t.sin_cos();
        (e1 * s - e2 * c) * self.radius
    }
    fn curvature(&self, _t: f64) -> f64 {
        let c = self.rise();
        self.radius / (self.radius * self.radius + c * c)
    }
    fn arc_length(&self, t0: f64, t1: f64) -> f64 {
        let c = self.rise();
        (self.radius * self.radius + c * c).sqrt() * (t1 - t0)
    }
    fn param_at_arc_length(&self, t0: f64, s: f64) -> f64 {
        let c = self.rise();
        t0 + s / (self.radius * self.radius + c * c).sqrt()
    }
}
