//! Arc-off transit moves against the deposited wall: where the torch is seen
//! from the part at any joints ([`torch_in_part`]), and the smallest
//! clearance between the torch and the wall along a joint move, sampled in
//! joint space ([`joint_move_clearance`]). A synchronised joint move (FANUC
//! `J`, KUKA `PTP`, ABB `MoveAbsJ`) is a straight line in joint space, so the
//! samples follow the path the controller takes whatever its speed.
//! [`build_program_with`](super::build_program_with) raises the retract and
//! approach points of a transition that collides; the validator checks the
//! joint moves it reads back. Part frame, mm, rad.

use std::sync::OnceLock;

use parry3d_f64::bounding_volume::{Aabb, BoundingVolume};

use crate::math::{Isometry3, Point3, Vector3};
use crate::robot::{CellLayout, Joints};
use crate::toolaxis::collision::{part_from_torch, Torch, Wall};
use crate::toolaxis::ToolAxisError;

/// Largest change of any joint between two samples of a joint move (rad,
/// 0.5°): at 1.5 m from the axis a sample every ~13 mm, well under the
/// torch's nozzle diameter, and the bead capsules' radius takes up the rest.
pub const TRANSIT_STEP_RAD: f64 = 0.5 * std::f64::consts::PI / 180.0;

/// Most points a bead keeps in the wall of a transit check; a longer bead is
/// decimated and the capsule radius grows by the largest distance of a
/// dropped point from its chord, so that the check stays conservative.
pub const WALL_POINTS_PER_BEAD: usize = 256;

/// The torch seen from the part at robot joints `q` (controller convention,
/// rad) and positioner joints `qp` (rad, torch-carried cell): the point it
/// deposits at (part frame, mm) and its axis from that point towards the
/// torch (part frame, unit), the [`part_from_torch`]
/// inputs. `None` in a torch-carried cell without positioner joints.
pub fn torch_in_part(
    cell: &CellLayout,
    q: &Joints,
    qp: Option<[f64; 2]>,
) -> Option<(Point3, Vector3)> {
    let base_from_flange = cell.robot().flange_pose(q);
    match cell {
        CellLayout::PartCarried(c) => {
            // the torch is fixed at D_R, pointing down: its axis towards the
            // torch is the base frame's +Z (eq. 3.8: A·T = +Z)
            let part_from_base = (base_from_flange * c.flange_from_part).inverse();
            Some((
                part_from_base * c.deposition_point_mm,
                part_from_base.rotation * Vector3::z(),
            ))
        }
        CellLayout::TorchCarried(c) => {
            let base_from_tcp = base_from_flange * c.flange_from_tcp;
            let part_from_base = c.base_from_part(&qp?).inverse();
            // the TCP's z axis points from the deposition point back into
            // the torch (checked against the planned tool axes in every
            // sample cell by the program tests)
            let axis = base_from_tcp.rotation * Vector3::z();
            Some((
                part_from_base * Point3::from(base_from_tcp.translation.vector),
                part_from_base.rotation * axis,
            ))
        }
    }
}

/// The tightest sample of a joint move where the torch touches the wall;
/// `min_clearance_mm = +inf` when it touches nowhere (the clearance is
/// only measured where it is `<= 0`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TransitClearance {
    /// Smallest clearance between the torch and the wall (mm; `<= 0`: a
    /// collision; `+inf` for an empty wall).
    pub min_clearance_mm: f64,
    /// Where along the move (0 at its start, 1 at its end).
    pub at_fraction: f64,
    /// The torch's deposition point there (part frame, mm).
    pub tip_mm: Point3,
}

/// How deep a transit's deepest sample goes into the wall, in words:
/// `min_clearance_mm` (negative, mm) below the capsules' surface, or, where
/// it reaches `bead_radius_mm` (the capsules' radius, mm), through the
/// bead: the distance measured is to the bead's centreline, so a torch
/// across it reads the radius whatever the crossing.
pub fn intrusion(min_clearance_mm: f64, bead_radius_mm: f64) -> String {
    let depth = -min_clearance_mm;
    if bead_radius_mm > 0.0 && depth >= bead_radius_mm - 1e-6 {
        "through the deposited wall (the torch crosses a bead's centreline)".to_string()
    } else {
        format!("{depth:.1} mm into the deposited wall")
    }
}

