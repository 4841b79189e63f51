//! Validator of robot programs from the files alone plus the cell [SPEC §8]:
//! joint limits (arm and positioner), joint speeds at the programmed speeds
//! (or segment times), reachability (Cartesian positions: IK with the file's
//! configuration data — FANUC `CONFIG` string and turn numbers, KUKA Status
//! and Turn, ABB `confdata` — then FK back within 0.01 mm; and, when the
//! plan is given, the deposition point of every bead position within 0.01 mm
//! of the planned one), configuration consistency (the cell's branch
//! everywhere, no joint jumping by half a turn or more between consecutive
//! linear moves), and that every bead starts and stops once. Every problem
//! names its file and line; the report lists them all.
//!
//! Each controller's reader turns its files into the same [`DecodedStep`]s (motions
//! with decoded joints, process on and off, in execution order); one checker
//! ([`check_steps`], in `check`) validates them; the decoders of FANUC,
//! KUKA and ABB files are `fanuc`, `kuka` and `abb`, one a controller,
//! each taking its vendor folder's reader's output. Bead points are the motions made with
//! the process on plus the motion that reaches a bead's first point (the one
//! before the process starts); the other motions (approach, retract,
//! transitions) are checked for limits, configuration and speeds but not
//! compared with the planned points.

pub(crate) mod between;
mod check;

pub(crate) use check::check_home_ends;
pub use check::check_steps;

use std::fmt;

use crate::math::{Isometry3, Point3};
use crate::program::MoveKind;
use crate::robot::ik::wrap_pi;
use crate::robot::{ArmSide, CellLayout, Configuration, Elbow, Joints, RobotModel, Vendor, Wrist};

/// Largest accepted distance between a position and what it should reach (mm).
pub const REACH_TOLERANCE_MM: f64 = 0.01;

/// One problem found in a program.
#[derive(Debug, Clone, PartialEq)]
pub struct Problem {
    /// What kind of problem, for a host program that branches on it.
    pub kind: ProblemKind,
    /// Program (file) name.
    pub file: String,
    /// Line (1-based).
    pub line: usize,
    /// What is wrong.
    pub message: String,
}

impl fmt::Display for Problem {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}:{}: {}", self.file, self.line, self.message)
    }
}

/// The kind of a [`Problem`]: what a host program may branch on (the
/// message says the rest, with its file and line).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub enum ProblemKind {
    /// The program is for another vendor's robot than the cell's.
    Vendor,
    /// The file disagrees with the emitter's options (weld data, I/O, axes).
    Options,
    /// An identifier or position is used but not declared, or has the wrong type.
    Declaration,
    /// An instruction the checker does not know or expect there.
    Instruction,
    /// A called program is missing or calls nest too deep.
    Call,
    /// Tool or user/base frame, or interpolation mode, not the expected one.
    Frame,
    /// A configuration flip, a turn jump or turn data that do not fit.
    Configuration,
    /// A position the arm cannot reach (no IK, or IK lands away from it).
    Reach,
    /// A joint (or positioner axis) outside its travel.
    JointLimit,
    /// A joint (or positioner axis) faster than its maximum at the programmed speed.
    JointSpeed,
    /// A move whose speed or time the controller would not run as planned.
    Timing,
    /// A deposition point away from the planned point, or a point count that differs.
    Deviation,
    /// Arc on/off out of order: a bead that never stops, stops twice, or a joint move with the arc on.
    Bead,
    /// A record that cannot be decoded (missing values).
    Format,
    /// The program's set-up disagrees with the cell's `[program]` options:
    /// home move missing or elsewhere, interlayer dwell, interpass wait or
    /// payload update missing, or one made with the arc on.
    Setup,
    /// An arc-off joint move sweeps the torch through the deposited wall.
    Collision,
    /// A program (or a group of a build) larger than the controller's
    /// memory budget (`max_positions`, `max_file_bytes`).
    Budget,
    /// An arc-on move whose wire feed over travel speed (the bead's
    /// cross-section) is not the plan's, or whose wire feed the file does
    /// not define.
    Feed,
}

impl ProblemKind {
    /// The kind's name in reports and bindings, snake case (`joint_limit`).
    pub fn name(self) -> &'static str {
        match self {
            Self::Vendor => "vendor",
            Self::Options => "options",
            Self::Declaration => "declaration",
            Self::Instruction => "instruction",
            Self::Call => "call",
            Self::Frame => "frame",
            Self::Configuration => "configuration",
            Self::Reach => "reach",
            Self::JointLimit => "joint_limit",
            Self::JointSpeed => "joint_speed",
            Self::Timing => "timing",
            Self::Deviation => "deviation",
            Self::Bead => "bead",
            Self::Format => "format",
            Self::Setup => "setup",
            Self::Collision => "collision",
            Self::Budget => "budget",
            Self::Feed => "feed",
        }
    }
}

