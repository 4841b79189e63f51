//! Frames along the guide: the rotation-minimising frame against a helix's
//! known twist-free frame, Frenet where defined and its refusal where not.

use crate::common::load_part;
use std::sync::Arc;
use waam_slicer::geometry::guide::{GuideCurve, Helix};
use waam_slicer::geometry::{FrameMethod, GeometryError, ProfileLaw, Tube, TubeRange};
use waam_slicer::io::part_file::{read_part_file, PartFileError};
use waam_slicer::math::{Point3, UnitVector3, Vector3};

fn helix() -> Helix {
    Helix {
        centre: Point3::origin(),
        axis: Vector3::z_axis(),
        radial0: Vector3::x_axis(),
        radius: 40.0,
        pitch: 120.0,
    }
}

/// Frenet frame of the helix, closed form.
fn helix_frenet(h: &Helix, t: f64) -> (Vector3, Vector3, Vector3) {
    let c = h.pitch / std::f64::consts::TAU;
    let w = (h.radius * h.radius + c * c).sqrt();
    let tan = Vector3::new(-h.radius * t.sin(), h.radius * t.cos(), c) / w;
    let n = Vector3::new(-t.cos(), -t.sin(), 0.0);
    (tan, n, tan.cross(&n))
}

#[test]
fn rmf_matches_the_twist_free_frame_of_a_helix() {
    let h = helix();
    let c = h.pitch / std::f64::consts::TAU;
    let w = (h.radius * h.radius + c * c).sqrt();
    let torsion = c / (w * w); // 1/mm
    let tube = Tube::new(
        Arc::new(h.clone()),
        FrameMethod::RotationMinimising,
        None, // starts on the Frenet normal
        ProfileLaw::Constant(8.0),
        TubeRange::new(0.0, 4.0 * std::f64::consts::PI),
    )
    .unwrap();
    for i in 0..=200 {
        let t = 4.0 * std::f64::consts::PI * i as f64 / 200.0;
        let (_, n_f, b_f) = helix_frenet(&h, t);
        // Bishop frame: N = cos(theta) N_F + sin(theta) B_F, theta' = -torsion per unit arc length.
        let theta = -torsion * w * t;
        let expect = n_f * theta.cos() + b_f * theta.sin();
        let got = tube.frame(t).normal;
        assert!((got - expect).norm() < 1e-9, "t = {t}: {got} vs {expect}");
    }
    // The frame turns by 2*pi*c/w per turn about the tangent relative to Frenet: not zero.
    assert!(torsion * w * 4.0 * std::f64::consts::PI > 1.0);
}

#[test]
fn frames_are_orthonormal_and_right_handed() {
    for name in crate::common::SAMPLE_PARTS {
        let part = load_part(name);
        let r = part.tube.range();
        for i in 0..=50 {
            let t = r.eval_min() + (r.eval_max() - r.eval_min()) * i as f64 / 50.0;
            let f = part.tube.frame(t);
            for (a, b) in [
                (f.tangent, f.normal),
                (f.normal, f.binormal),
                (f.tangent, f.binormal),
            ] {
                assert!(a.dot(&b).abs() < 1e-12);
            }
            assert!((f.tangent.cross(&f.normal) - f.binormal).norm() < 1e-12);
            let d1 = part.tube.guide().d1(t);
            assert!((f.tangent - d1.normalize()).norm() < 1e-12);
        }
    }
}

#[test]
fn frenet_on_the_helix_is_the_closed_form_frame() {
    let h = helix();
    let tube = Tube::new(
        Arc::new(h.clone()),
        FrameMethod::Frenet,
        None,
        ProfileLaw::Constant(8.0),
        TubeRange::new(0.0, 6.0),
    )
    .unwrap();
    for i in 0..=30 {
        let t = 0.2 * i as f64;
        let (tan, n, b) = helix_frenet(&h, t);
        let f = tube.frame(t);
        assert!(
            (f.tangent - tan).norm() < 1e-12
                && (f.normal - n).norm() < 1e-12
                && (f.binormal - b).norm() < 1e-12
        );
        // Frenet frames twist: dM/dt must include it (checked against finite differences).
        for v in [0.0, 1.0, 2.5] {
            let sp = tube.surface(t.max(1e-3), v);
            let e = 1e-6;
            let fd = (tube.point(t.max(1e-3) + e, v) - tube.point(t.max(1e-3) - e, v)) / (2.0 * e);
            assert!((sp.d_dt - fd).norm() < 1e-5 * fd.norm());
        }
    }
}

#[test]
fn frenet_is_refused_on_the_straight_legs_of_the_elbow() {
    let text = std::fs::read_to_string(crate::common::part_path("elbow.toml")).unwrap();
    let text = text.replace("method = \"rmf\"", "method = \"frenet\"");
    let err = waam_slicer::io::part_file::parse_part(
        &text,
        "elbow-frenet.toml",
        std::path::Path::new("."),
    )
    .unwrap_err();
    match &err {
        PartFileError::Geometry {
            file,
            source: GeometryError::FrenetUndefined { t },
        } => {
            assert_eq!(file, "elbow-frenet.toml");
            assert!(*t >= 0.0 && *t <= 30.0, "first straight leg, got t = {t}");
        }
        other => panic!("expected FrenetUndefined, got {other:?}"),
    }
    assert!(
        err.to_string().contains("elbow-frenet.toml") && err.to_string().contains("t = 0"),
        "{err}"
    );
}

#[test]
fn frenet_and_rmf_differ_on_the_general_tube_but_share_the_tangent() {
    let rmf = load_part("general-tube.toml");
    let path = crate::common::part_path("general-tube.toml");
    let text = std::fs::read_to_string(&path).unwrap() + "\n[frame]\nmethod = \"frenet\"\n";
    let frenet =
        waam_slicer::io::part_file::parse_part(&text, "x.toml", std::path::Path::new(".")).unwrap();
    assert!(read_part_file(&path).is_ok());
    let mut max_angle: f64 = 0.0;
    for i in 0..=40 {
        let t = i as f64;
        let (a, b) = (rmf.tube.frame(t), frenet.tube.frame(t));
        assert!((a.tangent - b.tangent).norm() < 1e-12);
        max_angle = max_angle.max(a.normal.dot(&b.normal).clamp(-1.0, 1.0).acos());
    }
    assert!(
        max_angle > 0.01,
        "the general tube's guide twists: frames must differ"
    );
    let _ = UnitVector3::new_normalize(Vector3::x());
    let _ = helix().curvature(0.0);
}