/// Where the torch touches `wall` along the joint move from `(qa, pa)` to
/// `(qb, pb)` (robot joints, positioner joints; rad), sampled every
/// [`TRANSIT_STEP_RAD`] of the joint that moves most, both ends included:
/// the deepest such sample, or `+inf` clearance when it clears everywhere.
///
/// # Errors
/// A message when a sample has no torch pose (torch-carried cell without
/// positioner joints) or parry cannot answer.
pub fn joint_move_clearance(
    cell: &CellLayout,
    wall: &(impl TransitWall + ?Sized),
    torch: &Torch,
    a: (&Joints, Option<[f64; 2]>),
    b: (&Joints, Option<[f64; 2]>),
) -> Result<TransitClearance, String> {
    let mut best = TransitClearance {
        min_clearance_mm: f64::INFINITY,
        at_fraction: 0.0,
        tip_mm: Point3::origin(),
    };
    walk_joint_move(cell, wall, torch, a, b, |s, c, tip| {
        if c < best.min_clearance_mm {
            best = TransitClearance {
                min_clearance_mm: c,
                at_fraction: s,
                tip_mm: tip,
            };
        }
        true
    })?;
    Ok(best)
}

/// Whether the torch touches `wall` along the joint move from `(qa, pa)`
/// to `(qb, pb)`: [`joint_move_clearance`]'s `min_clearance_mm <= 0`, from
/// the same samples, stopping at the first that touches.
///
/// # Errors
/// As [`joint_move_clearance`].
pub fn joint_move_touches(
    cell: &CellLayout,
    wall: &(impl TransitWall + ?Sized),
    torch: &Torch,
    a: (&Joints, Option<[f64; 2]>),
    b: (&Joints, Option<[f64; 2]>),
) -> Result<bool, String> {
    let mut touches = false;
    walk_joint_move(cell, wall, torch, a, b, |_, c, _| {
        touches = c <= 0.0;
        !touches
    })?;
    Ok(touches)
}

/// The samples of a joint move ([`joint_move_clearance`]): at each where
/// the torch is not clear of the wall, `seen(fraction, clearance_mm, tip)`,
/// which returns whether to go on.
///
/// A sample whose torch is clear of the wall by more than
/// [`TRANSIT_ROOM_MM`] vouches for the samples after it whose torch has
/// moved less than that from it (less [`TRANSIT_ROOM_SLACK_MM`], far above
/// the queries' rounding): they are clear, and are not asked. How far the
/// torch moved is bounded from its two poses as the wall sees them
/// ([`part_from_torch`]): the tip's displacement plus the rotation's
/// (`|R − R'| ≤ 2 |q − q'|` for unit quaternions of the same sign) times
/// the torch's farthest point from its tip. A sample is not clear by that
/// much asks the plain question, as every sample did before; it asks the
/// larger one again only after a few samples, more the more often it was
/// refused. So `seen` sees the same samples with the same clearances.
fn walk_joint_move(
    cell: &CellLayout,
    wall: &(impl TransitWall + ?Sized),
    torch: &Torch,
    (qa, pa): (&Joints, Option<[f64; 2]>),
    (qb, pb): (&Joints, Option<[f64; 2]>),
    mut seen: impl FnMut(f64, f64, Point3) -> bool,
) -> Result<(), String> {
    if wall.is_empty() {
        return Ok(());
    }
    let mut largest = qa
        .iter()
        .zip(qb)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max);
    if let (Some(a), Some(b)) = (pa, pb) {
        largest = largest.max((a[0] - b[0]).abs()).max((a[1] - b[1]).abs());
    }
    let n = ((largest / TRANSIT_STEP_RAD).ceil() as usize).clamp(1, 100_000);
    // the torch's farthest point from its tip (torch frame, mm)
    let reach = {
        let b = torch.bounds(&Point3::origin(), &Vector3::z());
        let far = |i: usize| b.mins[i].abs().max(b.maxs[i].abs());
        Vector3::new(far(0), far(1), far(2)).norm()
    };
    // the last sample clear by the room: the torch's pose there
    let mut vouch: Option<Isometry3> = None;
    // when to ask for the room again, and after how many samples next
    let (mut ask_room_at, mut wait) = (0, 1);
    for i in 0..=n {
        let s = i as f64 / n as f64;
        let q: Joints = std::array::from_fn(|j| qa[j] + s * (qb[j] - qa[j]));
        let p = match (pa, pb) {
            (Some(a), Some(b)) => Some([a[0] + s * (b[0] - a[0]), a[1] + s * (b[1] - a[1])]),
            _ => pa.or(pb),
        };
        let (tip, axis) = torch_in_part(cell, &q, p)
            .ok_or_else(|| "a torch-carried move without positioner joints".to_string())?;
        if let Some(v) = &vouch {
            let pose = part_from_torch(&tip, &axis);
            let (a, b) = (v.rotation.coords, pose.rotation.coords);
            let turn = 2.0 * (a - b).norm().min((a + b).norm());
            let moved = (pose.translation.vector - v.translation.vector).norm() + turn * reach;
            if moved < TRANSIT_ROOM_MM - TRANSIT_ROOM_SLACK_MM {
                continue;
            }
            vouch = None;
        }
        if i >= ask_room_at {
            if wall
                .is_clear(torch, &tip, &axis, TRANSIT_ROOM_MM)
                .map_err(|e| e.to_string())?
            {
                vouch = Some(part_from_torch(&tip, &axis));
                wait = 1;
                continue;
            }
            ask_room_at = i + wait;
            wait = (2 * wait).min(TRANSIT_ROOM_MAX_WAIT);
        }
        // a bounded query first; the distance only where the torch touches
        if wall
            .is_clear(torch, &tip, &axis, 0.0)
            .map_err(|e| e.to_string())?
        {
            continue;
        }
        let c = wall
            .clearance(torch, &tip, &axis)
            .map_err(|e| e.to_string())?;
        if !seen(s, c, tip) {
            break;
        }
    }
    Ok(())
}

