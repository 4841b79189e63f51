//! The torch as a collision shape, checked along the path against the part
//! built so far and the substrate, and an avoidance option that tilts the
//! tool axis within a cone, smoothly along each layer [SPEC §4 "Beyond";
//! parry3d distance queries]. Part frame, mm, rad.
//!
//! * **Torch frame**: origin at the deposition point (the path point), `+Z`
//!   along the tool axis `T` toward the torch. The torch is a union of convex
//!   parts: a coaxial nozzle (cone frustum) and body (cylinder) starting
//!   `tip_offset_mm` above the deposition point — so the wire stick-out and the
//!   nozzle tip region are left out — or the convex hull of an STL model given
//!   in the torch frame. It is placed by the smallest rotation taking `+Z` to
//!   `T` (the rotation about `T` is free; an axisymmetric torch does not care).
//! * **Part built so far** at a point of slice `k`: every layer of slices
//!   `0..k` as capsules of radius `bead_radius_mm` along the path (a parry
//!   polyline with its BVH, minus the radius). The slice being laid is left
//!   out (the bead under the torch is in contact with the arc by design).
//! * **Substrate**: a half-space (plane) or a long solid cylinder; meshes
//!   are not checked (reported).
//! * **Clearance** = smallest distance from the torch to those obstacles (mm);
//!   `<= 0` is a collision. Distances of overlapping shapes are 0 in parry, so a
//!   penetration shows as `-bead_radius_mm` (beads) or `0` (substrate).

use super::rules::{angle, smooth_angles};
use super::{LocalFrame, ToolAxisError};
use crate::geometry::Substrate;
use crate::math::{Isometry3, Point3, Translation3, UnitQuaternion, UnitVector3, Vector3};
use crate::path::Path;
use parry3d_f64::query;
use parry3d_f64::shape::{ConvexPolyhedron, Cylinder, HalfSpace, Polyline, Shape};
use rayon::prelude::*;
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
    parts: Vec<(Isometry3, TorchPart)>,
}

/// One convex part of a torch.
#[derive(Clone)]
enum TorchPart {
    Hull(ConvexPolyhedron),
    Cylinder(Cylinder),
}

