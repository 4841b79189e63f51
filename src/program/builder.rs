//! Stage 7, the builder: [`build_program`] and [`build_program_with`] check
//! that a planned [`JointTrajectory`] is buildable and assemble the
//! [`Program`]: one bead per layer between its approach and retract points,
//! the set-up before each bead, the home moves and the transits between
//! beads.

use crate::math::Point3;
use crate::program::{
    check_name, joints_move, moves, pose, split, transit, ArcFlag, BeadSetup, HomePosition,
    PlannedPoint, PointFeed, Program, ProgramError, ProgramOptions, ProgramPoint,
};
use crate::robot::cell::CellPoint;
use crate::robot::positioner::PositionerJoints;
use crate::robot::trajectory::{JointTrajectory, PathPointInput};
use crate::robot::{CellLayout, Joints};

/// Checks that the plan is buildable and assembles the program.
///
/// `points` and `trajectory` must be the same path in the same order (the
/// trajectory computed for these points by
/// [`joint_trajectory`](crate::robot::trajectory::joint_trajectory) or an
/// optimiser); each layer becomes one bead of at least two points. `feed`
/// gives each of them its travel speed and wire feed (mm/s, the move into
/// the point; [`PointFeed::constant`] for the same everywhere). Joint
/// speeds are re-checked at the given travel speeds.
///
/// # Errors
/// [`ProgramError::InvalidOptions`] for a bad name, speed or wire feed,
/// [`ProgramError::Mismatch`] when the inputs differ in length, layer or
/// point indices, or a layer has one point, and [`ProgramError::Infeasible`]
/// when the trajectory reports violations or a point has no joints, naming
/// the first.
pub fn build_program(
    name: &str,
    cell: &CellLayout,
    points: &[PathPointInput],
    trajectory: &JointTrajectory,
    feed: &[PointFeed],
) -> Result<Program, ProgramError> {
    build_program_with(
        name,
        cell,
        points,
        trajectory,
        feed,
        &ProgramOptions::default(),
    )
}

