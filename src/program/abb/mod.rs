//! ABB RAPID module (`.mod`) [SPEC §8]: [`abb_files`] takes a [`Program`]
//! (joints rad, positions mm, speeds mm/s) and [`AbbOptions`] and gives one
//! module `<name>.mod` that a task loads next to its own modules (over the
//! memory budget: a main module and the part modules it loads in turn).
//!
//! * **Names: one entry routine, everything else `LOCAL`.** The module is
//!   `MODULE MOD_<name>` ([`module_name`]) and holds one global routine,
//!   `PROC <name>()`, named after the program (the task's `main` calls it:
//!   `<name>;`, or `%"<name>"%;` after `Load`/`StartLoad` of
//!   `<name>.mod`). RAPID routine and module names are one name space, so
//!   the routine cannot take the module's name; the routine keeps the
//!   program's name because it is what a caller writes, and it matches the
//!   file's (RoboDK's ABB post names its modules `MOD_<prog>` for the same
//!   reason). Every data declaration (`tooldata`, `wobjdata`, `seamdata`,
//!   `welddata`, `loaddata`, `robtarget`s, `jointtarget`s) is `LOCAL` (`LOCAL
//!   PERS`, `LOCAL CONST`): visible in this module only, hiding a global of
//!   the same name (RAPID reference, "Basic Characteristics", §3.1 routine
//!   scope, §5.1 data scope), so that a task that already has a `main`, a
//!   `tWaam` or another program's `p1` accepts the module. The tool and work
//!   object stay `PERS` (what motion instructions expect of them). The name
//!   must not be one the module uses or RAPID reserves
//!   ([`check_entry_name`]).
//! * **Mechanical units.** In the torch-carried cell the positioner's unit
//!   ([`AbbOptions::ufmec`], default `STN1`) is activated by `ActUnit
//!   <unit>;` at the start of the entry routine, before the first motion,
//!   and deactivated by `DeactUnit <unit>;` after the last.
//! * **Gas times** ([`AbbOptions::purge_time_s`],
//!   [`AbbOptions::preflow_time_s`], [`AbbOptions::postflow_time_s`], s,
//!   written to the ms) are `seamdata`'s `purge_time`, `preflow_time` and
//!   `postflow_time`. The defaults (0.5, 0.3, 1.5 s) are typical GMAW/CMT
//!   values; the qualified ones come from the process qualification (the
//!   welding procedure).
//! * Positions as `robtarget`s (`[[x,y,z],[q1,q2,q3,q4],[cf1,cf4,cf6,cfx],
//!   [e1..e6]]`: the tool in the work object, mm, quaternion `[w,x,y,z]`)
//!   with `confdata` derived from the chosen joints (`cf1 cf4 cf6` the
//!   quarter turn of J1, J4, J6, `floor(q / 90°)`; `cfx` 0–7 = wrist
//!   centre in front of/behind axis 1 × in front of/behind the lower arm ×
//!   sign of J5, ABB's table, [`confdata`]), and a `jointtarget` for the joint move
//!   to every bead start; the torch-carried cell's positioner as external
//!   axes `eax_a`, `eax_b` (deg; [`AbbOptions::positioner_axes`]), the
//!   others `9E+09`.
//! * `ConfL \On` so that the controller keeps our branch on linear moves;
//!   with circular moves, `CirPathMode \ObjectFrame` so that it reorients
//!   the tool as the checker models it ([`CIR_PATH_MODE`]).
//! * **Memory budget** ([`AbbOptions::max_file_bytes`], default 2 MB): a
//!   build whose module is larger is cut between layers into part modules
//!   `<name>_P01.mod`, `<name>_P02.mod`, … (each a complete module as
//!   above, entry routine `<name>_P01`, from home to home), and
//!   `<name>.mod` becomes the main module whose entry routine `<name>()`
//!   loads each in turn from [`AbbOptions::load_path`] (`StartLoad
//!   \Dynamic`, `WaitLoad`), calls it late-bound (`%"<name>_P01"%;`) and
//!   unloads it (`UnLoad`), so one part module is resident at a time
//!   ([`loader`]).
//! * **Every identifier the module uses is declared in it** (`LOCAL`),
//!   except the controller data named in [`AbbOptions`] (the interpass
//!   input signal [`AbbOptions::interpass_signal`], the positioner's
//!   mechanical unit [`AbbOptions::ufmec`]) and RobotWare's predefined
//!   `fine`, `z<n>`: `tWaam` (`tooldata`), `wWaam` (`wobjdata`), `seamWaam`
//!   (`seamdata`), `weldWaam<k>` (`welddata`, one per planned travel
//!   speed), `loadWaam<k>` (`loaddata`, one per payload update), `jHome`,
//!   `j<n>`, `p<n>`.
//! * Arc process (ArcWare, RobotWare 6 Arc data layouts): `ArcLStart`
//!   (`fine`) / `ArcL` (`z<n>`) / `ArcLEnd` (`fine`) with `seamWaam` and
//!   `weldWaam<k>`. ArcWare takes the speed of the arc-on moves (`ArcL`,
//!   `ArcLEnd`) from `welddata.weld_speed` (mm/s) and the wire feed from
//!   its `main_arc.wirefeed` ("Weld data describes data that is often
//!   changed along a seam", RAPID reference, `welddata`), so there is one
//!   `welddata` per planned travel speed and wire feed (`weld_speed`
//!   rounded down to its 4 written decimals; `wirefeed` in m/min, RobotWare
//!   Arc's SI unit, 4 decimals: a system set to US units takes in/min and
//!   needs its own conversion), and the inline `speeddata` of those moves
//!   carries the same `v_tcp` (used when welding is blocked). `ArcLStart` moves with the arc
//!   off at its `speeddata` (the approach speed) and names the welddata of
//!   the bead's first segment. `welddata` = `[weld_speed, org_weld_speed,
//!   main_arc, org_arc]`, `seamdata` = `[purge_time, preflow_time, ign_arc,
//!   ign_move_delay, scrape_start, heat_speed, heat_time, heat_distance,
//!   heat_arc, cool_time, fill_time, fill_arc, bback_time, rback_time,
//!   bback_arc, postflow_time]`, `arcdata` = `[sched, mode, voltage,
//!   wirefeed, control, current, voltage2, wirefeed2, control2]` with
//!   `sched` = the process schedule (the power source's program or job)
//!   and everything else 0 but the gas times (`purge_time`, `preflow_time`,
//!   `postflow_time` from the options) and the welddata's wire feed: ignition, heat, crater fill and
//!   burn-back are left to the power source's program (tune them on the
//!   controller). The data are `LOCAL PERS` so that a program loaded after
//!   another one does not inherit that one's persistent values.
//!   Custom process: `MoveL` with the user's instructions after the first
//!   and after the last point of each bead. Speeds as inline `speeddata`
//!   `[v_tcp mm/s, v_ori 500 °/s, v_leax 5000 mm/s, v_reax °/s]`.
//! * Home ([`Program::home`]): `MoveAbsJ jHome` first and last, arc off.
//! * Before each bead ([`Program::bead_setup`]), in this order: `GripLoad
//!   loadWaam<k>` (payload), `WaitTime s` (dwell, s, rounded up to the ms)
//!   and `WaitDI <interpass_signal>, 1` (interpass temperature reached).
//! * Loads (`loaddata` `[mass kg, cog mm, aom, ix, iy, iz kg·m²]`, point
//!   masses: `aom` identity, inertia 0): `tWaam.tload` is
//!   [`AbbOptions::tool_load`], by default a 3 kg torch with its centre of
//!   gravity half way to the TCP (robot-held tool) or, with a stationary
//!   tool (where RAPID's `tload` is the load the robot holds besides the
//!   payload), the `[program]` base payload when the program sets no
//!   payload, else ABB's `load0` (`GripLoad` then carries everything). A
//!   payload's centre of gravity is written in the tool frame (robot-held
//!   tool) or in the robot-held work object's object frame (stationary
//!   tool), as RAPID's `loaddata` says.
//! * With approach and retract points: `MoveAbsJ` to the approach point's
//!   `jointtarget`, `ArcLStart` (or `MoveL`) into the bead's first point at
//!   the approach speed (the arc is off while it moves and ignites there),
//!   the bead, then `MoveL` out to the retract point; a transit's via
//!   points ([`ArcFlag::Transit`]) are `MoveAbsJ` to their `jointtarget`s.
//! * **Part-carried cell: stationary tool.** RAPID speeds are TCP speeds
//!   relative to the work object. In the part-carried cell the torch is
//!   declared as a stationary tool (`tooldata` `robhold` FALSE, `tframe` the
//!   fixed torch in the world frame, at `D_R` pointing down unless given)
//!   and the part as a robot-held work object (`wobjdata` `robhold` TRUE,
//!   `uframe` = the cell's `flange_from_part`): the speeds are then the
//!   torch's over the part, as planned, and `robtarget`s are the torch in
//!   the part frame.
//! * **Torch-carried cell, coordinated** (`[program] coordinated`, the
//!   default): the work object moves with the positioner's mechanical unit
//!   ([`AbbOptions::ufmec`]): `wWaam = [FALSE, FALSE, "STN1", uframe,
//!   oframe]`, whose user frame the controller takes from its system
//!   parameters (the written `uframe` is the identity and unused): it must
//!   be the positioner's *table frame* (origin at the table centre, Z the
//!   table normal, [`crate::robot::positioner`]) at the unit's joints, and
//!   `oframe` = the cell's `table_from_part`. `robtarget`s are then the
//!   torch in the part frame, and `v_tcp` (and `weld_speed`) are the
//!   torch's speed over the moving part: the planned travel speed, with no
//!   time argument.
//! * **Torch-carried cell, not coordinated.** Where the positioner moves
//!   within a bead ([`positioner_moves`]) the TCP's speed in the world
//!   frame is not the torch's over the part: such moves carry the optional
//!   argument `\T` (`ArcL p13, [6,500,5000,7.6857]\T:=5.855, ...`), the
//!   segment time in seconds = the length of the path the move deposits
//!   over the part as the controller interpolates it (an arc where the part
//!   turns under the torch, [`deposited_length_mm`](crate::program::deposited_length_mm)) / the
//!   planned speed, which RAPID uses instead of the `speeddata` (`Speed
//!   [\V] | [\T]` of `MoveL`/`MoveC`/`MoveAbsJ`; uncoordinated external
//!   axes reach their targets with the robot). ArcWare may take the arc-on
//!   speed from `weld_speed` instead of `\T`; the `speeddata`'s `v_reax`
//!   (°/s) is then bounded by the positioner's planned rate on that segment
//!   (its largest axis turn / the segment time, rounded down), so that the
//!   move takes at least the planned time either way (the positioner's
//!   axes are rotational: `v_leax` stays 5000 mm/s). The work object is
//!   fixed (`[FALSE, TRUE, "", uframe, oframe]`).

