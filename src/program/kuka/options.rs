//! KUKA KRL options: [`KukaOptions`] (the `[program.kuka]` table), its
//! arc-loss behaviour and stated base, and their validation (interrupt
//! priorities, trigger actions). Stage 7 (controller programs); the
//! [vendor module](super) describes the format.

use serde::{Deserialize, Serialize};

use crate::math::Isometry3;
use crate::program::frames::ToolFrames;
use crate::program::PositionMode;
use crate::program::{ProcessControl, ProgramError};
use crate::robot::CellLayout;

/// Default [`KukaOptions::max_file_bytes`]: 2 MB, half of the lower end
/// of the 4–8 MB of programs in total that KR C4 users report
/// (robot-forum field reports; KUKA publishes no figure), leaving the rest
/// for the cell's own programs and the system's; far above RoboDK's KUKA
/// posts' 1 400 (KR C2) to 2 500 lines a program, which no KR C4 limit
/// requires.
pub const DEFAULT_MAX_FILE_BYTES: usize = 2_000_000;

/// Longest KRL name (`DEF`, `DEFDAT`, characters).
pub const KRL_NAME_MAX: usize = 24;

/// Options of the KUKA emitter. Plain data.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct KukaOptions {
    /// `E6AXIS` (joint) or `E6POS` (Cartesian) positions. Default joint.
    pub positions: PositionMode,
    /// Blending distance `$APO.CDIS` inside beads (mm, > 0). Default 0.5 mm.
    pub cdis_mm: f64,
    /// `BAS(#VEL_PTP, n)` of the moves to bead starts (%, 1–100). Default 10.
    pub ptp_percent: u8,
    /// Arc output or user-given statements. Default output 1.
    pub process: ProcessControl,
    /// `BASE_DATA[n]` (1–32). Default 1.
    pub base: u8,
    /// `TOOL_DATA[n]` (1–16). Default 1.
    pub tool: u8,
    /// `BASE_DATA[base]` in the robot base frame (mm). Default identity.
    pub base_from_user: Isometry3,
    /// `TOOL_DATA[tool]` on the flange (mm); `None`: the cell's torch, or
    /// with an external TCP the part (`flange_from_part`).
    pub flange_from_tool: Option<Isometry3>,
    /// Fixed-tool mode (`$IPO_MODE = #TCP`); `None`: in the part-carried
    /// cell only (module doc).
    pub external_tcp: Option<bool>,
    /// With an external TCP, `BASE_DATA[base]`: the fixed torch in the robot
    /// base frame (mm); `None`: at the cell's `D_R`, z down (towards the
    /// part), x along the robot's X.
    pub fixed_tool: Option<Isometry3>,
    /// Digital input `$IN[n]` on once the power source reports the arc
    /// established (arc process only): after switching the arc on at a
    /// bead's first point the program waits for it at most
    /// [`KukaOptions::ignition_timeout_s`], then stops with a message; in
    /// the bead its fall fires the arc-loss interrupt (module doc).
    /// Default 1 (our choice: the input paired with the default arc output
    /// `$OUT[1]`; the controller's I/O mapping decides).
    pub arc_ok_input: u32,
    /// Longest wait for the arc-established input (s, > 0, at most 60).
    /// Default 1 s: twice the 0.5 s start time `START_T` of the ArcTech
    /// start data that RoboDK's ArcTech post writes (module doc, sources);
    /// a CMT/GMAW arc ignites well within it.
    pub ignition_timeout_s: f64,
    /// `$TIMER[n]` used for that timeout (1–16, present on KR C2 and KR C4).
    /// Default 1.
    pub ignition_timer: u8,
    /// Crater fill (s, 0–60): at a bead's last point the robot stands still
    /// with the arc on this long before the arc is switched off (arc process
    /// only; 0: none). Default 0.2 s (our choice, a short GMAW/CMT crater
    /// time; set it from the weld schedule).
    pub crater_fill_s: f64,
    /// Burn-back (s, 0–60): after switching the arc off the robot waits
    /// this long at the last point, so that the wire burns back before the
    /// torch leaves (arc process only; 0: none). Default 0.1 s (our choice,
    /// as above).
    pub burn_back_s: f64,
    /// `MACHINE_DEF[n]` of the positioner (an external base kinematic) in
    /// the math-coupled base `$BASE = EK(...)` of a torch-carried cell
    /// (2–32; 1 is the robot). Default 2, the first external kinematic.
    pub ek_machine: u8,
    /// What the arc-loss handler does once the robot has stopped and the
    /// arc is off (arc process only; module doc, "Arc supervision"). Default
    /// [`ArcLoss::Abort`].
    pub arc_loss: ArcLoss,
    /// Priority of the arc-loss interrupt `INTERRUPT DECL p WHEN
    /// $IN[arc_ok_input]==FALSE DO …` (arc process only): a user priority,
    /// 1, 2, 4–39 or 81–128 (1 the highest; 3 and 40–80 are the system's).
    /// Default 20 (our choice, inside 4–39 and clear of ArcTech's 3).
    pub arc_loss_interrupt: u8,
    /// Analog output `$ANOUT[n]` commanding the power source's wire feed
    /// (arc process only; 1–32): each bead sets it before its arc on, and
    /// a `TRIGGER WHEN DISTANCE=0` at the start of each move whose wire
    /// feed differs (module doc, "Wire feed"). Default 1.
    pub wire_feed_anout: u8,
    /// The wire feed (mm/s, > 0) commanded by `$ANOUT[wire_feed_anout] =
    /// 1.0` (KRL's full scale, the power source's 10 V): `$ANOUT = wire
    /// feed / this`. Default 400 mm/s (24 m/min; our choice, a usual
    /// wire feeder's top speed: set it from the power source's analog
    /// interface, e.g. Fronius TPSi "Wire feed speed command value", 0–10 V
    /// over the feeder's range).
    pub wire_feed_full_scale_mm_s: f64,
    /// Most bytes of one program (its `.src` and `.dat` together) the
    /// controller is given at once. A build with more is cut between
    /// layers into groups, each a complete program the cell selects and
    /// runs in turn (`NAME_P01.src`/`.dat`, `NAME_P02.src`/`.dat`, …,
    /// [`split`](crate::program::split)); a layer that does not fit alone
    /// is refused. Default [`DEFAULT_MAX_FILE_BYTES`].
    pub max_file_bytes: usize,
    /// The vendor-independent options (home, dwell, interpass wait,
    /// payload, transit, coordination) the validator checks the file
    /// against; not a key of `[program.<vendor>]` (set from `[program]` by
    /// [`crate::program::ProgramSettings`]).
    #[serde(skip)]
    pub common: crate::program::ProgramOptions,
}

