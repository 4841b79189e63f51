//! The four strategies on the sample parts against the thesis's published
//! figures (SPEC §3.2) and closed forms (eq. 2.4–2.6, 2.16).

use crate::common::{load_part, SAMPLE_PARTS};
use std::f64::consts::{FRAC_PI_2, TAU};
use waam_slicer::io::part_file::Part;
use waam_slicer::path::{distance_map, slice, EndRule, Path, PathError, StopReason, Strategy};

fn run(
    part: &Part,
    strategy: Strategy,
    delta: f64,
    end: EndRule,
    max_layers: Option<usize>,
) -> Path {
    let mut o = part.slice_options();
    o.strategy = strategy;
    o.delta_mm = delta;
    o.end = end;
    o.max_layers = max_layers;
    slice(&part.tube, &part.substrate, &o).unwrap_or_else(|e| panic!("{}: {e}", part.name))
}

/// Quarter torus, perpendicular slicing: 16 layers, variation 60 % (±30 %)
/// [thesis §2.2, fig. 2.6]. Layers k Delta apart along the guide are
/// (R + r cos v) k Delta / R apart at v: 1 ± r/R = ±30 %. Tolerance 0.5 % of
/// Delta (the polyline's chord error at 500 points is 0.0006 %).
#[test]
fn quarter_torus_perpendicular_varies_by_60_percent() {
    let part = load_part("quarter-torus.toml");
    let path = run(
        &part,
        Strategy::Perpendicular,
        5.0,
        EndRule::WholeLayers,
        None,
    );
    assert_eq!(path.num_slices(), 16);
    let s = distance_map(&path).overall.unwrap();
    assert!((s.variation - 0.60).abs() < 0.005, "{s:?}");
    assert!(
        (s.min_rel + 0.30).abs() < 0.005 && (s.max_rel - 0.30).abs() < 0.005,
        "{s:?}"
    );
}

/// Quarter torus, iso-`v` path with the same 16 layers (the guide reaching
/// past pi/2 on the inner side): about −45 % only downwards [thesis §2.2,
/// fig. 2.7]. Our independent re-computation gives 45.1 % (SPEC §3.2); we
/// accept 45.1 ± 1 %.
#[test]
fn quarter_torus_iso_path_drops_45_percent_only_downwards() {
    let part = load_part("quarter-torus.toml");
    let path = run(&part, Strategy::Iso, 5.0, EndRule::EvaluableRange, Some(16));
    assert_eq!(path.num_slices(), 16);
    assert_eq!(path.report.stop, StopReason::MaxLayers);
    let m = distance_map(&path);
    let s = m.overall.unwrap();
    assert!(s.max_rel <= 1e-9, "never above Delta: {s:?}");
    assert!((s.min_rel + 0.451).abs() < 0.01, "{s:?}");
    // The minimum is on the inner side (v = pi).
    let (li, pi) = m
        .points
        .iter()
        .enumerate()
        .flat_map(|(l, pts)| {
            pts.iter()
                .enumerate()
                .filter_map(move |(i, d)| d.map(|d| (l, i, d.0)))
        })
        .min_by(|a, b| a.2.total_cmp(&b.2))
        .map(|(l, i, _)| (l, i))
        .unwrap();
    let v = path.layers[li].points[pi].v;
    assert!(v.cos() < 0.0, "minimum on the inner half, got v = {v}");
}

/// Torus closed form of the iso-parametric path [SPEC §3.1.3]:
/// `u_{n+1} = u_n + acos(1 − D² / (2 (R + r cos v)²))`.
#[test]
fn quarter_torus_iso_path_matches_the_closed_form() {
    let part = load_part("quarter-torus.toml");
    let d = 5.0_f64;
    let path = run(&part, Strategy::Iso, d, EndRule::EvaluableRange, Some(12));
    for layer in &path.layers {
        for p in &layer.points {
            let rho = 50.0 + 15.0 * p.v.cos();
            let du = (1.0 - d * d / (2.0 * rho * rho)).acos();
            assert!(
                (p.t - layer.slice as f64 * du).abs() < 1e-9,
                "slice {} v {}: {} vs {}",
                layer.slice,
                p.v,
                p.t,
                layer.slice as f64 * du
            );
        }
    }
}

/// Quarter torus, constant distance: variation below 0.1 % (thesis: ~0 %).
/// Generated past the end and cut by the end plane (SPEC §3.5).
#[test]
fn quarter_torus_constant_distance_is_constant() {
    let part = load_part("quarter-torus.toml");
    let path = run(
        &part,
        Strategy::Constant,
        5.0,
        part.slice_options().end,
        None,
    );
    assert_eq!(path.report.stop, StopReason::PastEndPlane);
    assert!(path.report.truncated_points > 0);
    let s = distance_map(&path).overall.unwrap();
    assert!(s.variation < 1e-3, "{s:?}");
    // Every kept point is inside the end plane X >= -R, and the inner side
    // reaches the plane: the last slices are open.
    for l in &path.layers {
        for p in &l.points {
            assert!(p.position.x >= -50.0 - 1e-9);
        }
    }
    assert!(path.layers.iter().any(|l| !l.closed));
    // With t capped at pi/2, only about a dozen whole layers fit (SPEC §3.2).
    let whole = run(&part, Strategy::Constant, 5.0, EndRule::WholeLayers, None);
    assert!(
        (10..=13).contains(&whole.num_slices()),
        "{}",
        whole.num_slices()
    );
    assert!(whole.layers.iter().all(|l| l.closed));
}

