//! Reachability up front (issue 22): a cell whose deposition point (or
//! positioner) the arm cannot reach is refused by the cell-file reader,
//! naming the field, the distance and the arm's reach, before anything is
//! optimised; every sample cell still reads.

use waam_slicer::io::cell_file::{parse_cell_file, read_cell_file, CellFileError};
use waam_slicer::robot::{CellLayout, OutOfReach, RobotError};

use crate::common::part_path;

fn sample(name: &str) -> String {
    std::fs::read_to_string(part_path(&format!("cells/{name}"))).unwrap()
}

/// The ROBOWAM part-carried cell with its deposition point replaced.
fn robowam_with_point(point: &str) -> String {
    let text = sample("robowam_part_carried.toml");
    let line = text
        .lines()
        .find(|l| l.starts_with("deposition_point_mm"))
        .unwrap();
    text.replace(line, &format!("deposition_point_mm = {point}"))
}

fn refused(text: &str) -> (RobotError, String) {
    match parse_cell_file(text, "typo.toml") {
        Ok(_) => panic!("accepted:\n{text}"),
        Err(CellFileError::Robot { source, .. }) => {
            let msg = parse_cell_file(text, "typo.toml").unwrap_err().to_string();
            assert!(msg.starts_with("typo.toml: "), "{msg}");
            (source, msg)
        }
        Err(e) => panic!("not a robot error: {e}"),
    }
}

#[test]
fn every_sample_cell_reads_and_reaches_its_work() {
    let dir = part_path("cells");
    let mut cells = 0;
    for entry in std::fs::read_dir(&dir).unwrap() {
        let p = entry.unwrap().path();
        let file = read_cell_file(&p).unwrap_or_else(|e| panic!("{e}"));
        if let Some(cell) = file.cell {
            // also with no part allowance at all: the sample cells' work is in reach
            cell.check_reach(0.0)
                .unwrap_or_else(|e| panic!("{}: {e}", p.display()));
            cells += 1;
        }
    }
    assert!(cells >= 7, "{cells} cells");
}

/// The typo: `[5000, 0, 0]` for the ROBOWAM arm (upper arm 790 mm,
/// forearm 835 mm with a 250 mm elbow offset, wrist to flange 100 mm).
#[test]
fn deposition_point_out_of_reach_is_refused_naming_field_distance_and_reach() {
    let (e, msg) = refused(&robowam_with_point("[5000, 0, 0]"));
    let RobotError::OutOfReach(r) = e else {
        panic!("{e:?}")
    };
    let OutOfReach {
        field,
        distance_mm,
        max_reach_mm,
        arm_max_mm,
        ..
    } = *r;
    assert_eq!(field, "deposition_point_mm");
    // shoulder circle: radius 150 mm (J2 axis offset) at height 0
    assert!((distance_mm - 4850.0).abs() < 1e-9, "{distance_mm}");
    let k = 835.0_f64.hypot(250.0);
    assert!((arm_max_mm - (790.0 + k)).abs() < 1e-9, "{arm_max_mm}");
    // + wrist to flange 100 mm + the reader's 1 m part allowance
    assert!(
        (max_reach_mm - (arm_max_mm + 100.0 + 1000.0)).abs() < 1e-2,
        "{max_reach_mm}"
    );
    for part in [
        "`deposition_point_mm`",
        "(5000.0, 0.0, 0.0)",
        "4850.0 mm",
        "out of the arm's reach",
    ] {
        assert!(msg.contains(part), "{part} missing from: {msg}");
    }
}

#[test]
fn huge_deposition_point_is_refused_with_a_readable_message() {
    let (e, msg) = refused(&robowam_with_point("[1e308, 0, 0]"));
    assert!(
        matches!(&e, RobotError::OutOfReach(r) if r.field == "deposition_point_mm"),
        "{e:?}"
    );
    assert!(msg.contains("1.000e308"), "{msg}");
    assert!(msg.len() < 400, "{} characters: {msg}", msg.len());
    // components whose squares overflow
    let (e, _) = refused(&robowam_with_point("[1.7e308, 1.7e308, 1.7e308]"));
    assert!(matches!(e, RobotError::OutOfReach(_)), "{e:?}");
    let (e, msg) = refused(&robowam_with_point("[inf, 0, 0]"));
    assert!(
        matches!(
            e,
            RobotError::InvalidParameter {
                field: "deposition_point_mm",
                ..
            }
        ),
        "{e:?}"
    );
    assert!(msg.contains("finite"), "{msg}");
}

