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
//!
//! | piece | file |
//! |---|---|
//! | the torch model ([`TorchSpec`], [`Torch`], [`part_from_torch`]) | `torch` |
//! | clearance along a path ([`check_collisions`]) | `clearance` |
//! | avoidance within a cone ([`avoid_collisions`]) | `avoid` |
//! | hulls' support function over clustered vertices (parry's answers, faster) | `support` |

mod avoid;
mod clearance;
pub(crate) mod support;
mod torch;

pub use avoid::{avoid_collisions, AvoidanceOptions, AvoidanceReport};
pub use clearance::{check_collisions, CollisionOptions, CollisionReport, LayerClearance, Wall};
pub use torch::{part_from_torch, Torch, TorchSpec};
