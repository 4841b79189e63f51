//! Stage 5 alone (robot kinematics, [`waam_slicer::robot`]): the FANUC
//! ArcMate 120iC of the thesis's cell, forward kinematics against the
//! closed-form check values of SPEC §6.1 (FANUC's own joint conventions),
//! then the inverse kinematics of a flange pose in each of the eight
//! configurations, each solution put back through the forward kinematics.
//!
//! ```text
//! cargo run --example stage_ik
//! ```

use waam_slicer::math::Vector3;
use waam_slicer::robot::RobotModel;

fn main() {
    let robot = RobotModel::arcmate_120ic_nominal();
    let deg = |d: [f64; 6]| d.map(f64::to_radians);
    // SPEC §6.1: flange positions (mm) at these joints (deg)
    let checks = [
        ([0.0; 6], [1085.0, 0.0, 1040.0]),
        ([0.0, 10.0, 0.0, 0.0, 0.0, 0.0], [1222.18, 0.0, 1028.00]),
        ([0.0, 0.0, 10.0, 0.0, 0.0, 0.0], [1027.38, 0.0, 1198.56]),
        ([0.0, 0.0, 0.0, 0.0, 10.0, 0.0], [1083.48, 0.0, 1057.37]),
    ];
    for (q, want) in checks {
        let p = robot.flange_pose(&deg(q)).translation.vector;
        let err = (p - Vector3::from(want)).norm();
        println!(
            "q = {q:?} deg -> flange {:.2?} mm ({err:.3} mm off)",
            p.as_slice()
        );
        // the check values are printed to 0.01 mm
        assert!(err < 0.02, "forward kinematics off by {err} mm");
    }

    let q = deg([20.0, 15.0, -10.0, 30.0, -45.0, 60.0]);
    let pose = robot.flange_pose(&q);
    let mut solved = 0;
    for (k, sol) in robot.inverse_all(&pose).into_iter().enumerate() {
        let Ok(s) = sol else { continue };
        let back = robot.flange_pose(&s);
        let dp = (back.translation.vector - pose.translation.vector).norm();
        let dr = back.rotation.angle_to(&pose.rotation);
        assert!(
            dp < 1e-6 && dr < 1e-9,
            "configuration {k}: {dp} mm, {dr} rad"
        );
        solved += 1;
    }
    println!("{solved} of 8 configurations reach the pose exactly");
    // a pose inside the workspace, away from singularities: the original
    // joints' configuration at least
    assert!(solved >= 1);
    let same = robot
        .inverse(&pose, robot.configuration_of(&q))
        .expect("reachable");
    let dq = q
        .iter()
        .zip(&same)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max);
    assert!(dq < 1e-9, "the original joints come back ({dq} rad off)");
}
