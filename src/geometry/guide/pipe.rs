//! Pipe run: straight legs and circular bends chained tangentially, the way a
//! piping designer describes an elbow (one of our sample parts). Frenet frames
//! are undefined on the straight legs; the rotation-minimising frame is not.

use super::GuideCurve;
use crate::geometry::GeometryError;
use crate::math::{tol, Point3, UnitVector3, Vector3};

/// One piece of a [`PipeRun`], as given by the user.
#[derive(Debug, Clone, PartialEq)]
pub enum PipeSegment {
    /// A straight leg of the given length (mm, > 0).
    Straight {
        /// Length (mm).
        length: f64,
    },
    /// A circular bend of centre-line radius `radius` (mm) turning by `angle`
    /// (rad, in (0, 2π)) toward `toward` (part frame; its component
    /// perpendicular to the current direction gives the turning side).
    Bend {
        /// Centre-line radius of the bend (mm).
        radius: f64,
        /// Bend angle (rad).
        angle: f64,
        /// Direction the bend turns toward (part frame).
        toward: Vector3,
    },
}

#[derive(Debug, Clone)]
struct Piece {
    /// Arc length at the start of the piece (mm).
    s0: f64,
    length: f64,
    start: Point3,
    dir: Vector3,
    /// For bends: unit vector from the start point to the bend centre, and radius.
    bend: Option<(Vector3, f64)>,
}

/// Tangent-continuous chain of straight legs and bends; `t` is the arc length
/// from the start (mm). Before the start and after the end the run continues
/// straight along its end tangents.
#[derive(Debug, Clone)]
pub struct PipeRun {
    pieces: Vec<Piece>,
}

impl PipeRun {
    /// Chains `segments` from `start` along `direction` (part frame).
    ///
    /// # Errors
    /// [`GeometryError::Pipe`] naming the segment index when a length, radius
    /// or angle is not positive and finite, or a bend's `toward` is parallel to
    /// the current direction.
    pub fn new(
        start: Point3,
        direction: UnitVector3,
        segments: &[PipeSegment],
    ) -> Result<Self, GeometryError> {
        if segments.is_empty() {
            return Err(GeometryError::Pipe {
                index: 0,
                reason: "a pipe run needs at least one segment".into(),
            });
        }
        let mut pieces = Vec::with_capacity(segments.len());
        let mut p = start;
        let mut d = direction.into_inner();
        let mut s = 0.0;
        for (i, seg) in segments.iter().enumerate() {
            let bad = |reason: &str| GeometryError::Pipe {
                index: i,
                reason: reason.to_string(),
            };
            match *seg {
                PipeSegment::Straight { length } => {
                    if !(length.is_finite() && length > 0.0) {
                        return Err(bad("straight length must be positive and finite (mm)"));
                    }
                    pieces.push(Piece {
                        s0: s,
                        length,
                        start: p,
                        dir: d,
                        bend: None,
                    });
                    p += d * length;
                    s += length;
                }
                PipeSegment::Bend {
                    radius,
                    angle,
                    toward,
                } => {
                    if !(radius.is_finite() && radius > 0.0) {
                        return Err(bad("bend radius must be positive and finite (mm)"));
                    }
                    if !(angle.is_finite() && angle > 0.0 && angle < std::f64::consts::TAU) {
                        return Err(bad("bend angle must be in (0, 360) degrees"));
                    }
                    let perp = toward - d * d.dot(&toward);
                    if !(perp.norm() > tol::ANGLE_RAD * toward.norm().max(1.0))
                        || !perp.iter().all(|c| c.is_finite())
                    {
                        return Err(bad(
                            "bend `toward` must not be parallel to the incoming direction",
                        ));
                    }
                    let n = perp.normalize();
                    let length = radius * angle;
                    pieces.push(Piece {
                        s0: s,
                        length,
                        start: p,
                        dir: d,
                        bend: Some((n, radius)),
                    });
                    let (sn, cs) = angle.sin_cos();
                    p = p + n * radius * (1.0 - cs) + d * radius * sn;
                    d = d * cs + n * sn;
                    s += length;
                }
            }
        }
        Ok(Self { pieces })
    }

    /// Total centre-line length (mm): the parameter range is `[0, length]`.
    pub fn length(&self) -> f64 {
        let last = self.pieces.last().expect("non-empty");
        last.s0 + last.length
    }

    /// `[point, d1, d2, d3]` at arc length `t`.
    fn eval(&self, t: f64) -> [Vector3; 4] {
        let idx = self
            .pieces
            .partition_point(|pc| pc.s0 <= t)
            .saturating_sub(1);
        let pc = &self.pieces[idx];
        let u = t - pc.s0;
        let z = Vector3::zeros();
        let straight = |start: Point3, dir: Vector3, u: f64| [(start + dir * u).coords, dir, z, z];
        match pc.bend {
            Some((n, r)) if u <= pc.length || idx + 1 < self.pieces.len() => {
                if u < 0.0 {
                    return straight(pc.start, pc.dir, u);
                }
                let phi = u / r;
                let (sn, cs) = phi.sin_cos();
                let d = pc.dir;
                [
                    (pc.start + n * r * (1.0 - cs) + d * r * sn).coords,
                    n * sn + d * cs,
                    (n * cs - d * sn) / r,
                    (-n * sn - d * cs) / (r * r),
                ]
            }
            Some((n, r)) => {
                // Past the end of a final bend: continue straight.
                let phi = pc.length / r;
                let (sn, cs) = phi.sin_cos();
                let end = pc.start + n * r * (1.0 - cs) + pc.dir * r * sn;
                let dir = n * sn + pc.dir * cs;
                straight(end, dir, u - pc.length)
            }
            None => straight(pc.start, pc.dir, u),
        }
    }
}

impl GuideCurve for PipeRun {
    fn point(&self, t: f64) -> Point3 {
        Point3::from(self.eval(t)[0])
    }
    fn d1(&self, t: f64) -> Vector3 {
        self.eval(t)[1]
    }
    fn d2(&self, t: f64) -> Vector3 {
        self.eval(t)[2]
    }
    fn d3(&self, t: f64) -> Vector3 {
        self.eval(t)[3]
    }
    fn arc_length(&self, t0: f64, t1: f64) -> f64 {
        t1 - t0
    }
    fn param_at_arc_length(&self, t0: f64, s: f64) -> f64 {
        t0 + s
    }
}
