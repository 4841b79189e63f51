//! FANUC programs as [`Step`]s: the TP programs read by
//! [`parse_ls`](crate::program::readback::parse_ls), `CALL`s followed, each
//! position decoded (joints, or a Cartesian pose with its `CONFIG` string
//! and turn numbers).

use std::f64::consts::TAU;

use crate::math::Point3;
use crate::program::fanuc::{ArmPosition, FanucOptions, Op, TpProgram};
use crate::program::ProcessControl;
use crate::robot::orientation::FanucPose;
use crate::robot::{Cell, Configuration, Vendor};

use super::ProblemKind;
use super::{
    check_steps, decode_pose, push, vendor_matches, Motion, MotionSpeed, Step, ValidationReport,
};

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
    check_steps(&steps, cell, planned, &opts.common, &mut report);
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
                        ProblemKind::Call,
                        file,
                        line,
                        format!("CALL {name}: calls nested too deep"),
                    );
                    continue;
                }
                match programs.iter().find(|p| &p.name == name) {
                    Some(sub) => fanuc_steps(programs, sub, depth + 1, cell, opts, steps, report),
                    None => push(
                        report,
                        ProblemKind::Call,
                        file,
                        line,
                        format!("CALL {name}: no such program"),
                    ),
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
                ProblemKind::Instruction,
                file,
                line,
                format!("unexpected instruction `{}`", ins.op.to_string().trim()),
            ),
            Op::UFrame(n) if *n != opts.user_frame => push(
                report,
                ProblemKind::Frame,
                file,
                line,
                format!("UFRAME_NUM={n}, the options give {}", opts.user_frame),
            ),
            Op::UTool(n) if *n != opts.tool_frame => push(
                report,
                ProblemKind::Frame,
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
                    push(
                        report,
                        ProblemKind::Declaration,
                        file,
                        line,
                        format!("P[{position}] has no record"),
                    );
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
                                    report, ProblemKind::Configuration,
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
                                ProblemKind::Configuration,
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
