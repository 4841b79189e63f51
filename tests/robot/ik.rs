//! FK∘IK = identity in every configuration; typed errors for unreachable and
//! singular poses.

use waam_slicer::math::{Isometry3, Translation3, UnitQuaternion, Vector3};
use waam_slicer::robot::{Configuration, RobotError, RobotModel, Wrist};

use crate::common::{arms, joint_error, pose_error, Rng};

/// 10 000 random reachable poses per arm: generate joints, FK, IK in the
/// joints' own configuration (must give the joints back) and in all eight
/// (every branch found must reproduce the pose and be in its configuration).
#[test]
fn fk_ik_identity_10000_random_poses_every_configuration() {
    for robot in arms() {
        let mut rng = Rng::new(0x5eed);
        let (mut max_dp, mut max_dr, mut max_dq) = (0.0f64, 0.0f64, 0.0f64);
        let mut per_config = [0usize; 8];
        let mut n = 0;
        while n < 10_000 {
            let q = rng.joints(&robot);
            let sm = robot.singularity_measures(&q);
            // well away from the singularities, where joints are well conditioned
            if sm.wrist_sin_j5 < 1e-3 || sm.elbow_cos < 1e-3 || sm.shoulder_distance_mm < 1.0 {
                continue;
            }
            n += 1;
            let pose = robot.flange_pose(&q);
            let cfg = robot.configuration_of(&q);
            let back = robot.inverse(&pose, cfg).unwrap();
            max_dq = max_dq.max(joint_error(&q, &back));
            for (i, sol) in robot.inverse_all(&pose).iter().enumerate() {
                let Ok(qi) = sol else { continue };
                per_config[i] += 1;
                let (dp, dr) = pose_error(&robot.flange_pose(qi), &pose);
                max_dp = max_dp.max(dp);
                max_dr = max_dr.max(dr);
                assert_eq!(
                    robot.configuration_of(qi),
                    Configuration::from_index(i),
                    "{}: branch {i} at {q:?}",
                    robot.name
                );
                assert!(qi.iter().all(|v| v.is_finite()));
            }
            assert_eq!(
                robot.inverse_all(&pose)[cfg.index()].as_ref().unwrap(),
                &back
            );
        }
        assert!(
            max_dp < 1e-9,
            "{}: position error {max_dp:e} mm",
            robot.name
        );
        assert!(
            max_dr < 1e-9,
            "{}: rotation error {max_dr:e} rad",
            robot.name
        );
        assert!(max_dq < 1e-9, "{}: joint error {max_dq:e} rad", robot.name);
        // every configuration was exercised
        assert!(
            per_config.iter().all(|&c| c > 100),
            "{}: {per_config:?}",
            robot.name
        );
    }
}

#[test]
fn unreachable_pose_is_a_typed_error() {
    let r = RobotModel::arcmate_120ic_nominal();
    let far = Isometry3::from_parts(
        Translation3::new(3000.0, 0.0, 500.0),
        UnitQuaternion::identity(),
    );
    for sol in r.inverse_all(&far) {
        let e = sol.unwrap_err();
        assert!(matches!(e, RobotError::Unreachable { .. }), "{e}");
        assert!(e.to_string().contains("out of reach"), "{e}");
    }
}

#[test]
fn shoulder_singularity_is_a_typed_error() {
    let r = RobotModel::arcmate_120ic_nominal();
    // wrist centre on the J1 axis: approach -Z with the flange 100 mm under a point of the axis
    let rot = UnitQuaternion::from_axis_angle(&Vector3::y_axis(), std::f64::consts::PI);
    let pose = Isometry3::from_parts(Translation3::new(0.0, 0.0, 900.0), rot);
    let e = r.inverse(&pose, Configuration::NUT).unwrap_err();
    assert!(matches!(e, RobotError::ShoulderSingularity { .. }), "{e}");
    assert!(e.to_string().contains("J1 axis"));
}

#[test]
fn wrist_singularity_is_a_typed_error() {
    let r = RobotModel::arcmate_120ic_nominal();
    let q = [0.2, 0.1, -0.3, 0.4, 0.0, 0.5];
    let pose = r.flange_pose(&q);
    let cfg = r.configuration_of(&q);
    // both wrist branches of the arm solution through q are singular
    for wrist in [Wrist::NoFlip, Wrist::Flip] {
        let e = r
            .inverse(&pose, Configuration { wrist, ..cfg })
            .unwrap_err();
        assert!(matches!(e, RobotError::WristSingularity { .. }), "{e}");
        assert!(e.to_string().contains("J5"));
    }
}

#[test]
fn non_finite_pose_is_a_typed_error() {
    let r = RobotModel::arcmate_120ic_nominal();
    let pose = Isometry3::from_parts(
        Translation3::new(f64::NAN, 0.0, 0.0),
        UnitQuaternion::identity(),
    );
    let e = r.inverse(&pose, Configuration::NUT).unwrap_err();
    assert!(matches!(e, RobotError::NonFinite { .. }), "{e}");
}

#[test]
fn fanuc_config_string_of_home() {
    let r = RobotModel::arcmate_120ic_nominal();
    let home = [0.0, 0.0, 0.0, 0.0, -90f64.to_radians(), 0.0];
    assert_eq!(r.fanuc_config(&home).to_string(), "N U T, 0, 0, 0");
    let wound = [
        0.0,
        0.0,
        0.0,
        190f64.to_radians(),
        -90f64.to_radians(),
        400f64.to_radians(),
    ];
    assert_eq!(r.fanuc_config(&wound).to_string(), "N U T, 0, 1, 1");
}

#[test]
fn inverse_near_unwraps_j6() {
    let r = RobotModel::arcmate_120ic_nominal();
    let q = [0.1, 0.2, 0.1, 0.3, -1.0, 3.0 * std::f64::consts::TAU + 0.4];
    let pose = r.flange_pose(&q);
    let mut near = q;
    near[5] += 0.01;
    let back = r
        .inverse_near(&pose, r.configuration_of(&q), &near)
        .unwrap();
    assert!((back[5] - q[5]).abs() < 1e-9, "{back:?}");
}

#[test]
fn tcp_inverse_round_trip() {
    let r = RobotModel::arcmate_120ic_nominal();
    let tool = waam_slicer::robot::orientation::FanucPose::from_xyzwpr_deg([
        -86.0, 0.0, 406.0, -180.0, -36.0, 0.0,
    ])
    .to_isometry();
    let q = [0.3, 0.1, -0.2, 0.5, -0.8, 1.0];
    let tcp = r.tcp_pose(&q, &tool);
    let back = r.inverse_tcp(&tcp, &tool, r.configuration_of(&q)).unwrap();
    assert!(joint_error(&q, &back) < 1e-9);
}
