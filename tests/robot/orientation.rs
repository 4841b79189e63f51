//! Orientation conventions round-trip, gimbal lock included (SPEC §6.3).

use std::f64::consts::FRAC_PI_2;

use waam_slicer::math::{Rotation3, UnitQuaternion, Vector3};
use waam_slicer::robot::orientation::{
    abb_quaternion, rotation_from_abb_quaternion, Bryant, FanucPose, FanucWpr, KukaAbc,
};

use crate::common::Rng;

fn random_rotation(rng: &mut Rng) -> Rotation3 {
    let axis = waam_slicer::math::UnitVector3::new_normalize(rng.unit());
    Rotation3::from_axis_angle(
        &axis,
        rng.range(-std::f64::consts::PI, std::f64::consts::PI),
    )
}

fn same(a: &Rotation3, b: &Rotation3) -> bool {
    (a.matrix() - b.matrix()).norm() < 1e-12
}

#[test]
fn rotations_round_trip_through_every_convention() {
    let mut rng = Rng::new(3);
    for _ in 0..2000 {
        let r = random_rotation(&mut rng);
        assert!(same(&Bryant::from_rotation(&r).to_rotation(), &r));
        assert!(same(&FanucWpr::from_rotation(&r).to_rotation(), &r));
        assert!(same(&KukaAbc::from_rotation(&r).to_rotation(), &r));
        assert!(same(
            &rotation_from_abb_quaternion(abb_quaternion(&r)).unwrap(),
            &r
        ));
    }
}

#[test]
fn angles_round_trip_away_from_gimbal_lock() {
    let mut rng = Rng::new(4);
    for _ in 0..2000 {
        let (a, b, c) = (
            rng.range(-3.1, 3.1),
            rng.range(-1.5, 1.5),
            rng.range(-3.1, 3.1),
        );
        let br = Bryant {
            rx: a,
            ry: b,
            rz: c,
        };
        let back = Bryant::from_rotation(&br.to_rotation());
        assert!(
            (back.rx - a).abs() < 1e-9 && (back.ry - b).abs() < 1e-9 && (back.rz - c).abs() < 1e-9
        );
        let w = FanucWpr { w: a, p: b, r: c };
        let back = FanucWpr::from_rotation(&w.to_rotation());
        assert!(
            (back.w - a).abs() < 1e-9 && (back.p - b).abs() < 1e-9 && (back.r - c).abs() < 1e-9
        );
        let k = KukaAbc { a, b, c };
        let back = KukaAbc::from_rotation(&k.to_rotation());
        assert!(
            (back.a - a).abs() < 1e-9 && (back.b - b).abs() < 1e-9 && (back.c - c).abs() < 1e-9
        );
    }
}

#[test]
fn gimbal_lock_round_trips() {
    for s in [1.0, -1.0] {
        for (x, z) in [(0.3, 0.0), (0.3, 0.7), (-2.0, 1.1), (0.0, 0.0)] {
            let br = Bryant {
                rx: x,
                ry: s * FRAC_PI_2,
                rz: z,
            };
            let r = br.to_rotation();
            let back = Bryant::from_rotation(&r);
            assert!(back.rx.is_finite() && back.rz == 0.0);
            assert!(
                same(&back.to_rotation(), &r),
                "Bryant lock {s} {x} {z}: {back:?}"
            );
            let w = FanucWpr {
                w: x,
                p: s * FRAC_PI_2,
                r: z,
            };
            let r = w.to_rotation();
            let back = FanucWpr::from_rotation(&r);
            assert!(back.w == 0.0 && same(&back.to_rotation(), &r), "WPR lock");
            let k = KukaAbc {
                a: z,
                b: s * FRAC_PI_2,
                c: x,
            };
            let r = k.to_rotation();
            let back = KukaAbc::from_rotation(&r);
            assert!(back.c == 0.0 && same(&back.to_rotation(), &r), "ABC lock");
        }
    }
}

#[test]
fn conventions_match_their_definitions() {
    // Bryant = Rx Ry Rz (intrinsic), FANUC WPR = Rz(R) Ry(P) Rx(W) [SPEC §6.3, eq. B.1-B.3]
    let (a, b, c) = (0.3, -0.4, 1.2);
    let rx = Rotation3::from_axis_angle(&Vector3::x_axis(), a);
    let ry = Rotation3::from_axis_angle(&Vector3::y_axis(), b);
    let rz = Rotation3::from_axis_angle(&Vector3::z_axis(), c);
    assert!(same(
        &Bryant {
            rx: a,
            ry: b,
            rz: c
        }
        .to_rotation(),
        &(rx * ry * rz)
    ));
    assert!(same(
        &FanucWpr { w: a, p: b, r: c }.to_rotation(),
        &(rz * ry * rx)
    ));
    assert!(same(
        &KukaAbc { a: c, b, c: a }.to_rotation(),
        &(rz * ry * rx)
    ));
    // nalgebra's euler angles are roll-pitch-yaw about fixed axes, like FANUC's W P R
    let e = UnitQuaternion::from_euler_angles(a, b, c).to_rotation_matrix();
    assert!(same(&FanucWpr { w: a, p: b, r: c }.to_rotation(), &e));
}

#[test]
fn table_3_7_positioner_is_turned_about_45_degrees_about_the_vertical() {
    let p = FanucPose::from_xyzwpr_deg([920.588, 820.862, -254.408, 0.412, -0.131, 45.059]);
    let iso = p.to_isometry();
    let x = iso.rotation * Vector3::x();
    assert!((x.y.atan2(x.x).to_degrees() - 45.059).abs() < 0.01);
    let z = iso.rotation * Vector3::z();
    assert!(z.z > 0.9999);
    let back = FanucPose::from_isometry(&iso).to_xyzwpr_deg();
    for (u, v) in back
        .iter()
        .zip([920.588, 820.862, -254.408, 0.412, -0.131, 45.059])
    {
        assert!((u - v).abs() < 1e-9);
    }
}

#[test]
fn abb_quaternion_of_tool_down_is_0_0_1_0() {
    let r = Rotation3::from_axis_angle(&Vector3::y_axis(), std::f64::consts::PI);
    let q = abb_quaternion(&r);
    assert!((q[0]).abs() < 1e-12 && (q[2].abs() - 1.0).abs() < 1e-12);
    assert!(rotation_from_abb_quaternion([0.0; 4]).is_none());
}