/// Every problem of a set of programs, in execution order.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct ValidationReport {
    /// The problems.
    pub problems: Vec<Problem>,
    /// Motions checked.
    pub motions: usize,
    /// Beads (started and stopped once).
    pub beads: usize,
}

impl ValidationReport {
    /// `true` when no problem was found.
    pub fn is_ok(&self) -> bool {
        self.problems.is_empty()
    }
}

impl fmt::Display for ValidationReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.problems.is_empty() {
            return writeln!(f, "ok: {} motions, {} beads", self.motions, self.beads);
        }
        for p in &self.problems {
            writeln!(f, "{p}")?;
        }
        Ok(())
    }
}

/// How a motion's speed is given.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum MotionSpeed {
    /// Joint move (percentage or joint speed): not checked against the
    /// travel speed.
    Joint,
    /// Linear move at this speed of the deposition point relative to the
    /// part (mm/s).
    Linear(f64),
    /// Linear move taking this long (s).
    Time(f64),
    /// Linear move at the controller's TCP speed: the TCP (`flange ·
    /// flange_from_tcp`) travels at `mm_s` in the robot base frame, and the
    /// positioner's axes, moving with the path, arrive with it, each at most
    /// at `extax_fraction` of its maximum speed: the move takes the longest
    /// of these. This is what FANUC `mm/sec`/`cm/min`, ABB `v_tcp` with the
    /// tool held by the robot and KUKA `$VEL.CP` outside the fixed-tool mode
    /// mean; it equals [`MotionSpeed::Linear`] only where the part is still.
    Tcp {
        /// TCP speed in the robot base frame (mm/s).
        mm_s: f64,
        /// The TCP on the flange (mm).
        flange_from_tcp: Isometry3,
        /// Fraction (0–1] of each positioner axis's maximum speed allowed
        /// for external axes moving with the path (KUKA `$VEL_EXTAX[n]/100`;
        /// 1 elsewhere).
        extax_fraction: [f64; 2],
    },
}

/// One motion of a program, decoded.
#[derive(Debug, Clone, PartialEq)]
pub struct Motion {
    /// File (or program) of the motion instruction.
    pub file: String,
    /// Line of the motion instruction (1-based).
    pub line: usize,
    /// The target's name as written (`P[3]`, `P3`, `p3`).
    pub label: String,
    /// File of the target's record (the `.dat` for KUKA).
    pub record_file: String,
    /// Line of the target's record.
    pub record_line: usize,
    /// Line of each joint's value (the record line when one line holds them all).
    pub value_lines: [usize; 6],
    /// Robot joints (rad, controller convention); `None` when they could not
    /// be decoded (a problem names why).
    pub joints: Option<Joints>,
    /// `true` when the joints were decoded from a Cartesian pose (its
    /// configuration data were checked while decoding).
    pub from_cartesian: bool,
    /// Positioner joints `[q7, q8]` (rad), if the file gives them.
    pub positioner: Option<[f64; 2]>,
    /// Joint or linear move.
    pub kind: MoveKind,
    /// The speed.
    pub speed: MotionSpeed,
    /// The wire feed the file commands for this move with the arc on;
    /// `None` with the arc off, or where the file carries none (a custom
    /// process's user lines).
    pub wire_feed: Option<WireFeed>,
}

/// The wire feed of an arc-on move as a file writes it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WireFeed {
    /// Wire feed speed (mm/s).
    pub mm_s: f64,
    /// Largest relative difference between this move's wire feed over
    /// travel speed and the plan's that the rounding of its written numbers
    /// explains (the steps of the written wire feed and of the written
    /// speed or time, each relative to its value; dimensionless).
    pub tolerance: f64,
}

/// One step of a program as a controller's decoder reads it back from its
/// files, in execution order (the checker's input; not the path stage's
/// [`Step`](crate::path::strategy::Step)).
#[derive(Debug, Clone, PartialEq)]
pub enum DecodedStep {
    /// A motion.
    Motion(Box<Motion>),
    /// The process (arc) starts here.
    ProcessOn {
        /// File.
        file: String,
        /// Line.
        line: usize,
    },
    /// The process stops here.
    ProcessOff {
        /// File.
        file: String,
        /// Line.
        line: usize,
    },
    /// The program waits here: a dwell (`seconds`) or a digital input
    /// (`input`, waited for to be on).
    Wait {
        /// File.
        file: String,
        /// Line.
        line: usize,
        /// Dwell (s), if this is a timed wait.
        seconds: Option<f64>,
        /// Digital input number waited for, if this is an input wait.
        input: Option<u32>,
    },
    /// The payload on the flange is set here.
    Payload {
        /// File.
        file: String,
        /// Line.
        line: usize,
        /// Mass (kg).
        mass_kg: f64,
        /// Centre of gravity, flange frame (mm).
        cog_mm: Point3,
    },
}