pub mod decode;
pub mod read;

pub mod loader;

pub use decode::validate_abb;
pub use read::parse_mod;

use crate::program::contract::{groups_by_name, read_file, Controller};
use crate::program::cycle::CycleOptions;
use crate::program::split::{split_to_budget, Budget};
use crate::program::validate::{DecodedStep, ValidationReport};
use crate::program::ProgramOptions;
use std::path::Path;

use std::io::Write;

use serde::{Deserialize, Serialize};

use crate::math::Isometry3;
use crate::program::fmt::{ascii_comment, ceil_to, floor_to, Deg, Fixed, Mm, Unitless};
use crate::program::frames::ToolFrames;
use crate::program::{
    check_name, check_vendor, move_start, opens_bead, positioner_moves, render, ArcFlag,
    EmittedFile, ProcessControl, Program, ProgramError,
};
use crate::robot::orientation::abb_quaternion;
use crate::robot::{CellLayout, Joints, RobotModel, Vendor};

/// The emitter's name in [`ProgramError::VendorMismatch`].
pub const EMITTER: &str = "ABB RAPID";

/// The zones RobotWare predefines (`z0` .. `z200`, mm): the only values of
/// [`AbbOptions::zone_mm`] whose `z<n>` exists without a declaration.
pub const PREDEFINED_ZONES_MM: [u32; 14] = [0, 1, 5, 10, 15, 20, 30, 40, 50, 60, 80, 100, 150, 200];

/// ABB's predefined `load0` (`[0.001, [0, 0, 0.001], [1, 0, 0, 0], 0, 0,
/// 0]`): no load.
pub const LOAD0: AbbLoad = AbbLoad {
    mass_kg: 0.001,
    cog_mm: [0.0, 0.0, 0.001],
    inertia_kg_m2: [0.0; 3],
};

/// Mass of the default robot-held torch load (kg): the order of a
/// MIG/MAG robot torch with its neck and the first part of its hose
/// package (a published controller program's identified arc torch load is
/// 3.1 kg). Identify the real one (`LoadIdentify`) and give it as
/// [`AbbOptions::tool_load`].
pub const DEFAULT_TORCH_MASS_KG: f64 = 3.0;

/// Default [`AbbOptions::purge_time_s`] (s): a short purge, run while the
/// robot moves to the seam. A typical value, not a qualified one: take the
/// gas times from the process qualification (the welding procedure).
pub const DEFAULT_PURGE_TIME_S: f64 = 0.5;

/// Default [`AbbOptions::preflow_time_s`] (s): in the 0.3–0.5 s usual for
/// GMAW/CMT. Take the qualified value.
pub const DEFAULT_PREFLOW_TIME_S: f64 = 0.3;

/// Default [`AbbOptions::postflow_time_s`] (s): in the 1–2 s usual for
/// GMAW/CMT on steel (reactive alloys need more). Take the qualified value.
pub const DEFAULT_POSTFLOW_TIME_S: f64 = 1.5;

/// Default [`AbbOptions::max_file_bytes`]: 2 MB, RoboDK's IRC5 post's
/// 20 000 lines a module (its ABB post: "5000 recommended for S4, 20000
/// recommended for IRC5") at the ~100 bytes a line our modules measure
/// (tests/program/golden/abb_*.mod). ABB publishes no module size limit.
pub const DEFAULT_MAX_FILE_BYTES: usize = 2_000_000;

/// The `CirPathMode` switch written before a module's circular moves
/// (`CirPathMode \ObjectFrame;`): the tool reorients from the start to the
/// end orientation in the work object's frame, the slerp of
/// [`interpolate`](crate::program::pose::interpolate) that the thinner and
/// the checker model. RobotWare's default, `\PathFrame`, reorients
/// relative to the circular path ("The reorientation is performed relative
/// to the circular path. Thus, if the orientation relative to the path is
/// the same at the start and the destination points, the relative
/// orientation remains unchanged during the movement": RAPID reference,
/// MoveC, Basic Characteristics RAPID); on our thinned beads the two part
/// by about 0.5° mid-arc (issue 45). The switch names of RAPID's
/// `CirPathMode`: `\PathFrame`, `\ObjectFrame`, `\CirPointOri`,
/// `\Wrist45`, `\Wrist46`, `\Wrist56` (as RPI's abb_motion_program_exec
/// writes them).
pub const CIR_PATH_MODE: &str = "ObjectFrame";

/// The prefix of the module's name: `MODULE MOD_<name>` holds `PROC
/// <name>()`, since a routine and its module may not share a name (RAPID
/// routine and module names are one name space; RoboDK's ABB post writes
/// `MODULE MOD_<prog>` for the same reason).
pub const MODULE_PREFIX: &str = "MOD_";

/// The module that holds program `name`: `MOD_<name>`.
pub fn module_name(name: &str) -> String {
    format!("{MODULE_PREFIX}{name}")
}

