//! Straight guide line (parts of revolution, SPEC §2.1).

use super::GuideCurve;
use crate::math::{Point3, UnitVector3, Vector3};

/// Straight line `Mg(t) = origin + t·direction` in the part frame; `t` in mm.
#[derive(Debug, Clone, PartialEq)]
pub struct Line {
    /// Point at `t = 0` (part frame, mm).
    pub origin: Point3,
    /// Unit direction of increasing `t` (part frame).
    pub direction: UnitVector3,
}

impl GuideCurve for Line {
    fn point(&self, t: f64) -> Point3 {
        self.origin + self.direction.into_inner() * t
    }
    fn d1(&self, _t: f64) -> Vector3 {
        self.direction.into_inner()
    }
    fn d2(&self, _t: f64) -> Vector3 {
        Vector3::zeros()
    }
    fn d3(&self, _t: f64) -> Vector3 {
        Vector3::zeros()
    }
    fn curvature(&self, _t: f64) -> f64 {
        0.0
    }
    fn arc_length(&self, t0: f64, t1: f64) -> f64 {
        t1 - t0
    }
    fn param_at_arc_length(&self, t0: f64, s: f64) -> f64 {
        t0 + s
    }
}
