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
//! * Over [`FanucOptions::point_limit`] positions the program is split into
//!   numbered sub-programs and a main program calling them in order
//!   ([`split`](crate::program::split)); cuts fall between beads only, so
//!   every sub-program holds whole beads (arc start and end together).
//!
//! * With approach and retract points ([`ArcFlag::Approach`],
//!   [`ArcFlag::Retract`]) a bead is `J P[a] 10% FINE` (approach point, arc
//!   off), `L P[s] ... FINE` (into the bead), `Arc Start`, the bead, `Arc
//!   End`, `L P[r] ... FINE` (retract); the joint move from one layer's
//!   retract point to the next layer's approach point is the arc-off
//!   transition.
//!
//! Speeds are integers (mm/sec, cm/min or msec), the only form a TP motion
//! line takes without a register; speeds are rounded down and times up to
//! the unit, so that no move runs faster than planned (a joint planned at
//! its maximum speed stays within it); prefer cm/min for a finer step.
//!
//! **What the speed means.** The planned speed is the travel speed of the
//! deposition point relative to the part (what the plan and the validator
//! use). In the torch-carried cell with the torch as tool frame that is the
//! controller's TCP speed, and linear moves carry it in `mm/sec` or `cm/min`.
//! In the part-carried cell the controller's TCP (the flange, or the part
//! frame on it) is not the point that must travel at that speed: the fixed
//! torch is, relative to the part, while the flange mostly turns. A `mm/sec`
//! speed would be applied to the wrong point (and a turn of the part about
//! the torch would run at the controller's rotation speed limit). FANUC's
//! remote-TCP motion (the `RTCP` motion option, a paid software option whose
//! position data are written differently) would fix the reference point;
//! instead, by default ([`MotionTiming::Auto`]), linear moves in the
//! part-carried cell are **time-based**: `L P[n] 167msec CNT100`, the time
//! being the segment's length in the part frame divided by the planned
//! speed. This needs no option, keeps the positions as they are, and makes
//! every segment take exactly the planned time (1 ms resolution), so the
//! torch travels over the part at the planned speed on average over each
//! segment (exactly at the points; between them the controller interpolates
//! the flange pose, which for the short segments of a bead keeps the
//! deposition point within a fraction of a millimetre of the chord).
//!
//! The same holds in the torch-carried cell on a segment where the
//! positioner turns: the part moves under the torch, the TCP's travel in
//! the robot frame is not the deposition point's travel over the part (the
//! TCP may be nearly still while the part turns 45°), and a TCP speed would
//! be wrong. [`MotionTiming::Auto`] writes every such segment time-based
//! (segment length in the part frame / planned speed) and keeps `mm/sec`
//! or `cm/min` where the positioner is still.

use std::io::Write;

use serde::{Deserialize, Serialize};

use crate::math::Isometry3;
use crate::program::fmt::{ascii_comment, ceil_to, floor_to, FanucDeg, FanucMm};
use crate::program::frames::held_tool;
use crate::program::split::{chunks, sub_name, DEFAULT_POINT_LIMIT};
use crate::program::{
    check_name, check_vendor, joint_move_target, positioner_moves, render, segment_length_mm,
    ArcFlag, EmittedFile, ProcessControl, Program, ProgramError,
};
use crate::robot::orientation::FanucPose;
use crate::robot::{Cell, Joints, Vendor};

/// The emitter's name in [`ProgramError::VendorMismatch`].
pub const EMITTER: &str = "FANUC TP";

/// Distance (deg) from a turn-number edge (an odd multiple of 180°) of J1,
/// J4 or J6 within which a Cartesian position is written in joint
/// representation (module doc). Far above the joint error of re-solving a
/// pose printed to 0.001 mm and 0.0001° (about 1e-4°).
pub const TURN_EDGE_DEG: f64 = 0.01;