/// RAPID's reserved words (RAPID kernel reference, "Reserved words"): none
/// may name the entry routine.
pub const RAPID_RESERVED: &[&str] = &[
    "ALIAS",
    "AND",
    "BACKWARD",
    "CASE",
    "CONNECT",
    "CONST",
    "DEFAULT",
    "DIV",
    "DO",
    "ELSE",
    "ELSEIF",
    "ENDFOR",
    "ENDFUNC",
    "ENDIF",
    "ENDMODULE",
    "ENDPROC",
    "ENDRECORD",
    "ENDTEST",
    "ENDTRAP",
    "ENDWHILE",
    "ERROR",
    "EXIT",
    "FALSE",
    "FOR",
    "FROM",
    "FUNC",
    "GOTO",
    "IF",
    "INOUT",
    "LOCAL",
    "MOD",
    "MODULE",
    "NOSTEPIN",
    "NOT",
    "NOVIEW",
    "OR",
    "PERS",
    "PROC",
    "RAISE",
    "READONLY",
    "RECORD",
    "RETRY",
    "RETURN",
    "STEP",
    "SYSMODULE",
    "TASK",
    "TEST",
    "THEN",
    "TO",
    "TRAP",
    "TRUE",
    "TRYNEXT",
    "UNDO",
    "VAR",
    "VIEWONLY",
    "WHILE",
    "WITH",
    "XOR",
];

/// The names the module uses besides its entry routine (compared without
/// case, as RAPID does): the data types, instructions and predefined data
/// it names, and its own `LOCAL` data (`tWaam`, `wWaam`, `seamWaam`,
/// `jHome`); with a number after them, `p<n>`, `j<n>`, `weldWaam<k>`,
/// `loadWaam<k>`, `z<n>`.
const USED_NAMES: &[&str] = &[
    "tooldata",
    "wobjdata",
    "seamdata",
    "welddata",
    "loaddata",
    "robtarget",
    "jointtarget",
    "speeddata",
    "zonedata",
    "ConfL",
    "CirPathMode",
    "MoveAbsJ",
    "MoveL",
    "ArcLStart",
    "ArcL",
    "ArcLEnd",
    "MoveC",
    "ArcC",
    "ArcCEnd",
    "WaitTime",
    "WaitDI",
    "GripLoad",
    "ActUnit",
    "DeactUnit",
    "fine",
    "load0",
    "tool0",
    "wobj0",
    "tWaam",
    "wWaam",
    "seamWaam",
    "jHome",
    "loadsession",
    "StartLoad",
    "WaitLoad",
    "UnLoad",
    "ldWaam",
];
const NUMBERED_NAMES: &[&str] = &["p", "j", "weldWaam", "loadWaam", "z"];

/// Checks that `name` can name the module's entry routine (`PROC
/// <name>()`, global in the task) and its module (`MOD_<name>`): at most 28
/// characters (a RAPID name has 32), not a reserved word, not `main` (the
/// task's own entry routine, which calls ours), and none of the names the
/// module declares or uses (`p<n>`, `j<n>`, `tWaam`, `MoveL`, the
/// mechanical unit, the interpass signal, ...): a routine with such a name
/// would clash with the module's own data or hide an instruction. RAPID
/// names are compared without case.
///
/// # Errors
/// [`ProgramError::InvalidOptions`] naming `name`.
pub fn check_entry_name(name: &str, opts: &AbbOptions) -> Result<(), ProgramError> {
    let bad = |reason: &'static str| {
        Err(ProgramError::InvalidOptions {
            field: "name",
            value: name.to_string(),
            reason,
        })
    };
    check_name(name)?;
    if name.len() + MODULE_PREFIX.len() > 32 {
        return bad(
            "at most 28 characters for ABB: the module is MOD_<name>, a RAPID name at most 32",
        );
    }
    let is = |w: &str| name.eq_ignore_ascii_case(w);
    if RAPID_RESERVED.iter().any(|w| is(w)) {
        return bad("a RAPID reserved word cannot name the entry routine");
    }
    if is("main") {
        return bad(
            "`main` is the task's own entry routine: the program's routine must not clash with it",
        );
    }
    let numbered = NUMBERED_NAMES.iter().any(|p| {
        name.len() > p.len()
            && name[..p.len()].eq_ignore_ascii_case(p)
            && name[p.len()..].bytes().all(|b| b.is_ascii_digit())
    });
    if numbered || USED_NAMES.iter().any(|w| is(w)) || is(&opts.ufmec) || is(&opts.interpass_signal)
    {
        return bad("a name the module declares or uses (p<n>, j<n>, jHome, tWaam, wWaam, seamWaam, weldWaam<k>, loadWaam<k>, its instructions and data types, the mechanical unit, the interpass signal): the entry routine would clash with it");
    }
    Ok(())
}

/// A RAPID `loaddata` as a point mass or with principal inertia about axes
/// parallel to the frame's (`aom` identity). Plain data.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AbbLoad {
    /// Mass (kg, > 0).
    pub mass_kg: f64,
    /// Centre of gravity (mm): in the flange (wrist) frame for a tool load.
    pub cog_mm: [f64; 3],
    /// Moments of inertia about the centre of gravity, `ix iy iz`
    /// (kg·m², ≥ 0; all 0: a point mass).
    #[serde(default)]
    pub inertia_kg_m2: [f64; 3],
}

impl AbbLoad {
    /// `[mass,[x,y,z],[1,0,0,0],ix,iy,iz]` with the centre of gravity `cog`
    /// (mm, in the frame the reader expects).
    fn line(&self, cog: [f64; 3]) -> String {
        format!(
            "[{},[{},{},{}],[1,0,0,0],{},{},{}]",
            Fixed::new(self.mass_kg, 4),
            Mm(cog[0]),
            Mm(cog[1]),
            Mm(cog[2]),
            Fixed::new(self.inertia_kg_m2[0], 6),
            Fixed::new(self.inertia_kg_m2[1], 6),
            Fixed::new(self.inertia_kg_m2[2], 6),
        )
    }
}

/// Options of the ABB emitter. Plain data.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct AbbOptions {
    /// Arc instructions or user-given instructions. Default schedule 1
    /// (`arcdata.sched` of the declared `welddata`/`seamdata`).
    pub process: ProcessControl,
    /// Joint move speed to bead starts and home (mm/s of the TCP,
    /// `v_tcp`). Default 100.
    pub approach_speed_mm_s: f64,
    /// Zone inside beads (mm, one of [`PREDEFINED_ZONES_MM`]). Default 1 (`z1`).
    pub zone_mm: u32,
    /// Work object in the robot base frame (mm). Default identity. Not used
    /// with a coordinated work object (its user frame is the positioner's).
    pub base_from_user: Isometry3,
    /// Tool on the flange (`tool0`) (mm); `None`: the cell's torch; with a
    /// stationary tool the part on the flange (`flange_from_part`).
    pub flange_from_tool: Option<Isometry3>,
    /// Stationary tool and robot-held work object; `None`: in the
    /// part-carried cell only (module doc).
    pub stationary_tool: Option<bool>,
    /// With a stationary tool, the torch in the world (= robot base) frame
    /// (mm); `None`: at the cell's `D_R`, z down.
    pub fixed_tool: Option<Isometry3>,
    /// The external axes (`extjoint` fields `eax_a` .. `eax_f`, by their
    /// letter) holding the positioner's tilt `q7` and turn `q8` (deg), as
    /// the system's mechanical units are configured. Default `['a', 'b']`.
    pub positioner_axes: [char; 2],
    /// The positioner's mechanical unit (controller data, the system
    /// parameters' name) in the torch-carried cell: activated with
    /// `ActUnit <ufmec>` before the program's first motion and deactivated
    /// with `DeactUnit <ufmec>` after its last, and the `ufmec` of the
    /// coordinated work object. Default `"STN1"`.
    pub ufmec: String,
    /// The digital input signal (controller data, a RAPID name) that
    /// `[program] interpass_input = n` waits for: `WaitDI
    /// <interpass_signal>, 1` (the number `n` is written in a comment above
    /// it). Default `"diInterpass"`.
    pub interpass_signal: String,
    /// The tool load `tWaam.tload` (flange frame); `None`: module doc.
    pub tool_load: Option<AbbLoad>,
    /// Gas purge before each seam (s, finite, ≥ 0): `seamdata.purge_time`,
    /// gas through the hose and torch while the robot moves to the seam's
    /// start. Default 0.5 s (module doc: gas times).
    pub purge_time_s: f64,
    /// Gas pre-flow at the seam's start before the arc ignites (s, finite,
    /// ≥ 0): `seamdata.preflow_time`. Default 0.3 s.
    pub preflow_time_s: f64,
    /// Gas post-flow after the arc ends, shielding the cooling crater (s,
    /// finite, ≥ 0): `seamdata.postflow_time`. Default 1.5 s.
    pub postflow_time_s: f64,
    /// Most bytes of one module the controller is given at once. A build
    /// with more is cut between layers into part modules
    /// (`NAME_P01.mod`, `NAME_P02.mod`, …, [`split`](crate::program::split)),
    /// each within it, and `NAME.mod` becomes the main module whose entry
    /// routine loads, runs and unloads them in turn ([`loader`]); a layer
    /// that does not fit alone is refused. Default
    /// [`DEFAULT_MAX_FILE_BYTES`].
    pub max_file_bytes: usize,
    /// The controller folder the part modules are loaded from (a RAPID
    /// path, e.g. `HOME:` or `HOME:/waam`). Default `"HOME:"`.
    pub load_path: String,
    /// The vendor-independent options (home, dwell, interpass wait,
    /// payload, transit, coordination) the validator checks the file
    /// against; not a key of `[program.<vendor>]` (set from `[program]` by
    /// [`crate::program::ProgramSettings`]).
    #[serde(skip)]
    pub common: crate::program::ProgramOptions,
}