/// [`build_program`] with approach and retract points as `opts` say: before
/// each bead an [`ArcFlag::Approach`] point `clearance_mm` away from the part
/// along the tool axis (same orientation, same positioner joints), after it
/// an [`ArcFlag::Retract`] point, both checked like the bead points (joint
/// limits, and joint speeds of the linear moves into and out of the bead at
/// `approach_speed_mm_s`).
///
/// # Errors
/// As [`build_program`]; [`ProgramError::InvalidOptions`] for bad options;
/// [`ProgramError::Infeasible`] when an approach or retract point cannot be
/// reached, naming the layer.
pub fn build_program_with(
    name: &str,
    cell: &CellLayout,
    points: &[PathPointInput],
    trajectory: &JointTrajectory,
    feed: &[PointFeed],
    opts: &ProgramOptions,
) -> Result<Program, ProgramError> {
    opts.validate()?;
    check_name(name)?;
    if points.len() != trajectory.points.len() {
        return Err(ProgramError::Mismatch {
            index: points.len().min(trajectory.points.len()),
            reason: format!(
                "{} path points but {} trajectory points",
                points.len(),
                trajectory.points.len()
            ),
        });
    }
    if points.is_empty() {
        return Err(ProgramError::Mismatch {
            index: 0,
            reason: "empty path".into(),
        });
    }
    if feed.len() != points.len() {
        return Err(ProgramError::Mismatch {
            index: feed.len().min(points.len()),
            reason: format!(
                "{} speeds and wire feeds for {} points",
                feed.len(),
                points.len()
            ),
        });
    }
    for (i, f) in feed.iter().enumerate() {
        for (field, v) in [
            ("travel_speed_mm_s", f.travel_speed_mm_s),
            ("wire_feed_mm_s", f.wire_feed_mm_s),
        ] {
            if !(v.is_finite() && v > 0.0) {
                return Err(ProgramError::InvalidOptions {
                    field,
                    value: format!("{v} (index {i})"),
                    reason: "must be finite and > 0",
                });
            }
        }
    }
    let speeds: Vec<f64> = feed.iter().map(|f| f.travel_speed_mm_s).collect();
    if let Some(v) = trajectory.report.violations.first() {
        return Err(ProgramError::Infeasible {
            count: trajectory.report.violations.len(),
            first: v.to_string(),
            layers: vec![v.layer],
        });
    }
    let robot = cell.robot();
    let mut out: Vec<ProgramPoint> = Vec::with_capacity(points.len());
    for (i, (p, jp)) in points.iter().zip(&trajectory.points).enumerate() {
        if p.layer != jp.layer || p.point != jp.point {
            return Err(ProgramError::Mismatch {
                index: i,
                reason: format!(
                    "path point is layer {}, point {} but trajectory point is layer {}, point {}",
                    p.layer, p.point, jp.layer, jp.point
                ),
            });
        }
        let Some(q) = jp.joints else {
            return Err(ProgramError::Infeasible {
                count: 1,
                first: format!("layer {}, point {}: no joint solution", p.layer, p.point),
                layers: vec![p.layer],
            });
        };
        let first = i == 0 || !points[i - 1].same_bead(p);
        let last = i + 1 == points.len() || !points[i + 1].same_bead(p);
        if first && last {
            return Err(ProgramError::Mismatch {
                index: i,
                reason: format!("layer {} has a single point: no bead", p.layer),
            });
        }
        // speed re-check at the programmed speed (the trajectory used one TS)
        if !first {
            let prev = &out[i - 1];
            let d = (p.position_mm - prev.position_mm).norm();
            let turns = || {
                joints_move(&q, &prev.joints)
                    || match (jp.positioner, prev.positioner) {
                        (Some(a), Some(b)) => joints_move(&a, &b),
                        _ => false,
                    }
            };
            if d == 0.0 && turns() {
                return Err(ProgramError::Infeasible {
                    count: 1,
                    first: format!(
                        "layer {}, point {}: same position as point {} while the joints turn: \
                         a zero-length segment has no travel time at any speed",
                        p.layer,
                        p.point,
                        points[i - 1].point
                    ),
                    layers: vec![p.layer],
                });
            }
            if d > 0.0 {
                let dt = d / speeds[i];
                for (j, (qj, pj)) in q.iter().zip(prev.joints).enumerate() {
                    let s = (qj - pj).abs() / dt;
                    if s > robot.max_speed_rad_s[j] {
                        return Err(ProgramError::Infeasible {
                            count: 1,
                            first: format!(
                                "layer {}, point {}: J{} needs {:.2}°/s at {} mm/s, maximum {:.1}°/s",
                                p.layer,
                                p.point,
                                j + 1,
                                s.to_degrees(),
                                speeds[i],
                                robot.max_speed_rad_s[j].to_degrees()
                            ),
                            layers: vec![p.layer],
                        });
                    }
                }
            }
        }
        out.push(ProgramPoint {
            layer: p.layer,
            bead: p.bead,
            point: p.point,
            position_mm: p.position_mm,
            tool_axis: p.tool_axis,
            r_z: p.r_z,
            joints: q,
            positioner: jp.positioner,
            // a bead's first point carries its first segment's feed
            speed_mm_s: feed[if first && !last { i + 1 } else { i }].travel_speed_mm_s,
            wire_feed_mm_s: feed[if first && !last { i + 1 } else { i }].wire_feed_mm_s,
            arc: if first {
                ArcFlag::Start
            } else if last {
                ArcFlag::End
            } else {
                ArcFlag::On
            },
            via: false,
        });
    }
    if opts.clearance_mm > 0.0 {
        let mut all = Vec::with_capacity(out.len() + 2 * trajectory.points.len().min(out.len()));
        for (p, input) in out.iter().zip(points) {
            if p.arc == ArcFlag::Start {
                all.push(clearance_point_within_travel(
                    cell,
                    p,
                    input,
                    ArcFlag::Approach,
                    opts,
                )?);
            }
            all.push(*p);
            if p.arc == ArcFlag::End {
                all.push(clearance_point_within_travel(
                    cell,
                    p,
                    input,
                    ArcFlag::Retract,
                    opts,
                )?);
            }
        }
        out = all;
    }
    let home = opts.home(cell);
    if let Some(h) = &home {
        check_home(cell, h)?;
    }
    unwind_turns(cell, &mut out, home.as_ref())?;
    let bead_setup = out
        .iter()
        .filter(|p| p.arc == ArcFlag::Start)
        .enumerate()
        // a split bead waits as a layer's first does (`waam check` reads
        // every bead's set-up alike)
        .map(|(k, p)| BeadSetup {
            layer: p.layer,
            payload: None,
            dwell_s: if k > 0 { opts.dwell_s } else { 0.0 },
            wait_input: if k > 0 { opts.interpass_input } else { None },
        })
        .collect();
    let mut program = Program {
        name: name.to_string(),
        cell: cell.clone(),
        configuration: trajectory.configuration,
        points: out,
        home,
        bead_setup,
        planned: Vec::new(),
    };
    if opts.transit_check {
        safe_transits(&mut program, points, opts)?;
    }
    program.planned = program
        .bead_points()
        .map(|p| PlannedPoint {
            position_mm: p.position_mm,
            feed: PointFeed {
                travel_speed_mm_s: p.speed_mm_s,
                wire_feed_mm_s: p.wire_feed_mm_s,
            },
        })
        .collect();
    moves::thin_beads(&mut program, opts)?;
    Ok(program)
}

