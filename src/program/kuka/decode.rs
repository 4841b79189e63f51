//! KUKA programs as [`Step`]s: the `.src`/`.dat` pair read by
//! [`parse_krl`](crate::program::kuka::read::parse_krl), each position
//! decoded (`E6AXIS`, or `E6POS` with its Status and Turn bits). With the
//! arc process the file's own safety is checked too: each bead's ignition
//! handshake, and its arc-loss supervision (the interrupt declared on the
//! options' input, on for every motion with the arc on, off before the arc
//! off, and a handler that brakes, switches the arc off and never returns
//! into the bead with the arc off; module doc of [`crate::program::kuka`]).

use std::f64::consts::TAU;

use std::ops::{Mul, Sub};

use crate::math::{Isometry3, Point3};
use crate::program::kuka::read::{
    falling_input, InterruptAction, KrlOp, KrlProgram, KrlRoutine, KrlStatement,
};
use crate::program::kuka::{ArcLoss, KukaOptions, StatedBase, ARC_LOST_HANDLER};
use crate::program::kuka::{CIRC_CIRC_TYPE, CIRC_ORI_TYPE};
use crate::program::MoveKind;
use crate::robot::{CellLayout, Configuration, Joints};

use crate::program::validate::ProblemKind;
use crate::program::validate::{arm_of, wrist_of_j5};
use crate::program::validate::{decode_pose, push, Motion, MotionSpeed, Step, ValidationReport};

/// Validates a KUKA program read by
/// [`parse_krl`](crate::program::kuka::read::parse_krl) against `cell`
/// with the frames, tool/base numbers and process of `opts` (as the
/// [`Step`]s of the module doc). `E6POS` targets are decoded with the
/// Status bits (branch, checked against the cell's) and, for `PTP`, the
/// Turn bits (each of A1, A4, A6 the value of that sign nearest zero inside
/// its travel); a `LIN` ignores Turn as the controller does and takes the
/// value nearest the previous position. A cell whose robot is not a KUKA
/// arm is refused: the report holds that one problem (line 1 of the `.src`).
pub fn validate_kuka(
    program: &KrlProgram,
    cell: &CellLayout,
    opts: &KukaOptions,
    planned: Option<&[Point3]>,
) -> ValidationReport {
    use crate::program::contract::{Controller, Kuka};
    Kuka::validate(program, cell, opts, planned)
}

