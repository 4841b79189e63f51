//! The front door (`waam_slicer::{Part, Cell, slice_part, plan_part,
//! check_program}`), on real sample parts and cells: the one-call plan writes
//! a program that reads back clean, an infeasible plan cannot write one (no
//! layer silently vanishes), errors name the file, the joints CSV round-trips
//! and a host's cancel flag stops a run.

use std::sync::atomic::AtomicBool;
use std::sync::Arc;

use crate::shared::part_path;
use waam_slicer::io::joints_csv::read_joints_csv;
use waam_slicer::optimise::{Constraint, LayerStatus};
use waam_slicer::program::{LayerRefusal, ProgramError};
use waam_slicer::robot::Vendor;
use waam_slicer::{
    check_program, plan_part, plan_part_with, slice_part, Cell, Control, Error, ErrorKind, Part,
    PlanOptions, SliceOverrides,
};

fn small(points: usize) -> PlanOptions {
    PlanOptions {
        slice: SliceOverrides {
            discretisation: Some(waam_slicer::path::Discretisation::Points(points)),
            ..SliceOverrides::default()
        },
        ..PlanOptions::default()
    }
}

#[test]
fn one_call_plan_writes_a_program_that_reads_back_clean() {
    let part = Part::read(part_path("hemisphere.toml")).unwrap();
    let cell = Cell::read(part_path("cells/robowam_part_carried.toml")).unwrap();
    let sliced = slice_part(&part).unwrap();
    // Constant-distance layers hold Delta (SPEC §3.2: ~0 % variation).
    let o = sliced.map.overall.unwrap();
    assert!((o.max_mm - o.min_mm) < 1e-4 * sliced.path.delta_mm, "{o:?}");
    let planned = plan_part(&part, &cell, &small(120)).unwrap();
    assert!(planned.is_feasible(), "{:?}", planned.refusal());
    assert_eq!(planned.format, Vendor::Fanuc);
    let dir = tempfile::tempdir().unwrap();
    let files = planned.write_programs(dir.path()).unwrap();
    assert_eq!(files[0], dir.path().join("HEMISPHERE.ls"));
    let report = check_program(&files[0], &cell).unwrap();
    assert!(report.problems.is_empty(), "{:?}", report.problems);
    // Every planned point is in the program: the validator saw every bead.
    assert_eq!(report.beads, planned.plan.layers.len());
    // The folder plan wrote stands for its one program.
    let by_folder = check_program(dir.path(), &cell).unwrap();
    assert_eq!(
        (by_folder.motions, by_folder.beads),
        (report.motions, report.beads)
    );
    let empty = tempfile::tempdir().unwrap();
    let m = check_program(empty.path(), &cell).unwrap_err().to_string();
    assert!(m.contains("no program file"), "{m}");

    // Serialisable: summary plus one entry per point.
    let v = serde_json::to_value(&planned).unwrap();
    assert_eq!(v["summary"]["feasible"], true);
    assert_eq!(v["summary"]["cell_file"], cell.file.as_str());
    assert_eq!(v["points"].as_array().unwrap().len(), 14 * 120);
    let s = serde_json::to_value(&sliced).unwrap();
    assert_eq!(s["summary"]["layers"], sliced.path.layers.len());
    assert!(s["layers"][0]["delta"][0].is_null());
}

#[test]
fn an_infeasible_plan_cannot_write_a_program_and_names_its_layer() {
    let part = Part::read(part_path("hemisphere.toml")).unwrap();
    let cell = Cell::read(part_path("cells/robowam_part_carried.toml")).unwrap();
    let opts = small(60).with_rz("fixed:0".parse().unwrap());
    let planned = plan_part(&part, &cell, &opts).unwrap();
    assert!(!planned.is_feasible());
    let first = planned.plan.infeasible_layers().next().unwrap().layer;
    let dir = tempfile::tempdir().unwrap();
    let written = planned.write_programs(dir.path());
    // an answer about the part in the cell, not bad input
    assert_eq!(
        written.as_ref().map_err(Error::kind).err(),
        Some(ErrorKind::Infeasible)
    );
    match written {
        Err(Error::Program(ProgramError::InfeasibleLayer {
            layer,
            count,
            status,
        })) => {
            assert_eq!(layer, first);
            assert!(count >= 1);
            // typed: R_Z = 0 turns J5 out of its travel (thesis §4.3), the
            // binding constraint is J5's limit, read without parsing text
            let binding = match &status {
                LayerRefusal::Infeasible(
                    LayerStatus::Infeasible { binding } | LayerStatus::FixedViolates { binding },
                ) => binding.constraint,
                other => panic!("expected an infeasible layer's status, got {other:?}"),
            };
            assert_eq!(binding, Constraint::JointLimit { joint: 5 }, "{status}");
            assert!(status.to_string().contains("J5"), "{status}");
        }
        other => panic!("expected InfeasibleLayer, got {other:?}"),
    }
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
}

