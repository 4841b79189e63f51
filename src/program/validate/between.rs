//! Between the moves: a linear or circular move sampled as the controller
//! interpolates it ([`interpolate`](crate::program::pose::interpolate),
//! the model the compressor thinned the beads with: the tool on a straight
//! line or on the circle through the via, its orientation by slerp from
//! start to end, the positioner linearly, in the frame the move is
//! programmed in,
//! [`moves_in_part_frame`](crate::program::pose::moves_in_part_frame)),
//! each sample's joints solved in the cell's branch nearest the previous
//! sample's, and checked: joint travel, joint speeds over each sampled
//! stretch at the move's timing, no jump, and, when the plan is known, the
//! deposition point within the path tolerance of the planned polyline
//! between the two planned points the move joins (only for a move that
//! skips planned points: between two neighbouring planned points the plan
//! is its own discretisation).

use std::f64::consts::PI;

use crate::math::Point3;
use crate::program::pose::{controller_pose_at, flange_of, interpolate, moves_in_part_frame};
use crate::program::ProgramOptions;
use crate::robot::{CellLayout, Joints};

use super::{deposition_point, ProblemKind, NAMES, REACH_TOLERANCE_MM};

/// Samples per millimetre of the deposition point's travel over the part.
const SAMPLES_PER_MM: f64 = 1.0;
/// Samples per degree of the largest joint's turn.
const SAMPLES_PER_DEG: f64 = 2.0;
/// Fewest and most samples of one move.
const SAMPLES: (usize, usize) = (4, 400);

/// One linear or circular move, from the previous motion to this one.
pub(crate) struct InterpolatedMove<'a> {
    /// Joints and positioner joints where the move starts (rad).
    pub from: (&'a Joints, Option<[f64; 2]>),
    /// Joints and positioner joints of a circular move's via (rad); `None`
    /// for a linear move.
    pub via: Option<(&'a Joints, Option<[f64; 2]>)>,
    /// Joints and positioner joints where it ends (rad).
    pub to: (&'a Joints, Option<[f64; 2]>),
    /// How long it takes (s).
    pub duration_s: f64,
    /// The planned polyline it must follow (part frame, mm), when known.
    pub planned: Option<&'a [Point3]>,
}

/// The problems found between the ends of `mv` (module doc), each with its
/// kind; at most one of each kind.
pub(crate) fn check_between(
    cell: &CellLayout,
    common: &ProgramOptions,
    mv: &InterpolatedMove<'_>,
) -> Vec<(ProblemKind, String)> {
    let robot = cell.robot();
    let in_part = moves_in_part_frame(cell, common);
    let a = controller_pose_at(cell, mv.from.0, mv.from.1, in_part);
    let b = controller_pose_at(cell, mv.to.0, mv.to.1, in_part);
    let via = mv
        .via
        .map(|(q, qp)| controller_pose_at(cell, q, qp, in_part));
    // the legs through the via: travel and joint turn are summed over them
    let ends: Vec<(&Joints, Option<[f64; 2]>)> = [Some(mv.from), mv.via, Some(mv.to)]
        .into_iter()
        .flatten()
        .collect();
    let travel: f64 = ends
        .windows(2)
        .map(|w| {
            match (
                deposition_point(cell, w[0].0, w[0].1),
                deposition_point(cell, w[1].0, w[1].1),
            ) {
                (Some(p), Some(q)) => (p - q).norm(),
                _ => 0.0,
            }
        })
        .sum();
    let turn = ends
        .windows(2)
        .map(|w| {
            w[0].0
                .iter()
                .zip(w[1].0)
                .map(|(x, y)| (x - y).abs())
                .fold(0.0, f64::max)
        })
        .sum::<f64>()
        .to_degrees();
    let n = ((travel * SAMPLES_PER_MM).max(turn * SAMPLES_PER_DEG).ceil() as usize)
        .clamp(SAMPLES.0, SAMPLES.1);
    let mut out: Vec<(ProblemKind, String)> = Vec::new();
    let mut note = |kind: ProblemKind, msg: String| {
        if !out.iter().any(|(k, _)| *k == kind) {
            out.push((kind, msg));
        }
    };
    let mut prev = *mv.from.0;
    let tolerance = common.path_tolerance_mm + REACH_TOLERANCE_MM;
    for k in 1..n {
        let s = k as f64 / n as f64;
        let pose = interpolate(&a, via.as_ref(), &b, s);
        let qp = (!pose.ext.is_empty()).then(|| [pose.ext[0], pose.ext[1]]);
        let flange = flange_of(cell, &pose, in_part);
        let q = match robot.inverse_near(&flange, cell.configuration(), &prev) {
            Ok(q) => q,
            Err(e) => {
                note(
                    ProblemKind::Reach,
                    format!("between the moves, at {:.0}% of the move: {e}", 100.0 * s),
                );
                return out;
            }
        };
        let dt = mv.duration_s / n as f64;
        for j in 0..6 {
            if !robot.limits[j].contains(q[j]) {
                note(
                    ProblemKind::JointLimit,
                    format!(
                        "between the moves, at {:.0}% of the move: {} = {:.4}° outside its travel",
                        100.0 * s,
                        NAMES[j],
                        q[j].to_degrees()
                    ),
                );
            }
            let d = (q[j] - prev[j]).abs();
            if d >= PI / 2.0 {
                note(
                    ProblemKind::Configuration,
                    format!(
                        "between the moves, at {:.0}% of the move: {} jumps by {:.2}°",
                        100.0 * s,
                        NAMES[j],
                        d.to_degrees()
                    ),
                );
            } else if dt > 0.0 && d / dt > robot.max_speed_rad_s[j] {
                note(
                    ProblemKind::JointSpeed,
                    format!(
                        "between the moves, at {:.0}% of the move: {} needs {:.2}°/s, maximum {:.1}°/s",
                        100.0 * s,
                        NAMES[j],
                        (d / dt).to_degrees(),
                        robot.max_speed_rad_s[j].to_degrees()
                    ),
                );
            }
        }
        if let (Some(plan), Some(dep)) = (mv.planned, deposition_point(cell, &q, qp)) {
            let e = polyline_distance(plan, &dep);
            if e > tolerance {
                note(
                    ProblemKind::Deviation,
                    format!(
                        "between the moves, at {:.0}% of the move: deposition point {e:.4} mm from the planned path (path_tolerance_mm {})",
                        100.0 * s,
                        common.path_tolerance_mm
                    ),
                );
            }
        }
        prev = q;
    }
    out
}

/// Distance from `x` to the polyline through `plan` (mm).
fn polyline_distance(plan: &[Point3], x: &Point3) -> f64 {
    match plan {
        [] => f64::INFINITY,
        [p] => (x - p).norm(),
        _ => plan
            .windows(2)
            .map(|w| {
                let (a, b) = (w[0], w[1]);
                let ab = b - a;
                let l2 = ab.norm_squared();
                let t = if l2 > 0.0 {
                    ((x - a).dot(&ab) / l2).clamp(0.0, 1.0)
                } else {
                    0.0
                };
                (x - (a + ab * t)).norm()
            })
            .fold(f64::INFINITY, f64::min),
    }
}
