//! Unit tests of the robot stage (integration tests in `tests/robot/`).

use super::*;
use crate::math::Vector3;

#[test]
fn canonical_round_trip_all_vendors() {
    for robot in [
        RobotModel::arcmate_120ic_nominal(),
        RobotModel::kuka_kr16_2(),
        RobotModel::abb_irb2600_12_185(),
    ] {
        robot.validate().unwrap();
        let q = [0.1, -0.2, 0.3, -0.4, 0.5, -0.6];
        let t = robot.canonical_from_joints(&q);
        let back = robot.joints_from_canonical(&t);
        for j in 0..6 {
            assert!((back[j] - q[j]).abs() < 1e-15, "{}", robot.name);
        }
    }
}

#[test]
fn fanuc_zero_pose() {
    let r = RobotModel::arcmate_120ic_nominal();
    let f = r.flange_pose(&[0.0; 6]);
    assert!((f.translation.vector - Vector3::new(1085.0, 0.0, 1040.0)).norm() < 1e-12);
    let m = f.rotation.to_rotation_matrix();
    assert!(
        (m * Vector3::z() - Vector3::x()).norm() < 1e-12,
        "approach +X"
    );
    assert!((m * Vector3::x() - Vector3::z()).norm() < 1e-12, "x up");
}

#[test]
fn kuka_and_abb_mastering_poses() {
    // KUKA mastering pose A2 = -90, A3 = +90: forearm horizontal, flange z forward
    let k = RobotModel::kuka_kr16_2();
    let q = [0.0, -90f64.to_radians(), 90f64.to_radians(), 0.0, 0.0, 0.0];
    let f = k.flange_pose(&q);
    let expect = Vector3::new(260.0 + 670.0 + 158.0, 0.0, 675.0 + 680.0 - 35.0);
    assert!((f.translation.vector - expect).norm() < 1e-9);
    assert!((f.rotation * Vector3::z() - Vector3::x()).norm() < 1e-12);
    // ABB zero: tool0 z forward, x down
    let a = RobotModel::abb_irb2600_12_185();
    let f = a.flange_pose(&[0.0; 6]);
    let expect = Vector3::new(150.0 + 795.0 + 85.0, 0.0, 445.0 + 900.0 + 115.0);
    assert!((f.translation.vector - expect).norm() < 1e-9);
    assert!((f.rotation * Vector3::x() + Vector3::z()).norm() < 1e-12);
}

#[test]
fn configuration_index_round_trip_and_display() {
    for i in 0..8 {
        let c = Configuration::from_index(i);
        assert_eq!(c.index(), i);
        assert_eq!(Configuration::from_fanuc(&c.to_string()), Some(c));
    }
    assert_eq!(Configuration::NUT.to_string(), "N U T");
    assert_eq!(
        Configuration::from_fanuc("nub"),
        Some(Configuration {
            wrist: Wrist::NoFlip,
            elbow: Elbow::Up,
            side: ArmSide::Back,
        })
    );
    assert_eq!(Configuration::from_fanuc("X U T"), None);
}

#[test]
fn turn_numbers() {
    use crate::robot::ik::turn_number;
    assert_eq!(turn_number(0.0), 0);
    assert_eq!(turn_number(std::f64::consts::PI), 0);
    assert_eq!(turn_number(std::f64::consts::PI + 1e-9), 1);
    assert_eq!(turn_number(-std::f64::consts::PI), -1);
    assert_eq!(turn_number(-3.5 * std::f64::consts::PI), -2);
}

#[test]
fn invalid_model_names_field() {
    let mut r = RobotModel::arcmate_120ic_nominal();
    r.geometry.upper_arm_mm = -1.0;
    let e = r.validate().unwrap_err().to_string();
    assert!(e.contains("upper_arm_mm"), "{e}");
    let mut r = RobotModel::arcmate_120ic_nominal();
    r.convention.sign[3] = 0.5;
    assert!(r.validate().unwrap_err().to_string().contains("sign[3]"));
    let mut r = RobotModel::arcmate_120ic_nominal();
    r.limits[1] = JointLimit::from_degrees(10.0, -10.0);
    assert!(r
        .validate()
        .unwrap_err()
        .to_string()
        .contains("lower_deg[1]"));
    let mut r = RobotModel::arcmate_120ic_nominal();
    r.max_speed_rad_s[5] = 0.0;
    assert!(r
        .validate()
        .unwrap_err()
        .to_string()
        .contains("max_speed_deg_s[5]"));
}