/// The clearance a sample of a joint move is asked for before the plain
/// question, so that it vouches for the samples after it whose torch
/// moves less than this (mm; [`joint_move_clearance`], [`joint_move_touches`]).
pub const TRANSIT_ROOM_MM: f64 = 10.0;

/// How much of [`TRANSIT_ROOM_MM`] a vouched sample leaves unused (mm):
/// far above the rounding of the clearance queries and of the poses.
const TRANSIT_ROOM_SLACK_MM: f64 = 0.1;

/// Most samples between two asks for [`TRANSIT_ROOM_MM`] after it was
/// refused.
const TRANSIT_ROOM_MAX_WAIT: usize = 16;

/// The wall of `beads` (part frame, mm) for a transit check, as one
/// segment tree: each bead decimated to at most [`WALL_POINTS_PER_BEAD`]
/// points, capsules of `bead_radius_mm` grown by the largest distance of a
/// dropped point from its chord. [`WallBeads::wall`] answers the same
/// queries for any number of first beads without building a tree each time.
pub fn wall_of<'b>(beads: impl IntoIterator<Item = &'b [Point3]>, bead_radius_mm: f64) -> Wall {
    let mut decimated = WallBeads::default();
    for b in beads {
        decimated.push(b);
    }
    let grow = decimated.grow.last().copied().unwrap_or(0.0);
    Wall::new(
        decimated.kept.iter().map(Vec::as_slice),
        bead_radius_mm + grow,
    )
}

/// An obstacle a joint move is checked against (part frame, mm): one
/// [`Wall`], or the first beads of [`WallBeads`] ([`WallPrefix`]).
pub trait TransitWall {
    /// `true` when there is no bead to hit.
    fn is_empty(&self) -> bool;

    /// Whether the clearance of `torch` with its tip at `point` and its
    /// axis along `tool` (towards the torch, part frame) exceeds
    /// `margin_mm` (≥ 0); see [`Wall::is_clear`].
    ///
    /// # Errors
    /// [`ToolAxisError::UnsupportedQuery`] if parry cannot answer.
    fn is_clear(
        &self,
        torch: &Torch,
        point: &Point3,
        tool: &Vector3,
        margin_mm: f64,
    ) -> Result<bool, ToolAxisError>;

