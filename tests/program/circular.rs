//! Circular moves in thinned beads (issue 32, item 2): where a stretch of a
//! bead is a circle arc within `path_tolerance_mm` and
//! `orientation_tolerance_deg`, it is written as one circular move (two
//! positions: via and end) and read back and checked by sampling the
//! circle as the controller interpolates it.
//!
//! Vendor syntax each test relies on:
//! * FANUC TP (`.ls`): "Circular motion" — `C P[v]` with the via point, the
//!   end point, speed and termination on the continuation line `:  P[n]
//!   100mm/sec CNT100 ;` (as a controller exports it, e.g. `769:C P[698]` /
//!   `:  P[699] WELD_SPEED FINE`).
//! * KUKA KRL: `CIRC aux, end` with Cartesian auxiliary and end points
//!   (KSS 8 system software manual, "CIRC"); orientation `$ORI_TYPE = #VAR`,
//!   `$CIRC_TYPE = #BASE`: the orientation changes from start to end, the
//!   auxiliary point's orientation is ignored.
//! * ABB RAPID: `MoveC CirPoint, ToPoint, speed, zone, tool \WObj` and
//!   `ArcC` with the same two targets (RAPID reference, MoveC: "the
//!   orientation of the circle point is not critical").

use waam_slicer::program::contract::{check_files, emit};
use waam_slicer::program::ProgramSettings;

use crate::fixture::{cell, hemisphere, law, trajectory, TS_MM_S};

/// The hemisphere's `layers` at 240 points a layer in `c`, thinned at the
/// default tolerances (circular moves on).
fn thinned_hemisphere(
    c: &waam_slicer::robot::Cell,
    layers: std::ops::Range<usize>,
) -> waam_slicer::program::Program {
    let path = hemisphere(layers, 240, law(c));
    let tr = trajectory(c, &path);
    waam_slicer::program::build_program(
        "HEMI",
        c,
        &path,
        &tr,
        &waam_slicer::program::TravelSpeed::Constant(TS_MM_S),
    )
    .unwrap_or_else(|e| panic!("{}: {e}", c.name()))
}

/// Every sample cell: the hemisphere's layers (near circles) are written
/// with circular moves, and the files read back clean with every circular
/// move sampled on its circle against the dense plan.
#[test]
fn circular_beads_round_trip_in_every_vendor() {
    for file in crate::fixture::FANUC_CELLS
        .iter()
        .chain(&crate::fixture::KUKA_CELLS)
        .chain(&crate::fixture::ABB_CELLS)
    {
        let c = cell(file);
        let prog = thinned_hemisphere(&c, 0..3);
        let vias = prog.points.iter().filter(|p| p.via).count();
        let kept = prog.bead_points().count();
        println!(
            "{file}: {} planned, {kept} positions, {vias} circular moves",
            prog.planned.len()
        );
        // the ROBOWAM part-carried cells move the flange in the robot
        // base frame (FANUC without remote TCP): the part turns on J6 under
        // the torch and the flange's path is no circle
        if !file.starts_with("robowam_part_carried") {
            assert!(vias > 0, "{file}: no circular move");
        }
        let settings = ProgramSettings::default();
        let files = emit(&prog, &settings).unwrap();
        let r = check_files(c.robot().vendor, &files, &c, &settings, Some(&prog.planned)).unwrap();
        assert!(r.is_ok(), "{file}:\n{r}");
    }
}
