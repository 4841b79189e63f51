//! The motion statements of a KUKA program as read (`PTP`, `LIN`, `CIRC`):
//! the triggers switched with them, each target's `.dat` declaration
//! decoded to joints (`E6AXIS`, or `E6POS` with its Status and Turn bits)
//! and its speed in the frame the controller runs it in.

use std::f64::consts::TAU;

use super::{same, Decoder};
use crate::math::Isometry3;
use crate::program::kuka::read::{KrlOp, KrlPosition, KrlStatement, KrlValue};
use crate::program::validate::{arm_of, decode_pose, push, wrist_of_j5};
use crate::program::validate::{
    DecodedStep, Motion, MotionSpeed, ProblemKind, ValidationReport, WireFeed,
};
use crate::program::MoveKind;
use crate::robot::orientation::KukaAbc;
use crate::robot::{CellLayout, Configuration, Joints};

impl Decoder<'_> {
    /// A motion statement `st`: the frames must have been stated, the
    /// arc supervised; its triggers and its targets become steps.
    /// `report_out` is the caller's report, overwritten when the decoding
    /// ends (an E2 written outside (-180°, 180°] is noted there).
    pub(super) fn motion(&mut self, st: &KrlStatement, report_out: &mut ValidationReport) {
        let line = st.line;
        let src = self.src();
        // the positions a motion statement moves to, with how: a `CIRC`'s
        // auxiliary point first, as its own step
        let (targets, linear) = match &st.op {
            KrlOp::Ptp(t) => (vec![(t, MoveKind::Joint)], false),
            KrlOp::Lin { target, .. } => (vec![(target, MoveKind::Linear)], true),
            KrlOp::Circ { aux, target, .. } => {
                self.circ_types_stated(line);
                (
                    vec![(aux, MoveKind::Via), (target, MoveKind::Circular)],
                    true,
                )
            }
            _ => return,
        };
        // a motion: the frames must have been stated, the ignition checked
        self.frames_stated(line);
        if self.arc && self.arc_is_on {
            let what = match targets.as_slice() {
                [(aux, _), (target, _)] => format!("CIRC {aux}, {target}"),
                [(target, _), ..] => format!("{} {target}", if linear { "LIN" } else { "PTP" }),
                [] => String::new(),
            };
            self.sup
                .motion(line, &what, self.opts, src, &mut self.report);
        }
        if let Some((_, l)) = self.mass.take() {
            self.instruction(l, "$LOAD.M without a $LOAD.CM after it".into());
        }
        let after = self.triggered();
        for (target, kind) in targets {
            let dat = &self.program.dat_file;
            let Some(pos) = self.program.positions.iter().find(|p| &p.name == target) else {
                push(
                    &mut self.report,
                    ProblemKind::Declaration,
                    src,
                    line,
                    format!("{target} has no DECL in {dat}"),
                );
                continue;
            };
            let step = self.target_step(line, pos, kind, linear, report_out);
            self.steps.push(step);
        }
        self.steps.extend(after);
    }

    /// The pending triggers' switches: those at the motion's start pushed
    /// as steps, those at its end returned (to follow its steps).
    fn triggered(&mut self) -> Vec<DecodedStep> {
        let src = self.src();
        let mut after = Vec::new();
        for (distance, action, l) in std::mem::take(&mut self.pending) {
            // the wire feed's command switched at the move's start
            let anout = action
                .split_once('=')
                .and_then(|(k, v)| crate::program::kuka::read::parse_anout(k, v))
                .filter(|(n, _)| *n == self.opts.wire_feed_anout && self.arc);
            if let (Some((_, v)), 0) = (anout, distance) {
                self.anout = Some(v);
                continue;
            }
            let step = if same(&action, &self.on) {
                DecodedStep::ProcessOn {
                    file: src.to_string(),
                    line: l,
                }
            } else if same(&action, &self.off) {
                DecodedStep::ProcessOff {
                    file: src.to_string(),
                    line: l,
                }
            } else {
                self.instruction(l, format!("unexpected trigger action `{action}`"));
                continue;
            };
            if distance == 0 {
                self.steps.push(step);
            } else {
                after.push(step);
            }
        }
        after
    }

    /// The motion step to `pos` (declared in the `.dat`) of the statement at
    /// `line`: its joints decoded, its speed in the controller's meaning.
    fn target_step(
        &mut self,
        line: usize,
        pos: &KrlPosition,
        kind: MoveKind,
        linear: bool,
        report_out: &mut ValidationReport,
    ) -> DecodedStep {
        let (src, dat) = (self.src(), &self.program.dat_file);
        let cell = self.cell;
        let speed = if linear {
            match self.vel {
                Some(v) => MotionSpeed::Linear(v),
                None => {
                    push(
                        &mut self.report,
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
                &mut self.report,
                ProblemKind::Declaration,
                src,
                line,
                format!(
                    "LIN to {}, an E6AXIS ({dat}:{}): a LIN target must be an E6POS",
                    pos.name, pos.line
                ),
            );
        }
        let mut positioner =
            matches!(cell, CellLayout::TorchCarried(_)).then(|| pos.external.map(f64::to_radians));
        if let (true, Some(qp)) = (self.modulo, positioner.as_mut()) {
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
            qp[1] = self.turn_at + crate::robot::ik::wrap_pi(qp[1] - self.turn_at);
            self.turn_at = qp[1];
        }
        let (joints, from_cartesian) = match &pos.value {
            KrlValue::Axis(a) => (Some(a.map(f64::to_radians)), false),
            KrlValue::Pos {
                xyzabc,
                status,
                turn,
            } => (
                self.decode_e6pos(pos, xyzabc, *status, *turn, positioner, linear),
                true,
            ),
        };
        // Outside the fixed-tool mode and without a coupled base $VEL.CP is
        // the TCP's speed in the robot frame, and external axes move with
        // the path at $VEL_EXTAX. (In the fixed-tool mode $VEL.CP is the
        // torch's speed over the part; with the base coupled to the
        // positioner it is the TCP's speed relative to the moving base, the
        // part: both the planned meaning.)
        let speed = match speed {
            MotionSpeed::Linear(v) if !self.external_tcp && !self.coordinated => MotionSpeed::Tcp {
                mm_s: v,
                flange_from_tcp: self.tool,
                extax_fraction: [self.vel_extax[0] / 100.0, self.vel_extax[1] / 100.0],
            },
            speed => speed,
        };
        self.prev_q = joints.or(self.prev_q);
        DecodedStep::Motion(Box::new(Motion {
            file: src.to_string(),
            line,
            label: pos.name.clone(),
            record_file: dat.clone(),
            record_line: pos.line,
            value_lines: [pos.line; 6],
            joints,
            from_cartesian,
            positioner,
            kind,
            wire_feed: self.wire_feed(&speed),
            speed,
        }))
    }

    /// The wire feed of a move at `speed` with the arc on: the analog
    /// command times its full scale, with the relative steps of the written
    /// command (4 decimals) and `$VEL.CP` (6 decimals of m/s) as its
    /// tolerance.
    fn wire_feed(&self, speed: &MotionSpeed) -> Option<WireFeed> {
        if !(self.arc && self.arc_is_on) {
            return None;
        }
        let a = self.anout.filter(|a| *a > 0.0)?;
        let v = match *speed {
            MotionSpeed::Linear(v) | MotionSpeed::Tcp { mm_s: v, .. } => v,
            MotionSpeed::Time(_) | MotionSpeed::Joint => return None,
        };
        Some(WireFeed {
            mm_s: a * self.opts.wire_feed_full_scale_mm_s,
            tolerance: 0.5e-4 / a + 1e-3 / v,
        })
    }

    /// The arm joints (rad) of the `E6POS` `pos` (`xyzabc` in mm and deg
    /// in the base at the positioner joints `positioner`), its Status bits
    /// checked against the cell's configuration; a `PTP` (not `linear`)
    /// takes each of A1, A4, A6 by its Turn bit, a `LIN` nearest the
    /// previous position.
    fn decode_e6pos(
        &mut self,
        pos: &KrlPosition,
        xyzabc: &[f64; 6],
        status: u8,
        turn: u8,
        positioner: Option<[f64; 2]>,
        linear: bool,
    ) -> Option<Joints> {
        let (cell, robot, dat) = (self.cell, self.cell.robot(), &self.program.dat_file);
        let (side, elbow) = arm_of(status & 1 != 0, status & 2 != 0);
        let cfg = Configuration {
            wrist: wrist_of_j5(robot, status & 4 == 0),
            elbow,
            side,
        };
        if cfg != cell.configuration() {
            push(
                &mut self.report,
                ProblemKind::Configuration,
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
        let base = self.opts.base_at(cell, positioner);
        let base_from_flange = base * pose * self.tool.inverse();
        let prev_q = self.prev_q;
        decode_pose(
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
            &mut self.report,
        )
    }
}