    /// Smallest distance from `torch` (tip at `point`, axis along `tool`) to
    /// the beads' capsules (mm; `<= 0` a collision, `+inf` without beads);
    /// see [`Wall::clearance`].
    ///
    /// # Errors
    /// [`ToolAxisError::UnsupportedQuery`] if parry cannot answer.
    fn clearance(
        &self,
        torch: &Torch,
        point: &Point3,
        tool: &Vector3,
    ) -> Result<f64, ToolAxisError>;
}

impl TransitWall for Wall {
    fn is_empty(&self) -> bool {
        Wall::is_empty(self)
    }

    fn is_clear(
        &self,
        torch: &Torch,
        point: &Point3,
        tool: &Vector3,
        margin_mm: f64,
    ) -> Result<bool, ToolAxisError> {
        Wall::is_clear(self, torch, point, tool, margin_mm)
    }

    fn clearance(
        &self,
        torch: &Torch,
        point: &Point3,
        tool: &Vector3,
    ) -> Result<f64, ToolAxisError> {
        Wall::clearance(self, torch, point, tool)
    }
}

/// Beads decimated once for the transit check, in deposition order (part
/// frame, mm), from which the wall after any number of beads is queried
/// without decimating or building the earlier beads' segment trees again.
///
/// The beads are grouped in blocks as in a Fenwick tree: block `m` (1-based)
/// holds beads `m - low(m) .. m`, where `low(m)` is the largest power of two
/// dividing `m`, and its segment tree is built once, at its first query
/// (capsule radius left to the query). The first `n` beads are the disjoint
/// union of the blocks `n`, `n - low(n)`, … (at most `log2(n) + 1` of them),
/// so [`WallBeads::wall`] costs no tree build after the first, and all the
/// walls of a program's `L` transits build `O(L log L)` beads' segments
/// instead of `O(L²)`.
///
/// The queries answer as [`wall_of`] of the first `n` beads (one tree):
/// * `is_clear`: parry reports a segment within the margin when one is,
///   whatever the tree (a node's box holds its segments' boxes, so it is
///   never cut off before such a segment is found), and the blocks are
///   clear exactly when each is;
/// * `clearance`: parry's distance query gives the smallest distance over
///   the segments it visits, and it leaves out only those whose box is no
///   closer than a distance already found; each block's search here starts
///   from the smallest distance of the blocks before it
///   ([`Wall::axis_distance_below`]). Both are the smallest segment
///   distance over all the beads as long as no computed segment distance
///   falls below its box's bound by rounding; the radius is taken off
///   once, as in [`Wall::clearance`]. `tests/program/transit_wall.rs`
///   finds them equal to the bit on sample-part beads and program moves.
#[derive(Debug, Default)]
pub struct WallBeads {
    kept: Vec<Vec<Point3>>,
    /// Largest chord distance of a dropped point over beads `..=i` (mm).
    grow: Vec<f64>,
    /// Beads of at least two kept points (the wall's segments) among
    /// beads `..=i`.
    solid: Vec<usize>,
    /// `blocks[m - 1]`: the wall of beads `m - low(m) .. m`, built on first
    /// use (capsule radius 0: queries give theirs).
    blocks: Vec<OnceLock<Wall>>,
    /// Per bead, the box of its kept points when it has a segment (two or
    /// more of them).
    bead_bounds: Vec<Option<Aabb>>,
    /// `block_bounds[m - 1]`: block `m`'s [`Wall::segment_bounds`], from
    /// its beads' boxes without building its tree (on first use).
    block_bounds: Vec<OnceLock<Option<Aabb>>>,
}

