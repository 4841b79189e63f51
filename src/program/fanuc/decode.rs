//! FANUC TP programs as [`DecodedStep`]s: the programs read by
//! [`parse_ls`](super::parse_ls), `CALL`s followed, each position decoded
//! (joints, or a Cartesian pose with its `CONFIG` string and turn numbers)
//! in the frames of [`FanucOptions::frames`].
//!
//! Besides motions and arc on/off, the decoder checks what a controller
//! needs that the file says: the frames stated in the header remarks
//! against the options (a missing or different statement is a
//! [`ProblemKind::Frame`]); `RTCP` on every linear move of the part-carried
//! cell with remote TCP, with the remote TCP `CONTROL_CODE` bit, and
//! `COORD` on every linear move of the torch-carried cell with coordination
//! (a missing or unexpected option is a [`ProblemKind::Frame`]), whose
//! speeds are then the travel speed over the part
//! ([`MotionSpeed::Linear`]); `ARC : TRUE` in `/APPL` of an arc program;
//! the arc instructions of the options (`Arc Start[s]` or `Weld
//! Start[p,s]`; another schedule or form is a [`ProblemKind::Options`]);
//! dwells (`WAIT x(sec)`) and interpass waits (`WAIT DI[n]=ON`) as
//! [`DecodedStep::Wait`]; payload updates (`$PLST_GRP1[n]` mass and CoG, kg and
//! cm, then `PAYLOAD[n]`) as [`DecodedStep::Payload`] (CoG in mm).

use std::collections::HashMap;
use std::f64::consts::TAU;

use crate::math::{Isometry3, Point3};
use crate::program::contract::validate_decoded;
use crate::program::fanuc::emit::parse_schedule_remark;
use crate::program::fanuc::Fanuc;
use crate::program::fanuc::{
    parse_frame_remark, ArmPosition, FanucFrames, FanucOptions, FrameKind, MotionOptions, MoveKind,
    Op, PayloadField, Position, Speed, TpProgram,
};
use crate::program::validate::{
    decode_pose, push, DecodedStep, Motion, MotionSpeed, ProblemKind, ValidationReport, WireFeed,
};
use crate::program::PlannedPoint;
use crate::program::ProcessControl;
use crate::robot::orientation::FanucPose;
use crate::robot::{CellLayout, Configuration, Joints};

/// Largest difference between a stated frame and the options' frame:
/// position (mm) and rotation (deg); the remarks print 3 decimals.
pub const FRAME_TOLERANCE: f64 = 0.005;

/// The [`DecodedStep`]s of `programs` (the first is executed; `CALL`s are followed
/// into the others by name) in `cell` with `opts`, in execution order; what
/// cannot be decoded or disagrees with the options is added to `report`
/// (module doc). The cell's robot is assumed to be a FANUC arm (checked by
/// [`validate_fanuc`]).
pub fn fanuc_steps(
    programs: &[TpProgram],
    cell: &CellLayout,
    opts: &FanucOptions,
    report: &mut ValidationReport,
) -> Vec<DecodedStep> {
    let mut steps = Vec::new();
    if let Some(main) = programs.first() {
        let mut state = Decoder {
            programs,
            cell,
            opts,
            frames: opts.frames(cell),
            payloads: HashMap::new(),
            checked: Vec::new(),
            schedules: HashMap::new(),
            arc_on: false,
            schedule: None,
        };
        state.steps(main, 0, &mut steps, report);
    }
    steps
}

/// A frame's values stated in remarks (X..R, mm and deg, `None` where not
/// stated) and the line of its first remark.
type StatedFrame = ([Option<f64>; 6], usize);

/// What the decoder carries through the calls.
struct Decoder<'a> {
    programs: &'a [TpProgram],
    cell: &'a CellLayout,
    opts: &'a FanucOptions,
    frames: FanucFrames,
    /// Values assigned to each payload schedule so far (kg, cm; with the
    /// line of the last assignment).
    payloads: HashMap<u8, [Option<f64>; 4]>,
    /// Programs whose header (frames, `/APPL`) was checked.
    checked: Vec<String>,
    /// The wire feed (mm/s) each weld schedule's remark states.
    schedules: HashMap<u32, f64>,
    /// The arc is on (an `Arc Start` ran, no `Arc End` since).
    arc_on: bool,
    /// The weld schedule of the last `Arc Start` (the one the arc runs with).
    schedule: Option<u32>,
}

