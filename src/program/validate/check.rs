//! The one checker of decoded [`DecodedStep`]s (module doc of
//! [`validate`](super)): bead points, joint limits, speeds, configuration
//! consistency, deposition points against the plan, process on and off.

use std::f64::consts::PI;

use crate::math::Point3;
use crate::program::pose::{arc_length, interpolate, ControllerPose};
use crate::program::transit::{joint_move_clearance, WallBeads};
use crate::program::MoveKind;
use crate::program::{PlannedPoint, ProgramOptions};
use crate::robot::{CellLayout, Joints};
use crate::toolaxis::collision::Torch;
use nalgebra::UnitQuaternion;

use super::between::{check_between, InterpolatedMove};
use super::ProblemKind;
use super::{
    deposition_point, push, DecodedStep, Motion, MotionSpeed, ValidationReport, NAMES,
    REACH_TOLERANCE_MM,
};

/// A motion as the checker keeps it for the next move: its joints (rad),
/// its positioner joints (rad) and its deposition point (part frame, mm).
type Reached = (Joints, Option<[f64; 2]>, Option<Point3>);

/// Checks decoded `steps` against `cell` (module doc), adding problems and
/// counts to `report`. `planned`: the planned deposition points (part
/// frame, mm) with their travel speeds and wire feeds (mm/s), one per bead
/// motion in execution order; with them, each arc-on move's wire feed over
/// its travel speed (the bead's cross-section, SPEC §5) is checked against
/// the planned points it reaches, within the rounding of the written
/// numbers ([`WireFeed::tolerance`](super::WireFeed::tolerance)).
pub fn check_steps(
    steps: &[DecodedStep],
    cell: &CellLayout,
    planned: Option<&[PlannedPoint]>,
    common: &crate::program::ProgramOptions,
    report: &mut ValidationReport,
) {
    let bead = bead_points(steps);
    let mut checker = Checker {
        cell,
        planned,
        common,
        bead: &bead,
        arc_on: None,
        prev: None,
        plan_cursor: 0,
        via: None,
        prev_matched: None,
        bead_motions: 0,
        first_file: None,
    };
    for (i, s) in steps.iter().enumerate() {
        match s {
            DecodedStep::ProcessOn { file, line } => checker.process_on(file, *line, report),
            DecodedStep::ProcessOff { file, line } => checker.process_off(file, *line, report),
            DecodedStep::Wait { .. } | DecodedStep::Payload { .. } => {}
            DecodedStep::Motion(m) => checker.motion(i, m, report),
        }
    }
    checker.finish(steps, report);
}

/// Which motions of `steps` are bead points: made with the process on, or
/// the last motion before the process starts.
fn bead_points(steps: &[DecodedStep]) -> Vec<bool> {
    let mut bead = vec![false; steps.len()];
    let mut on = false;
    let mut last_motion: Option<usize> = None;
    for (i, s) in steps.iter().enumerate() {
        match s {
            DecodedStep::Motion(_) => {
                bead[i] = on;
                last_motion = Some(i);
            }
            DecodedStep::ProcessOn { .. } => {
                if let Some(k) = last_motion {
                    bead[k] = true;
                }
                on = true;
            }
            DecodedStep::ProcessOff { .. } => on = false,
            DecodedStep::Wait { .. } | DecodedStep::Payload { .. } => {}
        }
    }
    bead
}

/// What [`check_steps`] carries from step to step.
struct Checker<'a> {
    cell: &'a CellLayout,
    planned: Option<&'a [PlannedPoint]>,
    common: &'a ProgramOptions,
    /// `bead[i]`: step `i` is a bead motion.
    bead: &'a [bool],
    /// The bead on: file and line of its start.
    arc_on: Option<(String, usize)>,
    /// The last motion's end.
    prev: Option<Reached>,
    /// The planned point each bead motion lands on, in order: thinned
    /// programs skip planned points, none goes back.
    plan_cursor: usize,
    /// The via of the circular move the next motion ends.
    via: Option<Reached>,
    /// The planned point the last motion landed on.
    prev_matched: Option<usize>,
    bead_motions: usize,
    first_file: Option<String>,
}