/// `true` when J1, J4 or J6 of `q` (rad) is within [`TURN_EDGE_DEG`] of an
/// odd multiple of 180°.
pub fn near_turn_edge(q: &Joints) -> bool {
    [0, 3, 5].iter().any(|&j| {
        let r = (q[j].to_degrees() - 180.0).rem_euclid(360.0);
        r.min(360.0 - r) < TURN_EDGE_DEG
    })
}

/// The remark opening a program with time-based linear moves (≤ 32 characters).
pub const TIME_BASED_REMARK: &str = "TIMED: TORCH SPEED OVER PART";

/// How positions are written.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum PositionMode {
    /// `J1..J6` in degrees (the thesis's articular mode: the branch is ours).
    #[default]
    Joint,
    /// `X Y Z W P R` with configuration string and turn numbers.
    Cartesian,
}

/// Unit of linear speeds.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum SpeedUnit {
    /// `mm/sec`.
    MmPerSec,
    /// `cm/min` (the unit of the thesis's process tables).
    #[default]
    CmPerMin,
}

/// How linear moves carry their speed (module doc, "What the speed means").
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum MotionTiming {
    /// Time-based (`msec`) in the part-carried cell; in the torch-carried
    /// cell time-based on every segment where the positioner moves
    /// ([`positioner_moves`]), TCP speed
    /// elsewhere.
    #[default]
    Auto,
    /// TCP speed (`mm/sec` or `cm/min`) everywhere: only right in the
    /// part-carried cell if the controller moves relative to the fixed torch
    /// (remote TCP).
    TcpSpeed,
    /// Segment times (`msec`) everywhere.
    Time,
}

/// Options of the FANUC emitter. Plain data.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct FanucOptions {
    /// Joint or Cartesian positions. Default joint.
    pub positions: PositionMode,
    /// Unit of the linear speeds. Default cm/min.
    pub speed_unit: SpeedUnit,
    /// Speeds or segment times on linear moves. Default
    /// [`MotionTiming::Auto`].
    pub timing: MotionTiming,
    /// `CNT` value (0–100) of the blended moves inside a bead. Default 100.
    pub cnt: u8,
    /// Joint speed of the move to each bead's approach point (or first point
    /// without approach points) (%, 1–100). Default 10.
    pub approach_percent: u8,
    /// Arc instructions or user-given start/end lines. Default `Arc Start[1]`.
    pub process: ProcessControl,
    /// `UFRAME_NUM` (0 = world). Default 0.
    pub user_frame: u8,
    /// `UTOOL_NUM` (1–10). Default 1.
    pub tool_frame: u8,
    /// The user frame's pose in the robot base frame, as stored in the
    /// controller's `UFRAME[user_frame]` (mm). Default identity.
    pub base_from_user: Isometry3,
    /// The tool frame on the flange, as stored in `UTOOL[tool_frame]` (mm).
    /// `None`: the cell's torch (`flange_from_tcp`) in the torch-carried
    /// cell, the flange itself in the part-carried cell.
    pub flange_from_tool: Option<Isometry3>,
    /// Most positions in one program; more are split into sub-programs of
    /// whole beads, so it must be at least the longest bead's point count
    /// (approach and retract included). Default 15 000 (R-30iB Plus).
    pub point_limit: usize,
    /// The vendor-independent options (home, dwell, interpass wait,
    /// payload, transit, coordination) the validator checks the file
    /// against; not a key of `[program.<vendor>]` (set from `[program]` by
    /// [`crate::program::ProgramSettings`]).
    #[serde(skip)]
    pub common: crate::program::ProgramOptions,
}

impl Default for FanucOptions {
    fn default() -> Self {
        Self {
            positions: PositionMode::Joint,
            speed_unit: SpeedUnit::CmPerMin,
            timing: MotionTiming::Auto,
            cnt: 100,
            approach_percent: 10,
            process: ProcessControl::default(),
            user_frame: 0,
            tool_frame: 1,
            base_from_user: Isometry3::identity(),
            flange_from_tool: None,
            point_limit: DEFAULT_POINT_LIMIT,
            common: Default::default(),
        }
    }
}