/// Shifts the positioner's turn of each bead's block of points (approach,
/// bead, retract) by whole turns into the turn's stroke
/// ([`Positioner::turn_stroke`](crate::robot::positioner::Positioner::turn_stroke)),
/// choosing, of the shifts that fit, the one that starts the block nearest
/// where the table is (the previous block's last point, or home): the
/// table unwinds during the arc-off joint move between beads, never during
/// a bead. The turn is periodic, so the arm's joints and the deposition
/// point are unchanged. Nothing to do without a positioner.
///
/// # Errors
/// [`ProgramError::Infeasible`] naming the layer whose bead turns the
/// table through more than the stroke holds.
fn unwind_turns(
    cell: &CellLayout,
    points: &mut [ProgramPoint],
    home: Option<&HomePosition>,
) -> Result<(), ProgramError> {
    use std::f64::consts::TAU;
    let CellLayout::TorchCarried(c) = cell else {
        return Ok(());
    };
    let stroke = pose::turn_stroke(cell).unwrap_or(c.positioner.limits[1]);
    let mut at = home.and_then(|h| h.positioner).map_or(0.0, |q| q[1]);
    for b in blocks(points) {
        let turns: Vec<f64> = points[b.first..=b.last]
            .iter()
            .filter_map(|p| p.positioner.map(|q| q[1]))
            .collect();
        let Some(&start) = turns.first() else {
            continue;
        };
        let lo = turns.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = turns.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        let Some((k_min, k_max)) = stroke.whole_turn_shifts(lo, hi) else {
            return Err(ProgramError::Infeasible {
                count: 1,
                first: format!(
                    "layer {}: the bead turns the positioner's table from {:.1}° to {:.1}° ({:.1}°), more than its stroke [{:.1}°, {:.1}°] holds",
                    points[b.start].layer,
                    lo.to_degrees(),
                    hi.to_degrees(),
                    (hi - lo).to_degrees(),
                    stroke.lower_rad.to_degrees(),
                    stroke.upper_rad.to_degrees()
                ),
                layers: vec![points[b.start].layer],
            });
        };
        let k = ((at - start) / TAU).round().clamp(k_min, k_max);
        for p in &mut points[b.first..=b.last] {
            if let Some(q) = &mut p.positioner {
                q[1] += k * TAU;
            }
        }
        at = points[b.last].positioner.map_or(at, |q| q[1]);
    }
    Ok(())
}

