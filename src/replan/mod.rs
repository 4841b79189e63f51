//! **Stage 9 — the closed loop: replan the remaining layers from a measured
//! layer.** Takes a part and its cell (or a part already planned there), a
//! [`Measured`] top of layer `K` (scan points or height errors, part frame,
//! mm) and returns a [`ReplannedPart`]: layers `K+1..` with the travel speed
//! (mm/s) and bead height (mm) of every point, their joints optimised in
//! the cell and a program that continues the build's layer numbering from
//! the cell's state (home, the payload of the layers already deposited).
//! A client of the front door ([`crate::pipeline`]); SPEC §9 "Closed loop",
//! issue 29.
//!
//! Two corrections, in this order, per point of the layers after `K`:
//! 1. **speed** — the bead height `h` that brings the top back to the
//!    nominal layer is the distance from the nominal point to the measured
//!    top below it; the travel speed that lays it comes from the process's
//!    law `ln h = a ln v + b` ([`BeadHeightLaw`](crate::process::BeadHeightLaw),
//!    anchored by default so that the nominal speed lays `Delta`);
//! 2. **geometry** — where that speed leaves the process window
//!    (`travel_speed_min_mm_s..travel_speed_max_mm_s`), the point is put at
//!    the nearest height the window allows, at constant local distance from
//!    the layer below as it will stand (the constant-distance march, SPEC
//!    §3.1.4, started from the measured layer instead of the substrate);
//!    the next layer is built on that one, and so on until a layer lands on
//!    its nominal layer at every point: from there on the nominal layers
//!    and speed are kept. Where the wall stands half a layer high or more,
//!    the layers may instead aim at a later nominal layer (layer `K+1` at
//!    nominal `K+2`, ..), when that rejoins in fewer layers: the skipped
//!    nominal layers are named ([`ReplannedPart::skipped`]) and the layers
//!    after them renumbered so that the build's numbering has no gap.
//!
//! The predicted error of a layer is its predicted top minus its nominal top
//! along the column (mm, + high); "before" is what the nominal plan would
//! leave (under the law a nominal bead lays the nominal height, so the
//! measured error stays), "after" what the replan leaves.
//!
//! Not yet handled: the arc-off transits of the resumed program are checked
//! against the beads it lays, not against the layers `0..=K` already on the
//! part.

mod driver;
mod options;
mod outcome;
mod rebuild;
pub mod scan;
pub mod summary;

pub use crate::error::ReplanError;
pub use driver::{replan_part, replan_part_with, replan_planned};
pub use options::ReplanOptions;
pub use outcome::{program_name_for, ErrorStats, LayerCorrection, ReplanTimes, ReplannedPart};
pub use scan::{HeightError, Measured, Outlier, ScanEstimate};
