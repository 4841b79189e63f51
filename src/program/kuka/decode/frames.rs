//! The frame statements of a KUKA program as read: `$TOOL`, `$BASE` (a
//! fixed frame or math-coupled to the positioner, `EK`), `TOOL_DATA` and
//! `BASE_DATA` numbers, `$IPO_MODE`, and `$ORI_TYPE`/`$CIRC_TYPE` before a
//! `CIRC`, each against the frames the positions assume.

use std::ops::{Mul, Sub};

use super::Decoder;
use crate::math::Isometry3;
use crate::program::kuka::read::{KrlOp, KrlStatement};
use crate::program::kuka::StatedBase;
use crate::program::kuka::{CIRC_CIRC_TYPE, CIRC_ORI_TYPE};
use crate::program::validate::{push, ProblemKind};

impl Decoder<'_> {
    /// A [`ProblemKind::Frame`] problem at `line` of the `.src`.
    fn frame_problem(&mut self, line: usize, msg: String) {
        let src = self.src();
        push(&mut self.report, ProblemKind::Frame, src, line, msg)
    }

    /// A frame statement (`$ORI_TYPE`, `$CIRC_TYPE`, `$IPO_MODE`,
    /// `TOOL_DATA`/`BASE_DATA` numbers, `$TOOL`, `$BASE`) against the
    /// options.
    pub(super) fn frame_statement(&mut self, st: &KrlStatement) {
        let (line, opts, cell) = (st.line, self.opts, self.cell);
        match &st.op {
            KrlOp::OriType(v) | KrlOp::CircType(v) => {
                let (name, want) = match st.op {
                    KrlOp::OriType(_) => ("$ORI_TYPE", CIRC_ORI_TYPE),
                    _ => ("$CIRC_TYPE", CIRC_CIRC_TYPE),
                };
                if v == want {
                    self.circ_stated[usize::from(name == "$CIRC_TYPE")] = true;
                } else {
                    self.frame_problem(
                        line,
                        format!("{name} = {v}: the checker models {want} (orientation by slerp from start to end)"),
                    );
                }
            }
            KrlOp::IpoTcp(tcp) if *tcp != opts.uses_external_tcp(cell) => {
                self.frame_problem(
                    line,
                    format!(
                        "$IPO_MODE = {}, the options give {}",
                        if *tcp { "#TCP" } else { "#BASE" },
                        if *tcp { "#BASE" } else { "#TCP" }
                    ),
                );
            }
            KrlOp::Tool(n) | KrlOp::Base(n) => {
                let (what, want) = match st.op {
                    KrlOp::Tool(_) => ("TOOL_DATA", opts.tool),
                    _ => ("BASE_DATA", opts.base),
                };
                if *n != want {
                    self.frame_problem(line, format!("{what}[{n}], the options give {want}"));
                }
            }
            KrlOp::ToolFrame(f) => {
                self.tool_stated = true;
                if let Some(d) = frame_differs(f, &self.tool) {
                    self.frame_problem(
                        line,
                        format!(
                            "$TOOL = {} differs from the frame the positions assume, {} ({d})",
                            show(f),
                            crate::program::kuka::frame_literal(&self.tool)
                        ),
                    );
                }
            }
            KrlOp::BaseFrame(f) => {
                self.base_stated = true;
                match opts.stated_base(cell) {
                    StatedBase::Fixed(base) => {
                        if let Some(d) = frame_differs(f, &base) {
                            self.frame_problem(
                                line,
                                format!(
                                    "$BASE = {} differs from the frame the positions assume, {} ({d})",
                                    show(f),
                                    crate::program::kuka::frame_literal(&base)
                                ),
                            );
                        }
                    }
                    StatedBase::Coupled { machine, .. } => self.frame_problem(
                        line,
                        format!(
                            "$BASE is a fixed frame: the positioner is not math-coupled (expected $BASE = EK (MACHINE_DEF[{machine}].ROOT, …) for coordinated motion)"
                        ),
                    ),
                }
            }
            KrlOp::BaseEk { machine, offset } => {
                self.base_stated = true;
                match opts.stated_base(cell) {
                    StatedBase::Coupled {
                        machine: want,
                        offset: want_offset,
                    } => {
                        if *machine != want {
                            self.frame_problem(
                                line,
                                format!("$BASE = EK of MACHINE_DEF[{machine}], the options give {want}"),
                            );
                        }
                        if let Some(d) = frame_differs(offset, &want_offset) {
                            self.frame_problem(
                                line,
                                format!(
                                    "EK offset {} is not the part frame on the table {} ({d})",
                                    show(offset),
                                    crate::program::kuka::frame_literal(&want_offset)
                                ),
                            );
                        }
                    }
                    StatedBase::Fixed(_) => self.frame_problem(
                        line,
                        "$BASE = EK (math-coupled positioner), but the options give a fixed base (coordinated motion off, no positioner, or the fixed-tool mode)".into(),
                    ),
                }
            }
            _ => {}
        }
    }

    /// A `CIRC` at `line`: the controller's orientation and circle type
    /// must have been stated (reported once).
    pub(super) fn circ_types_stated(&mut self, line: usize) {
        if self.circ_stated != [true; 2] {
            self.frame_problem(
                line,
                format!("CIRC before the program states $ORI_TYPE = {CIRC_ORI_TYPE} and $CIRC_TYPE = {CIRC_CIRC_TYPE}: the controller's orientation on the circle would be its default, not the checked one"),
            );
            self.circ_stated = [true; 2];
        }
    }

    /// The first motion (at `line`): `$TOOL` and `$BASE` must have been
    /// stated before it.
    pub(super) fn frames_stated(&mut self, line: usize) {
        if !self.first_motion {
            return;
        }
        self.first_motion = false;
        if !self.tool_stated {
            self.frame_problem(
                line,
                format!(
                    "first motion before the program states $TOOL (expected $TOOL = {})",
                    crate::program::kuka::frame_literal(&self.tool)
                ),
            );
        }
        if !self.base_stated {
            let want = match self.opts.stated_base(self.cell) {
                StatedBase::Fixed(b) => crate::program::kuka::frame_literal(&b),
                StatedBase::Coupled { machine, .. } => {
                    format!(
                        "EK (MACHINE_DEF[{machine}].ROOT, …): the positioner is not math-coupled"
                    )
                }
            };
            self.frame_problem(
                line,
                format!("first motion before the program states $BASE (expected $BASE = {want})"),
            );
        }
    }
}

/// Largest difference between a stated frame and the expected one: 0.001
/// mm (the `.src` prints 4 decimals) and 0.0001° (5 decimals).
const FRAME_TOL_MM: f64 = 1e-3;
const FRAME_TOL_DEG: f64 = 1e-4;

/// `Some(how)` when the frame `[X, Y, Z, A, B, C]` (mm, deg) is not `want`.
pub(super) fn frame_differs(f: &[f64; 6], want: &Isometry3) -> Option<String> {
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

pub(super) fn show(f: &[f64; 6]) -> String {
    format!(
        "{{X {},Y {},Z {},A {},B {},C {}}}",
        f[0], f[1], f[2], f[3], f[4], f[5]
    )
}