/// The [`Step`]s of a KUKA program (motions decoded, process on and off,
/// waits, payloads) in execution order, with the problems of the file
/// itself (frames, triggers, ignition handshake, arc-loss supervision and
/// its handler, end times) added to `report_out`. The cell's robot must be
/// a KUKA arm.
pub(crate) fn kuka_steps(
    program: &KrlProgram,
    cell: &CellLayout,
    opts: &KukaOptions,
    report_out: &mut ValidationReport,
) -> Vec<Step> {
    use crate::program::kuka::read::KrlValue;
    use crate::robot::orientation::KukaAbc;
    let mut report = std::mem::take(report_out);
    let robot = cell.robot();
    let (_, tool) = opts.frames(cell);
    let (on, off) = crate::program::kuka::switch_statements(opts);
    let arc = opts.arc_process();
    let coordinated = opts.coordinated(cell);
    let src = &program.src_file;
    let dat = &program.dat_file;
    let mut steps = Vec::new();
    let mut vel: Option<f64> = None;
    let mut pending: Vec<(u8, String, usize)> = Vec::new();
    let mut prev_q: Option<Joints> = None;
    // An endless turn written modulo 360°: the controller takes the
    // shortest way from where the table is (home's turn before the first
    // motion).
    let modulo = crate::program::contract::turn_modulo(cell);
    let mut turn_at: f64 = opts
        .common
        .home(cell)
        .and_then(|h| h.positioner)
        .map_or(0.0, |q| q[1]);
    // external axes' path speeds (%), as the last `BAS (#VEL_PTP,n)` or
    // `$VEL_EXTAX[n]` left them (assumed 100 before either)
    let mut vel_extax = [100.0; 6];
    let external_tcp = opts.uses_external_tcp(cell);
    // frames stated before the first motion
    let mut tool_stated = false;
    let mut base_stated = false;
    let mut first_motion = true;
    // the arc process: the ignition handshake (a LOOP) at each bead's
    // start, the arc-loss supervision around each bead, the end times
    let mut sup = Supervision::default();
    // line of a stray `IF NOT $IN[n] THEN` (reported, its body skipped)
    let mut in_if: Option<usize> = None;
    let mut arc_is_on = false;
    let mut crater: Option<(f64, usize)> = None;
    let mut after_off: Option<usize> = None;
    let mut mass: Option<(f64, usize)> = None;
    let frame_problem = |report: &mut ValidationReport, line: usize, msg: String| {
        push(report, ProblemKind::Frame, src, line, msg)
    };
    let stmts = &program.statements;
    // `$ORI_TYPE = #VAR`, `$CIRC_TYPE = #BASE` stated before a `CIRC`
    let mut circ_stated = [false; 2];
    let mut next = 0;
    while let Some(st) = stmts.get(next) {
        next += 1;
        let line = st.line;
        // the burn-back wait is the statement right after the arc off
        if let Some(l) = after_off.take() {
            if let KrlOp::WaitSec(s) = &st.op {
                check_time(&mut report, src, line, "burn-back", *s, opts.burn_back_s);
                continue;
            }
            missing_burn_back(&mut report, src, l, opts);
        }
        if in_if.is_some() {
            // inside a stray `IF NOT $IN[n] THEN … ENDIF` (reported)
            match &st.op {
                KrlOp::EndIf => in_if = None,
                KrlOp::Ptp(_) | KrlOp::Lin { .. } | KrlOp::Circ { .. } => push(
                    &mut report,
                    ProblemKind::Instruction,
                    src,
                    line,
                    "motion inside `IF NOT $IN[n] THEN … ENDIF`".into(),
                ),
                _ => {}
            }
            continue;
        }
        // the positions a motion statement moves to, with how: a `CIRC`'s
        // auxiliary point first, as its own step
        let (targets, linear) = match &st.op {
            KrlOp::Ptp(t) => (vec![(t, MoveKind::Joint)], false),
            KrlOp::Lin { target, .. } => (vec![(target, MoveKind::Linear)], true),
            KrlOp::Circ { aux, target, .. } if circ_stated != [true; 2] => {
                frame_problem(
                    &mut report,
                    line,
                    format!("CIRC before the program states $ORI_TYPE = {CIRC_ORI_TYPE} and $CIRC_TYPE = {CIRC_CIRC_TYPE}: the controller's orientation on the circle would be its default, not the checked one"),
                );
                circ_stated = [true; 2];
                (
                    vec![(aux, MoveKind::Via), (target, MoveKind::Circular)],
                    true,
                )
            }
            KrlOp::Circ { aux, target, .. } => (
                vec![(aux, MoveKind::Via), (target, MoveKind::Circular)],
                true,
            ),
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
            KrlOp::Trigger {
                distance,
                action,
                prio,
            } => {
                if crate::program::kuka::is_call(action) && prio.is_none() {
                    push(
                        &mut report,
                        ProblemKind::Instruction,
                        src,
                        line,
                        format!("TRIGGER calls the subprogram `{action}` without PRIO (KRL requires one, e.g. PRIO=-1)"),
                    );
                }
                if arc && same(action, &on) {
                    push(
                        &mut report,
                        ProblemKind::Instruction,
                        src,
                        line,
                        format!(
                            "the arc is switched on by a TRIGGER while moving: no ignition wait for $IN[{}] is possible",
                            opts.arc_ok_input
                        ),
                    );
                }
                pending.push((*distance, action.clone(), line));
                continue;
            }
            KrlOp::OriType(v) | KrlOp::CircType(v) => {
                let (name, want) = match st.op {
                    KrlOp::OriType(_) => ("$ORI_TYPE", CIRC_ORI_TYPE),
                    _ => ("$CIRC_TYPE", CIRC_CIRC_TYPE),
                };
                if v == want {
                    circ_stated[usize::from(name == "$CIRC_TYPE")] = true;
                } else {
                    frame_problem(
                        &mut report,
                        line,
                        format!("{name} = {v}: the checker models {want} (orientation by slerp from start to end)"),
                    );
                }
                continue;
            }
            KrlOp::IpoTcp(tcp) => {
                if *tcp != opts.uses_external_tcp(cell) {
                    frame_problem(
                        &mut report,
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
                    frame_problem(
                        &mut report,
                        line,
                        format!("{what}[{n}], the options give {want}"),
                    );
                }
                continue;
            }
            KrlOp::ToolFrame(f) => {
                tool_stated = true;
                if let Some(d) = frame_differs(f, &tool) {
                    frame_problem(
                        &mut report,
                        line,
                        format!(
                            "$TOOL = {} differs from the frame the positions assume, {} ({d})",
                            show(f),
                            crate::program::kuka::frame_literal(&tool)
                        ),
                    );
                }
                continue;
            }
            KrlOp::BaseFrame(f) => {
                base_stated = true;
                match opts.stated_base(cell) {
                    StatedBase::Fixed(base) => {
                        if let Some(d) = frame_differs(f, &base) {
                            frame_problem(
                                &mut report,
                                line,
                                format!(
                                    "$BASE = {} differs from the frame the positions assume, {} ({d})",
                                    show(f),
                                    crate::program::kuka::frame_literal(&base)
                                ),
                            );
                        }
                    }
                    StatedBase::Coupled { machine, .. } => frame_problem(
                        &mut report,
                        line,
                        format!(
                            "$BASE is a fixed frame: the positioner is not math-coupled (expected $BASE = EK (MACHINE_DEF[{machine}].ROOT, …) for coordinated motion)"
                        ),
                    ),
                }
                continue;
            }
            KrlOp::BaseEk { machine, offset } => {
                base_stated = true;
                match opts.stated_base(cell) {
                    StatedBase::Coupled {
                        machine: want,
                        offset: want_offset,
                    } => {
                        if *machine != want {
                            frame_problem(
                                &mut report,
                                line,
                                format!("$BASE = EK of MACHINE_DEF[{machine}], the options give {want}"),
                            );
                        }
                        if let Some(d) = frame_differs(offset, &want_offset) {
                            frame_problem(
                                &mut report,
                                line,
                                format!(
                                    "EK offset {} is not the part frame on the table {} ({d})",
                                    show(offset),
                                    crate::program::kuka::frame_literal(&want_offset)
                                ),
                            );
                        }
                    }
                    StatedBase::Fixed(_) => frame_problem(
                        &mut report,
                        line,
                        "$BASE = EK (math-coupled positioner), but the options give a fixed base (coordinated motion off, no positioner, or the fixed-tool mode)".into(),
                    ),
                }
                continue;
            }
            KrlOp::LoadMass(m) => {
                mass = Some((*m, line));
                continue;
            }
            KrlOp::LoadCm(c) => {
                match mass.take() {
                    Some((m, _)) => steps.push(Step::Payload {
                        file: src.clone(),
                        line,
                        mass_kg: m,
                        cog_mm: crate::math::Point3::new(c[0], c[1], c[2]),
                    }),
                    None => push(
                        &mut report,
                        ProblemKind::Instruction,
                        src,
                        line,
                        "$LOAD.CM without a $LOAD.M before it".into(),
                    ),
                }
                continue;
            }
            KrlOp::LoadJ(_) => continue,
            KrlOp::WaitSec(s) => {
                if arc_is_on {
                    crater = Some((*s, line));
                } else {
                    steps.push(Step::Wait {
                        file: src.clone(),
                        line,
                        seconds: Some(*s),
                        input: None,
                    });
                }
                continue;
            }
            // a wait for an input, with or without the ignition timer
            KrlOp::WaitIn(input) | KrlOp::WaitInOrTimer { input, .. } => {
                steps.push(Step::Wait {
                    file: src.clone(),
                    line,
                    seconds: None,
                    input: Some(*input),
                });
                continue;
            }
            // outside the ignition handshake: plain statements
            KrlOp::Timer { .. } | KrlOp::TimerStop { .. } => continue,
            KrlOp::IfNotIn(n) => {
                push(
                    &mut report,
                    ProblemKind::Instruction,
                    src,
                    line,
                    format!(
                        "`IF NOT $IN[{n}] THEN` outside the ignition handshake: after a HALT in it the start goes on without the arc ({})",
                        handshake_form(opts)
                    ),
                );
                in_if = Some(line);
                continue;
            }
            KrlOp::Loop => {
                let Some(end) = loop_end(stmts, next - 1) else {
                    push(
                        &mut report,
                        ProblemKind::Instruction,
                        src,
                        line,
                        "LOOP without ENDLOOP".into(),
                    );
                    break;
                };
                let block = &stmts[next - 1..=end];
                next = end + 1;
                match read_handshake(block, opts, &on, &off, src, &mut report) {
                    Some(h) if arc => {
                        steps.push(Step::ProcessOn {
                            file: src.clone(),
                            line: h.on_line,
                        });
                        arc_is_on = true;
                        sup.bead_start(h.on_line, true);
                    }
                    _ => push(
                        &mut report,
                        ProblemKind::Instruction,
                        src,
                        line,
                        format!(
                            "a LOOP in the main routine that is not the ignition handshake ({})",
                            handshake_form(opts)
                        ),
                    ),
                }
                continue;
            }
            KrlOp::InterruptDecl {
                prio,
                when,
                handler,
                ..
            } => {
                if arc {
                    sup.declare(*prio, when, handler, line, opts, src, &mut report);
                }
                continue;
            }
            KrlOp::Interrupt { action, prio } => {
                if arc {
                    sup.control(*action, *prio, line, arc_is_on, opts, src, &mut report);
                }
                continue;
            }
            KrlOp::EndIf
            | KrlOp::Halt
            | KrlOp::IfIn(_)
            | KrlOp::EndLoop
            | KrlOp::Exit
            | KrlOp::Brake { .. }
            | KrlOp::Resume => {
                push(
                    &mut report,
                    ProblemKind::Instruction,
                    src,
                    line,
                    format!("unexpected `{}`", keyword(&st.op)),
                );
                continue;
            }
            KrlOp::Other(text) => {
                if same(text, &on) {
                    steps.push(Step::ProcessOn {
                        file: src.clone(),
                        line,
                    });
                    arc_is_on = true;
                    if arc {
                        sup.bead_start(line, false);
                        push(
                            &mut report,
                            ProblemKind::Instruction,
                            src,
                            line,
                            format!(
                                "arc on without the ignition handshake ({})",
                                handshake_form(opts)
                            ),
                        );
                    }
                } else if same(text, &off) {
                    steps.push(Step::ProcessOff {
                        file: src.clone(),
                        line,
                    });
                    arc_is_on = false;
                    if arc {
                        sup.arc_off(line, src, &mut report);
                        let (s, _) = crater.take().unwrap_or((0.0, line));
                        check_time(&mut report, src, line, "crater fill", s, opts.crater_fill_s);
                        after_off = Some(line);
                    }
                }
                continue;
            }
        };
        // a motion: the frames must have been stated, the ignition checked
        if first_motion {
            first_motion = false;
            if !tool_stated {
                frame_problem(
                    &mut report,
                    line,
                    format!(
                        "first motion before the program states $TOOL (expected $TOOL = {})",
                        crate::program::kuka::frame_literal(&tool)
                    ),
                );
            }
            if !base_stated {
                let want = match opts.stated_base(cell) {
                    StatedBase::Fixed(b) => crate::program::kuka::frame_literal(&b),
                    StatedBase::Coupled { machine, .. } => {
                        format!("EK (MACHINE_DEF[{machine}].ROOT, …): the positioner is not math-coupled")
                    }
                };
                frame_problem(
                    &mut report,
                    line,
                    format!(
                        "first motion before the program states $BASE (expected $BASE = {want})"
                    ),
                );
            }
        }
        if arc && arc_is_on {
            let what = match targets.as_slice() {
                [(aux, _), (target, _)] => format!("CIRC {aux}, {target}"),
                [(target, _), ..] => format!("{} {target}", if linear { "LIN" } else { "PTP" }),
                [] => String::new(),
            };
            sup.motion(line, &what, opts, src, &mut report);
        }
        if let Some((_, l)) = mass.take() {
            push(
                &mut report,
                ProblemKind::Instruction,
                src,
                l,
                "$LOAD.M without a $LOAD.CM after it".into(),
            );
        }
        let mut after = Vec::new();
        for (distance, action, l) in pending.drain(..) {
            let step = if same(&action, &on) {
                Step::ProcessOn {
                    file: src.clone(),
                    line: l,
                }
            } else if same(&action, &off) {
                Step::ProcessOff {
                    file: src.clone(),
                    line: l,
                }
            } else {
                push(
                    &mut report,
                    ProblemKind::Instruction,
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
        for (target, kind) in targets {
            let Some(pos) = program.positions.iter().find(|p| &p.name == target) else {
                push(
                    &mut report,
                    ProblemKind::Declaration,
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
                        push(
                            &mut report,
                            ProblemKind::Timing,
                            src,
                            line,
                            "LIN before any $VEL.CP".into(),
                        );
                        MotionSpeed::Joint
                    }
                }
            } else {
                MotionSpeed::Joint
            };
            if linear && matches!(pos.value, KrlValue::Axis(_)) {
                push(
                    &mut report,
                    ProblemKind::Declaration,
                    src,
                    line,
                    format!(
                        "LIN to {}, an E6AXIS ({dat}:{}): a LIN target must be an E6POS",
                        pos.name, pos.line
                    ),
                );
            }
            let mut positioner = matches!(cell, CellLayout::TorchCarried(_))
                .then(|| pos.external.map(f64::to_radians));
            if let (true, Some(qp)) = (modulo, positioner.as_mut()) {
                if qp[1].abs() > std::f64::consts::PI + 1e-9 {
                    push(
                    report_out,
                    ProblemKind::JointLimit,
                    dat,
                    pos.line,
                    format!(
                        "{}: E2 = {:.3}° on an infinitely rotating axis: written modulo 360° in (-180°, 180°]",
                        pos.name,
                        qp[1].to_degrees()
                    ),
                );
                }
                qp[1] = turn_at + crate::robot::ik::wrap_pi(qp[1] - turn_at);
                turn_at = qp[1];
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
                        &mut report, ProblemKind::Configuration,
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
                    // with a coupled base, the base at this position's E1, E2
                    let base = opts.base_at(cell, positioner);
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
            // Outside the fixed-tool mode and without a coupled base $VEL.CP is
            // the TCP's speed in the robot frame, and external axes move with
            // the path at $VEL_EXTAX. (In the fixed-tool mode $VEL.CP is the
            // torch's speed over the part; with the base coupled to the
            // positioner it is the TCP's speed relative to the moving base, the
            // part: both the planned meaning.)
            let speed = match speed {
                MotionSpeed::Linear(v) if !external_tcp && !coordinated => MotionSpeed::Tcp {
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
                positioner,
                kind,
                speed,
            })));
        }
        steps.extend(after);
    }
    for (_, action, l) in pending {
        push(
            &mut report,
            ProblemKind::Instruction,
            src,
            l,
            format!("trigger `{action}` without a motion after it"),
        );
    }
    if let Some(l) = after_off {
        missing_burn_back(&mut report, src, l, opts);
    }
    if let Some(l) = in_if {
        push(
            &mut report,
            ProblemKind::Instruction,
            src,
            l,
            "IF without ENDIF".into(),
        );
    }
    if arc {
        sup.finish(program, opts, &on, &off, &mut report);
    }
    *report_out = report;
    steps
}

/// Whitespace-insensitive equality of two statements.
fn same(a: &str, b: &str) -> bool {
    a.chars()
        .filter(|c| !c.is_whitespace())
        .eq(b.chars().filter(|c| !c.is_whitespace()))
}

/// The statement keyword of `op` in messages.
fn keyword(op: &KrlOp) -> String {
    match op {
        KrlOp::EndIf => "ENDIF".into(),
        KrlOp::Halt => "HALT".into(),
        KrlOp::IfIn(n) => format!("IF $IN[{n}] THEN"),
        KrlOp::Loop => "LOOP".into(),
        KrlOp::EndLoop => "ENDLOOP".into(),
        KrlOp::Exit => "EXIT".into(),
        KrlOp::Brake { fast: true } => "BRAKE F".into(),
        KrlOp::Brake { fast: false } => "BRAKE".into(),
        KrlOp::Resume => "RESUME".into(),
        other => format!("{other:?}"),
    }
}

/// The expected ignition handshake, in messages.
fn handshake_form(opts: &KukaOptions) -> String {
    let (n, t) = (opts.arc_ok_input, opts.ignition_timer);
    format!(
        "expected a LOOP: arc on, WAIT FOR $IN[{n}] OR $TIMER_FLAG[{t}] with a {:.3} s timeout, IF $IN[{n}] THEN EXIT ENDIF, arc off, HALT, ENDLOOP",
        opts.ignition_timeout_s
    )
}

/// Index of the `ENDLOOP` closing the `LOOP` at `start`.
fn loop_end(stmts: &[KrlStatement], start: usize) -> Option<usize> {
    let mut depth = 0usize;
    for (k, st) in stmts.iter().enumerate().skip(start) {
        match st.op {
            KrlOp::Loop => depth += 1,
            KrlOp::EndLoop => {
                depth -= 1;
                if depth == 0 {
                    return Some(k);
                }
            }
            _ => {}
        }
    }
    None
}

/// An ignition handshake as read ([`read_handshake`]).
#[derive(Debug)]
struct Handshake {
    /// Line of the arc on in it.
    on_line: usize,
    /// Nothing missing: its problems, if any, were reported.
    complete: bool,
}

/// Reads `block` (a `LOOP` to its `ENDLOOP`) as the ignition handshake the
/// emitter writes: arc on, `$TIMER[t]` set to minus the timeout and
/// started, `WAIT FOR $IN[n] OR $TIMER_FLAG[t]`, `IF $IN[n] THEN EXIT
/// ENDIF`, then the failed branch: arc off, message, `HALT`. `None` when
/// the loop switches no arc on (not a handshake). What is missing or
/// differs from `opts` is added to `report`.
fn read_handshake(
    block: &[KrlStatement],
    opts: &KukaOptions,
    on: &str,
    off: &str,
    src: &str,
    report: &mut ValidationReport,
) -> Option<Handshake> {
    let body = &block[1..block.len() - 1];
    let on_line = body
        .iter()
        .find(|s| matches!(&s.op, KrlOp::Other(t) if same(t, on)))?
        .line;
    let (mut timer_ms, mut started, mut waited) = (None, false, None);
    // after `IF $IN[n] THEN EXIT ENDIF`: the failed branch
    let mut exit_on: Option<u32> = None;
    let (mut failed_off, mut halt) = (false, false);
    let mut k = 0;
    while let Some(st) = body.get(k) {
        k += 1;
        let line = st.line;
        let mut problem = |kind, msg: String| push(report, kind, src, line, msg);
        match &st.op {
            KrlOp::Timer { timer, ms } if *timer == opts.ignition_timer => timer_ms = Some(*ms),
            KrlOp::TimerStop { timer, stop: false }
                if *timer == opts.ignition_timer && timer_ms.is_some() =>
            {
                started = true;
            }
            KrlOp::WaitInOrTimer { input, timer } => {
                if *input != opts.arc_ok_input || *timer != opts.ignition_timer {
                    problem(
                        ProblemKind::Options,
                        format!(
                            "ignition wait on $IN[{input}] / $TIMER_FLAG[{timer}], the options give $IN[{}] / $TIMER_FLAG[{}]",
                            opts.arc_ok_input, opts.ignition_timer
                        ),
                    );
                }
                let want = -(opts.ignition_timeout_s * 1000.0).round();
                match (timer_ms, started) {
                    (Some(ms), true) if (ms - want).abs() <= 0.5 => {}
                    (Some(ms), true) => problem(
                        ProblemKind::Options,
                        format!(
                            "ignition timeout {:.3} s ($TIMER[{timer}] = {ms}), the options give {:.3} s",
                            -ms / 1000.0,
                            opts.ignition_timeout_s
                        ),
                    ),
                    _ => problem(
                        ProblemKind::Instruction,
                        format!("ignition wait without its timer: $TIMER[{timer}] not set to minus the timeout and started"),
                    ),
                }
                waited = Some(*input);
            }
            KrlOp::IfIn(n) if exit_on.is_none() => {
                let exits = matches!(
                    (body.get(k).map(|s| &s.op), body.get(k + 1).map(|s| &s.op)),
                    (Some(KrlOp::Exit), Some(KrlOp::EndIf))
                );
                if !exits {
                    problem(
                        ProblemKind::Instruction,
                        format!("expected `IF $IN[{n}] THEN`, `EXIT`, `ENDIF`: the loop is left only with the arc established"),
                    );
                    continue;
                }
                k += 2;
                if waited.is_some_and(|w| w != *n) {
                    problem(
                        ProblemKind::Instruction,
                        format!(
                            "the ignition loop is left on $IN[{n}], not on the input waited for, $IN[{}]",
                            waited.unwrap_or_default()
                        ),
                    );
                }
                exit_on = Some(*n);
            }
            KrlOp::Exit => problem(
                ProblemKind::Instruction,
                "EXIT of the ignition loop without the arc established: the bead would start without the arc".into(),
            ),
            KrlOp::Other(t) if exit_on.is_some() && same(t, off) => failed_off = true,
            KrlOp::Other(t) if exit_on.is_some() && same(t, on) => problem(
                ProblemKind::Instruction,
                "arc on in the failed-ignition branch".into(),
            ),
            KrlOp::Halt if exit_on.is_some() => halt = true,
            KrlOp::Ptp(_) | KrlOp::Lin { .. } | KrlOp::Circ { .. } => problem(
                ProblemKind::Instruction,
                "motion inside the ignition loop".into(),
            ),
            _ => {}
        }
    }
    let complete = waited.is_some() && exit_on.is_some() && halt;
    if !complete {
        push(
            report,
            ProblemKind::Instruction,
            src,
            on_line,
            format!(
                "arc on without the ignition handshake ({})",
                handshake_form(opts)
            ),
        );
    } else if !failed_off {
        push(
            report,
            ProblemKind::Instruction,
            src,
            block[0].line,
            format!("the failed-ignition branch halts with the arc output on (expected `{off}` before its HALT)"),
        );
    }
    Some(Handshake {
        on_line,
        complete: complete && failed_off,
    })
}

/// The arc-loss supervision of a program's main routine as read (module
/// doc of [`crate::program::kuka`], "Arc supervision").
#[derive(Debug, Default)]
struct Supervision {
    /// The arc-loss interrupt's `INTERRUPT DECL`: priority, routine, line.
    decl: Option<(u8, String, usize)>,
    /// `INTERRUPT ON` of it, not `OFF` since.
    on: bool,
    /// `INTERRUPT DISABLE` of it, not `ENABLE` since.
    disabled: bool,
    /// Beads started so far.
    beads: usize,
    /// Line of the first bead's arc on.
    first_bead: Option<usize>,
    /// The current bead's ignition handshake was read.
    established: bool,
    /// The current bead's unsupervised motion was reported.
    reported: bool,
}

impl Supervision {
    fn armed(&self) -> bool {
        self.on && !self.disabled
    }

    fn prio(&self, opts: &KukaOptions) -> u8 {
        self.decl.as_ref().map_or(opts.arc_loss_interrupt, |d| d.0)
    }

    /// An `INTERRUPT DECL`: the arc-loss interrupt if it has the options'
    /// priority or fires on the arc-established input going off.
    #[allow(clippy::too_many_arguments)]
    fn declare(
        &mut self,
        prio: u8,
        when: &str,
        handler: &str,
        line: usize,
        opts: &KukaOptions,
        src: &str,
        report: &mut ValidationReport,
    ) {
        let input = falling_input(when);
        if prio != opts.arc_loss_interrupt && input != Some(opts.arc_ok_input) {
            return; // another interrupt (the INI fold's IR_STOPM)
        }
        let mut problem = |kind, msg: String| push(report, kind, src, line, msg);
        if prio != opts.arc_loss_interrupt {
            problem(
                ProblemKind::Options,
                format!(
                    "arc-loss interrupt priority {prio}, the options give {}",
                    opts.arc_loss_interrupt
                ),
            );
        }
        if input != Some(opts.arc_ok_input) {
            problem(
                ProblemKind::Options,
                format!(
                    "the arc-loss interrupt {prio} fires on `{when}`, the options give the arc-established input going off, `$IN[{}]==FALSE`",
                    opts.arc_ok_input
                ),
            );
        }
        if let Some(first) = self.first_bead {
            problem(
                ProblemKind::Instruction,
                format!("the arc-loss interrupt is declared after the first bead (arc on at line {first})"),
            );
        }
        self.decl = Some((prio, handler.to_string(), line));
    }

    /// `INTERRUPT action [prio]`.
    #[allow(clippy::too_many_arguments)]
    fn control(
        &mut self,
        action: InterruptAction,
        prio: Option<u8>,
        line: usize,
        arc_is_on: bool,
        opts: &KukaOptions,
        src: &str,
        report: &mut ValidationReport,
    ) {
        let ours = match (&self.decl, prio) {
            (Some(_), None) => true,
            (Some(d), Some(p)) => d.0 == p,
            (None, p) => {
                if p == Some(opts.arc_loss_interrupt) {
                    push(
                        report,
                        ProblemKind::Instruction,
                        src,
                        line,
                        format!(
                            "INTERRUPT {} {} before its INTERRUPT DECL",
                            action.keyword(),
                            opts.arc_loss_interrupt
                        ),
                    );
                }
                false
            }
        };
        if !ours {
            return;
        }
        match action {
            InterruptAction::On => {
                if !(arc_is_on && self.established) {
                    push(
                        report,
                        ProblemKind::Instruction,
                        src,
                        line,
                        format!(
                            "INTERRUPT ON {} before the arc is established: it fires when $IN[{}] goes off (an edge), so it is armed after the ignition handshake",
                            self.prio(opts),
                            opts.arc_ok_input
                        ),
                    );
                }
                self.on = true;
            }
            InterruptAction::Off => self.on = false,
            InterruptAction::Disable => self.disabled = true,
            InterruptAction::Enable => self.disabled = false,
        }
    }

    /// An arc on at `line`; `established`: in an ignition handshake.
    fn bead_start(&mut self, line: usize, established: bool) {
        self.beads += 1;
        self.first_bead.get_or_insert(line);
        self.established = established;
        self.reported = false;
    }

    /// A motion (`what`, e.g. `LIN P3`) with the arc on: the interrupt must
    /// be on (reported once a bead).
    fn motion(
        &mut self,
        line: usize,
        what: &str,
        opts: &KukaOptions,
        src: &str,
        report: &mut ValidationReport,
    ) {
        if self.armed() || self.reported {
            return;
        }
        self.reported = true;
        let (b, p, n) = (self.beads, self.prio(opts), opts.arc_ok_input);
        let msg = match self.decl {
            None => format!(
                "bead {b}: {what} with the arc on and no arc-loss supervision (INTERRUPT DECL {p} WHEN $IN[{n}]==FALSE DO {ARC_LOST_HANDLER}( ) before the first bead, INTERRUPT ON {p} after each ignition): an arc loss goes unseen"
            ),
            Some(_) => format!(
                "bead {b}: {what} with the arc on while the arc-loss interrupt {p} is not on (INTERRUPT ON {p} after the ignition handshake, INTERRUPT OFF {p} only before the arc off): an arc loss here goes unseen"
            ),
        };
        push(report, ProblemKind::Instruction, src, line, msg);
    }

    /// The arc switched off at `line` (a bead's end).
    fn arc_off(&mut self, line: usize, src: &str, report: &mut ValidationReport) {
        if self.armed() {
            let p = self.decl.as_ref().map_or(0, |d| d.0);
            push(
                report,
                ProblemKind::Instruction,
                src,
                line,
                format!("arc off with the arc-loss interrupt {p} on: the input going off fires it at every bead's end (INTERRUPT OFF {p} before the arc off)"),
            );
        }
        self.established = false;
    }

    /// After the main routine: the declaration exists and its routine is
    /// the handler the options give.
    fn finish(
        &self,
        program: &KrlProgram,
        opts: &KukaOptions,
        on: &str,
        off: &str,
        report: &mut ValidationReport,
    ) {
        let src = &program.src_file;
        let Some(first) = self.first_bead else {
            return;
        };
        match &self.decl {
            None => push(
                report,
                ProblemKind::Instruction,
                src,
                first,
                format!(
                    "no arc-loss supervision: `INTERRUPT DECL {p} WHEN $IN[{n}]==FALSE DO {ARC_LOST_HANDLER}( )` missing before the first bead, so an arc loss in a bead is never seen",
                    p = opts.arc_loss_interrupt,
                    n = opts.arc_ok_input
                ),
            ),
            Some((prio, handler, line)) => match program.routine(handler) {
                None => push(
                    report,
                    ProblemKind::Declaration,
                    src,
                    *line,
                    format!("the arc-loss interrupt calls {handler}( ), which is not a DEF in {src}"),
                ),
                Some(r) => check_handler(r, *prio, opts, on, off, src, report),
            },
        }
    }
}

/// Checks the arc-loss interrupt routine `r` (priority `prio`): it stops
/// the robot (`BRAKE F`), switches the arc off, and never returns into the
/// bead with the arc off: an endless `HALT` (abort) or, after a `HALT`, the
/// ignition handshake and the interrupt re-armed (reignite), as
/// [`KukaOptions::arc_loss`] gives.
fn check_handler(
    r: &KrlRoutine,
    prio: u8,
    opts: &KukaOptions,
    on: &str,
    off: &str,
    src: &str,
    report: &mut ValidationReport,
) {
    let name = &r.name;
    let stmts = &r.statements;
    let (mut brake, mut arc_off, mut halt) = (false, false, false);
    // the routine ends in an endless LOOP with a HALT
    let mut endless = false;
    // an ignition handshake read (complete?), then the interrupt re-armed
    let mut reignite: Option<bool> = None;
    let mut rearmed = false;
    let mut next = 0;
    while let Some(st) = stmts.get(next) {
        next += 1;
        let line = st.line;
        let mut problem = |msg: String| push(report, ProblemKind::Instruction, src, line, msg);
        match &st.op {
            KrlOp::Brake { fast } => {
                brake = true;
                if !fast {
                    problem(format!("`BRAKE` in the arc-loss handler {name} stops with the normal ramp: `BRAKE F` stops on the path as fast as possible"));
                }
            }
            KrlOp::Other(t) if same(t, off) => {
                if reignite.is_some() {
                    problem(format!("arc off after the re-ignition in {name}: the bead goes on with the arc off"));
                } else {
                    arc_off = true;
                }
            }
            KrlOp::Other(t) if same(t, on) => problem(format!(
                "arc on in {name} outside the ignition handshake ({})",
                handshake_form(opts)
            )),
            KrlOp::Halt => halt = true,
            KrlOp::Loop => {
                let Some(end) = loop_end(stmts, next - 1) else {
                    problem("LOOP without ENDLOOP".into());
                    break;
                };
                let block = &stmts[next - 1..=end];
                next = end + 1;
                if let Some(h) = read_handshake(block, opts, on, off, src, report) {
                    if !halt {
                        push(
                            report,
                            ProblemKind::Instruction,
                            src,
                            h.on_line,
                            format!("{name} re-ignites without a HALT first: the operator does not see the arc loss"),
                        );
                    }
                    reignite = Some(h.complete);
                    continue;
                }
                let body = &block[1..block.len() - 1];
                let exits = body.iter().any(|s| s.op == KrlOp::Exit);
                let halts = body.iter().any(|s| s.op == KrlOp::Halt);
                if !exits && halts {
                    endless = true;
                    break; // nothing after it runs
                }
                push(
                    report,
                    ProblemKind::Instruction,
                    src,
                    line,
                    format!("a LOOP in {name} that is neither an endless HALT nor the ignition handshake"),
                );
            }
            KrlOp::Interrupt {
                action: InterruptAction::On | InterruptAction::Enable,
                prio: p,
            } if p.is_none_or(|p| p == prio) => {
                if reignite.is_some() {
                    rearmed = true;
                } else {
                    problem(format!("INTERRUPT ON {prio} in {name} before the arc is established again"));
                }
            }
            KrlOp::Ptp(_) | KrlOp::Lin { .. } | KrlOp::Circ { .. } => problem(format!("motion in the arc-loss handler {name}")),
            KrlOp::Resume => problem(format!(
                "RESUME in the arc-loss handler {name}: it abandons the rest of the bead, and the program goes on without it"
            )),
            KrlOp::Exit => problem(format!("EXIT outside a loop in {name}")),
            _ => {}
        }
    }
    let mut problem = |kind, msg: String| push(report, kind, src, r.line, msg);
    if !brake {
        problem(
            ProblemKind::Instruction,
            format!("the arc-loss handler {name} does not stop the robot (`BRAKE F`)"),
        );
    }
    if !arc_off {
        problem(
            ProblemKind::Instruction,
            format!("the arc-loss handler {name} does not switch the arc off (`{off}`): the output stays on while the robot stands"),
        );
    }
    let quoted = |m: ArcLoss| match m {
        ArcLoss::Abort => "\"abort\"",
        ArcLoss::Reignite => "\"reignite\"",
    };
    match (endless, reignite, opts.arc_loss) {
        (false, None, _) => problem(
            ProblemKind::Instruction,
            format!("the arc-loss handler {name} returns into the bead with the arc off: the start goes on without the arc (abort: end in LOOP HALT ENDLOOP; reignite: HALT, then the ignition handshake)"),
        ),
        (true, _, ArcLoss::Reignite) => problem(
            ProblemKind::Options,
            format!("the arc-loss handler {name} ends the program (abort), the options give arc_loss = {}", quoted(opts.arc_loss)),
        ),
        (false, Some(_), ArcLoss::Abort) => problem(
            ProblemKind::Options,
            format!("the arc-loss handler {name} re-ignites, the options give arc_loss = {}", quoted(opts.arc_loss)),
        ),
        (false, Some(_), ArcLoss::Reignite) if !rearmed => problem(
            ProblemKind::Instruction,
            format!("the arc-loss handler {name} re-ignites but does not re-arm the interrupt (INTERRUPT ON {prio} before its END): a second arc loss in the bead goes unseen"),
        ),
        _ => {}
    }
}

/// Largest difference between a stated frame and the expected one: 0.001
/// mm (the `.src` prints 4 decimals) and 0.0001° (5 decimals).
const FRAME_TOL_MM: f64 = 1e-3;
const FRAME_TOL_DEG: f64 = 1e-4;

/// `Some(how)` when the frame `[X, Y, Z, A, B, C]` (mm, deg) is not `want`.
fn frame_differs(f: &[f64; 6], want: &Isometry3) -> Option<String> {
    use crate::robot::orientation::KukaAbc;
    let t = want.translation.vector;
    let d = ((f[0] - t.x).powi(2) + (f[1] - t.y).powi(2) + (f[2] - t.z).powi(2)).sqrt();
    let r = KukaAbc::from_degrees(f[3], f[4], f[5]).to_rotation();
    let ang = (r.transpose() * want.rotation.to_rotation_matrix().matrix())
        .trace()
        .sub(1.0)
        .mul(0.5)
        .clamp(-1.0, 1.0)
        .acos()
        .to_degrees();
    (d > FRAME_TOL_MM || ang > FRAME_TOL_DEG).then(|| format!("{d:.4} mm, {ang:.5} deg apart"))
}

fn show(f: &[f64; 6]) -> String {
    format!(
        "{{X {},Y {},Z {},A {},B {},C {}}}",
        f[0], f[1], f[2], f[3], f[4], f[5]
    )
}

/// An end time (`what`) of `s` s written where the options give `want`.
fn check_time(
    report: &mut ValidationReport,
    file: &str,
    line: usize,
    what: &str,
    s: f64,
    want: f64,
) {
    if (s - want).abs() > 5e-4 {
        push(
            report,
            ProblemKind::Options,
            file,
            line,
            format!("{what} {s:.3} s, the options give {want:.3} s"),
        );
    }
}

/// An arc off (line `l`) not followed by the burn-back wait the options give.
fn missing_burn_back(report: &mut ValidationReport, file: &str, l: usize, opts: &KukaOptions) {
    if opts.burn_back_s > 0.0 {
        push(
            report,
            ProblemKind::Options,
            file,
            l,
            format!(
                "arc off without the burn-back wait `WAIT SEC {:.3}` after it",
                opts.burn_back_s
            ),
        );
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::{UnitVector3, Vector3};
    use crate::program::kuka::read::parse_krl;
    use crate::program::kuka::{kuka_files, KukaOptions, HOME_NAME};
    use crate::program::{build_program, BeadSetup, HomePosition, Payload, TravelSpeed};
    use crate::robot::trajectory::{joint_trajectory, PathPointInput, TrajectoryOptions};

    /// Two layers of the hemisphere (R_s 45 mm, Delta 5 mm, 8 points) in
    /// the KUKA part-carried example cell, `R_Z = 0`.
    fn program() -> (crate::program::Program, CellLayout) {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("parts/cells/kuka_kr16_2_part_carried.toml");
        let cell = crate::io::cell_file::read_cell_file(&path)
            .unwrap()
            .cell
            .unwrap();
        let mut pts = Vec::new();
        for layer in 0..2usize {
            let phi = layer as f64 * 5.0 / 45.0;
            for k in 0..8usize {
                let v = std::f64::consts::TAU * k as f64 / 8.0;
                pts.push(PathPointInput {
                    layer,
                    point: k,
                    position_mm: Point3::new(
                        45.0 * phi.cos() * v.cos(),
                        45.0 * phi.cos() * v.sin(),
                        45.0 * phi.sin(),
                    ),
                    tool_axis: UnitVector3::new_normalize(Vector3::new(
                        -phi.sin() * v.cos(),
                        -phi.sin() * v.sin(),
                        phi.cos(),
                    )),
                    build_direction: None,
                    positioner: None,
                    r_z: 0.0,
                });
            }
        }
        let tr = joint_trajectory(&cell, &pts, 6.0, &TrajectoryOptions::default()).unwrap();
        let prog = build_program("HEMI", &cell, &pts, &tr, &TravelSpeed::Constant(6.0)).unwrap();
        (prog, cell)
    }

    /// The emitted home, payload, dwell and interpass wait come back as the
    /// right steps in the right order: home first and last (joint moves to
    /// the home joints), before bead 0 its payload, before bead 1 payload,
    /// dwell, wait; the crater and burn-back waits and the ignition wait
    /// are not dwell or interpass steps.
    #[test]
    fn emitted_setup_reads_back_as_steps() {
        let (mut prog, cell) = program();
        let home = [10.0, -80.0, 100.0, 0.0, 40.0, 0.0].map(f64::to_radians);
        prog.home = Some(HomePosition {
            joints: home,
            positioner: None,
        });
        let load = |m: f64, z: f64| Payload {
            mass_kg: m,
            cog_mm: Point3::new(0.0, 0.0, z),
        };
        prog.bead_setup = vec![
            BeadSetup {
                layer: 0,
                payload: Some(load(5.0, 60.0)),
                dwell_s: 0.0,
                wait_input: None,
            },
            BeadSetup {
                layer: 1,
                payload: Some(load(5.25, 61.5)),
                dwell_s: 30.0,
                wait_input: Some(7),
            },
        ];
        let opts = KukaOptions::default();
        let f = kuka_files(&prog, &opts).unwrap();
        let p = parse_krl(&f[0].text, &f[0].name, &f[1].text, &f[1].name).unwrap();
        let mut report = ValidationReport::default();
        let steps = kuka_steps(&p, &cell, &opts, &mut report);
        assert!(report.is_ok(), "{report}");
        let motions: Vec<&Motion> = steps
            .iter()
            .filter_map(|s| match s {
                Step::Motion(m) => Some(m.as_ref()),
                _ => None,
            })
            .collect();
        assert_eq!(motions.len(), 2 + 20);
        for m in [motions[0], motions[motions.len() - 1]] {
            assert_eq!((m.label.as_str(), m.kind), (HOME_NAME, MoveKind::Joint));
            let q = m.joints.unwrap();
            assert!(
                q.iter().zip(home).all(|(a, b)| (a - b).abs() < 1e-7),
                "{q:?}"
            );
        }
        // the other steps in order, as (kind, value)
        let rest: Vec<String> = steps
            .iter()
            .filter_map(|s| match s {
                Step::Motion(_) => None,
                Step::ProcessOn { .. } => Some("on".into()),
                Step::ProcessOff { .. } => Some("off".into()),
                Step::Wait { seconds, input, .. } => Some(format!("wait {seconds:?} {input:?}")),
                Step::Payload {
                    mass_kg, cog_mm, ..
                } => Some(format!("load {mass_kg} {}", cog_mm.z)),
            })
            .collect();
        assert_eq!(
            rest,
            [
                "load 5 60",
                "on",
                "off",
                "load 5.25 61.5",
                "wait Some(30.0) None",
                "wait None Some(7)",
                "on",
                "off"
            ]
        );
        // each set-up is before its bead's approach (the first PTP after home)
        let pos = |pred: &dyn Fn(&Step) -> bool| steps.iter().position(pred).unwrap();
        let wait7 = pos(&|s| matches!(s, Step::Wait { input: Some(7), .. }));
        assert!(
            matches!(&steps[wait7 + 1], Step::Motion(m) if m.kind == MoveKind::Joint && m.label == "P11"),
            "{:?}",
            steps[wait7 + 1]
        );
    }
}
