//! FANUC TP ASCII programs (`.ls`) [SPEC §8, thesis §3.1.2]: `/PROG`,
//! `/ATTR`, `/APPL` (arc welding), `/MN`, `/POS`, `/END`.
//!
//! * Positions in joint representation (degrees, FANUC's J2/J3 convention,
//!   which is the controller convention of [`RobotModel`](crate::robot::RobotModel))
//!   or Cartesian `X Y Z W P R` (mm, deg, tool frame in the user frame) with
//!   `CONFIG : 'F U T, t1, t4, t6'` derived from the chosen joints, so that
//!   the controller reproduces our branch and turns. A position whose J1,
//!   J4 or J6 lies within [`TURN_EDGE_DEG`] of a turn-number edge (an odd
//!   multiple of 180°) is written in joint representation even then: the
//!   controller recomputes the joints from the rounded `W P R`, and on the
//!   edge the turn number alone cannot say on which side (a full turn
//!   apart) it should land.
//! * Each bead: a joint move (`J P[n] 10% FINE`) to its first point with the
//!   arc off, `Arc Start[s]` (or the user's start line), linear moves at the
//!   travel speed blended with `CNT`, the last one `FINE` so that the arc
//!   switching points are not moved, `Arc End[s]` (or the user's end line).
//! * The torch-carried cell's positioner is motion group 2 (`GP2`, `J1 J2` =
//!   `q7 q8` in degrees), `DEFAULT_GROUP = 1,1,*,*,*`.
//! * **Memory budget.** Sub-programs called from a main program are
//!   resident together, so the budget counts every position of every
//!   program resident at once ([`FanucOptions::max_positions`], default
//!   15 000, the R-30iB's standard program space). A build with more is
//!   cut between layers into groups, each a complete program the cell
//!   loads and runs in turn — `NAME_P01.ls`, `NAME_P02.ls`, … (frames,
//!   home → its beads with their set-up → home) — and no main program
//!   ([`split`](crate::program::split)); a layer that does not fit alone
//!   is refused with the numbers.
//!
//! * With approach and retract points ([`ArcFlag::Approach`](crate::program::ArcFlag::Approach),
//!   [`ArcFlag::Retract`](crate::program::ArcFlag::Retract)) a bead is `J P[a] 10% FINE` (approach point, arc
//!   off), `L P[s] ... FINE` (into the bead), `Arc Start`, the bead, `Arc
//!   End`, `L P[r] ... FINE` (retract); the joint move from one layer's
//!   retract point to the next layer's approach point is the arc-off
//!   transition, or `J P[v] 10% FINE` through each of its via points
//!   ([`ArcFlag::Transit`](crate::program::ArcFlag::Transit)) where one joint move would cross the wall.
//!
//! Speeds are integers (mm/sec, cm/min or msec), the only form a TP motion
//! line takes without a register; speeds are rounded down and times up to
//! the unit, so that no move runs faster than planned (a joint planned at
//! its maximum speed stays within it); prefer cm/min for a finer step.
//!
//! **What the speed means.** The planned speed is the travel speed of the
//! deposition point relative to the part (what the plan and the validator
//! use). In the torch-carried cell with the torch as tool frame and the
//! positioner still that is the controller's TCP speed. Where the part
//! moves it is not, and the file says how it is kept:
//!
//! * **Torch-carried cell, coordinated** (`common.coordinated`, default):
//!   every linear move carries the `COORD` motion option, the positioner
//!   (group 2) being the leader of a coordinated pair on the controller.
//!   FANUC: "multiple motion groups move together to maintain the same
//!   position relative to each other. Motion speed which is specified in
//!   the line is relative speed for coordinated motion" (TP help, Motion
//!   Options 6.5): the speed is the torch's over the part on the
//!   positioner, the planned travel speed, also where the positioner turns
//!   45° under a nearly still torch. Positions are unchanged (robot joints
//!   plus the positioner's). Joint moves carry no `COORD` (it acts on
//!   linear and circular moves).
//! * **Part-carried cell without remote TCP** (default) and the
//!   torch-carried cell without coordination: linear moves are
//!   **time-based** ([`MotionTiming::Auto`]): `L P[n] 5891msec CNT100`,
//!   the length of the path the move deposits divided by the planned
//!   speed, rounded up to the millisecond (in the torch-carried cell only
//!   where the positioner turns). This needs no option and makes every
//!   segment take the planned time over what it deposits: the controller
//!   interpolates the flange pose, so where the part turns under the fixed
//!   torch the deposition point travels an arc, not the chord (a 45° turn
//!   of a 45 mm circle: 35.34 mm, the chord 34.44 mm, 2.6 % shorter); the
//!   length is measured along that interpolation
//!   ([`deposited_length_mm`](crate::program::deposited_length_mm); before
//!   issue 45 the chord's time made such moves 2.6 % too fast).
//! * **Part-carried cell with remote TCP** (`common.remote_tcp`, off in
//!   [`FanucOptions::default`]): every linear move carries `RTCP`, the user
//!   frame being the remote TCP frame at the fixed torch
//!   ([`FanucOptions::remote_tcp_frame`], [`FanucOptions::base_from_torch`]),
//!   and `CONTROL_CODE = 00000001 00000000`, as a controller writes a
//!   program with `RTCP` moves. FANUC: "In a motion instruction that
//!   includes RTCP, the speed specified is the relative speed between the
//!   workpiece and the tool" — the planned travel speed. Remote TCP is a
//!   paid option, disabled on a controller with Coordinated Motion loaded,
//!   and not supported with weaving or multi-group programs. Positions must
//!   be joints: a controller writes the Cartesian positions of an RTCP
//!   program as `RX RY RZ RW RP RR`, a representation FANUC does not
//!   document (a post-processor author reports failing to reproduce it);
//!   Cartesian positions with remote TCP are refused. That is why it is
//!   off by default.
//!
//! Where a speed relative to the part (`COORD`, `RTCP`) would put a joint
//! above [`JOINT_SPEED_MARGIN`] of its maximum, the segment is written
//! time-based instead (rounded up), so that the positions' rounding cannot
//! push it over.
//!
//! **Frames.** Each program opens with remarks stating the user and tool
//! frames its positions assume, in FANUC `X,Y,Z,W,P,R` (mm, deg): `!
//! UF1 X,Y=1045.747,-630.155`, `! UF1 Z,W=653.167,180.000`, `! UF1
//! P,R=0.000,0.000`, the same for `UT`, then `UFRAME_NUM`/`UTOOL_NUM`
//! ([`FanucOptions::frames`]): UFRAME 0 (world) or [`FanucOptions::user_frame`]
//! with [`FanucOptions::base_from_user`], or the remote TCP frame; UTOOL
//! [`FanucOptions::tool_frame`] = the torch (torch-carried cell) or the
//! flange (part-carried cell) unless [`FanucOptions::flange_from_tool`]
//! says otherwise. The program does not write the frames (that would
//! overwrite what was taught on the controller); the validator checks the
//! statements against the options and the cell.
//!
//! **Wire feed** (arc process). ArcTool takes the wire feed from the weld
//! schedule an `Arc Start[n]` (or `Weld Start[p,n]`) names, and an `Arc
//! Start` while the arc is on switches the running weld to schedule `n`;
//! writing `$AWESCH[...]` during a weld does not change the running weld
//! (a practitioner's note, industrialmonitordirect.com "FANUC weld
//! parameter change during auto mode welding"; the ArcTool manual is not
//! in our sources). So the program defines its schedules and says which
//! it assumes: schedule `s + k` (`s` the process's schedule) is the `k`-th
//! distinct wire feed of its arc-on moves, each stated in a header remark
//! `! WELD SCHED 2: WFS 80.00 MM/S` (mm/s to 0.01; set the schedules on the
//! controller to these values, in the unit its power source takes), the
//! same table in every group of a build. A bead starts with its first
//! segment's schedule, and before a move whose wire feed differs an `Arc
//! Start[k]` line switches to its schedule (a stand-alone line after the
//! move into the segment's start: with `CNT` the controller runs it as the
//! robot passes that point). `Arc End[s]` keeps the process's schedule
//! (crater fill). The travel speed stays on the motion lines. `waam check`
//! reads the remarks back and checks each arc-on move's wire feed over its
//! travel speed against the plan's. A custom process writes no wire feed.
//!
//! **Arc, home, set-up.** `/APPL` has `ARC : TRUE ;` and `ARC Welding
//! Equipment` as an ArcTool program exported by a controller; beads start
//! and stop with `Arc Start[s]`/`Arc End[s]` or, with
//! [`FanucOptions::weld_procedure`], `Weld Start[p,s]`/`Weld End[p,s]`.
//! With a home position the first and last motions are `J` moves to it.
//! Before each bead: payload (`$PLST_GRP1[n].$PAYLOAD` kg,
//! `$PAYLOAD_X/_Y/_Z` cm in the faceplate frame, then `PAYLOAD[n]`; the
//! schedule's inertia is left as set on the controller), dwell (`WAIT
//! 30.00(sec)`), interpass wait (`WAIT DI[n]=ON`).

