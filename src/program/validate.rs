//! Validator of FANUC programs from the files alone plus the cell [SPEC §8]:
//! joint limits (arm and positioner), joint speeds at the programmed speeds,
//! reachability (Cartesian positions: IK with the file's configuration string
//! and turn numbers, then FK back within 0.01 mm; and, when the plan is
//! given, the deposition point of every position within 0.01 mm of the
//! planned one), configuration consistency (the cell's branch everywhere, no
//! joint jumping by half a turn or more between consecutive positions), and
//! that every bead starts and stops once. Every problem names its file and
//! line; the report lists them all.

use std::f64::consts::{PI, TAU};
use std::fmt;

use crate::math::{Isometry3, Point3};
use crate::program::fanuc::{ArmPosition, FanucOptions, MoveKind, Op, Position, TpProgram};
use crate::program::ProcessControl;
use crate::robot::ik::wrap_pi;
use crate::robot::orientation::FanucPose;
use crate::robot::{Cell, Configuration, Joints};

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

struct Prev {
    q: Joints,
    qp: Option<[f64; 2]>,
    m: Option<Point3>,
}

/// Validates `programs` (the first is executed; `CALL`s are followed into
/// the others by name) against `cell`, with the frames and process of
/// `opts`. `planned`: the planned deposition points (part frame, mm), one
/// per motion in execution order, when available.
pub fn validate_fanuc(
    programs: &[TpProgram],
    cell: &Cell,
    opts: &FanucOptions,
    planned: Option<&[Point3]>,
) -> ValidationReport {
    let mut v = Validator {
        programs,
        cell,
        opts,
        planned,
        tool: opts.tool_in(cell),
        report: ValidationReport::default(),
        arc_on: None,
        prev: None,
    };
    if let Some(main) = programs.first() {
        v.run(main, 0);
    }
    if let Some((file, line)) = v.arc_on.take() {
        v.problem(
            &file,
            line,
            "bead started here never stops (no Arc End / end instruction before the program ends)"
                .into(),
        );
    }
    if let Some(p) = planned {
        if p.len() != v.report.motions {
            let file = programs.first().map(|p| p.name.clone()).unwrap_or_default();
            v.problem(
                &file,
                0,
                format!(
                    "{} motions in the programs, {} planned points",
                    v.report.motions,
                    p.len()
                ),
            );
        }
    }
    v.report
}

struct Validator<'a> {
    programs: &'a [TpProgram],
    cell: &'a Cell,
    opts: &'a FanucOptions,
    planned: Option<&'a [Point3]>,
    tool: Isometry3,
    report: ValidationReport,
    arc_on: Option<(String, usize)>,
    prev: Option<Prev>,
}

