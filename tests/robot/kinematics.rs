//! Forward kinematics check values of SPEC §6.1 (thesis eq. C.1 with FANUC's conventions).

use waam_slicer::math::Vector3;
use waam_slicer::robot::RobotModel;

fn deg(j: [f64; 6]) -> [f64; 6] {
    j.map(f64::to_radians)
}

fn assert_close(v: Vector3, expect: [f64; 3], tol: f64, what: &str) {
    let e = Vector3::from(expect);
    assert!((v - e).norm() <= tol, "{what}: got {v:?}, expected {e:?}");
}

#[test]
fn zero_joints_put_flange_at_1085_0_1040_approach_x() {
    let r = RobotModel::arcmate_120ic_nominal();
    let f = r.flange_pose(&[0.0; 6]);
    assert_close(f.translation.vector, [1085.0, 0.0, 1040.0], 1e-9, "zero");
    assert_close(
        f.rotation * Vector3::z(),
        [1.0, 0.0, 0.0],
        1e-12,
        "approach",
    );
    assert_close(
        f.rotation * Vector3::x(),
        [0.0, 0.0, 1.0],
        1e-12,
        "flange x up",
    );
    assert_close(
        f.rotation * Vector3::y(),
        [0.0, -1.0, 0.0],
        1e-12,
        "flange y along -Y",
    );
}

#[test]
fn spec_check_values_to_001_mm() {
    let r = RobotModel::arcmate_120ic_nominal();
    // SPEC values are rounded to 0.01 mm: accept half a unit of the last digit
    let tol = 0.005 + 1e-9;
    let f = r.flange_pose(&deg([0.0, 10.0, 0.0, 0.0, 0.0, 0.0]));
    assert_close(
        f.translation.vector,
        [1222.18, 0.0, 1028.00],
        tol,
        "J2 = +10",
    );
    assert_close(
        f.rotation * Vector3::z(),
        [1.0, 0.0, 0.0],
        1e-12,
        "J2 keeps the forearm",
    );
    let f = r.flange_pose(&deg([0.0, 0.0, 10.0, 0.0, 0.0, 0.0]));
    assert_close(
        f.translation.vector,
        [1027.38, 0.0, 1198.56],
        tol,
        "J3 = +10",
    );
    let f = r.flange_pose(&deg([0.0, 0.0, 0.0, 0.0, 10.0, 0.0]));
    assert_close(
        f.translation.vector,
        [1083.48, 0.0, 1057.36],
        tol,
        "J5 = +10",
    );
    assert_close(
        f.rotation * Vector3::z(),
        [0.985, 0.0, 0.174],
        0.0005,
        "J5 = +10 approach",
    );
    let f = r.flange_pose(&deg([0.0, 0.0, 0.0, 0.0, -90.0, 0.0]));
    assert_close(f.translation.vector, [985.0, 0.0, 940.0], 1e-9, "J5 = -90");
    assert_close(
        f.rotation * Vector3::z(),
        [0.0, 0.0, -1.0],
        1e-12,
        "J5 = -90 approach",
    );
}

#[test]
fn j1_turns_about_z_and_j4_j6_about_the_approach() {
    let r = RobotModel::arcmate_120ic_nominal();
    let f = r.flange_pose(&deg([90.0, 0.0, 0.0, 0.0, 0.0, 0.0]));
    assert_close(f.translation.vector, [0.0, 1085.0, 1040.0], 1e-9, "J1 = 90");
    // J4, J6 at J5 = 0 turn the flange about its approach axis only
    let f0 = r.flange_pose(&[0.0; 6]);
    for q in [
        deg([0.0, 0.0, 0.0, 30.0, 0.0, 0.0]),
        deg([0.0, 0.0, 0.0, 0.0, 0.0, 30.0]),
    ] {
        let f = r.flange_pose(&q);
        assert_close(
            f.translation.vector,
            [1085.0, 0.0, 1040.0],
            1e-9,
            "J4/J6 keep position",
        );
        assert_close(
            f.rotation * Vector3::z(),
            [1.0, 0.0, 0.0],
            1e-12,
            "J4/J6 keep approach",
        );
        // about -x of the forearm: x (up) turns towards +Y
        let x = f.rotation * Vector3::x();
        assert!((x.y - 0.5).abs() < 1e-12 && x.z > 0.8, "{x:?}");
        assert!(f.rotation.angle_to(&f0.rotation) > 0.5);
    }
}

#[test]
fn flange_position_matches_flange_pose() {
    let mut rng = crate::common::Rng::new(7);
    for r in crate::common::arms() {
        for _ in 0..100 {
            let q = rng.joints(&r);
            let a = r.flange_pose(&q).translation.vector;
            let b = r.flange_position(&q).coords;
            assert!((a - b).norm() < 1e-9);
        }
    }
}
