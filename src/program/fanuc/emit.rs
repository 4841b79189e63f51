//! FANUC TP writer: the program model of a `.ls` file ([`TpProgram`],
//! [`Instruction`], [`Op`], [`Position`]), the builder from a [`Program`]
//! ([`tp_programs`]) and the ASCII writer ([`write_ls`], [`fanuc_files`]).
//! Stage 7 (controller programs); the [vendor module](super) describes the
//! format.

use std::io::Write;

use crate::math::Isometry3;
use crate::program::contract::Controller;
use crate::program::fanuc::options::{is_identity, FanucFrames, FanucOptions, SpeedUnit};
use crate::program::fanuc::{Fanuc, EMITTER};
use crate::program::fmt::{ascii_comment, ceil_to, floor_to, FanucDeg, FanucMm, Fixed};
use crate::program::kinds::{MoveKind, PositionMode};
use crate::program::pose::moves_in_part_frame;
use crate::program::split::split_to_budget;
use crate::program::{
    check_name, check_vendor, deposited_length_mm, joint_move_target, move_start, opens_bead,
    render, segment_length_mm, ArcFlag, EmittedFile, ProcessControl, Program, ProgramError,
};
use crate::robot::orientation::FanucPose;
use crate::robot::{CellLayout, Joints, Vendor};

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

/// Prefix of the remarks stating a frame: `UF` (user frame) or `UT` (tool
/// frame).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum FrameKind {
    /// `UFRAME[n]`, remarks `UFn ...`.
    User,
    /// `UTOOL[n]`, remarks `UTn ...`.
    Tool,
}

impl FrameKind {
    fn prefix(self) -> &'static str {
        match self {
            FrameKind::User => "UF",
            FrameKind::Tool => "UT",
        }
    }
}

const AXES: [char; 6] = ['X', 'Y', 'Z', 'W', 'P', 'R'];

/// The three remarks stating frame `n` = `pose` in FANUC `X,Y,Z,W,P,R` (mm,
/// deg, 3 decimals), each at most 32 characters: `UF1 X,Y=1045.747,-630.155`,
/// `UF1 Z,W=653.167,180.000`, `UF1 P,R=0.000,0.000`.
pub fn frame_remarks(kind: FrameKind, n: u8, pose: &Isometry3) -> [String; 3] {
    let v = FanucPose::from_isometry(pose).to_xyzwpr_deg();
    let line = |a: usize| {
        format!(
            "{}{n} {},{}={},{}",
            kind.prefix(),
            AXES[a],
            AXES[a + 1],
            Fixed::new(v[a], 3),
            Fixed::new(v[a + 1], 3)
        )
    };
    [line(0), line(2), line(4)]
}

/// One remark of [`frame_remarks`] read back: the frame, the indices
/// (0–5 = X..R) of its two values, and the values (mm, deg).
pub fn parse_frame_remark(s: &str) -> Option<(FrameKind, u8, [usize; 2], [f64; 2])> {
    let s = s.trim();
    let (kind, rest) = if let Some(r) = s.strip_prefix("UF") {
        (FrameKind::User, r)
    } else {
        (FrameKind::Tool, s.strip_prefix("UT")?)
    };
    let (n, rest) = rest.split_once(' ')?;
    let n: u8 = n.parse().ok()?;
    let (names, values) = rest.trim().split_once('=')?;
    let (a, b) = names.split_once(',')?;
    let axis = |t: &str| {
        let mut c = t.trim().chars();
        let ch = c.next()?;
        if c.next().is_some() {
            return None;
        }
        AXES.iter().position(|x| *x == ch)
    };
    let (va, vb) = values.split_once(',')?;
    let num = |t: &str| t.trim().parse::<f64>().ok().filter(|x| x.is_finite());
    Some((kind, n, [axis(a)?, axis(b)?], [num(va)?, num(vb)?]))
}

