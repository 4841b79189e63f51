//! KUKA programs as [`DecodedStep`]s: the `.src`/`.dat` pair read by
//! [`parse_krl`](crate::program::kuka::read::parse_krl), each position
//! decoded (`E6AXIS`, or `E6POS` with its Status and Turn bits). With the
//! arc process the file's own safety is checked too: each bead's ignition
//! handshake, and its arc-loss supervision (the interrupt declared on the
//! options' input, on for every motion with the arc on, off before the arc
//! off, and a handler that brakes, switches the arc off and never returns
//! into the bead with the arc off; module doc of [`crate::program::kuka`]).
//!
//! `kuka_steps` dispatches each statement of the main routine to the
//! decoder of its kind: motions (`motion`), frame statements (`frames`),
//! speeds and triggers, payloads and waits (here), and the arc process
//! with its ignition handshake (`handshake`) and arc-loss supervision
//! (`supervision`).

mod frames;
mod handshake;
mod motion;
mod supervision;

use crate::math::Isometry3;
use crate::program::kuka::read::{KrlOp, KrlProgram, KrlStatement};
use crate::program::kuka::KukaOptions;
use crate::program::PlannedPoint;
use crate::robot::{CellLayout, Joints};

use crate::program::validate::ProblemKind;
use crate::program::validate::{push, DecodedStep, ValidationReport};

use handshake::{handshake_form, loop_end, read_handshake};
use supervision::Supervision;

/// Validates a KUKA program read by
/// [`parse_krl`](crate::program::kuka::read::parse_krl) against `cell`
/// with the frames, tool/base numbers and process of `opts` (as the
/// [`DecodedStep`]s of the module doc). `E6POS` targets are decoded with the
/// Status bits (branch, checked against the cell's) and, for `PTP`, the
/// Turn bits (each of A1, A4, A6 the value of that sign nearest zero inside
/// its travel); a `LIN` ignores Turn as the controller does and takes the
/// value nearest the previous position. A cell whose robot is not a KUKA
/// arm is refused: the report holds that one problem (line 1 of the `.src`).
pub fn validate_kuka(
    program: &KrlProgram,
    cell: &CellLayout,
    opts: &KukaOptions,
    planned: Option<&[PlannedPoint]>,
) -> ValidationReport {
    use crate::program::contract::Controller;
    use crate::program::kuka::Kuka;
    Kuka::validate(program, cell, opts, planned)
}

/// The [`DecodedStep`]s of a KUKA program (motions decoded, process on and off,
/// waits, payloads) in execution order, with the problems of the file
/// itself (frames, triggers, ignition handshake, arc-loss supervision and
/// its handler, end times) added to `report_out`. The cell's robot must be
/// a KUKA arm.
pub(crate) fn kuka_steps(
    program: &KrlProgram,
    cell: &CellLayout,
    opts: &KukaOptions,
    report_out: &mut ValidationReport,
) -> Vec<DecodedStep> {
    let mut d = Decoder::new(program, cell, opts, std::mem::take(report_out));
    let stmts = &program.statements;
    let mut next = 0;
    while let Some(st) = stmts.get(next) {
        next += 1;
        if d.burn_back_wait(st) || d.inside_stray_if(st) {
            continue;
        }
        match &st.op {
            KrlOp::Ptp(_) | KrlOp::Lin { .. } | KrlOp::Circ { .. } => d.motion(st, report_out),
            KrlOp::VelCp(_)
            | KrlOp::VelExtax { .. }
            | KrlOp::VelPtp(_)
            | KrlOp::Trigger { .. }
            | KrlOp::Anout { .. } => d.speed_or_trigger(st),
            KrlOp::OriType(_)
            | KrlOp::CircType(_)
            | KrlOp::IpoTcp(_)
            | KrlOp::Tool(_)
            | KrlOp::Base(_)
            | KrlOp::ToolFrame(_)
            | KrlOp::BaseFrame(_)
            | KrlOp::BaseEk { .. } => d.frame_statement(st),
            KrlOp::LoadMass(_)
            | KrlOp::LoadCm(_)
            | KrlOp::LoadJ(_)
            | KrlOp::WaitSec(_)
            | KrlOp::WaitIn(_)
            | KrlOp::WaitInOrTimer { .. }
            | KrlOp::Timer { .. }
            | KrlOp::TimerStop { .. } => d.payload_or_wait(st),
            KrlOp::Loop => match d.ignition_loop(stmts, next - 1) {
                Some(end) => next = end + 1,
                None => break,
            },
            KrlOp::IfNotIn(n) => d.stray_if(*n, st.line),
            KrlOp::InterruptDecl { .. } | KrlOp::Interrupt { .. } => d.interrupt(st),
            KrlOp::EndIf
            | KrlOp::Halt
            | KrlOp::IfIn(_)
            | KrlOp::EndLoop
            | KrlOp::Exit
            | KrlOp::Brake { .. }
            | KrlOp::Resume => d.instruction(st.line, format!("unexpected `{}`", keyword(&st.op))),
            KrlOp::Other(text) => d.switch(text, st.line),
        }
    }
    let (steps, report) = d.finish();
    *report_out = report;
    steps
}