impl Default for KukaOptions {
    fn default() -> Self {
        Self {
            positions: PositionMode::Joint,
            cdis_mm: 0.5,
            ptp_percent: 10,
            process: ProcessControl::default(),
            base: 1,
            tool: 1,
            base_from_user: Isometry3::identity(),
            flange_from_tool: None,
            external_tcp: None,
            fixed_tool: None,
            arc_ok_input: 1,
            ignition_timeout_s: 1.0,
            ignition_timer: 1,
            crater_fill_s: 0.2,
            burn_back_s: 0.1,
            ek_machine: 2,
            arc_loss: ArcLoss::Abort,
            arc_loss_interrupt: 20,
            wire_feed_anout: 1,
            wire_feed_full_scale_mm_s: 400.0,
            max_file_bytes: DEFAULT_MAX_FILE_BYTES,
            common: Default::default(),
        }
    }
}

impl KukaOptions {
    /// `true` when `$IPO_MODE = #TCP` is written for `cell`.
    pub fn uses_external_tcp(&self, cell: &CellLayout) -> bool {
        self.external_tcp
            .unwrap_or(matches!(cell, CellLayout::PartCarried(_)))
    }

    /// `($BASE, $TOOL)` in `cell` (robot base frame, flange frame; mm): the
    /// frames Cartesian positions are written in, `$BASE · pos = flange ·
    /// $TOOL`.
    pub fn frames(&self, cell: &CellLayout) -> (Isometry3, Isometry3) {
        match ToolFrames::new(
            cell,
            self.uses_external_tcp(cell),
            self.flange_from_tool,
            self.fixed_tool,
            self.base_from_user,
        ) {
            ToolFrames::Held {
                flange_from_tool,
                base_from_work,
            } => (base_from_work, flange_from_tool),
            ToolFrames::Stationary {
                base_from_tool,
                flange_from_work,
            } => (base_from_tool, flange_from_work),
        }
    }

    /// `true` when the positioner is math-coupled to the base (`$BASE =
    /// EK(...)`): a torch-carried cell outside the fixed-tool mode with
    /// [`crate::program::ProgramOptions::coordinated`] on (module doc).
    pub fn coordinated(&self, cell: &CellLayout) -> bool {
        self.common.coordinated
            && matches!(cell, CellLayout::TorchCarried(_))
            && !self.uses_external_tcp(cell)
    }

