//! ABB modules as [`Step`]s: the module read by
//! [`parse_mod`](crate::program::readback::abb::parse_mod), each
//! `robtarget` decoded with its `confdata` in the file's own frames.

use std::f64::consts::TAU;

use crate::math::Point3;
use crate::program::fanuc::MoveKind;
use crate::program::ProcessControl;
use crate::robot::{Cell, Configuration, Vendor};

use super::ProblemKind;
use super::{arm_of, wrist_of_j5};
use super::{
    check_steps, decode_pose, push, vendor_matches, Motion, MotionSpeed, Step, ValidationReport,
};

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
            push(&mut report, ProblemKind::Options, file, 1, e.to_string());
            return report;
        }
    };
    let robot = cell.robot();
    let frames = match (&module.tool, &module.wobj) {
        (Some(t), Some(w)) => match (t.robhold, w.robhold) {
            (true, false) => Some(AbbFrames::Held {
                flange_from_tool: t.pose,
                base_from_work: w.pose,
            }),
            (false, true) => Some(AbbFrames::Stationary {
                base_from_tool: t.pose,
                flange_from_work: w.pose,
            }),
            _ => {
                push(
                    &mut report,
                    ProblemKind::Declaration,
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
                ProblemKind::Declaration,
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
                        ProblemKind::Instruction,
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
                        ProblemKind::Options,
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
                ProblemKind::Configuration,
                file,
                line,
                "linear move without `ConfL \\On`: the controller may change the configuration"
                    .into(),
            );
        }
        let Some(t) = module.targets.iter().find(|t| &t.name == target) else {
            push(
                &mut report,
                ProblemKind::Declaration,
                file,
                line,
                format!("{target} is not declared"),
            );
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
                        &mut report, ProblemKind::Configuration,
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
                    ProblemKind::Declaration,
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
    check_steps(&steps, cell, planned, &opts.common, &mut report);
    report
}
