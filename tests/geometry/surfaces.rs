//! Surface points and normals of every sample part against closed forms
//! (thesis eq. 2.2, 2.8, 2.11) to 1e-9 mm, and derivative consistency.

use crate::common::{load_part, SAMPLE_PARTS};
use std::f64::consts::{FRAC_PI_2, PI, TAU};
use waam_slicer::geometry::Tube;
use waam_slicer::math::{Point3, Vector3};

const TOL: f64 = 1e-9;

fn grid(tube: &Tube, nt: usize, nv: usize) -> Vec<(f64, f64)> {
    let r = tube.range();
    let mut out = Vec::new();
    for i in 0..=nt {
        let t = r.t_min + (r.t_max - r.t_min) * i as f64 / nt as f64;
        for k in 0..nv {
            out.push((t, TAU * k as f64 / nv as f64));
        }
    }
    out
}

fn assert_close(a: Point3, b: Point3, what: &str) {
    assert!(
        (a - b).norm() < TOL,
        "{what}: {a} vs {b}, diff {}",
        (a - b).norm()
    );
}

fn assert_dir(a: Vector3, b: Vector3, what: &str) {
    assert!((a - b).norm() < TOL, "{what}: {a} vs {b}");
}

/// Surface of revolution about Z with radius law `a(t)`: closed form point and
/// outward normal ∝ (cos v, sin v, -A'(t)).
fn check_revolution(name: &str, a: impl Fn(f64) -> f64, da: impl Fn(f64) -> f64) {
    let part = load_part(name);
    for (t, v) in grid(&part.tube, 40, 24) {
        let sp = part.tube.surface(t, v);
        let expect = Point3::new(a(t) * v.cos(), a(t) * v.sin(), t);
        assert_close(sp.position, expect, &format!("{name} M({t}, {v})"));
        let n = Vector3::new(v.cos(), v.sin(), -da(t)).normalize();
        assert_dir(sp.normal.into_inner(), n, &format!("{name} n({t}, {v})"));
    }
}

#[test]
fn hemisphere_matches_sphere_eq_2_2() {
    let rs = 45.0_f64;
    check_revolution(
        "hemisphere.toml",
        |z| (rs * rs - z * z).sqrt(),
        |z| -z / (rs * rs - z * z).sqrt(),
    );
    // On a sphere the outward normal is the position over the radius.
    let part = load_part("hemisphere.toml");
    for (t, v) in grid(&part.tube, 20, 12) {
        let sp = part.tube.surface(t, v);
        assert!((sp.position.coords.norm() - rs).abs() < TOL);
        assert_dir(
            sp.normal.into_inner(),
            sp.position.coords / rs,
            "sphere normal",
        );
    }
}

#[test]
fn nozzle_matches_eq_2_8() {
    let a = |z: f64| {
        if z <= 96.5 {
            ((z - 100.0) * 2.0 * -10.0).sqrt()
        } else {
            ((z - 85.0) * 6.0).sqrt()
        }
    };
    let da = |z: f64| if z <= 96.5 { -10.0 / a(z) } else { 3.0 / a(z) };
    check_revolution("nozzle.toml", a, da);
}

#[test]
fn half_catenoid_matches_eq_3_19() {
    let rs = 45.0_f64;
    check_revolution(
        "half-catenoid.toml",
        |z| 2.0 * rs - (rs * rs - z * z).sqrt(),
        |z| z / (rs * rs - z * z).sqrt(),
    );
}

fn torus_closed_form(t: f64, v: f64) -> (Point3, Vector3) {
    let (rr, r) = (50.0, 15.0);
    let rho = rr + r * v.cos();
    let p = Point3::new(rho * t.cos() - rr, r * v.sin(), rho * t.sin());
    let n = Vector3::new(v.cos() * t.cos(), v.sin(), v.cos() * t.sin());
    (p, n)
}

#[test]
fn quarter_torus_matches_eq_2_11() {
    for name in ["quarter-torus.toml", "torus-on-cylinder.toml"] {
        let part = load_part(name);
        // Also past the end, where paths are generated before truncation.
        let r = part.tube.range();
        for i in 0..=60 {
            let t = r.eval_min() + (r.eval_max() - r.eval_min()) * i as f64 / 60.0;
            for k in 0..24 {
                let v = TAU * k as f64 / 24.0;
                let sp = part.tube.surface(t, v);
                let (p, n) = torus_closed_form(t, v);
                assert_close(sp.position, p, &format!("{name} M({t}, {v})"));
                assert_dir(sp.normal.into_inner(), n, &format!("{name} n({t}, {v})"));
            }
        }
        // Inner side v = pi advances slower along t... as the surface: |dM/dt| = R + r cos v.
        let sp = part.tube.surface(FRAC_PI_2 / 2.0, PI);
        assert!((sp.d_dt.norm() - 35.0).abs() < 1e-9);
        let sp = part.tube.surface(FRAC_PI_2 / 2.0, 0.0);
        assert!((sp.d_dt.norm() - 65.0).abs() < 1e-9);
    }
}

