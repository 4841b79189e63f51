//! KUKA programs as [`Step`]s: the `.src`/`.dat` pair read by
//! [`parse_krl`](crate::program::readback::kuka::parse_krl), each position
//! decoded (`E6AXIS`, or `E6POS` with its Status and Turn bits).

use std::f64::consts::TAU;

use crate::math::{Isometry3, Point3};
use crate::program::fanuc::MoveKind;
use crate::robot::{Cell, Configuration, Joints, Vendor};

use super::ProblemKind;
use super::{arm_of, wrist_of_j5};
use super::{
    check_steps, decode_pose, push, vendor_matches, Motion, MotionSpeed, Step, ValidationReport,
};

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
                        ProblemKind::Frame,
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
                        ProblemKind::Frame,
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
            ProblemKind::Instruction,
            src,
            l,
            format!("trigger `{action}` without a motion after it"),
        );
    }
    check_steps(&steps, cell, planned, &opts.common, &mut report);
    report
}
