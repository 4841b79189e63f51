//! Unit tests of the placement stage's pieces.

use super::score::reach_margin_mm;
use crate::math::{Isometry3, Translation3, Vector3};
use crate::robot::ik::Configuration;
use crate::robot::RobotModel;

/// At zero joints the SPEC §6.1 chain puts the flange at (1085, 0, 1040)
/// mm with the approach along +X, so the wrist centre at (985, 0, 1040),
/// 1333.7 mm from the J2 axis at (150, 0, 0); the arm spans
/// |790 − 871.6| .. 790 + 871.6 mm (871.6 = hypot(835, 250)).
#[test]
fn the_reach_margin_at_zero_joints_is_the_specs_closed_form() {
    let robot = RobotModel::arcmate_120ic_nominal();
    let k = 835f64.hypot(250.0);
    let d = 835f64.hypot(1040.0);
    let expected = (d - (790.0 - k).abs()).min(790.0 + k - d);
    let got = reach_margin_mm(&robot, &[0.0; 6]);
    assert!((got - expected).abs() < 1e-9, "{got} vs {expected}");
    assert!((expected - 327.9).abs() < 0.1);
}

/// A wrist centre placed `m` mm inside the stretched arm's reach (the
/// flange pose of zero joints moved along X) comes back from the inverse
/// kinematics with a margin of `m`; 1 mm beyond, the inverse refuses it.
#[test]
fn the_reach_margin_agrees_with_the_inverse_kinematics_reach() {
    let robot = RobotModel::arcmate_120ic_nominal();
    let home = robot.flange_pose(&[0.0; 6]);
    let arm_max = 790.0 + 835f64.hypot(250.0);
    for m in [100.0, 10.0, 1.0] {
        // the wrist centre at (150 + x, 0, 1040): distance hypot(x, 1040)
        let x = ((arm_max - m).powi(2) - 1040f64.powi(2)).sqrt();
        let shift = Vector3::new(x - 835.0, 0.0, 0.0);
        let pose = Isometry3::from_parts(
            Translation3::from(home.translation.vector + shift),
            home.rotation,
        );
        let q = robot.inverse(&pose, Configuration::NUT).unwrap();
        let got = reach_margin_mm(&robot, &q);
        assert!((got - m).abs() < 1e-6, "{got} vs {m}");
    }
    let x = ((arm_max + 1.0).powi(2) - 1040f64.powi(2)).sqrt();
    let pose = Isometry3::from_parts(
        Translation3::from(home.translation.vector + Vector3::new(x - 835.0, 0.0, 0.0)),
        home.rotation,
    );
    assert!(robot.inverse(&pose, Configuration::NUT).is_err());
}

/// The binding's words are `placement.json`'s `binding.constraint` and the
/// CLI's message: each variant reads as the former `(String, f64)` did
/// (the formats of the search before the binding was typed: the
/// constraint's own words, `, e.g. <refusal>` after a refusal on the
/// subsample, ` (on the full path)` with the other candidate's refusal
/// after `; `, ` (program check)`).
#[test]
fn a_binding_reads_as_placement_json_has_it() {
    use super::{Binding, Limit};
    use crate::optimise::Constraint;
    use crate::program::ProgramError;
    use std::sync::Arc;
    let refusal = Arc::new(ProgramError::InfeasibleLayer {
        layer: 17,
        count: 1,
        status: crate::program::LayerRefusal::Infeasible(
            crate::optimise::LayerStatus::Infeasible {
                binding: crate::optimise::BindingConstraint {
                    point: 3,
                    constraint: Constraint::JointLimit { joint: 5 },
                    violation: 1f64.to_radians(),
                },
            },
        ),
    });
    let words = "refusing to write a program: layer 17 cannot be built \
                 (infeasible: J5 travel at point 3 (over by 1.0000°)); 1 layer(s) in all";
    let j5 = Limit::Layer(Constraint::JointLimit { joint: 5 });
    let cases = [
        (
            Binding::Subsample {
                limit: j5.clone(),
                share: 0.5,
                example: None,
            },
            "J5 travel".to_string(),
            0.5,
        ),
        (
            Binding::Subsample {
                limit: Limit::ProgramCheck,
                share: 1.0,
                example: Some(refusal.clone()),
            },
            format!("program check on the subsample (transit or set-up), e.g. {words}"),
            1.0,
        ),
        (
            Binding::Subsample {
                limit: Limit::KeepOut,
                share: 0.25,
                example: Some(refusal.clone()),
            },
            "keep-out box".to_string(),
            0.25,
        ),
        (
            Binding::FullPath {
                limit: Limit::Layer(Constraint::JointSpeed { joint: 4 }),
                share: 0.125,
                refused: None,
            },
            "J4 speed (on the full path)".to_string(),
            0.125,
        ),
        (
            Binding::FullPath {
                limit: j5,
                share: 0.125,
                refused: Some(refusal.clone()),
            },
            format!(
                "J5 travel (on the full path); another candidate was refused by the program check: {words}"
            ),
            0.125,
        ),
        (
            Binding::ProgramCheck { refusal },
            format!("{words} (program check)"),
            1.0,
        ),
    ];
    for (binding, expected, share) in cases {
        assert_eq!(binding.to_string(), expected);
        assert_eq!(binding.share(), share);
    }
}