#[test]
fn elbow_legs_and_bend_match_closed_form() {
    let part = load_part("elbow.toml");
    let (a, rb) = (20.0, 60.0);
    for k in 0..24 {
        let v = TAU * k as f64 / 24.0;
        // First leg: a straight cylinder about Z.
        for t in [0.0, 10.0, 30.0] {
            let sp = part.tube.surface(t, v);
            assert_close(
                sp.position,
                Point3::new(a * v.cos(), a * v.sin(), t),
                "elbow leg",
            );
            assert_dir(
                sp.normal.into_inner(),
                Vector3::new(v.cos(), v.sin(), 0.0),
                "elbow leg normal",
            );
        }
        // Bend: torus about the axis through (60, *, 30) parallel to Y; angle phi from the start.
        for phi in [0.1, 0.7, 1.5] {
            let t = 30.0 + rb * phi;
            let c = Point3::new(rb, 0.0, 30.0);
            let radial = Vector3::new(-phi.cos(), 0.0, phi.sin()); // from bend centre to guide
            let rho = rb - a * v.cos(); // v = 0 (reference +X) points toward the bend centre
            let p = c + radial * rho + Vector3::new(0.0, a * v.sin(), 0.0);
            assert_close(part.tube.point(t, v), p, "elbow bend");
        }
        // Second leg: horizontal, along +X, at Z = 30 + 60.
        let t_end = part.tube.range().t_max;
        let sp = part.tube.surface(t_end, v);
        let guide_end = Point3::new(60.0 + 30.0, 0.0, 90.0);
        let e = sp.position - guide_end;
        assert!(
            (e.norm() - a).abs() < TOL && e.x.abs() < TOL,
            "second leg is a circle in the plane X = 90"
        );
    }
}

#[test]
fn derivatives_match_finite_differences_on_every_part() {
    for name in SAMPLE_PARTS {
        let part = load_part(name);
        let tube = &part.tube;
        let r = tube.range();
        let h = 1e-6 * (r.t_max - r.t_min);
        for (t, v) in grid(tube, 7, 8) {
            let t = t.clamp(r.t_min + 2.0 * h, r.t_max - 2.0 * h);
            let sp = tube.surface(t, v);
            let fd_t = (tube.point(t + h, v) - tube.point(t - h, v)) / (2.0 * h);
            let fd_v = (tube.point(t, v + 1e-6) - tube.point(t, v - 1e-6)) / 2e-6;
            let scale = sp.d_dt.norm().max(1.0);
            assert!(
                (sp.d_dt - fd_t).norm() < 1e-5 * scale,
                "{name} dM/dt at ({t}, {v}): {} vs {}",
                sp.d_dt,
                fd_t
            );
            assert!(
                (sp.d_dv - fd_v).norm() < 1e-5 * sp.d_dv.norm().max(1.0),
                "{name} dM/dv at ({t}, {v})"
            );
            // The normal is unit, perpendicular to both derivatives and points away from the guide.
            let n = sp.normal.into_inner();
            assert!(
                n.dot(&sp.d_dt).abs() < 1e-9 * scale
                    && n.dot(&sp.d_dv).abs() < 1e-9 * sp.d_dv.norm()
            );
            assert!(
                n.dot(&(sp.position - tube.guide().point(t))) > 0.0,
                "{name}: normal points outward"
            );
            // |M - Mg| = A(t) and M - Mg is in the normal plane.
            let e = sp.position - tube.guide().point(t);
            assert!((e.norm() - tube.radius(t)).abs() < 1e-9);
            assert!(e.dot(&tube.frame(t).tangent).abs() < 1e-9);
        }
    }
}

#[test]
fn iso_lines_lie_on_the_surface() {
    let part = load_part("quarter-torus.toml");
    let circle = part.tube.iso_t(0.3, 36);
    assert_eq!(circle.len(), 36);
    for (k, p) in circle.iter().enumerate() {
        let (q, _) = torus_closed_form(0.3, TAU * k as f64 / 36.0);
        assert_close(*p, q, "iso-t");
    }
    let ts = [0.0, 0.5, 1.0, 1.5];
    let gen = part.tube.iso_v(PI, &ts);
    for (p, t) in gen.iter().zip(ts) {
        assert_close(*p, torus_closed_form(t, PI).0, "iso-v");
    }
}

#[test]
fn arc_length_of_the_guide_and_its_inverse() {
    let torus = load_part("quarter-torus.toml");
    assert!((torus.tube.arc_length(FRAC_PI_2) - 50.0 * FRAC_PI_2).abs() < 1e-9);
    let general = load_part("general-tube.toml");
    // Independent value: fine trapezoid rule on |Mg'(t)|.
    let speed = |t: f64| {
        let dx = (0.015 * t * t - 0.44 * t) / 6.0;
        let dy = 0.04 * t;
        (dx * dx + dy * dy + 1.0_f64).sqrt()
    };
    let n = 200_000;
    let h = 40.0 / n as f64;
    let trap: f64 = (0..n)
        .map(|i| 0.5 * h * (speed(i as f64 * h) + speed((i + 1) as f64 * h)))
        .sum();
    let s = general.tube.arc_length(40.0);
    assert!((s - trap).abs() < 1e-6, "{s} vs {trap}");
    for s in [0.0, 1.0, 17.3, s] {
        let t = general.tube.t_at_arc_length(s);
        assert!((general.tube.arc_length(t) - s).abs() < 1e-9);
    }
}