    /// The `$BASE` a program states for `cell` (module doc, "Frames").
    pub fn stated_base(&self, cell: &CellLayout) -> StatedBase {
        match cell {
            CellLayout::TorchCarried(c) if self.coordinated(cell) => StatedBase::Coupled {
                machine: self.ek_machine,
                offset: c.table_from_part,
            },
            _ => StatedBase::Fixed(self.frames(cell).0),
        }
    }

    /// The base frame (robot base frame, mm) Cartesian positions are
    /// written in at positioner joints `positioner` (rad): with a coupled
    /// base the part frame on the positioner there, else
    /// [`KukaOptions::frames`]' base.
    pub fn base_at(&self, cell: &CellLayout, positioner: Option<[f64; 2]>) -> Isometry3 {
        match (cell, positioner) {
            (CellLayout::TorchCarried(c), Some(q)) if self.coordinated(cell) => {
                c.base_from_part(&q)
            }
            _ => self.frames(cell).0,
        }
    }

    /// `true` when the bead is switched by the arc output with the ignition
    /// handshake and end times (process [`ProcessControl::Arc`]).
    pub fn arc_process(&self) -> bool {
        matches!(self.process, ProcessControl::Arc { .. })
    }

    /// Checks every field.
    ///
    /// # Errors
    /// [`ProgramError::InvalidOptions`] naming the field.
    pub fn validate(&self) -> Result<(), ProgramError> {
        let bad = |field, value: String, reason| ProgramError::InvalidOptions {
            field,
            value,
            reason,
        };
        if self.max_file_bytes == 0 {
            return Err(bad("max_file_bytes", "0".into(), "must be >= 1"));
        }
        if !(self.cdis_mm.is_finite() && self.cdis_mm > 0.0) {
            return Err(bad(
                "cdis_mm",
                self.cdis_mm.to_string(),
                "must be finite and > 0",
            ));
        }
        if !(1..=100).contains(&self.ptp_percent) {
            return Err(bad(
                "ptp_percent",
                self.ptp_percent.to_string(),
                "must be in 1..=100",
            ));
        }
        if !(1..=32).contains(&self.base) {
            return Err(bad("base", self.base.to_string(), "must be in 1..=32"));
        }
        if !(1..=16).contains(&self.tool) {
            return Err(bad("tool", self.tool.to_string(), "must be in 1..=16"));
        }
        if self.arc_ok_input == 0 {
            return Err(bad("arc_ok_input", "0".into(), "must be >= 1"));
        }
        for (field, v, min_exclusive) in [
            ("ignition_timeout_s", self.ignition_timeout_s, true),
            ("crater_fill_s", self.crater_fill_s, false),
            ("burn_back_s", self.burn_back_s, false),
        ] {
            let ok = v.is_finite() && v <= 60.0 && if min_exclusive { v > 0.0 } else { v >= 0.0 };
            if !ok {
                return Err(bad(
                    field,
                    v.to_string(),
                    if min_exclusive {
                        "must be > 0 and <= 60 s"
                    } else {
                        "must be between 0 and 60 s"
                    },
                ));
            }
        }
        if !(1..=16).contains(&self.ignition_timer) {
            return Err(bad(
                "ignition_timer",
                self.ignition_timer.to_string(),
                "must be in 1..=16",
            ));
        }
        if !is_user_interrupt(self.arc_loss_interrupt) {
            return Err(bad(
                "arc_loss_interrupt",
                self.arc_loss_interrupt.to_string(),
                "KRL user interrupt priorities are 1, 2, 4..=39 and 81..=128 (3 and 40..=80 are reserved for the system)",
            ));
        }
        if !(1..=32).contains(&self.wire_feed_anout) {
            return Err(bad(
                "wire_feed_anout",
                self.wire_feed_anout.to_string(),
                "must be in 1..=32 ($ANOUT[1..32])",
            ));
        }
        if !(self.wire_feed_full_scale_mm_s.is_finite() && self.wire_feed_full_scale_mm_s > 0.0) {
            return Err(bad(
                "wire_feed_full_scale_mm_s",
                self.wire_feed_full_scale_mm_s.to_string(),
                "must be finite and > 0",
            ));
        }
        if !(2..=32).contains(&self.ek_machine) {
            return Err(bad(
                "ek_machine",
                self.ek_machine.to_string(),
                "must be in 2..=32 (MACHINE_DEF[1] is the robot)",
            ));
        }
        self.common.validate()?;
        self.process.validate()?;
        if let ProcessControl::Custom { start, end } = &self.process {
            for (field, line) in [("process.start", start), ("process.end", end)] {
                if !is_trigger_action(line) {
                    return Err(bad(
                        field,
                        line.clone(),
                        "a KRL `TRIGGER ... DO` takes only an assignment `NAME=value` or a subprogram call `NAME(...)` (e.g. `$OUT[3]=TRUE`, `ARC_ON()`); put other statements in a subprogram",
                    ));
                }
            }
        }
        Ok(())
    }
}