impl Decoder<'_> {
    /// Checks `tp`'s `/APPL` and frame statements (once per program).
    fn check_header(&mut self, tp: &TpProgram, report: &mut ValidationReport) {
        if self.checked.contains(&tp.name) {
            return;
        }
        self.checked.push(tp.name.clone());
        let file = &tp.name;
        for ins in &tp.instructions {
            if let Op::Remark(r) = &ins.op {
                if let Some((n, v)) = parse_schedule_remark(r) {
                    self.schedules.insert(n, v);
                }
            }
        }
        if matches!(self.opts.process, ProcessControl::Arc { .. }) && !tp.arc_enabled {
            push(
                report,
                ProblemKind::Options,
                file,
                1,
                "/APPL has no `ARC : TRUE ;`: ArcTool does not run the arc instructions of a program not marked as an arc program".into(),
            );
        }
        let rtcp_moves = tp
            .instructions
            .iter()
            .any(|i| matches!(i.op, Op::Move { options, .. } if options.rtcp));
        if (self.opts.remote_tcp(self.cell) || rtcp_moves) && !tp.remote_tcp {
            push(
                report,
                ProblemKind::Frame,
                file,
                1,
                "remote TCP program without `CONTROL_CODE = 00000001 00000000` (the remote TCP bit a controller sets on programs with RTCP moves)".into(),
            );
        }
        // the stated frames: (kind, number) -> X..R and the line of each
        let mut stated: HashMap<(FrameKind, u8), StatedFrame> = HashMap::new();
        for ins in &tp.instructions {
            if let Op::Remark(r) = &ins.op {
                if let Some((kind, n, axes, values)) = parse_frame_remark(r) {
                    let e = stated.entry((kind, n)).or_insert(([None; 6], ins.line));
                    e.0[axes[0]] = Some(values[0]);
                    e.0[axes[1]] = Some(values[1]);
                }
            }
        }
        for ins in &tp.instructions {
            let (kind, n, what) = match ins.op {
                Op::UFrame(n) => (FrameKind::User, n, "UFRAME"),
                Op::UTool(n) => (FrameKind::Tool, n, "UTOOL"),
                _ => continue,
            };
            let (want_n, want) = match kind {
                FrameKind::User => (self.frames.user_frame, self.frames.base_from_user),
                FrameKind::Tool => (self.frames.tool_frame, self.frames.flange_from_tool),
            };
            if n != want_n {
                continue; // the number itself is checked with the instruction
            }
            let want_v = FanucPose::from_isometry(&want).to_xyzwpr_deg();
            match stated.get(&(kind, n)) {
                Some((v, line)) if v.iter().all(Option::is_some) => {
                    let v = v.map(|x| x.expect("checked"));
                    if let Some(msg) = frame_difference(&v, &want) {
                        push(
                            report,
                            ProblemKind::Frame,
                            file,
                            *line,
                            format!(
                                "{what}[{n}] stated as {} but the options/cell give {} ({msg})",
                                xyzwpr(&v),
                                xyzwpr(&want_v)
                            ),
                        );
                    }
                }
                _ => push(
                    report,
                    ProblemKind::Frame,
                    file,
                    ins.line,
                    format!(
                        "{what}_NUM={n}: the program does not state the value of {what}[{n}] its positions assume (remarks `{}{n} X,Y=...`); the options/cell give {}",
                        match kind {
                            FrameKind::User => "UF",
                            FrameKind::Tool => "UT",
                        },
                        xyzwpr(&want_v)
                    ),
                ),
            }
        }
    }

    /// The steps of `tp` (called at `depth`) appended to `steps`: each
    /// instruction to the decoder of its kind.
    fn steps(
        &mut self,
        tp: &TpProgram,
        depth: usize,
        steps: &mut Vec<DecodedStep>,
        report: &mut ValidationReport,
    ) {
        self.check_header(tp, report);
        let opts = self.opts;
        let (start, end) = opts.process_ops();
        let arc = matches!(opts.process, ProcessControl::Arc { .. });
        let frames = self.frames;
        for ins in &tp.instructions {
            let line = ins.line;
            let file = &tp.name;
            match &ins.op {
                Op::Call(name) => self.call(name, depth, file, line, steps, report),
                op @ (Op::ArcStart(_) | Op::WeldStart(..)) if arc => {
                    // a bead's start, or with the arc on a change of
                    // schedule (module doc, "Wire feed")
                    let (n, same_form) = match (op, &start) {
                        (Op::ArcStart(n), Op::ArcStart(_)) => (*n, true),
                        (Op::WeldStart(p, n), Op::WeldStart(q, _)) => (*n, p == q),
                        (Op::ArcStart(n) | Op::WeldStart(_, n), _) => (*n, false),
                        _ => unreachable!("matched above"),
                    };
                    if !same_form {
                        push(
                            report,
                            ProblemKind::Options,
                            file,
                            line,
                            format!("`{}`: the options give `{}`", op_text(op), op_text(&start)),
                        );
                    }
                    if !self.schedules.contains_key(&n) {
                        push(
                            report,
                            ProblemKind::Feed,
                            file,
                            line,
                            format!(
                                "`{}`: the program states no wire feed for weld schedule {n} (remark `WELD SCHED {n}: WFS ... MM/S`)",
                                op_text(op)
                            ),
                        );
                    }
                    // the same schedule again is a second start (an `Arc
                    // End` missing), not a change
                    let change = self.arc_on && self.schedule != Some(n);
                    self.schedule = Some(n);
                    if !change {
                        self.arc_on = true;
                        steps.push(DecodedStep::ProcessOn {
                            file: file.clone(),
                            line,
                        });
                    }
                }
                op if *op == end => {
                    self.arc_on = false;
                    steps.push(DecodedStep::ProcessOff {
                        file: file.clone(),
                        line,
                    })
                }
                op @ (Op::ArcEnd(_) | Op::WeldEnd(..)) if arc => {
                    // another schedule or form than the options': named,
                    // and counted as the end it is
                    push(
                        report,
                        ProblemKind::Options,
                        file,
                        line,
                        format!("`{}`: the options give `{}`", op_text(op), op_text(&end)),
                    );
                    self.arc_on = false;
                    steps.push(DecodedStep::ProcessOff {
                        file: file.clone(),
                        line,
                    });
                }
                op if *op == start => steps.push(DecodedStep::ProcessOn {
                    file: file.clone(),
                    line,
                }),
                Op::Remark(_) => {}
                Op::WaitTime(t) => steps.push(DecodedStep::Wait {
                    file: file.clone(),
                    line,
                    seconds: Some(*t),
                    input: None,
                }),
                Op::WaitInput(n) => steps.push(DecodedStep::Wait {
                    file: file.clone(),
                    line,
                    seconds: None,
                    input: Some(*n),
                }),
                Op::PayloadValue {
                    schedule,
                    field,
                    value,
                } => {
                    let k = PayloadField::ALL
                        .iter()
                        .position(|f| f == field)
                        .expect("every field is in ALL");
                    self.payloads.entry(*schedule).or_insert([None; 4])[k] = Some(*value);
                }
                Op::Payload(n) => self.payload(*n, file, line, steps, report),
                Op::ArcStart(_)
                | Op::ArcEnd(_)
                | Op::WeldStart(..)
                | Op::WeldEnd(..)
                | Op::Other(_) => push(
                    report,
                    ProblemKind::Instruction,
                    file,
                    line,
                    format!("unexpected instruction `{}`", op_text(&ins.op)),
                ),
                Op::UFrame(n) if *n != frames.user_frame => push(
                    report,
                    ProblemKind::Frame,
                    file,
                    line,
                    format!("UFRAME_NUM={n}, the options give {}", frames.user_frame),
                ),
                Op::UTool(n) if *n != frames.tool_frame => push(
                    report,
                    ProblemKind::Frame,
                    file,
                    line,
                    format!("UTOOL_NUM={n}, the options give {}", frames.tool_frame),
                ),
                Op::UFrame(_) | Op::UTool(_) => {}
                Op::Move {
                    kind,
                    position,
                    via,
                    speed,
                    options,
                    ..
                } => {
                    // a circular move's via first, as its own step
                    let via = via.map(|v| (v, MoveKind::Via));
                    for (position, kind) in via.into_iter().chain([(*position, *kind)]) {
                        let Some(pos) = tp.positions.iter().find(|p| p.index == position) else {
                            push(
                                report,
                                ProblemKind::Declaration,
                                file,
                                line,
                                format!("P[{position}] has no record"),
                            );
                            continue;
                        };
                        steps.push(self.motion(tp, line, pos, kind, speed, options, report));
                    }
                }
            }
        }
    }

    /// `CALL name` at `file:line` (in a program called at `depth`): the
    /// called program's steps.
    fn call(
        &mut self,
        name: &str,
        depth: usize,
        file: &str,
        line: usize,
        steps: &mut Vec<DecodedStep>,
        report: &mut ValidationReport,
    ) {
        if depth > 4 {
            push(
                report,
                ProblemKind::Call,
                file,
                line,
                format!("CALL {name}: calls nested too deep"),
            );
            return;
        }
        match self.programs.iter().find(|p| p.name == name) {
            Some(sub) => self.steps(sub, depth + 1, steps, report),
            None => push(
                report,
                ProblemKind::Call,
                file,
                line,
                format!("CALL {name}: no such program"),
            ),
        }
    }

    /// `PAYLOAD[n]` at `file:line`: a [`DecodedStep::Payload`] of the mass and
    /// CoG the programs set for schedule `n` before it.
    fn payload(
        &self,
        n: u8,
        file: &str,
        line: usize,
        steps: &mut Vec<DecodedStep>,
        report: &mut ValidationReport,
    ) {
        let opts = self.opts;
        if n != opts.payload_schedule {
            push(
                report,
                ProblemKind::Options,
                file,
                line,
                format!(
                    "PAYLOAD[{n}]: the options give payload schedule {}",
                    opts.payload_schedule
                ),
            );
        }
        match self.payloads.get(&n) {
            Some([Some(m), Some(x), Some(y), Some(z)]) => steps.push(DecodedStep::Payload {
                file: file.to_string(),
                line,
                mass_kg: *m,
                // FANUC payload CoG is in cm
                cog_mm: Point3::new(10.0 * x, 10.0 * y, 10.0 * z),
            }),
            _ => push(
                report,
                ProblemKind::Options,
                file,
                line,
                format!(
                    "PAYLOAD[{n}] selects a schedule whose mass and CoG the programs do not set before it ($PLST_GRP1[{n}].$PAYLOAD, _X, _Y, _Z)"
                ),
            ),
        }
    }

    /// The wire feed of a move at `speed` with the arc on: the current
    /// schedule's (its remark, to 0.01 mm/s), with the relative steps of
    /// that value and of the written speed or time as its tolerance.
    fn wire_feed(&self, speed: &Speed) -> Option<WireFeed> {
        if !self.arc_on {
            return None;
        }
        let mm_s = *self.schedules.get(&self.schedule?)?;
        let speed_step = match *speed {
            Speed::MmPerSec(v) | Speed::CmPerMin(v) | Speed::Msec(v) => 1.0 / f64::from(v.max(1)),
            Speed::Percent(_) => return None,
        };
        Some(WireFeed {
            mm_s,
            tolerance: 0.005 / mm_s + speed_step,
        })
    }

    /// The motion step of a move at `line` of `tp` to `pos` (`kind`, at
    /// `speed` with `options`): its options against the cell's, its
    /// position decoded.
    #[allow(clippy::too_many_arguments)]
    fn motion(
        &self,
        tp: &TpProgram,
        line: usize,
        pos: &Position,
        kind: MoveKind,
        speed: &Speed,
        options: &MotionOptions,
        report: &mut ValidationReport,
    ) -> DecodedStep {
        let (opts, cell, file) = (self.opts, self.cell, &tp.name);
        let want_rtcp = opts.remote_tcp(cell);
        let want_coord = opts.coordinated(cell);
        let label = format!("P[{}]", pos.index);
        let linear = kind != MoveKind::Joint;
        for (name, present, want) in [
            ("COORD", options.coord, want_coord && linear),
            ("RTCP", options.rtcp, want_rtcp && linear),
        ] {
            let why = match (present, want) {
                (false, true) if name == "COORD" => Some(
                    "linear move without COORD: its speed would be the TCP's in the world frame, not the travel speed over the part on the positioner",
                ),
                (false, true) => Some(
                    "linear move without RTCP: the controller would move the flange's tool frame, not the part about the fixed torch (remote TCP)",
                ),
                (true, false) if !linear => Some("on a joint move"),
                (true, false) => Some("not expected: the options and cell do not use it"),
                _ => None,
            };
            if let Some(why) = why {
                push(
                    report,
                    ProblemKind::Frame,
                    file,
                    line,
                    format!("{label}: {name}: {why}"),
                );
            }
        }
        if options.coord && tp.groups < 2 {
            push(
                report,
                ProblemKind::Frame,
                file,
                line,
                format!("{label}: COORD in a program of one motion group (no leader)"),
            );
        }
        let (joints, from_cartesian) = self.arm_joints(tp, pos, &label, report);
        DecodedStep::Motion(Box::new(Motion {
            file: file.clone(),
            line,
            label,
            record_file: file.clone(),
            record_line: pos.line,
            value_lines: pos.value_lines,
            joints,
            from_cartesian,
            positioner: pos.group2.map(|g| g.map(f64::to_radians)),
            kind,
            speed: match (speed.mm_s(), speed.time_s()) {
                // COORD: relative to the leader (the positioner
                // carrying the part); RTCP: relative speed of
                // the workpiece and the fixed torch. Both are
                // the deposition point's speed over the part.
                (Some(v), _) if options.coord || options.rtcp => MotionSpeed::Linear(v),
                (Some(v), _) => MotionSpeed::Tcp {
                    mm_s: v,
                    flange_from_tcp: self.frames.flange_from_tool,
                    extax_fraction: [1.0; 2],
                },
                (None, Some(t)) => MotionSpeed::Time(t),
                _ => MotionSpeed::Joint,
            },
            wire_feed: self.wire_feed(speed),
        }))
    }

    /// The arm joints (rad) of `pos` (`label`) of `tp`, and whether they
    /// were decoded from a Cartesian pose (with its `CONFIG` and turn
    /// numbers, in the options' frames).
    fn arm_joints(
        &self,
        tp: &TpProgram,
        pos: &Position,
        label: &str,
        report: &mut ValidationReport,
    ) -> (Option<Joints>, bool) {
        let (cell, frames, file) = (self.cell, self.frames, &tp.name);
        let tool = frames.flange_from_tool;
        match &pos.arm {
            ArmPosition::Joint(d) => (Some(d.map(f64::to_radians)), false),
            ArmPosition::Cartesian { .. } if tp.remote_tcp => {
                push(
                    report,
                    ProblemKind::Format,
                    file,
                    pos.line,
                    format!("{label}: Cartesian position in a remote TCP program: its representation (RX..RR) is not documented, write joint positions"),
                );
                (None, true)
            }
            ArmPosition::Cartesian { xyzwpr, config } => {
                let cfg_line = pos.line + 2;
                let q = if pos.uf_ut != (frames.user_frame, frames.tool_frame) {
                    push(
                        report,
                        ProblemKind::Frame,
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
                            ProblemKind::Configuration,
                            file,
                            cfg_line,
                            format!(
                                "{label}: CONFIG '{cfg}' is not the cell's '{}' (configuration flip)",
                                cell.configuration()
                            ),
                        );
                    }
                    let user_from_tool = FanucPose::from_xyzwpr_deg(*xyzwpr).to_isometry();
                    let base_from_flange = frames.base_from_user * user_from_tool * tool.inverse();
                    decode_pose(
                        cell.robot(),
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
                        label,
                        file,
                        pos.value_lines[0],
                        report,
                    )
                } else {
                    push(
                        report,
                        ProblemKind::Configuration,
                        file,
                        cfg_line,
                        format!("{label}: bad CONFIG '{config}'"),
                    );
                    None
                };
                (q, true)
            }
        }
    }
}

