//! The ignition handshake of a KUKA program as read: the `LOOP` the
//! emitter writes at each bead's start (arc on, wait for the
//! arc-established input or the ignition timer, leave the loop only with
//! the arc, else arc off and `HALT`), checked against the options (module
//! doc of [`crate::program::kuka`]).

use super::same;
use crate::program::kuka::read::{KrlOp, KrlStatement};
use crate::program::kuka::KukaOptions;
use crate::program::validate::{push, ProblemKind, ValidationReport};

/// The expected ignition handshake, in messages.
pub(super) fn handshake_form(opts: &KukaOptions) -> String {
    let (n, t) = (opts.arc_ok_input, opts.ignition_timer);
    format!(
        "expected a LOOP: arc on, WAIT FOR $IN[{n}] OR $TIMER_FLAG[{t}] with a {:.3} s timeout, IF $IN[{n}] THEN EXIT ENDIF, arc off, HALT, ENDLOOP",
        opts.ignition_timeout_s
    )
}

/// Index of the `ENDLOOP` closing the `LOOP` at `start`.
pub(super) fn loop_end(stmts: &[KrlStatement], start: usize) -> Option<usize> {
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
pub(super) struct Handshake {
    /// Line of the arc on in it.
    pub(super) on_line: usize,
    /// Nothing missing: its problems, if any, were reported.
    pub(super) complete: bool,
}

/// Reads `block` (a `LOOP` to its `ENDLOOP`) as the ignition handshake the
/// emitter writes: arc on, `$TIMER[t]` set to minus the timeout and
/// started, `WAIT FOR $IN[n] OR $TIMER_FLAG[t]`, `IF $IN[n] THEN EXIT
/// ENDIF`, then the failed branch: arc off, message, `HALT`. `None` when
/// the loop switches no arc on (not a handshake). What is missing or
/// differs from `opts` is added to `report`.
pub(super) fn read_handshake(
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