/// Adds a problem to `report`.
pub(crate) fn push(
    report: &mut ValidationReport,
    kind: ProblemKind,
    file: &str,
    line: usize,
    message: String,
) {
    report.problems.push(Problem {
        kind,
        file: file.to_string(),
        line,
        message,
    });
}

/// Deposition point in the part frame (mm) at joints `q`, positioner `qp`:
/// the fixed torch's point seen from the part (part-carried cell), or the
/// TCP seen from the part on the positioner (torch-carried cell).
pub fn deposition_point(cell: &CellLayout, q: &Joints, qp: Option<[f64; 2]>) -> Option<Point3> {
    let flange = cell.robot().flange_pose(q);
    match cell {
        CellLayout::PartCarried(c) => {
            let base_from_part = flange * c.flange_from_part;
            Some(base_from_part.inverse() * c.deposition_point_mm)
        }
        CellLayout::TorchCarried(c) => {
            let tcp = flange * c.flange_from_tcp;
            let base_from_part = c.base_from_part(&qp?);
            Some(base_from_part.inverse() * Point3::from(tcp.translation.vector))
        }
    }
}

const NAMES: [&str; 6] = ["J1", "J2", "J3", "J4", "J5", "J6"];

/// Joints reaching `base_from_flange` in branch `cfg` (J2, J3, J5 as the IK
/// gives them), each of J1, J4, J6 turned by `turn(j, q)` (which gets the
/// solution's value in `(-π, π]` and returns the joint value, or `None` when
/// the file's turn data do not fit),
/// checked by FK within [`REACH_TOLERANCE_MM`]. Problems are named `label`.
#[allow(clippy::too_many_arguments)]
pub(crate) fn decode_pose(
    robot: &RobotModel,
    base_from_flange: &Isometry3,
    cfg: Configuration,
    mut turn: impl FnMut(usize, f64) -> Option<f64>,
    label: &str,
    file: &str,
    line: usize,
    report: &mut ValidationReport,
) -> Option<Joints> {
    let mut q = match robot.inverse(base_from_flange, cfg) {
        Ok(q) => q,
        Err(e) => {
            push(
                report,
                ProblemKind::Reach,
                file,
                line,
                format!("{label}: {e}"),
            );
            return None;
        }
    };
    for j in [0, 3, 5] {
        match turn(j, wrap_pi(q[j])) {
            Some(v) => q[j] = v,
            None => {
                push(
                    report,
                    ProblemKind::Configuration,
                    file,
                    line,
                    format!(
                        "{label}: the turn data of {} do not fit its angle {:.4}°",
                        NAMES[j],
                        wrap_pi(q[j]).to_degrees()
                    ),
                );
                return None;
            }
        }
    }
    let back = robot.flange_pose(&q);
    let err = (back.translation.vector - base_from_flange.translation.vector).norm();
    if err > REACH_TOLERANCE_MM {
        push(
            report,
            ProblemKind::Reach,
            file,
            line,
            format!("{label}: IK with the file's configuration reaches {err:.4} mm away"),
        );
    }
    Some(q)
}

/// `false`, with the problem pushed (line 1 of `file`), when `cell`'s robot
/// is not a `vendor` arm: its joints are in another controller's convention
/// and nothing else in the file can be checked against it.
pub(crate) fn vendor_matches(
    cell: &CellLayout,
    vendor: Vendor,
    emitter: &'static str,
    file: &str,
    report: &mut ValidationReport,
) -> bool {
    match crate::program::check_vendor(cell, vendor, emitter) {
        Ok(()) => true,
        Err(e) => {
            push(report, ProblemKind::Vendor, file, 1, e.to_string());
            false
        }
    }
}

/// The branch whose wrist has controller J5 of sign `j5_positive`.
pub(crate) fn wrist_of_j5(robot: &RobotModel, j5_positive: bool) -> Wrist {
    // NoFlip when the canonical t5 = sign5·J5 is positive
    if j5_positive == (robot.convention.sign[4] > 0.0) {
        Wrist::NoFlip
    } else {
        Wrist::Flip
    }
}

/// The arm side and elbow of `back`/`positive_cos` (KUKA Status bits 0
/// and 1; ABB `cfx` bit 2 and the negation of bit 1).
pub(crate) fn arm_of(back: bool, positive_cos: bool) -> (ArmSide, Elbow) {
    let side = if back { ArmSide::Back } else { ArmSide::Front };
    let elbow = if positive_cos != back {
        Elbow::Up
    } else {
        Elbow::Down
    };
    (side, elbow)
}
