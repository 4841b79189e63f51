//! Two-axis positioner: FK (eq. C.5–C.6) and the angles that turn a build
//! direction vertical, checked against the FK.

use waam_slicer::math::{UnitVector3, Vector3};
use waam_slicer::robot::orientation::FanucPose;
use waam_slicer::robot::Positioner;

use crate::common::Rng;

#[test]
fn fk_matches_eq_c5_c6() {
    let p = Positioner::robowam_nominal();
    let (q7, q8) = (0.4f64, -1.1f64);
    let t = p.positioner_from_table(&[q7, q8]);
    let expect = Vector3::new(150.0 * q7.sin(), 0.0, 150.0 * q7.cos());
    assert!((t.translation.vector - expect).norm() < 1e-12);
    assert!(
        (p.positioner_from_table(&[0.0, 0.0]).translation.vector - Vector3::new(0.0, 0.0, 150.0))
            .norm()
            < 1e-12
    );
    assert_eq!(Positioner::robowam_identified().tilt_to_table_mm, 149.631);
    // table normal tilts towards +X for q7 > 0
    let n = t.rotation * Vector3::z();
    assert!((n - Vector3::new(q7.sin(), 0.0, q7.cos())).norm() < 1e-12);
}

#[test]
fn angles_turn_the_build_direction_vertical_level_positioner() {
    let p = Positioner::robowam_identified();
    let mut rng = Rng::new(21);
    for _ in 0..2000 {
        let b = UnitVector3::new_normalize(rng.unit());
        let q = p
            .angles_for_vertical(&b, &Vector3::z_axis(), 0.0, 0.0)
            .unwrap();
        let up = p.positioner_from_table(&q).rotation * b.into_inner();
        assert!((up - Vector3::z()).norm() < 1e-12, "{b:?} -> {q:?}: {up:?}");
        // the printed eq. C.24-C.25 give the same angles for a level positioner
        let q7 = (b.x.hypot(b.y)).atan2(b.z);
        let q8 = b.y.atan2(-b.x);
        let d8 = (q[1] - q8).rem_euclid(std::f64::consts::TAU);
        assert!(
            (q[0] - q7).abs() < 1e-12 && !(1e-12..=std::f64::consts::TAU - 1e-12).contains(&d8)
        );
    }
}

#[test]
fn angles_turn_the_build_direction_vertical_in_the_robot_frame() {
    // positioner pose of table 3.7: slightly tilted, so "up" is not its own Z
    let base_from_pos =
        FanucPose::from_xyzwpr_deg([920.588, 820.862, -254.408, 0.412, -0.131, 45.059])
            .to_isometry();
    let up = base_from_pos.rotation.inverse() * Vector3::z_axis();
    let p = Positioner::robowam_identified();
    let mut rng = Rng::new(22);
    for _ in 0..2000 {
        let b = UnitVector3::new_normalize(rng.unit());
        let Ok(q) = p.angles_for_vertical(&b, &up, 0.0, 0.0) else {
            // only when b_z is out of reach of the tilted positioner's cone
            continue;
        };
        let world =
            base_from_pos.rotation * (p.positioner_from_table(&q).rotation * b.into_inner());
        assert!((world - Vector3::z()).norm() < 1e-12);
    }
}

#[test]
fn vertical_build_direction_keeps_the_hint() {
    let p = Positioner::robowam_nominal();
    let q = p
        .angles_for_vertical(&Vector3::z_axis(), &Vector3::z_axis(), 0.7, 0.0)
        .unwrap();
    assert_eq!(q, [0.0, 0.7]);
}

#[test]
fn out_of_level_positioner_accepts_the_closest_tilt_within_tolerance() {
    let base_from_pos =
        FanucPose::from_xyzwpr_deg([0.0, 0.0, 0.0, 0.412, -0.131, 45.059]).to_isometry();
    let up = base_from_pos.rotation.inverse() * Vector3::z_axis();
    let p = Positioner::robowam_identified();
    assert!(p
        .angles_for_vertical(&Vector3::z_axis(), &up, 0.0, 0.0)
        .is_err());
    let q = p
        .angles_for_vertical(&Vector3::z_axis(), &up, 0.0, 1f64.to_radians())
        .unwrap();
    let world = base_from_pos.rotation * (p.positioner_from_table(&q).rotation * Vector3::z());
    let err = world.z.acos().to_degrees();
    assert!(err < 0.42 && err > 0.40, "{err}");
}