impl FanucOptions {
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
        if self.cnt > 100 {
            return Err(bad("cnt", self.cnt.to_string(), "must be in 0..=100"));
        }
        if !(1..=100).contains(&self.approach_percent) {
            return Err(bad(
                "approach_percent",
                self.approach_percent.to_string(),
                "must be in 1..=100",
            ));
        }
        if self.user_frame > 9 {
            return Err(bad(
                "user_frame",
                self.user_frame.to_string(),
                "must be in 0..=9",
            ));
        }
        if !(1..=10).contains(&self.tool_frame) {
            return Err(bad(
                "tool_frame",
                self.tool_frame.to_string(),
                "must be in 1..=10",
            ));
        }
        if self.point_limit == 0 {
            return Err(bad("point_limit", "0".into(), "must be >= 1"));
        }
        self.process.validate()
    }

    /// `true` when every linear move is written as a segment time in
    /// `cell` (see [`FanucOptions::segment_time_based`] for single
    /// segments).
    pub fn time_based(&self, cell: &Cell) -> bool {
        match self.timing {
            MotionTiming::Auto => matches!(cell, Cell::PartCarried(_)),
            MotionTiming::TcpSpeed => false,
            MotionTiming::Time => true,
        }
    }

    /// `true` when the linear move into point `i` of `program` is written
    /// as a segment time: [`FanucOptions::time_based`], or with
    /// [`MotionTiming::Auto`] a segment where the positioner moves.
    pub fn segment_time_based(&self, program: &Program, i: usize) -> bool {
        self.time_based(&program.cell)
            || (self.timing == MotionTiming::Auto && positioner_moves(program, i))
    }

    /// The tool frame used for Cartesian positions in `cell` (mm).
    pub fn tool_in(&self, cell: &Cell) -> Isometry3 {
        held_tool(cell, self.flange_from_tool)
    }
}

/// A motion's speed as written.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Speed {
    /// Joint move, percent of the maximum.
    Percent(u32),
    /// Linear, mm/sec.
    MmPerSec(u32),
    /// Linear, cm/min.
    CmPerMin(u32),
    /// Time-based, the move takes this many milliseconds.
    Msec(u32),
}

impl Speed {
    /// Linear speed (mm/s), `None` for a percentage or a time.
    pub fn mm_s(&self) -> Option<f64> {
        match self {
            Speed::Percent(_) | Speed::Msec(_) => None,
            Speed::MmPerSec(v) => Some(*v as f64),
            Speed::CmPerMin(v) => Some(*v as f64 / 6.0),
        }
    }

    /// Duration of a time-based move (s).
    pub fn time_s(&self) -> Option<f64> {
        match self {
            Speed::Msec(v) => Some(*v as f64 / 1000.0),
            _ => None,
        }
    }
}

impl std::fmt::Display for Speed {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Speed::Percent(v) => write!(f, "{v}%"),
            Speed::MmPerSec(v) => write!(f, "{v}mm/sec"),
            Speed::CmPerMin(v) => write!(f, "{v}cm/min"),
            Speed::Msec(v) => write!(f, "{v}msec"),
        }
    }
}

/// Motion termination.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Termination {
    /// Exact stop.
    Fine,
    /// Blended, `CNT0`–`CNT100`.
    Cnt(u8),
}

impl std::fmt::Display for Termination {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Termination::Fine => write!(f, "FINE"),
            Termination::Cnt(c) => write!(f, "CNT{c}"),
        }
    }
}

/// Joint (`J`) or linear (`L`) move.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MoveKind {
    /// `J`.
    Joint,
    /// `L`.
    Linear,
}