/// Motion options written after the termination type.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct MotionOptions {
    /// `COORD`: coordinated with the leader group (the positioner): the
    /// speed is relative to it.
    pub coord: bool,
    /// `RTCP`: remote TCP: the speed is the relative speed between the
    /// workpiece (on the flange) and the fixed tool (the user frame).
    pub rtcp: bool,
}

/// A field of a payload schedule `$PLST_GRP1[n]` (FANUC units: kg, cm).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum PayloadField {
    /// `$PAYLOAD`: mass (kg).
    Mass,
    /// `$PAYLOAD_X`: centre of gravity X, faceplate frame (cm).
    X,
    /// `$PAYLOAD_Y` (cm).
    Y,
    /// `$PAYLOAD_Z` (cm).
    Z,
}

impl PayloadField {
    /// Every field, in the order they are written.
    pub const ALL: [PayloadField; 4] = [Self::Mass, Self::X, Self::Y, Self::Z];

    /// The system variable's field name.
    pub fn name(self) -> &'static str {
        match self {
            Self::Mass => "$PAYLOAD",
            Self::X => "$PAYLOAD_X",
            Self::Y => "$PAYLOAD_Y",
            Self::Z => "$PAYLOAD_Z",
        }
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

/// One `/MN` instruction.
#[derive(Debug, Clone, PartialEq)]
pub enum Op {
    /// `UFRAME_NUM=n`.
    UFrame(u8),
    /// `UTOOL_NUM=n`.
    UTool(u8),
    /// `J P[n] ...` / `L P[n] ...`, or a circular move written on two
    /// lines, `C P[v]` then `:  P[n] ...` (FANUC TP, "Circular motion": the
    /// via point on the `C` line, the end point, speed, termination and
    /// options on the continuation line); `position` is the `P[]` index in
    /// this program.
    Move {
        /// J, L or C ([`MoveKind::Circular`]).
        kind: MoveKind,
        /// `P[]` index (1-based) in this program.
        position: usize,
        /// The via point's `P[]` index of a circular move (`None` otherwise).
        via: Option<usize>,
        /// Speed.
        speed: Speed,
        /// Termination.
        term: Termination,
        /// Motion options (`COORD`, `RTCP`).
        options: MotionOptions,
    },
    /// `Arc Start[n]`.
    ArcStart(u32),
    /// `Arc End[n]`.
    ArcEnd(u32),
    /// `Weld Start[procedure,schedule]`.
    WeldStart(u32, u32),
    /// `Weld End[procedure,schedule]`.
    WeldEnd(u32, u32),
    /// `WAIT x.xx(sec)`: a dwell (s, 0.01 s steps).
    WaitTime(f64),
    /// `WAIT DI[n]=ON`: wait for a digital input.
    WaitInput(u32),
    /// `$PLST_GRP1[schedule].<field>=value`: one value of a payload
    /// schedule (kg or cm, [`PayloadField`]).
    PayloadValue {
        /// Payload schedule (1–10).
        schedule: u8,
        /// The field.
        field: PayloadField,
        /// The value (kg or cm).
        value: f64,
    },
    /// `PAYLOAD[n]`: select payload schedule `n`.
    Payload(u8),
    /// `CALL NAME`.
    Call(String),
    /// `! remark` (a comment line).
    Remark(String),
    /// Any other instruction, as written (user-given start/end lines).
    Other(String),
}

/// `t` (s) as a TP `WAIT` time: two decimals, no leading zero below 1 s
/// (`.50`), right-aligned in 6 characters, as the controller prints it.
fn wait_seconds(t: f64) -> String {
    let s = format!("{}", Fixed::new(t, 2));
    let s = s
        .strip_prefix('0')
        .filter(|r| r.starts_with('.'))
        .map_or(s.clone(), String::from);
    format!("{s:>6}")
}

impl std::fmt::Display for Op {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Op::UFrame(n) => write!(f, "  UFRAME_NUM={n} ;"),
            Op::UTool(n) => write!(f, "  UTOOL_NUM={n} ;"),
            Op::Move {
                kind,
                position,
                via,
                speed,
                term,
                options,
            } => {
                match (kind, via) {
                    (MoveKind::Joint, _) => write!(f, "J ")?,
                    (MoveKind::Circular, Some(v)) => write!(f, "C P[{v}]    \n    :  ")?,
                    _ => write!(f, "L ")?,
                }
                write!(f, "P[{position}] {speed} {term}")?;
                if options.coord {
                    write!(f, " COORD")?;
                }
                if options.rtcp {
                    write!(f, " RTCP")?;
                }
                write!(f, "    ;")
            }
            Op::ArcStart(n) => write!(f, "  Arc Start[{n}] ;"),
            Op::ArcEnd(n) => write!(f, "  Arc End[{n}] ;"),
            Op::WeldStart(p, s) => write!(f, "  Weld Start[{p},{s}] ;"),
            Op::WeldEnd(p, s) => write!(f, "  Weld End[{p},{s}] ;"),
            Op::WaitTime(t) => write!(f, "  WAIT {}(sec) ;", wait_seconds(*t)),
            Op::WaitInput(n) => write!(f, "  WAIT DI[{n}]=ON    ;"),
            Op::PayloadValue {
                schedule,
                field,
                value,
            } => write!(
                f,
                "  $PLST_GRP1[{schedule}].{}={} ;",
                field.name(),
                Fixed::new(*value, 3)
            ),
            Op::Payload(n) => write!(f, "  PAYLOAD[{n}] ;"),
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
/// [`parse_ls`](super::read::parse_ls) reads.
#[derive(Debug, Clone, PartialEq)]
pub struct TpProgram {
    /// `/PROG` name.
    pub name: String,
    /// `/ATTR COMMENT` (at most [`COMMENT_MAX`] characters: `waam-slicer`,
    /// or `waam: 1 of 3` for group 1 of a build cut to the memory budget).
    pub comment: String,
    /// Motion groups in use (1 or 2).
    pub groups: usize,
    /// `/APPL` arc welding section present (`ARC Welding Equipment`).
    pub arc_welding: bool,
    /// `/APPL` says `ARC : TRUE ;` (an ArcTool arc program).
    pub arc_enabled: bool,
    /// `CONTROL_CODE = 00000001 00000000`: a remote TCP program (what a
    /// controller writes for a program with `RTCP` moves).
    pub remote_tcp: bool,
    /// `/MN`.
    pub instructions: Vec<Instruction>,
    /// `/POS`, in index order.
    pub positions: Vec<Position>,
}

/// The FANUC programs of `program`: one program when its positions (home
/// included) fit `opts.max_positions`, else the groups of whole beads the
/// cell loads in turn, `NAME_P01`, `NAME_P02`, … each within it
/// ([`split::split_to_budget`](crate::program::split::split_to_budget)).
///
/// Every program opens with remarks stating its frames ([`frame_remarks`],
/// [`FanucOptions::frames`]), then `UFRAME_NUM`/`UTOOL_NUM`. With
/// `program.home`, the first and the last motion (of the main program when
/// of each group) are a joint move to the home joints. Before each bead's first
/// motion come its [`BeadSetup`](crate::program::BeadSetup) instructions:
/// payload (`$PLST_GRP1[n]` mass and CoG in kg and cm, then `PAYLOAD[n]`),
/// dwell (`WAIT x.xx(sec)`, rounded up to 0.01 s), interpass wait (`WAIT
/// DI[n]=ON`).
///
/// # Errors
/// [`ProgramError::InvalidOptions`] for bad options or a name too long for
/// the group suffix; [`ProgramError::OverBudget`] for a bead that does not
/// fit `max_positions` alone (naming the layer and the numbers);
/// [`ProgramError::VendorMismatch`] when the
/// cell's robot is not a FANUC arm; [`ProgramError::Mismatch`] when
/// `program.bead_setup` is not one per bead, or a home or set-up value is
/// not finite.
pub fn tp_programs(program: &Program, opts: &FanucOptions) -> Result<Vec<TpProgram>, ProgramError> {
    check_vendor(&program.cell, Vendor::Fanuc, EMITTER)?;
    program.check_finite()?;
    opts.validate()?;
    check_name(&program.name)?;
    if opts.remote_tcp(&program.cell) && opts.positions == PositionMode::Cartesian {
        return Err(ProgramError::InvalidOptions {
            field: "positions",
            value: "cartesian".into(),
            reason: "remote TCP (`remote_tcp`) in the part-carried cell needs joint positions: the Cartesian representation of FANUC RTCP programs (RX..RR) is not documented",
        });
    }
    // every program resident at once within the budget: one program, or
    // groups of whole beads the cell loads in turn (module doc)
    let home_positions = usize::from(program.home.is_some());
    // one schedule table for every group: the controller's schedules are
    // shared by the programs it runs in turn
    let schedules = WeldSchedules::of(program, opts);
    let parts = split_to_budget(program, &Fanuc::budget(opts), |g| {
        Ok(g.points.len() + home_positions)
    })?;
    let n = parts.len();
    parts
        .iter()
        .enumerate()
        .map(|(k, part)| {
            check_name(&part.name)?;
            let comment = if n == 1 {
                "waam-slicer".to_string()
            } else {
                format!("waam: {} of {n}", k + 1)
            };
            tp_program(part, opts, &comment, &schedules)
        })
        .collect()
}

/// The weld schedules a program's beads use (module doc, "Wire feed"):
/// the `k`-th distinct wire feed of its arc-on moves (mm/s, as written: to
/// 0.01 mm/s) is schedule `base + k`, `base` the process's schedule; empty
/// without the arc process.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct WeldSchedules {
    /// `(schedule, wire feed mm/s as written)`, in order of first use.
    pub rows: Vec<(u32, f64)>,
}

impl WeldSchedules {
    /// The schedules of `program`'s bead points with `opts`' process.
    pub fn of(program: &Program, opts: &FanucOptions) -> Self {
        let ProcessControl::Arc { schedule } = opts.process else {
            return Self::default();
        };
        let mut rows: Vec<(u32, f64)> = Vec::new();
        for p in program.bead_points() {
            let v = written_wire_feed(p.wire_feed_mm_s);
            if !rows.iter().any(|r| r.1 == v) {
                rows.push((schedule + rows.len() as u32, v));
            }
        }
        Self { rows }
    }