/// Hemisphere closed form of the iso-parametric path [eq. 2.5]:
/// `Zg_{i+1} = Zg_i (1 − D²/(2 R²)) + D sqrt((1 − D²/(4 R²))(1 − Zg_i²/R²))`;
/// the distances are within 0.1 % of Delta, and the constant-distance method
/// within 0.01 %, for Delta = 5 and 1.
#[test]
fn hemisphere_iso_closed_form_and_constant_distance() {
    let part = load_part("hemisphere.toml");
    let r = 45.0_f64;
    for d in [5.0_f64, 1.0] {
        let iso = run(&part, Strategy::Iso, d, EndRule::WholeLayers, None);
        let mut z = 0.0_f64;
        for layer in iso.layers.iter().skip(1) {
            z = z * (1.0 - d * d / (2.0 * r * r))
                + d * ((1.0 - d * d / (4.0 * r * r)) * (1.0 - z * z / (r * r))).sqrt();
            for p in &layer.points {
                assert!(
                    (p.t - z).abs() < 1e-9,
                    "Delta {d}, slice {}: Zg {} vs {z}",
                    layer.slice,
                    p.t
                );
            }
        }
        let s = distance_map(&iso).overall.unwrap();
        assert!(
            s.min_rel.abs() < 1e-3 && s.max_rel.abs() < 1e-3,
            "iso, Delta {d}: {s:?}"
        );
        let constant = run(&part, Strategy::Constant, d, EndRule::WholeLayers, None);
        let s = distance_map(&constant).overall.unwrap();
        assert!(
            s.min_rel.abs() < 1e-4 && s.max_rel.abs() < 1e-4,
            "constant, Delta {d}: {s:?}"
        );
        // Layers reach close to the pole.
        let top = constant.layers.last().unwrap().points[0].t;
        assert!(top > 44.9 - 2.0 * d, "top layer at Zg = {top}");
    }
}

/// Every sample part sliced with the constant method at Delta = 1 and 5:
/// every distance within 0.1 % of Delta, layers monotone along the guide
/// (each column's t increases), no layer crossing the one below.
#[test]
fn every_sample_part_constant_distance_at_1_and_5_mm() {
    for name in SAMPLE_PARTS {
        let part = load_part(name);
        for d in [1.0, 5.0] {
            let mut o = part.slice_options();
            o.strategy = Strategy::Constant;
            o.delta_mm = d;
            o.discretisation = waam_slicer::path::Discretisation::Points(200);
            let path = slice(&part.tube, &part.substrate, &o)
                .unwrap_or_else(|e| panic!("{name} Delta {d}: {e}"));
            assert!(
                path.num_slices() >= 3,
                "{name} Delta {d}: {} slices",
                path.num_slices()
            );
            let m = distance_map(&path);
            let s = m.overall.unwrap();
            assert!(
                s.min_rel.abs() < 1e-3 && s.max_rel.abs() < 1e-3,
                "{name} Delta {d}: {s:?}"
            );
            // Monotone along the guide: compare each point with its column (same v) below.
            let mut last_t: std::collections::HashMap<u64, f64> = Default::default();
            for l in &path.layers {
                for p in &l.points {
                    let key = p.v.to_bits();
                    if let Some(&t0) = last_t.get(&key) {
                        assert!(
                            p.t > t0,
                            "{name} Delta {d}: slice {} v {} goes back ({} <= {t0})",
                            l.slice,
                            p.v,
                            p.t
                        );
                    }
                    last_t.insert(key, p.t);
                }
            }
            // No crossing: every point lies on the far side of the layer below,
            // i.e. its distance to the layer below is Delta and its column moved forward;
            // additionally no point of layer n is closer than Delta/2 to layer n-2.
            let by_slice = |s: usize| path.layers.iter().filter(move |l| l.slice == s);
            for l in path.layers.iter().filter(|l| l.slice >= 2) {
                for p in &l.points {
                    let closest = by_slice(l.slice - 2)
                        .flat_map(|b| b.points.iter())
                        .map(|q| (q.position - p.position).norm())
                        .fold(f64::MAX, f64::min);
                    assert!(
                        closest > 1.5 * d,
                        "{name} Delta {d}: slice {} comes within {closest} of slice {}",
                        l.slice,
                        l.slice - 2
                    );
                }
            }
        }
    }
}