impl WallBeads {
    /// Adds the next bead (part frame, mm), decimated to at most
    /// [`WALL_POINTS_PER_BEAD`] points.
    pub fn push(&mut self, b: &[Point3]) {
        let mut grow = self.grow.last().copied().unwrap_or(0.0);
        if b.len() <= WALL_POINTS_PER_BEAD {
            self.kept.push(b.to_vec());
        } else {
            let step = b.len().div_ceil(WALL_POINTS_PER_BEAD - 1);
            let mut idx: Vec<usize> = (0..b.len()).step_by(step).collect();
            if idx.last() != Some(&(b.len() - 1)) {
                idx.push(b.len() - 1);
            }
            for w in idx.windows(2) {
                let (a, c) = (b[w[0]], b[w[1]]);
                for p in &b[w[0] + 1..w[1]] {
                    grow = grow.max(point_segment_distance(p, &a, &c));
                }
            }
            self.kept.push(idx.iter().map(|&i| b[i]).collect());
        }
        self.grow.push(grow);
        let solid = self.solid.last().copied().unwrap_or(0);
        self.solid
            .push(solid + usize::from(self.kept.last().is_some_and(|k| k.len() >= 2)));
        self.blocks.push(OnceLock::new());
        let kept = self.kept.last().map_or(&[][..], Vec::as_slice);
        self.bead_bounds.push((kept.len() >= 2).then(|| {
            kept.iter().fold(Aabb::new_invalid(), |b, p| Aabb {
                mins: b.mins.inf(p),
                maxs: b.maxs.sup(p),
            })
        }));
        self.block_bounds.push(OnceLock::new());
    }

    /// Beads added so far.
    pub fn len(&self) -> usize {
        self.kept.len()
    }

    /// Whether no bead was added.
    pub fn is_empty(&self) -> bool {
        self.kept.is_empty()
    }

    /// The wall of the first `n` beads (at most [`Self::len`]), capsules of
    /// `bead_radius_mm` grown by the largest chord distance of their
    /// decimation: the queries of [`wall_of`] on those beads, answered by
    /// the blocks' segment trees.
    pub fn wall(&self, n: usize, bead_radius_mm: f64) -> WallPrefix<'_> {
        let n = n.min(self.kept.len());
        let grow = if n == 0 { 0.0 } else { self.grow[n - 1] };
        WallPrefix {
            beads: self,
            n,
            // the radius `wall_of` gives its `Wall`
            bead_radius_mm: bead_radius_mm + grow,
        }
    }

    /// Block `m` (1-based): the wall of beads `m - low(m) .. m`.
    fn block(&self, m: usize) -> &Wall {
        self.blocks[m - 1]
            .get_or_init(|| Wall::new(self.kept[m - low(m)..m].iter().map(Vec::as_slice), 0.0))
    }

    /// Block `m`'s box around its segments, as its tree's
    /// ([`Wall::segment_bounds`]: the smallest and largest coordinates of
    /// their ends, taken exactly by both) without building the tree.
    fn block_bounds(&self, m: usize) -> Option<Aabb> {
        *self.block_bounds[m - 1].get_or_init(|| {
            self.bead_bounds[m - low(m)..m]
                .iter()
                .flatten()
                .copied()
                .reduce(|a, b| a.merged(&b))
        })
    }
}

/// The largest power of two dividing `m` (> 0).
fn low(m: usize) -> usize {
    m & m.wrapping_neg()
}

/// The wall of the first beads of a [`WallBeads`] ([`WallBeads::wall`]).
#[derive(Debug, Clone, Copy)]
pub struct WallPrefix<'a> {
    beads: &'a WallBeads,
    n: usize,
    /// Capsule radius (mm): the bead radius grown by the decimation.
    bead_radius_mm: f64,
}

impl WallPrefix<'_> {
    /// The blocks whose union is the wall (their `m`), latest beads first.
    fn block_indices(&self) -> impl Iterator<Item = usize> {
        std::iter::successors((self.n > 0).then_some(self.n), |&m| {
            (m > low(m)).then(|| m - low(m))
        })
    }

    /// The blocks whose union is the wall, latest beads first.
    fn blocks(&self) -> impl Iterator<Item = &Wall> + '_ {
        self.block_indices().map(|m| self.beads.block(m))
    }
}

