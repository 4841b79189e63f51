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
use waam_slicer::pipeline::{place_part, PlaceRequest};
use waam_slicer::place::PlaceOptions;
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
                    planned.refusal()
                );
                table.push(format!(
                    "{cell_name} {part_name}: placed ({:.1} s)",
                    p.time_s
                ));
            } else {
                let (binding, share) = p
                    .binding
                    .as_ref()
                    .map(|b| (b.to_string(), b.share()))
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
    assert!(placed.placement.feasible, "{:#?}", placed.summary());
    let again = Cell::from_toml_str(&placed.toml, "placed.toml").unwrap();
    let replaced = place_part(&part, &again, &req).unwrap();
    assert!(replaced.placement.feasible, "{:#?}", replaced.summary());
    let (a, b) = match (&placed.cell.layout, &replaced.cell.layout) {
        (
            waam_slicer::robot::CellLayout::PartCarried(a),
            waam_slicer::robot::CellLayout::PartCarried(b),
        ) => (a, b),
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

/// `waam place`: exit 0 with a `cell.toml` that `waam plan` takes, exit 1
/// naming a bad range's field, exit 2 naming the binding constraint (the
/// general tube in the KUKA torch-carried cell: the positioner's J8 speed,
/// as the README's table gives it). Coarse grids for test time.
#[test]
fn the_place_command_exits_0_1_or_2() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("placed");
    let grid = ["--delta", "8", "--points", "16", "--samples", "8"];
    let run = |args: &[&str]| crate::common::waam().args(args).output().unwrap();
    let hemi = part_path("hemisphere.toml");
    let cell = part_path("cells/robowam_part_carried.toml");
    let mut args = vec![
        "place",
        hemi.to_str().unwrap(),
        "--cell",
        cell.to_str().unwrap(),
    ];
    args.extend(grid);
    args.extend(["--out", out.to_str().unwrap()]);
    let o = run(&args);
    assert_eq!(
        o.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    let placed = out.join("cell.toml");
    assert!(out.join("placement.json").exists());
    let plan_out = dir.path().join("plan");
    let mut args = vec![
        "plan",
        hemi.to_str().unwrap(),
        "--cell",
        placed.to_str().unwrap(),
    ];
    args.extend([
        "--delta",
        "8",
        "--points",
        "16",
        "--out",
        plan_out.to_str().unwrap(),
    ]);
    let o = run(&args);
    assert_eq!(
        o.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );

    let bad = dir.path().join("bad.toml");
    let text = std::fs::read_to_string(&cell).unwrap() + "\n[placement]\ntilt_x_deg = [-100, 0]\n";
    std::fs::write(&bad, text).unwrap();
    let o = run(&[
        "place",
        hemi.to_str().unwrap(),
        "--cell",
        bad.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&o.stderr).contains("placement.tilt_x_deg"));

    // the general tube at this coarse grid: refused as given in the KUKA
    // torch-carried cell before the laws' knots followed the turning of `b`
    // (exit 2, the cone); placed now, and its placed cell plans
    let tube = part_path("general-tube.toml");
    let torch = part_path("cells/kuka_kr16_2_torch_carried.toml");
    let mut args = vec![
        "place",
        tube.to_str().unwrap(),
        "--cell",
        torch.to_str().unwrap(),
    ];
    args.extend(grid);
    args.extend(["--out", out.to_str().unwrap()]);
    let o = run(&args);
    assert_eq!(
        o.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    let o = run(&[
        "plan",
        tube.to_str().unwrap(),
        "--cell",
        placed.to_str().unwrap(),
        "--delta",
        "8",
        "--points",
        "16",
        "--out",
        plan_out.to_str().unwrap(),
    ]);
    assert_eq!(
        o.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );

    // the quarter torus with 120 points a layer: its top layer turns `b`
    // faster than the cone lets any placement follow (exit 2, named)
    let torus = part_path("quarter-torus.toml");
    let o = run(&[
        "place",
        torus.to_str().unwrap(),
        "--cell",
        torch.to_str().unwrap(),
        "--delta",
        "8",
        "--points",
        "120",
        "--samples",
        "8",
        "--out",
        out.to_str().unwrap(),
    ]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    // the binding constraint is named: the build direction's cone (the
    // positioner's laws; before them the turn's J8 speed bound everywhere)
    assert!(
        err.contains("cone of the vertical") || err.contains("speed"),
        "{err}"
    );
}