/// `None` when `stated` (FANUC X..R, mm and deg) is `want` within
/// [`FRAME_TOLERANCE`], else how far apart they are.
fn frame_difference(stated: &[f64; 6], want: &Isometry3) -> Option<String> {
    let s = FanucPose::from_xyzwpr_deg(*stated).to_isometry();
    let dp = (s.translation.vector - want.translation.vector).norm();
    let da = (s.rotation.inverse() * want.rotation).angle().to_degrees();
    (dp > FRAME_TOLERANCE || da > FRAME_TOLERANCE)
        .then(|| format!("{dp:.3} mm and {da:.3} deg apart"))
}

/// An instruction as written, without the line's `;`.
fn op_text(op: &Op) -> String {
    op.to_string()
        .trim()
        .trim_end_matches(';')
        .trim()
        .to_string()
}

fn xyzwpr(v: &[f64; 6]) -> String {
    format!(
        "({:.3}, {:.3}, {:.3}, {:.3}, {:.3}, {:.3})",
        v[0], v[1], v[2], v[3], v[4], v[5]
    )
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
    cell: &CellLayout,
    opts: &FanucOptions,
    planned: Option<&[PlannedPoint]>,
) -> ValidationReport {
    let main = programs.first().map_or("", |p| p.name.as_str());
    validate_decoded::<Fanuc>(cell, main, opts, planned, |report| {
        Some(fanuc_steps(programs, cell, opts, report))
    })
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
