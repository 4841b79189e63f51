//! Stage 7, the moves a controller is given: each bead of a [`Program`]
//! thinned to the fewest positions whose interpolated path stays within
//! [`ProgramOptions::path_tolerance_mm`] and
//! [`ProgramOptions::orientation_tolerance_deg`] of every planned point
//! ([`compress`]), with linear moves and, where a stretch is a circle arc
//! within the tolerances and [`ProgramOptions::circular_moves`] is on,
//! circular ones (FANUC `C`, KUKA `CIRC`, ABB `ArcC`; the via is marked
//! [`ProgramPoint::via`]). The controller's model of a move is the one the
//! emitters ask for and the checker samples
//! ([`interpolate`](crate::program::compress::interpolate)): the tool
//! centre point moves on a straight line or on the circle through the via,
//! its orientation turns by slerp from the start to the end over the
//! path's length (the via's orientation is not used: KUKA `$ORI_TYPE =
//! #VAR` with `$CIRC_TYPE = #BASE`, ABB `MoveC`/`ArcC`, FANUC `C`; the
//! via's planned orientation is within the orientation tolerance of that
//! slerp, so a controller that passes through it stays within it too) in
//! the frame the move is programmed in, extra axes (the positioner)
//! linearly —
//! the part frame where the part is the moving frame (remote/fixed tool in
//! the part-carried cell, coordinated motion in the torch-carried one),
//! else the robot base frame with the positioner turning the part under it.
//! The deviation is measured over the part in both cases. Bead ends, speed
//! and wire feed changes and every point outside beads are kept.

use crate::math::Isometry3;
use crate::program::compress::{compress, CompressOptions, Move};
use crate::program::frames::fixed_torch_at;
use crate::program::pose::{arc_length, controller_pose_at, moves_in_part_frame, ControllerPose};
use crate::program::validate::between::{check_between, InterpolatedMove};
use crate::program::{ArcFlag, Program, ProgramError, ProgramOptions, ProgramPoint};
use crate::robot::CellLayout;

/// What thinning did to a program's beads.
#[derive(Debug, Clone, Copy, PartialEq, Default, serde::Serialize)]
pub struct Thinning {
    /// Bead points before (one per planned point).
    pub bead_points_before: usize,
    /// Bead positions kept: one per linear move, two per circular move
    /// (its via and its end), plus each bead's first point.
    pub bead_points_after: usize,
    /// Circular moves among them ([`ProgramOptions::circular_moves`]).
    pub circular_moves: usize,
    /// Largest distance between the interpolated path and the planned
    /// points or polyline, over the part (mm).
    pub max_path_error_mm: f64,
    /// Largest angle between the interpolated and the planned torch axis
    /// (deg).
    pub max_orientation_error_deg: f64,
}

/// Relative speed change that makes a point a must-keep (a move carries one
/// speed).
const SPEED_CHANGE: f64 = 1e-9;

/// Largest turn of any joint over one thinned move (rad): a controller
/// solves the joints between two positions itself, and near the wrist
/// singularity a small change of orientation is a large one of J4 and J6;
/// a move stops where the planned joints have turned this much, so that
/// the controller's joints cannot take the other way round.
const MAX_JOINT_TURN_PER_MOVE_RAD: f64 = std::f64::consts::FRAC_PI_4;

/// Largest sweep of a circular move in a thinned bead (deg): a whole layer
/// is three circular moves (six positions) rather than two whose
/// orientation turns half a turn each (see [`thin_beads`]).
pub const MAX_ARC_SWEEP_DEG: f64 = 120.0;

