//! Jacobian against finite differences; indices at singular and regular poses.

use waam_slicer::math::Vector3;
use waam_slicer::robot::indices::{
    dexterity, joint_limit_distance, manipulability, positioning_uncertainty, LimitDistance,
    UncertaintyFormula,
};
use waam_slicer::robot::RobotModel;

use crate::common::{arms, Rng};

#[test]
fn jacobian_matches_central_differences() {
    let mut rng = Rng::new(11);
    let h = 1e-6;
    for r in arms() {
        for _ in 0..200 {
            let q = rng.joints(&r);
            let tcp = Vector3::new(
                rng.range(-100.0, 100.0),
                rng.range(-100.0, 100.0),
                rng.range(0.0, 400.0),
            );
            let j = r.jacobian_at(&q, &tcp);
            for k in 0..6 {
                let mut qp = q;
                let mut qm = q;
                qp[k] += h;
                qm[k] -= h;
                let fp = r.flange_pose(&qp);
                let fm = r.flange_pose(&qm);
                let v = (fp * waam_slicer::math::Point3::from(tcp)
                    - fm * waam_slicer::math::Point3::from(tcp))
                    / (2.0 * h);
                let w = (fp.rotation * fm.rotation.inverse()).scaled_axis() / (2.0 * h);
                let jv = j.fixed_view::<3, 1>(0, k).into_owned();
                let jw = j.fixed_view::<3, 1>(3, k).into_owned();
                assert!(
                    (jv - v).norm() < 1e-5 * (1.0 + v.norm()),
                    "{} J{}: {jv:?} vs {v:?}",
                    r.name,
                    k + 1
                );
                assert!(
                    (jw - w).norm() < 1e-7,
                    "{} J{}: {jw:?} vs {w:?}",
                    r.name,
                    k + 1
                );
            }
        }
    }
}

#[test]
fn fanuc_j2_moves_the_forearm_parallel_to_itself() {
    let r = RobotModel::arcmate_120ic_nominal();
    let j = r.jacobian(&[0.1, 0.2, 0.3, 0.4, 0.5, 0.6]);
    // angular velocity of J2 alone is zero: the J2/J3 coupling
    assert!(j.fixed_view::<3, 1>(3, 1).norm() < 1e-15);
}

#[test]
fn dexterity_is_zero_at_j5_zero() {
    for r in arms() {
        let q = [0.3, 0.2, 0.1, 0.5, 0.0, 0.7];
        let j = r.jacobian(&q);
        assert!(dexterity(&j, 1.0) < 1e-12, "{}", r.name);
        assert!(dexterity(&j, 1000.0) < 1e-12, "{}", r.name);
        assert!(
            manipulability(&j)
                < 1e-6 * manipulability(&r.jacobian(&[0.3, 0.2, 0.1, 0.5, 0.5, 0.7]))
        );
        let j = r.jacobian(&[0.3, 0.2, 0.1, 0.5, 0.8, 0.7]);
        let d = dexterity(&j, 1.0);
        assert!(d > 1e-5 && d <= 1.0, "{}: {d}", r.name);
        let d = dexterity(&j, 1000.0);
        assert!(d > 1e-2 && d <= 1.0, "{}: {d}", r.name);
    }
}

#[test]
fn joint_limit_distances() {
    let r = RobotModel::arcmate_120ic_nominal();
    let mid: [f64; 6] = std::array::from_fn(|j| r.limits[j].mid_rad());
    for k in [
        LimitDistance::Liegeois,
        LimitDistance::Fournier,
        LimitDistance::Klein,
    ] {
        assert_eq!(joint_limit_distance(&mid, &r.limits, k), 0.0);
    }
    let mut at_stop = mid;
    at_stop[1] = r.limits[1].upper_rad;
    assert!(
        (joint_limit_distance(&at_stop, &r.limits, LimitDistance::Liegeois) - 1.0).abs() < 1e-12
    );
    assert!(
        (joint_limit_distance(&at_stop, &r.limits, LimitDistance::Fournier) - 0.25).abs() < 1e-12
    );
    assert!((joint_limit_distance(&at_stop, &r.limits, LimitDistance::Klein) - 0.5).abs() < 1e-12);
    // J6 unlimited: ignored
    let mut wound = mid;
    wound[5] = 100.0;
    assert_eq!(
        joint_limit_distance(&wound, &r.limits, LimitDistance::Fournier),
        0.0
    );
}

#[test]
fn positioning_uncertainty_scales_with_sigma() {
    let r = RobotModel::arcmate_120ic_nominal();
    let q = [0.3, 0.2, 0.1, 0.5, -0.8, 0.7];
    let j = r.jacobian(&q);
    let sigma = r.encoder_sigma_rad.unwrap();
    let i1 = positioning_uncertainty(&j, &sigma, UncertaintyFormula::RootTrace);
    let i2 = positioning_uncertainty(&j, &sigma.map(|s| 2.0 * s), UncertaintyFormula::RootTrace);
    assert!(i1 > 0.0 && (i2 / i1 - 2.0).abs() < 1e-9);
    // single joint: I = |column| sigma
    let mut one = [0.0; 6];
    one[0] = 1e-6;
    let i = positioning_uncertainty(&j, &one, UncertaintyFormula::RootTrace);
    let col = j.fixed_view::<3, 1>(0, 0).norm();
    assert!((i - col * 1e-6).abs() < 1e-15);
    // programming resolution 1e-4 deg: a few micrometres at this pose
    let prog = [1e-4f64.to_radians(); 6];
    let i = positioning_uncertainty(&j, &prog, UncertaintyFormula::RootTrace);
    assert!(i > 1e-3 && i < 1e-2, "{i}");
}