/// What [`kuka_steps`] carries from statement to statement of the main
/// routine.
struct Decoder<'a> {
    program: &'a KrlProgram,
    cell: &'a CellLayout,
    opts: &'a KukaOptions,
    /// The tool frame the positions assume (flange from TCP, mm).
    tool: Isometry3,
    /// The statements that switch the process on and off.
    on: String,
    off: String,
    /// The options' process is the arc.
    arc: bool,
    coordinated: bool,
    external_tcp: bool,
    /// An endless turn written modulo 360°: the controller takes the
    /// shortest way from where the table is.
    modulo: bool,
    steps: Vec<DecodedStep>,
    report: ValidationReport,
    /// `$VEL.CP` (mm/s), once stated.
    vel: Option<f64>,
    /// Triggers waiting for the next motion: distance, action, line.
    pending: Vec<(u8, String, usize)>,
    /// The last decoded arm joints (rad).
    prev_q: Option<Joints>,
    /// Where the endless turn is (rad; home's turn before the first motion).
    turn_at: f64,
    /// External axes' path speeds (%), as the last `BAS (#VEL_PTP,n)` or
    /// `$VEL_EXTAX[n]` left them (assumed 100 before either).
    vel_extax: [f64; 6],
    /// Frames stated before the first motion.
    tool_stated: bool,
    base_stated: bool,
    first_motion: bool,
    /// The arc process: the ignition handshake (a LOOP) at each bead's
    /// start, the arc-loss supervision around each bead, the end times.
    sup: Supervision,
    /// Line of a stray `IF NOT $IN[n] THEN` (reported, its body skipped).
    in_if: Option<usize>,
    arc_is_on: bool,
    /// The crater-fill wait with the arc on: seconds, line.
    crater: Option<(f64, usize)>,
    /// Line of the last arc off, until the statement after it.
    after_off: Option<usize>,
    /// `$LOAD.M` (kg) and its line, until its `$LOAD.CM`.
    mass: Option<(f64, usize)>,
    /// `$ORI_TYPE = #VAR`, `$CIRC_TYPE = #BASE` stated before a `CIRC`.
    circ_stated: [bool; 2],
    /// The wire feed's analog command (`$ANOUT[wire_feed_anout]`, −1 to
    /// 1) as last set, by a statement or a trigger at a move's start.
    anout: Option<f64>,
}