pub mod decode;
pub mod emit;
pub mod options;
pub mod read;

pub use decode::{fanuc_steps, parse_config, validate_fanuc};
pub use emit::*;
pub use options::*;
pub use read::parse_ls;

use crate::program::contract::Controller;
use crate::program::cycle::CycleOptions;
use crate::program::validate::{DecodedStep, ValidationReport};
use crate::program::ProgramOptions;
use std::path::Path;

use crate::program::kinds::MoveKind;
use crate::program::split::Budget;
use crate::program::{EmittedFile, Program, ProgramError};
use crate::robot::{CellLayout, Vendor};

/// The emitter's name in [`ProgramError::VendorMismatch`].
pub const EMITTER: &str = "FANUC TP";

/// FANUC TP ASCII `.ls` programs: the [`Controller`] implementation.
#[derive(Debug, Clone, Copy)]
pub struct Fanuc;

/// The FANUC program at `main` and every program it calls, read from the
/// same folder (`NAME.ls`), each once, in the order first called.
///
/// # Errors
/// [`ProgramError::Read`] naming the file (and the line for a parse error).
pub fn read_with_calls(main: &Path) -> Result<Vec<TpProgram>, ProgramError> {
    Fanuc::read(&Fanuc::files_on_disk(main)?)
}

impl Controller for Fanuc {
    const VENDOR: Vendor = Vendor::Fanuc;
    const KEY: &'static str = "fanuc";
    const EMITTER: &'static str = EMITTER;
    const EXTENSIONS: &'static [&'static str] = &["ls"];
    type Options = FanucOptions;
    type Read = Vec<TpProgram>;

    fn with_common(own: &FanucOptions, common: &ProgramOptions) -> FanucOptions {
        FanucOptions {
            common: *common,
            ..own.clone()
        }
    }

    fn check_options(opts: &FanucOptions) -> Result<(), ProgramError> {
        opts.validate()
    }

    fn cycle_options(opts: &FanucOptions) -> CycleOptions {
        CycleOptions {
            joint_speed_fraction: f64::from(opts.approach_percent) / 100.0,
            // the flange interpolated unless remote TCP (part carried) or
            // COORD (torch carried)
            beads_in_part_frame: [opts.common.remote_tcp, opts.common.coordinated],
            ..CycleOptions::default()
        }
    }

    fn common(opts: &FanucOptions) -> &ProgramOptions {
        &opts.common
    }

    fn budget(opts: &FanucOptions) -> Budget {
        Budget {
            field: "[program.fanuc] max_positions",
            limit: opts.max_positions,
            unit: "positions",
        }
    }

    /// Every `P[]` record of the programs read together (a main program
    /// and what it calls are resident at once).
    fn occupied(_files: &[EmittedFile], read: &Vec<TpProgram>) -> usize {
        read.iter().map(|p| p.positions.len()).sum()
    }

    fn emit(program: &Program, opts: &FanucOptions) -> Result<Vec<EmittedFile>, ProgramError> {
        fanuc_files(program, opts)
    }

    fn read(files: &[EmittedFile]) -> Result<Vec<TpProgram>, ProgramError> {
        files.iter().map(|f| parse_ls(&f.text, &f.name)).collect()
    }

    fn files_on_disk(path: &Path) -> Result<Vec<EmittedFile>, ProgramError> {
        read::files_with_calls(path)
    }

    fn main_file(read: &Vec<TpProgram>) -> &str {
        read.first().map_or("", |p| p.name.as_str())
    }

    fn steps(
        read: &Vec<TpProgram>,
        cell: &CellLayout,
        opts: &FanucOptions,
        report: &mut ValidationReport,
    ) -> Option<Vec<DecodedStep>> {
        Some(fanuc_steps(read, cell, opts, report))
    }
}

