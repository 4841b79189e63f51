//! Issue 19, deliverable 4: every sample part in every sample cell, after
//! `place_part`, plans feasibly in the placed cell file (read back as `plan`
//! reads it, the program stage's checks included), or the search is refused
//! with the binding constraint named. The placed cell reproduces itself:
//! placing again from the written file keeps the placement (the cell as
//! given is certified first unless beaten by `KEEP_MARGIN`).
//!
//! Reduced for test time (stated; the README's table is from the full
//! search at the part files' own grids): Delta 8 mm and 16 points a layer,
//! 8 coarse candidates on a 4-layer × 8-point subsample, one compass
//! search of 6 evaluations, 2 rounds. Feasibility on this coarse grid is
//! not the fine grid's: the test checks that `place` keeps its promise
//! (feasible when it says so, a named constraint when it does not), not the
//! README's table. What is not checked here: that the margins are the best
//! attainable (only that the search is consistent with itself).

use crate::common::{part_path, SAMPLE_PARTS};
use waam_slicer::optimise::place::PlaceOptions;
use waam_slicer::pipeline::{place_part, PlaceRequest};
use waam_slicer::{plan_part, Cell, Part, PlanOptions, SliceOverrides};

fn coarse() -> SliceOverrides {
    SliceOverrides {
        delta_mm: Some(8.0),
        discretisation: Some(waam_slicer::path::Discretisation::Points(16)),
        ..SliceOverrides::default()
    }
}

fn small_search() -> PlaceRequest {
    PlaceRequest {
        slice: coarse(),
        search: PlaceOptions {
            samples: 8,
            layers: 4,
            points_per_layer: 8,
            refined: 1,
            refine_evaluations: 6,
            rounds: 2,
            ..PlaceOptions::default()
        },
        ..PlaceRequest::default()
    }
}

/// The sample cells with a layout (the robot-only files are skipped).
fn sample_cells() -> Vec<(String, Cell)> {
    let mut cells: Vec<(String, Cell)> = std::fs::read_dir(part_path("cells"))
        .unwrap()
        .filter_map(|e| {
            let p = e.unwrap().path();
            let name = p.file_name()?.to_str()?.to_string();
            Cell::read(&p).ok().map(|c| (name, c))
        })
        .collect();
    cells.sort_by(|a, b| a.0.cmp(&b.0));
    cells
}

/// Words of the constraints the optimiser and the program stage name.
const CONSTRAINTS: [&str; 8] = [
    "travel",
    "speed",
    "dexterity",
    "hose torsion",
    "no joint solution",
    "keep-out",
    "program check",
    "vertical",
];

#[test]
fn every_sample_part_in_every_sample_cell_plans_after_placement_or_names_its_binding() {
    let cells = sample_cells();
    assert!(cells.len() >= 7, "{} cells", cells.len());
    let parts: Vec<&str> = SAMPLE_PARTS
        .iter()
        .copied()
        .chain(["s-bend.toml"])
        .collect();
    let opts = PlanOptions {
        slice: coarse(),
        ..PlanOptions::default()
    };
    let req = small_search();
    let mut table = Vec::new();
    for (cell_name, cell) in &cells {
        for part_name in &parts {
            let part = Part::read(part_path(part_name)).unwrap();
            let placed = place_part(&part, cell, &req)
                .unwrap_or_else(|e| panic!("{part_name} in {cell_name}: {e}"));
            let p = &placed.placement;
            if p.feasible {
                let again = Cell::from_toml_str(&placed.toml, "placed.toml")
                    .unwrap_or_else(|e| panic!("{part_name} in {cell_name}: {e}"));
                let planned = plan_part(&part, &again, &opts).unwrap();
                assert!(
                    planned.is_feasible(),
                    "{part_name} in {cell_name}: placed but {:?}",
                    planned.refusal
                );
                table.push(format!(
                    "{cell_name} {part_name}: placed ({:.1} s)",
                    p.time_s
                ));
            } else {
                let (binding, share) = p
                    .binding
                    .clone()
                    .unwrap_or_else(|| panic!("{part_name} in {cell_name}: no binding named"));
                assert!(
                    CONSTRAINTS.iter().any(|c| binding.contains(c)) && share > 0.0,
                    "{part_name} in {cell_name}: binding {binding:?} ({share})"
                );
                table.push(format!(
                    "{cell_name} {part_name}: refused, {binding} ({:.0} %, {:.1} s)",
                    100.0 * share,
                    p.time_s
                ));
            }
        }
    }
    eprintln!("{}", table.join("\n"));
}

/// Placing again from a placed cell file finds the same placement: the
/// deposition point within 0.01 mm and the mount within 0.01° (the file
/// keeps 6 decimals of mm and degrees).
#[test]
fn a_placed_cell_placed_again_finds_itself() {
    // The S-bend is refused where the ROBOWAM part-carried cell puts it: the
    // first placement moves it, the second must keep it.
    let part = Part::read(part_path("s-bend.toml")).unwrap();
    let cell = Cell::read(part_path("cells/robowam_part_carried.toml")).unwrap();
    let req = small_search();
    let placed = place_part(&part, &cell, &req).unwrap();
    assert!(placed.placement.feasible, "{:#}", placed.summary());
    let again = Cell::from_toml_str(&placed.toml, "placed.toml").unwrap();
    let replaced = place_part(&part, &again, &req).unwrap();
    assert!(replaced.placement.feasible, "{:#}", replaced.summary());
    let (a, b) = match (&placed.cell.layout, &replaced.cell.layout) {
        (waam_slicer::robot::Cell::PartCarried(a), waam_slicer::robot::Cell::PartCarried(b)) => {
            (a, b)
        }
        _ => panic!("part carried"),
    };
    let d = (a.deposition_point_mm - b.deposition_point_mm).norm();
    assert!(d < 0.01, "D_R moved by {d} mm");
    let angle = a
        .flange_from_part
        .rotation
        .angle_to(&b.flange_from_part.rotation)
        .to_degrees();
    assert!(angle < 0.01, "mount turned by {angle} deg");
}