/// The layers a program-stage refusal brings into the subsample come from
/// the error's typed fields: `InfeasibleLayer` names one; an error whose
/// layers are only in its words names none (nothing reads them back).
#[test]
fn a_refusal_names_its_layers_from_typed_fields_only() {
    use crate::program::ProgramError;
    let e = ProgramError::InfeasibleLayer {
        layer: 80,
        count: 2,
        status: crate::program::LayerRefusal::NoPlan,
    };
    assert_eq!(e.layers(), vec![80]);
    // the words are not read: the typed layers are
    let e = ProgramError::Infeasible {
        count: 1,
        first: "layer 80: the arc-off joint move to layer 81's approach".into(),
        layers: vec![80, 81],
    };
    assert_eq!(e.layers(), vec![80, 81]);
    let e = ProgramError::Infeasible {
        count: 1,
        first: "layer 80".into(),
        layers: Vec::new(),
    };
    assert!(e.layers().is_empty());
}

/// Typed values and the table's order agree, for both cell kinds: the
/// seventh variable is the mount offset (mm) part carried, the torch's
/// rotation in its clamp (rad) torch carried; the eighth and ninth the
/// part's offset in its mount's plane (mm) for both; the tenth the part's
/// rotation on the table (rad) torch carried, none part carried; and the
/// placed cell puts the deposition point (positioner origin) at the
/// values' position.
#[test]
fn placement_values_follow_the_table_for_both_cell_kinds() {
    use super::bounds::{placed_cell, PlacementValues};
    use crate::io::cell_file::parse_cell_file;
    use crate::math::Point3;
    use crate::robot::CellLayout;
    let x = [
        1000.0, -200.0, 500.0, 0.5, 0.1, -0.2, 30.0, 40.0, -60.0, 0.3,
    ];
    for file in [
        "parts/cells/robowam_part_carried.toml",
        "parts/cells/kuka_kr16_2_torch_carried.toml",
    ] {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join(file);
        let text = std::fs::read_to_string(&path).unwrap();
        let cell = parse_cell_file(&text, file).unwrap().cell.unwrap();
        let v = PlacementValues::from_coords(&cell, &x);
        let mut table = x;
        if matches!(cell, CellLayout::PartCarried(_)) {
            // part carried, the mount's rotation is variable 3 alone
            table[9] = 0.0;
        }
        assert_eq!(v.in_table_order(&cell), table);
        assert_eq!((v.offset_x_mm, v.offset_y_mm), (40.0, -60.0));
        assert_eq!(v.position_mm, Point3::new(1000.0, -200.0, 500.0));
        let placed = placed_cell(&cell, &x);
        match (&cell, &placed) {
            (CellLayout::PartCarried(_), CellLayout::PartCarried(c)) => {
                assert_eq!((v.offset_mm, v.torch_rotation), (30.0, 0.0));
                assert_eq!(c.deposition_point_mm, v.position_mm);
            }
            (CellLayout::TorchCarried(_), CellLayout::TorchCarried(c)) => {
                assert_eq!((v.offset_mm, v.torch_rotation), (0.0, 30.0));
                assert_eq!(v.fixture_rotation, 0.3);
                assert_eq!(
                    Point3::from(c.base_from_positioner.translation.vector),
                    v.position_mm
                );
            }
            _ => panic!("{file}: the cell kind changed"),
        }
    }
}

