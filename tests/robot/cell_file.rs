//! Cell files of `parts/cells/` and the reader's errors.

use std::path::PathBuf;

use waam_slicer::io::cell_file::{parse_cell_file, read_cell_file, CellFileError};
use waam_slicer::math::Point3;
use waam_slicer::robot::{CellLayout, Configuration, RobotModel, Vendor};

fn cells_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("parts/cells")
}

#[test]
fn every_shipped_cell_file_reads_and_validates() {
    let mut n = 0;
    for entry in std::fs::read_dir(cells_dir()).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_some_and(|e| e == "toml") {
            let f = read_cell_file(&path).unwrap_or_else(|e| panic!("{e}"));
            f.robot.validate().unwrap();
            assert!(!f.source.is_empty(), "{}: name the source", path.display());
            n += 1;
        }
    }
    assert!(n >= 5);
}

#[test]
fn robowam_part_carried_files_match_the_thesis() {
    let f = read_cell_file(cells_dir().join("robowam_part_carried.toml")).unwrap();
    let Some(CellLayout::PartCarried(c)) = f.cell else {
        panic!("part-carried cell expected")
    };
    assert_eq!(
        c.deposition_point_mm,
        Point3::new(1045.747, -630.155, 653.167)
    );
    assert_eq!(c.configuration, Configuration::from_fanuc("F U T").unwrap());
    assert!((c.robot.limits[4].upper_rad.to_degrees() - 135.0).abs() < 1e-12);
    assert!(c.robot.limits[5].is_unlimited());
    assert_eq!(
        c.robot.geometry,
        RobotModel::arcmate_120ic_nominal().geometry
    );
    let f = read_cell_file(cells_dir().join("robowam_part_carried_second_position.toml")).unwrap();
    let Some(CellLayout::PartCarried(c)) = f.cell else {
        panic!()
    };
    assert_eq!(
        c.deposition_point_mm,
        Point3::new(988.057, -733.138, 1104.885)
    );
}

#[test]
fn robowam_torch_carried_file_matches_the_thesis() {
    let f = read_cell_file(cells_dir().join("robowam_torch_carried.toml")).unwrap();
    let Some(CellLayout::TorchCarried(c)) = f.cell else {
        panic!("torch-carried cell expected")
    };
    assert_eq!(c.positioner.tilt_to_table_mm, 149.631);
    let t = c.base_from_positioner.translation.vector;
    assert!((t - waam_slicer::math::Vector3::new(920.588, 820.862, -254.408)).norm() < 1e-12);
    let tcp = c.flange_from_tcp.translation.vector;
    assert!((tcp - waam_slicer::math::Vector3::new(-86.0, 0.0, 406.0)).norm() < 1e-12);
    assert!((c.max_hose_torsion_rad.to_degrees() - 120.0).abs() < 1e-12);
}

#[test]
fn kuka_and_abb_files_equal_the_presets() {
    let k = read_cell_file(cells_dir().join("kuka_kr16_2.toml")).unwrap();
    let p = RobotModel::kuka_kr16_2();
    assert_eq!(k.robot.vendor, Vendor::Kuka);
    assert_eq!(k.robot.geometry, p.geometry);
    assert_eq!(k.robot.convention, p.convention);
    for j in 0..6 {
        assert!((k.robot.limits[j].upper_rad - p.limits[j].upper_rad).abs() < 1e-9);
        assert!((k.robot.max_speed_rad_s[j] - p.max_speed_rad_s[j]).abs() < 1e-9);
    }
    let a = read_cell_file(cells_dir().join("abb_irb2600_12_185.toml")).unwrap();
    let p = RobotModel::abb_irb2600_12_185();
    assert_eq!(a.robot.geometry, p.geometry);
    for j in 0..6 {
        assert!(
            (a.robot.limits[j].lower_rad - p.limits[j].lower_rad).abs() < 1e-6,
            "J{}",
            j + 1
        );
        assert!(
            (a.robot.limits[j].upper_rad - p.limits[j].upper_rad).abs() < 1e-6,
            "J{}",
            j + 1
        );
        assert!((a.robot.max_speed_rad_s[j] - p.max_speed_rad_s[j]).abs() < 1e-6);
    }
    assert!(a.cell.is_none());
}

const MINIMAL: &str = r#"
name = "t"
source = "test"
[robot]
preset = "arcmate120ic_nominal"
[part_carried]
deposition_point_mm = [1000.0, 0.0, 500.0]
configuration = "N U T"
"#;

#[test]
fn misspelt_key_is_an_error_naming_it() {
    assert!(parse_cell_file(MINIMAL, "mem").is_ok());
    let bad = MINIMAL.replace("deposition_point_mm", "deposition_pont_mm");
    let e = parse_cell_file(&bad, "mem.toml").unwrap_err();
    assert!(matches!(e, CellFileError::Syntax { .. }));
    let s = e.to_string();
    assert!(
        s.contains("mem.toml") && s.contains("deposition_pont_mm"),
        "{s}"
    );
}

#[test]
fn bad_values_are_errors_naming_the_key() {
    let e = parse_cell_file(&MINIMAL.replace("\"N U T\"", "\"X U T\""), "f").unwrap_err();
    assert!(e.to_string().contains("part_carried.configuration"), "{e}");
    let e = parse_cell_file(
        &MINIMAL.replace("preset = \"arcmate120ic_nominal\"", "vendor = \"fanuc\""),
        "f",
    )
    .unwrap_err();
    assert!(e.to_string().contains("robot.geometry"), "{e}");
    let e = parse_cell_file(
        &MINIMAL.replace(
            "preset = \"arcmate120ic_nominal\"",
            "preset = \"arcmate120ic_nominal\"\nlower_deg = [0, 0, 0, 0, 0, 0]\nupper_deg = [1, 1, 1, 1, 1, -1]",
        ),
        "f",
    )
    .unwrap_err();
    assert!(
        matches!(e, CellFileError::Robot { .. }) && e.to_string().contains("lower_deg[5]"),
        "{e}"
    );
    let e = parse_cell_file(
        &MINIMAL.replace(
            "preset = \"arcmate120ic_nominal\"",
            "preset = \"no_such_robot\"",
        ),
        "f",
    )
    .unwrap_err();
    assert!(e.to_string().contains("no_such_robot"), "{e}");
    let e = read_cell_file("/nonexistent/cell.toml").unwrap_err();
    assert!(
        matches!(e, CellFileError::Io { .. }) && e.to_string().contains("/nonexistent/cell.toml")
    );
}