/// Refuses a home position outside the arm's (or positioner's) travel.
fn check_home(cell: &CellLayout, h: &HomePosition) -> Result<(), ProgramError> {
    let bad = |what: String| ProgramError::InvalidOptions {
        field: "home_deg",
        value: what,
        reason: "the home position must be inside the joints' travel",
    };
    if let Some((j, v)) = cell.robot().limit_violations(&h.joints).next() {
        return Err(bad(format!("J{} = {:.3}°", j + 1, v.to_degrees())));
    }
    if let (CellLayout::TorchCarried(c), Some(qp)) = (cell, h.positioner) {
        let turn = pose::turn_stroke(cell).unwrap_or(c.positioner.limits[1]);
        let stroke = [c.positioner.limits[0], turn];
        for (i, (l, v)) in stroke.iter().zip(qp).enumerate() {
            if !l.contains(v) {
                return Err(ProgramError::InvalidOptions {
                    field: "home_positioner_deg",
                    value: format!("J{} = {:.3}°", i + 7, v.to_degrees()),
                    reason: "the home position must be inside the positioner's travel",
                });
            }
        }
    }
    Ok(())
}

/// The points of one bead's block in a program: indices of its first point
/// (approach, or the bead's first point), its bead's first and last points,
/// its last point (retract, or the bead's last point), and of the bead's
/// first point among the path points.
#[derive(Debug, Clone, Copy)]
struct Block {
    first: usize,
    start: usize,
    end: usize,
    last: usize,
    start_input: usize,
}

fn blocks(points: &[ProgramPoint]) -> Vec<Block> {
    let arcs: Vec<ArcFlag> = points.iter().map(|p| p.arc).collect();
    let mut bead_points = 0;
    split::beads(&arcs)
        .into_iter()
        .map(|r| {
            let find = |flag| r.clone().find(|&i| arcs[i] == flag).unwrap_or(r.start);
            let block = Block {
                first: r.start,
                start: find(ArcFlag::Start),
                end: find(ArcFlag::End),
                last: r.end - 1,
                start_input: bead_points,
            };
            bead_points += arcs[r].iter().filter(|a| a.is_bead()).count();
            block
        })
        .collect()
}