/// One `/MN` instruction.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Op {
    /// `UFRAME_NUM=n`.
    UFrame(u8),
    /// `UTOOL_NUM=n`.
    UTool(u8),
    /// `J P[n] ...` / `L P[n] ...`; `position` is the `P[]` index in this program.
    Move {
        /// J or L.
        kind: MoveKind,
        /// `P[]` index (1-based) in this program.
        position: usize,
        /// Speed.
        speed: Speed,
        /// Termination.
        term: Termination,
    },
    /// `Arc Start[n]`.
    ArcStart(u32),
    /// `Arc End[n]`.
    ArcEnd(u32),
    /// `CALL NAME`.
    Call(String),
    /// `! remark` (a comment line).
    Remark(String),
    /// Any other instruction, as written (user-given start/end lines).
    Other(String),
}

impl std::fmt::Display for Op {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Op::UFrame(n) => write!(f, "  UFRAME_NUM={n} ;"),
            Op::UTool(n) => write!(f, "  UTOOL_NUM={n} ;"),
            Op::Move {
                kind,
                position,
                speed,
                term,
            } => {
                let k = match kind {
                    MoveKind::Joint => 'J',
                    MoveKind::Linear => 'L',
                };
                write!(f, "{k} P[{position}] {speed} {term}    ;")
            }
            Op::ArcStart(n) => write!(f, "  Arc Start[{n}] ;"),
            Op::ArcEnd(n) => write!(f, "  Arc End[{n}] ;"),
            Op::Call(n) => write!(f, "  CALL {n}    ;"),
            Op::Remark(s) => write!(f, "  ! {} ;", ascii_comment(s)),
            Op::Other(s) => write!(f, "  {s} ;"),
        }
    }
}

/// One instruction with the file line it was read from (0 when generated).
#[derive(Debug, Clone, PartialEq)]
pub struct Instruction {
    /// File line (1-based), 0 if generated.
    pub line: usize,
    /// The instruction.
    pub op: Op,
}

/// Group 1 (the arm) of a position.
#[derive(Debug, Clone, PartialEq)]
pub enum ArmPosition {
    /// `J1..J6` (deg).
    Joint([f64; 6]),
    /// `X Y Z W P R` (mm, deg) of the tool frame in the user frame, and the
    /// `CONFIG` string (`F U T, 0, 0, 1`).
    Cartesian {
        /// `[X, Y, Z, W, P, R]` (mm, deg).
        xyzwpr: [f64; 6],
        /// The configuration string without quotes.
        config: String,
    },
}

/// One `/POS` record.
#[derive(Debug, Clone, PartialEq)]
pub struct Position {
    /// `P[]` index (1-based).
    pub index: usize,
    /// `UF` and `UT` of group 1.
    pub uf_ut: (u8, u8),
    /// The arm.
    pub arm: ArmPosition,
    /// Group 2 (positioner) `J1 J2` (deg), if present.
    pub group2: Option<[f64; 2]>,
    /// File line of `P[n]{` (0 if generated).
    pub line: usize,
    /// File line of each of the six group-1 values (0 if generated).
    pub value_lines: [usize; 6],
    /// File line of group 2's values (0 if generated or absent).
    pub group2_line: usize,
}

/// A TP program as data: what [`write_ls`] prints and
/// [`parse_ls`](crate::program::readback::parse_ls) reads.
#[derive(Debug, Clone, PartialEq)]
pub struct TpProgram {
    /// `/PROG` name.
    pub name: String,
    /// `/ATTR COMMENT` (at most [`COMMENT_MAX`] characters: `waam-slicer`,
    /// `waam: 3 parts` for a main program, `waam: 1 of 3` for a
    /// sub-program).
    pub comment: String,
    /// Motion groups in use (1 or 2).
    pub groups: usize,
    /// `/APPL` arc welding section present.
    pub arc_welding: bool,
    /// `/MN`.
    pub instructions: Vec<Instruction>,
    /// `/POS`, in index order.
    pub positions: Vec<Position>,
}