#[cfg(test)]
mod tests {
    use crate::robot::ik::turn_number;
    use crate::robot::RobotModel;

    /// FANUC turn 0 is `-180° < J <= 180°`: +180° is turn 0, −180° turn −1.
    #[test]
    fn turn_numbers_at_half_a_turn() {
        let t = |deg: f64| turn_number(deg.to_radians());
        assert_eq!(t(180.0), 0);
        assert_eq!(turn_number(std::f64::consts::PI), 0);
        assert_eq!(t(180.0001), 1);
        assert_eq!(t(181.0), 1);
        assert_eq!(t(540.0), 1);
        assert_eq!(t(540.0001), 2);
        assert_eq!(t(-179.9999), 0);
        assert_eq!(t(-180.0), -1);
        assert_eq!(t(-540.0), -2);
        assert_eq!(t(0.0), 0);
    }

    /// The CONFIG string of a posture with J4 = +180° and J6 = −180°.
    #[test]
    fn config_turns_at_half_a_turn() {
        let r = RobotModel::arcmate_120ic_nominal();
        let q = [0.0, 0.0, 0.0, 180.0, -30.0, -180.0].map(f64::to_radians);
        let c = r.fanuc_config(&q);
        assert_eq!((c.turn_j1, c.turn_j4, c.turn_j6), (0, 0, -1));
    }
}