/// The bead points every thinned move must stop at: where the travel
/// speed or the wire feed changes (a move carries one of each: the point
/// between the last segment of one and the first of the other), and where
/// the joints have turned [`MAX_JOINT_TURN_PER_MOVE_RAD`] since the last
/// such point.
fn must_keep(bead: &[ProgramPoint]) -> Vec<bool> {
    let mut keep = vec![false; bead.len()];
    let mut anchor = 0;
    let changes = |a: f64, b: f64| (a - b).abs() > SPEED_CHANGE * a.abs();
    for k in 1..bead.len() {
        // point k carries the feed of the segment into it
        let feed = changes(bead[k].speed_mm_s, bead[k - 1].speed_mm_s)
            || changes(bead[k].wire_feed_mm_s, bead[k - 1].wire_feed_mm_s);
        let turned = bead[k]
            .joints
            .iter()
            .zip(&bead[anchor].joints)
            .any(|(a, b)| (a - b).abs() > MAX_JOINT_TURN_PER_MOVE_RAD);
        if feed || turned {
            // a feed change ends the move at the segment's start; a turn
            // stops at the last point before it grows too large
            let at = if k - 1 > anchor { k - 1 } else { k };
            keep[at] = true;
            anchor = at;
        }
    }
    keep
}

/// The tool centre point's pose and the positioner joints as the controller
/// interpolates them for point `p` (module doc): part frame when `in_part`,
/// else robot base frame.
fn controller_pose(cell: &CellLayout, p: &ProgramPoint, in_part: bool) -> ControllerPose {
    controller_pose_at(cell, &p.joints, p.positioner, in_part)
}

/// `true` when the circular move from `a` through `via` to `b` runs as the
/// checker samples it ([`check_between`]): every joint within its travel,
/// no jump, no joint above its maximum speed at the planned travel speed.
fn circle_runs(
    cell: &CellLayout,
    opts: &ProgramOptions,
    a: &ProgramPoint,
    via: &ProgramPoint,
    b: &ProgramPoint,
) -> bool {
    let length = arc_length(&a.position_mm, &via.position_mm, &b.position_mm);
    let mv = InterpolatedMove {
        from: (&a.joints, a.positioner),
        via: Some((&via.joints, via.positioner)),
        to: (&b.joints, b.positioner),
        duration_s: length / b.speed_mm_s,
        planned: None,
    };
    check_between(cell, opts, &mv).is_empty()
}

