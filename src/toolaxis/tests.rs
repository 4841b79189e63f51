//! Unit tests of the tool-axis stage: Rodrigues closed form, rules, smoothing,
//! projection, and one bad-input test per error variant.

use super::rules::{max_rate, project_build};
use super::*;
use crate::math::{Point3, Vector3};
use crate::path::{Layer, PathPoint, SliceReport, StopReason, Strategy};
use approx::assert_relative_eq;

fn frame(t: Vector3, n: Vector3, b: Vector3) -> LocalFrame {
    LocalFrame {
        tangent: t,
        normal: n,
        build: b,
        tool: b,
    }
}

/// A frame whose `b` leans `lean` rad from +Z toward −X, `t = +Y`, `n` outward
/// (+X side), as on the hemisphere at the X axis.
fn leaning_frame(lean: f64) -> LocalFrame {
    let b = Vector3::new(-lean.sin(), 0.0, lean.cos());
    let n = Vector3::new(lean.cos(), 0.0, lean.sin());
    frame(Vector3::y(), n, b)
}

#[test]
fn closed_form_matches_literal_rodrigues() {
    let f = frame(Vector3::x(), Vector3::y(), Vector3::z());
    for (lead, tilt) in [(0.0, 0.0), (0.3, 0.0), (0.0, -0.4), (0.5, 0.7), (-1.2, 0.2)] {
        let a = tool_axis(&f, lead, tilt);
        let b = tool_axis_rodrigues(lead, tilt);
        assert_relative_eq!(a, b, epsilon = 1e-14);
        let (l, t) = lead_tilt_of(&f, &a);
        assert_relative_eq!(l, lead, epsilon = 1e-14);
        assert_relative_eq!(t, tilt, epsilon = 1e-14);
    }
}

#[test]
fn rodrigues_matrix_is_a_rotation() {
    let k = Vector3::new(1.0, 2.0, -0.5).normalize();
    let r = lead_tilt::rodrigues(&k, 0.8);
    assert_relative_eq!(
        r * r.transpose(),
        crate::math::Matrix3::identity(),
        epsilon = 1e-14
    );
    assert_relative_eq!(r.determinant(), 1.0, epsilon = 1e-14);
    assert_relative_eq!(r * k, k, epsilon = 1e-14);
}

#[test]
fn fifty_degree_rule_tilts_back_to_exactly_fifty() {
    let rule = AxisRule::thesis_50_deg();
    for lean_deg in [0.0, 30.0, 49.9, 50.0, 60.0, 80.0, 89.0] {
        let f = leaning_frame(f64::to_radians(lean_deg));
        let out = rule.apply(&f, 0.0, 0.0, 0, 0);
        let t = tool_axis(&f, out.lead_rad, out.tilt_rad);
        let angle = t.z.acos().to_degrees();
        if lean_deg <= 50.0 {
            assert!(!out.active);
            assert_relative_eq!(angle, lean_deg, epsilon = 1e-9);
        } else {
            assert!(out.active && out.reached);
            assert_relative_eq!(angle, 50.0, epsilon = 1e-9);
            // Tilted toward the outside here (n has +Z).
            assert!(out.tilt_rad > 0.0);
        }
    }
    // With a lead angle, the lead is kept and the cone still reached.
    let f = leaning_frame(70f64.to_radians());
    let out = rule.apply(&f, 0.2, 0.0, 0, 0);
    assert_eq!(out.lead_rad, 0.2);
    let t = tool_axis(&f, out.lead_rad, out.tilt_rad);
    assert_relative_eq!(t.z.acos().to_degrees(), 50.0, epsilon = 1e-9);
}

#[test]
fn cone_out_of_reach_by_tilt_is_reported() {
    // b horizontal, t = +Z: tilting in the (n, b) plane never reaches +Z.
    let f = frame(Vector3::z(), Vector3::y(), Vector3::x());
    let out = AxisRule::thesis_50_deg().apply(&f, 0.0, 0.0, 0, 0);
    assert!(out.active && !out.reached);
}

#[test]
fn projection_into_a_plane() {
    let mut frames = vec![vec![leaning_frame(0.6)]];
    let b0 = frames[0][0].build;
    frames[0][0].build = (b0 + Vector3::y() * 0.3).normalize();
    project_build(&mut frames, &Vector3::y(), std::f64::consts::FRAC_PI_2);
    let f = frames[0][0];
    assert!(f.build.y.abs() < 1e-15);
    assert_relative_eq!(f.build, b0, epsilon = 1e-12);
    assert!(f.tangent.dot(&f.build).abs() < 1e-12 && f.normal.dot(&f.build).abs() < 1e-12);
    assert_eq!(f.tool, f.build);
}