impl Checker<'_> {
    /// A bead starts at `file:line`.
    fn process_on(&mut self, file: &str, line: usize, report: &mut ValidationReport) {
        if let Some((f, l)) = &self.arc_on {
            let msg = format!(
                "bead starts while the bead started at {f}:{l} is still on (missing Arc End / end instruction)"
            );
            push(report, ProblemKind::Bead, file, line, msg);
        }
        self.arc_on = Some((file.to_string(), line));
    }

    /// A bead stops at `file:line`.
    fn process_off(&mut self, file: &str, line: usize, report: &mut ValidationReport) {
        if self.arc_on.take().is_none() {
            push(
                report,
                ProblemKind::Bead,
                file,
                line,
                "bead stops but none was started".into(),
            );
        } else {
            report.beads += 1;
        }
    }

    /// Motion `m`, step `i`: its position (limits, configuration, the plan)
    /// and the move to it from the last one.
    fn motion(&mut self, i: usize, m: &Motion, report: &mut ValidationReport) {
        self.first_file.get_or_insert_with(|| m.file.clone());
        report.motions += 1;
        let k = self.bead_motions;
        if self.bead[i] {
            self.bead_motions += 1;
        }
        if m.kind == MoveKind::Joint && self.arc_on.is_some() {
            push(
                report,
                ProblemKind::Bead,
                &m.file,
                m.line,
                "joint move with the arc on".into(),
            );
        }
        // a circular move's via comes first as its own motion; the move is
        // checked at its end, the next motion
        let circle_via = self.via.take();
        match (m.kind, &circle_via) {
            (MoveKind::Circular, None) => push(
                report,
                ProblemKind::Instruction,
                &m.file,
                m.line,
                format!("{}: circular move without a via point", m.label),
            ),
            (MoveKind::Circular, Some(_)) => {}
            (_, Some(_)) => push(
                report,
                ProblemKind::Instruction,
                &m.file,
                m.line,
                format!(
                    "{}: a via point not followed by the end of its circular move",
                    m.label
                ),
            ),
            _ => {}
        }
        let Some(q) = m.joints else {
            self.prev = None;
            self.prev_matched = None;
            return;
        };
        self.check_position(m, &q, report);
        let qp = m.positioner;
        let dep = deposition_point(self.cell, &q, qp);
        let matched = self.match_plan(i, m, dep, k, report);
        if m.kind == MoveKind::Via {
            self.via = Some((q, qp, dep));
            return;
        }
        if let Some(prev) = &self.prev {
            let msgs = self.check_move(i, m, prev, &(q, qp, dep), circle_via.as_ref(), matched);
            for (kind, msg) in msgs {
                push(report, kind, &m.file, m.line, msg);
            }
        }
        self.prev = Some((q, qp, dep));
        self.prev_matched = matched;
    }

    /// Motion `m`'s joints `q`: inside the arm's limits, in the cell's
    /// configuration (joint positions), the positioner inside its travel.
    fn check_position(&self, m: &Motion, q: &Joints, report: &mut ValidationReport) {
        let (cell, robot) = (self.cell, self.cell.robot());
        for (j, name) in NAMES.iter().enumerate() {
            let l = robot.limits[j];
            if !l.contains(q[j]) {
                push(
                    report,
                    ProblemKind::JointLimit,
                    &m.record_file,
                    m.value_lines[j],
                    format!(
                        "{}: {name} = {:.4}° outside [{:.1}°, {:.1}°]",
                        m.label,
                        q[j].to_degrees(),
                        l.lower_rad.to_degrees(),
                        l.upper_rad.to_degrees()
                    ),
                );
            }
        }
        let cfg = robot.configuration_of(q);
        if !m.from_cartesian && cfg != cell.configuration() {
            push(
                report,
                ProblemKind::Configuration,
                &m.record_file,
                m.record_line,
                format!(
                    "{}: joints are in configuration '{cfg}', not the cell's '{}'",
                    m.label,
                    cell.configuration()
                ),
            );
        }
        let qp = m.positioner;
        if let CellLayout::TorchCarried(c) = cell {
            match qp {
                None => push(
                    report,
                    ProblemKind::Format,
                    &m.record_file,
                    m.record_line,
                    format!("{}: no positioner values", m.label),
                ),
                Some(qp) => {
                    let turn =
                        crate::program::pose::turn_stroke(cell).unwrap_or(c.positioner.limits[1]);
                    let travel = [c.positioner.limits[0], turn];
                    for (n, l) in travel.iter().enumerate() {
                        if !l.contains(qp[n]) {
                            push(
                                report,
                                ProblemKind::JointLimit,
                                &m.record_file,
                                m.record_line,
                                format!(
                                    "{}: positioner J{} = {:.4}° outside its travel",
                                    m.label,
                                    n + 1,
                                    qp[n].to_degrees()
                                ),
                            );
                        }
                    }
                }
            }
        }
    }

    /// The planned point bead motion `m` (step `i`, the `k`-th bead motion)
    /// lands on with its deposition point `dep`: the plan is followed in
    /// order, from where it stands on.
    fn match_plan(
        &mut self,
        i: usize,
        m: &Motion,
        dep: Option<Point3>,
        k: usize,
        report: &mut ValidationReport,
    ) -> Option<usize> {
        let mut matched = None;
        let plan_cursor = self.plan_cursor;
        if let (true, Some(plan), Some(d)) = (self.bead[i], self.planned, dep) {
            matched = (plan_cursor..plan.len())
                .find(|&j| (d - plan[j].position_mm).norm() <= REACH_TOLERANCE_MM);
            match matched {
                // a bead's first motion lands on the next planned point:
                // no bead is skipped
                Some(j) if self.prev_matched.is_none() && j != plan_cursor => {
                    push(
                        report,
                        ProblemKind::Deviation,
                        &m.record_file,
                        m.value_lines[0],
                        format!(
                            "{}: a bead starts at planned point {j}, but the plan continues at point {plan_cursor}: planned points skipped",
                            m.label
                        ),
                    );
                    self.plan_cursor = j + 1;
                }
                Some(j) => self.plan_cursor = j + 1,
                None => {
                    let e = plan
                        .get(plan_cursor.min(plan.len().saturating_sub(1)))
                        .map_or(f64::INFINITY, |t| (d - t.position_mm).norm());
                    push(
                        report,
                        ProblemKind::Deviation,
                        &m.record_file,
                        m.value_lines[0],
                        format!(
                            "{}: deposition point on no planned point from {plan_cursor} on ({e:.4} mm from it; bead motion {k})",
                            m.label
                        ),
                    );
                }
            }
        }
        matched
    }

    /// The problems of the move of motion `m` (step `i`) from `prev` to
    /// `to` (through `circle_via`, landing on planned point `matched`):
    /// joint jumps, what its duration asks of the joints, and the path
    /// between its ends.
    fn check_move(
        &self,
        i: usize,
        m: &Motion,
        prev: &Reached,
        to: &Reached,
        circle_via: Option<&Reached>,
        matched: Option<usize>,
    ) -> Vec<(ProblemKind, String)> {
        let (cell, planned) = (self.cell, self.planned);
        let ((pq, pqp, _), (q, qp, _)) = (prev, *to);
        let mut msgs = jumps(m, pq, &q, circle_via);
        let dt = self.duration(m, prev, to, circle_via, &mut msgs);
        // with the plan known, a move between neighbouring planned
        // points is the plan's own discretisation (the planner checked
        // it); the moves that skip planned points are sampled
        let skips = match (planned, self.prev_matched, matched) {
            (Some(_), Some(j0), Some(j1)) => j1 > j0 + 1,
            (Some(_), _, _) => false,
            (None, _, _) => true,
        } || m.kind == MoveKind::Circular;
        let interpolated = matches!(m.kind, MoveKind::Linear | MoveKind::Circular);
        if let (Some((duration_s, _)), true, true) = (&dt, interpolated, skips) {
            let planned_between = match (planned, self.prev_matched, matched) {
                // a move between neighbouring planned points is the
                // plan's own discretisation: only moves that skip planned
                // points are held to the planned polyline
                (Some(plan), Some(j0), Some(j1)) if self.bead[i] && j1 > j0 + 1 => Some(
                    plan[j0..=j1]
                        .iter()
                        .map(|p| p.position_mm)
                        .collect::<Vec<Point3>>(),
                ),
                _ => None,
            };
            msgs.extend(check_between(
                cell,
                self.common,
                &InterpolatedMove {
                    from: (pq, *pqp),
                    via: circle_via.map(|(qv, qvp, _)| (qv, *qvp)),
                    to: (&q, qp),
                    duration_s: *duration_s,
                    planned: planned_between.as_deref(),
                },
            ));
        }
        if let Some((dt, how)) = &dt {
            msgs.extend(joint_speeds(cell, pq, *pqp, &q, qp, *dt, how));
        }
        if let (Some((dt, _)), true) = (dt, self.arc_on.is_some()) {
            msgs.extend(self.check_feed(m, prev, to, circle_via, dt, matched));
        }
        msgs
    }

    /// The wire feed over the travel speed of arc-on move `m` (from `prev`
    /// to `to` through `circle_via`, taking `dt` s, landing on planned
    /// point `matched`) against the plan's at every planned point it
    /// reaches: equal within the rounding of the written numbers
    /// ([`WireFeed::tolerance`](super::WireFeed::tolerance)). Nothing without the plan, a wire feed in
    /// the file (a custom process) or a deposition point.
    fn check_feed(
        &self,
        m: &Motion,
        prev: &Reached,
        to: &Reached,
        circle_via: Option<&Reached>,
        dt: f64,
        matched: Option<usize>,
    ) -> Option<(ProblemKind, String)> {
        let (plan, feed, j0, j1) = (self.planned?, m.wire_feed?, self.prev_matched?, matched?);
        let (a, b) = (prev.2?, to.2?);
        // the path the move deposits as the controller interpolates it
        // (in the robot base frame it bows away from the chord)
        let d = if crate::program::pose::moves_in_part_frame(self.cell, self.common) {
            match circle_via.and_then(|v| v.2) {
                Some(v) => arc_length(&a, &v, &b),
                None => (b - a).norm(),
            }
        } else {
            crate::program::pose::deposited_length_mm(
                self.cell,
                (&prev.0, prev.1),
                circle_via.map(|v| (&v.0, v.1)),
                (&to.0, to.1),
                false,
            )
        };
        if !(dt > 0.0 && d > 0.0) {
            return None;
        }
        let ts = d / dt;
        let ratio = feed.mm_s / ts;
        // the written numbers' steps, and the length measured between
        // positions decoded within REACH_TOLERANCE_MM of the planned ones
        let tolerance = feed.tolerance + 2.0 * REACH_TOLERANCE_MM / d;
        plan.get(j0 + 1..=j1)?.iter().enumerate().find_map(|(n, p)| {
            let want = p.feed.ratio();
            ((ratio / want - 1.0).abs() > tolerance + 1e-9).then(|| {
                (
                    ProblemKind::Feed,
                    format!(
                        "{}: wire feed {:.3} mm/s at {:.3} mm/s travel speed (WFS/TS {:.4}) but the plan has {:.3} mm/s at {:.3} mm/s ({:.4}) at planned point {}: the bead's cross-section is {:+.2} % off (rounding allows {:.2} %)",
                        m.label,
                        feed.mm_s,
                        ts,
                        ratio,
                        p.feed.wire_feed_mm_s,
                        p.feed.travel_speed_mm_s,
                        want,
                        j0 + 1 + n,
                        100.0 * (ratio / want - 1.0),
                        100.0 * tolerance
                    ),
                )
            })
        })
    }

    /// The duration (s) of the move of motion `m` from `prev` to `to`
    /// (through `circle_via`) as the controller runs it at `m`'s speed, and
    /// how, in messages; `None` for a joint move (the controller's own
    /// speed). A move the controller would not run at its speed adds to
    /// `msgs`.
    fn duration(
        &self,
        m: &Motion,
        prev: &Reached,
        to: &Reached,
        circle_via: Option<&Reached>,
        msgs: &mut Vec<(ProblemKind, String)>,
    ) -> Option<(f64, String)> {
        let (cell, robot) = (self.cell, self.cell.robot());
        let ((pq, pqp, pm), (q, qp, dep)) = (prev, *to);
        // the length of the path: the chord, or the arc through the via
        let path_length = |a: &Point3, b: &Point3, via: Option<Point3>| match via {
            Some(v) => arc_length(a, &v, b),
            None => (b - a).norm(),
        };
        let via_dep = circle_via.and_then(|(_, _, d)| *d);
        match (m.speed, dep, pm) {
            (MotionSpeed::Linear(v), Some(a), Some(b))
                if circle_via.is_none() || via_dep.is_some() =>
            {
                let d = path_length(b, &a, via_dep);
                (d > 0.0).then(|| (d / v, format!("at {v:.3} mm/s")))
            }
            (
                MotionSpeed::Tcp {
                    mm_s,
                    flange_from_tcp,
                    extax_fraction,
                },
                _,
                _,
            ) => {
                let tcp = |q: &Joints| (robot.flange_pose(q) * flange_from_tcp).translation.vector;
                let via_tcp = circle_via.map(|(qv, _, _)| Point3::from(tcp(qv)));
                let mut t =
                    path_length(&Point3::from(tcp(pq)), &Point3::from(tcp(&q)), via_tcp) / mm_s;
                if let (CellLayout::TorchCarried(c), Some(a), Some(b)) = (cell, qp, pqp) {
                    for n in 0..2 {
                        let max = c.positioner.max_speed_rad_s[n] * extax_fraction[n];
                        let turn = (a[n] - b[n]).abs();
                        if max.is_finite() && max > 0.0 && turn > 0.0 {
                            t = t.max(turn / max);
                        }
                    }
                }
                if t == 0.0 && crate::program::joints_move(&q, pq) {
                    // the controller then runs the move at its
                    // orientation speed, not at any planned speed
                    msgs.push((ProblemKind::Timing, format!(
                        "linear move at {mm_s:.3} mm/s TCP speed with the TCP still while the joints turn: \
                         the controller would turn at its orientation speed limit (write it time-based)"
                    )));
                }
                (t > 0.0).then(|| (t, format!("at {mm_s:.3} mm/s TCP speed")))
            }
            (MotionSpeed::Time(t), _, _) => {
                if t > 0.0 {
                    Some((t, format!("in {:.0} ms", t * 1000.0)))
                } else {
                    msgs.push((ProblemKind::Timing, "zero duration".into()));
                    None
                }
            }
            _ => None,
        }
    }

    /// After the last step: a bead never stopped, the set-up, and the plan
    /// built to its end.
    fn finish(self, steps: &[DecodedStep], report: &mut ValidationReport) {
        if let Some((file, line)) = self.arc_on {
            push(
                report,
                ProblemKind::Bead,
                &file,
                line,
                "bead started here never stops (no Arc End / end instruction before the program ends)"
                    .into(),
            );
        }
        check_setup(steps, self.cell, self.common, self.bead, report);
        let (plan_cursor, bead_motions) = (self.plan_cursor, self.bead_motions);
        if let Some(p) = self.planned {
            if plan_cursor != p.len() {
                push(
                    report,
                    ProblemKind::Deviation,
                    self.first_file.as_deref().unwrap_or(""),
                    0,
                    format!(
                        "{bead_motions} bead motions in the programs end at planned point {plan_cursor} of {}: the rest of the plan is not built",
                        p.len()
                    ),
                );
            }
        }
    }
}