/// Thins every bead of `program` (module doc); `None` when
/// `opts.path_tolerance_mm` is 0 (every point kept).
///
/// # Errors
/// [`ProgramError::InvalidOptions`] for a tolerance the compressor refuses;
/// [`ProgramError::Mismatch`] naming the layer when a bead's poses cannot
/// be compressed (not finite).
pub fn thin_beads(
    program: &mut Program,
    opts: &ProgramOptions,
) -> Result<Option<Thinning>, ProgramError> {
    if opts.path_tolerance_mm == 0.0 {
        return Ok(None);
    }
    let copts = CompressOptions {
        path_tolerance_mm: opts.path_tolerance_mm,
        orientation_tolerance_deg: opts.orientation_tolerance_deg,
        allow_circular: opts.circular_moves,
        // where the part frame moves with the positioner, the torch turns
        // over the part as much as the arc sweeps: at 180° the slerp's
        // shortest way round is undefined and the rounding of the written
        // positions picks it; MAX_ARC_SWEEP_DEG keeps it well away
        max_arc_angle_deg: MAX_ARC_SWEEP_DEG,
        // the joints follow the whole rotation, R_Z included
        rotation_tolerance_deg: Some(opts.orientation_tolerance_deg),
        ..CompressOptions::default()
    };
    let cell = program.cell.clone();
    // the part frame is the moving frame unless a torch-carried cell moves
    // without coordination
    let in_part = moves_in_part_frame(&cell, opts);
    // the fixed torch of a part-carried cell, once (the same pose at every
    // call)
    let fixed_torch = match &cell {
        CellLayout::PartCarried(c) => fixed_torch_at(&c.deposition_point_mm),
        CellLayout::TorchCarried(_) => Isometry3::identity(),
    };
    let map = |pose: &ControllerPose| -> (crate::math::Point3, crate::math::Vector3) {
        let controller = Isometry3::from_parts(pose.p.coords.into(), pose.q);
        let frame = match (&cell, in_part) {
            (_, true) => controller,
            (CellLayout::TorchCarried(c), false) => {
                let qp = [pose.ext[0], pose.ext[1]];
                c.base_from_part(&qp).inverse() * controller
            }
            // the fixed torch seen from the part held by the interpolated flange
            (CellLayout::PartCarried(c), false) => {
                (controller * c.flange_from_part).inverse() * fixed_torch
            }
        };
        (
            frame.translation.vector.into(),
            frame.rotation * crate::math::Vector3::z(),
        )
    };
    let points = std::mem::take(&mut program.points);
    // the beads (arc start ..= arc end), each thinned on its own, in
    // parallel; then the program rebuilt in order
    let mut beads: Vec<(usize, usize)> = Vec::new();
    let mut i = 0;
    while i < points.len() {
        if points[i].arc != ArcFlag::Start {
            i += 1;
            continue;
        }
        let end = (i..points.len())
            .find(|&k| points[k].arc == ArcFlag::End)
            .unwrap_or(points.len() - 1);
        beads.push((i, end));
        i = end + 1;
    }
    let thin_one = |&(i, end): &(usize, usize)| -> Result<_, ProgramError> {
        let bead = &points[i..=end];
        let poses: Vec<ControllerPose> = bead
            .iter()
            .map(|p| controller_pose(&cell, p, in_part))
            .collect();
        let keep = must_keep(bead);
        let c = compress(&poses, &keep, &map, &copts).map_err(|e| ProgramError::Mismatch {
            index: i,
            reason: format!("layer {}: move compression: {e}", bead[0].layer),
        })?;
        // a circular move whose joints leave their travel, jump or outrun
        // their speed between the positions (sampled as the checker does)
        // is written with linear moves instead
        let mut c = c;
        let mut moves = Vec::with_capacity(c.moves.len());
        let mut start = 0;
        for m in &c.moves {
            match *m {
                Move::Circular { via, to }
                    if !circle_runs(&cell, opts, &bead[start], &bead[via], &bead[to]) =>
                {
                    let sub = compress(
                        &poses[start..=to],
                        &keep[start..=to],
                        &map,
                        &CompressOptions {
                            allow_circular: false,
                            ..copts.clone()
                        },
                    )
                    .map_err(|e| ProgramError::Mismatch {
                        index: i,
                        reason: format!("layer {}: move compression: {e}", bead[0].layer),
                    })?;
                    c.max_path_error_mm = c.max_path_error_mm.max(sub.max_path_error_mm);
                    c.max_orientation_error_deg = c
                        .max_orientation_error_deg
                        .max(sub.max_orientation_error_deg);
                    moves.extend(
                        sub.moves
                            .iter()
                            .map(|s| Move::Linear { to: start + s.to() }),
                    );
                }
                m => moves.push(m),
            }
            start = m.to();
        }
        c.moves = moves;
        Ok(c)
    };
    let thinned: Vec<_> = {
        use rayon::prelude::*;
        beads.par_iter().map(thin_one).collect()
    };
    let mut report = Thinning::default();
    let mut kept: Vec<ProgramPoint> = Vec::with_capacity(points.len());
    let mut next = 0;
    for (&(i, end), c) in beads.iter().zip(thinned) {
        let c = c?;
        kept.extend_from_slice(&points[next..i]);
        let bead = &points[i..=end];
        report.bead_points_before += bead.len();
        report.max_path_error_mm = report.max_path_error_mm.max(c.max_path_error_mm);
        report.max_orientation_error_deg = report
            .max_orientation_error_deg
            .max(c.max_orientation_error_deg);
        kept.push(bead[0]);
        for m in &c.moves {
            if let Move::Circular { via, .. } = *m {
                kept.push(ProgramPoint {
                    via: true,
                    ..bead[via]
                });
                report.circular_moves += 1;
            }
            kept.push(bead[m.to()]);
        }
        report.bead_points_after += c.programmed_indices().len();
        next = end + 1;
    }
    kept.extend_from_slice(&points[next..]);
    program.points = kept;
    Ok(Some(report))
}