/// The FANUC programs of `program`: one program when it has at most
/// `opts.point_limit` points, else the main program (first, named
/// `program.name`) and its sub-programs `NAME_001`, `NAME_002`, ... of
/// whole beads ([`split::chunks`](crate::program::split::chunks)).
///
/// # Errors
/// [`ProgramError::InvalidOptions`] for bad options, a name too long for
/// the sub-program suffix, or a bead longer than the point limit (field
/// `point_limit`, naming the layer); [`ProgramError::VendorMismatch`] when the
/// cell's robot is not a FANUC arm.
pub fn tp_programs(program: &Program, opts: &FanucOptions) -> Result<Vec<TpProgram>, ProgramError> {
    check_vendor(&program.cell, Vendor::Fanuc, EMITTER)?;
    program.check_finite()?;
    opts.validate()?;
    check_name(&program.name)?;
    let robot = program.cell.robot();
    let tool = opts.tool_in(&program.cell);
    let user_from_base = opts.base_from_user.inverse();
    let groups = if program.points.iter().any(|p| p.positioner.is_some()) {
        2
    } else {
        1
    };
    let arc_welding = matches!(opts.process, ProcessControl::Arc { .. });
    let (start_op, end_op) = match &opts.process {
        ProcessControl::Arc { schedule } => (Op::ArcStart(*schedule), Op::ArcEnd(*schedule)),
        ProcessControl::Custom { start, end } => (Op::Other(start.clone()), Op::Other(end.clone())),
    };
    // the segment time of the linear move into point `i` at `v` mm/s,
    // rounded up: never faster than planned (a joint at its maximum speed
    // stays within it)
    let timed = |i: usize, v: f64| {
        let ms = 1000.0 * segment_length_mm(program, i) / v;
        Speed::Msec((ceil_to(ms, 0) as u32).max(1))
    };
    // the speed of the linear move into point `i` at `v` mm/s: rounded down
    // (never faster than planned); a speed below the unit's step is written
    // as the segment time rather than raised to 1
    let linear_speed = |i: usize, v: f64| {
        if opts.segment_time_based(program, i) {
            return timed(i, v);
        }
        let (n, speed): (f64, fn(u32) -> Speed) = match opts.speed_unit {
            SpeedUnit::MmPerSec => (floor_to(v, 0), Speed::MmPerSec),
            SpeedUnit::CmPerMin => (floor_to(v * 6.0, 0), Speed::CmPerMin),
        };
        if n >= 1.0 {
            speed(n as u32)
        } else {
            timed(i, v)
        }
    };
    let arcs: Vec<ArcFlag> = program.points.iter().map(|p| p.arc).collect();
    let ranges = chunks(&arcs, opts.point_limit).map_err(|b| ProgramError::InvalidOptions {
        field: "point_limit",
        value: format!(
            "{} (the bead of layer {} has {} points with its approach and retract)",
            opts.point_limit, program.points[b.first].layer, b.len
        ),
        reason: "a sub-program holds whole beads: the limit must be at least the longest bead's point count",
    })?;
    let split = ranges.len() > 1;
    let mut out = Vec::new();
    if split {
        let names: Vec<String> = (1..=ranges.len())
            .map(|k| sub_name(&program.name, k))
            .collect();
        check_name(names.last().expect("at least two chunks"))?;
        out.push(TpProgram {
            name: program.name.clone(),
            comment: attr_comment(&format!("waam: {} parts", ranges.len())),
            groups,
            arc_welding,
            instructions: names
                .into_iter()
                .map(|n| Instruction {
                    line: 0,
                    op: Op::Call(n),
                })
                .collect(),
            positions: Vec::new(),
        });
    }
    for (k, range) in ranges.iter().enumerate() {
        let mut ins = vec![
            Instruction {
                line: 0,
                op: Op::UFrame(opts.user_frame),
            },
            Instruction {
                line: 0,
                op: Op::UTool(opts.tool_frame),
            },
        ];
        if range
            .clone()
            .any(|i| !joint_move_target(program, i) && opts.segment_time_based(program, i))
        {
            ins.push(Instruction {
                line: 0,
                op: Op::Remark(TIME_BASED_REMARK.into()),
            });
        }
        let mut positions = Vec::with_capacity(range.len());
        for (local, p) in program.points[range.clone()].iter().enumerate() {
            let index = local + 1;
            let global = range.start + local;
            let prev = global.checked_sub(1).map(|g| &program.points[g]);
            let arm = match opts.positions {
                PositionMode::Cartesian if !near_turn_edge(&p.joints) => {
                    let pose = user_from_base * robot.flange_pose(&p.joints) * tool;
                    ArmPosition::Cartesian {
                        xyzwpr: FanucPose::from_isometry(&pose).to_xyzwpr_deg(),
                        config: robot.fanuc_config(&p.joints).to_string(),
                    }
                }
                _ => ArmPosition::Joint(p.joints.map(f64::to_degrees)),
            };
            positions.push(Position {
                index,
                uf_ut: (opts.user_frame, opts.tool_frame),
                arm,
                group2: p.positioner.map(|q| q.map(f64::to_degrees)),
                line: 0,
                value_lines: [0; 6],
                group2_line: 0,
            });
            let mv = |kind, speed, term| Instruction {
                line: 0,
                op: Op::Move {
                    kind,
                    position: index,
                    speed,
                    term,
                },
            };
            let joint_move = || {
                mv(
                    MoveKind::Joint,
                    Speed::Percent(opts.approach_percent as u32),
                    Termination::Fine,
                )
            };
            match p.arc {
                ArcFlag::Approach => ins.push(joint_move()),
                ArcFlag::Start => {
                    ins.push(match prev {
                        Some(a) if a.arc == ArcFlag::Approach => mv(
                            MoveKind::Linear,
                            linear_speed(global, a.speed_mm_s),
                            Termination::Fine,
                        ),
                        _ => joint_move(),
                    });
                    ins.push(Instruction {
                        line: 0,
                        op: start_op.clone(),
                    });
                }
                ArcFlag::On => ins.push(mv(
                    MoveKind::Linear,
                    linear_speed(global, p.speed_mm_s),
                    Termination::Cnt(opts.cnt),
                )),
                ArcFlag::End => {
                    ins.push(mv(
                        MoveKind::Linear,
                        linear_speed(global, p.speed_mm_s),
                        Termination::Fine,
                    ));
                    ins.push(Instruction {
                        line: 0,
                        op: end_op.clone(),
                    });
                }
                ArcFlag::Retract => ins.push(mv(
                    MoveKind::Linear,
                    linear_speed(global, p.speed_mm_s),
                    Termination::Fine,
                )),
            }
        }
        out.push(TpProgram {
            name: if split {
                sub_name(&program.name, k + 1)
            } else {
                program.name.clone()
            },
            comment: attr_comment(&if split {
                format!("waam: {} of {}", k + 1, ranges.len())
            } else {
                "waam-slicer".into()
            }),
            groups,
            arc_welding,
            instructions: ins,
            positions,
        });
    }
    Ok(out)
}

