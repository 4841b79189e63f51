//! The arc-loss supervision of a KUKA program as read: the interrupt
//! declared on the arc-established input, on for every motion with the arc
//! on and off before the arc off, and its handler (brake, arc off, never
//! back into the bead with the arc off; module doc of
//! [`crate::program::kuka`], "Arc supervision").

use super::handshake::{handshake_form, loop_end, read_handshake};
use super::same;
use crate::program::kuka::read::{falling_input, InterruptAction, KrlOp, KrlProgram, KrlRoutine};
use crate::program::kuka::{ArcLoss, KukaOptions, ARC_LOST_HANDLER};
use crate::program::validate::{push, ProblemKind, ValidationReport};

/// The arc-loss supervision of a program's main routine as read (module
/// doc of [`crate::program::kuka`], "Arc supervision").
#[derive(Debug, Default)]
pub(super) struct Supervision {
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
    pub(super) fn declare(
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
    pub(super) fn control(
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
    pub(super) fn bead_start(&mut self, line: usize, established: bool) {
        self.beads += 1;
        self.first_bead.get_or_insert(line);
        self.established = established;
        self.reported = false;
    }

    /// A motion (`what`, e.g. `LIN P3`) with the arc on: the interrupt must
    /// be on (reported once a bead).
    pub(super) fn motion(
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
    pub(super) fn arc_off(&mut self, line: usize, src: &str, report: &mut ValidationReport) {
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
    pub(super) fn finish(
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
