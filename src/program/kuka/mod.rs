//! KUKA KRL programs: `.src` (motions) and `.dat` (positions) [SPEC §8].
//!
//! * Positions as `E6AXIS` (A1..A6 in degrees, KUKA convention of the
//!   robot model) or `E6POS` (`X Y Z A B C`, mm and deg, `$TOOL` in `$BASE`)
//!   with the Status `S` and Turn `T` bits derived from the chosen joints;
//!   the torch-carried cell's positioner as external axes `E1 E2` (deg).
//!   With joint positions ([`PositionMode::Joint`]) only the `PTP` targets
//!   are `E6AXIS`: `LIN` targets (bead points, the move into a bead, the
//!   retract point) are always `E6POS` with S and T, the Cartesian target
//!   form of a `LIN` (an axis-specific `LIN` target is not the form KUKA's
//!   inline forms write, and may be refused).
//! * Each bead: `PTP` to its first point (exact stop), then `LIN` moves at
//!   `$VEL.CP` (m/s) blended with `C_DIS` inside the bead, the last one
//!   exact.
//! * **Arc process** (`$OUT[schedule]`): the arc is switched on at the
//!   bead's first point, where the robot stands (exact stop), inside the
//!   ignition handshake, a `LOOP` left only with the arc established: arc
//!   on, `$TIMER[t]` set to minus the timeout (ms) and started, `WAIT FOR
//!   $IN[arc_ok] OR $TIMER_FLAG[t]` (KRL's `WAIT FOR` has no timeout; the
//!   flag turns on when the timer reaches 0), `IF $IN[arc_ok] THEN EXIT
//!   ENDIF`; else arc off, a message (`Set_KrlMsg(#QUIT, …)`, KSS 8) and
//!   `HALT`, and the operator's start tries again: the bead never starts
//!   without the arc (before issue 32 the start after that `HALT` ran the
//!   bead with the arc off). At the bead's last point (exact): `WAIT SEC
//!   crater` with the arc on, arc off, `WAIT SEC burn-back`
//!   ([`KukaOptions::arc_ok_input`], [`KukaOptions::ignition_timeout_s`],
//!   [`KukaOptions::crater_fill_s`], [`KukaOptions::burn_back_s`]).
//! * **Arc supervision** (arc process only: a custom process switches a
//!   device through lines we cannot interpret and has no input to watch,
//!   so it gets none). An arc lost during a bead stops the robot and
//!   switches the arc off, and the bead never goes on without the arc:
//!   - `INTERRUPT DECL p WHEN $IN[arc_ok]==FALSE DO WAAM_ARC_LOST( )` once
//!     in the main routine, before the first bead (`p` =
//!     [`KukaOptions::arc_loss_interrupt`], a user priority: 1, 2, 4–39 or
//!     81–128, default 20; 3 and 40–80 are the system's).
//!   - `INTERRUPT ON p` right after each bead's handshake: a KRL interrupt
//!     fires when its condition *becomes* true (an edge), so it is armed
//!     with the arc established and fires on its loss. `INTERRUPT OFF p`
//!     just before the arc off at the bead's end, after the crater wait; a
//!     crater time of 0 is written `WAIT SEC 0.000`, an advance-run stop,
//!     so that the `INTERRUPT OFF` never runs in the advance run while the
//!     bead's last motions still do (whether `INTERRUPT ON/OFF` stop the
//!     advance run themselves was not confirmed). The crater fill is thus
//!     supervised too.
//!   - The handler [`ARC_LOST_HANDLER`], a local `DEF` after the main
//!     routine's `END`: `INTERRUPT OFF p`, `BRAKE F` (stop on the path as
//!     fast as possible), arc off and burn-back as at a bead's end, a
//!     message, then per [`KukaOptions::arc_loss`]: *abort* (default)
//!     `LOOP HALT ENDLOOP`, the start never leaves it and the program must
//!     be cancelled; *reignite* `HALT`, then where the robot stopped the
//!     ignition handshake and `INTERRUPT ON p`, after which the interrupted
//!     motion goes on with the arc. (Jogging the robot during that `HALT`
//!     would move the re-ignition off the path: the handler runs before
//!     the controller returns to the path; inferred, not checked.)
//!   - No `RESUME`: it abandons the rest of the interrupted subprogram and
//!     goes on after its call, which here would skip the rest of the bead
//!     (a partial layer, then the next bead), the very failure supervised;
//!     it would also need each bead in a subprogram one level below the
//!     declaring routine and the advance run stopped there. Without it the
//!     beads stay in the main routine, where the interrupt is declared.
//! * **Custom process**: the user's statements, switched by `TRIGGER WHEN
//!   DISTANCE=0` before the first `LIN` (fires at the exact first point)
//!   and `TRIGGER WHEN DISTANCE=1` before the last `LIN` (fires at its
//!   exact end point), so blending never moves a switching point; a
//!   `TRIGGER ... DO` accepts only an assignment or a subprogram call
//!   ([`is_trigger_action`]; others are refused by
//!   [`KukaOptions::validate`]), and a call gets `PRIO=-1`
//!   ([`trigger_line`]).
//! * **Frames stated**: after `BAS (#TOOL,n)`/`BAS (#BASE,n)` (numbers and
//!   load) the program assigns `$TOOL = {X …,A …}` and `$BASE = {…}`, the
//!   frames its positions assume ([`KukaOptions::frames`]): the torch
//!   (its z axis along the torch, from the wire tip into it: not KUKA's
//!   +X tool direction, so a torch measured on the controller is another
//!   frame) over the user base, or in the fixed-tool mode the part on the
//!   flange and the fixed torch.
//! * **Coordinated positioner** (torch-carried cell,
//!   [`crate::program::ProgramOptions::coordinated`], default on): `$BASE =
//!   EK (MACHINE_DEF[m].ROOT, MACHINE_DEF[m].MECH_TYPE, {table_from_part})`
//!   math-couples the base to the positioner (E1, E2), so `E6POS`
//!   positions are the part frame at each point's E1, E2 and `$VEL.CP` is
//!   the TCP's speed relative to the moving base: the planned travel speed
//!   over the part, also where the positioner turns ([`KukaOptions::coordinated`]).
//!   Assumes the controller's positioner kinematic is the cell's (root at
//!   the positioner pose, flange = table frame at E1 = E2 = 0).
//! * **Home and bead set-up**: `PTP PHOME` (an `E6AXIS` of the home joints
//!   and positioner) first and last; before each bead's first motion its
//!   payload (`$LOAD.M` kg, `$LOAD.CM` mm in the flange frame, `$LOAD.J`
//!   of a point mass), dwell (`WAIT SEC`) and interpass wait (`WAIT FOR
//!   $IN[n]`).
//! * **Memory budget** ([`KukaOptions::max_file_bytes`], default 2 MB for
//!   the `.src` and `.dat` together): a larger build is cut between layers
//!   into several complete programs, `NAME_P01.src`/`.dat`,
//!   `NAME_P02.src`/`.dat`, … (each from home to home, with its own
//!   declarations, interrupt and set-up), which the cell selects and runs
//!   in turn ([`split`](crate::program::split)).
//! * **Part-carried cell: external TCP.** `$VEL.CP` is the speed of the TCP;
//!   the planned speed is the torch's relative to the part. In the
//!   part-carried cell the emitter switches to KUKA's fixed-tool mode,
//!   `$IPO_MODE = #TCP`, with `$TOOL` = the part on the flange
//!   (`TOOL_DATA[tool]`, the cell's `flange_from_part`) and `$BASE` = the
//!   fixed torch (`BASE_DATA[base]`, at `D_R` with z pointing down at the
//!   part unless given): the controller then moves the part so that the
//!   fixed torch travels over it at `$VEL.CP`, and `E6POS` positions are the
//!   part frame in the torch frame ([`KukaOptions::external_tcp`]).
//!
//! * **Torch-carried cell, positioner turning, not coordinated.** `$VEL.CP` is the TCP's
//!   speed in the robot frame; where the positioner turns within a bead the
//!   part moves under a nearly still torch, and the planned speed (over the
//!   part) is not the TCP's. KRL's `LIN` has no time argument: such a `LIN`
//!   gets `$VEL.CP` = the TCP's travel / the planned segment time and
//!   `$VEL_EXTAX[n]` = the positioner axis's turn / that time, in % of its
//!   maximum speed ([`timed_segment`]), so that the TCP and each external
//!   axis take the planned time; the next `PTP` re-issues `BAS
//!   (#VEL_PTP,n)`. **Assumptions, not checked on a controller:** the
//!   positioner's axes are non-integrated external axes moved with the path
//!   (the `LIN` taking the longest of the TCP's and the axes' times),
//!   `BAS (#VEL_PTP,n)` also sets `$VEL_EXTAX`, and the orientation speed
//!   (`$VEL.ORI1/2`) does not bind; a `$VEL.CP` under 0.001 mm/s (a still
//!   TCP) is written as 0.001 mm/s. The validator uses the same model.
//!
//! Status bits (KUKA): bit 0 wrist centre behind the A1 axis (x < 0 in the
//! A1 frame: overhead area), bit 1 `A3 >= phi`, `phi` the A3 angle of the
//! stretched elbow (a joint test: the same for the wrist centre in front of
//! or behind A1; set in the usual elbow-up posture, `S 2`), bit 2 A5 in
//! `[-180°, 0°)` (strictly negative; clear at `A5 = 0`). Turn bit `i` set
//! when `A(i+1) < 0`. Source of these definitions: the KUKA expert
//! programming manual's Status table as quoted on robot-forum.com (not
//! checked against the manual itself).