/// Checks every arc-off joint move between two beads (and the last one, to
/// home) against the wall deposited so far ([`transit`](crate::program::transit)); where one
/// collides, moves that transition's retract and approach points further
/// along the tool axis (2, 4, 8… times `clearance_mm`, up to
/// `transit_max_clearance_mm`) until it clears, and where none of these
/// clears, leaves the retract and approach points as they were and goes
/// through [`ArcFlag::Transit`] via points instead ([`via_points`]).
fn safe_transits(
    program: &mut Program,
    inputs: &[PathPointInput],
    opts: &ProgramOptions,
) -> Result<(), ProgramError> {
    use rayon::prelude::*;
    let torch = crate::toolaxis::collision::Torch::new(&Default::default()).map_err(|e| {
        ProgramError::InvalidOptions {
            field: "transit_check",
            value: e.to_string(),
            reason: "the torch model for the transit check is invalid",
        }
    })?;
    let blocks = blocks(&program.points);
    // Each bead decimated once; the wall after bead k is the union of at
    // most log2(k + 1) + 1 blocks of them, each block's tree built once.
    let mut decimated = transit::WallBeads::default();
    for b in &blocks {
        let bead: Vec<Point3> = program.points[b.start..=b.end]
            .iter()
            .map(|p| p.position_mm)
            .collect();
        decimated.push(&bead);
    }
    let n = blocks.len();
    let target = |program: &Program, k: usize| -> Option<(Joints, Option<PositionerJoints>)> {
        if k + 1 < n {
            let p = &program.points[blocks[k + 1].first];
            Some((p.joints, p.positioner))
        } else {
            program.home.map(|h| (h.joints, h.positioner))
        }
    };
    // the joint move after bead k: the wall so far, the point it leaves
    // from and the joints it goes to (none after the last bead without home)
    let transit_of = |program: &Program, k: usize| {
        target(program, k).map(|(qb, pb)| {
            let wall = decimated.wall(k + 1, opts.bead_radius_mm);
            (wall, program.points[blocks[k].last], qb, pb)
        })
    };
    // the deepest sample of a transit, for a refusal's text
    let check = |program: &Program, k: usize| -> Result<transit::TransitClearance, ProgramError> {
        let Some((wall, from, qb, pb)) = transit_of(program, k) else {
            return Ok(transit::TransitClearance {
                min_clearance_mm: f64::INFINITY,
                at_fraction: 0.0,
                tip_mm: Point3::origin(),
            });
        };
        let a = (&from.joints, from.positioner);
        transit::joint_move_clearance(&program.cell, &wall, &torch, a, (&qb, pb))
            .map_err(|e| transit_failed(from.layer, e))
    };
    // whether a transit touches, stopping at its first sample that does
    let touches = |program: &Program, k: usize| -> Result<bool, ProgramError> {
        let Some((wall, from, qb, pb)) = transit_of(program, k) else {
            return Ok(false);
        };
        let a = (&from.joints, from.positioner);
        transit::joint_move_touches(&program.cell, &wall, &torch, a, (&qb, pb))
            .map_err(|e| transit_failed(from.layer, e))
    };
    // via points to insert after a block's last point, in block order
    let mut inserts: Vec<(usize, Vec<ProgramPoint>)> = Vec::new();
    let first: Vec<Result<bool, ProgramError>> = (0..n)
        .into_par_iter()
        .map(|k| touches(program, k))
        .collect();
    for (k, r) in first.into_iter().enumerate() {
        if !r? {
            continue;
        }
        let layer = program.points[blocks[k].end].layer;
        let next_layer = (k + 1 < n).then(|| program.points[blocks[k + 1].start].layer);
        let to_what = match next_layer {
            Some(l) => format!("layer {l}'s approach"),
            None => "home".to_string(),
        };
        let layers: Vec<usize> = std::iter::once(layer)
            .chain(next_layer.filter(|&l| l != layer))
            .collect();
        let refuse = |r: transit::TransitClearance, why: String| ProgramError::Infeasible {
            count: 1,
            first: format!(
                "layer {layer}: the arc-off joint move to {to_what} passes {} at {:.0}% of the \
                 move (torch tip at [{:.1}, {:.1}, {:.1}] mm, part frame){why}",
                transit::intrusion(r.min_clearance_mm, opts.bead_radius_mm),
                100.0 * r.at_fraction,
                r.tip_mm.x,
                r.tip_mm.y,
                r.tip_mm.z
            ),
            layers: layers.clone(),
        };
        let has_retract = program.points[blocks[k].last].arc == ArcFlag::Retract;
        let next_approach = (k + 1 < n)
            .then(|| blocks[k + 1])
            .filter(|b| program.points[b.first].arc == ArcFlag::Approach);
        if opts.clearance_mm <= 0.0 || !has_retract {
            return Err(refuse(
                check(program, k)?,
                " and the program has no retract points to raise (clearance_mm = 0)".into(),
            ));
        }
        let mut fixed = false;
        for c in lifts(opts) {
            let end = program.points[blocks[k].end];
            let end_input = &inputs[blocks[k].start_input + (blocks[k].end - blocks[k].start)];
            let Ok(retract) =
                clearance_point(&program.cell, &end, end_input, ArcFlag::Retract, opts, c)
            else {
                continue;
            };
            let approach = match next_approach {
                Some(b) => {
                    let start = program.points[b.start];
                    match clearance_point(
                        &program.cell,
                        &start,
                        &inputs[b.start_input],
                        ArcFlag::Approach,
                        opts,
                        c,
                    ) {
                        Ok(a) => Some((b.first, a)),
                        Err(_) => continue,
                    }
                }
                None => None,
            };
            let old_retract = program.points[blocks[k].last];
            let old_approach = approach.map(|(i, _)| program.points[i]);
            program.points[blocks[k].last] = retract;
            if let Some((i, a)) = approach {
                program.points[i] = a;
            }
            if !touches(program, k)? {
                fixed = true;
                break;
            } else {
                program.points[blocks[k].last] = old_retract;
                if let (Some((i, _)), Some(a)) = (approach, old_approach) {
                    program.points[i] = a;
                }
            }
        }
        if !fixed {
            // the program is as it was: through via points, or the
            // deepest sample of the direct transit
            let wall = decimated.wall(k + 1, opts.bead_radius_mm);
            let transit = Transit {
                from: blocks[k],
                to: next_approach,
                target: target(program, k),
            };
            match via_points(program, inputs, opts, &transit, &wall, &torch)? {
                Some(vias) => inserts.push((blocks[k].last, vias)),
                None => {
                    return Err(refuse(
                        check(program, k)?,
                        format!(
                            ", even with the retract and approach points raised up to {} mm \
                             along the tool axis (transit_max_clearance_mm) or through via \
                             points (the torch lifted that far, the positioner turning alone, \
                             home)",
                            opts.transit_max_clearance_mm
                        ),
                    ))
                }
            }
        }
    }
    for (after, vias) in inserts.into_iter().rev() {
        program.points.splice(after + 1..after + 1, vias);
    }
    Ok(())
}

