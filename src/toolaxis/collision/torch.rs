//! The torch model: a union of convex parts in the torch frame (origin at
//! the deposition point, `+Z` along the tool axis; mm), from a coaxial
//! nozzle-and-body description or an STL hull, and its pose at a path point.

use super::support::SupportedHull;
use crate::math::{Isometry3, Point3, Translation3, UnitQuaternion, UnitVector3, Vector3};
use crate::toolaxis::ToolAxisError;
use parry3d_f64::bounding_volume::{Aabb, BoundingVolume};
use parry3d_f64::shape::{ConvexPolyhedron, Cylinder, Shape};
use serde::{Deserialize, Serialize};

/// Segments of the circles of the nozzle and body polyhedra.
const CIRCLE_SEGMENTS: usize = 32;

/// Geometry of the torch, in the torch frame (origin at the deposition point,
/// `+Z` along the tool axis), mm. Plain data; [`Torch::new`] validates and
/// builds the shapes.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case", tag = "kind", deny_unknown_fields)]
pub enum TorchSpec {
    /// A coaxial torch: a nozzle (cone frustum from `tip_radius_mm` at
    /// `z = tip_offset_mm` to `nozzle_radius_mm` at `z = tip_offset_mm +
    /// nozzle_length_mm`) under a cylindrical body of radius `body_radius_mm`
    /// and length `body_length_mm`.
    Nozzle {
        /// Distance from the deposition point to the nozzle tip along `T` (mm):
        /// the region left out of the check (stick-out plus nozzle set-back).
        tip_offset_mm: f64,
        /// Outer radius at the nozzle tip (mm).
        tip_radius_mm: f64,
        /// Outer radius at the top of the nozzle (mm).
        nozzle_radius_mm: f64,
        /// Length of the nozzle (mm).
        nozzle_length_mm: f64,
        /// Radius of the body above the nozzle (mm).
        body_radius_mm: f64,
        /// Length of the body (mm).
        body_length_mm: f64,
    },
    /// The convex hull of points (torch frame, mm), e.g. the vertices of an
    /// STL model ([`Torch::from_stl_bytes`]). Conservative for a non-convex
    /// torch.
    Hull {
        /// The points (mm).
        points: Vec<[f64; 3]>,
    },
}

impl TorchSpec {
    /// A CMT welding torch, coarse: nozzle tip 15 mm above the deposition
    /// point (contact-tube-to-work distance plus set-back), gas nozzle Ø 20 mm
    /// at the tip widening to Ø 26 mm over 45 mm, body Ø 40 mm over 150 mm.
    pub fn cmt_torch() -> Self {
        TorchSpec::Nozzle {
            tip_offset_mm: 15.0,
            tip_radius_mm: 10.0,
            nozzle_radius_mm: 13.0,
            nozzle_length_mm: 45.0,
            body_radius_mm: 20.0,
            body_length_mm: 150.0,
        }
    }

    /// The thesis's polymer deposition nozzle, coarse (designed slender and
    /// symmetric, §3.1): tip 2 mm above the deposition point, Ø 6 mm tip cone
    /// widening to Ø 20 mm over 25 mm, body Ø 40 mm over 100 mm.
    pub fn pla_nozzle() -> Self {
        TorchSpec::Nozzle {
            tip_offset_mm: 2.0,
            tip_radius_mm: 3.0,
            nozzle_radius_mm: 10.0,
            nozzle_length_mm: 25.0,
            body_radius_mm: 20.0,
            body_length_mm: 100.0,
        }
    }

    /// Checks every field.
    ///
    /// # Errors
    /// [`ToolAxisError::InvalidTorch`] naming the field.
    pub fn validate(&self) -> Result<(), ToolAxisError> {
        let bad = |field: &'static str, reason: String| {
            Err(ToolAxisError::InvalidTorch { field, reason })
        };
        match self {
            TorchSpec::Nozzle {
                tip_offset_mm,
                tip_radius_mm,
                nozzle_radius_mm,
                nozzle_length_mm,
                body_radius_mm,
                body_length_mm,
            } => {
                if !(tip_offset_mm.is_finite() && *tip_offset_mm >= 0.0) {
                    return bad(
                        "tip_offset_mm",
                        format!("must be finite and >= 0, got {tip_offset_mm}"),
                    );
                }
                for (field, v) in [
                    ("tip_radius_mm", tip_radius_mm),
                    ("nozzle_radius_mm", nozzle_radius_mm),
                    ("nozzle_length_mm", nozzle_length_mm),
                    ("body_radius_mm", body_radius_mm),
                    ("body_length_mm", body_length_mm),
                ] {
                    if !(v.is_finite() && *v > 0.0) {
                        return bad(field, format!("must be positive and finite, got {v}"));
                    }
                }
                Ok(())
            }
            TorchSpec::Hull { points } => {
                if points.len() < 4 {
                    return bad(
                        "points",
                        format!("a hull needs at least 4 points, got {}", points.len()),
                    );
                }
                if let Some(i) = points.iter().position(|p| !p.iter().all(|c| c.is_finite())) {
                    return bad("points", format!("point {i} is not finite"));
                }
                Ok(())
            }
        }
    }
}

impl Default for TorchSpec {
    fn default() -> Self {
        Self::cmt_torch()
    }
}

/// A validated torch: convex parts in the torch frame.
#[derive(Clone)]
pub struct Torch {
    spec: TorchSpec,
    /// Convex parts and their poses in the torch frame (`torch_from_part`).
    pub(super) parts: Vec<(Isometry3, TorchPart)>,
}