#[test]
fn smoothing_bounds_the_rate_and_keeps_a_cone() {
    // A step of 40° in the middle of a 1 mm-spaced line.
    let n = 41;
    let positions: Vec<Point3> = (0..n).map(|i| Point3::new(i as f64, 0.0, 0.0)).collect();
    let a = Vector3::new(0.0, 0.0, 1.0);
    let b = Vector3::new(40f64.to_radians().sin(), 0.0, 40f64.to_radians().cos());
    let mut axes: Vec<Vector3> = (0..n).map(|i| if i < 20 { a } else { b }).collect();
    assert!(max_rate(&positions, &axes, false) > 0.6);
    let moved = smooth_layer(&positions, &mut axes, false, 0.05);
    assert!(moved > 0);
    assert!(max_rate(&positions, &axes, false) <= 0.05 * (1.0 + 1e-6));
    for x in &axes {
        assert!(x.z.acos() <= 40f64.to_radians() + 1e-12);
        assert_relative_eq!(x.norm(), 1.0, epsilon = 1e-12);
    }
    // Closed layer: the wrap pair is bounded too.
    let mut axes: Vec<Vector3> = (0..n).map(|i| if i < 20 { a } else { b }).collect();
    smooth_layer(&positions, &mut axes, true, 0.05);
    assert!(max_rate(&positions, &axes, true) <= 0.05 * (1.0 + 1e-6));
}

fn tiny_path(layers: Vec<Vec<Point3>>) -> Path {
    Path {
        strategy: Strategy::Constant,
        delta_mm: 1.0,
        layers: layers
            .into_iter()
            .enumerate()
            .map(|(k, pts)| Layer {
                slice: k,
                points: pts
                    .into_iter()
                    .map(|position| PathPoint {
                        t: 0.0,
                        v: 0.0,
                        position,
                        delta: (k > 0).then_some(1.0),
                    })
                    .collect(),
                closed: true,
            })
            .collect(),
        report: SliceReport {
            stop: StopReason::ReachedEnd,
            ..SliceReport::default()
        },
        spiral: None,
    }
}

fn ring(z: f64, r: f64, n: usize) -> Vec<Point3> {
    (0..n)
        .map(|i| {
            let a = std::f64::consts::TAU * i as f64 / n as f64;
            Point3::new(r * a.cos(), r * a.sin(), z)
        })
        .collect()
}

#[test]
fn numeric_frames_of_a_cylinder() {
    let path = tiny_path(vec![
        ring(0.0, 10.0, 64),
        ring(1.0, 10.0, 64),
        ring(2.0, 10.0, 64),
    ]);
    let opts = ToolAxisOptions {
        normals: NormalMethod::Numeric,
        ..ToolAxisOptions::default()
    };
    let axes = tool_axes(&path, None, None, &opts).unwrap();
    // The facets (M_{i-1}, M_{i+1}, Q) miss M_i by the polygon's sagitta:
    // one facet leans by ~ sagitta / Delta = 0.048 rad on the first and last
    // layers; the two facets of the middle layer lean opposite ways and cancel.
    for (k, (l, fl)) in path.layers.iter().zip(&axes.frames).enumerate() {
        let tol = if k == 1 { 1e-12 } else { 0.05 };
        for (p, f) in l.points.iter().zip(fl) {
            let radial = Vector3::new(p.position.x, p.position.y, 0.0).normalize();
            assert_relative_eq!(f.normal, radial, epsilon = tol);
            assert_relative_eq!(f.build, Vector3::z(), epsilon = tol);
            assert_eq!(f.tool, f.build);
        }
    }
}