impl Default for AbbOptions {
    fn default() -> Self {
        Self {
            process: ProcessControl::default(),
            approach_speed_mm_s: 100.0,
            zone_mm: 1,
            base_from_user: Isometry3::identity(),
            flange_from_tool: None,
            stationary_tool: None,
            fixed_tool: None,
            positioner_axes: ['a', 'b'],
            ufmec: "STN1".into(),
            interpass_signal: "diInterpass".into(),
            tool_load: None,
            purge_time_s: DEFAULT_PURGE_TIME_S,
            preflow_time_s: DEFAULT_PREFLOW_TIME_S,
            postflow_time_s: DEFAULT_POSTFLOW_TIME_S,
            max_file_bytes: DEFAULT_MAX_FILE_BYTES,
            load_path: "HOME:".into(),
            common: Default::default(),
        }
    }
}

/// The frames of a RAPID program (robot base = world frame, mm): `tWaam`
/// is the tool (`flange_from_tool` or `base_from_tool`), `wWaam` the work
/// object (`base_from_work` or `flange_from_work`), and a `robtarget` is
/// [`ToolFrames::target`].
pub type AbbFrames = ToolFrames;

/// `true` when `s` is a RAPID identifier: a letter, then letters, digits
/// or `_`, at most 32 characters.
pub fn is_rapid_name(s: &str) -> bool {
    !s.is_empty()
        && s.len() <= 32
        && s.starts_with(|c: char| c.is_ascii_alphabetic())
        && s.chars().all(|c| c.is_ascii_alphanumeric() || c == '_')
}

impl AbbOptions {
    /// The frames written for `cell`.
    pub fn frames(&self, cell: &CellLayout) -> AbbFrames {
        ToolFrames::new(
            cell,
            self.stationary(cell),
            self.flange_from_tool,
            self.fixed_tool,
            self.base_from_user,
        )
    }

    fn stationary(&self, cell: &CellLayout) -> bool {
        self.stationary_tool
            .unwrap_or(matches!(cell, CellLayout::PartCarried(_)))
    }

    /// `true` when the work object is coordinated with the positioner's
    /// mechanical unit: `[program] coordinated`, a torch-carried cell and a
    /// robot-held tool.
    pub fn coordinated(&self, cell: &CellLayout) -> bool {
        self.common.coordinated
            && matches!(cell, CellLayout::TorchCarried(_))
            && !self.stationary(cell)
    }

    /// Checks every field.
    ///
    /// # Errors
    /// [`ProgramError::InvalidOptions`] naming the field.
    pub fn validate(&self) -> Result<(), ProgramError> {
        let bad = |field: &'static str, value: String, reason: &'static str| {
            Err(ProgramError::InvalidOptions {
                field,
                value,
                reason,
            })
        };
        if self.max_file_bytes == 0 {
            return bad("max_file_bytes", "0".into(), "must be >= 1");
        }
        if self.load_path.is_empty()
            || !self
                .load_path
                .chars()
                .all(|c| c.is_ascii_graphic() && c != '"' && c != '\\')
        {
            return bad(
                "load_path",
                self.load_path.clone(),
                "must be a non-empty controller path of printable ASCII without `\"` or `\\`",
            );
        }
        if !(self.approach_speed_mm_s.is_finite() && self.approach_speed_mm_s > 0.0) {
            return bad(
                "approach_speed_mm_s",
                self.approach_speed_mm_s.to_string(),
                "must be finite and > 0",
            );
        }
        if !PREDEFINED_ZONES_MM.contains(&self.zone_mm) {
            return bad(
                "zone_mm",
                self.zone_mm.to_string(),
                "must be a zone RobotWare predefines: 0, 1, 5, 10, 15, 20, 30, 40, 50, 60, 80, 100, 150 or 200",
            );
        }
        if !is_rapid_name(&self.ufmec) {
            return bad(
                "ufmec",
                self.ufmec.clone(),
                "a mechanical unit name: a letter, then letters, digits or `_`, at most 32 characters",
            );
        }
        if !is_rapid_name(&self.interpass_signal) {
            return bad(
                "interpass_signal",
                self.interpass_signal.clone(),
                "a signal name: a letter, then letters, digits or `_`, at most 32 characters",
            );
        }
        for (field, v) in [
            ("purge_time_s", self.purge_time_s),
            ("preflow_time_s", self.preflow_time_s),
            ("postflow_time_s", self.postflow_time_s),
        ] {
            if !(v.is_finite() && v >= 0.0) {
                return bad(field, v.to_string(), "a time in s, finite and >= 0");
            }
        }
        if let Some(l) = &self.tool_load {
            let finite = l
                .cog_mm
                .iter()
                .chain(&l.inertia_kg_m2)
                .all(|v| v.is_finite());
            if !(l.mass_kg.is_finite() && l.mass_kg > 0.0 && finite)
                || l.inertia_kg_m2.iter().any(|v| *v < 0.0)
            {
                return bad(
                    "tool_load",
                    format!("{l:?}"),
                    "mass finite and > 0 kg, centre of gravity finite, inertia finite and >= 0",
                );
            }
        }
        self.positioner_slots()?;
        self.process.validate()
    }

    /// Indices (0 = `eax_a` .. 5 = `eax_f`) of [`AbbOptions::positioner_axes`].
    ///
    /// # Errors
    /// [`ProgramError::InvalidOptions`] unless two different letters `a`–`f`.
    pub fn positioner_slots(&self) -> Result<[usize; 2], ProgramError> {
        let slot = |c: char| {
            ('a'..='f')
                .position(|l| l == c.to_ascii_lowercase())
                .ok_or(())
        };
        match (slot(self.positioner_axes[0]), slot(self.positioner_axes[1])) {
            (Ok(a), Ok(b)) if a != b => Ok([a, b]),
            _ => Err(ProgramError::InvalidOptions {
                field: "positioner_axes",
                value: format!("{:?}", self.positioner_axes),
                reason: "two different external axes among a..f (eax_a..eax_f)",
            }),
        }
    }
}

/// ABB `confdata` `[cf1, cf4, cf6, cfx]` of joints `q` (ABB convention,
/// rad) (module doc). `cfx` = 4 · (wrist centre behind axis 1) + 2 · (wrist
/// centre behind the lower arm) + (J5 < 0), ABB's table (RAPID reference,
/// `confdata`, as quoted by CEAD-group/py-opw-kinematics
/// `AXIS_CONFIGURATION.md`). "Behind the lower arm" is a joint test of the
/// elbow (J3 past the stretched-elbow angle), not the geometric elbow-down:
/// with the wrist centre behind axis 1 the usual posture is `cfx` 4 or 5,
/// not 6 or 7.
pub fn confdata(robot: &RobotModel, q: &Joints) -> [i32; 4] {
    let printed = crate::program::fmt::as_printed_rad;
    let quarter = |v: f64| (printed(v) / std::f64::consts::FRAC_PI_2).floor() as i32;
    let c = robot.configuration_of(q);
    let side = matches!(c.side, crate::robot::ArmSide::Back) as i32;
    let elbow = !crate::robot::controller::elbow_positive_cos(&c) as i32;
    let wrist = (printed(q[4]) < 0.0) as i32;
    [
        quarter(q[0]),
        quarter(q[3]),
        quarter(q[5]),
        4 * side + 2 * elbow + wrist,
    ]
}