/// Planar slices of the quarter torus leave the part at the top: open
/// layers, and the distance map handles them.
#[test]
fn planar_slices_of_the_quarter_torus_open_at_the_top() {
    let part = load_part("quarter-torus.toml");
    let path = run(&part, Strategy::Planar, 5.0, EndRule::WholeLayers, None);
    // Z = 5, 10, ... up to 60 < 65 = R + r (Z = 65 touches the top in one point: no layer).
    assert_eq!(path.num_slices(), 13);
    for l in &path.layers {
        for p in &l.points {
            assert!((p.position.z - 5.0 * l.slice as f64).abs() < 1e-9);
        }
    }
    let open: Vec<_> = path.layers.iter().filter(|l| !l.closed).collect();
    assert!(!open.is_empty());
    assert!(
        open.iter().all(|l| l.points[0].position.z > 35.0 - 1e-9),
        "opens above the inner top R - r = 35"
    );
    let m = distance_map(&path);
    assert!(
        m.overall.unwrap().min_rel > -1e-9,
        "planar layers are at least Delta apart"
    );
    // Overhang: the outer side drifts apart, up to 3x Delta near the top.
    assert!(m.overall.unwrap().max_rel > 1.0);
}

#[test]
fn seams_align_and_stagger() {
    let part = load_part("hemisphere.toml");
    let mut o = part.slice_options();
    o.max_layers = Some(5);
    let path = slice(&part.tube, &part.substrate, &o).unwrap();
    for w in path.layers.windows(2) {
        let end = w[0].points.last().unwrap().position;
        let start = w[1].points[0].position;
        let closest = w[1]
            .points
            .iter()
            .map(|p| (p.position - end).norm())
            .fold(f64::MAX, f64::min);
        assert!(((start - end).norm() - closest).abs() < 1e-12);
    }
    o.align_seams = false;
    o.stagger_rad = TAU / 10.0;
    let path = slice(&part.tube, &part.substrate, &o).unwrap();
    for l in &path.layers {
        let expect = (l.slice as f64 * TAU / 10.0).rem_euclid(TAU);
        assert!(
            (l.points[0].v - expect).abs() < 1e-9,
            "slice {}: starts at v = {}",
            l.slice,
            l.points[0].v
        );
    }
}

#[test]
fn bad_delta_and_missing_substrate_are_clear_errors() {
    let part = load_part("quarter-torus.toml");
    for d in [0.0, -1.0, f64::NAN] {
        let mut o = part.slice_options();
        o.delta_mm = d;
        let e = slice(&part.tube, &part.substrate, &o).unwrap_err();
        assert!(
            matches!(
                e,
                PathError::InvalidOption {
                    field: "delta_mm",
                    ..
                }
            ),
            "{e}"
        );
    }
    let mut o = part.slice_options();
    o.delta_mm = 500.0;
    let e = slice(&part.tube, &part.substrate, &o).unwrap_err();
    assert!(e.to_string().contains("larger than the part"), "{e}");
    let far = waam_slicer::geometry::Substrate::Plane {
        point: waam_slicer::math::Point3::new(0.0, 0.0, 500.0),
        normal: waam_slicer::math::Vector3::z_axis(),
    };
    let e = slice(&part.tube, &far, &part.slice_options()).unwrap_err();
    assert!(
        e.to_string().contains("substrate misses the tube at v = 0"),
        "{e}"
    );
    let _ = FRAC_PI_2;
}

/// The constant-distance method on a meshed substrate: the torus on a
/// cylinder given as an STL (2000 facets around) matches the analytic cylinder
/// substrate layer for layer, within the facets' sagitta.
#[test]
fn constant_distance_on_an_stl_substrate() {
    let part = load_part("torus-on-cylinder.toml");
    let mut tris = Vec::new();
    let n = 2000;
    for k in 0..n {
        let a0 = TAU * k as f64 / n as f64;
        let a1 = TAU * (k + 1) as f64 / n as f64;
        let p = |a: f64, y: f64| waam_slicer::math::Point3::new(32.0 * a.cos(), y, 32.0 * a.sin());
        tris.push([p(a0, -40.0), p(a1, -40.0), p(a1, 40.0)]);
        tris.push([p(a0, -40.0), p(a1, 40.0), p(a0, 40.0)]);
    }
    let mesh =
        waam_slicer::geometry::MeshSubstrate::from_triangles(&tris, "cylinder mesh").unwrap();
    let substrate = waam_slicer::geometry::Substrate::Mesh(Box::new(mesh));
    let mut o = part.slice_options();
    o.discretisation = waam_slicer::path::Discretisation::Points(120);
    let on_mesh = slice(&part.tube, &substrate, &o).unwrap();
    let analytic = slice(&part.tube, &part.substrate, &o).unwrap();
    let s = distance_map(&on_mesh).overall.unwrap();
    assert!(s.variation < 1e-3, "{s:?}");
    assert_eq!(on_mesh.num_slices(), analytic.num_slices());
    for (a, b) in on_mesh
        .layers
        .iter()
        .zip(&analytic.layers)
        .filter(|(a, b)| a.closed && b.closed)
    {
        for (p, q) in a.points.iter().zip(&b.points) {
            assert!((p.position - q.position).norm() < 1e-3, "slice {}", a.slice);
        }
    }
}
