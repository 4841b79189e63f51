//! Validator of robot programs from the files alone plus the cell [SPEC §8]:
//! joint limits (arm and positioner), joint speeds at the programmed speeds
//! (or segment times), reachability (Cartesian positions: IK with the file's
//! configuration data — FANUC `CONFIG` string and turn numbers, KUKA Status
//! and Turn, ABB `confdata` — then FK back within 0.01 mm; and, when the
//! plan is given, the deposition point of every bead position within 0.01 mm
//! of the planned one), configuration consistency (the cell's branch
//! everywhere, no joint jumping by half a turn or more between consecutive
//! linear moves), and that every bead starts and stops once. Every problem
//! names its file and line; the report lists them all.
//!
//! Each controller's reader turns its files into the same [`Step`]s (motions
//! with decoded joints, process on and off, in execution order); one checker
//! ([`check_steps`]) validates them. Bead points are the motions made with
//! the process on plus the motion that reaches a bead's first point (the one
//! before the process starts); the other motions (approach, retract,
//! transitions) are checked for limits, configuration and speeds but not
//! compared with the planned points.

use std::f64::consts::{PI, TAU};
use std::fmt;

use crate::math::{Isometry3, Point3};
use crate::program::fanuc::{ArmPosition, FanucOptions, MoveKind, Op, TpProgram};
use crate::program::ProcessControl;
use crate::robot::ik::wrap_pi;
use crate::robot::orientation::FanucPose;
use crate::robot::{ArmSide, Cell, Configuration, Elbow, Joints, RobotModel, Vendor, Wrist};

/// Largest accepted distance between a position and what it should reach (mm).
pub const REACH_TOLERANCE_MM: f64 = 0.01;

/// One problem found in a program.
#[derive(Debug, Clone, PartialEq)]
pub struct Problem {
    /// Program (file) name.
    pub file: String,
    /// Line (1-based).
    pub line: usize,
    /// What is wrong.
    pub message: String,
}

impl fmt::Display for Problem {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}:{}: {}", self.file, self.line, self.message)
    }
}

/// Every problem of a set of programs, in execution order.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct ValidationReport {
    /// The problems.
    pub problems: Vec<Problem>,
    /// Motions checked.
    pub motions: usize,
    /// Beads (started and stopped once).
    pub beads: usize,
}

impl ValidationReport {
    /// `true` when no problem was found.
    pub fn is_ok(&self) -> bool {
        self.problems.is_empty()
    }
}

impl fmt::Display for ValidationReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.problems.is_empty() {
            return writeln!(f, "ok: {} motions, {} beads", self.motions, self.beads);
        }
        for p in &self.problems {
            writeln!(f, "{p}")?;
        }
        Ok(())
    }
}

/// How a motion's speed is given.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum MotionSpeed {
    /// Joint move (percentage or joint speed): not checked against the
    /// travel speed.
    Joint,
    /// Linear move at this speed of the deposition point relative to the
    /// part (mm/s).
    Linear(f64),
    /// Linear move taking this long (s).
    Time(f64),
    /// Linear move at the controller's TCP speed: the TCP (`flange ·
    /// flange_from_tcp`) travels at `mm_s` in the robot base frame, and the
    /// positioner's axes, moving with the path, arrive with it, each at most
    /// at `extax_fraction` of its maximum speed: the move takes the longest
    /// of these. This is what FANUC `mm/sec`/`cm/min`, ABB `v_tcp` with the
    /// tool held by the robot and KUKA `$VEL.CP` outside the fixed-tool mode
    /// mean; it equals [`MotionSpeed::Linear`] only where the part is still.
    Tcp {
        /// TCP speed in the robot base frame (mm/s).
        mm_s: f64,
        /// The TCP on the flange (mm).
        flange_from_tcp: Isometry3,
        /// Fraction (0–1] of each positioner axis's maximum speed allowed
        /// for external axes moving with the path (KUKA `$VEL_EXTAX[n]/100`;
        /// 1 elsewhere).
        extax_fraction: [f64; 2],
    },
}

/// One motion of a program, decoded.
#[derive(Debug, Clone, PartialEq)]
pub struct Motion {
    /// File (or program) of the motion instruction.
    pub file: String,
    /// Line of the motion instruction (1-based).
    pub line: usize,
    /// The target's name as written (`P[3]`, `P3`, `p3`).
    pub label: String,
    /// File of the target's record (the `.dat` for KUKA).
    pub record_file: String,
    /// Line of the target's record.
    pub record_line: usize,
    /// Line of each joint's value (the record line when one line holds them all).
    pub value_lines: [usize; 6],
    /// Robot joints (rad, controller convention); `None` when they could not
    /// be decoded (a problem names why).
    pub joints: Option<Joints>,
    /// `true` when the joints were decoded from a Cartesian pose (its
    /// configuration data were checked while decoding).
    pub from_cartesian: bool,
    /// Positioner joints `[q7, q8]` (rad), if the file gives them.
    pub positioner: Option<[f64; 2]>,
    /// Joint or linear move.
    pub kind: MoveKind,
    /// The speed.
    pub speed: MotionSpeed,
}