#[test]
fn a_layer_lost_between_plan_and_program_is_refused() {
    let part = Part::read(part_path("hemisphere.toml")).unwrap();
    let cell = Cell::read(part_path("cells/robowam_part_carried.toml")).unwrap();
    let mut planned = plan_part(&part, &cell, &small(60)).unwrap();
    assert!(planned.is_feasible());
    // A host that drops a layer's plan (or an optimiser that returned none).
    planned.plan.layers.pop();
    let last = planned.layers.last().unwrap().layer;
    match planned.program_files() {
        Err(Error::Program(ProgramError::InfeasibleLayer { layer, .. })) => assert_eq!(layer, last),
        other => panic!("expected InfeasibleLayer, got {other:?}"),
    }
}

#[test]
fn another_vendors_format_is_refused_before_planning() {
    let part = Part::read(part_path("hemisphere.toml")).unwrap();
    let cell = Cell::read(part_path("cells/robowam_part_carried.toml")).unwrap();
    let opts = PlanOptions {
        format: Some(Vendor::Kuka),
        ..small(60)
    };
    let e = plan_part(&part, &cell, &opts).unwrap_err();
    assert!(
        matches!(e, Error::Program(ProgramError::VendorMismatch { .. })),
        "{e}"
    );
}

#[test]
fn errors_name_the_file_and_field() {
    let e = Part::read(part_path("no-such-part.toml")).unwrap_err();
    assert!(e.to_string().contains("no-such-part.toml"), "{e}");
    assert_eq!(
        Error::from(e.clone()).kind(),
        ErrorKind::Io,
        "a missing file: {e}"
    );
    // A robot-only cell file is not a cell.
    let e = Cell::read(part_path("cells/kuka_kr16_2.toml")).unwrap_err();
    assert!(e.to_string().contains("kuka_kr16_2.toml"), "{e}");
    assert!(e.to_string().contains("not a cell"), "{e}");
    assert_eq!(Error::from(e).kind(), ErrorKind::Input);
    // A bad override names the part file and the option.
    let part = Part::read(part_path("hemisphere.toml")).unwrap();
    let cell = Cell::read(part_path("cells/robowam_part_carried.toml")).unwrap();
    let mut opts = small(60);
    opts.slice.delta_mm = Some(-1.0);
    let e: Error = plan_part(&part, &cell, &opts).unwrap_err();
    assert_eq!(e.kind(), ErrorKind::Input, "{e}");
    let m = e.to_string();
    assert!(
        m.contains("hemisphere.toml") && m.contains("delta_mm"),
        "{m}"
    );
    opts.slice.delta_mm = None;
    opts.slice.travel_speed_mm_s = Some(f64::NAN);
    let m = plan_part(&part, &cell, &opts).unwrap_err().to_string();
    assert!(
        m.contains("hemisphere.toml") && m.contains("travel_speed"),
        "{m}"
    );
    // An unknown program type names the file.
    let m = check_program("out/HEMI.txt", &cell)
        .unwrap_err()
        .to_string();
    assert!(
        m.contains("HEMI.txt") && m.contains("unknown program type"),
        "{m}"
    );
    // Part::from_toml_str names the origin.
    let m = Part::from_toml_str("name = 3", "host-buffer.toml")
        .unwrap_err()
        .to_string();
    assert!(m.contains("host-buffer.toml"), "{m}");
}

#[test]
fn joints_csv_round_trips_the_plan() {
    let part = Part::read(part_path("hemisphere.toml")).unwrap();
    let cell = Cell::read(part_path("cells/kuka_kr16_2_torch_carried.toml")).unwrap();
    let opts = PlanOptions {
        slice: SliceOverrides {
            max_layers: Some(3),
            ..small(60).slice
        },
        ..PlanOptions::default()
    };
    let planned = plan_part(&part, &cell, &opts).unwrap();
    let mut buf = Vec::new();
    planned.write_joints_csv(&mut buf).unwrap();
    let rows = read_joints_csv(std::str::from_utf8(&buf).unwrap(), "joints.csv").unwrap();
    let points: Vec<_> = planned.plan.layers.iter().flat_map(|l| &l.points).collect();
    assert_eq!(rows.len(), points.len());
    for (r, p) in rows.iter().zip(points) {
        let q = p.joints.unwrap();
        for (read, planned) in r.joints_deg.unwrap().iter().zip(q) {
            assert!((read - planned.to_degrees()).abs() < 1e-6);
        }
        let e = p.positioner.unwrap();
        assert!((r.positioner_deg.unwrap()[1] - e[1].to_degrees()).abs() < 1e-6);
        // every plan writes the process columns: the programmed speed and
        // the point's local distance to the layer below (Delta on layer 0)
        assert!((r.travel_speed_mm_s.unwrap() - planned.travel_speed_mm_s()).abs() < 1e-6);
        let want = planned.sliced.path.layers[r.layer].points[r.point]
            .delta
            .unwrap_or(planned.sliced.path.delta_mm);
        assert!((r.bead_height_mm.unwrap() - want).abs() < 1e-6);
    }
    // A damaged row is named by its line and column.
    let text = String::from_utf8(buf).unwrap();
    let mut lines: Vec<String> = text.lines().map(String::from).collect();
    let mut cells: Vec<&str> = lines[1].split(',').collect();
    cells[2] = "x";
    lines[1] = cells.join(",");
    let Err(e) = read_joints_csv(&lines.join("\n"), "joints.csv") else {
        panic!("a damaged row must be refused");
    };
    let m = e.to_string();
    assert!(
        m.starts_with("joints.csv, line 2") && m.contains("`x`"),
        "{m}"
    );
}

