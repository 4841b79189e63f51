//! **Stage 7 — robot programs.** Takes a planned [`JointTrajectory`](crate::robot::trajectory::JointTrajectory) (joints
//! per path point, rad), the path points it was computed for
//! ([`PathPointInput`](crate::robot::trajectory::PathPointInput): layer structure, part-frame positions (mm), tool axes,
//! `R_Z`), the [`CellLayout`](crate::robot::CellLayout) and each point's travel speed and wire feed ([`PointFeed`], mm/s), checks that the plan is
//! buildable, and returns a [`Program`]: one bead per layer, every point
//! carrying its arc flag, with an approach point before and a retract point
//! after each bead. Emitters turn a [`Program`] into controller files; every
//! format is read back and validated against the cell. SPEC §8, thesis
//! §3.1.2.
//!
//! | piece | module | entry points |
//! |---|---|---|
//! | the program as data (its vocabulary) | [`model`] | [`Program`], [`ProgramPoint`], [`ArcFlag`], [`EmittedFile`] |
//! | the program's options, the stage's errors | [`options`], [`error`] | [`ProgramOptions`], [`ProcessControl`], [`ProgramError`] |
//! | feasibility check and assembly | [`builder`] | [`build_program`], [`build_program_with`] |
//! | the controller's pose and interpolation (thinner and checker) | [`pose`] | [`pose::ControllerPose`], [`pose::interpolate`] |
//! | the vendor contract: options, emit, read, decode | [`contract`] | [`contract::Controller`], [`contract::validate_build`] |
//! | the registry: the one vendor list, dispatch by vendor, `[program.<key>]` tables | [`registry`] | [`registry::ProgramSettings`], [`registry::emit`], [`registry::check_files`] |
//! | FANUC TP ASCII `.ls` (emitter, reader, decoder) | [`fanuc`] | [`fanuc::Fanuc`], [`fanuc::fanuc_files`], [`fanuc::parse_ls`], [`fanuc::validate_fanuc`] |
//! | KUKA KRL `.src` + `.dat` | [`kuka`] | [`kuka::Kuka`], [`kuka::kuka_files`], [`kuka::parse_krl`], [`kuka::validate_kuka`] |
//! | ABB RAPID `.mod` | [`abb`] | [`abb::Abb`], [`abb::abb_files`], [`abb::parse_mod`], [`abb::validate_abb`] |
//! | vendor-neutral words: move kinds, position modes | [`kinds`] | [`MoveKind`], [`PositionMode`] |
//! | cutting a build into groups within a memory budget | [`split`] | [`split::split_to_budget`], [`split::Budget`] |
//! | CSV of every point | [`csv`] | [`csv::write_csv`] |
//! | the whole cell against collisions along every motion | [`cell_check`] | [`cell_check::check_cell`] |
//! | the build's cycle time (per move, layer, build) | [`cycle`] | [`cycle::cycle_time`] |
//! | the one checker of decoded steps (file + cell) | [`validate`] | [`validate::check_steps`], [`validate::DecodedStep`] |
//! | arc-off transits against the wall | [`transit`] | [`transit::joint_move_clearance`] |
//! | tool and work frames of every emitter | [`frames`] | [`frames::ToolFrames`], [`frames::held_tool`] |
//! | number formatting | [`fmt`] | [`fmt::Fixed`] |
//!
//! Each vendor's folder holds its emitter (`mod.rs`), its reader
//! (`read.rs`) and its decoder into the checker's steps (`decode.rs`), and
//! implements [`contract::Controller`]; nothing outside the vendors'
//! folders and [`registry`] chooses among vendors.
//!
//! JSON of every point: [`Program`] implements `serde::Serialize`; serialise
//! it with any serde format (the command-line tool uses `serde_json`).
//!
//! Files reach disk through [`write_files`] (atomic: temporary file, then
//! rename).

pub mod abb;
pub mod builder;
pub mod cell_check;
pub mod compress;
pub mod contract;
pub mod csv;
pub mod cycle;
pub mod error;
pub mod fanuc;
pub mod fmt;
pub mod frames;
pub mod kinds;
pub mod kuka;
pub mod model;
pub mod moves;
pub mod options;
pub mod pose;
pub mod registry;
pub mod split;
pub mod transit;
pub mod validate;

pub use builder::{build_program, build_program_with};
pub use error::{LayerRefusal, ProgramError};
pub use kinds::{MoveKind, PositionMode};
pub(crate) use model::render;
pub use model::{
    check_name, check_vendor, deposited_length_mm, joint_move_target, joints_move, move_start,
    opens_bead, positioner_moves, segment_length_mm, write_files, ArcFlag, BeadSetup, EmittedFile,
    Payload, PlannedPoint, PointFeed, Program, ProgramPoint, JOINT_STILL_RAD, POSITIONER_STILL_DEG,
};
pub use options::{HomePosition, ProcessControl, ProgramOptions};
pub use registry::ProgramSettings;
