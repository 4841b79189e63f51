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
//! | — leaf helpers every stage may use: types, tolerances, root finding; atomic writes, decimal text | [`math`], [`util`] | |
//! | 1. tube geometry: guide curves, frames, profile law, substrates | [`geometry`] | §2 |
//! | 2. deposition paths: four strategies + spiral, distance map, truncation, seams, smoothing | [`path`] | §3 |
//! | 3. tool axes (local frames, build direction) | [`toolaxis`] | §4 |
//! | 4. process: bead, travel speeds, estimates | [`process`] | §5 |
//! | 5. robot kinematics, orientation conventions, cells | [`robot`] | §6 |
//! | 6. layer-by-layer optimisation of `R_Z` (branch, SQP, quality) | [`optimise`] | §7 |
//! | 6a. the torch-carried positioner's tilt and turn laws within the cone of the vertical | [`optimise::positioner`] | §9 |
//! | 7. robot programs (FANUC `.ls`, KUKA `.src`/`.dat`, ABB `.mod`, CSV), read-back and validation | [`program`] | §8 |
//! | 8. placement of the part in the cell: an outer search over 6 and 7 (the optimiser as its oracle, the program stage's checks in certification) | [`place`] | — |
//! | files at the edges: part and cell files read into the stages' types, CSV and STL written | [`io`] | §2, §6 |
//! | 0a. a tube from a mesh: guide spline and radius law fitted to a tubular STL (on a flat or an STL substrate), written as a part | [`fit`] | §2 |
//! | the interactive 3-D report (of a path or plan, and of a fit: the mesh coloured by its distance to the fitted tube) | [`report`] | |
//! | the front door: one call per job | [`pipeline`] | |
//!
//! A module imports only modules above it in this table (the leaf helpers
//! from everywhere; tests aside), and the children of one module form no
//! import cycle; [`error`] gathers every stage's error and sits below the
//! front door. `ARCHITECTURE.md` draws the rooms; `tests/robustness/house.rs`
//! keeps the rule true.
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
//! stands; [`Part::from_mesh`] fits a part to a tubular STL; [`replan_part`]
//! (or [`replan_planned`]) with a [`Measured`] layer → [`ReplannedPart`]
//! closes the loop during a build.
//!
//! ```no_run
//! use waam_slicer::{Cell, Part, PlanOptions};
//! # fn main() -> Result<(), waam_slicer::Error> {
//! let part = Part::read("parts/hemisphere.toml")?;
//! let cell = Cell::read("parts/cells/robowam_part_carried.toml")?;
//! let planned = waam_slicer::plan_part(&part, &cell, &PlanOptions::default())?;
//! if planned.is_feasible() {
//!     planned.write_programs("out/hemisphere")?;
//! }
//! # Ok(()) }
//! ```
//!
//! ## Examples
//!
//! * `examples/waam` — the command-line tool (`cargo run --release --example waam -- --help`).
//! * `examples/embed.rs` — a host program planning a part through the front door.
//! * One stage alone, each ending in an `assert!` against an independent value
//!   (`cargo test` runs them):
//!   * `examples/stage_slice.rs` — stage 2: the quarter torus sliced normal to
//!     the guide (60 % distance variation, closed form) and at constant
//!     distance (below 1e-6);
//!   * `examples/stage_ik.rs` — stage 5: the ArcMate 120iC's forward kinematics
//!     against SPEC §6.1's check values, the inverse in all eight
//!     configurations;
//!   * `examples/stage_emit.rs` — stages 5 and 7 without the optimiser: the
//!     hemisphere's first layers with the thesis's law `R_Z = −v`, a FANUC
//!     program emitted, read back and checked;
//!   * `examples/stage_place.rs` — stage 8: the hemisphere refused in the KUKA
//!     part-carried cell as it stands, placed, and the placed cell file read
//!     back, planned again and its program checked.
#![warn(missing_docs, missing_debug_implementations)]
#![forbid(unsafe_code)]
// `!(x > 0.0)` is how we reject NaN together with the bad range; keep it readable.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

pub use nalgebra;

pub mod error;
pub mod fit;
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
pub mod util;

// Stage 8, after the stages it searches over (see the table above).
pub mod place;
// Stage 9, a client of the front door.
pub mod replan;

#[cfg(feature = "python")]
mod python;

pub use error::{Error, ErrorKind};

// The README's "Use as a library" block runs as a doctest.
#[cfg(doctest)]
#[doc = include_str!("../README.md")]
struct ReadmeDoctests;
pub use fit::{FitOptions, FitReport, StartEnd};
pub use pipeline::FittedPart;
pub use pipeline::{
    check_program, place_part, plan_part, plan_part_with, slice_part, slice_part_with, Cell,
    Control, Part, PlaceRequest, PlacedCell, PlanOptions, PlannedPart, RzLaw, SliceOverrides,
    SlicedPart,
};
pub use place::PlaceOptions;
pub use replan::{replan_part, replan_part_with, replan_planned, Measured, ReplannedPart};