/// One step of a program in execution order.
#[derive(Debug, Clone, PartialEq)]
pub enum Step {
    /// A motion.
    Motion(Box<Motion>),
    /// The process (arc) starts here.
    ProcessOn {
        /// File.
        file: String,
        /// Line.
        line: usize,
    },
    /// The process stops here.
    ProcessOff {
        /// File.
        file: String,
        /// Line.
        line: usize,
    },
}

/// Adds a problem to `report`.
pub(crate) fn push(report: &mut ValidationReport, file: &str, line: usize, message: String) {
    report.problems.push(Problem {
        file: file.to_string(),
        line,
        message,
    });
}

/// Deposition point in the part frame (mm) at joints `q`, positioner `qp`:
/// the fixed torch's point seen from the part (part-carried cell), or the
/// TCP seen from the part on the positioner (torch-carried cell).
pub fn deposition_point(cell: &Cell, q: &Joints, qp: Option<[f64; 2]>) -> Option<Point3> {
    let flange = cell.robot().flange_pose(q);
    match cell {
        Cell::PartCarried(c) => {
            let base_from_part = flange * c.flange_from_part;
            Some(base_from_part.inverse() * c.deposition_point_mm)
        }
        Cell::TorchCarried(c) => {
            let tcp = flange * c.flange_from_tcp;
            let base_from_part = c.base_from_part(&qp?);
            Some(base_from_part.inverse() * Point3::from(tcp.translation.vector))
        }
    }
}

const NAMES: [&str; 6] = ["J1", "J2", "J3", "J4", "J5", "J6"];