fn pose_line(pose: &Isometry3) -> String {
    let t = pose.translation.vector;
    let q = abb_quaternion(&pose.rotation.to_rotation_matrix());
    format!(
        "[[{},{},{}],[{},{},{},{}]]",
        Mm(t.x),
        Mm(t.y),
        Mm(t.z),
        Unitless(q[0]),
        Unitless(q[1]),
        Unitless(q[2]),
        Unitless(q[3])
    )
}

/// `extjoint` with the positioner's joints (rad) in `slots`, `9E+09` elsewhere.
fn extax(e: Option<[f64; 2]>, slots: [usize; 2]) -> String {
    let mut v: [String; 6] = std::array::from_fn(|_| "9E+09".to_string());
    if let Some(e) = e {
        for (k, slot) in slots.iter().enumerate() {
            v[*slot] = Deg(e[k].to_degrees()).to_string();
        }
    }
    format!("[{}]", v.join(","))
}

/// `jointtarget` `[[J1..J6],[extax]]` (joints rad, written in degrees).
fn jointtarget(q: &Joints, e: Option<[f64; 2]>, slots: [usize; 2]) -> String {
    let a = q.map(f64::to_degrees);
    format!(
        "[[{},{},{},{},{},{}],{}]",
        Deg(a[0]),
        Deg(a[1]),
        Deg(a[2]),
        Deg(a[3]),
        Deg(a[4]),
        Deg(a[5]),
        extax(e, slots)
    )
}

/// Inline `speeddata` `[v_tcp, 500, 5000, v_reax]`, `v_tcp` rounded down to
/// its 4 written decimals (never faster than planned), `v_reax` (°/s) as
/// given (already rounded down), or 1000 °/s (no bound) when `None`.
fn speeddata(v_tcp_mm_s: f64, v_reax_deg_s: Option<f64>) -> String {
    let v_reax = v_reax_deg_s.map_or("1000".to_string(), |v| Mm(v).to_string());
    format!("[{},500,5000,{v_reax}]", Mm(floor_to(v_tcp_mm_s, 4)))
}

/// Millimetres a second in one metre a minute.
const MM_S_PER_M_MIN: f64 = 1000.0 / 60.0;

/// A wire feed (mm/s) as `arcdata.wirefeed` writes it: m/min to 4 decimals.
pub fn wirefeed_m_min(wire_feed_mm_s: f64) -> f64 {
    (wire_feed_mm_s / MM_S_PER_M_MIN * 1e4).round() / 1e4
}

/// The welddata of `program`, in order of first use: one per planned
/// travel speed and wire feed of an arc-on move (a bead's first point
/// carries its first segment's), as written: `weld_speed` rounded down to
/// 4 decimals (mm/s), `wirefeed` to 4 decimals (m/min).
fn weld_feeds(program: &Program) -> Vec<(f64, f64)> {
    let mut out: Vec<(f64, f64)> = Vec::new();
    for p in program.bead_points() {
        let v = (floor_to(p.speed_mm_s, 4), wirefeed_m_min(p.wire_feed_mm_s));
        if !out.contains(&v) {
            out.push(v);
        }
    }
    out
}

/// The frame a payload's centre of gravity is written in, from the flange
/// frame: the tool frame (robot-held tool) or the robot-held work object's
/// object frame (stationary tool), RAPID `loaddata.cog`.
fn payload_frame_from_flange(frames: &AbbFrames) -> Isometry3 {
    match frames {
        AbbFrames::Held {
            flange_from_tool, ..
        } => flange_from_tool.inverse(),
        AbbFrames::Stationary {
            flange_from_work, ..
        } => flange_from_work.inverse(),
    }
}

/// The tool load written in `tWaam` (module doc).
fn tool_load(program: &Program, opts: &AbbOptions, frames: &AbbFrames) -> AbbLoad {
    if let Some(l) = opts.tool_load {
        return l;
    }
    match frames {
        AbbFrames::Held {
            flange_from_tool, ..
        } => {
            let t = flange_from_tool.translation.vector * 0.5;
            AbbLoad {
                mass_kg: DEFAULT_TORCH_MASS_KG,
                cog_mm: [t.x, t.y, t.z],
                inertia_kg_m2: [0.0; 3],
            }
        }
        AbbFrames::Stationary { .. } => {
            let payloads = program.bead_setup.iter().any(|s| s.payload.is_some());
            if !payloads && opts.common.payload_base_kg > 0.0 {
                AbbLoad {
                    mass_kg: opts.common.payload_base_kg,
                    cog_mm: opts.common.payload_base_cog_mm,
                    inertia_kg_m2: [0.0; 3],
                }
            } else {
                LOAD0
            }
        }
    }
}