impl<'a> Decoder<'a> {
    fn new(
        program: &'a KrlProgram,
        cell: &'a CellLayout,
        opts: &'a KukaOptions,
        report: ValidationReport,
    ) -> Self {
        let (_, tool) = opts.frames(cell);
        let (on, off) = crate::program::kuka::switch_statements(opts);
        // An endless turn written modulo 360°: the controller takes the
        // shortest way from where the table is (home's turn before the first
        // motion).
        let modulo = crate::program::pose::turn_modulo(cell);
        let turn_at: f64 = opts
            .common
            .home(cell)
            .and_then(|h| h.positioner)
            .map_or(0.0, |q| q[1]);
        Self {
            program,
            cell,
            opts,
            tool,
            on,
            off,
            arc: opts.arc_process(),
            coordinated: opts.coordinated(cell),
            external_tcp: opts.uses_external_tcp(cell),
            modulo,
            steps: Vec::new(),
            report,
            vel: None,
            pending: Vec::new(),
            prev_q: None,
            turn_at,
            vel_extax: [100.0; 6],
            tool_stated: false,
            base_stated: false,
            first_motion: true,
            sup: Supervision::default(),
            in_if: None,
            arc_is_on: false,
            crater: None,
            after_off: None,
            mass: None,
            circ_stated: [false; 2],
            anout: None,
        }
    }