/// Checks decoded `steps` against `cell` (module doc), adding problems and
/// counts to `report`. `planned`: the planned deposition points (part
/// frame, mm), one per bead motion in execution order.
pub fn check_steps(
    steps: &[Step],
    cell: &Cell,
    planned: Option<&[Point3]>,
    report: &mut ValidationReport,
) {
    // which motions are bead points: made with the process on, or the last
    // motion before the process starts
    let mut bead = vec![false; steps.len()];
    let mut on = false;
    let mut last_motion: Option<usize> = None;
    for (i, s) in steps.iter().enumerate() {
        match s {
            Step::Motion(_) => {
                bead[i] = on;
                last_motion = Some(i);
            }
            Step::ProcessOn { .. } => {
                if let Some(k) = last_motion {
                    bead[k] = true;
                }
                on = true;
            }
            Step::ProcessOff { .. } => on = false,
        }
    }
    let robot = cell.robot();
    let mut arc_on: Option<(String, usize)> = None;
    let mut prev: Option<(Joints, Option<[f64; 2]>, Option<Point3>)> = None;
    let mut bead_motions = 0;
    let mut first_file: Option<String> = None;
    for (i, s) in steps.iter().enumerate() {
        let m = match s {
            Step::ProcessOn { file, line } => {
                if let Some((f, l)) = &arc_on {
                    let msg = format!(
                        "bead starts while the bead started at {f}:{l} is still on (missing Arc End / end instruction)"
                    );
                    push(report, file, *line, msg);
                }
                arc_on = Some((file.clone(), *line));
                continue;
            }
            Step::ProcessOff { file, line } => {
                if arc_on.take().is_none() {
                    push(
                        report,
                        file,
                        *line,
                        "bead stops but none was started".into(),
                    );
                } else {
                    report.beads += 1;
                }
                continue;
            }
            Step::Motion(m) => m,
        };
        first_file.get_or_insert_with(|| m.file.clone());
        report.motions += 1;
        let k = bead_motions;
        if bead[i] {
            bead_motions += 1;
        }
        if m.kind == MoveKind::Joint && arc_on.is_some() {
            push(report, &m.file, m.line, "joint move with the arc on".into());
        }
        let Some(q) = m.joints else {
            prev = None;
            continue;
        };
        for (j, name) in NAMES.iter().enumerate() {
            let l = robot.limits[j];
            if !l.contains(q[j]) {
                push(
                    report,
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
        let cfg = robot.configuration_of(&q);
        if !m.from_cartesian && cfg != cell.configuration() {
            push(
                report,
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
        if let Cell::TorchCarried(c) = cell {
            match qp {
                None => push(
                    report,
                    &m.record_file,
                    m.record_line,
                    format!("{}: no positioner values", m.label),
                ),
                Some(qp) => {
                    for (n, l) in c.positioner.limits.iter().enumerate() {
                        if !l.contains(qp[n]) {
                            push(
                                report,
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
        let dep = deposition_point(cell, &q, qp);
        if let (true, Some(plan), Some(d)) = (bead[i], planned, dep) {
            if let Some(target) = plan.get(k) {
                let e = (d - target).norm();
                if e > REACH_TOLERANCE_MM {
                    push(
                        report,
                        &m.record_file,
                        m.value_lines[0],
                        format!(
                            "{}: deposition point {e:.4} mm from the planned point {k}",
                            m.label
                        ),
                    );
                }
            }
        }
        if let Some((pq, pqp, pm)) = &prev {
            let mut msgs = Vec::new();
            let linear = m.speed != MotionSpeed::Joint;
            // joint moves (between beads) may rewind J4/J6; linear moves may not jump
            for j in (0..6).filter(|_| linear) {
                if (q[j] - pq[j]).abs() >= PI {
                    msgs.push(format!(
                        "{} jumps by {:.2}° from the previous position (turn or configuration change)",
                        NAMES[j],
                        (q[j] - pq[j]).to_degrees()
                    ));
                }
            }
            let dt = match (m.speed, dep, pm) {
                (MotionSpeed::Linear(v), Some(a), Some(b)) => {
                    let d = (a - b).norm();
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
                    let tcp =
                        |q: &Joints| (robot.flange_pose(q) * flange_from_tcp).translation.vector;
                    let mut t = (tcp(&q) - tcp(pq)).norm() / mm_s;
                    if let (Cell::TorchCarried(c), Some(a), Some(b)) = (cell, qp, pqp) {
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
                        msgs.push(format!(
                            "linear move at {mm_s:.3} mm/s TCP speed with the TCP still while the joints turn: \
                             the controller would turn at its orientation speed limit (write it time-based)"
                        ));
                    }
                    (t > 0.0).then(|| (t, format!("at {mm_s:.3} mm/s TCP speed")))
                }
                (MotionSpeed::Time(t), _, _) => {
                    if t > 0.0 {
                        Some((t, format!("in {:.0} ms", t * 1000.0)))
                    } else {
                        msgs.push("zero duration".into());
                        None
                    }
                }
                _ => None,
            };
            if let Some((dt, how)) = dt {
                for j in 0..6 {
                    let sp = (q[j] - pq[j]).abs() / dt;
                    if sp > robot.max_speed_rad_s[j] {
                        msgs.push(format!(
                            "{} needs {:.2}°/s {how}, maximum {:.1}°/s",
                            NAMES[j],
                            sp.to_degrees(),
                            robot.max_speed_rad_s[j].to_degrees()
                        ));
                    }
                }
                if let (Cell::TorchCarried(c), Some(a), Some(b)) = (cell, qp, pqp) {
                    for n in 0..2 {
                        let sp = (a[n] - b[n]).abs() / dt;
                        if sp > c.positioner.max_speed_rad_s[n] {
                            msgs.push(format!(
                                "positioner J{} needs {:.2}°/s",
                                n + 1,
                                sp.to_degrees()
                            ));
                        }
                    }
                }
            }
            for msg in msgs {
                push(report, &m.file, m.line, msg);
            }
        }
        prev = Some((q, qp, dep));
    }
    if let Some((file, line)) = arc_on {
        push(
            report,
            &file,
            line,
            "bead started here never stops (no Arc End / end instruction before the program ends)"
                .into(),
        );
    }
    if let Some(p) = planned {
        if p.len() != bead_motions {
            push(
                report,
                first_file.as_deref().unwrap_or(""),
                0,
                format!(
                    "{bead_motions} bead motions in the programs, {} planned points",
                    p.len()
                ),
            );
        }
    }
}

/// Joints reaching `base_from_flange` in branch `cfg` (J2, J3, J5 as the IK
/// gives them), each of J1, J4, J6 turned by `turn(j, q)` (which gets the
/// solution's value in `(-π, π]` and returns the joint value, or `None` when
/// the file's turn data do not fit),
/// checked by FK within [`REACH_TOLERANCE_MM`]. Problems are named `label`.
#[allow(clippy::too_many_arguments)]
pub(crate) fn decode_pose(
    robot: &RobotModel,
    base_from_flange: &Isometry3,
    cfg: Configuration,
    mut turn: impl FnMut(usize, f64) -> Option<f64>,
    label: &str,
    file: &str,
    line: usize,
    report: &mut ValidationReport,
) -> Option<Joints> {
    let mut q = match robot.inverse(base_from_flange, cfg) {
        Ok(q) => q,
        Err(e) => {
            push(report, file, line, format!("{label}: {e}"));
            return None;
        }
    };
    for j in [0, 3, 5] {
        match turn(j, wrap_pi(q[j])) {
            Some(v) => q[j] = v,
            None => {
                push(
                    report,
                    file,
                    line,
                    format!(
                        "{label}: the turn data of {} do not fit its angle {:.4}°",
                        NAMES[j],
                        wrap_pi(q[j]).to_degrees()
                    ),
                );
                return None;
            }
        }
    }
    let back = robot.flange_pose(&q);
    let err = (back.translation.vector - base_from_flange.translation.vector).norm();
    if err > REACH_TOLERANCE_MM {
        push(
            report,
            file,
            line,
            format!("{label}: IK with the file's configuration reaches {err:.4} mm away"),
        );
    }
    Some(q)
}

/// `false`, with the problem pushed (line 1 of `file`), when `cell`'s robot
/// is not a `vendor` arm: its joints are in another controller's convention
/// and nothing else in the file can be checked against it.
fn vendor_matches(
    cell: &Cell,
    vendor: Vendor,
    emitter: &'static str,
    file: &str,
    report: &mut ValidationReport,
) -> bool {
    match crate::program::check_vendor(cell, vendor, emitter) {
        Ok(()) => true,
        Err(e) => {
            push(report, file, 1, e.to_string());
            false
        }
    }
}

/// The branch whose wrist has controller J5 of sign `j5_positive`.
pub(crate) fn wrist_of_j5(robot: &RobotModel, j5_positive: bool) -> Wrist {
    // NoFlip when the canonical t5 = sign5·J5 is positive
    if j5_positive == (robot.convention.sign[4] > 0.0) {
        Wrist::NoFlip
    } else {
        Wrist::Flip
    }
}

/// The arm side and elbow of `back`/`positive_cos` (KUKA Status bits 0
/// and 1; ABB `cfx` bit 2 and the negation of bit 1).
pub(crate) fn arm_of(back: bool, positive_cos: bool) -> (ArmSide, Elbow) {
    let side = if back { ArmSide::Back } else { ArmSide::Front };
    let elbow = if positive_cos != back {
        Elbow::Up
    } else {
        Elbow::Down
    };
    (side, elbow)
}

/// Validates `programs` (the first is executed; `CALL`s are followed into
/// the others by name) against `cell`, with the frames and process of
/// `opts`. `planned`: the planned deposition points of the beads (part
/// frame, mm), one per bead motion in execution order, when available.
/// A cell whose robot is not a FANUC arm is refused: the report holds that
/// one problem ([`ProgramError::VendorMismatch`](crate::program::ProgramError::VendorMismatch)'s
/// message, line 1 of the main program).
pub fn validate_fanuc(
    programs: &[TpProgram],
    cell: &Cell,
    opts: &FanucOptions,
    planned: Option<&[Point3]>,
) -> ValidationReport {
    let mut report = ValidationReport::default();
    let file = programs.first().map_or("", |p| p.name.as_str());
    if !vendor_matches(
        cell,
        Vendor::Fanuc,
        crate::program::fanuc::EMITTER,
        file,
        &mut report,
    ) {
        return report;
    }
    let mut steps = Vec::new();
    if let Some(main) = programs.first() {
        fanuc_steps(programs, main, 0, cell, opts, &mut steps, &mut report);
    }
    check_steps(&steps, cell, planned, &mut report);
    report
}

fn fanuc_steps(
    programs: &[TpProgram],
    tp: &TpProgram,
    depth: usize,
    cell: &Cell,
    opts: &FanucOptions,
    steps: &mut Vec<Step>,
    report: &mut ValidationReport,
) {
    let (start, end) = match &opts.process {
        ProcessControl::Arc { schedule } => (Op::ArcStart(*schedule), Op::ArcEnd(*schedule)),
        ProcessControl::Custom { start, end } => (Op::Other(start.clone()), Op::Other(end.clone())),
    };
    let robot = cell.robot();
    let tool = opts.tool_in(cell);
    for ins in &tp.instructions {
        let line = ins.line;
        let file = &tp.name;
        match &ins.op {
            Op::Call(name) => {
                if depth > 4 {
                    push(
                        report,
                        file,
                        line,
                        format!("CALL {name}: calls nested too deep"),
                    );
                    continue;
                }
                match programs.iter().find(|p| &p.name == name) {
                    Some(sub) => fanuc_steps(programs, sub, depth + 1, cell, opts, steps, report),
                    None => push(report, file, line, format!("CALL {name}: no such program")),
                }
            }
            op if *op == start => steps.push(Step::ProcessOn {
                file: file.clone(),
                line,
            }),
            op if *op == end => steps.push(Step::ProcessOff {
                file: file.clone(),
                line,
            }),
            Op::Remark(_) => {}
            Op::ArcStart(_) | Op::ArcEnd(_) | Op::Other(_) => push(
                report,
                file,
                line,
                format!("unexpected instruction `{}`", ins.op.to_string().trim()),
            ),
            Op::UFrame(n) if *n != opts.user_frame => push(
                report,
                file,
                line,
                format!("UFRAME_NUM={n}, the options give {}", opts.user_frame),
            ),
            Op::UTool(n) if *n != opts.tool_frame => push(
                report,
                file,
                line,
                format!("UTOOL_NUM={n}, the options give {}", opts.tool_frame),
            ),
            Op::UFrame(_) | Op::UTool(_) => {}
            Op::Move {
                kind,
                position,
                speed,
                ..
            } => {
                let Some(pos) = tp.positions.iter().find(|p| p.index == *position) else {
                    push(report, file, line, format!("P[{position}] has no record"));
                    continue;
                };
                let label = format!("P[{}]", pos.index);
                let (joints, from_cartesian) = match &pos.arm {
                    ArmPosition::Joint(d) => (Some(d.map(f64::to_radians)), false),
                    ArmPosition::Cartesian { xyzwpr, config } => {
                        let cfg_line = pos.line + 2;
                        let q = if pos.uf_ut != (opts.user_frame, opts.tool_frame) {
                            push(
                                report,
                                file,
                                pos.line,
                                format!(
                                    "{label}: UF {}, UT {} are not the frames of the options",
                                    pos.uf_ut.0, pos.uf_ut.1
                                ),
                            );
                            None
                        } else if let Some((cfg, turns)) = parse_config(config) {
                            if cfg != cell.configuration() {
                                push(
                                    report,
                                    file,
                                    cfg_line,
                                    format!(
                                        "{label}: CONFIG '{cfg}' is not the cell's '{}' (configuration flip)",
                                        cell.configuration()
                                    ),
                                );
                            }
                            let user_from_tool = FanucPose::from_xyzwpr_deg(*xyzwpr).to_isometry();
                            let base_from_flange =
                                opts.base_from_user * user_from_tool * tool.inverse();
                            decode_pose(
                                robot,
                                &base_from_flange,
                                cfg,
                                |j, q| {
                                    let t = match j {
                                        0 => turns[0],
                                        3 => turns[1],
                                        _ => turns[2],
                                    };
                                    Some(q + TAU * t as f64)
                                },
                                &label,
                                file,
                                pos.value_lines[0],
                                report,
                            )
                        } else {
                            push(
                                report,
                                file,
                                cfg_line,
                                format!("{label}: bad CONFIG '{config}'"),
                            );
                            None
                        };
                        (q, true)
                    }
                };
                steps.push(Step::Motion(Box::new(Motion {
                    file: file.clone(),
                    line,
                    label,
                    record_file: file.clone(),
                    record_line: pos.line,
                    value_lines: pos.value_lines,
                    joints,
                    from_cartesian,
                    positioner: pos.group2.map(|g| g.map(f64::to_radians)),
                    kind: *kind,
                    speed: match (speed.mm_s(), speed.time_s()) {
                        (Some(v), _) => MotionSpeed::Tcp {
                            mm_s: v,
                            flange_from_tcp: tool,
                            extax_fraction: [1.0; 2],
                        },
                        (None, Some(t)) => MotionSpeed::Time(t),
                        _ => MotionSpeed::Joint,
                    },
                })));
            }
        }
    }
}

/// Parses `F U T, 0, 0, 1` into the branch and the turns of J1, J4, J6.
pub fn parse_config(s: &str) -> Option<(Configuration, [i32; 3])> {
    let mut parts = s.split(',');
    let cfg = Configuration::from_fanuc(parts.next()?)?;
    let mut turns = [0; 3];
    for t in &mut turns {
        *t = parts.next()?.trim().parse().ok()?;
    }
    if parts.next().is_some() {
        return None;
    }
    Some((cfg, turns))
}

/// The value of `q` (its solution in `(-π, π]`) shifted by whole turns to
/// lie in ABB quadrant `cf` (`floor(q / 90°)`), `None` if more than 1e-6 rad
/// away from it.
fn abb_quadrant(q: f64, cf: i32) -> Option<f64> {
    let quarter = std::f64::consts::FRAC_PI_2;
    let centre = (cf as f64 + 0.5) * quarter;
    let v = q + TAU * ((centre - q) / TAU).round();
    let lo = cf as f64 * quarter;
    (v >= lo - 1e-6 && v <= lo + quarter + 1e-6).then_some(v)
}

/// Validates a KUKA program read by
/// [`parse_krl`](crate::program::readback::kuka::parse_krl) against `cell`
/// with the frames, tool/base numbers and process of `opts` (as the
/// [`Step`]s of the module doc). `E6POS` targets are decoded with the
/// Status bits (branch, checked against the cell's) and, for `PTP`, the
/// Turn bits (each of A1, A4, A6 the value of that sign nearest zero inside
/// its travel); a `LIN` ignores Turn as the controller does and takes the
/// value nearest the previous position. A cell whose robot is not a KUKA
/// arm is refused: the report holds that one problem (line 1 of the `.src`).
pub fn validate_kuka(
    program: &crate::program::readback::kuka::KrlProgram,
    cell: &Cell,
    opts: &crate::program::kuka::KukaOptions,
    planned: Option<&[Point3]>,
) -> ValidationReport {
    use crate::program::readback::kuka::{KrlOp, KrlValue};
    use crate::robot::orientation::KukaAbc;
    let mut report = ValidationReport::default();
    if !vendor_matches(
        cell,
        Vendor::Kuka,
        crate::program::kuka::EMITTER,
        &program.src_file,
        &mut report,
    ) {
        return report;
    }
    let robot = cell.robot();
    let (base, tool) = opts.frames(cell);
    let (on, off) = crate::program::kuka::switch_statements(opts);
    let src = &program.src_file;
    let dat = &program.dat_file;
    let mut steps = Vec::new();
    let mut vel: Option<f64> = None;
    let mut pending: Vec<(u8, String, usize)> = Vec::new();
    let mut prev_q: Option<Joints> = None;
    // external axes' path speeds (%), as the last `BAS (#VEL_PTP,n)` or
    // `$VEL_EXTAX[n]` left them (assumed 100 before either)
    let mut vel_extax = [100.0; 6];
    let external_tcp = opts.uses_external_tcp(cell);
    for st in &program.statements {
        let line = st.line;
        let (target, linear) = match &st.op {
            KrlOp::Ptp(t) => (t, false),
            KrlOp::Lin { target, .. } => (target, true),
            KrlOp::VelCp(v) => {
                vel = Some(v * 1000.0);
                continue;
            }
            KrlOp::VelExtax { axis, percent } => {
                if let Some(slot) = (*axis as usize)
                    .checked_sub(1)
                    .and_then(|i| vel_extax.get_mut(i))
                {
                    *slot = *percent;
                }
                continue;
            }
            KrlOp::VelPtp(p) => {
                vel_extax = [*p; 6];
                continue;
            }
            KrlOp::Trigger { distance, action } => {
                pending.push((*distance, action.clone(), line));
                continue;
            }
            KrlOp::IpoTcp(tcp) => {
                if *tcp != opts.uses_external_tcp(cell) {
                    push(
                        &mut report,
                        src,
                        line,
                        format!(
                            "$IPO_MODE = {}, the options give {}",
                            if *tcp { "#TCP" } else { "#BASE" },
                            if *tcp { "#BASE" } else { "#TCP" }
                        ),
                    );
                }
                continue;
            }
            KrlOp::Tool(n) | KrlOp::Base(n) => {
                let (what, want) = match st.op {
                    KrlOp::Tool(_) => ("TOOL_DATA", opts.tool),
                    _ => ("BASE_DATA", opts.base),
                };
                if *n != want {
                    push(
                        &mut report,
                        src,
                        line,
                        format!("{what}[{n}], the options give {want}"),
                    );
                }
                continue;
            }
            KrlOp::Other(_) => continue,
        };
        let mut after = Vec::new();
        for (distance, action, l) in pending.drain(..) {
            let step = if action == on {
                Step::ProcessOn {
                    file: src.clone(),
                    line: l,
                }
            } else if action == off {
                Step::ProcessOff {
                    file: src.clone(),
                    line: l,
                }
            } else {
                push(
                    &mut report,
                    src,
                    l,
                    format!("unexpected trigger action `{action}`"),
                );
                continue;
            };
            if distance == 0 {
                steps.push(step);
            } else {
                after.push(step);
            }
        }
        let Some(pos) = program.positions.iter().find(|p| &p.name == target) else {
            push(
                &mut report,
                src,
                line,
                format!("{target} has no DECL in {dat}"),
            );
            continue;
        };
        let speed = if linear {
            match vel {
                Some(v) => MotionSpeed::Linear(v),
                None => {
                    push(&mut report, src, line, "LIN before any $VEL.CP".into());
                    MotionSpeed::Joint
                }
            }
        } else {
            MotionSpeed::Joint
        };
        if linear && matches!(pos.value, KrlValue::Axis(_)) {
            push(
                &mut report,
                src,
                line,
                format!(
                    "LIN to {}, an E6AXIS ({dat}:{}): a LIN target must be an E6POS",
                    pos.name, pos.line
                ),
            );
        }
        let (joints, from_cartesian) = match &pos.value {
            KrlValue::Axis(a) => (Some(a.map(f64::to_radians)), false),
            KrlValue::Pos {
                xyzabc,
                status,
                turn,
            } => {
                let (side, elbow) = arm_of(status & 1 != 0, status & 2 != 0);
                let cfg = Configuration {
                    wrist: wrist_of_j5(robot, status & 4 == 0),
                    elbow,
                    side,
                };
                if cfg != cell.configuration() {
                    push(
                        &mut report,
                        dat,
                        pos.line,
                        format!(
                            "{}: S {status} is configuration '{cfg}', not the cell's '{}' (configuration flip)",
                            pos.name,
                            cell.configuration()
                        ),
                    );
                }
                let rot = KukaAbc::from_degrees(xyzabc[3], xyzabc[4], xyzabc[5]).to_rotation();
                let pose = Isometry3::from_parts(
                    nalgebra::Translation3::new(xyzabc[0], xyzabc[1], xyzabc[2]),
                    nalgebra::UnitQuaternion::from_rotation_matrix(&rot),
                );
                let base_from_flange = base * pose * tool.inverse();
                let q = decode_pose(
                    robot,
                    &base_from_flange,
                    cfg,
                    |j, q| match (&prev_q, linear) {
                        (Some(p), true) => Some(crate::robot::ik::unwrap_near(q, p[j])),
                        _ => {
                            let negative = turn & (1 << j) != 0;
                            (-2..=2)
                                .map(|k| q + TAU * k as f64)
                                .filter(|v| {
                                    // a joint at zero may be written with either sign
                                    ((*v < 0.0) == negative || v.abs() < 1e-6)
                                        && robot.limits[j].contains(*v)
                                })
                                .min_by(|a, b| a.abs().total_cmp(&b.abs()))
                        }
                    },
                    &pos.name,
                    dat,
                    pos.line,
                    &mut report,
                );
                (q, true)
            }
        };
        // Outside the fixed-tool mode $VEL.CP is the TCP's speed in the
        // robot frame, and external axes move with the path at
        // $VEL_EXTAX. (In the fixed-tool mode $VEL.CP is the torch's speed
        // over the part, the planned meaning.)
        let speed = match speed {
            MotionSpeed::Linear(v) if !external_tcp => MotionSpeed::Tcp {
                mm_s: v,
                flange_from_tcp: tool,
                extax_fraction: [vel_extax[0] / 100.0, vel_extax[1] / 100.0],
            },
            speed => speed,
        };
        prev_q = joints.or(prev_q);
        steps.push(Step::Motion(Box::new(Motion {
            file: src.clone(),
            line,
            label: pos.name.clone(),
            record_file: dat.clone(),
            record_line: pos.line,
            value_lines: [pos.line; 6],
            joints,
            from_cartesian,
            positioner: matches!(cell, Cell::TorchCarried(_))
                .then(|| pos.external.map(f64::to_radians)),
            kind: if linear {
                MoveKind::Linear
            } else {
                MoveKind::Joint
            },
            speed,
        })));
        steps.extend(after);
    }
    for (_, action, l) in pending {
        push(
            &mut report,
            src,
            l,
            format!("trigger `{action}` without a motion after it"),
        );
    }
    check_steps(&steps, cell, planned, &mut report);
    report
}

/// Validates an ABB module read by
/// [`parse_mod`](crate::program::readback::abb::parse_mod) against `cell`
/// with the process of `opts`; the frames are the file's own `tWaam` and
/// `wWaam` (held or stationary tool). `robtarget`s are decoded with their
/// `confdata`: `cfx` gives the branch (checked against the cell's), `cf1`,
/// `cf4`, `cf6` the quadrant of J1, J4, J6 (`ConfL \On` makes the controller
/// keep them on linear moves). A cell whose robot is not an ABB arm is
/// refused: the report holds that one problem (line 1 of the module).
pub fn validate_abb(
    module: &crate::program::readback::abb::RapidModule,
    cell: &Cell,
    opts: &crate::program::abb::AbbOptions,
    planned: Option<&[Point3]>,
) -> ValidationReport {
    use crate::program::abb::AbbFrames;
    use crate::program::readback::abb::{RapidOp, RapidTargetValue};
    let mut report = ValidationReport::default();
    if !vendor_matches(
        cell,
        Vendor::Abb,
        crate::program::abb::EMITTER,
        &module.file,
        &mut report,
    ) {
        return report;
    }
    let file = &module.file;
    let slots = match opts.positioner_slots() {
        Ok(s) => s,
        Err(e) => {
            push(&mut report, file, 1, e.to_string());
            return report;
        }
    };
    let robot = cell.robot();
    let frames = match (&module.tool, &module.wobj) {
        (Some(t), Some(w)) => match (t.robhold, w.robhold) {
            (true, false) => Some(AbbFrames::Held {
                flange_from_tool: t.pose,
                base_from_wobj: w.pose,
            }),
            (false, true) => Some(AbbFrames::Stationary {
                base_from_tool: t.pose,
                flange_from_wobj: w.pose,
            }),
            _ => {
                push(
                    &mut report,
                    file,
                    t.line,
                    "tWaam and wWaam: exactly one of them must be held by the robot".into(),
                );
                None
            }
        },
        _ => {
            push(
                &mut report,
                file,
                1,
                "no `tooldata tWaam` or `wobjdata wWaam` declaration".into(),
            );
            None
        }
    };
    let (start, end) = match &opts.process {
        ProcessControl::Arc { schedule } => (None, Some(format!("weld{schedule}"))),
        ProcessControl::Custom { start, end } => (Some((start.clone(), end.clone())), None),
    };
    let mut steps = Vec::new();
    let mut conf_l = false;
    for ins in &module.instructions {
        let line = ins.line;
        let (target, speed, kind, event) = match &ins.op {
            RapidOp::ConfL(on) => {
                conf_l = *on;
                continue;
            }
            RapidOp::Other(s) => {
                match &start {
                    Some((a, _)) if s == a => steps.push(Step::ProcessOn {
                        file: file.clone(),
                        line,
                    }),
                    Some((_, b)) if s == b => steps.push(Step::ProcessOff {
                        file: file.clone(),
                        line,
                    }),
                    _ => push(
                        &mut report,
                        file,
                        line,
                        format!("unexpected instruction `{s}`"),
                    ),
                }
                continue;
            }
            RapidOp::MoveAbsJ { target } => (target, MotionSpeed::Joint, MoveKind::Joint, None),
            RapidOp::Linear {
                instruction,
                target,
                speed_mm_s,
                weld,
                time_s,
            } => {
                let arc = instruction != "MoveL";
                if arc && (start.is_some() || weld.as_ref() != end.as_ref()) {
                    push(
                        &mut report,
                        file,
                        line,
                        format!(
                            "{instruction} with `{}`: the options give {}",
                            weld.clone().unwrap_or_default(),
                            end.clone().unwrap_or_else(|| "a custom process".into())
                        ),
                    );
                }
                let event = match instruction.as_str() {
                    "ArcLStart" => Some(true),
                    "ArcLEnd" => Some(false),
                    _ => None,
                };
                (
                    target,
                    match (time_s, &frames) {
                        (Some(t), _) => MotionSpeed::Time(*t),
                        // v_tcp is the speed of the robot-held tool
                        (
                            None,
                            Some(AbbFrames::Held {
                                flange_from_tool, ..
                            }),
                        ) => MotionSpeed::Tcp {
                            mm_s: *speed_mm_s,
                            flange_from_tcp: *flange_from_tool,
                            extax_fraction: [1.0; 2],
                        },
                        // a stationary tool: v_tcp is its speed over the work object
                        (None, _) => MotionSpeed::Linear(*speed_mm_s),
                    },
                    MoveKind::Linear,
                    event,
                )
            }
        };
        if kind == MoveKind::Linear && !conf_l {
            push(
                &mut report,
                file,
                line,
                "linear move without `ConfL \\On`: the controller may change the configuration"
                    .into(),
            );
        }
        let Some(t) = module.targets.iter().find(|t| &t.name == target) else {
            push(&mut report, file, line, format!("{target} is not declared"));
            continue;
        };
        let (joints, from_cartesian) = match (&t.value, kind) {
            (RapidTargetValue::Joint(a), MoveKind::Joint) => (Some(a.map(f64::to_radians)), false),
            (RapidTargetValue::Rob { pose, conf }, MoveKind::Linear) => {
                // cfx bit 2: wrist centre behind axis 1; bit 1: behind the
                // lower arm, the elbow joint test (abb::confdata)
                let (side, elbow) = arm_of(conf[3] & 4 != 0, conf[3] & 2 == 0);
                let cfg = Configuration {
                    wrist: wrist_of_j5(robot, conf[3] & 1 == 0),
                    elbow,
                    side,
                };
                if !(0..8).contains(&conf[3]) || cfg != cell.configuration() {
                    push(
                        &mut report,
                        file,
                        t.line,
                        format!(
                            "{}: cfx {} is configuration '{cfg}', not the cell's '{}' (configuration flip)",
                            t.name,
                            conf[3],
                            cell.configuration()
                        ),
                    );
                }
                let q = frames.and_then(|f| {
                    decode_pose(
                        robot,
                        &f.flange(pose),
                        cfg,
                        |j, q| {
                            let cf = match j {
                                0 => conf[0],
                                3 => conf[1],
                                _ => conf[2],
                            };
                            abb_quadrant(q, cf)
                        },
                        &t.name,
                        file,
                        t.line,
                        &mut report,
                    )
                });
                (q, true)
            }
            _ => {
                push(
                    &mut report,
                    file,
                    line,
                    format!("{target}: wrong target type for this instruction"),
                );
                continue;
            }
        };
        steps.push(Step::Motion(Box::new(Motion {
            file: file.clone(),
            line,
            label: t.name.clone(),
            record_file: file.clone(),
            record_line: t.line,
            value_lines: [t.line; 6],
            joints,
            from_cartesian,
            positioner: match (t.external[slots[0]], t.external[slots[1]]) {
                (Some(a), Some(b)) => Some([a.to_radians(), b.to_radians()]),
                _ => None,
            },
            kind,
            speed,
        })));
        match event {
            Some(true) => steps.push(Step::ProcessOn {
                file: file.clone(),
                line,
            }),
            Some(false) => steps.push(Step::ProcessOff {
                file: file.clone(),
                line,
            }),
            None => {}
        }
    }
    check_steps(&steps, cell, planned, &mut report);
    report
}