/// The joint jumps of a linear or circular move of motion `m` from `pq`
/// to `q` (each leg through `circle_via`): joint moves (between beads) may
/// rewind J4/J6; linear and circular moves (each leg of these) may not
/// jump.
fn jumps(
    m: &Motion,
    pq: &Joints,
    q: &Joints,
    circle_via: Option<&Reached>,
) -> Vec<(ProblemKind, String)> {
    let mut msgs = Vec::new();
    let linear = m.speed != MotionSpeed::Joint;
    // joint moves (between beads) may rewind J4/J6; linear and
    // circular moves (each leg of these) may not jump
    let legs: Vec<(&Joints, &Joints)> = match circle_via {
        Some((qv, _, _)) => vec![(pq, qv), (qv, q)],
        None => vec![(pq, q)],
    };
    for (j, (a, b)) in (0..6)
        .filter(|_| linear)
        .flat_map(|j| legs.iter().map(move |leg| (j, *leg)))
    {
        if (b[j] - a[j]).abs() >= PI {
            msgs.push((
                ProblemKind::Configuration,
                format!(
                    "{} jumps by {:.2}° from the previous position (turn or configuration change)",
                    NAMES[j],
                    (b[j] - a[j]).to_degrees()
                ),
            ));
        }
    }
    msgs
}