impl Validator<'_> {
    fn problem(&mut self, file: &str, line: usize, message: String) {
        self.report.problems.push(Problem {
            file: file.to_string(),
            line,
            message,
        });
    }

    fn run(&mut self, tp: &TpProgram, depth: usize) {
        let (start, end) = match &self.opts.process {
            ProcessControl::Arc { schedule } => (Op::ArcStart(*schedule), Op::ArcEnd(*schedule)),
            ProcessControl::Custom { start, end } => {
                (Op::Other(start.clone()), Op::Other(end.clone()))
            }
        };
        for ins in &tp.instructions {
            let line = ins.line;
            match &ins.op {
                Op::Call(name) => {
                    if depth > 4 {
                        self.problem(
                            &tp.name,
                            line,
                            format!("CALL {name}: calls nested too deep"),
                        );
                        continue;
                    }
                    match self.programs.iter().find(|p| &p.name == name) {
                        Some(sub) => self.run(sub, depth + 1),
                        None => {
                            self.problem(&tp.name, line, format!("CALL {name}: no such program"))
                        }
                    }
                }
                op if *op == start => {
                    if let Some((f, l)) = &self.arc_on {
                        let msg = format!(
                            "bead starts while the bead started at {f}:{l} is still on (missing Arc End)"
                        );
                        self.problem(&tp.name, line, msg);
                    }
                    self.arc_on = Some((tp.name.clone(), line));
                }
                op if *op == end => {
                    if self.arc_on.take().is_none() {
                        self.problem(&tp.name, line, "bead stops but none was started".into());
                    } else {
                        self.report.beads += 1;
                    }
                }
                Op::ArcStart(_) | Op::ArcEnd(_) | Op::Other(_) => {
                    self.problem(
                        &tp.name,
                        line,
                        format!("unexpected instruction `{}`", ins.op.to_string().trim()),
                    );
                }
                Op::UFrame(n) if *n != self.opts.user_frame => self.problem(
                    &tp.name,
                    line,
                    format!("UFRAME_NUM={n}, the options give {}", self.opts.user_frame),
                ),
                Op::UTool(n) if *n != self.opts.tool_frame => self.problem(
                    &tp.name,
                    line,
                    format!("UTOOL_NUM={n}, the options give {}", self.opts.tool_frame),
                ),
                Op::UFrame(_) | Op::UTool(_) => {}
                Op::Move {
                    kind,
                    position,
                    speed,
                    ..
                } => {
                    let Some(pos) = tp.positions.iter().find(|p| p.index == *position) else {
                        self.problem(&tp.name, line, format!("P[{position}] has no record"));
                        continue;
                    };
                    if *kind == MoveKind::Joint && self.arc_on.is_some() {
                        self.problem(&tp.name, line, "joint move with the arc on".into());
                    }
                    self.motion(tp, line, pos, speed.mm_s());
                }
            }
        }
    }

    /// Joints of a position; `None` (with a problem) if they cannot be had.
    fn joints_of(&mut self, tp: &TpProgram, pos: &Position) -> Option<Joints> {
        let robot = self.cell.robot();
        match &pos.arm {
            ArmPosition::Joint(d) => Some(d.map(f64::to_radians)),
            ArmPosition::Cartesian { xyzwpr, config } => {
                if pos.uf_ut != (self.opts.user_frame, self.opts.tool_frame) {
                    self.problem(
                        &tp.name,
                        pos.line,
                        format!(
                            "P[{}]: UF {}, UT {} are not the frames of the options",
                            pos.index, pos.uf_ut.0, pos.uf_ut.1
                        ),
                    );
                    return None;
                }
                let Some((cfg, turns)) = parse_config(config) else {
                    self.problem(
                        &tp.name,
                        pos.line + 2,
                        format!("P[{}]: bad CONFIG '{config}'", pos.index),
                    );
                    return None;
                };
                if cfg != self.cell.configuration() {
                    self.problem(
                        &tp.name,
                        pos.line + 2,
                        format!(
                            "P[{}]: CONFIG '{cfg}' is not the cell's '{}' (configuration flip)",
                            pos.index,
                            self.cell.configuration()
                        ),
                    );
                }
                let user_from_tool = FanucPose::from_xyzwpr_deg(*xyzwpr).to_isometry();
                let base_from_tool = self.opts.base_from_user * user_from_tool;
                let base_from_flange = base_from_tool * self.tool.inverse();
                let mut q = match robot.inverse(&base_from_flange, cfg) {
                    Ok(q) => q,
                    Err(e) => {
                        self.problem(
                            &tp.name,
                            pos.value_lines[0],
                            format!("P[{}]: {e}", pos.index),
                        );
                        return None;
                    }
                };
                for (j, t) in [(0, turns[0]), (3, turns[1]), (5, turns[2])] {
                    q[j] = wrap_pi(q[j]) + TAU * t as f64;
                }
                let back = robot.flange_pose(&q) * self.tool;
                let err = (back.translation.vector - base_from_tool.translation.vector).norm();
                if err > REACH_TOLERANCE_MM {
                    self.problem(
                        &tp.name,
                        pos.value_lines[0],
                        format!(
                            "P[{}]: IK with '{config}' reaches {err:.4} mm away",
                            pos.index
                        ),
                    );
                }
                Some(q)
            }
        }
    }

    /// Deposition point in the part frame (mm) at joints `q`, positioner `qp`.
    fn deposition_point(&self, q: &Joints, qp: Option<[f64; 2]>) -> Option<Point3> {
        let flange = self.cell.robot().flange_pose(q);
        match self.cell {
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

    fn motion(&mut self, tp: &TpProgram, line: usize, pos: &Position, speed_mm_s: Option<f64>) {
        let k = self.report.motions;
        self.report.motions += 1;
        let Some(q) = self.joints_of(tp, pos) else {
            self.prev = None;
            return;
        };
        let robot = self.cell.robot();
        let names = ["J1", "J2", "J3", "J4", "J5", "J6"];
        for (j, name) in names.iter().enumerate() {
            let l = robot.limits[j];
            if !l.contains(q[j]) {
                self.problem(
                    &tp.name,
                    pos.value_lines[j],
                    format!(
                        "P[{}]: {name} = {:.4}° outside [{:.1}°, {:.1}°]",
                        pos.index,
                        q[j].to_degrees(),
                        l.lower_rad.to_degrees(),
                        l.upper_rad.to_degrees()
                    ),
                );
            }
        }
        let cfg = robot.configuration_of(&q);
        if matches!(pos.arm, ArmPosition::Joint(_)) && cfg != self.cell.configuration() {
            self.problem(
                &tp.name,
                pos.line,
                format!(
                    "P[{}]: joints are in configuration '{cfg}', not the cell's '{}'",
                    pos.index,
                    self.cell.configuration()
                ),
            );
        }
        let qp = pos.group2.map(|g| g.map(f64::to_radians));
        if let Cell::TorchCarried(c) = self.cell {
            match qp {
                None => self.problem(
                    &tp.name,
                    pos.line,
                    format!("P[{}]: no GP2 (positioner) values", pos.index),
                ),
                Some(qp) => {
                    for (i, l) in c.positioner.limits.iter().enumerate() {
                        if !l.contains(qp[i]) {
                            self.problem(
                                &tp.name,
                                pos.group2_line,
                                format!(
                                    "P[{}]: positioner J{} = {:.4}° outside its travel",
                                    pos.index,
                                    i + 1,
                                    qp[i].to_degrees()
                                ),
                            );
                        }
                    }
                }
            }
        }
        let m = self.deposition_point(&q, qp);
        if let (Some(plan), Some(m)) = (self.planned, m) {
            if let Some(target) = plan.get(k) {
                let e = (m - target).norm();
                if e > REACH_TOLERANCE_MM {
                    self.problem(
                        &tp.name,
                        pos.value_lines[0],
                        format!(
                            "P[{}]: deposition point {e:.4} mm from the planned point {k}",
                            pos.index
                        ),
                    );
                }
            }
        }
        if let Some(prev) = &self.prev {
            let mut msgs = Vec::new();
            // joint moves (between beads) may rewind J4/J6; linear moves may not jump
            for j in (0..6).filter(|_| speed_mm_s.is_some()) {
                if (q[j] - prev.q[j]).abs() >= PI {
                    msgs.push(format!(
                        "{} jumps by {:.2}° from the previous position (turn or configuration change)",
                        names[j],
                        (q[j] - prev.q[j]).to_degrees()
                    ));
                }
            }
            if let (Some(v), Some(m), Some(pm)) = (speed_mm_s, m, prev.m) {
                let d = (m - pm).norm();
                if d > 0.0 {
                    let dt = d / v;
                    for j in 0..6 {
                        let s = (q[j] - prev.q[j]).abs() / dt;
                        if s > robot.max_speed_rad_s[j] {
                            msgs.push(format!(
                                "{} needs {:.2}°/s at {v:.3} mm/s, maximum {:.1}°/s",
                                names[j],
                                s.to_degrees(),
                                robot.max_speed_rad_s[j].to_degrees()
                            ));
                        }
                    }
                    if let (Cell::TorchCarried(c), Some(a), Some(b)) = (self.cell, qp, prev.qp) {
                        for i in 0..2 {
                            let s = (a[i] - b[i]).abs() / dt;
                            if s > c.positioner.max_speed_rad_s[i] {
                                msgs.push(format!(
                                    "positioner J{} needs {:.2}°/s",
                                    i + 1,
                                    s.to_degrees()
                                ));
                            }
                        }
                    }
                }
            }
            for msg in msgs {
                self.problem(&tp.name, line, msg);
            }
        }
        self.prev = Some(Prev { q, qp, m });
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