    /// The schedule of wire feed `mm_s` (as [`written_wire_feed`] rounds
    /// it); `None` when no row has it.
    pub fn schedule_of(&self, mm_s: f64) -> Option<u32> {
        let v = written_wire_feed(mm_s);
        self.rows.iter().find(|r| r.1 == v).map(|r| r.0)
    }
}

/// A wire feed (mm/s) as a schedule remark writes it: to 0.01 mm/s.
pub fn written_wire_feed(mm_s: f64) -> f64 {
    (mm_s * 100.0).round() / 100.0
}

/// The remark stating weld schedule `n`'s wire feed (mm/s, ≤ 32
/// characters): `WELD SCHED 2: WFS 80.00 MM/S`.
pub fn schedule_remark(n: u32, wire_feed_mm_s: f64) -> String {
    format!("WELD SCHED {n}: WFS {} MM/S", Fixed::new(wire_feed_mm_s, 2))
}

/// A [`schedule_remark`] read back: the schedule and its wire feed (mm/s).
pub fn parse_schedule_remark(s: &str) -> Option<(u32, f64)> {
    let rest = s.trim().strip_prefix("WELD SCHED ")?;
    let (n, rest) = rest.split_once(':')?;
    let v = rest.trim().strip_prefix("WFS ")?.strip_suffix("MM/S")?;
    let v: f64 = v.trim().parse().ok().filter(|x: &f64| x.is_finite())?;
    Some((n.trim().parse().ok()?, v))
}

/// One TP program of [`tp_programs`]: `program` whole, named
/// `program.name`, with `/ATTR COMMENT` `comment`.
fn tp_program(
    program: &Program,
    opts: &FanucOptions,
    comment: &str,
    schedules: &WeldSchedules,
) -> Result<TpProgram, ProgramError> {
    let robot = program.cell.robot();
    let frames = opts.frames(&program.cell);
    let user_from_base = frames.base_from_user.inverse();
    let groups = if program.points.iter().any(|p| p.positioner.is_some()) {
        2
    } else {
        1
    };
    let arc_welding = matches!(opts.process, ProcessControl::Arc { .. });
    let (start_op, end_op) = opts.process_ops();
    let options = MotionOptions {
        coord: groups == 2 && opts.coordinated(&program.cell),
        rtcp: opts.remote_tcp(&program.cell),
    };
    let bead_of = bead_openings(program)?;
    let home = home_position(program, groups)?;
    // the segment time of the linear move into point `i` at `v` mm/s over
    // the path it deposits (in the robot base frame the part turns under a
    // straight flange path: longer than the chord), rounded up: never
    // faster than planned (a joint at its maximum speed stays within it)
    let in_part = moves_in_part_frame(&program.cell, &opts.common);
    let timed = |i: usize, v: f64| {
        let ms = 1000.0 * deposited_length_mm(program, i, in_part) / v;
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
        let written = speed(n as u32).mm_s().unwrap_or(0.0);
        // a speed relative to the part (RTCP, COORD) is exact: a joint
        // planned within JOINT_SPEED_MARGIN of its maximum gets the
        // segment's time instead, rounded up to the millisecond, so that
        // the positions' 0.0001 deg rounding cannot push it over
        let at_limit = (options.rtcp || options.coord)
            && joint_speed_ratio(program, i, written) > JOINT_SPEED_MARGIN;
        if n >= 1.0 && !at_limit {
            speed(n as u32)
        } else {
            timed(i, v)
        }
    };
    let joint_move = |position: usize| Instruction {
        line: 0,
        op: Op::Move {
            kind: MoveKind::Joint,
            position,
            via: None,
            speed: Speed::Percent(opts.approach_percent as u32),
            term: Termination::Fine,
            options: MotionOptions::default(),
        },
    };
    let home_record = |index: usize| {
        home.map(|(j, g)| Position {
            index,
            uf_ut: (frames.user_frame, frames.tool_frame),
            arm: ArmPosition::Joint(j),
            group2: g,
            line: 0,
            value_lines: [0; 6],
            group2_line: 0,
        })
    };
    let range = 0..program.points.len();
    let mut ins = frame_header(program, opts, &frames);
    for &(n, v) in &schedules.rows {
        ins.push(Instruction {
            line: 0,
            op: Op::Remark(schedule_remark(n, v)),
        });
    }
    // the schedule the arc runs with (module doc, "Wire feed")
    let mut schedule_on: Option<u32> = None;
    let schedule_op = |n: u32| match (&start_op, opts.weld_procedure) {
        (Op::WeldStart(p, _), _) => Op::WeldStart(*p, n),
        _ => Op::ArcStart(n),
    };
    if range
        .clone()
        .any(|i| !joint_move_target(program, i) && opts.segment_time_based(program, i))
    {
        ins.push(Instruction {
            line: 0,
            op: Op::Remark(TIME_BASED_REMARK.into()),
        });
    }
    let mut positions = Vec::with_capacity(range.len() + 1);
    // the home record follows the points, so that P[n] is point n
    let home_index = range.len() + 1;
    if home.is_some() {
        ins.push(joint_move(home_index));
    }
    for (local, p) in program.points[range.clone()].iter().enumerate() {
        let index = local + 1;
        let global = range.start + local;
        let prev = global.checked_sub(1).map(|g| &program.points[g]);
        let arm = match opts.positions {
            PositionMode::Cartesian if !near_turn_edge(&p.joints) => {
                let pose = user_from_base * robot.flange_pose(&p.joints) * frames.flange_from_tool;
                ArmPosition::Cartesian {
                    xyzwpr: FanucPose::from_isometry(&pose).to_xyzwpr_deg(),
                    config: robot.fanuc_config(&p.joints).to_string(),
                }
            }
            _ => ArmPosition::Joint(p.joints.map(f64::to_degrees)),
        };
        positions.push(Position {
            index,
            uf_ut: (frames.user_frame, frames.tool_frame),
            arm,
            group2: p.positioner.map(|q| q.map(f64::to_degrees)),
            line: 0,
            value_lines: [0; 6],
            group2_line: 0,
        });
        if let Some(b) = bead_of[global] {
            if let Some(setup) = program.bead_setup.get(b) {
                ins.extend(
                    setup_ops(setup, opts)
                        .into_iter()
                        .map(|op| Instruction { line: 0, op }),
                );
            }
        }
        // the move into this point: circular through the point before it
        // when that one is a via
        let circular = prev.is_some_and(|a| a.via) && local > 0;
        let linear = |speed, term| Instruction {
            line: 0,
            op: Op::Move {
                kind: if circular {
                    MoveKind::Circular
                } else {
                    MoveKind::Linear
                },
                position: index,
                via: circular.then(|| index - 1),
                speed,
                term,
                options,
            },
        };
        match p.arc {
            ArcFlag::Approach | ArcFlag::Transit => ins.push(joint_move(index)),
            ArcFlag::Start => {
                ins.push(match prev {
                    Some(a) if a.arc == ArcFlag::Approach => {
                        linear(linear_speed(global, a.speed_mm_s), Termination::Fine)
                    }
                    _ => joint_move(index),
                });
                schedule_on = schedules.schedule_of(p.wire_feed_mm_s);
                ins.push(Instruction {
                    line: 0,
                    op: schedule_on.map_or_else(|| start_op.clone(), schedule_op),
                });
            }
            // a via is written with the move it is the via of
            ArcFlag::On if p.via => {}
            ArcFlag::On | ArcFlag::End
                if schedule_on.is_some()
                    && schedules.schedule_of(p.wire_feed_mm_s) != schedule_on =>
            {
                // the wire feed changes: the next schedule, from the
                // move's start on
                schedule_on = schedules.schedule_of(p.wire_feed_mm_s);
                ins.push(Instruction {
                    line: 0,
                    op: schedule_on.map_or_else(|| start_op.clone(), schedule_op),
                });
                ins.push(linear(
                    linear_speed(global, p.speed_mm_s),
                    if p.arc == ArcFlag::End {
                        Termination::Fine
                    } else {
                        Termination::Cnt(opts.cnt)
                    },
                ));
                if p.arc == ArcFlag::End {
                    schedule_on = None;
                    ins.push(Instruction {
                        line: 0,
                        op: end_op.clone(),
                    });
                }
            }
            ArcFlag::On => ins.push(linear(
                linear_speed(global, p.speed_mm_s),
                Termination::Cnt(opts.cnt),
            )),
            ArcFlag::End => {
                schedule_on = None;
                ins.push(linear(
                    linear_speed(global, p.speed_mm_s),
                    Termination::Fine,
                ));
                ins.push(Instruction {
                    line: 0,
                    op: end_op.clone(),
                });
            }
            ArcFlag::Retract => ins.push(linear(
                linear_speed(global, p.speed_mm_s),
                Termination::Fine,
            )),
        }
    }
    if let Some(h) = home_record(home_index) {
        positions.push(h);
        ins.push(joint_move(home_index));
    }
    Ok(TpProgram {
        name: program.name.clone(),
        comment: attr_comment(comment),
        groups,
        arc_welding,
        arc_enabled: arc_welding,
        remote_tcp: options.rtcp,
        instructions: ins,
        positions,
    })
}

/// Fraction of a joint's (or positioner axis's) maximum speed above which
/// a linear move with a speed relative to the part (`RTCP`, `COORD`) is
/// written as a segment time (rounded up) instead.
pub const JOINT_SPEED_MARGIN: f64 = 0.98;

/// The largest ratio of joint (and positioner axis) speed to its maximum
/// on the segment into point `i` of `program` run at `v` mm/s over the part
/// (0 for a zero-length segment or `i = 0`).
pub fn joint_speed_ratio(program: &Program, i: usize, v: f64) -> f64 {
    let d = segment_length_mm(program, i);
    let Some(prev) = move_start(program, i).map(|k| &program.points[k]) else {
        return 0.0;
    };
    if d <= 0.0 || v <= 0.0 {
        return 0.0;
    }
    let dt = d / v;
    let p = &program.points[i];
    let robot = program.cell.robot();
    let mut ratio: f64 = 0.0;
    for j in 0..6 {
        ratio = ratio.max((p.joints[j] - prev.joints[j]).abs() / dt / robot.max_speed_rad_s[j]);
    }
    if let (CellLayout::TorchCarried(c), Some(a), Some(b)) =
        (&program.cell, p.positioner, prev.positioner)
    {
        for n in 0..2 {
            let max = c.positioner.max_speed_rad_s[n];
            if max.is_finite() && max > 0.0 {
                ratio = ratio.max((a[n] - b[n]).abs() / dt / max);
            }
        }
    }
    ratio
}

/// The remarks stating the frames, then `UFRAME_NUM` and `UTOOL_NUM`.
fn frame_header(program: &Program, opts: &FanucOptions, frames: &FanucFrames) -> Vec<Instruction> {
    let what_user = if opts.remote_tcp(&program.cell) {
        "REMOTE TCP AT TORCH"
    } else if frames.user_frame == 0 {
        "WORLD"
    } else {
        "WORK"
    };
    let what_tool = match &program.cell {
        CellLayout::TorchCarried(_) => "TORCH TCP",
        CellLayout::PartCarried(_) if is_identity(&frames.flange_from_tool) => "FLANGE",
        CellLayout::PartCarried(_) => "PART ON FLANGE",
    };
    let mut remarks = vec![
        "FRAMES: X,Y,Z MM W,P,R DEG".to_string(),
        format!("UFRAME[{}] = {what_user}", frames.user_frame),
    ];
    remarks.extend(frame_remarks(
        FrameKind::User,
        frames.user_frame,
        &frames.base_from_user,
    ));
    remarks.push(format!("UTOOL[{}] = {what_tool}", frames.tool_frame));
    remarks.extend(frame_remarks(
        FrameKind::Tool,
        frames.tool_frame,
        &frames.flange_from_tool,
    ));
    let mut ins: Vec<Instruction> = remarks
        .into_iter()
        .map(|r| Instruction {
            line: 0,
            op: Op::Remark(r),
        })
        .collect();
    ins.push(Instruction {
        line: 0,
        op: Op::UFrame(frames.user_frame),
    });
    ins.push(Instruction {
        line: 0,
        op: Op::UTool(frames.tool_frame),
    });
    ins
}

/// For each point of `program`, the index of the bead it opens (an
/// approach point, or a bead's first point without one), checking that
/// `program.bead_setup` is empty or one per bead in layer order with finite
/// values.
fn bead_openings(program: &Program) -> Result<Vec<Option<usize>>, ProgramError> {
    let mut k = 0;
    let mut out = Vec::with_capacity(program.points.len());
    for i in 0..program.points.len() {
        let prev = i.checked_sub(1).map(|k| program.points[k].arc);
        if opens_bead(prev, program.points[i].arc) {
            if let Some(s) = program.bead_setup.get(k) {
                let p = &program.points[i];
                let bad = |reason: String| ProgramError::Mismatch { index: i, reason };
                if s.layer != p.layer {
                    return Err(bad(format!(
                        "bead_setup[{k}] is for layer {}, but bead {k} is layer {}",
                        s.layer, p.layer
                    )));
                }
                let finite_payload = s.payload.is_none_or(|pl| {
                    pl.mass_kg.is_finite()
                        && pl.mass_kg >= 0.0
                        && pl.cog_mm.iter().all(|v| v.is_finite())
                });
                if !(finite_payload && s.dwell_s.is_finite() && s.dwell_s >= 0.0) {
                    return Err(bad(format!(
                        "bead_setup[{k}] (layer {}): payload or dwell_s not finite and >= 0",
                        s.layer
                    )));
                }
                if s.wait_input == Some(0) {
                    return Err(bad(format!(
                        "bead_setup[{k}] (layer {}): wait_input 0 (DI numbers start at 1)",
                        s.layer
                    )));
                }
            }
            out.push(Some(k));
            k += 1;
        } else {
            out.push(None);
        }
    }
    if !program.bead_setup.is_empty() && program.bead_setup.len() != k {
        return Err(ProgramError::Mismatch {
            index: program.points.len(),
            reason: format!(
                "{} bead_setup entries for {k} beads",
                program.bead_setup.len()
            ),
        });
    }
    Ok(out)
}

/// The home joints (deg) and, in a two-group program, the positioner's
/// (deg; `[0, 0]` when the home position gives none).
#[allow(clippy::type_complexity)]
fn home_position(
    program: &Program,
    groups: usize,
) -> Result<Option<([f64; 6], Option<[f64; 2]>)>, ProgramError> {
    let Some(h) = program.home else {
        return Ok(None);
    };
    let g = (groups == 2).then(|| h.positioner.unwrap_or([0.0; 2]).map(f64::to_degrees));
    if !h.joints.iter().all(|v| v.is_finite())
        || g.is_some_and(|g| !g.iter().all(|v| v.is_finite()))
    {
        return Err(ProgramError::Mismatch {
            index: 0,
            reason: "home: joints or positioner joints not finite".into(),
        });
    }
    Ok(Some((h.joints.map(f64::to_degrees), g)))
}

/// The instructions of one bead's set-up: payload (the schedule's mass in
/// kg and CoG in cm, then `PAYLOAD[n]`), dwell, interpass wait.
fn setup_ops(setup: &crate::program::BeadSetup, opts: &FanucOptions) -> Vec<Op> {
    let mut ops = Vec::new();
    let schedule = opts.payload_schedule;
    if let Some(p) = setup.payload {
        for field in PayloadField::ALL {
            let value = match field {
                PayloadField::Mass => p.mass_kg,
                PayloadField::X => p.cog_mm.x / 10.0,
                PayloadField::Y => p.cog_mm.y / 10.0,
                PayloadField::Z => p.cog_mm.z / 10.0,
            };
            ops.push(Op::PayloadValue {
                schedule,
                field,
                value,
            });
        }
        ops.push(Op::Payload(schedule));
    }
    if setup.dwell_s > 0.0 {
        // never shorter than planned
        ops.push(Op::WaitTime(ceil_to(setup.dwell_s, 2)));
    }
    if let Some(n) = setup.wait_input {
        ops.push(Op::WaitInput(n));
    }
    ops
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
    let code = if tp.remote_tcp {
        "00000001"
    } else {
        "00000000"
    };
    writeln!(w, "CONTROL_CODE\t= {code} 00000000;")?;
    if tp.arc_welding || tp.arc_enabled {
        writeln!(w, "/APPL")?;
        if tp.arc_enabled {
            writeln!(w, "  ARC : TRUE ;")?;
        }
        if tp.arc_welding {
            writeln!(w, "  ARC Welding Equipment : 1,*,*,*,*;")?;
        }
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

/// The `.ls` files of `program`: one, or its groups in the order the cell
/// runs them ([`tp_programs`]).
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

impl FanucOptions {
    /// The instructions starting and stopping a bead.
    pub fn process_ops(&self) -> (Op, Op) {
        match (&self.process, self.weld_procedure) {
            (ProcessControl::Arc { schedule }, None) => {
                (Op::ArcStart(*schedule), Op::ArcEnd(*schedule))
            }
            (ProcessControl::Arc { schedule }, Some(p)) => {
                (Op::WeldStart(p, *schedule), Op::WeldEnd(p, *schedule))
            }
            (ProcessControl::Custom { start, end }, _) => {
                (Op::Other(start.clone()), Op::Other(end.clone()))
            }
        }
    }
}