    /// The `.src` file's name.
    fn src(&self) -> &'a str {
        &self.program.src_file
    }

    /// An [`ProblemKind::Instruction`] problem at `line` of the `.src`.
    fn instruction(&mut self, line: usize, msg: String) {
        let src = self.src();
        push(&mut self.report, ProblemKind::Instruction, src, line, msg);
    }

    /// The burn-back wait is the statement right after the arc off: `true`
    /// when `st` is it (checked); an arc off without it is reported.
    fn burn_back_wait(&mut self, st: &KrlStatement) -> bool {
        let Some(l) = self.after_off.take() else {
            return false;
        };
        let src = self.src();
        if let KrlOp::WaitSec(s) = &st.op {
            check_time(
                &mut self.report,
                src,
                st.line,
                "burn-back",
                *s,
                self.opts.burn_back_s,
            );
            return true;
        }
        missing_burn_back(&mut self.report, src, l, self.opts);
        false
    }

    /// `true` when `st` is inside a stray `IF NOT $IN[n] THEN … ENDIF`
    /// (reported; a motion in it too).
    fn inside_stray_if(&mut self, st: &KrlStatement) -> bool {
        if self.in_if.is_none() {
            return false;
        }
        match &st.op {
            KrlOp::EndIf => self.in_if = None,
            KrlOp::Ptp(_) | KrlOp::Lin { .. } | KrlOp::Circ { .. } => {
                self.instruction(st.line, "motion inside `IF NOT $IN[n] THEN … ENDIF`".into())
            }
            _ => {}
        }
        true
    }

    /// `$VEL.CP`, `$VEL_EXTAX[n]`, `BAS (#VEL_PTP, n)` and `TRIGGER`: the
    /// speeds and switches of the motions after them.
    fn speed_or_trigger(&mut self, st: &KrlStatement) {
        let line = st.line;
        match &st.op {
            KrlOp::VelCp(v) => self.vel = Some(v * 1000.0),
            KrlOp::VelExtax { axis, percent } => {
                if let Some(slot) = (*axis as usize)
                    .checked_sub(1)
                    .and_then(|i| self.vel_extax.get_mut(i))
                {
                    *slot = *percent;
                }
            }
            KrlOp::VelPtp(p) => self.vel_extax = [*p; 6],
            KrlOp::Anout { channel, value } => {
                if *channel == self.opts.wire_feed_anout && self.arc {
                    self.anout = Some(*value);
                } else {
                    self.instruction(
                        line,
                        format!("`$ANOUT[{channel}] = {value}`: not the wire feed's command (the options give the arc process's $ANOUT[{}])", self.opts.wire_feed_anout),
                    );
                }
            }
            KrlOp::Trigger {
                distance,
                action,
                prio,
            } => {
                if crate::program::kuka::is_call(action) && prio.is_none() {
                    self.instruction(
                        line,
                        format!("TRIGGER calls the subprogram `{action}` without PRIO (KRL requires one, e.g. PRIO=-1)"),
                    );
                }
                if self.arc && same(action, &self.on) {
                    self.instruction(
                        line,
                        format!(
                            "the arc is switched on by a TRIGGER while moving: no ignition wait for $IN[{}] is possible",
                            self.opts.arc_ok_input
                        ),
                    );
                }
                self.pending.push((*distance, action.clone(), line));
            }
            _ => {}
        }
    }

    /// `$LOAD.M`, `$LOAD.CM` (a payload step), `$LOAD.J`, `WAIT SEC` (a
    /// wait step, or the crater fill with the arc on), `WAIT FOR $IN[n]`
    /// and the timer statements outside the ignition handshake.
    fn payload_or_wait(&mut self, st: &KrlStatement) {
        let line = st.line;
        let src = self.src();
        match &st.op {
            KrlOp::LoadMass(m) => self.mass = Some((*m, line)),
            KrlOp::LoadCm(c) => match self.mass.take() {
                Some((m, _)) => self.steps.push(DecodedStep::Payload {
                    file: src.to_string(),
                    line,
                    mass_kg: m,
                    cog_mm: crate::math::Point3::new(c[0], c[1], c[2]),
                }),
                None => self.instruction(line, "$LOAD.CM without a $LOAD.M before it".into()),
            },
            KrlOp::WaitSec(s) => {
                if self.arc_is_on {
                    self.crater = Some((*s, line));
                } else {
                    self.steps.push(DecodedStep::Wait {
                        file: src.to_string(),
                        line,
                        seconds: Some(*s),
                        input: None,
                    });
                }
            }
            // a wait for an input, with or without the ignition timer
            KrlOp::WaitIn(input) | KrlOp::WaitInOrTimer { input, .. } => {
                self.steps.push(DecodedStep::Wait {
                    file: src.to_string(),
                    line,
                    seconds: None,
                    input: Some(*input),
                })
            }
            // `$LOAD.J`, and outside the ignition handshake the timer
            // statements: plain statements
            _ => {}
        }
    }

    /// A stray `IF NOT $IN[n] THEN` (outside the ignition handshake): its
    /// body is skipped to the `ENDIF`.
    fn stray_if(&mut self, n: u32, line: usize) {
        let form = handshake_form(self.opts);
        self.instruction(
            line,
            format!(
                "`IF NOT $IN[{n}] THEN` outside the ignition handshake: after a HALT in it the start goes on without the arc ({form})"
            ),
        );
        self.in_if = Some(line);
    }

    /// The `LOOP` at `start` of `stmts`: a bead's ignition handshake (the
    /// arc on). The index of its `ENDLOOP`, `None` when there is none (the
    /// rest of the routine is not read).
    fn ignition_loop(&mut self, stmts: &[KrlStatement], start: usize) -> Option<usize> {
        let line = stmts[start].line;
        let Some(end) = loop_end(stmts, start) else {
            self.instruction(line, "LOOP without ENDLOOP".into());
            return None;
        };
        let block = &stmts[start..=end];
        let src = self.src();
        match read_handshake(block, self.opts, &self.on, &self.off, src, &mut self.report) {
            Some(h) if self.arc => {
                self.steps.push(DecodedStep::ProcessOn {
                    file: src.to_string(),
                    line: h.on_line,
                });
                self.arc_is_on = true;
                self.sup.bead_start(h.on_line, true);
                if self.anout.is_none() {
                    push(
                        &mut self.report,
                        ProblemKind::Feed,
                        src,
                        h.on_line,
                        format!(
                            "arc on without the wire feed's command: no `$ANOUT[{}] = ...` before it",
                            self.opts.wire_feed_anout
                        ),
                    );
                }
            }
            _ => {
                let form = handshake_form(self.opts);
                self.instruction(
                    line,
                    format!(
                        "a LOOP in the main routine that is not the ignition handshake ({form})"
                    ),
                )
            }
        }
        Some(end)
    }

    /// `INTERRUPT DECL` and `INTERRUPT action`: the arc-loss supervision.
    fn interrupt(&mut self, st: &KrlStatement) {
        if !self.arc {
            return;
        }
        let (line, opts, src) = (st.line, self.opts, self.src());
        match &st.op {
            KrlOp::InterruptDecl {
                prio,
                when,
                handler,
                ..
            } => self
                .sup
                .declare(*prio, when, handler, line, opts, src, &mut self.report),
            KrlOp::Interrupt { action, prio } => self.sup.control(
                *action,
                *prio,
                line,
                self.arc_is_on,
                opts,
                src,
                &mut self.report,
            ),
            _ => {}
        }
    }

    /// Any other statement: the process switched on or off (another is
    /// not read).
    fn switch(&mut self, text: &str, line: usize) {
        let src = self.src();
        if same(text, &self.on) {
            self.steps.push(DecodedStep::ProcessOn {
                file: src.to_string(),
                line,
            });
            self.arc_is_on = true;
            if self.arc {
                self.sup.bead_start(line, false);
                let form = handshake_form(self.opts);
                self.instruction(
                    line,
                    format!("arc on without the ignition handshake ({form})"),
                );
            }
        } else if same(text, &self.off) {
            self.steps.push(DecodedStep::ProcessOff {
                file: src.to_string(),
                line,
            });
            self.arc_is_on = false;
            if self.arc {
                self.sup.arc_off(line, src, &mut self.report);
                let (s, _) = self.crater.take().unwrap_or((0.0, line));
                check_time(
                    &mut self.report,
                    src,
                    line,
                    "crater fill",
                    s,
                    self.opts.crater_fill_s,
                );
                self.after_off = Some(line);
            }
        }
    }

    /// After the main routine: what is left open is reported, and the
    /// arc-loss handler checked. The steps and the report.
    fn finish(mut self) -> (Vec<DecodedStep>, ValidationReport) {
        let src = self.src();
        for (_, action, l) in std::mem::take(&mut self.pending) {
            self.instruction(l, format!("trigger `{action}` without a motion after it"));
        }
        if let Some(l) = self.after_off {
            missing_burn_back(&mut self.report, src, l, self.opts);
        }
        if let Some(l) = self.in_if {
            self.instruction(l, "IF without ENDIF".into());
        }
        if self.arc {
            self.sup.finish(
                self.program,
                self.opts,
                &self.on,
                &self.off,
                &mut self.report,
            );
        }
        (self.steps, self.report)
    }
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
    use crate::math::{Point3, UnitVector3, Vector3};
    use crate::program::kuka::read::parse_krl;
    use crate::program::kuka::{kuka_files, KukaOptions, HOME_NAME};
    use crate::program::validate::Motion;
    use crate::program::MoveKind;
    use crate::program::{build_program, BeadSetup, HomePosition, Payload, PointFeed};
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
                    bead: 0,
                    travel_speed_mm_s: 6.0,
                });
            }
        }
        let tr = joint_trajectory(&cell, &pts, &TrajectoryOptions::default()).unwrap();
        let prog = build_program(
            "HEMI",
            &cell,
            &pts,
            &tr,
            &PointFeed::constant(6.0, 80.0, pts.len()),
        )
        .unwrap();
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
                DecodedStep::Motion(m) => Some(m.as_ref()),
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
                DecodedStep::Motion(_) => None,
                DecodedStep::ProcessOn { .. } => Some("on".into()),
                DecodedStep::ProcessOff { .. } => Some("off".into()),
                DecodedStep::Wait { seconds, input, .. } => {
                    Some(format!("wait {seconds:?} {input:?}"))
                }
                DecodedStep::Payload {
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
        let pos = |pred: &dyn Fn(&DecodedStep) -> bool| steps.iter().position(pred).unwrap();
        let wait7 = pos(&|s| matches!(s, DecodedStep::Wait { input: Some(7), .. }));
        assert!(
            matches!(&steps[wait7 + 1], DecodedStep::Motion(m) if m.kind == MoveKind::Joint && m.label == "P11"),
            "{:?}",
            steps[wait7 + 1]
        );
    }
}