/// Longest `/ATTR COMMENT` a TP program takes (characters).
pub const COMMENT_MAX: usize = 16;

/// `s` cut to [`COMMENT_MAX`] characters.
fn attr_comment(s: &str) -> String {
    s.chars().take(COMMENT_MAX).collect()
}

/// Writes one TP program as ASCII `.ls`.
///
/// # Errors
/// I/O errors of `w`.
pub fn write_ls(w: &mut dyn Write, tp: &TpProgram) -> std::io::Result<()> {
    writeln!(w, "/PROG  {}", tp.name)?;
    writeln!(w, "/ATTR")?;
    writeln!(w, "OWNER\t\t= MNEDITOR;")?;
    writeln!(w, "COMMENT\t\t= \"{}\";", ascii_comment(&tp.comment))?;
    writeln!(w, "PROG_SIZE\t= 0;")?;
    writeln!(w, "CREATE\t\t= DATE 00-01-01  TIME 00:00:00;")?;
    writeln!(w, "MODIFIED\t= DATE 00-01-01  TIME 00:00:00;")?;
    writeln!(w, "FILE_NAME\t= ;")?;
    writeln!(w, "VERSION\t\t= 0;")?;
    writeln!(w, "LINE_COUNT\t= {};", tp.instructions.len())?;
    writeln!(w, "MEMORY_SIZE\t= 0;")?;
    writeln!(w, "PROTECT\t\t= READ_WRITE;")?;
    writeln!(w, "TCD:  STACK_SIZE\t= 0,")?;
    writeln!(w, "      TASK_PRIORITY\t= 50,")?;
    writeln!(w, "      TIME_SLICE\t= 0,")?;
    writeln!(w, "      BUSY_LAMP_OFF\t= 0,")?;
    writeln!(w, "      ABORT_REQUEST\t= 0,")?;
    writeln!(w, "      PAUSE_REQUEST\t= 0;")?;
    let groups = if tp.groups >= 2 {
        "1,1,*,*,*"
    } else {
        "1,*,*,*,*"
    };
    writeln!(w, "DEFAULT_GROUP\t= {groups};")?;
    writeln!(w, "CONTROL_CODE\t= 00000000 00000000;")?;
    if tp.arc_welding {
        writeln!(w, "/APPL")?;
        writeln!(w, "  ARC Welding Equipment : 1,*,*,*,*;")?;
    }
    writeln!(w, "/MN")?;
    for (i, ins) in tp.instructions.iter().enumerate() {
        writeln!(w, "{:>4}:{}", i + 1, ins.op)?;
    }
    writeln!(w, "/POS")?;
    for p in &tp.positions {
        writeln!(w, "P[{}]{{", p.index)?;
        writeln!(w, "   GP1:")?;
        let (uf, ut) = p.uf_ut;
        match &p.arm {
            ArmPosition::Joint(j) => {
                writeln!(w, "\tUF : {uf}, UT : {ut},\t")?;
                writeln!(
                    w,
                    "\tJ1= {} deg,\tJ2= {} deg,\tJ3= {} deg,",
                    FanucDeg(j[0]),
                    FanucDeg(j[1]),
                    FanucDeg(j[2])
                )?;
                writeln!(
                    w,
                    "\tJ4= {} deg,\tJ5= {} deg,\tJ6= {} deg",
                    FanucDeg(j[3]),
                    FanucDeg(j[4]),
                    FanucDeg(j[5])
                )?;
            }
            ArmPosition::Cartesian { xyzwpr: v, config } => {
                writeln!(w, "\tUF : {uf}, UT : {ut},\t\tCONFIG : '{config}',")?;
                writeln!(
                    w,
                    "\tX = {}  mm,\tY = {}  mm,\tZ = {}  mm,",
                    FanucMm(v[0]),
                    FanucMm(v[1]),
                    FanucMm(v[2])
                )?;
                writeln!(
                    w,
                    "\tW = {} deg,\tP = {} deg,\tR = {} deg",
                    FanucDeg(v[3]),
                    FanucDeg(v[4]),
                    FanucDeg(v[5])
                )?;
            }
        }
        if let Some(g) = p.group2 {
            writeln!(w, "   GP2:")?;
            writeln!(w, "\tUF : {uf}, UT : {ut},\t")?;
            writeln!(
                w,
                "\tJ1= {} deg,\tJ2= {} deg",
                FanucDeg(g[0]),
                FanucDeg(g[1])
            )?;
        }
        writeln!(w, "}};")?;
    }
    writeln!(w, "/END")?;
    Ok(())
}

/// The `.ls` files of `program` (main program first when split).
///
/// # Errors
/// As [`tp_programs`].
pub fn fanuc_files(
    program: &Program,
    opts: &FanucOptions,
) -> Result<Vec<EmittedFile>, ProgramError> {
    tp_programs(program, opts)?
        .iter()
        .map(|tp| {
            Ok(EmittedFile {
                name: format!("{}.ls", tp.name),
                text: render(|w| write_ls(w, tp))?,
            })
        })
        .collect()
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