/// An arc-off transit between two beads' blocks ([`via_points`]): the
/// block it leaves, the next one's block when it has an approach point,
/// and the joints it goes to (the next block's first point, or home).
struct Transit {
    from: Block,
    to: Option<Block>,
    target: Option<(Joints, Option<PositionerJoints>)>,
}

/// Via points ([`ArcFlag::Transit`]) for an arc-off transit whose direct
/// joint move touches `wall`, tried at lift heights of 2, 4, 8… times
/// `clearance_mm` up to `transit_max_clearance_mm`, each in this order:
/// 1. the torch lifted that far along the tool axis from the bead's last
///    point; the positioner turning alone to the next bead's joints with the
///    arm still; the torch lowered along the tool axis to the next bead's
///    first point that far (torch-carried cell);
/// 2. the same without the positioner's own move;
/// 3. the first lifted point, the home position, the second.
///
/// The first sequence whose every joint move (from the retract point
/// through the vias to the next approach point, or home) clears `wall` is
/// kept; `None` when none does.
fn via_points(
    program: &Program,
    inputs: &[PathPointInput],
    opts: &ProgramOptions,
    transit: &Transit,
    wall: &(impl transit::TransitWall + ?Sized),
    torch: &crate::toolaxis::collision::Torch,
) -> Result<Option<Vec<ProgramPoint>>, ProgramError> {
    let Some(target) = transit.target else {
        return Ok(None);
    };
    let cell = &program.cell;
    let retract = program.points[transit.from.last];
    let end = program.points[transit.from.end];
    let end_input = &inputs[transit.from.start_input + (transit.from.end - transit.from.start)];
    // a via point at joints `q`, `qp`: the torch tip and axis seen from the
    // part, labelled as the bead it leaves
    let via_at = |q: Joints, qp: Option<PositionerJoints>| -> Option<ProgramPoint> {
        let (tip, axis) = transit::torch_in_part(cell, &q, qp)?;
        Some(ProgramPoint {
            position_mm: tip,
            tool_axis: crate::math::UnitVector3::new_normalize(axis),
            joints: q,
            positioner: qp,
            speed_mm_s: opts.approach_speed_mm_s,
            wire_feed_mm_s: 0.0,
            arc: ArcFlag::Transit,
            via: false,
            ..end
        })
    };
    let clears = |vias: &[ProgramPoint]| -> Result<bool, ProgramError> {
        let mut from = (retract.joints, retract.positioner);
        for to in vias
            .iter()
            .map(|v| (v.joints, v.positioner))
            .chain(std::iter::once(target))
        {
            if transit::joint_move_touches(cell, wall, torch, (&from.0, from.1), (&to.0, to.1))
                .map_err(|e| transit_failed(end.layer, e))?
            {
                return Ok(false);
            }
            from = to;
        }
        Ok(true)
    };
    let home = program.home.and_then(|h| via_at(h.joints, h.positioner));
    // a sequence already checked at a lower lift (the retract point or the
    // approach point standing in for a lifted one) is not walked again
    let mut tried: Vec<Vec<ProgramPoint>> = Vec::new();
    for lift in lifts(opts) {
        let via = |p: &ProgramPoint, input: &PathPointInput| {
            // labelled as the bead the transit leaves, in whose block it is
            lifted(cell, p, input, ArcFlag::Transit, lift).map(|v| ProgramPoint {
                speed_mm_s: opts.approach_speed_mm_s,
                layer: end.layer,
                bead: end.bead,
                point: end.point,
                ..v
            })
        };
        // a point that leaves a joint's travel at this lift is left out:
        // the transit then starts from the retract point, or ends at the
        // approach point, themselves
        let up = via(&end, end_input).ok();
        let down = transit
            .to
            .and_then(|b| via(&program.points[b.start], &inputs[b.start_input]).ok());
        let mut candidates: Vec<Vec<ProgramPoint>> = Vec::new();
        // the positioner alone, with the torch lifted
        let arm = up.map_or(retract.joints, |u| u.joints);
        let positioner = up.map_or(retract.positioner, |u| u.positioner);
        if target.1.is_some() && target.1 != positioner {
            if let Some(turned) = via_at(arm, target.1) {
                candidates.push([up, Some(turned), down].into_iter().flatten().collect());
            }
        }
        if up.is_some() || down.is_some() {
            candidates.push([up, down].into_iter().flatten().collect());
        }
        if let Some(h) = home {
            candidates.push([up, Some(h), down].into_iter().flatten().collect());
        }
        for vias in candidates {
            if tried.contains(&vias) {
                continue;
            }
            if clears(&vias)? {
                return Ok(Some(vias));
            }
            tried.push(vias);
        }
    }
    Ok(None)
}

