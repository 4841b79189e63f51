//! Clearance of the torch along a path: the obstacles at a slice (the
//! layers laid before it as bead capsules, the substrate) and the smallest
//! distance from the torch to them at every point (part frame, mm).

use crate::geometry::Substrate;
use crate::math::{Isometry3, Point3, Translation3, UnitQuaternion, UnitVector3, Vector3};
use crate::path::Path;
use crate::toolaxis::{LocalFrame, ToolAxisError};
use parry3d_f64::bounding_volume::Aabb;
use parry3d_f64::partitioning::BvhNode;
use parry3d_f64::query::{self, DefaultQueryDispatcher, QueryDispatcher};
use parry3d_f64::shape::{Cylinder, HalfSpace, Polyline, Shape};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use super::torch::{part_from_torch, Torch};

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
    pub(super) fn from_layers(layers: Vec<LayerClearance>, substrate_checked: bool) -> Self {
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
pub(super) struct Obstacles<'a> {
    built: Option<Polyline>,
    bead_radius: f64,
    substrate: Option<&'a (Isometry3, Box<dyn Shape>)>,
}

impl<'a> Obstacles<'a> {
    pub(super) fn new(
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
    pub(super) fn is_clear(
        &self,
        torch: &Torch,
        point: &Point3,
        tool: &Vector3,
        margin: f64,
    ) -> Result<bool, ToolAxisError> {
        self.is_clear_with_radius(torch, point, tool, margin, self.bead_radius)
    }

    /// [`Obstacles::is_clear`] with beads of `bead_radius` (mm) in place of
    /// the obstacles' own.
    fn is_clear_with_radius(
        &self,
        torch: &Torch,
        point: &Point3,
        tool: &Vector3,
        margin: f64,
        bead_radius: f64,
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
                    margin + bead_radius,
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
    pub(super) fn clearance(
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

/// Deposited beads as an obstacle for the torch placed anywhere (part
/// frame, mm): each bead an open polyline of its points, standing for
/// capsules of `bead_radius_mm`. Used to check arc-off moves (transits
/// between layers) against the wall built so far.
pub struct Wall {
    obstacles: Obstacles<'static>,
}

impl std::fmt::Debug for Wall {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Wall")
            .field("bead_radius_mm", &self.obstacles.bead_radius)
            .field("empty", &self.obstacles.built.is_none())
            .finish()
    }
}

impl Wall {
    /// The wall of `beads` (part frame, mm), capsules of `bead_radius_mm`
    /// (≥ 0). Beads of fewer than two points are left out.
    pub fn new<'b>(beads: impl IntoIterator<Item = &'b [Point3]>, bead_radius_mm: f64) -> Self {
        let mut vertices = Vec::new();
        let mut indices: Vec<[u32; 2]> = Vec::new();
        for b in beads {
            if b.len() < 2 {
                continue;
            }
            let base = vertices.len() as u32;
            vertices.extend_from_slice(b);
            indices.extend((0..b.len() as u32 - 1).map(|i| [base + i, base + i + 1]));
        }
        let built = (!indices.is_empty()).then(|| Polyline::new(vertices, Some(indices)));
        Self {
            obstacles: Obstacles {
                built,
                bead_radius: bead_radius_mm.max(0.0),
                substrate: None,
            },
        }
    }

    /// The box around the beads' segments (part frame, mm; the capsules'
    /// radius not included); `None` without a bead.
    pub fn segment_bounds(&self) -> Option<Aabb> {
        self.obstacles.built.as_ref().map(Polyline::local_aabb)
    }

    /// `true` when there is no bead.
    pub fn is_empty(&self) -> bool {
        self.obstacles.built.is_none()
    }

    /// Clearance of `torch` with its tip at `point` and its axis along
    /// `tool` (towards the torch, part frame): smallest distance to the
    /// beads' capsules (mm; `<= 0` is a collision, `+inf` without beads).
    ///
    /// # Errors
    /// [`ToolAxisError::UnsupportedQuery`] if parry cannot answer.
    pub fn clearance(
        &self,
        torch: &Torch,
        point: &Point3,
        tool: &Vector3,
    ) -> Result<f64, ToolAxisError> {
        self.obstacles.clearance(torch, point, tool)
    }

    /// Whether the clearance of `torch` at `point` with axis `tool` exceeds
    /// `margin_mm` (≥ 0): a bounded query that only visits beads within the
    /// margin, much cheaper than [`Wall::clearance`].
    ///
    /// # Errors
    /// [`ToolAxisError::UnsupportedQuery`] if parry cannot answer.
    pub fn is_clear(
        &self,
        torch: &Torch,
        point: &Point3,
        tool: &Vector3,
        margin_mm: f64,
    ) -> Result<bool, ToolAxisError> {
        self.obstacles.is_clear(torch, point, tool, margin_mm)
    }

    /// Smallest distance (mm) from `torch` with its tip at `point` and its
    /// axis along `tool` (towards the torch, part frame) to the beads'
    /// polylines — the capsules' axes, radius not taken off — when it is
    /// below `below_mm`; `None` when no segment is that close (or without
    /// beads). Subtracting the capsule radius from the smallest of these
    /// over several walls gives the clearance of their union.
    ///
    /// Each torch part runs parry's own composite distance query
    /// (`query::distance`, as [`Wall::clearance`] does: the same relative
    /// pose, box bounds and segment distances), started from the bound
    /// instead of `f64::MAX`: a segment tree whose box is no closer than
    /// the bound is left at its root.
    pub fn axis_distance_below(
        &self,
        torch: &Torch,
        point: &Point3,
        tool: &Vector3,
        below_mm: f64,
    ) -> Option<f64> {
        let built = self.obstacles.built.as_ref()?;
        let torch_pose = part_from_torch(point, tool);
        let mut best: Option<f64> = None;
        for (local, part) in &torch.parts {
            let pose = torch_pose * local;
            let part = part.shape();
            // as `query::distance(&pose, part, &identity, built)` →
            // `distance_shape_composite_shape` → `distance_to_shape`
            let pos12 = pose.inv_mul(&Isometry3::identity());
            let pose12 = pos12.inverse();
            let aabb = part.compute_aabb(&pose12);
            let shift = -aabb.center().coords;
            let half = aabb.half_extents();
            let bound = best.unwrap_or(below_mm);
            let found = built.bvh().find_best(
                bound,
                |node: &BvhNode, _| {
                    Aabb {
                        mins: node.mins() + shift - half,
                        maxs: node.maxs() + shift + half,
                    }
                    .distance_to_origin()
                },
                |i, _| {
                    DefaultQueryDispatcher
                        .distance(&pose12, &built.segment(i), part)
                        .ok()
                },
            );
            if let Some((_, d)) = found {
                best = Some(d);
            }
        }
        best
    }

    /// [`Wall::is_clear`] with capsules of `bead_radius_mm` (≥ 0) in place
    /// of the wall's own.
    ///
    /// # Errors
    /// [`ToolAxisError::UnsupportedQuery`] if parry cannot answer.
    pub fn is_clear_with_radius(
        &self,
        torch: &Torch,
        point: &Point3,
        tool: &Vector3,
        margin_mm: f64,
        bead_radius_mm: f64,
    ) -> Result<bool, ToolAxisError> {
        self.obstacles
            .is_clear_with_radius(torch, point, tool, margin_mm, bead_radius_mm.max(0.0))
    }
}

/// The substrate as a parry shape and its pose, sized from the path.
pub(super) fn substrate_shape(
    path: &Path,
    substrate: &Substrate,
) -> Option<(Isometry3, Box<dyn Shape>)> {
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

pub(super) fn check_shape(path: &Path, frames: &[Vec<LocalFrame>]) -> Result<(), ToolAxisError> {
    crate::toolaxis::rules::check_shape(path, frames.iter().map(Vec::len))
}

pub(super) fn layer_clearances(
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

pub(super) fn summarise(li: usize, c: &[f64]) -> LayerClearance {
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