impl TransitWall for WallPrefix<'_> {
    fn is_empty(&self) -> bool {
        self.n == 0 || self.beads.solid[self.n - 1] == 0
    }

    fn is_clear(
        &self,
        torch: &Torch,
        point: &Point3,
        tool: &Vector3,
        margin_mm: f64,
    ) -> Result<bool, ToolAxisError> {
        // a block whose segments' box lies farther from the torch's box than
        // the margin and the capsules' radius is clear without asking parry
        // (which would bound the same boxes, once per block); the slack
        // keeps the skip off parry's rounding at that distance
        let torch_box = torch.bounds(point, tool);
        let reach = margin_mm + self.bead_radius_mm.max(0.0) + BOX_SLACK_MM;
        // (the box from the beads' boxes: a block far from every torch is
        // never built)
        for m in self.block_indices() {
            if self
                .beads
                .block_bounds(m)
                .is_some_and(|bb| box_gap(&bb, &torch_box) > reach)
            {
                continue;
            }
            let b = self.beads.block(m);
            if !b.is_clear_with_radius(torch, point, tool, margin_mm, self.bead_radius_mm)? {
                return Ok(false);
            }
        }
        Ok(true)
    }

    fn clearance(
        &self,
        torch: &Torch,
        point: &Point3,
        tool: &Vector3,
    ) -> Result<f64, ToolAxisError> {
        // the smallest distance to a segment of any block, each block's
        // search bounded by the smallest found so far; the radius taken off
        // once (`d - r` is monotone in `d`, so this is the smallest `d - r`)
        let mut axis = f64::MAX;
        for b in self.blocks() {
            if let Some(d) = b.axis_distance_below(torch, point, tool, axis) {
                axis = d;
            }
        }
        if axis == f64::MAX {
            return Ok(f64::INFINITY);
        }
        Ok(axis - self.bead_radius_mm.max(0.0))
    }
}

/// How far beyond the margin a block's box must lie for
/// [`WallPrefix`]'s `is_clear` to skip it (mm).
const BOX_SLACK_MM: f64 = 1e-6;

/// The distance between two boxes (mm; 0 when they overlap).
fn box_gap(a: &Aabb, b: &Aabb) -> f64 {
    let gap = Vector3::from_fn(|i, _| (a.mins[i] - b.maxs[i]).max(b.mins[i] - a.maxs[i]).max(0.0));
    gap.norm()
}