pub mod decode;
pub mod read;

pub use decode::validate_kuka;
pub use read::parse_krl;

use crate::program::contract::{read_file, Controller};
use crate::program::cycle::CycleOptions;
use crate::program::split::{split_to_budget, Budget};
use crate::program::validate::{DecodedStep, ValidationReport};
use crate::program::ProgramOptions;
use std::path::Path;

use std::io::Write;

use serde::{Deserialize, Serialize};

use crate::math::Isometry3;
use crate::program::fmt::{ascii_comment, floor_to, Deg, Fixed, Mm};
pub use crate::program::frames::fixed_torch_at;
use crate::program::frames::{held_tool, ToolFrames};
use crate::program::PositionMode;
use crate::program::{
    check_name, check_vendor, joint_move_target, move_start, positioner_moves, render,
    segment_length_mm, ArcFlag, BeadSetup, EmittedFile, ProcessControl, Program, ProgramError,
};
use crate::robot::orientation::KukaAbc;
use crate::robot::{ArmSide, CellLayout, Joints, RobotModel, Vendor};

/// The emitter's name in [`ProgramError::VendorMismatch`].
pub const EMITTER: &str = "KUKA KRL";

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

/// Name of the arc-loss interrupt routine, a local `DEF` after the main
/// routine's `END` in the `.src`.
pub const ARC_LOST_HANDLER: &str = "WAAM_ARC_LOST";

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