/// Writes the `.mod` of `program`.
///
/// # Errors
/// I/O errors of `w`; an error of kind `Other` wrapping
/// [`ProgramError::VendorMismatch`] when the cell's robot is not an ABB arm,
/// or [`ProgramError::InvalidOptions`] for a program name that cannot name
/// the entry routine ([`check_entry_name`]).
pub fn write_mod(w: &mut dyn Write, program: &Program, opts: &AbbOptions) -> std::io::Result<()> {
    check_vendor(&program.cell, Vendor::Abb, EMITTER).map_err(std::io::Error::other)?;
    check_entry_name(&program.name, opts).map_err(std::io::Error::other)?;
    let robot = program.cell.robot();
    let frames = opts.frames(&program.cell);
    let slots = opts.positioner_slots().map_err(std::io::Error::other)?;
    // the coordinated work object: the part on the positioner's table
    let coordinated = match (&program.cell, opts.coordinated(&program.cell)) {
        (CellLayout::TorchCarried(c), true) => Some(c),
        _ => None,
    };
    writeln!(w, "MODULE {}", module_name(&program.name))?;
    writeln!(
        w,
        "  ! waam-slicer: {}, {} points, {} beads",
        ascii_comment(program.cell.name()),
        program.points.len(),
        program.num_beads()
    )?;
    writeln!(
        w,
        "  ! entry routine {} (call it from the task's main); every other name is LOCAL to this module",
        program.name
    )?;
    let (tool_held, tool, wobj_held, wobj) = match frames {
        AbbFrames::Held {
            flange_from_tool,
            base_from_work,
        } => ("TRUE", flange_from_tool, "FALSE", base_from_work),
        AbbFrames::Stationary {
            base_from_tool,
            flange_from_work,
        } => {
            writeln!(
                w,
                "  ! stationary torch (tWaam), part held by the robot (wWaam): speeds are the torch's over the part"
            )?;
            ("FALSE", base_from_tool, "TRUE", flange_from_work)
        }
    };
    let tload = tool_load(program, opts, &frames);
    let load_note = match (opts.tool_load.is_some(), &frames) {
        (true, _) => "[program.abb] tool_load",
        (false, AbbFrames::Held { .. }) => {
            "a 3 kg torch, centre of gravity half way to the TCP: identify the real one (LoadIdentify) and set [program.abb] tool_load"
        }
        (false, AbbFrames::Stationary { .. }) => {
            if program.bead_setup.iter().any(|s| s.payload.is_some()) {
                "load0: the payload updates (GripLoad) carry the part, substrate and fixture"
            } else if opts.common.payload_base_kg > 0.0 {
                "what the robot holds: [program] payload_base_kg (no payload updates)"
            } else {
                "load0: set [program] payload_base_kg or payload_every_layers for the part the robot holds"
            }
        }
    };
    writeln!(w, "  ! tWaam.tload: {load_note}")?;
    writeln!(
        w,
        "  LOCAL PERS tooldata tWaam := [{tool_held},{},{}];",
        pose_line(&tool),
        tload.line(tload.cog_mm)
    )?;
    match coordinated {
        Some(c) => {
            writeln!(
                w,
                "  ! wWaam moves with mechanical unit {}: its user frame is the positioner's table frame (system parameters), oframe the part on the table; speeds are the torch's over the part",
                opts.ufmec
            )?;
            writeln!(
                w,
                "  LOCAL PERS wobjdata wWaam := [FALSE,FALSE,\"{}\",[[0,0,0],[1,0,0,0]],{}];",
                opts.ufmec,
                pose_line(&c.table_from_part)
            )?;
        }
        None => writeln!(
            w,
            "  LOCAL PERS wobjdata wWaam := [{wobj_held},TRUE,\"\",{},[[0,0,0],[1,0,0,0]]];",
            pose_line(&wobj)
        )?,
    }
    let weld_feeds = weld_feeds(program);
    let weld_of = |p: &crate::program::ProgramPoint| {
        let v = (floor_to(p.speed_mm_s, 4), wirefeed_m_min(p.wire_feed_mm_s));
        weld_feeds.iter().position(|s| *s == v).map_or(1, |k| k + 1)
    };
    if let ProcessControl::Arc { schedule } = &opts.process {
        writeln!(
            w,
            "  ! ArcWare data (RobotWare 6 Arc): process schedule {schedule} (arcdata.sched); one welddata per planned travel speed (weld_speed, mm/s) and wire feed (main_arc.wirefeed, m/min)"
        )?;
        let zeros = "[0,0,0,0,0,0,0,0,0]";
        let arc = format!("[{schedule},0,0,0,0,0,0,0,0]");
        let (purge, preflow, postflow) = (
            Fixed::new(opts.purge_time_s, 3),
            Fixed::new(opts.preflow_time_s, 3),
            Fixed::new(opts.postflow_time_s, 3),
        );
        writeln!(
            w,
            "  ! gas (s): purge_time {purge}, preflow_time {preflow}, postflow_time {postflow} ([program.abb] purge_time_s, preflow_time_s, postflow_time_s)"
        )?;
        writeln!(
            w,
            "  LOCAL PERS seamdata seamWaam := [{purge},{preflow},{arc},0,0,0,0,0,{zeros},0,0,{zeros},0,0,{zeros},{postflow}];"
        )?;
        for (k, (v, wfs)) in weld_feeds.iter().enumerate() {
            writeln!(
                w,
                "  LOCAL PERS welddata weldWaam{} := [{},0,[{schedule},0,0,{},0,0,0,0,0],{zeros}];",
                k + 1,
                Mm(*v),
                Fixed::new(*wfs, 4)
            )?;
        }
    }
    let cog_frame = payload_frame_from_flange(&frames);
    let mut n_loads = 0;
    for s in &program.bead_setup {
        if let Some(p) = &s.payload {
            n_loads += 1;
            let c = cog_frame * p.cog_mm;
            let l = AbbLoad {
                mass_kg: p.mass_kg,
                cog_mm: [c.x, c.y, c.z],
                inertia_kg_m2: [0.0; 3],
            };
            writeln!(
                w,
                "  LOCAL PERS loaddata loadWaam{n_loads} := {};",
                l.line(l.cog_mm)
            )?;
        }
    }
    if let Some(h) = &program.home {
        writeln!(
            w,
            "  LOCAL CONST jointtarget jHome := {};",
            jointtarget(&h.joints, h.positioner, slots)
        )?;
    }
    for (i, p) in program.points.iter().enumerate() {
        let flange = robot.flange_pose(&p.joints);
        let pose = match (coordinated, p.positioner) {
            (Some(c), Some(qp)) => {
                let AbbFrames::Held {
                    flange_from_tool, ..
                } = frames
                else {
                    unreachable!("coordinated only with a robot-held tool")
                };
                c.base_from_part(&qp).inverse() * flange * flange_from_tool
            }
            _ => frames.target(&flange),
        };
        let c = confdata(robot, &p.joints);
        let pl = pose_line(&pose);
        writeln!(
            w,
            "  LOCAL CONST robtarget p{} := [{},[{},{},{},{}],{}];",
            i + 1,
            &pl[1..pl.len() - 1],
            c[0],
            c[1],
            c[2],
            c[3],
            extax(p.positioner, slots)
        )?;
        let prev = i.checked_sub(1).map(|k| program.points[k].arc);
        if opens_bead(prev, p.arc) || p.arc == ArcFlag::Transit {
            writeln!(
                w,
                "  LOCAL CONST jointtarget j{} := {};",
                i + 1,
                jointtarget(&p.joints, p.positioner, slots)
            )?;
        }
    }
    writeln!(w, "  PROC {}()", program.name)?;
    // the positioner's unit moves only while active
    let unit = matches!(program.cell, CellLayout::TorchCarried(_)).then_some(opts.ufmec.as_str());
    if let Some(u) = unit {
        writeln!(
            w,
            "    ! positioner: mechanical unit {u} active for the program"
        )?;
        writeln!(w, "    ActUnit {u};")?;
    }
    writeln!(w, "    ConfL \\On;")?;
    if program.points.iter().any(|p| p.via) {
        // the reorientation of circular moves the checker models: from the
        // start to the end orientation in the work object's frame (slerp),
        // not RobotWare's default relative to the path
        writeln!(
            w,
            "    ! circular moves reorient the tool in the work object's frame, start to end orientation"
        )?;
        writeln!(w, "    CirPathMode \\{CIR_PATH_MODE};")?;
    }
    let tw = "tWaam\\WObj:=wWaam";
    let zone = format!("z{}", opts.zone_mm);
    let joint_speed = speeddata(opts.approach_speed_mm_s, None);
    if program.home.is_some() {
        writeln!(w, "    ! home")?;
        writeln!(w, "    MoveAbsJ jHome, {joint_speed}, fine, {tw};")?;
    }
    let abs_j =
        |w: &mut dyn Write, k: usize| writeln!(w, "    MoveAbsJ j{k}, {joint_speed}, fine, {tw};");
    let mut bead = 0;
    let mut load = 0;
    for (i, p) in program.points.iter().enumerate() {
        let k = i + 1;
        let prev = i.checked_sub(1).map(|k| &program.points[k]);
        if opens_bead(prev.map(|q| q.arc), p.arc) {
            if let Some(s) = program.bead_setup.get(bead) {
                if s.payload.is_some() {
                    load += 1;
                    writeln!(w, "    ! bead {bead} (layer {}): payload", s.layer)?;
                    writeln!(w, "    GripLoad loadWaam{load};")?;
                }
                if s.dwell_s > 0.0 {
                    writeln!(w, "    ! bead {bead} (layer {}): dwell (s)", s.layer)?;
                    writeln!(w, "    WaitTime {};", Fixed::new(ceil_to(s.dwell_s, 3), 3))?;
                }
                if let Some(n) = s.wait_input {
                    writeln!(
                        w,
                        "    ! bead {bead} (layer {}): interpass wait, [program] interpass_input {n} = signal {}",
                        s.layer, opts.interpass_signal
                    )?;
                    writeln!(w, "    WaitDI {}, 1;", opts.interpass_signal)?;
                }
            }
            bead += 1;
        }
        let mut v = speeddata(p.speed_mm_s, None);
        if coordinated.is_none() && positioner_moves(program, i) {
            // the part turns under the torch: time the move (s)
            // over the path it deposits (interpolated in the robot base
            // frame, the part turning under the TCP)
            let t = crate::program::deposited_length_mm(program, i, false) / p.speed_mm_s;
            // rounded up to the ms: never faster than planned
            let t = ceil_to(t, 3).max(0.001);
            // and bound the positioner to its planned rate (°/s), for a
            // controller that runs the move at weld_speed instead of \T
            let start = move_start(program, i).map(|k| &program.points[k]);
            let (a, b) = (
                p.positioner.unwrap_or([0.0; 2]),
                start.and_then(|q| q.positioner).unwrap_or([0.0; 2]),
            );
            let turn_deg = (a[0] - b[0]).abs().max((a[1] - b[1]).abs()).to_degrees();
            let v_reax = floor_to(turn_deg / t, 4).max(1e-4);
            v = format!(
                "{}\\T:={}",
                speeddata(p.speed_mm_s, Some(v_reax)),
                Fixed::new(t, 3)
            );
        }
        let weld = |p: &crate::program::ProgramPoint| format!("seamWaam, weldWaam{}", weld_of(p));
        // the circle point of a circular move into this point (`ArcC`,
        // `ArcCEnd`, `MoveC`: RAPID reference, "CirPoint, ToPoint"), written
        // just before it
        let circle = prev.filter(|a| a.via).map(|_| format!("p{}, ", k - 1));
        let (arc_on, arc_end, move_on) = match &circle {
            Some(_) => ("ArcC", "ArcCEnd", "MoveC"),
            None => ("ArcL", "ArcLEnd", "MoveL"),
        };
        let c = circle.as_deref().unwrap_or("");
        match (&opts.process, p.arc) {
            // written with the circular move it is the circle point of
            (_, ArcFlag::On) if p.via => {}
            (_, ArcFlag::Approach | ArcFlag::Transit) => {
                let what = if p.arc == ArcFlag::Approach {
                    "approach"
                } else {
                    "arc-off transit via point"
                };
                writeln!(
                    w,
                    "    ! bead {} (layer {}): {what}",
                    p.bead_label(),
                    p.layer
                )?;
                abs_j(w, k)?;
            }
            (_, ArcFlag::Retract) => writeln!(w, "    MoveL p{k}, {v}, fine, {tw};")?,
            (_, ArcFlag::Start) => {
                // into the bead: from the approach point at its speed, else
                // a joint move to the first point
                let v_in = match prev {
                    Some(a) if a.arc == ArcFlag::Approach => speeddata(a.speed_mm_s, None),
                    _ => {
                        writeln!(w, "    ! bead {} (layer {})", p.bead_label(), p.layer)?;
                        abs_j(w, k)?;
                        // MoveAbsJ has reached the point: the arc start is a
                        // zero-length move, never timed
                        speeddata(p.speed_mm_s, None)
                    }
                };
                match &opts.process {
                    ProcessControl::Arc { .. } => {
                        writeln!(w, "    ArcLStart p{k}, {v_in}, {}, fine, {tw};", weld(p))?
                    }
                    ProcessControl::Custom { start, .. } => {
                        writeln!(w, "    MoveL p{k}, {v_in}, fine, {tw};")?;
                        writeln!(w, "    {start};")?;
                    }
                }
            }
            (ProcessControl::Arc { .. }, ArcFlag::On) => {
                writeln!(w, "    {arc_on} {c}p{k}, {v}, {}, {zone}, {tw};", weld(p))?
            }
            (ProcessControl::Arc { .. }, ArcFlag::End) => {
                writeln!(w, "    {arc_end} {c}p{k}, {v}, {}, fine, {tw};", weld(p))?
            }
            (ProcessControl::Custom { .. }, ArcFlag::On) => {
                writeln!(w, "    {move_on} {c}p{k}, {v}, {zone}, {tw};")?
            }
            (ProcessControl::Custom { end, .. }, ArcFlag::End) => {
                writeln!(w, "    {move_on} {c}p{k}, {v}, fine, {tw};")?;
                writeln!(w, "    {end};")?;
            }
        }
    }
    if program.home.is_some() {
        writeln!(w, "    ! home")?;
        writeln!(w, "    MoveAbsJ jHome, {joint_speed}, fine, {tw};")?;
    }
    if let Some(u) = unit {
        writeln!(w, "    DeactUnit {u};")?;
    }
    writeln!(w, "  ENDPROC")?;
    writeln!(w, "ENDMODULE")?;
    Ok(())
}