/// The lifts a transit's retract and approach points are raised to, and
/// its via points lifted to ([`via_points`]): 2, 4, 8… times
/// `clearance_mm`, the last one `transit_max_clearance_mm` (mm).
fn lifts(opts: &ProgramOptions) -> impl Iterator<Item = f64> + '_ {
    std::iter::successors(Some(opts.clearance_mm), |&c| {
        (c < opts.transit_max_clearance_mm).then(|| (2.0 * c).min(opts.transit_max_clearance_mm))
    })
    .skip(1)
}

/// A transit check that could not be made (a sample without a torch pose,
/// or parry's error), named by the layer it leaves.
fn transit_failed(layer: usize, e: String) -> ProgramError {
    ProgramError::Infeasible {
        count: 1,
        first: format!("layer {layer}: transit check: {e}"),
        layers: vec![layer],
    }
}

/// The approach or retract point of bead point `p` at `clearance_mm`, or,
/// where that one leaves a joint's travel (a bead that ends with J5 a
/// fraction of a degree inside its stop), at a half, a quarter or an eighth
/// of it; refused with the full clearance's reason if none works.
fn clearance_point_within_travel(
    cell: &CellLayout,
    p: &ProgramPoint,
    input: &PathPointInput,
    flag: ArcFlag,
    opts: &ProgramOptions,
) -> Result<ProgramPoint, ProgramError> {
    let mut first_error = None;
    for divisor in [1.0, 2.0, 4.0, 8.0] {
        match clearance_point(cell, p, input, flag, opts, opts.clearance_mm / divisor) {
            Ok(point) => return Ok(point),
            Err(e) => {
                first_error.get_or_insert(e);
            }
        }
    }
    Err(first_error.expect("at least one clearance tried"))
}