/// One convex part of a torch.
#[derive(Clone)]
pub(super) enum TorchPart {
    Hull(Box<SupportedHull>),
    Cylinder(Cylinder),
}

impl TorchPart {
    pub(super) fn shape(&self) -> &dyn Shape {
        match self {
            TorchPart::Hull(h) => h.as_ref(),
            TorchPart::Cylinder(c) => c,
        }
    }
}

impl std::fmt::Debug for Torch {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Torch")
            .field("spec", &self.spec)
            .field("parts", &self.parts.len())
            .finish()
    }
}

/// Points of two coaxial circles (radii `r0` at `z0`, `r1` at `z1`).
fn frustum_points(r0: f64, z0: f64, r1: f64, z1: f64) -> Vec<Point3> {
    let mut pts = Vec::with_capacity(2 * CIRCLE_SEGMENTS);
    // Circumscribe the polygon so that it contains the true circle.
    let k = 1.0 / (std::f64::consts::PI / CIRCLE_SEGMENTS as f64).cos();
    for (r, z) in [(r0, z0), (r1, z1)] {
        for i in 0..CIRCLE_SEGMENTS {
            let a = std::f64::consts::TAU * i as f64 / CIRCLE_SEGMENTS as f64;
            pts.push(Point3::new(k * r * a.cos(), k * r * a.sin(), z));
        }
    }
    pts
}

impl Torch {
    /// The box (part frame, mm) around every convex part of the torch with
    /// its tip at `point` and its axis along `tool` (unit, towards the
    /// torch; part frame), as parry bounds each part at that pose.
    pub fn bounds(&self, point: &Point3, tool: &Vector3) -> Aabb {
        let pose = part_from_torch(point, tool);
        self.parts
            .iter()
            .map(|(local, part)| part.shape().compute_aabb(&(pose * local)))
            .reduce(|a, b| a.merged(&b))
            .unwrap_or_else(|| Aabb::new(*point, *point))
    }

    /// Builds the collision shapes of a torch.
    ///
    /// # Errors
    /// [`ToolAxisError::InvalidTorch`] for a bad field or a degenerate hull.
    pub fn new(spec: &TorchSpec) -> Result<Self, ToolAxisError> {
        spec.validate()?;
        let hull = |pts: &[Point3], field: &'static str| {
            ConvexPolyhedron::from_convex_hull(pts)
                .map(|h| Box::new(SupportedHull::new(h)))
                .ok_or_else(|| ToolAxisError::InvalidTorch {
                    field,
                    reason: "degenerate (flat) convex hull".into(),
                })
        };
        let parts = match spec {
            TorchSpec::Nozzle {
                tip_offset_mm,
                tip_radius_mm,
                nozzle_radius_mm,
                nozzle_length_mm,
                body_radius_mm,
                body_length_mm,
            } => {
                let z1 = tip_offset_mm + nozzle_length_mm;
                // parry's cylinder is along its local Y: turn Y onto Z.
                let body_pose = Isometry3::from_parts(
                    Translation3::new(0.0, 0.0, z1 + 0.5 * body_length_mm),
                    UnitQuaternion::from_axis_angle(
                        &UnitVector3::new_normalize(Vector3::x()),
                        std::f64::consts::FRAC_PI_2,
                    ),
                );
                vec![
                    (
                        Isometry3::identity(),
                        TorchPart::Hull(hull(
                            &frustum_points(*tip_radius_mm, *tip_offset_mm, *nozzle_radius_mm, z1),
                            "nozzle",
                        )?),
                    ),
                    (
                        body_pose,
                        TorchPart::Cylinder(Cylinder::new(0.5 * body_length_mm, *body_radius_mm)),
                    ),
                ]
            }
            TorchSpec::Hull { points } => {
                let pts: Vec<Point3> = points.iter().map(|p| Point3::from(*p)).collect();
                vec![(
                    Isometry3::identity(),
                    TorchPart::Hull(hull(&pts, "points")?),
                )]
            }
        };
        Ok(Self {
            spec: spec.clone(),
            parts,
        })
    }

    /// A torch from an STL model in the torch frame (origin at the deposition
    /// point, `+Z` along the tool axis, mm): the convex hull of its vertices.
    ///
    /// # Errors
    /// [`ToolAxisError::InvalidTorch`] if the STL cannot be read or is flat.
    pub fn from_stl_bytes(bytes: &[u8]) -> Result<Self, ToolAxisError> {
        let mut cursor = std::io::Cursor::new(bytes);
        let mesh = stl_io::read_stl(&mut cursor).map_err(|e| ToolAxisError::InvalidTorch {
            field: "stl",
            reason: format!("unreadable STL: {e}"),
        })?;
        let points = mesh
            .vertices
            .iter()
            .map(|v| [v.0[0] as f64, v.0[1] as f64, v.0[2] as f64])
            .collect();
        Self::new(&TorchSpec::Hull { points })
    }

    /// The specification it was built from.
    pub fn spec(&self) -> &TorchSpec {
        &self.spec
    }
}

/// Pose of the torch frame at a deposition point with tool axis `tool`
/// (part frame): `part_from_torch`.
pub fn part_from_torch(point: &Point3, tool: &Vector3) -> Isometry3 {
    let rot = UnitQuaternion::rotation_between(&Vector3::z(), tool).unwrap_or_else(|| {
        UnitQuaternion::from_axis_angle(
            &UnitVector3::new_normalize(Vector3::x()),
            std::f64::consts::PI,
        )
    });
    Isometry3::from_parts(Translation3::from(point.coords), rot)
}