/// What the arc-loss handler does after `BRAKE F` and arc off (module doc,
/// "Arc supervision"): in either case the bead never continues with the arc
/// off.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ArcLoss {
    /// A message, then `HALT` in an endless `LOOP`: the start never leaves
    /// the handler, the program must be cancelled (the bead and its layer
    /// are incomplete; the operator decides how to go on).
    #[default]
    Abort,
    /// A message and `HALT`; the start then re-runs the ignition handshake
    /// where the robot stopped (arc on, wait for the arc-established input
    /// with the timeout, arc off, message and `HALT` again without it) and
    /// only with the arc established re-arms the interrupt and returns: the
    /// bead continues from there.
    Reignite,
}

/// `true` for a priority KRL leaves to user interrupts: 1, 2, 4–39 and
/// 81–128 (3 and 40–80 are reserved for system applications; KUKA College
/// training material, vendor notes §1).
pub fn is_user_interrupt(prio: u8) -> bool {
    matches!(prio, 1 | 2 | 4..=39 | 81..=128)
}

/// The `$BASE` a program states (module doc, "Frames").
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum StatedBase {
    /// `$BASE = {X …, A …}`: a fixed frame in the robot base frame (mm).
    Fixed(Isometry3),
    /// `$BASE = EK (MACHINE_DEF[machine].ROOT, MACHINE_DEF[machine].MECH_TYPE,
    /// {offset})`: the base moves with the positioner; `offset` is the part
    /// frame in the positioner's flange (table) frame (mm).
    Coupled {
        /// `MACHINE_DEF` index of the positioner.
        machine: u8,
        /// The part frame on the table (mm).
        offset: Isometry3,
    },
}

/// `true` when `s` is a subprogram call `NAME(...)` (which a KRL `TRIGGER`
/// must give a priority: `PRIO=-1`).
pub fn is_call(s: &str) -> bool {
    let s = s.trim();
    let name_len = s
        .find(|c: char| !(c.is_ascii_alphanumeric() || c == '_' || c == '$'))
        .unwrap_or(s.len());
    name_len > 0 && s[name_len..].trim_start().starts_with('(') && s.ends_with(')')
}

/// `true` when `s` is a statement a KRL `TRIGGER WHEN ... DO` accepts: an
/// assignment `NAME=value` (`NAME` a variable, optionally indexed `[...]`
/// or with `.FIELD`s: `$OUT[1]=TRUE`, `$ANOUT[2]=0.5`, `FLAG.ON=TRUE`) or a
/// subprogram call `NAME(...)`. Anything else (`WAIT FOR ...`, `IF ...`,
/// `PULSE(...)` is a call and accepted) would not compile after `DO`.
pub fn is_trigger_action(s: &str) -> bool {
    let s = s.trim();
    let ident_len = |t: &str| {
        let mut n = 0;
        for (i, c) in t.char_indices() {
            let ok = if i == 0 {
                c.is_ascii_alphabetic() || c == '$' || c == '_'
            } else {
                c.is_ascii_alphanumeric() || c == '$' || c == '_'
            };
            if !ok {
                break;
            }
            n = i + c.len_utf8();
        }
        n
    };
    let n = ident_len(s);
    if n == 0 {
        return false;
    }
    let rest = s[n..].trim_start();
    // a call: NAME ( ... )
    if rest.starts_with('(') {
        return rest.ends_with(')');
    }
    // an assignment: a variable path, then `=` (not `==`), then a value
    let mut t = &s[n..];
    loop {
        if let Some(r) = t.strip_prefix('[') {
            match r.find(']') {
                Some(k) if k > 0 => t = &r[k + 1..],
                _ => return false,
            }
        } else if let Some(r) = t.strip_prefix('.') {
            let m = ident_len(r);
            if m == 0 {
                return false;
            }
            t = &r[m..];
        } else {
            break;
        }
    }
    match t.trim_start().strip_prefix('=') {
        Some(v) => !v.starts_with('=') && !v.trim().is_empty(),
        None => false,
    }
}