/// The joint speeds of a move from `pq` (positioner `pqp`) to `q` (`qp`)
/// in `dt` s (`how`, in messages) above the arm's and the positioner's
/// maxima.
fn joint_speeds(
    cell: &CellLayout,
    pq: &Joints,
    pqp: Option<[f64; 2]>,
    q: &Joints,
    qp: Option<[f64; 2]>,
    dt: f64,
    how: &str,
) -> Vec<(ProblemKind, String)> {
    let robot = cell.robot();
    let mut msgs = Vec::new();
    for j in 0..6 {
        let sp = (q[j] - pq[j]).abs() / dt;
        if sp > robot.max_speed_rad_s[j] {
            msgs.push((
                ProblemKind::JointSpeed,
                format!(
                    "{} needs {:.2}°/s {how}, maximum {:.1}°/s",
                    NAMES[j],
                    sp.to_degrees(),
                    robot.max_speed_rad_s[j].to_degrees()
                ),
            ));
        }
    }
    if let (CellLayout::TorchCarried(c), Some(a), Some(b)) = (cell, qp, pqp) {
        for n in 0..2 {
            let sp = (a[n] - b[n]).abs() / dt;
            if sp > c.positioner.max_speed_rad_s[n] {
                msgs.push((
                    ProblemKind::JointSpeed,
                    format!("positioner J{} needs {:.2}°/s", n + 1, sp.to_degrees()),
                ));
            }
        }
    }
    msgs
}