/// The default bounds of a torch-carried cell search the part's offset on
/// the table: the part origin within ±`TABLE_OFFSET_MM` of the turn axis,
/// widened to hold the file's mount (offset 0); a part-carried cell keeps
/// its mount.
#[test]
fn the_default_bounds_search_the_offset_on_the_table_torch_carried_only() {
    use super::bounds::{PlacementBounds, TABLE_OFFSET_MM};
    use crate::io::cell_file::parse_cell_file;
    use crate::robot::CellLayout;
    let read = |file: &str| {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join(file);
        let text = std::fs::read_to_string(&path).unwrap();
        parse_cell_file(&text, file).unwrap().cell.unwrap()
    };
    let pc = PlacementBounds::around(&read("parts/cells/robowam_part_carried.toml"), 400.0);
    assert!(pc.variables[6..].iter().all(|v| !v.is_free()));
    let mut tc = read("parts/cells/kuka_kr16_2_torch_carried.toml");
    let b = PlacementBounds::around(&tc, 400.0);
    let v = &b.variables;
    assert_eq!(
        (v[7].name, v[8].name, v[9].name),
        ("fixture.offset_x", "fixture.offset_y", "fixture.rotation")
    );
    assert_eq!(
        (v[7].lower, v[7].upper),
        (-TABLE_OFFSET_MM, TABLE_OFFSET_MM)
    );
    assert_eq!(
        (v[8].lower, v[8].upper),
        (-TABLE_OFFSET_MM, TABLE_OFFSET_MM)
    );
    assert!(!v[7].angle && v[9].angle && !v[9].is_free());
    // Mounted 220 mm off the axis along x, 40 mm along y: back to within
    // 150 mm of it, or kept.
    if let CellLayout::TorchCarried(c) = &mut tc {
        c.table_from_part = Isometry3::translation(220.0, 40.0, 5.0);
    }
    let b = PlacementBounds::around(&tc, 400.0);
    let v = &b.variables;
    assert_eq!((v[7].lower, v[7].upper), (-370.0, 0.0));
    assert_eq!((v[8].lower, v[8].upper), (-190.0, 110.0));
    b.validate().unwrap();
}

/// `apply` composes the torch-carried mount variables as documented:
/// `T(offset_x, offset_y, 0) · Rz(fixture_rotation) · Rx(tilt_x) ·
/// Ry(tilt_y) · table_from_part₀` (table frame), written out here with
/// explicit matrices; the part-carried offsets likewise in the flange frame.
#[test]
fn the_mount_variables_compose_in_the_documented_order() {
    use super::bounds::PlacementValues;
    use crate::io::cell_file::parse_cell_file;
    use crate::math::{Matrix3, Point3};
    use crate::robot::CellLayout;
    let (ox, oy, fr, tx, ty): (f64, f64, f64, f64, f64) = (-120.0, 35.0, 0.4, 0.1, -0.2);
    let rx = Matrix3::new(
        1.0,
        0.0,
        0.0,
        0.0,
        tx.cos(),
        -tx.sin(),
        0.0,
        tx.sin(),
        tx.cos(),
    );
    let ry = Matrix3::new(
        ty.cos(),
        0.0,
        ty.sin(),
        0.0,
        1.0,
        0.0,
        -ty.sin(),
        0.0,
        ty.cos(),
    );
    let rz = Matrix3::new(
        fr.cos(),
        -fr.sin(),
        0.0,
        fr.sin(),
        fr.cos(),
        0.0,
        0.0,
        0.0,
        1.0,
    );
    let v = PlacementValues {
        tilt_x: tx,
        tilt_y: ty,
        offset_x_mm: ox,
        offset_y_mm: oy,
        fixture_rotation: fr,
        ..PlacementValues::default()
    };
    let file = "parts/cells/kuka_kr16_2_torch_carried.toml";
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join(file);
    let text = std::fs::read_to_string(&path).unwrap();
    let mut cell = parse_cell_file(&text, file).unwrap().cell.unwrap();
    let m0 = Isometry3::translation(220.0, 10.0, 5.0);
    if let CellLayout::TorchCarried(c) = &mut cell {
        c.table_from_part = m0;
    }
    let v = PlacementValues {
        position_mm: match &cell {
            CellLayout::TorchCarried(c) => Point3::from(c.base_from_positioner.translation.vector),
            _ => unreachable!(),
        },
        ..v
    };
    let CellLayout::TorchCarried(c) = v.apply(&cell) else {
        panic!("torch carried")
    };
    let p = Point3::new(12.0, -7.0, 30.0);
    let by_hand =
        rz * rx * ry * (p.coords + m0.translation.vector) + crate::math::Vector3::new(ox, oy, 0.0);
    assert!((c.table_from_part * p - Point3::from(by_hand)).norm() < 1e-9);

    // Part carried: the mount's rotation is variable 3, its offset along
    // the flange axis variable 6.
    let file = "parts/cells/robowam_part_carried.toml";
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join(file);
    let text = std::fs::read_to_string(&path).unwrap();
    let mut cell = parse_cell_file(&text, file).unwrap().cell.unwrap();
    if let CellLayout::PartCarried(c) = &mut cell {
        c.flange_from_part = m0;
    }
    let v = PlacementValues {
        rotation: fr,
        fixture_rotation: 0.0,
        offset_mm: 25.0,
        ..v
    };
    let CellLayout::PartCarried(c) = v.apply(&cell) else {
        panic!("part carried")
    };
    let by_hand =
        rz * rx * ry * (p.coords + m0.translation.vector) + crate::math::Vector3::new(ox, oy, 25.0);
    assert!((c.flange_from_part * p - Point3::from(by_hand)).norm() < 1e-9);
}
