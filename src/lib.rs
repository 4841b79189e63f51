//! # waam-slicer
//!
//! Plans wire-arc additive manufacturing (WAAM) of thin-walled metal tubes on
//! industrial robots, after Chalvin (2020), *Additive manufacturing of tubes by
//! multi-axis robotized wire deposition*. The technical reference is `SPEC.md`
//! (shared with the project); section numbers below point into it.
//!
//! ## The pipeline
//!
//! ```text
//! part file (TOML) -> Tube geometry -> deposition path (layers of points)
//!                  -> tool axes -> process (speeds, bead)
//!                  -> cell (robot + positioner + torch) -> joint trajectory (IK)
//!                  -> layer-by-layer optimisation of R_Z -> validation -> robot program
//! ```
//!
//! Each stage is one public module whose entry point takes a typed value and
//! returns the next one, so that software embedding the library can call any
//! stage alone:
//!
//! | stage | module | SPEC |
//! |---|---|---|
//! | 0. read a part file | [`io::part_file`] | §2 |
//! | 1. tube geometry: guide curves, frames, profile law, substrates | [`geometry`] | §2 |
//! | 2. deposition paths: four strategies + spiral, distance map, truncation, seams, smoothing | [`path`] | §3 |
//! | 3. tool axes (local frames, build direction) | [`toolaxis`] | §4 |
//! | 3b. process: bead, travel speeds, estimates | [`process`] | §5 |
//! | 4. robot kinematics, orientation conventions, cells | [`robot`] | §6 |
//! | 5a. the torch-carried positioner's tilt and turn laws within the cone of the vertical | [`optimise::positioner`] | §9 |
//! | 5. layer-by-layer optimisation of `R_Z` (branch, SQP, quality) | [`optimise`] | §7 |
//! | 6. robot programs (FANUC `.ls`, KUKA `.src`/`.dat`, ABB `.mod`, CSV), read-back and validation | [`program`] | §8 |
//! | 7. placement of the part in the cell: an outer search over 5 and 6 | [`place`] | — |
//!
//! ## Units and frames
//!
//! * Lengths in **millimetres**, angles in **radians**, time in seconds, speeds
//!   in mm/s throughout the API. Degrees and vendor units (cm/min, FANUC
//!   `W P R`) appear only at the edges: part and cell files, robot programs and
//!   reports, and every such field says so in its name (`angle_deg`).
//! * Geometry of a part is expressed in the **part frame** (the frame the part
//!   file is written in; Z is the nominal build direction for flat substrates).
//!   Robot quantities are in the robot base frame unless the name says
//!   otherwise; rigid transforms are named `a_from_b`.
//! * Scalars are concrete `f64`; vector types are the aliases of [`math`], and
//!   [`nalgebra`] is re-exported so that users get the same version.
//!
//! ## The front door
//!
//! Most callers need only the crate root ([`pipeline`]): [`Part::read`],
//! [`Cell::read`], [`slice_part`], [`plan_part`] →
//! [`PlannedPart::write_programs`], [`check_program`], and [`place_part`]
//! ([`PlaceRequest`] → [`PlacedCell`]) when a cell refuses a part where it
//! stands.
//!
//! ```no_run
//! use waam_slicer::{Cell, Part, PlanOptions, ProgramFormat};
//! # fn main() -> Result<(), waam_slicer::Error> {
//! let part = Part::read("parts/hemisphere.toml")?;
//! let cell = Cell::read("parts/cells/robowam_part_carried.toml")?;
//! let planned = waam_slicer::plan_part(&part, &cell, &PlanOptions::default())?;
//! if planned.is_feasible() {
//!     planned.write_programs("out/hemisphere", ProgramFormat::Fanuc)?;
//! }
//! # Ok(()) }
//! ```
//!
//! ## Examples
//!
//! * `examples/waam` — the command-line tool (`cargo run --release --example waam -- --help`).
//! * `examples/embed.rs` — a host program planning a part through the front door.
#![warn(missing_docs, missing_debug_implementations)]
#![forbid(unsafe_code)]
// `!(x > 0.0)` is how we reject NaN together with the bad range; keep it readable.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

pub use nalgebra;

pub mod error;
pub mod geometry;
pub mod io;
pub mod math;
pub mod optimise;
pub mod path;
pub mod pipeline;
pub mod process;
pub mod program;
pub mod report;
pub mod robot;
pub mod toolaxis;

// Stage 7, after the stages it searches over (see the table above).
pub mod place;

#[cfg(feature = "python")]
mod python;

pub use error::Error;

// The README's "Use as a library" block runs as a doctest.
#[cfg(doctest)]
#[doc = include_str!("../README.md")]
struct ReadmeDoctests;
pub use pipeline::{
    check_program, place_part, plan_part, slice_part, slice_part_with, Cell, Control, Part,
    PlaceRequest, PlacedCell, PlanOptions, PlannedPart, ProgramFormat, RzLaw, SliceOverrides,
    SlicedPart,
};
pub use place::PlaceOptions;