impl TorchPart {
    fn shape(&self) -> &dyn Shape {
        match self {
            TorchPart::Hull(h) => h,
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
    /// Builds the collision shapes of a torch.
    ///
    /// # Errors
    /// [`ToolAxisError::InvalidTorch`] for a bad field or a degenerate hull.
    pub fn new(spec: &TorchSpec) -> Result<Self, ToolAxisError> {
        spec.validate()?;
        let hull = |pts: &[Point3], field: &'static str| {
            ConvexPolyhedron::from_convex_hull(pts).ok_or_else(|| ToolAxisError::InvalidTorch {
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

/// Options of [`check_collisions`]. Plain data.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct CollisionOptions {
    /// Radius of the capsules standing for the deposited beads (mm, >= 0):
    /// half the bead width.
    pub bead_radius_mm: f64,
    /// Check the torch against the substrate too.
    pub check_substrate: bool,
}

impl Default for CollisionOptions {
    fn default() -> Self {
        Self {
            bead_radius_mm: 2.0,
            check_substrate: true,
        }
    }
}

impl CollisionOptions {
    /// Checks every field.
    ///
    /// # Errors
    /// [`ToolAxisError::InvalidOption`] naming the field.
    pub fn validate(&self) -> Result<(), ToolAxisError> {
        if !(self.bead_radius_mm.is_finite() && self.bead_radius_mm >= 0.0) {
            return Err(ToolAxisError::InvalidOption {
                field: "bead_radius_mm",
                reason: format!("must be finite and >= 0, got {}", self.bead_radius_mm),
            });
        }
        Ok(())
    }
}

/// Clearance of the torch along one layer.
#[derive(Debug, Clone, PartialEq)]
pub struct LayerClearance {
    /// Layer index in `path.layers`.
    pub layer: usize,
    /// Smallest clearance over the layer (mm); `f64::INFINITY` when nothing
    /// is there to hit.
    pub min_clearance_mm: f64,
    /// Point where it occurs.
    pub min_at_point: usize,
    /// First colliding point (clearance <= 0), in deposition order.
    pub first_collision: Option<usize>,
    /// Number of colliding points.
    pub colliding_points: usize,
}

/// Result of [`check_collisions`]: per layer and overall.
#[derive(Debug, Clone, PartialEq)]
pub struct CollisionReport {
    /// One entry per layer.
    pub layers: Vec<LayerClearance>,
    /// First colliding point of the path, `(layer, point)`.
    pub first_collision: Option<(usize, usize)>,
    /// Colliding points in total.
    pub colliding_points: usize,
    /// Smallest clearance over the path (mm).
    pub min_clearance_mm: f64,
    /// Whether the substrate was part of the check (false for meshes or when
    /// switched off).
    pub substrate_checked: bool,
}

impl CollisionReport {
    fn from_layers(layers: Vec<LayerClearance>, substrate_checked: bool) -> Self {
        let first_collision = layers
            .iter()
            .find_map(|l| l.first_collision.map(|p| (l.layer, p)));
        Self {
            colliding_points: layers.iter().map(|l| l.colliding_points).sum(),
            min_clearance_mm: layers
                .iter()
                .map(|l| l.min_clearance_mm)
                .fold(f64::INFINITY, f64::min),
            first_collision,
            layers,
            substrate_checked,
        }
    }
}

/// The obstacles seen from one slice.
struct Obstacles<'a> {
    built: Option<Polyline>,
    bead_radius: f64,
    substrate: Option<&'a (Isometry3, Box<dyn Shape>)>,
}

impl<'a> Obstacles<'a> {
    fn new(
        path: &Path,
        slice: usize,
        substrate: Option<&'a (Isometry3, Box<dyn Shape>)>,
        bead_radius: f64,
    ) -> Self {
        let mut vertices = Vec::new();
        let mut indices: Vec<[u32; 2]> = Vec::new();
        for l in path.layers.iter().filter(|l| l.slice < slice) {
            let base = vertices.len() as u32;
            let n = l.points.len() as u32;
            vertices.extend(l.points.iter().map(|p| p.position));
            indices.extend((0..n.saturating_sub(1)).map(|i| [base + i, base + i + 1]));
            if l.closed && n > 2 {
                indices.push([base + n - 1, base]);
            }
        }
        let built = (!indices.is_empty()).then(|| Polyline::new(vertices, Some(indices)));
        Self {
            built,
            bead_radius,
            substrate,
        }
    }

    /// Whether the clearance of the torch at `point` with axis `tool` exceeds
    /// `margin` (mm): bounded queries that only visit obstacles within the
    /// margin, much cheaper than [`Obstacles::clearance`].
    fn is_clear(
        &self,
        torch: &Torch,
        point: &Point3,
        tool: &Vector3,
        margin: f64,
    ) -> Result<bool, ToolAxisError> {
        let torch_pose = part_from_torch(point, tool);
        for (local, part) in &torch.parts {
            let pose = torch_pose * local;
            let part = part.shape();
            if let Some(built) = &self.built {
                let q = query::closest_points(
                    &pose,
                    part,
                    &Isometry3::identity(),
                    built,
                    margin + self.bead_radius,
                )
                .map_err(|_| ToolAxisError::UnsupportedQuery {
                    what: "the built part",
                })?;
                if !matches!(q, query::ClosestPoints::Disjoint) {
                    return Ok(false);
                }
            }
            if let Some((iso, shape)) = self.substrate {
                let q = query::closest_points(&pose, part, iso, shape.as_ref(), margin).map_err(
                    |_| ToolAxisError::UnsupportedQuery {
                        what: "the substrate",
                    },
                )?;
                if !matches!(q, query::ClosestPoints::Disjoint) {
                    return Ok(false);
                }
            }
        }
        Ok(true)
    }

    /// Clearance of the torch placed at `point` with axis `tool` (mm).
    fn clearance(
        &self,
        torch: &Torch,
        point: &Point3,
        tool: &Vector3,
    ) -> Result<f64, ToolAxisError> {
        let torch_pose = part_from_torch(point, tool);
        let mut best = f64::INFINITY;
        for (local, part) in &torch.parts {
            let pose = torch_pose * local;
            let part = part.shape();
            if let Some(built) = &self.built {
                let d =
                    query::distance(&pose, part, &Isometry3::identity(), built).map_err(|_| {
                        ToolAxisError::UnsupportedQuery {
                            what: "the built part",
                        }
                    })?;
                best = best.min(d - self.bead_radius);
            }
            if let Some((iso, shape)) = self.substrate {
                let d = query::distance(&pose, part, iso, shape.as_ref()).map_err(|_| {
                    ToolAxisError::UnsupportedQuery {
                        what: "the substrate",
                    }
                })?;
                best = best.min(d);
            }
        }
        Ok(best)
    }
}

/// The substrate as a parry shape and its pose, sized from the path.
fn substrate_shape(path: &Path, substrate: &Substrate) -> Option<(Isometry3, Box<dyn Shape>)> {
    match substrate {
        Substrate::Plane { point, normal } => Some((
            Isometry3::translation(point.x, point.y, point.z),
            Box::new(HalfSpace::new(*normal)),
        )),
        Substrate::Cylinder {
            axis_point,
            axis,
            radius,
        } => {
            // Centre it on the path's projection on the axis, long enough to
            // reach past the path and a torch in every direction.
            let pts: Vec<&Point3> = path
                .layers
                .iter()
                .flat_map(|l| l.points.iter().map(|p| &p.position))
                .collect();
            let n = pts.len().max(1) as f64;
            let c = pts.iter().fold(Vector3::zeros(), |a, p| a + p.coords) / n;
            let s = (c - axis_point.coords).dot(axis);
            let extent = pts
                .iter()
                .map(|p| (p.coords - c).norm())
                .fold(0.0, f64::max);
            let centre = axis_point + axis.into_inner() * s;
            let rot = UnitQuaternion::rotation_between(&Vector3::y(), axis).unwrap_or_else(|| {
                UnitQuaternion::from_axis_angle(
                    &UnitVector3::new_normalize(Vector3::x()),
                    std::f64::consts::PI,
                )
            });
            Some((
                Isometry3::from_parts(Translation3::from(centre.coords), rot),
                Box::new(Cylinder::new(extent + 2.0 * radius + 500.0, *radius)),
            ))
        }
        Substrate::Mesh(_) => None,
    }
}

fn check_shape(path: &Path, frames: &[Vec<LocalFrame>]) -> Result<(), ToolAxisError> {
    super::rules::check_shape(path, frames.iter().map(Vec::len))
}

fn layer_clearances(
    obstacles: &Obstacles,
    torch: &Torch,
    path: &Path,
    li: usize,
    axes: &[Vector3],
) -> Result<Vec<f64>, ToolAxisError> {
    path.layers[li]
        .points
        .iter()
        .zip(axes)
        .map(|(p, a)| obstacles.clearance(torch, &p.position, a))
        .collect()
}

fn summarise(li: usize, c: &[f64]) -> LayerClearance {
    let (min_at_point, min_clearance_mm) = c
        .iter()
        .copied()
        .enumerate()
        .min_by(|a, b| a.1.total_cmp(&b.1))
        .unwrap_or((0, f64::INFINITY));
    LayerClearance {
        layer: li,
        min_clearance_mm,
        min_at_point,
        first_collision: c.iter().position(|&x| x <= 0.0),
        colliding_points: c.iter().filter(|&&x| x <= 0.0).count(),
    }
}

/// Checks the torch along the path with the tool axes of `frames`
/// (`frames[layer][point].tool`, same shape as `path.layers`) against the
/// part built so far and, when given, the substrate. Layers in parallel.
///
/// # Errors
/// [`ToolAxisError`] for bad options, a shape mismatch, or an unsupported
/// query.
pub fn check_collisions(
    path: &Path,
    frames: &[Vec<LocalFrame>],
    substrate: Option<&Substrate>,
    torch: &Torch,
    opts: &CollisionOptions,
) -> Result<CollisionReport, ToolAxisError> {
    opts.validate()?;
    check_shape(path, frames)?;
    let sub = substrate
        .filter(|_| opts.check_substrate)
        .and_then(|s| substrate_shape(path, s));
    let layers = (0..path.layers.len())
        .into_par_iter()
        .map(|li| {
            let obstacles = Obstacles::new(
                path,
                path.layers[li].slice,
                sub.as_ref(),
                opts.bead_radius_mm,
            );
            let axes: Vec<Vector3> = frames[li].iter().map(|f| f.tool).collect();
            let c = layer_clearances(&obstacles, torch, path, li, &axes)?;
            Ok(summarise(li, &c))
        })
        .collect::<Result<Vec<_>, ToolAxisError>>()?;
    Ok(CollisionReport::from_layers(layers, sub.is_some()))
}

/// Options of [`avoid_collisions`]. Plain data.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct AvoidanceOptions {
    /// Largest deviation of the tool axis from its nominal direction (rad,
    /// in (0, π/2)): the user's cone.
    pub cone_half_angle_rad: f64,
    /// Angular step of the search rings (rad, > 0).
    pub step_rad: f64,
    /// Directions per search ring (>= 4).
    pub azimuths: usize,
    /// Clearance to reach (mm, >= 0).
    pub margin_mm: f64,
    /// Bound on the rate of change of the corrections along a layer (rad per
    /// mm of path, > 0): a correction fades in and out over neighbouring
    /// points at this rate.
    pub max_rate_rad_per_mm: f64,
    /// Search rounds (>= 1): a round re-searches the points a blended
    /// correction did not clear.
    pub rounds: usize,
}

impl Default for AvoidanceOptions {
    fn default() -> Self {
        Self {
            cone_half_angle_rad: 60f64.to_radians(),
            step_rad: 2.5f64.to_radians(),
            azimuths: 16,
            margin_mm: 1.0,
            max_rate_rad_per_mm: 0.05,
            rounds: 3,
        }
    }
}

impl AvoidanceOptions {
    /// Checks every field.
    ///
    /// # Errors
    /// [`ToolAxisError::InvalidOption`] naming the field.
    pub fn validate(&self) -> Result<(), ToolAxisError> {
        let bad = |field: &'static str, reason: String| {
            Err(ToolAxisError::InvalidOption { field, reason })
        };
        if !(self.cone_half_angle_rad > 0.0
            && self.cone_half_angle_rad < std::f64::consts::FRAC_PI_2)
        {
            return bad(
                "cone_half_angle_rad",
                format!("must be in (0, π/2), got {}", self.cone_half_angle_rad),
            );
        }
        if !(self.step_rad > 0.0 && self.step_rad.is_finite()) {
            return bad(
                "step_rad",
                format!("must be positive, got {}", self.step_rad),
            );
        }
        if self.azimuths < 4 {
            return bad("azimuths", format!("must be >= 4, got {}", self.azimuths));
        }
        if !(self.margin_mm >= 0.0 && self.margin_mm.is_finite()) {
            return bad("margin_mm", format!("must be >= 0, got {}", self.margin_mm));
        }
        if !(self.max_rate_rad_per_mm > 0.0 && self.max_rate_rad_per_mm.is_finite()) {
            return bad(
                "max_rate_rad_per_mm",
                format!("must be positive, got {}", self.max_rate_rad_per_mm),
            );
        }
        if self.rounds == 0 {
            return bad("rounds", "must be >= 1".into());
        }
        Ok(())
    }
}

/// What [`avoid_collisions`] did.
#[derive(Debug, Clone, PartialEq)]
pub struct AvoidanceReport {
    /// Clearances with the input axes.
    pub before: CollisionReport,
    /// Clearances with the corrected axes.
    pub after: CollisionReport,
    /// Points whose axis was changed.
    pub corrected_points: usize,
    /// Largest change of an axis (rad).
    pub max_correction_rad: f64,
    /// Points for which no direction in the cone reached the margin,
    /// `(layer, point)`, first 100.
    pub unresolved: Vec<(usize, usize)>,
}

/// Unit basis `(e1, e2)` perpendicular to `tool`, `e1` along the tangent.
fn cone_basis(f: &LocalFrame, tool: &Vector3) -> (Vector3, Vector3) {
    let e1 = f.tangent - tool * f.tangent.dot(tool);
    let e1 = if e1.norm() > 1e-9 {
        e1.normalize()
    } else {
        crate::math::any_perpendicular(tool)
    };
    (e1, tool.cross(&e1))
}

/// `tool` tilted by the correction `c = angle · (cos φ, sin φ)` in the cone
/// basis of the frame.
fn corrected(f: &LocalFrame, tool: &Vector3, c: &[f64; 2]) -> Vector3 {
    let m = c[0].hypot(c[1]);
    if m == 0.0 {
        return *tool;
    }
    let (e1, e2) = cone_basis(f, tool);
    let dir = (e1 * c[0] + e2 * c[1]) / m;
    (tool * m.cos() + dir * m.sin()).normalize()
}

/// Tilts the tool axes, within a cone around each nominal axis, to clear the
/// torch from the part built so far and the substrate, smoothly along each
/// layer. For each point that misses the margin, rings of directions
/// (`azimuths` per ring, `step_rad` apart) are searched for the smallest ring
/// with a direction reaching the margin (bounded, cheap queries), taking the
/// bisector of its widest free arc — starting from the previous
/// point's ring, going down while rings clear and up otherwise (clearance is
/// assumed to grow with the tilt; the result is re-checked) — and that
/// direction kept; the corrections (angle and direction in the
/// local `(t, T × t)` basis) are then spread along the layer as an upper
/// envelope falling off at `max_rate_rad_per_mm`, re-searched where that
/// did not clear, and the correction field finally smoothed to that rate. Returns the
/// new frames (only `tool` changes) and a report; points left unresolved are
/// reported, not errors. The smoothing acts on the corrections, expressed
/// in each point's local basis, so the rate bound applies to the change of
/// the correction, on top of the nominal axes' own variation. Layers in
/// parallel.
///
/// # Errors
/// [`ToolAxisError`] for bad options, a shape mismatch, or an unsupported
/// query.
pub fn avoid_collisions(
    path: &Path,
    frames: &[Vec<LocalFrame>],
    substrate: Option<&Substrate>,
    torch: &Torch,
    copts: &CollisionOptions,
    aopts: &AvoidanceOptions,
) -> Result<(Vec<Vec<LocalFrame>>, AvoidanceReport), ToolAxisError> {
    copts.validate()?;
    aopts.validate()?;
    check_shape(path, frames)?;
    let sub = substrate
        .filter(|_| copts.check_substrate)
        .and_then(|s| substrate_shape(path, s));
    struct LayerOut {
        frames: Vec<LocalFrame>,
        before: LayerClearance,
        after: LayerClearance,
        corrected: usize,
        max_corr: f64,
        unresolved: Vec<usize>,
    }
    let outs = (0..path.layers.len())
        .into_par_iter()
        .map(|li| -> Result<LayerOut, ToolAxisError> {
            let layer = &path.layers[li];
            let obstacles = Obstacles::new(path, layer.slice, sub.as_ref(), copts.bead_radius_mm);
            let fr = &frames[li];
            let nominal: Vec<Vector3> = fr.iter().map(|f| f.tool).collect();
            let c0 = layer_clearances(&obstacles, torch, path, li, &nominal)?;
            let before = summarise(li, &c0);
            let n = fr.len();
            let positions: Vec<Point3> = layer.points.iter().map(|p| p.position).collect();
            // Arc length along the layer (mm).
            let mut s = vec![0.0; n];
            for i in 1..n {
                s[i] = s[i - 1] + (positions[i] - positions[i - 1]).norm();
            }
            let total = s[n - 1]
                + if layer.closed {
                    (positions[0] - positions[n - 1]).norm()
                } else {
                    0.0
                };
            let dist = |i: usize, j: usize| {
                let d = (s[i] - s[j]).abs();
                if layer.closed {
                    d.min(total - d)
                } else {
                    d
                }
            };
            // Required corrections per point, and the blended field.
            let mut need: Vec<[f64; 2]> = vec![[0.0, 0.0]; n];
            let mut unresolved = vec![false; n];
            let mut current = c0.clone();
            let mut axes = nominal.clone();
            let mut blended: Vec<[f64; 2]> = vec![[0.0, 0.0]; n];
            for _round in 0..aopts.rounds {
                let todo: Vec<usize> = (0..n)
                    .filter(|&i| current[i] < aopts.margin_mm && !unresolved[i])
                    .collect();
                if todo.is_empty() {
                    break;
                }
                let mut hint = 1;
                for &i in &todo {
                    let start = blended[i][0].hypot(blended[i][1]);
                    let rings = (aopts.cone_half_angle_rad / aopts.step_rad).floor() as usize;
                    let first = ((start / aopts.step_rad).floor() as usize + 1).max(1);
                    if first > rings {
                        unresolved[i] = true;
                        continue;
                    }
                    // Ring `r`: the direction in the middle of its longest run
                    // of clear azimuths (the bisector of the free arc), if any.
                    let m = aopts.azimuths;
                    let dir_of = |r: usize, k: usize| {
                        let theta = r as f64 * aopts.step_rad;
                        let phi = std::f64::consts::TAU * k as f64 / m as f64;
                        [theta * phi.cos(), theta * phi.sin()]
                    };
                    let ring = |r: usize| -> Result<Option<[f64; 2]>, ToolAxisError> {
                        let mut clear = Vec::with_capacity(m);
                        for k in 0..m {
                            let dir = corrected(&fr[i], &nominal[i], &dir_of(r, k));
                            clear.push(obstacles.is_clear(
                                torch,
                                &positions[i],
                                &dir,
                                aopts.margin_mm,
                            )?);
                        }
                        if clear.iter().all(|&c| c) {
                            // No obstacle in reach: keep the tilt along t.
                            return Ok(Some(dir_of(r, 0)));
                        }
                        // Longest circular run of clear azimuths.
                        let start = clear.iter().position(|&c| !c).expect("one blocked");
                        let (mut best, mut run) = (None::<(usize, usize)>, None::<(usize, usize)>);
                        for step in 1..=m {
                            let k = (start + step) % m;
                            if clear[k] {
                                run = Some(run.map_or((k, 1), |(s0, len)| (s0, len + 1)));
                                let cur = run.expect("just set");
                                if best.is_none_or(|b| cur.1 > b.1) {
                                    best = Some(cur);
                                }
                            } else {
                                run = None;
                            }
                        }
                        Ok(best.map(|(s0, len)| {
                            // Middle of the run (half-step for even lengths).
                            let mid = s0 as f64 + 0.5 * (len as f64 - 1.0);
                            let theta = r as f64 * aopts.step_rad;
                            let phi = std::f64::consts::TAU * mid / m as f64;
                            [theta * phi.cos(), theta * phi.sin()]
                        }))
                    };
                    // Smallest clearing ring, searched from the previous
                    // point's answer (neighbours need similar tilts): down
                    // while rings clear, else up until one does.
                    let mut found: Option<[f64; 2]> = None;
                    let mut r = hint.clamp(first, rings);
                    if let Some(c) = ring(r)? {
                        found = Some(c);
                        while r > first {
                            match ring(r - 1)? {
                                Some(c) => {
                                    r -= 1;
                                    found = Some(c);
                                }
                                None => break,
                            }
                        }
                    } else {
                        while r < rings {
                            r += 1;
                            if let Some(c) = ring(r)? {
                                found = Some(c);
                                break;
                            }
                        }
                    }
                    hint = r;
                    match found {
                        Some(c) => need[i] = c,
                        None => {
                            // Best effort: the clearest direction of the widest ring.
                            unresolved[i] = true;
                            let mut best: Option<([f64; 2], f64)> = None;
                            for k in 0..m {
                                let c = dir_of(rings, k);
                                let dir = corrected(&fr[i], &nominal[i], &c);
                                let cl = obstacles.clearance(torch, &positions[i], &dir)?;
                                if best.is_none_or(|b| cl > b.1) {
                                    best = Some((c, cl));
                                }
                            }
                            if let Some((c, _)) = best {
                                need[i] = c;
                            }
                        }
                    }
                }
                // Upper envelope: |c_i| = max_j (|c_j| - rate d_ij), direction of the argmax.
                let sources: Vec<usize> = (0..n)
                    .filter(|&j| need[j][0] != 0.0 || need[j][1] != 0.0)
                    .collect();
                for (i, bl) in blended.iter_mut().enumerate() {
                    let mut best = (0.0, [0.0, 0.0]);
                    for &j in &sources {
                        let m = need[j][0].hypot(need[j][1]);
                        let v = m - aopts.max_rate_rad_per_mm * dist(i, j);
                        if v > best.0 {
                            best = (v, [need[j][0] / m * v, need[j][1] / m * v]);
                        }
                    }
                    *bl = best.1;
                }
                for i in 0..n {
                    axes[i] = corrected(&fr[i], &nominal[i], &blended[i]);
                }
                current = layer_clearances(&obstacles, torch, path, li, &axes)?;
            }
            // Smooth the correction field (local coordinates) to the rate.
            let mut pairs: Vec<(f64, f64)> = blended.iter().map(|c| (c[0], c[1])).collect();
            if smooth_angles(
                &positions,
                &mut pairs,
                layer.closed,
                aopts.max_rate_rad_per_mm,
            ) > 0
            {
                for (b, p) in blended.iter_mut().zip(&pairs) {
                    *b = [p.0, p.1];
                }
                for i in 0..n {
                    axes[i] = corrected(&fr[i], &nominal[i], &blended[i]);
                }
            }
            let c1 = layer_clearances(&obstacles, torch, path, li, &axes)?;
            let after = summarise(li, &c1);
            let mut out_frames = fr.clone();
            let mut corrected_count = 0;
            let mut max_corr: f64 = 0.0;
            for (f, a) in out_frames.iter_mut().zip(&axes) {
                let d = angle(&f.tool, a);
                if d > 1e-12 {
                    corrected_count += 1;
                }
                max_corr = max_corr.max(d);
                f.tool = *a;
            }
            Ok(LayerOut {
                frames: out_frames,
                before,
                after,
                corrected: corrected_count,
                max_corr,
                unresolved: (0..n).filter(|&i| unresolved[i] || c1[i] <= 0.0).collect(),
            })
        })
        .collect::<Result<Vec<_>, ToolAxisError>>()?;
    let mut new_frames = Vec::with_capacity(outs.len());
    let mut before = Vec::with_capacity(outs.len());
    let mut after = Vec::with_capacity(outs.len());
    let mut corrected_points = 0;
    let mut max_correction_rad: f64 = 0.0;
    let mut unresolved = Vec::new();
    for (li, o) in outs.into_iter().enumerate() {
        corrected_points += o.corrected;
        max_correction_rad = max_correction_rad.max(o.max_corr);
        for p in o.unresolved {
            if unresolved.len() < 100 {
                unresolved.push((li, p));
            }
        }
        new_frames.push(o.frames);
        before.push(o.before);
        after.push(o.after);
    }
    let checked = sub.is_some();
    Ok((
        new_frames,
        AvoidanceReport {
            before: CollisionReport::from_layers(before, checked),
            after: CollisionReport::from_layers(after, checked),
            corrected_points,
            max_correction_rad,
            unresolved,
        },
    ))
}