/// Largest difference between a home joint in the file and the cell's
/// `home_deg` (rad): 0.01°, above the files' rounding.
const HOME_TOLERANCE_RAD: f64 = 0.01 * PI / 180.0;

/// Checks the program's set-up against the cell's `[program]` options
/// (`common`): home as first and last motion, the dwell, interpass wait and
/// payload updates between beads (never with the arc on), and every arc-off
/// joint move against the wall deposited before it (the bead motions'
/// deposition points, capsules of `bead_radius_mm`; the substrate is not in
/// the files and is not checked). `bead[i]`: step `i` is a bead motion.
fn check_setup(
    steps: &[DecodedStep],
    cell: &CellLayout,
    common: &ProgramOptions,
    bead: &[bool],
    report: &mut ValidationReport,
) {
    check_home_ends(steps, cell, common, [true, true], report);
    // what happens before each bead: from the end of the previous bead (or
    // the program start) to the bead's process-on
    let part_carried = matches!(cell, CellLayout::PartCarried(_));
    let mut on = false;
    let mut beads_started = 0usize;
    let mut waited_s = 0.0;
    let mut waited_input = false;
    let mut payload = false;
    let mut last_mass: Option<f64> = None;
    for s in steps {
        match s {
            DecodedStep::ProcessOn { file, line } => {
                let k = beads_started;
                let mut missing = Vec::new();
                if k > 0 && common.dwell_s > 0.0 && waited_s + 0.005 < common.dwell_s {
                    missing.push(format!(
                        "an interlayer dwell of {} s (waits {waited_s} s)",
                        common.dwell_s
                    ));
                }
                if let (true, Some(n)) = (k > 0, common.interpass_input) {
                    if !waited_input {
                        missing.push(format!("an interpass wait on input {n}"));
                    }
                }
                let every = common.payload_every_layers as usize;
                if part_carried && every > 0 && k % every == 0 && !payload {
                    missing.push("a payload update".into());
                }
                if !missing.is_empty() {
                    push(
                        report,
                        ProblemKind::Setup,
                        file,
                        *line,
                        format!(
                            "bead {} starts without {} before it (cell [program] options)",
                            k + 1,
                            missing.join(", ")
                        ),
                    );
                }
                beads_started += 1;
                on = true;
            }
            DecodedStep::ProcessOff { .. } => {
                on = false;
                waited_s = 0.0;
                waited_input = false;
                payload = false;
            }
            DecodedStep::Wait {
                file,
                line,
                seconds,
                input,
            } => {
                if on {
                    push(
                        report,
                        ProblemKind::Setup,
                        file,
                        *line,
                        "a wait with the arc on (the bead would burn through)".into(),
                    );
                }
                waited_s += seconds.unwrap_or(0.0);
                if input.is_some() && *input == common.interpass_input {
                    waited_input = true;
                }
            }
            DecodedStep::Payload {
                file,
                line,
                mass_kg,
                cog_mm,
            } => {
                if on {
                    push(
                        report,
                        ProblemKind::Setup,
                        file,
                        *line,
                        "a payload change with the arc on".into(),
                    );
                }
                if !(mass_kg.is_finite() && *mass_kg >= 0.0 && cog_mm.iter().all(|v| v.is_finite()))
                {
                    push(
                        report,
                        ProblemKind::Setup,
                        file,
                        *line,
                        format!("payload {mass_kg} kg at {cog_mm:?} is not a valid load"),
                    );
                } else if last_mass.is_some_and(|m| *mass_kg + 1e-3 < m) {
                    push(
                        report,
                        ProblemKind::Setup,
                        file,
                        *line,
                        format!(
                            "payload {mass_kg:.3} kg is less than the previous {:.3} kg: the part only grows",
                            last_mass.unwrap_or_default()
                        ),
                    );
                } else if last_mass.is_none() && *mass_kg + 1e-3 < common.payload_base_kg {
                    push(
                        report,
                        ProblemKind::Setup,
                        file,
                        *line,
                        format!(
                            "payload {mass_kg:.3} kg is less than the substrate and fixture ({} kg)",
                            common.payload_base_kg
                        ),
                    );
                }
                last_mass = Some(*mass_kg);
                payload = true;
            }
            DecodedStep::Motion(_) => {}
        }
    }
    if common.transit_check {
        check_transits(steps, cell, common, bead, report);
    }
}