#[test]
fn error_variants_name_the_place() {
    let good = tiny_path(vec![ring(0.0, 10.0, 8), ring(1.0, 10.0, 8)]);
    let numeric = ToolAxisOptions {
        normals: NormalMethod::Numeric,
        ..ToolAxisOptions::default()
    };
    // InvalidOption
    let e = tool_axes(
        &good,
        None,
        None,
        &ToolAxisOptions {
            lead_rad: 2.0,
            ..numeric.clone()
        },
    )
    .unwrap_err();
    assert!(e.to_string().contains("lead_rad"), "{e}");
    let e = tool_axes(
        &good,
        None,
        None,
        &ToolAxisOptions {
            rule: AxisRule::MaxAngleFromAxis {
                axis: [0.0; 3],
                max_angle_rad: 0.5,
            },
            ..numeric.clone()
        },
    )
    .unwrap_err();
    assert!(e.to_string().contains("rule.axis"), "{e}");
    // NeedsTube
    let e = tool_axes(
        &good,
        None,
        None,
        &ToolAxisOptions {
            normals: NormalMethod::Analytic,
            ..ToolAxisOptions::default()
        },
    )
    .unwrap_err();
    assert_eq!(e, ToolAxisError::NeedsTube);
    // TooFewSlices
    let one = tiny_path(vec![ring(0.0, 10.0, 8)]);
    let e = tool_axes(&one, None, None, &numeric).unwrap_err();
    assert!(e.to_string().contains("has 1"), "{e}");
    // TooFewPoints
    let short = tiny_path(vec![ring(0.0, 10.0, 8), vec![Point3::origin()]]);
    let e = tool_axes(&short, None, None, &numeric).unwrap_err();
    assert!(e.to_string().starts_with("layer 1: 1 point"), "{e}");
    // DegenerateTangent: neighbours of point 1 coincide.
    let mut pts = ring(1.0, 10.0, 8);
    pts[2] = pts[0];
    let degenerate = tiny_path(vec![ring(0.0, 10.0, 8), pts]);
    let e = tool_axes(&degenerate, None, None, &numeric).unwrap_err();
    assert!(e.to_string().starts_with("layer 1, point 1"), "{e}");
    // DegenerateNormal: the layer above is the same ring (flat facets).
    let line = |x0: f64| {
        (0..4)
            .map(|i| Point3::new(x0 + i as f64, 0.0, 0.0))
            .collect()
    };
    let flat = tiny_path(vec![line(0.0), line(0.5)]);
    let e = tool_axes(&flat, None, None, &numeric).unwrap_err();
    assert!(
        matches!(e, ToolAxisError::DegenerateNormal { layer: 0, point: 0 }),
        "{e}"
    );
    // ShapeMismatch
    let e = tool_axes(
        &good,
        None,
        None,
        &ToolAxisOptions {
            rule: AxisRule::PerPoint {
                angles: vec![vec![[0.0, 0.0]; 8], vec![[0.0, 0.0]; 7]],
            },
            ..numeric.clone()
        },
    )
    .unwrap_err();
    assert!(
        e.to_string().contains("layer 1: 7 frames for 8 points"),
        "{e}"
    );
    // InvalidTorch
    let e = Torch::new(&TorchSpec::Hull {
        points: vec![[0.0; 3]; 3],
    })
    .unwrap_err();
    assert!(e.to_string().contains("torch `points`"), "{e}");
    let e = Torch::new(&TorchSpec::Nozzle {
        tip_offset_mm: 1.0,
        tip_radius_mm: 1.0,
        nozzle_radius_mm: -1.0,
        nozzle_length_mm: 1.0,
        body_radius_mm: 1.0,
        body_length_mm: 1.0,
    })
    .unwrap_err();
    assert!(e.to_string().contains("nozzle_radius_mm"), "{e}");
    // Collision option
    let torch = Torch::new(&TorchSpec::pla_nozzle()).unwrap();
    let frames = tool_axes(&good, None, None, &numeric).unwrap().frames;
    let e = check_collisions(
        &good,
        &frames,
        None,
        &torch,
        &CollisionOptions {
            bead_radius_mm: f64::NAN,
            ..CollisionOptions::default()
        },
    )
    .unwrap_err();
    assert!(e.to_string().contains("bead_radius_mm"), "{e}");
    let e = avoid_collisions(
        &good,
        &frames,
        None,
        &torch,
        &CollisionOptions::default(),
        &AvoidanceOptions {
            azimuths: 2,
            ..AvoidanceOptions::default()
        },
    )
    .unwrap_err();
    assert!(e.to_string().contains("azimuths"), "{e}");
}

#[test]
fn options_round_trip_through_serde() {
    let o = ToolAxisOptions {
        rule: AxisRule::thesis_50_deg(),
        project_build: Some([1.0, 0.0, 0.0]),
        max_rate_rad_per_mm: Some(0.1),
        ..ToolAxisOptions::default()
    };
    let s = serde_json::to_string(&o).unwrap();
    let back: ToolAxisOptions = serde_json::from_str(&s).unwrap();
    assert_eq!(back, o);
    let t: TorchSpec =
        serde_json::from_str(&serde_json::to_string(&TorchSpec::cmt_torch()).unwrap()).unwrap();
    assert_eq!(t, TorchSpec::cmt_torch());
}

#[test]
fn smoothing_alternating_tilts_on_a_ring() {
    let positions = ring(0.0, 5.0, 100);
    let mut axes: Vec<Vector3> = (0..100)
        .map(|i| {
            let radial = positions[i].coords.normalize();
            let s = if i % 2 == 0 { 0.3f64 } else { -0.3 };
            (Vector3::z() * s.cos() + radial * s.sin()).normalize()
        })
        .collect();
    smooth_layer(&positions, &mut axes, true, 0.02);
    let r = max_rate(&positions, &axes, true);
    assert!(r <= 0.02 * (1.0 + 1e-6), "{r}");
}
