//! A plane of the part frame, given by a point and a unit normal; used to cut
//! layers past the end of a tube (SPEC §3.5).

use crate::math::{Point3, UnitVector3};

/// A plane given by a point and a unit normal (part frame).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Plane {
    /// A point of the plane (mm).
    pub point: Point3,
    /// Unit normal pointing out of the part (material is kept behind it).
    pub normal: UnitVector3,
}