#[test]
fn a_cancel_flag_stops_the_run() {
    let part = Part::read(part_path("hemisphere.toml")).unwrap();
    let cell = Cell::read(part_path("cells/robowam_part_carried.toml")).unwrap();
    let flag = Arc::new(AtomicBool::new(true));
    let seen = Arc::new(std::sync::Mutex::new(Vec::new()));
    let s2 = seen.clone();
    let control = Control::default()
        .with_cancel(flag)
        .with_progress(move |stage, f| s2.lock().unwrap().push((stage.to_string(), f)));
    let e = plan_part_with(&part, &cell, &small(60), &control).unwrap_err();
    assert!(matches!(e, Error::Cancelled { .. }), "{e}");
    assert_eq!(e.kind(), ErrorKind::Cancelled);
    assert!(seen.lock().unwrap().is_empty());
}

/// A plan reports the fraction of the whole run: its slicing stage reports
/// within the first tenth, and the fractions never go back.
#[test]
fn a_plans_progress_rises_from_0_to_1() {
    let part = Part::read(part_path("hemisphere.toml")).unwrap();
    let cell = Cell::read(part_path("cells/robowam_part_carried.toml")).unwrap();
    let seen = Arc::new(std::sync::Mutex::new(Vec::new()));
    let s2 = seen.clone();
    let control = Control::default()
        .with_progress(move |stage, f| s2.lock().unwrap().push((stage.to_string(), f)));
    let opts = small(40).with_rz("fixed:90".parse().unwrap());
    plan_part_with(&part, &cell, &opts, &control).unwrap();
    let seen = seen.lock().unwrap();
    let fractions: Vec<f64> = seen.iter().map(|s| s.1).collect();
    assert!(fractions.windows(2).all(|w| w[0] <= w[1]), "{seen:?}");
    assert_eq!(fractions.first(), Some(&0.0), "{seen:?}");
    assert_eq!(fractions.last(), Some(&1.0), "{seen:?}");
    assert!(
        seen.iter()
            .filter(|s| s.0 == "slicing" || s.0 == "tool axes")
            .all(|s| s.1 <= 0.1),
        "{seen:?}"
    );
}

#[test]
fn a_run_over_the_point_budget_is_refused_before_any_work() {
    // `--delta 0.01 --points 2000` (meant `--delta 1`): ~20 M points.
    let part = Part::read(part_path("quarter-torus.toml")).unwrap();
    let o = SliceOverrides {
        delta_mm: Some(0.01),
        discretisation: Some(waam_slicer::path::Discretisation::Points(2000)),
        ..SliceOverrides::default()
    };
    // refused before any work: no stage of the run reports progress
    let reports = std::sync::Arc::new(std::sync::atomic::AtomicUsize::new(0));
    let seen = reports.clone();
    let control = Control::default().with_progress(move |_, _| {
        seen.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    });
    let e = waam_slicer::slice_part_with(&part, &o, &control).unwrap_err();
    assert_eq!(reports.load(std::sync::atomic::Ordering::Relaxed), 0);
    match &e {
        Error::OverBudget { points, budget, .. } => {
            assert!(*points > 10_000_000 && *budget == waam_slicer::pipeline::DEFAULT_MAX_POINTS)
        }
        other => panic!("expected OverBudget, got {other}"),
    }
    let m = e.to_string();
    assert!(
        m.contains("quarter-torus.toml") && m.contains("--max-points"),
        "{m}"
    );
    // Raised budget: the same request passes the gate (checked with a
    // smaller part of the work: one layer).
    let o = SliceOverrides {
        max_points: Some(u64::MAX),
        max_layers: Some(2),
        ..o
    };
    assert!(waam_slicer::slice_part_with(&part, &o, &Control::default()).is_ok());
}

#[test]
fn a_cancel_during_optimisation_stops_between_layers() {
    let part = Part::read(part_path("hemisphere.toml")).unwrap();
    let cell = Cell::read(part_path("cells/robowam_part_carried.toml")).unwrap();
    let flag = Arc::new(AtomicBool::new(false));
    let f2 = flag.clone();
    let control = Control::default()
        .with_cancel(flag)
        .with_progress(move |stage, f| {
            // the host presses "stop" once a layer is done
            if stage == "optimising" && f > 0.1 {
                f2.store(true, std::sync::atomic::Ordering::Relaxed);
            }
        });
    let e = plan_part_with(&part, &cell, &small(60), &control).unwrap_err();
    assert!(
        matches!(
            e,
            Error::Cancelled {
                stage: "optimising"
            }
        ),
        "{e}"
    );
}