/// Checks the program's home and per-bead set-up: one set-up per bead (or
/// none), finite values, masses > 0 and dwells ≥ 0.
fn check_setup(program: &Program) -> Result<(), ProgramError> {
    let beads = program.num_beads();
    let n = program.bead_setup.len();
    if n != 0 && n != beads {
        return Err(ProgramError::Mismatch {
            index: n,
            reason: format!("{n} bead set-ups for {beads} beads"),
        });
    }
    for (index, s) in program.bead_setup.iter().enumerate() {
        let bad = |field: &str| ProgramError::Mismatch {
            index,
            reason: format!(
                "bead set-up {index} (layer {}): `{field}` is invalid",
                s.layer
            ),
        };
        if !(s.dwell_s.is_finite() && s.dwell_s >= 0.0) {
            return Err(bad("dwell_s (finite, >= 0)"));
        }
        if let Some(p) = &s.payload {
            if !(p.mass_kg.is_finite() && p.mass_kg > 0.0) {
                return Err(bad("payload.mass_kg (finite, > 0)"));
            }
            if !p.cog_mm.iter().all(|v| v.is_finite()) {
                return Err(bad("payload.cog_mm (finite)"));
            }
        }
    }
    if let Some(h) = &program.home {
        let finite = h
            .joints
            .iter()
            .chain(h.positioner.iter().flatten())
            .all(|v| v.is_finite());
        if !finite {
            return Err(ProgramError::Mismatch {
                index: 0,
                reason: "home: joints are not finite".into(),
            });
        }
    }
    Ok(())
}

/// The `.mod` files of `program`: `<name>.mod`, holding `MODULE
/// MOD_<name>` with the entry routine `PROC <name>()` (module doc), when
/// it fits [`AbbOptions::max_file_bytes`]; else the main module
/// `<name>.mod` that loads, runs and unloads the part modules in turn
/// ([`loader`]), then the part modules `<name>_P01.mod`, … (groups of
/// whole beads, [`split::split_to_budget`](crate::program::split::split_to_budget)),
/// each a complete module within the budget.
///
/// # Errors
/// [`ProgramError::InvalidOptions`] for bad options (naming the field) or
/// a name that cannot name the entry routine ([`check_entry_name`], group
/// suffix included); [`ProgramError::OverBudget`] for a bead whose module
/// alone does not fit `max_file_bytes`;
/// [`ProgramError::VendorMismatch`] when the cell's robot is not an ABB arm;
/// [`ProgramError::Mismatch`] for a bead set-up list that does not fit the
/// beads or holds non-finite values.
pub fn abb_files(program: &Program, opts: &AbbOptions) -> Result<Vec<EmittedFile>, ProgramError> {
    let size = |g: &Program| -> Result<usize, ProgramError> { Ok(abb_module(g, opts)?.text.len()) };
    let parts = split_to_budget(program, &Abb::budget(opts), size)?;
    if parts.len() == 1 {
        return Ok(vec![abb_module(program, opts)?]);
    }
    let names: Vec<String> = parts.iter().map(|p| p.name.clone()).collect();
    let mut out = vec![loader::loader_file(&program.name, &names, opts)?];
    for part in &parts {
        out.push(abb_module(part, opts)?);
    }
    Ok(out)
}

/// The one module of `program`.
fn abb_module(program: &Program, opts: &AbbOptions) -> Result<EmittedFile, ProgramError> {
    check_vendor(&program.cell, Vendor::Abb, EMITTER)?;
    program.check_finite()?;
    check_setup(program)?;
    opts.validate()?;
    check_entry_name(&program.name, opts)?;
    Ok(EmittedFile {
        name: format!("{}.mod", program.name),
        text: render(|w| write_mod(w, program, opts))?,
    })
}

/// ABB RAPID `.mod` modules: the [`Controller`] implementation.
#[derive(Debug, Clone, Copy)]
pub struct Abb;