fn point_segment_distance(p: &Point3, a: &Point3, b: &Point3) -> f64 {
    let ab = b - a;
    let l2 = ab.norm_squared();
    let t = if l2 > 0.0 {
        ((p - a).dot(&ab) / l2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (p - (a + ab * t)).norm()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A block's box from its beads' boxes is its tree's box to the bit,
    /// with beads of one point (no segment) and decimated beads among them;
    /// without a segment, both are `None`.
    #[test]
    fn block_bounds_are_the_trees() {
        let mut beads = WallBeads::default();
        let mut next = crate::util::uniform(0x2545_f491_4f6c_dd1d, -100.0, 100.0);
        beads.push(&[Point3::new(1.0, 2.0, 3.0)]);
        assert_eq!(beads.block_bounds(1), None);
        assert!(beads.block(1).segment_bounds().is_none());
        for k in 0..40 {
            let n = [1, 2, 7, 300][k % 4];
            let bead: Vec<Point3> = (0..n)
                .map(|_| Point3::new(next(), next(), next() + k as f64))
                .collect();
            beads.push(&bead);
        }
        for m in 1..=beads.len() {
            let ours = beads.block_bounds(m).map(|b| (b.mins, b.maxs));
            let tree = beads.block(m).segment_bounds().map(|b| (b.mins, b.maxs));
            assert_eq!(ours, tree, "block {m}");
        }
    }

    /// A wall that counts the plain questions (margin 0) it is asked.
    struct Counted<'a> {
        wall: WallPrefix<'a>,
        plain: std::cell::Cell<usize>,
    }

    impl TransitWall for Counted<'_> {
        fn is_empty(&self) -> bool {
            self.wall.is_empty()
        }

        fn is_clear(
            &self,
            torch: &Torch,
            point: &Point3,
            tool: &Vector3,
            margin_mm: f64,
        ) -> Result<bool, ToolAxisError> {
            if margin_mm == 0.0 {
                self.plain.set(self.plain.get() + 1);
            }
            self.wall.is_clear(torch, point, tool, margin_mm)
        }

        fn clearance(
            &self,
            torch: &Torch,
            point: &Point3,
            tool: &Vector3,
        ) -> Result<f64, ToolAxisError> {
            self.wall.clearance(torch, point, tool)
        }
    }

    /// The samples a walk sees (fraction, clearance, tip), every sample
    /// asked: the walk without vouching.
    fn every_sample(
        cell: &CellLayout,
        wall: &impl TransitWall,
        torch: &Torch,
        (qa, qb): (&Joints, &Joints),
    ) -> Vec<(f64, f64, Point3)> {
        let largest = qa
            .iter()
            .zip(qb)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        let n = ((largest / TRANSIT_STEP_RAD).ceil() as usize).clamp(1, 100_000);
        let mut out = Vec::new();
        for i in 0..=n {
            let s = i as f64 / n as f64;
            let q: Joints = std::array::from_fn(|j| qa[j] + s * (qb[j] - qa[j]));
            let (tip, axis) = torch_in_part(cell, &q, None).unwrap();
            if !wall.is_clear(torch, &tip, &axis, 0.0).unwrap() {
                out.push((s, wall.clearance(torch, &tip, &axis).unwrap(), tip));
            }
        }
        out
    }

    /// The samples a sample clear by the room vouches for are clear: the
    /// hemisphere's program in the ROBOWAM part-carried cell, each bead's
    /// retract point joint-moved to the next bead's approach and first
    /// point and back to its own first point (into the wall), against the
    /// wall so far: the walk sees the samples every sample asked sees, with
    /// the same clearances, and asks the plain question of fewer samples.
    #[test]
    fn vouched_samples_are_clear() {
        let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("parts");
        let part = crate::Part::read(root.join("hemisphere.toml")).unwrap();
        let cell = crate::Cell::read(root.join("cells/robowam_part_carried.toml")).unwrap();
        let planned = crate::plan_part(&part, &cell, &crate::PlanOptions::default()).unwrap();
        let program = planned.program.as_ref().unwrap();
        let pts = &program.points;
        // each bead: the range of its points
        let mut beads: Vec<std::ops::Range<usize>> = Vec::new();
        for (i, p) in pts.iter().enumerate() {
            if !p.arc.is_bead() {
                continue;
            }
            match beads.last_mut() {
                Some(r) if r.end == i && pts[r.start].same_bead(p) => r.end = i + 1,
                _ => beads.push(i..i + 1),
            }
        }
        let mut wall = WallBeads::default();
        for r in &beads {
            let b: Vec<Point3> = pts[r.clone()].iter().map(|p| p.position_mm).collect();
            wall.push(&b);
        }
        let torch = Torch::new(&Default::default()).unwrap();
        let (mut samples, mut plain, mut seen_any) = (0, 0, false);
        for (k, r) in beads.iter().enumerate() {
            let from = pts[(r.end).min(pts.len() - 1)].joints;
            let mut to = vec![pts[r.start].joints];
            if let Some(next) = beads.get(k + 1) {
                to.extend([pts[next.start - 1].joints, pts[next.start].joints]);
            }
            for qb in &to {
                let counted = Counted {
                    wall: wall.wall(k + 1, 2.0),
                    plain: std::cell::Cell::new(0),
                };
                let mut seen = Vec::new();
                walk_joint_move(
                    &program.cell,
                    &counted,
                    &torch,
                    (&from, None),
                    (qb, None),
                    |s, c, t| {
                        seen.push((s, c, t));
                        true
                    },
                )
                .unwrap();
                plain += counted.plain.get();
                let every = every_sample(&program.cell, &counted.wall, &torch, (&from, qb));
                samples += ((from
                    .iter()
                    .zip(qb)
                    .map(|(a, b)| (a - b).abs())
                    .fold(0.0, f64::max)
                    / TRANSIT_STEP_RAD)
                    .ceil() as usize)
                    .clamp(1, 100_000)
                    + 1;
                seen_any |= !every.is_empty();
                assert_eq!(seen, every, "bead {k}");
            }
        }
        assert!(seen_any, "no move touches the wall");
        assert!(
            plain < samples / 2,
            "{plain} plain questions of {samples} samples"
        );
    }
}
