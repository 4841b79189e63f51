//! KUKA KRL programs: `.src` (motions) and `.dat` (positions) [SPEC §8].
//!
//! * Positions as `E6AXIS` (A1..A6 in degrees, KUKA convention of the
//!   robot model) or `E6POS` (`X Y Z A B C`, mm and deg, `$TOOL` in `$BASE`)
//!   with the Status `S` and Turn `T` bits derived from the chosen joints;
//!   the torch-carried cell's positioner as external axes `E1 E2` (deg).
//!   With joint positions ([`PositionMode::Joint`](crate::program::PositionMode::Joint)) only the `PTP` targets
//!   are `E6AXIS`: `LIN` targets (bead points, the move into a bead, the
//!   retract point) are always `E6POS` with S and T, the Cartesian target
//!   form of a `LIN` (an axis-specific `LIN` target is not the form KUKA's
//!   inline forms write, and may be refused).
//! * Each bead: `PTP` to its first point (exact stop), then `LIN` moves at
//!   `$VEL.CP` (m/s) blended with `C_DIS` inside the bead, the last one
//!   exact. A transit's via points ([`ArcFlag::Transit`](crate::program::ArcFlag::Transit)), where one joint
//!   move from a bead to the next would cross the wall, are `PTP`s.
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
//! * **Wire feed** (arc process). These programs switch the arc by I/O
//!   with their own handshake, not through ArcTech's inline forms (whose
//!   weld data live in package-version-specific `.dat` structures), so the
//!   wire feed goes to the power source as its analog command, as
//!   KUKA.ArcTech Analog does for "power sources with analog reference
//!   voltage" (KR C2 manual, ArcTechAnalog R1.1) and a Fronius TPSi takes it
//!   ("Wire feed speed command value", analog 0–10 V): `$ANOUT[n] = wire
//!   feed / full scale` ([`KukaOptions::wire_feed_anout`],
//!   [`KukaOptions::wire_feed_full_scale_mm_s`]) before each bead's arc on,
//!   and where a move's wire feed differs from the one before, `TRIGGER WHEN
//!   DISTANCE=0 DELAY=0 DO $ANOUT[n]=v` before it, switching at the move's
//!   start point (in the middle of its blend). Written to 4 decimals; a
//!   wire feed above the full scale is refused.
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
//!   gets `$VEL.CP` = the TCP's travel / the planned segment time (the
//!   length of the path it deposits over the part / the planned speed,
//!   [`deposited_length_mm`](crate::program::deposited_length_mm)) and
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
pub mod emit;
pub mod options;
pub mod read;

pub use decode::validate_kuka;
pub use emit::*;
pub use options::*;
pub use read::parse_krl;

use crate::program::contract::{read_file, Controller};
use crate::program::cycle::CycleOptions;
use crate::program::split::Budget;
use crate::program::validate::{DecodedStep, ValidationReport};
use crate::program::ProgramOptions;
use std::path::Path;

pub use crate::program::frames::fixed_torch_at;
use crate::program::{EmittedFile, Program, ProgramError};
use crate::robot::{CellLayout, Vendor};

/// The emitter's name in [`ProgramError::VendorMismatch`].
pub const EMITTER: &str = "KUKA KRL";

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
            // fixed-tool mode (part carried by default) or a base coupled
            // to the positioner: the part frame
            beads_in_part_frame: [
                opts.external_tcp.unwrap_or(true),
                opts.common.coordinated && !opts.external_tcp.unwrap_or(false),
            ],
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
    use crate::program::ProcessControl;
    use crate::robot::{Joints, RobotModel};

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