impl Controller for Abb {
    const VENDOR: Vendor = Vendor::Abb;
    const KEY: &'static str = "abb";
    const EMITTER: &'static str = EMITTER;
    const EXTENSIONS: &'static [&'static str] = &["mod"];
    type Options = AbbOptions;
    type Read = read::RapidModule;

    fn with_common(own: &AbbOptions, common: &ProgramOptions) -> AbbOptions {
        AbbOptions {
            common: *common,
            ..own.clone()
        }
    }

    fn check_options(opts: &AbbOptions) -> Result<(), ProgramError> {
        opts.validate()
    }

    fn cycle_options(opts: &AbbOptions) -> CycleOptions {
        CycleOptions {
            joint_speed_fraction: 1.0,
            joint_move_tcp_speed_mm_s: Some(opts.approach_speed_mm_s),
            // a stationary tool (part carried by default) or a work object
            // moving with the positioner: the part frame
            beads_in_part_frame: [
                opts.stationary_tool.unwrap_or(true),
                opts.common.coordinated && !opts.stationary_tool.unwrap_or(false),
            ],
            ..CycleOptions::default()
        }
    }

    fn common(opts: &AbbOptions) -> &ProgramOptions {
        &opts.common
    }

    fn budget(opts: &AbbOptions) -> Budget {
        Budget {
            field: "[program.abb] max_file_bytes",
            limit: opts.max_file_bytes,
            unit: "bytes",
        }
    }

    /// The bytes of the module (a part module of a build is resident alone
    /// beside the small main module).
    fn occupied(files: &[EmittedFile], _read: &read::RapidModule) -> usize {
        files.iter().map(|f| f.text.len()).sum()
    }

    /// The part modules in the order the main module loads them, that
    /// order checked ([`loader::read_loader`]): every part loaded, run and
    /// unloaded once, in the order of their numbers.
    fn groups(
        files: &[EmittedFile],
        report: &mut ValidationReport,
    ) -> Result<Vec<Vec<EmittedFile>>, ProgramError> {
        let (rest, groups) = groups_by_name(files)?;
        if groups.is_empty() {
            return Ok(vec![rest]);
        }
        let loaders: Vec<&EmittedFile> =
            rest.iter().filter(|f| loader::is_loader(&f.text)).collect();
        if let Some(f) = rest.iter().find(|f| !loader::is_loader(&f.text)) {
            return Err(ProgramError::Read {
                file: f.name.clone(),
                line: 0,
                reason: "neither a part module (NAME_P01, ...) nor the main module loading them"
                    .into(),
            });
        }
        if let Some(main) = loaders.first() {
            let loaded = loader::read_loader(main, report);
            let want: Vec<String> = groups
                .iter()
                .map(|g| crate::program::contract::file_stem(&g[0].name).to_string())
                .collect();
            let got: Vec<String> = loaded.iter().map(|p| p.routine.clone()).collect();
            let files: Vec<String> = loaded
                .iter()
                .map(|p| {
                    crate::program::contract::file_stem(loader::path_file(&p.path)).to_string()
                })
                .collect();
            let same = |a: &[String]| {
                a.len() == want.len() && a.iter().zip(&want).all(|(x, y)| x.eq_ignore_ascii_case(y))
            };
            if !(same(&got) && same(&files)) {
                crate::program::validate::push(
                    report,
                    crate::program::validate::ProblemKind::Call,
                    &main.name,
                    loaded.first().map_or(0, |p| p.line),
                    format!(
                        "the main module loads and calls {got:?} (files {files:?}); the build's part modules are {want:?}, in that order"
                    ),
                );
            }
        }
        Ok(groups)
    }

    fn emit(program: &Program, opts: &AbbOptions) -> Result<Vec<EmittedFile>, ProgramError> {
        abb_files(program, opts)
    }

    fn read(files: &[EmittedFile]) -> Result<read::RapidModule, ProgramError> {
        let main = files.first().ok_or_else(|| ProgramError::Read {
            file: String::new(),
            line: 0,
            reason: "no module to read".into(),
        })?;
        parse_mod(&main.text, &main.name)
    }

    /// The module at `path`; for a main module of part modules, the part
    /// modules it loads too, read from the same folder by their file names.
    fn files_on_disk(path: &Path) -> Result<Vec<EmittedFile>, ProgramError> {
        let main = read_file(path)?;
        if !loader::is_loader(&main.text) {
            return Ok(vec![main]);
        }
        let mut scratch = ValidationReport::default();
        let parts = loader::read_loader(&main, &mut scratch);
        let mut out = vec![main];
        for p in parts {
            out.push(read_file(&path.with_file_name(loader::path_file(&p.path)))?);
        }
        Ok(out)
    }

    fn main_file(read: &read::RapidModule) -> &str {
        &read.file
    }

    fn steps(
        read: &read::RapidModule,
        cell: &CellLayout,
        opts: &AbbOptions,
        report: &mut ValidationReport,
    ) -> Option<Vec<DecodedStep>> {
        decode::abb_steps(read, cell, opts, report)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::robot::ArmGeometry;

    /// An ABB IRB 1660-like arm (the OPW parameters of CEAD-group's
    /// py-opw-kinematics `axis_configuration.rs` test: a1 150, a2 −110,
    /// c1 486.5, c2 700, c3 678, c4 135 mm) on the IRB 2600's travel.
    fn irb1660() -> RobotModel {
        let mut r = RobotModel::abb_irb2600_12_185();
        r.geometry = ArmGeometry {
            shoulder_offset_mm: 150.0,
            lateral_offset_mm: 0.0,
            shoulder_height_mm: 486.5,
            upper_arm_mm: 700.0,
            elbow_offset_mm: 110.0,
            forearm_mm: 678.0,
            wrist_to_flange_mm: 135.0,
        };
        r
    }

    fn rad(d: [f64; 6]) -> Joints {
        d.map(f64::to_radians)
    }

    /// Joints written as `0.00000` (within 1e-12 rad of a quadrant edge or
    /// of J5 = 0) take the quadrant of the printed value, not the one of a
    /// rounding residue a quarter turn away.
    #[test]
    fn quadrants_follow_the_printed_value() {
        let r = RobotModel::abb_irb2600_12_185();
        let q = [
            -1e-12,
            0.3,
            0.2,
            -1e-13,
            -1e-12,
            std::f64::consts::FRAC_PI_2 - 1e-13,
        ];
        let c = confdata(&r, &q);
        assert_eq!([c[0], c[1], c[2]], [0, 0, 1]);
        assert_eq!(c[3] & 1, 0, "J5 printed 0 is not negative: cfx {}", c[3]);
    }

    /// Wrist centre behind axis 1 (J2 ≈ −85°: the upper arm leans back),
    /// elbow in its usual range: `cfx` 5 with J5 < 0 and 4 with J5 > 0
    /// (the reference's cases), where the geometric elbow (down, seen from
    /// behind) would give 7 and 6.
    #[test]
    fn cfx_behind_axis_1_follows_the_elbow_joint_test() {
        let r = irb1660();
        for (q, cfx) in [
            ([-103.1, -85.03, 19.06, -70.19, -35.87, 185.01], 5),
            ([-116.97, -85.69, 16.82, -63.5, -39.63, 192.76], 5),
            ([-124.68, -61.16, -20.4, 56.41, -38.79, -24.56], 5),
            ([-103.1, -85.03, 19.06, 109.81, 35.87, 5.01], 4),
            ([-127.36, -62.29, -16.83, -120.65, 35.14, 156.58], 4),
        ] {
            let q = rad(q);
            assert_eq!(
                r.configuration_of(&q).side,
                crate::robot::ArmSide::Back,
                "{q:?}"
            );
            assert_eq!(confdata(&r, &q)[3], cfx, "{q:?}");
            // the validator decodes cfx back to the same branch
            let c = r.configuration_of(&q);
            assert_eq!(
                crate::program::validate::arm_of(cfx & 4 != 0, cfx & 2 == 0),
                (c.side, c.elbow)
            );
        }
        // in front: the usual posture is 0/1, the elbow past stretched 2/3
        assert_eq!(confdata(&r, &rad([0.0, 0.0, 0.0, 0.0, 30.0, 0.0]))[3], 0);
        assert_eq!(confdata(&r, &rad([0.0, 0.0, 0.0, 0.0, -30.0, 0.0]))[3], 1);
        assert_eq!(
            confdata(&r, &rad([0.0, 30.0, -150.0, 0.0, 30.0, 0.0]))[3],
            2
        );
    }
}