/// The approach or retract point of bead point `p`: `clearance_mm` along the
/// tool axis, same orientation and positioner joints, joints unwrapped
/// towards `p`'s ([`lifted`]); refused if a joint leaves its travel or the
/// linear move between it and `p` outruns a joint at the approach speed.
fn clearance_point(
    cell: &CellLayout,
    p: &ProgramPoint,
    input: &PathPointInput,
    flag: ArcFlag,
    opts: &ProgramOptions,
    clearance_mm: f64,
) -> Result<ProgramPoint, ProgramError> {
    let lifted = lifted(cell, p, input, flag, clearance_mm)?;
    let robot = cell.robot();
    let dt = clearance_mm / opts.approach_speed_mm_s;
    for (j, (qj, pj)) in lifted.joints.iter().zip(p.joints).enumerate() {
        let s = (qj - pj).abs() / dt;
        if s > robot.max_speed_rad_s[j] {
            return Err(lifted_error(
                p,
                flag,
                clearance_mm,
                format!(
                    "J{} needs {:.2}°/s at {} mm/s, maximum {:.1}°/s",
                    j + 1,
                    s.to_degrees(),
                    opts.approach_speed_mm_s,
                    robot.max_speed_rad_s[j].to_degrees()
                ),
            ));
        }
    }
    Ok(ProgramPoint {
        speed_mm_s: opts.approach_speed_mm_s,
        ..lifted
    })
}

/// A refusal of the point `clearance_mm` from bead point `p` along the tool
/// axis, for `flag`'s purpose.
fn lifted_error(p: &ProgramPoint, flag: ArcFlag, clearance_mm: f64, msg: String) -> ProgramError {
    let what = match flag {
        ArcFlag::Approach => "approach",
        ArcFlag::Retract => "retract",
        _ => "transit via",
    };
    ProgramError::Infeasible {
        count: 1,
        first: format!(
            "layer {}, {what} point ({} mm from point {} along the tool axis): {msg}",
            p.layer, clearance_mm, p.point
        ),
        layers: vec![p.layer],
    }
}

/// Bead point `p` moved `clearance_mm` along the tool axis with `flag`,
/// same orientation and positioner joints, the arm's joints from the IK
/// unwrapped towards `p`'s, the arc off (speed: `p`'s, to be set by the
/// caller); refused if the positioner would have to move or a joint leaves
/// its travel.
fn lifted(
    cell: &CellLayout,
    p: &ProgramPoint,
    input: &PathPointInput,
    flag: ArcFlag,
    clearance_mm: f64,
) -> Result<ProgramPoint, ProgramError> {
    let infeasible = |msg: String| lifted_error(p, flag, clearance_mm, msg);
    let position_mm = p.position_mm + p.tool_axis.into_inner() * clearance_mm;
    let cp = CellPoint {
        position_mm,
        tool_axis: p.tool_axis,
        build_direction: input.build_direction,
        // the planned positioner as the program writes it (its turn
        // unwound by whole turns, `unwind_turns`)
        positioner: input.positioner.and(p.positioner),
        travel_speed_mm_s: input.travel_speed_mm_s,
    };
    let q8 = p.positioner.map_or(0.0, |q| q[1]);
    let (q, pose) = cell
        .joints(&cp, p.r_z, Some(&p.joints), q8)
        .map_err(|e| infeasible(e.to_string()))?;
    if let (Some(a), Some(b)) = (pose.positioner, p.positioner) {
        if (a[0] - b[0]).abs() > 1e-9 || (a[1] - b[1]).abs() > 1e-9 {
            return Err(infeasible("the positioner would have to move".into()));
        }
    }
    let robot = cell.robot();
    if let Some((j, v)) = robot.limit_violations(&q).next() {
        return Err(infeasible(format!(
            "J{} = {:.3}° outside its travel",
            j + 1,
            v.to_degrees()
        )));
    }
    Ok(ProgramPoint {
        position_mm,
        joints: q,
        positioner: pose.positioner,
        wire_feed_mm_s: 0.0,
        arc: flag,
        via: false,
        ..*p
    })
}
