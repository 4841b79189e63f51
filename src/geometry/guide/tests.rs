use super::*;
use crate::math::UnitVector3;
use std::collections::BTreeMap;

fn fd(c: &dyn GuideCurve, t: f64, order: usize) -> Vector3 {
    let h = 1e-5;
    match order {
        1 => (c.point(t + h) - c.point(t - h)) / (2.0 * h),
        2 => (c.d1(t + h) - c.d1(t - h)) / (2.0 * h),
        _ => (c.d2(t + h) - c.d2(t - h)) / (2.0 * h),
    }
}

fn check_derivatives(c: &dyn GuideCurve, ts: &[f64]) {
    for &t in ts {
        for (order, exact) in [(1, c.d1(t)), (2, c.d2(t)), (3, c.d3(t))] {
            let approx = fd(c, t, order);
            assert!(
                (exact - approx).norm() < 1e-6 * exact.norm().max(1.0),
                "{c:?} order {order} at {t}: {exact} vs {approx}"
            );
        }
    }
}

fn consts() -> BTreeMap<String, f64> {
    BTreeMap::from([("R".to_string(), 50.0)])
}

#[test]
fn expression_derivatives_are_analytic() {
    let e = Expression::parse("R * sin(2*t) + t^3", "t", &consts()).unwrap();
    let t = 0.7_f64;
    assert!((e.eval(t) - (50.0 * (2.0 * t).sin() + t.powi(3))).abs() < 1e-12);
    assert!((e.eval_derivative(1, t) - (100.0 * (2.0 * t).cos() + 3.0 * t * t)).abs() < 1e-12);
    assert!((e.eval_derivative(2, t) - (-200.0 * (2.0 * t).sin() + 6.0 * t)).abs() < 1e-12);
    assert!((e.eval_derivative(3, t) - (-400.0 * (2.0 * t).cos() + 6.0)).abs() < 1e-11);
    let k = Expression::parse("R / 2", "t", &consts()).unwrap();
    assert!(!k.depends_on_param());
    assert_eq!(k.eval(3.0), 25.0);
    assert_eq!(k.eval_derivative(1, 3.0), 0.0);
}

#[test]
fn expression_errors_name_the_text() {
    for bad in ["", "sin(", "t +* 2", "q * t"] {
        let e = Expression::parse(bad, "t", &consts()).unwrap_err();
        assert!(e.to_string().contains(&format!("`{bad}`")), "{e}");
    }
    let long = "t+".repeat(MAX_EXPRESSION_LEN) + "t";
    let e = Expression::parse(&long, "t", &consts()).unwrap_err();
    assert!(e.to_string().contains("limit"), "{e}");
}

#[test]
fn analytic_curves_have_consistent_derivatives_and_arc_lengths() {
    let arc = CircleArc {
        centre: Point3::new(-50.0, 0.0, 0.0),
        radius: 50.0,
        radial0: Vector3::x_axis(),
        tangent0: Vector3::z_axis(),
    };
    let helix = Helix {
        centre: Point3::origin(),
        axis: Vector3::z_axis(),
        radial0: Vector3::x_axis(),
        radius: 40.0,
        pitch: 120.0,
    };
    let line = Line {
        origin: Point3::origin(),
        direction: UnitVector3::new_normalize(Vector3::new(1.0, 1.0, 1.0)),
    };
    for c in [&arc as &dyn GuideCurve, &helix, &line] {
        check_derivatives(c, &[-0.3, 0.0, 0.4, 1.3]);
        // Analytic arc length against the trait's default quadrature.
        let numeric = math::gauss_legendre(|t| c.d1(t).norm(), 0.2, 1.9, 8);
        assert!((c.arc_length(0.2, 1.9) - numeric).abs() < 1e-10);
        assert!((c.param_at_arc_length(0.2, numeric) - 1.9).abs() < 1e-10);
        assert!((default_param_at_arc_length(c, 0.2, numeric) - 1.9).abs() < 1e-9);
    }
    assert!((arc.curvature(1.0) - 1.0 / 50.0).abs() < 1e-15);
    assert!(
        (helix.curvature(0.3) - 40.0 / (1600.0 + (120.0 / std::f64::consts::TAU).powi(2))).abs()
            < 1e-15
    );
}

#[test]
fn spline_interpolates_and_is_c2() {
    let pts: Vec<Point3> = (0..12)
        .map(|i| {
            let a = i as f64 * 0.3;
            Point3::new(30.0 * a.cos(), 30.0 * a.sin(), 5.0 * a)
        })
        .collect();
    let s = CubicSpline::new(&pts).unwrap();
    let mut t = 0.0;
    for w in pts.windows(2) {
        assert!((s.point(t) - w[0]).norm() < 1e-12);
        t += (w[1] - w[0]).norm();
    }
    assert!((s.point(s.length()) - pts[11]).norm() < 1e-12);
    check_derivatives(&s, &[0.5, 7.0, 20.0]);
    // Natural end conditions and C2 at an interior knot.
    assert!(s.d2(0.0).norm() < 1e-12 && s.d2(s.length()).norm() < 1e-12);
    let k = (pts[1] - pts[0]).norm();
    assert!((s.d2(k - 1e-9) - s.d2(k + 1e-9)).norm() < 1e-6);
    // Straight extension beyond the ends.
    assert!(
        (s.point(s.length() + 2.0) - (s.point(s.length()) + s.d1(s.length()) * 2.0)).norm() < 1e-12
    );
    assert!(CubicSpline::new(&pts[..2]).is_err());
    let dup = [pts[0], pts[1], pts[1], pts[2]];
    assert!(CubicSpline::new(&dup)
        .unwrap_err()
        .to_string()
        .contains("point 2"));
}

#[test]
fn pipe_run_is_tangent_continuous() {
    let run = PipeRun::new(
        Point3::origin(),
        Vector3::z_axis(),
        &[
            PipeSegment::Straight { length: 30.0 },
            PipeSegment::Bend {
                radius: 60.0,
                angle: std::f64::consts::FRAC_PI_2,
                toward: Vector3::x(),
            },
            PipeSegment::Straight { length: 30.0 },
        ],
    )
    .unwrap();
    let l = run.length();
    assert!((l - (60.0 + 30.0 * std::f64::consts::PI)).abs() < 1e-12);
    assert!((run.point(l) - Point3::new(90.0, 0.0, 90.0)).norm() < 1e-12);
    for t in [30.0, 30.0 + 30.0 * std::f64::consts::PI] {
        assert!((run.point(t - 1e-9) - run.point(t + 1e-9)).norm() < 1e-8);
        assert!((run.d1(t - 1e-9) - run.d1(t + 1e-9)).norm() < 1e-8);
    }
    check_derivatives(&run, &[10.0, 50.0, 100.0]);
    assert!((run.curvature(50.0) - 1.0 / 60.0).abs() < 1e-12);
    assert_eq!(run.curvature(10.0), 0.0);
    let e = PipeRun::new(
        Point3::origin(),
        Vector3::z_axis(),
        &[PipeSegment::Bend {
            radius: 5.0,
            angle: 1.0,
            toward: Vector3::z(),
        }],
    );
    assert!(e.unwrap_err().to_string().contains("segment 0"));
}