/// A KRL `FRAME` aggregate `{X …,Y …,Z …,A …,B …,C …}` of `f` (mm, deg).
pub fn frame_literal(f: &Isometry3) -> String {
    let t = f.translation.vector;
    let abc = KukaAbc::from_rotation(&f.rotation.to_rotation_matrix()).to_degrees();
    format!(
        "{{X {},Y {},Z {},A {},B {},C {}}}",
        Mm(t.x),
        Mm(t.y),
        Mm(t.z),
        Deg(abc[0]),
        Deg(abc[1]),
        Deg(abc[2])
    )
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

/// `TRIGGER WHEN DISTANCE=d DELAY=0 DO action`, with ` PRIO=-1` when the
/// action is a subprogram call (KRL requires a priority there; `-1` lets
/// the controller choose a free one).
pub fn trigger_line(distance: u8, action: &str) -> String {
    let prio = if is_call(action) { " PRIO=-1" } else { "" };
    format!("TRIGGER WHEN DISTANCE={distance} DELAY=0 DO {action}{prio}")
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

/// KUKA Status bits of joints `q` (A1..A6, KUKA convention, rad) (module
/// doc).
pub fn status(robot: &RobotModel, q: &Joints) -> u8 {
    let c = robot.configuration_of(q);
    let back = c.side == ArmSide::Back;
    let a5_negative = crate::program::fmt::as_printed_rad(q[4]) < 0.0;
    (back as u8)
        | ((crate::robot::controller::elbow_positive_cos(&c) as u8) << 1)
        | ((a5_negative as u8) << 2)
}

/// KUKA Turn bits of joints `q`: bit `i` set when `A(i+1) < 0`.
pub fn turn(q: &Joints) -> u8 {
    q.iter().enumerate().fold(0, |t, (i, v)| {
        t | (((crate::program::fmt::as_printed_rad(*v) < 0.0) as u8) << i)
    })
}

pub(crate) fn switch_statements(opts: &KukaOptions) -> (String, String) {
    match &opts.process {
        ProcessControl::Arc { schedule } => (
            format!("$OUT[{schedule}]=TRUE"),
            format!("$OUT[{schedule}]=FALSE"),
        ),
        ProcessControl::Custom { start, end } => (start.clone(), end.clone()),
    }
}

/// The speeds of a timed `LIN` (module doc, "Torch-carried cell,
/// positioner turning").
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TimedSegment {
    /// The segment's planned time (s): its length over the part (part frame)
    /// / the planned speed.
    pub time_s: f64,
    /// `$VEL.CP` (mm/s; written in m/s) making the TCP's travel in the robot
    /// base frame take `time_s` (at least 0.001 mm/s).
    pub vel_cp_mm_s: f64,
    /// `$VEL_EXTAX[1]`, `$VEL_EXTAX[2]` (% of the positioner axes' maximum
    /// speeds, at most 100) making each axis's turn take `time_s`; `None`
    /// for an axis that does not move or has no finite maximum speed.
    pub vel_extax_percent: [Option<f64>; 2],
}

/// The speeds of the `LIN` into point `i` when it must be timed: in a
/// torch-carried cell outside the fixed-tool mode, where the positioner
/// moves ([`positioner_moves`]); `None` elsewhere (the planned speed is the
/// TCP's: `$VEL.CP` = the planned speed).
pub fn timed_segment(program: &Program, opts: &KukaOptions, i: usize) -> Option<TimedSegment> {
    let CellLayout::TorchCarried(c) = &program.cell else {
        return None;
    };
    if opts.uses_external_tcp(&program.cell)
        || opts.coordinated(&program.cell)
        || !positioner_moves(program, i)
    {
        return None;
    }
    let start = move_start(program, i)?;
    let (p, a) = (&program.points[i], &program.points[start]);
    let time_s = segment_length_mm(program, i) / p.speed_mm_s;
    let robot = &c.robot;
    let tool = held_tool(&program.cell, opts.flange_from_tool);
    let tcp =
        |q: &Joints| crate::math::Point3::from((robot.flange_pose(q) * tool).translation.vector);
    // a circular move's TCP runs on the arc through its via
    let tcp_mm = if start + 2 == i {
        let via = &program.points[i - 1].joints;
        crate::program::compress::arc_length(&tcp(&a.joints), &tcp(via), &tcp(&p.joints))
    } else {
        (tcp(&p.joints) - tcp(&a.joints)).norm()
    };
    let (qp, qa) = (p.positioner?, a.positioner?);
    let vel_extax_percent = std::array::from_fn(|n| {
        let max = c.positioner.max_speed_rad_s[n];
        let turn = (qp[n] - qa[n]).abs();
        (max.is_finite() && turn > 0.0).then(|| (100.0 * turn / time_s / max).clamp(1e-4, 100.0))
    });
    Some(TimedSegment {
        time_s,
        vel_cp_mm_s: (tcp_mm / time_s).max(1e-3),
        vel_extax_percent,
    })
}

/// `$ORI_TYPE` written before the first `CIRC`: the orientation changes
/// continuously from the start to the end orientation (KUKA system
/// software, "Orientation control"), the slerp of
/// [`interpolate`](crate::program::compress::interpolate).
pub const CIRC_ORI_TYPE: &str = "#VAR";
/// `$CIRC_TYPE` written before the first `CIRC`: orientation control
/// relative to the base (`#PATH` would turn it with the circle's tangent),
/// the auxiliary point's orientation ignored.
pub const CIRC_CIRC_TYPE: &str = "#BASE";

/// Name of the home position in the `.dat` (an `E6AXIS`).
pub const HOME_NAME: &str = "PHOME";

/// Writes the `.src` of `program`.
///
/// # Errors
/// I/O errors of `w`; an error of kind `Other` wrapping
/// [`ProgramError::VendorMismatch`] when the cell's robot is not a KUKA arm.
pub fn write_src(w: &mut dyn Write, program: &Program, opts: &KukaOptions) -> std::io::Result<()> {
    check_vendor(&program.cell, Vendor::Kuka, EMITTER).map_err(std::io::Error::other)?;
    let (on, off) = switch_statements(opts);
    let arc = opts.arc_process();
    writeln!(w, "&ACCESS RVP")?;
    writeln!(w, "&REL 1")?;
    writeln!(w, "DEF {}( )", program.name)?;
    writeln!(
        w,
        "  ; waam-slicer: {}, {} points, {} beads",
        ascii_comment(program.cell.name()),
        program.points.len(),
        program.num_beads()
    )?;
    if arc {
        // the message of a failed ignition (KSS 8 Set_KrlMsg)
        write_message_decls(w)?;
    }
    writeln!(w, "  ;FOLD INI")?;
    writeln!(
        w,
        "  GLOBAL INTERRUPT DECL 3 WHEN $STOPMESS==TRUE DO IR_STOPM ( )"
    )?;
    writeln!(w, "  INTERRUPT ON 3")?;
    writeln!(w, "  BAS (#INITMOV,0 )")?;
    writeln!(w, "  ;ENDFOLD")?;
    writeln!(w, "  $BWDSTART = FALSE")?;
    // BAS sets $TOOL and $LOAD (TOOL_DATA[n], LOAD_DATA[n]), and $BASE;
    // the frames the positions assume are then stated explicitly
    writeln!(w, "  BAS (#TOOL,{})", opts.tool)?;
    writeln!(w, "  BAS (#BASE,{})", opts.base)?;
    let (_, tool) = opts.frames(&program.cell);
    if opts.uses_external_tcp(&program.cell) {
        writeln!(
            w,
            "  ; external TCP: the tool is the part on the flange, the base the fixed torch (z towards the part)"
        )?;
    } else if matches!(program.cell, CellLayout::TorchCarried(_)) && opts.flange_from_tool.is_none()
    {
        writeln!(
            w,
            "  ; the tool is the torch, +Z along the wire out of the torch (set $TOOL_DIRECTION = #Z for tool-frame weaving and jogging)"
        )?;
    }
    writeln!(w, "  $TOOL = {}", frame_literal(&tool))?;
    match opts.stated_base(&program.cell) {
        StatedBase::Fixed(base) => writeln!(w, "  $BASE = {}", frame_literal(&base))?,
        StatedBase::Coupled { machine, offset } => {
            writeln!(
                w,
                "  ; positioner math-coupled: the base is the part on the positioner, $VEL.CP the speed over it"
            )?;
            writeln!(
                w,
                "  $BASE = EK (MACHINE_DEF[{machine}].ROOT, MACHINE_DEF[{machine}].MECH_TYPE, {})",
                frame_literal(&offset)
            )?;
        }
    }
    if opts.uses_external_tcp(&program.cell) {
        writeln!(w, "  $IPO_MODE = #TCP")?;
    } else {
        writeln!(w, "  $IPO_MODE = #BASE")?;
    }
    if program.points.iter().any(|p| p.via) {
        // the orientation on a circle: from start to end, the auxiliary
        // point's ignored, relative to the base (the checker's model)
        writeln!(w, "  $ORI_TYPE = {CIRC_ORI_TYPE}")?;
        writeln!(w, "  $CIRC_TYPE = {CIRC_CIRC_TYPE}")?;
    }
    writeln!(w, "  $APO.CDIS = {}", Mm(opts.cdis_mm))?;
    writeln!(w, "  BAS (#VEL_PTP,{} )", opts.ptp_percent)?;
    if arc {
        writeln!(
            w,
            "  ; arc-loss supervision: interrupt {} fires when IN {} (arc established) goes off; on only in the beads",
            opts.arc_loss_interrupt, opts.arc_ok_input
        )?;
        writeln!(
            w,
            "  INTERRUPT DECL {} WHEN $IN[{}]==FALSE DO {ARC_LOST_HANDLER}( )",
            opts.arc_loss_interrupt, opts.arc_ok_input
        )?;
    }
    // external-axis speeds (%) written since the last PTP speed setting
    let mut extax: [Option<f64>; 2] = [None; 2];
    // before a PTP after timed moves: the PTP speeds again (BAS sets the
    // external axes' speeds too)
    let restore_ptp = |w: &mut dyn Write, extax: &mut [Option<f64>; 2]| -> std::io::Result<()> {
        if extax.iter().any(Option::is_some) {
            writeln!(w, "  BAS (#VEL_PTP,{} )", opts.ptp_percent)?;
            *extax = [None; 2];
        }
        Ok(())
    };
    let mut vel: Option<f64> = None;
    let mut set_vel = |w: &mut dyn Write, mm_s: f64| -> std::io::Result<()> {
        // m/s, rounded down to the written 6 decimals: never faster than
        // planned
        let v = floor_to(mm_s / 1000.0, 6).max(1e-6);
        if vel != Some(v) {
            writeln!(w, "  $VEL.CP = {}", crate::program::fmt::Fixed::new(v, 6))?;
            vel = Some(v);
        }
        Ok(())
    };
    if program.home.is_some() {
        writeln!(w, "  ; home, arc off")?;
        writeln!(w, "  PTP {HOME_NAME}")?;
    }
    let mut bead = 0usize;
    for (i, p) in program.points.iter().enumerate() {
        let name = format!("P{}", i + 1);
        let prev = i.checked_sub(1).map(|k| &program.points[k]);
        if joint_move_target(program, i) {
            if let Some(setup) = program.bead_setup.get(bead) {
                write_bead_setup(w, setup)?;
            }
            bead += 1;
        }
        match p.arc {
            ArcFlag::Approach => {
                writeln!(
                    w,
                    "  ; bead {} (layer {}): approach, arc off",
                    p.layer, p.layer
                )?;
                restore_ptp(w, &mut extax)?;
                writeln!(w, "  PTP {name}")?;
            }
            ArcFlag::Start => {
                match prev {
                    Some(a) if a.arc == ArcFlag::Approach => {
                        set_vel(w, a.speed_mm_s)?;
                        writeln!(w, "  LIN {name}")?;
                    }
                    _ => {
                        writeln!(w, "  ; bead {} (layer {}), arc off", p.layer, p.layer)?;
                        restore_ptp(w, &mut extax)?;
                        writeln!(w, "  PTP {name}")?;
                    }
                }
                if arc {
                    write_ignition(w, opts, &on, &off, p.layer)?;
                }
            }
            // a via is written with the circular move it is the via of
            ArcFlag::On if p.via => continue,
            ArcFlag::On | ArcFlag::End => match timed_segment(program, opts, i) {
                Some(t) => {
                    set_vel(w, t.vel_cp_mm_s)?;
                    for (n, pct) in t.vel_extax_percent.iter().enumerate() {
                        if let Some(pct) = pct {
                            if extax[n] != Some(*pct) {
                                writeln!(
                                    w,
                                    "  $VEL_EXTAX[{}] = {}",
                                    n + 1,
                                    Fixed::new(floor_to(*pct, 4).max(1e-4), 4)
                                )?;
                                extax[n] = Some(*pct);
                            }
                        }
                    }
                }
                None => set_vel(w, p.speed_mm_s)?,
            },
            ArcFlag::Retract => {}
        }
        match p.arc {
            ArcFlag::Approach | ArcFlag::Start => {}
            ArcFlag::On | ArcFlag::End => {
                let start = move_start(program, i).map(|k| &program.points[k]);
                if !arc && start.is_some_and(|q| q.arc == ArcFlag::Start) {
                    writeln!(w, "  {}", trigger_line(0, &on))?;
                }
                // `CIRC aux, end` through the via written just before
                let mv = match prev {
                    Some(v) if v.via => format!("CIRC P{}, {name}", i),
                    _ => format!("LIN {name}"),
                };
                if p.arc == ArcFlag::End {
                    if !arc {
                        writeln!(w, "  {}", trigger_line(1, &off))?;
                    }
                    writeln!(w, "  {mv}")?;
                    if arc {
                        write_arc_end(w, opts, &off)?;
                    }
                } else {
                    writeln!(w, "  {mv} C_DIS")?;
                }
            }
            ArcFlag::Retract => {
                set_vel(w, p.speed_mm_s)?;
                writeln!(w, "  LIN {name}")?;
            }
        }
    }
    if program.home.is_some() {
        writeln!(w, "  ; home, arc off")?;
        restore_ptp(w, &mut extax)?;
        writeln!(w, "  PTP {HOME_NAME}")?;
    }
    writeln!(w, "END")?;
    if arc {
        write_arc_lost_handler(w, opts, &on, &off)?;
    }
    Ok(())
}

/// Seconds as written in `WAIT SEC` (3 decimals).
fn sec(s: f64) -> Fixed {
    Fixed::new(s, 3)
}

/// What happens before a bead: payload, dwell, interpass wait (module doc).
fn write_bead_setup(w: &mut dyn Write, setup: &BeadSetup) -> std::io::Result<()> {
    if let Some(load) = &setup.payload {
        writeln!(
            w,
            "  ; payload: substrate, fixture and the metal deposited so far (kg; CoG mm, flange frame; J of a point mass)"
        )?;
        writeln!(w, "  $LOAD.M = {}", Fixed::new(load.mass_kg, 3))?;
        let c = load.cog_mm;
        writeln!(
            w,
            "  $LOAD.CM = {{X {},Y {},Z {},A 0.0,B 0.0,C 0.0}}",
            Mm(c.x),
            Mm(c.y),
            Mm(c.z)
        )?;
        writeln!(w, "  $LOAD.J = {{X 0.0,Y 0.0,Z 0.0}}")?;
    }
    if setup.dwell_s > 0.0 {
        writeln!(w, "  ; interlayer dwell")?;
        writeln!(w, "  WAIT SEC {}", sec(setup.dwell_s))?;
    }
    if let Some(n) = setup.wait_input {
        writeln!(w, "  ; interpass temperature reached")?;
        writeln!(w, "  WAIT FOR $IN[{n}]")?;
    }
    Ok(())
}

/// Arc on at a bead's first point (the robot stands there, exact stop)
/// with the ignition handshake ([`write_handshake`]), then the arc-loss
/// interrupt armed: the arc is established, so the interrupt fires on its
/// loss (an edge).
fn write_ignition(
    w: &mut dyn Write,
    opts: &KukaOptions,
    on: &str,
    off: &str,
    layer: usize,
) -> std::io::Result<()> {
    writeln!(
        w,
        "  ; arc on, then wait at most {} s for the arc (IN {}); without it: arc off, message, HALT, and the start tries again",
        sec(opts.ignition_timeout_s),
        opts.arc_ok_input
    )?;
    write_handshake(w, opts, on, off, "  ", &format!("arc on, layer {layer}"))?;
    writeln!(
        w,
        "  ; arc established: arc-loss supervision on (interrupt {})",
        opts.arc_loss_interrupt
    )?;
    writeln!(w, "  INTERRUPT ON {}", opts.arc_loss_interrupt)?;
    Ok(())
}

/// The ignition handshake at `indent`, a `LOOP` left only with the arc
/// established: arc on, `$TIMER[t]` set to minus the timeout (ms) and
/// started, `WAIT FOR $IN[n] OR $TIMER_FLAG[t]` (KRL's `WAIT FOR` has no
/// timeout; the flag turns on when the timer reaches 0), `EXIT` if the
/// input is on; else arc off, a message ("No arc … after `after`") and
/// `HALT`, and the operator's start tries again.
fn write_handshake(
    w: &mut dyn Write,
    opts: &KukaOptions,
    on: &str,
    off: &str,
    indent: &str,
    after: &str,
) -> std::io::Result<()> {
    let (t, n) = (opts.ignition_timer, opts.arc_ok_input);
    let ms = (opts.ignition_timeout_s * 1000.0).round() as i64;
    writeln!(w, "{indent}LOOP")?;
    writeln!(w, "{indent}  {on}")?;
    writeln!(w, "{indent}  $TIMER_STOP[{t}] = TRUE")?;
    writeln!(w, "{indent}  $TIMER[{t}] = -{ms}")?;
    writeln!(w, "{indent}  $TIMER_STOP[{t}] = FALSE")?;
    writeln!(w, "{indent}  WAIT FOR $IN[{n}] OR $TIMER_FLAG[{t}]")?;
    writeln!(w, "{indent}  $TIMER_STOP[{t}] = TRUE")?;
    writeln!(w, "{indent}  IF $IN[{n}] THEN")?;
    writeln!(w, "{indent}    EXIT")?;
    writeln!(w, "{indent}  ENDIF")?;
    writeln!(w, "{indent}  {off}")?;
    write_message(
        w,
        &format!("{indent}  "),
        1,
        &format!(
            "No arc: IN {n} off {} s after {after}",
            sec(opts.ignition_timeout_s)
        ),
    )?;
    writeln!(w, "{indent}  HALT")?;
    writeln!(w, "{indent}ENDLOOP")?;
    Ok(())
}

/// A message the operator acknowledges (`Set_KrlMsg(#QUIT, …)`, KSS 8)
/// with number `nr`, in the routine's `WAAM_MSG`/`WAAM_PAR`/`WAAM_OPT`/
/// `WAAM_H` ([`write_message_decls`]). KRL's `MSG_TXT[]` holds 80
/// characters.
fn write_message(w: &mut dyn Write, indent: &str, nr: u32, text: &str) -> std::io::Result<()> {
    debug_assert!(text.len() <= 80, "{text}");
    writeln!(
        w,
        "{indent}WAAM_MSG = {{MODUL[] \"WAAM\",NR {nr},MSG_TXT[] \"{text}\"}}"
    )?;
    writeln!(
        w,
        "{indent}WAAM_OPT = {{VL_STOP TRUE,CLEAR_P_RESET TRUE,CLEAR_P_SAW FALSE,LOG_TO_DB TRUE}}"
    )?;
    writeln!(
        w,
        "{indent}WAAM_H = SET_KRLMSG(#QUIT,WAAM_MSG,WAAM_PAR[],WAAM_OPT)"
    )?;
    Ok(())
}

/// The declarations [`write_message`] uses, at the top of a routine.
fn write_message_decls(w: &mut dyn Write) -> std::io::Result<()> {
    writeln!(w, "  DECL KRLMSG_T WAAM_MSG")?;
    writeln!(w, "  DECL KRLMSGPAR_T WAAM_PAR[3]")?;
    writeln!(w, "  DECL KRLMSGOPT_T WAAM_OPT")?;
    writeln!(w, "  DECL INT WAAM_H")?;
    Ok(())
}

/// At a bead's last point (exact stop): crater fill with the arc on (a
/// `WAIT SEC 0.000` without one: an advance-run stop, so that what follows
/// runs when the robot stands at the last point), the arc-loss interrupt
/// off, arc off, burn-back wait.
fn write_arc_end(w: &mut dyn Write, opts: &KukaOptions, off: &str) -> std::io::Result<()> {
    if opts.crater_fill_s > 0.0 {
        writeln!(w, "  ; crater fill, arc on")?;
    } else {
        writeln!(
            w,
            "  ; advance-run stop: the supervision goes off at the bead's last point"
        )?;
    }
    writeln!(w, "  WAIT SEC {}", sec(opts.crater_fill_s))?;
    writeln!(
        w,
        "  ; arc-loss supervision off (interrupt {}), then arc off",
        opts.arc_loss_interrupt
    )?;
    writeln!(w, "  INTERRUPT OFF {}", opts.arc_loss_interrupt)?;
    write_arc_off(w, opts, off, "  ")
}

/// Arc off, then the burn-back wait: the end of a bead and of the arc-loss
/// handler.
fn write_arc_off(
    w: &mut dyn Write,
    opts: &KukaOptions,
    off: &str,
    indent: &str,
) -> std::io::Result<()> {
    writeln!(w, "{indent}{off}")?;
    if opts.burn_back_s > 0.0 {
        writeln!(w, "{indent}; burn-back")?;
        writeln!(w, "{indent}WAIT SEC {}", sec(opts.burn_back_s))?;
    }
    Ok(())
}

/// The arc-loss interrupt routine ([`ARC_LOST_HANDLER`], a local `DEF`
/// after the main routine): interrupt off, `BRAKE F`, arc off as at a
/// bead's end, a message, then per [`KukaOptions::arc_loss`] an endless
/// `HALT` (abort) or `HALT`, the ignition handshake and the interrupt
/// re-armed (reignite). Module doc, "Arc supervision".
fn write_arc_lost_handler(
    w: &mut dyn Write,
    opts: &KukaOptions,
    on: &str,
    off: &str,
) -> std::io::Result<()> {
    let (p, n) = (opts.arc_loss_interrupt, opts.arc_ok_input);
    writeln!(w)?;
    writeln!(w, "DEF {ARC_LOST_HANDLER}( )")?;
    writeln!(
        w,
        "  ; arc lost in a bead (interrupt {p}: IN {n} off): stop on the path, arc off; the bead never goes on with the arc off"
    )?;
    write_message_decls(w)?;
    writeln!(w, "  INTERRUPT OFF {p}")?;
    writeln!(w, "  BRAKE F")?;
    write_arc_off(w, opts, off, "  ")?;
    match opts.arc_loss {
        ArcLoss::Abort => {
            write_message(
                w,
                "  ",
                2,
                &format!("Arc lost (IN {n} off) in a bead: layer incomplete, cancel the program"),
            )?;
            writeln!(w, "  ; abort: the start never leaves this routine")?;
            writeln!(w, "  LOOP")?;
            writeln!(w, "    HALT")?;
            writeln!(w, "  ENDLOOP")?;
        }
        ArcLoss::Reignite => {
            write_message(
                w,
                "  ",
                2,
                &format!(
                    "Arc lost (IN {n} off) in a bead: start re-ignites here, the bead goes on"
                ),
            )?;
            writeln!(w, "  HALT")?;
            writeln!(
                w,
                "  ; re-ignite where the robot stopped: arc on, then wait at most {} s for the arc (IN {n}); without it: arc off, message, HALT, and the start tries again",
                sec(opts.ignition_timeout_s)
            )?;
            write_handshake(w, opts, on, off, "  ", "re-ignition")?;
            writeln!(
                w,
                "  ; arc established again: supervision on, the bead goes on from here"
            )?;
            writeln!(w, "  INTERRUPT ON {p}")?;
        }
    }
    writeln!(w, "END")?;
    Ok(())
}

/// Writes the `.dat` of `program`.
///
/// # Errors
/// I/O errors of `w`; an error of kind `Other` wrapping
/// [`ProgramError::VendorMismatch`] when the cell's robot is not a KUKA arm.
pub fn write_dat(w: &mut dyn Write, program: &Program, opts: &KukaOptions) -> std::io::Result<()> {
    check_vendor(&program.cell, Vendor::Kuka, EMITTER).map_err(std::io::Error::other)?;
    let robot = program.cell.robot();
    let (_, tool) = opts.frames(&program.cell);
    // An endless turn written modulo 360° (the controller's infinitely
    // rotating axis takes the shortest way, at most 180° a motion).
    let modulo = crate::program::pose::turn_modulo(&program.cell);
    let ext_of = |q: Option<[f64; 2]>| {
        let mut e = q.unwrap_or([0.0; 2]).map(f64::to_degrees);
        if modulo {
            e[1] = modulo_180(e[1]);
        }
        format!(
            "E1 {},E2 {},E3 0.0,E4 0.0,E5 0.0,E6 0.0",
            Deg(e[0]),
            Deg(e[1])
        )
    };
    let axis = |q: &Joints| {
        let a = q.map(f64::to_degrees);
        format!(
            "A1 {},A2 {},A3 {},A4 {},A5 {},A6 {}",
            Deg(a[0]),
            Deg(a[1]),
            Deg(a[2]),
            Deg(a[3]),
            Deg(a[4]),
            Deg(a[5])
        )
    };
    writeln!(w, "&ACCESS RVP")?;
    writeln!(w, "&REL 1")?;
    writeln!(w, "DEFDAT {}", program.name)?;
    if let Some(h) = &program.home {
        writeln!(
            w,
            "  DECL E6AXIS {HOME_NAME}={{{},{}}}",
            axis(&h.joints),
            ext_of(h.positioner)
        )?;
    }
    for (i, p) in program.points.iter().enumerate() {
        let ext = ext_of(p.positioner);
        let user_from_base = opts.base_at(&program.cell, p.positioner).inverse();
        match (opts.positions, joint_move_target(program, i)) {
            (PositionMode::Joint, true) => {
                writeln!(w, "  DECL E6AXIS P{}={{{},{ext}}}", i + 1, axis(&p.joints))?;
            }
            (PositionMode::Cartesian, _) | (PositionMode::Joint, false) => {
                let pose = user_from_base * robot.flange_pose(&p.joints) * tool;
                let t = pose.translation.vector;
                let abc = KukaAbc::from_rotation(&pose.rotation.to_rotation_matrix()).to_degrees();
                writeln!(
                    w,
                    "  DECL E6POS P{}={{X {},Y {},Z {},A {},B {},C {},S {},T {},{ext}}}",
                    i + 1,
                    Mm(t.x),
                    Mm(t.y),
                    Mm(t.z),
                    Deg(abc[0]),
                    Deg(abc[1]),
                    Deg(abc[2]),
                    status(robot, &p.joints),
                    turn(&p.joints)
                )?;
            }
        }
    }
    writeln!(w, "ENDDAT")?;
    Ok(())
}

/// The `.src` and `.dat` files of `program`: one pair when its bytes fit
/// [`KukaOptions::max_file_bytes`], else one pair per group of whole beads,
/// `NAME_P01`, `NAME_P02`, … in the order the cell runs them
/// ([`split::split_to_budget`](crate::program::split::split_to_budget)).
///
/// # Errors
/// [`ProgramError::InvalidOptions`] for bad options or a bad name (or one
/// longer than [`KRL_NAME_MAX`], group suffix included);
/// [`ProgramError::OverBudget`] for a bead whose program alone does not
/// fit `max_file_bytes`; [`ProgramError::VendorMismatch`] when the cell's
/// robot is not a KUKA arm.
pub fn kuka_files(program: &Program, opts: &KukaOptions) -> Result<Vec<EmittedFile>, ProgramError> {
    let size = |g: &Program| -> Result<usize, ProgramError> {
        Ok(kuka_pair(g, opts)?.iter().map(|f| f.text.len()).sum())
    };
    let parts = split_to_budget(program, &Kuka::budget(opts), size)?;
    let mut out = Vec::with_capacity(2 * parts.len());
    for part in &parts {
        out.extend(kuka_pair(part, opts)?);
    }
    Ok(out)
}

/// The `.src` and `.dat` of `program` as one KRL program.
fn kuka_pair(program: &Program, opts: &KukaOptions) -> Result<Vec<EmittedFile>, ProgramError> {
    check_vendor(&program.cell, Vendor::Kuka, EMITTER)?;
    program.check_finite()?;
    opts.validate()?;
    check_name(&program.name)?;
    if program.name.len() > KRL_NAME_MAX {
        return Err(ProgramError::InvalidOptions {
            field: "name",
            value: program.name.clone(),
            reason: "KRL names (DEF, DEFDAT, file name) have at most 24 characters",
        });
    }
    if opts.arc_process() && program.name.eq_ignore_ascii_case(ARC_LOST_HANDLER) {
        return Err(ProgramError::InvalidOptions {
            field: "name",
            value: program.name.clone(),
            reason: "taken by the arc-loss interrupt routine, a local DEF in the same .src",
        });
    }
    Ok(vec![
        EmittedFile {
            name: format!("{}.src", program.name),
            text: render(|w| write_src(w, program, opts))?,
        },
        EmittedFile {
            name: format!("{}.dat", program.name),
            text: render(|w| write_dat(w, program, opts))?,
        },
    ])
}

/// `deg` in (−180°, 180°], the value an infinitely rotating KUKA axis is
/// written with.
pub fn modulo_180(deg: f64) -> f64 {
    let r = deg.rem_euclid(360.0);
    if r > 180.0 {
        r - 360.0
    } else {
        r
    }
}

/// KUKA KRL `.src`/`.dat` programs: the [`Controller`] implementation.
#[derive(Debug, Clone, Copy)]
pub struct Kuka;

impl Controller for Kuka {
    const VENDOR: Vendor = Vendor::Kuka;
    const KEY: &'static str = "kuka";
    const EMITTER: &'static str = EMITTER;
    const EXTENSIONS: &'static [&'static str] = &["src", "dat"];
    type Options = KukaOptions;
    type Read = read::KrlProgram;

    fn with_common(own: &KukaOptions, common: &ProgramOptions) -> KukaOptions {
        KukaOptions {
            common: *common,
            ..own.clone()
        }
    }

    fn check_options(opts: &KukaOptions) -> Result<(), ProgramError> {
        opts.validate()
    }

    fn cycle_options(opts: &KukaOptions) -> CycleOptions {
        CycleOptions {
            joint_speed_fraction: f64::from(opts.ptp_percent) / 100.0,
            ..CycleOptions::default()
        }
    }

    fn common(opts: &KukaOptions) -> &ProgramOptions {
        &opts.common
    }

    fn budget(opts: &KukaOptions) -> Budget {
        Budget {
            field: "[program.kuka] max_file_bytes",
            limit: opts.max_file_bytes,
            unit: "bytes",
        }
    }

    /// The bytes of the `.src` and `.dat` read together.
    fn occupied(files: &[EmittedFile], _read: &read::KrlProgram) -> usize {
        files.iter().map(|f| f.text.len()).sum()
    }

    fn emit(program: &Program, opts: &KukaOptions) -> Result<Vec<EmittedFile>, ProgramError> {
        kuka_files(program, opts)
    }

    fn read(files: &[EmittedFile]) -> Result<read::KrlProgram, ProgramError> {
        let find = |ext: &str| {
            files
                .iter()
                .find(|f| f.name.to_ascii_lowercase().ends_with(ext))
                .ok_or_else(|| ProgramError::Read {
                    file: files.first().map_or_else(String::new, |f| f.name.clone()),
                    line: 0,
                    reason: format!("a KRL program needs its `{ext}` file"),
                })
        };
        let (src, dat) = (find(".src")?, find(".dat")?);
        parse_krl(&src.text, &src.name, &dat.text, &dat.name)
    }

    fn files_on_disk(path: &Path) -> Result<Vec<EmittedFile>, ProgramError> {
        Ok(vec![
            read_file(&path.with_extension("src"))?,
            read_file(&path.with_extension("dat"))?,
        ])
    }

    fn main_file(read: &read::KrlProgram) -> &str {
        &read.src_file
    }

    fn steps(
        read: &read::KrlProgram,
        cell: &CellLayout,
        opts: &KukaOptions,
        report: &mut ValidationReport,
    ) -> Option<Vec<DecodedStep>> {
        Some(decode::kuka_steps(read, cell, opts, report))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rad(d: [f64; 6]) -> Joints {
        d.map(f64::to_radians)
    }

    /// Bit 2 is set for A5 strictly negative: clear at A5 = 0.
    #[test]
    fn status_bit_2_is_a5_strictly_negative() {
        let r = RobotModel::kuka_kr16_2();
        let s = |a5: f64| status(&r, &rad([0.0, -90.0, 90.0, 0.0, a5, 0.0])) & 4;
        assert_eq!(s(30.0), 0);
        assert_eq!(s(0.0), 0);
        assert_eq!(s(-1e-3), 4);
        assert_eq!(s(-30.0), 4);
    }

    /// Bit 1 (`A3 >= phi`) is a joint test: an elbow-up A3 (60°..120°)
    /// sets it whether the wrist centre is in front of A1 (bit 0 clear) or
    /// behind it (bit 0 set, the upper arm leaning back), and an A3 past the
    /// stretched elbow (−60°) clears it on both sides.
    #[test]
    fn status_bit_1_is_the_a3_joint_test_on_both_sides() {
        let r = RobotModel::kuka_kr16_2();
        assert_eq!(status(&r, &rad([0.0, -90.0, 90.0, 0.0, 30.0, 0.0])), 2);
        let mut sides = [0usize; 2];
        for a3 in [60.0, 90.0, 120.0, -60.0] {
            for k in 0..=38 {
                let a2 = -155.0 + 5.0 * k as f64;
                let s = status(&r, &rad([0.0, a2, a3, 0.0, 30.0, 0.0]));
                sides[(s & 1) as usize] += 1;
                let want = if a3 > 0.0 { 2 } else { 0 };
                assert_eq!(s & 2, want, "A2 {a2}, A3 {a3}: S {s}");
            }
        }
        assert!(sides[0] > 0 && sides[1] > 0, "{sides:?}");
    }

    #[test]
    fn trigger_actions_are_assignments_or_calls() {
        for ok in [
            "$OUT[3]=TRUE",
            "$OUT[3] = FALSE",
            "$ANOUT[2]=0.5",
            "FLAG.ON=TRUE",
            "ARC_ON()",
            "PULSE($OUT[2],TRUE,0.1)",
            "EXTRUDER_ON ( 3 )",
        ] {
            assert!(is_trigger_action(ok), "{ok}");
        }
        for bad in [
            "WAIT FOR $IN[1]==TRUE",
            "WAIT SEC 0.5",
            "$OUT[3]==TRUE",
            "IF A THEN",
            "=TRUE",
            "$OUT[]=TRUE",
            "$OUT[1]=",
            "HALT",
        ] {
            assert!(!is_trigger_action(bad), "{bad}");
        }
        let opts = KukaOptions {
            process: ProcessControl::Custom {
                start: "$OUT[2]=TRUE".into(),
                end: "WAIT FOR $IN[1]".into(),
            },
            ..Default::default()
        };
        let e = opts.validate().unwrap_err().to_string();
        assert!(e.contains("`process.end`") && e.contains("TRIGGER"), "{e}");
    }

    #[test]
    fn turn_bits() {
        assert_eq!(turn(&rad([91.0, -45.0, 37.0, 1.0, -1.0, 0.0])), 0b010010);
        // a joint printed as 0.00000 is not negative (A4 = -1e-12 rad)
        assert_eq!(turn(&[0.1, -0.5, 0.3, -1e-12, 0.2, -1e-9]), 0b000010);
    }
}
