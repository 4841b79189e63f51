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