/// Too near: the point inside the arm's dead zone? The ROBOWAM arm folds
/// to |790 − 872| = 82 mm, less than its wrist and mounts, so no point is
/// too near for it; an arm with a long upper arm and short forearm has a
/// dead zone around its shoulder.
#[test]
fn point_in_the_dead_zone_of_a_folded_arm_is_refused() {
    let text = robowam_with_point("[150, 0, 0]").replace(
        "preset = \"arcmate120ic_nominal\"",
        "vendor = \"fanuc\"\nmax_speed_deg_s = [100, 100, 100, 100, 100, 100]\n\
             geometry = { shoulder_offset_mm = 150, upper_arm_mm = 3000, elbow_offset_mm = 0, \
             forearm_mm = 500, wrist_to_flange_mm = 100 }",
    );
    // within 1 m allowance of the 2500 mm dead zone: refused with the nearest-reach distance
    let file = parse_cell_file(&text, "typo.toml");
    let Err(CellFileError::Robot {
        source: RobotError::OutOfReach(r),
        ..
    }) = file
    else {
        panic!("{file:?}")
    };
    let (distance_mm, min_reach_mm) = (r.distance_mm, r.min_reach_mm);
    assert!(distance_mm < min_reach_mm, "{distance_mm} {min_reach_mm}");
    assert!(
        (min_reach_mm - (2500.0 - 100.0 - 1000.0)).abs() < 1e-2,
        "{min_reach_mm}"
    );
}

/// A torch-carried cell whose positioner is 9 m away.
#[test]
fn positioner_out_of_reach_is_refused() {
    let text = sample("kuka_kr16_2_torch_carried.toml").replace(
        "positioner_pose_xyzwpr = [1100.0, 0.0, 150.0, 0.0, 0.0, 0.0]",
        "positioner_pose_xyzwpr = [9000.0, 0.0, 150.0, 0.0, 0.0, 0.0]",
    );
    let (e, msg) = refused(&text);
    assert!(
        matches!(&e, RobotError::OutOfReach(r) if r.field == "positioner_pose_xyzwpr"),
        "{e:?}"
    );
    assert!(msg.contains("`positioner_pose_xyzwpr`"), "{msg}");
}

#[test]
fn huge_mounts_are_refused_naming_the_field() {
    let text = sample("kuka_kr16_2_torch_carried.toml").replace(
        "tool_xyzwpr = [-86.0, 0.0, 406.0, -180.0, -36.0, 0.0]",
        "tool_xyzwpr = [1e308, 0.0, 406.0, -180.0, -36.0, 0.0]",
    );
    let (e, msg) = refused(&text);
    assert!(
        matches!(
            e,
            RobotError::InvalidParameter {
                field: "tool_xyzwpr",
                ..
            }
        ),
        "{e:?}"
    );
    assert!(msg.contains("100 m"), "{msg}");
    let text = sample("kuka_kr16_2_torch_carried.toml")
        .replace("tilt_to_table_mm = 150.0", "tilt_to_table_mm = 1e308");
    let (e, _) = refused(&text);
    assert!(
        matches!(
            e,
            RobotError::InvalidParameter {
                field: "positioner.tilt_to_table_mm",
                ..
            }
        ),
        "{e:?}"
    );
    let text = robowam_with_point(
        "[1045.747, -630.155, 653.167]\nflange_from_part_xyzwpr = [0, 0, 1e300, 0, 0, 0]",
    );
    let (e, _) = refused(&text);
    assert!(
        matches!(
            e,
            RobotError::InvalidParameter {
                field: "flange_from_part_xyzwpr",
                ..
            }
        ),
        "{e:?}"
    );
}

/// The bound is sound: points the arm does reach (FK of random joints) are
/// never refused, with the wrist and mounts accounted for.
#[test]
fn reachable_deposition_points_are_never_refused() {
    let text = sample("robowam_part_carried.toml");
    let Some(CellLayout::PartCarried(base)) = parse_cell_file(&text, "robowam.toml").unwrap().cell
    else {
        panic!("not a part-carried cell")
    };
    let mut state = 12345_u64;
    let mut next = || {
        state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (state >> 11) as f64 / (1u64 << 53) as f64
    };
    for _ in 0..2000 {
        let q: [f64; 6] = std::array::from_fn(|_| (next() - 0.5) * 2.0 * std::f64::consts::PI);
        let flange = base.robot.flange_pose(&q);
        // the part origin at the flange (identity mount): a path point there
        let mut cell = base.clone();
        cell.deposition_point_mm = flange.translation.vector.into();
        cell.check_reach(0.0)
            .unwrap_or_else(|e| panic!("q = {q:?}: {e}"));
    }
}