/// Checks that the first (`ends[0]`) and the last (`ends[1]`) motion of
/// `steps` are joint moves to the cell's home, when `common` has one: a
/// whole program's, or those of one group of a build cut to the memory
/// budget (each group starts and ends at home).
pub(crate) fn check_home_ends(
    steps: &[DecodedStep],
    cell: &CellLayout,
    common: &ProgramOptions,
    ends: [bool; 2],
    report: &mut ValidationReport,
) {
    let motions: Vec<(usize, &Motion)> = steps
        .iter()
        .enumerate()
        .filter_map(|(i, s)| match s {
            DecodedStep::Motion(m) => Some((i, m.as_ref())),
            _ => None,
        })
        .collect();
    if let Some(h) = common.home(cell) {
        // an endless turn written modulo 360° is home at any whole turn
        let modulo = crate::program::pose::turn_modulo(cell);
        let turn_difference = |n: usize, d: f64| {
            if modulo && n == 1 {
                crate::robot::ik::wrap_pi(d)
            } else {
                d
            }
        };
        let is_home =
            |m: &Motion| {
                m.kind == MoveKind::Joint
                    && m.joints.is_some_and(|q| {
                        q.iter()
                            .zip(h.joints)
                            .all(|(a, b)| (a - b).abs() <= HOME_TOLERANCE_RAD)
                    })
                    && match (h.positioner, m.positioner) {
                        (Some(a), Some(b)) => a.iter().zip(b).enumerate().all(|(n, (x, y))| {
                            turn_difference(n, x - y).abs() <= HOME_TOLERANCE_RAD
                        }),
                        (None, _) => true,
                        (Some(_), None) => false,
                    }
            };
        let home_deg = |h: &crate::program::HomePosition| {
            h.joints
                .iter()
                .map(|v| format!("{:.3}", v.to_degrees()))
                .collect::<Vec<_>>()
                .join(", ")
        };
        for ((which, m), check) in [("first", motions.first()), ("last", motions.last())]
            .into_iter()
            .zip(ends)
        {
            if !check {
                continue;
            }
            match m {
                Some((_, m)) if !is_home(m) => push(
                    report,
                    ProblemKind::Setup,
                    &m.file,
                    m.line,
                    format!(
                        "the {which} motion ({}) is not a joint move to the cell's home [{}] deg",
                        m.label,
                        home_deg(&h)
                    ),
                ),
                None => push(
                    report,
                    ProblemKind::Setup,
                    "",
                    0,
                    "no motion: the cell's home position is never reached".into(),
                ),
                _ => {}
            }
        }
    }
}

/// Every arc-off joint move against the wall of the beads before it.
fn check_transits(
    steps: &[DecodedStep],
    cell: &CellLayout,
    common: &ProgramOptions,
    bead: &[bool],
    report: &mut ValidationReport,
) {
    let Ok(torch) = Torch::new(&Default::default()) else {
        return;
    };
    let mut beads = WallBeads::default();
    let mut current: Vec<Point3> = Vec::new();
    let mut via_dep: Option<Point3> = None;
    let mut prev: Option<(Joints, Option<[f64; 2]>)> = None;
    for (i, s) in steps.iter().enumerate() {
        match s {
            DecodedStep::ProcessOff { .. } if !current.is_empty() => {
                beads.push(&std::mem::take(&mut current));
            }
            DecodedStep::Motion(m) => {
                let Some(q) = m.joints else {
                    prev = None;
                    continue;
                };
                if bead[i] {
                    if let Some(d) = deposition_point(cell, &q, m.positioner) {
                        match (m.kind, via_dep.take(), current.last()) {
                            // the wall follows the arc, not the chords
                            // through the via
                            (MoveKind::Via, ..) => via_dep = Some(d),
                            (MoveKind::Circular, Some(v), Some(a)) => {
                                current.extend(arc_samples(a, &v, &d));
                            }
                            _ => current.push(d),
                        }
                    }
                }
                if let (Some((pq, pp)), MoveKind::Joint) = (prev, m.kind) {
                    if !beads.is_empty() {
                        // the blocks' trees are built once, at their first use
                        let wall = beads.wall(beads.len(), common.bead_radius_mm);
                        match joint_move_clearance(cell, &wall, &torch, (&pq, pp), (&q, m.positioner)) {
                            Ok(c) if c.min_clearance_mm <= 0.0 => push(
                                report,
                                ProblemKind::Collision,
                                &m.file,
                                m.line,
                                format!(
                                    "the joint move to {} sweeps the torch {} at {:.0}% of the move (torch tip at [{:.1}, {:.1}, {:.1}] mm, part frame)",
                                    m.label,
                                    crate::program::transit::intrusion(c.min_clearance_mm, common.bead_radius_mm),
                                    100.0 * c.at_fraction,
                                    c.tip_mm.x,
                                    c.tip_mm.y,
                                    c.tip_mm.z
                                ),
                            ),
                            Ok(_) => {}
                            Err(e) => push(report, ProblemKind::Collision, &m.file, m.line, format!("transit check: {e}")),
                        }
                    }
                }
                prev = Some((q, m.positioner));
            }
            _ => {}
        }
    }
}

/// Largest distance (mm) between the wall's points along a circular bead.
const WALL_ARC_STEP_MM: f64 = 1.0;

/// Points along the circle arc from `a` through `via` to `b` (part frame,
/// mm; [`interpolate`]'s circle), every [`WALL_ARC_STEP_MM`] at most, `b`
/// last and `a` left out.
fn arc_samples(a: &Point3, via: &Point3, b: &Point3) -> Vec<Point3> {
    let pose = |p: &Point3| ControllerPose::new(*p, UnitQuaternion::identity(), Vec::new());
    let (pa, pv, pb) = (pose(a), pose(via), pose(b));
    let n = ((arc_length(a, via, b) / WALL_ARC_STEP_MM).ceil() as usize).clamp(1, 10_000);
    (1..=n)
        .map(|k| interpolate(&pa, Some(&pv), &pb, k as f64 / n as f64).p)
        .collect()
}
