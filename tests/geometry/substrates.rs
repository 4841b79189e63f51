//! First layer = tube ∩ substrate: the torus on the cylinder against the
//! closed form of thesis eq. 2.17–2.19, the flat plate, a meshed substrate
//! read from STL, and the errors when the substrate misses.

use crate::common::load_part;
use std::f64::consts::TAU;
use waam_slicer::geometry::{GeometryError, MeshSubstrate, Substrate};
use waam_slicer::math::{Point3, UnitVector3, Vector3};

/// u0(v) of eq. 2.19: where the torus (R, r) meets the cylinder R_c.
fn u0(v: f64) -> f64 {
    let (rr, r, rc) = (50.0_f64, 15.0_f64, 32.0_f64);
    let rho = rr + r * v.cos();
    ((rr * rr - rc * rc + rho * rho) / (2.0 * rr * rho)).acos()
}

#[test]
fn cylinder_first_layer_matches_eq_2_19() {
    let part = load_part("torus-on-cylinder.toml");
    let layer = part.substrate.first_layer(&part.tube, 500).unwrap();
    assert_eq!(layer.len(), 500);
    for p in &layer {
        assert!(
            (p.t - u0(p.v)).abs() < 1e-10,
            "v = {}: t = {} vs u0 = {}",
            p.v,
            p.t,
            u0(p.v)
        );
        let xz = Vector3::new(p.position.x, 0.0, p.position.z).norm();
        assert!((xz - 32.0).abs() < 1e-9);
    }
    // The inner side (v = pi) starts higher up the guide than the outer side.
    assert!(u0(std::f64::consts::PI) > u0(0.0));
}

#[test]
fn plate_first_layer_is_the_base_circle() {
    for name in [
        "hemisphere.toml",
        "nozzle.toml",
        "quarter-torus.toml",
        "elbow.toml",
        "general-tube.toml",
    ] {
        let part = load_part(name);
        for p in part.substrate.first_layer(&part.tube, 64).unwrap() {
            assert!(p.t.abs() < 1e-9, "{name}: t = {}", p.t);
            assert!(p.position.z.abs() < 1e-9);
        }
    }
}

#[test]
fn helix_first_layer_lies_on_the_plate() {
    let part = load_part("helix.toml");
    let layer = part.substrate.first_layer(&part.tube, 200).unwrap();
    for p in &layer {
        assert!(p.position.z.abs() < 1e-9);
        assert!(p.t > -0.6 && p.t < 0.6);
    }
    // A tilted section: the t's differ around the profile.
    let (lo, hi) = layer
        .iter()
        .fold((f64::MAX, f64::MIN), |(a, b), p| (a.min(p.t), b.max(p.t)));
    assert!(hi - lo > 0.2);
}

/// Binary STL of a cylinder about Y (radius rc, from y0 to y1), `n` facets around.
fn cylinder_stl(rc: f64, y0: f64, y1: f64, n: usize) -> Vec<u8> {
    let mut tris = Vec::new();
    for k in 0..n {
        let a0 = TAU * k as f64 / n as f64;
        let a1 = TAU * (k + 1) as f64 / n as f64;
        let p = |a: f64, y: f64| {
            stl_io::Vertex::new([(rc * a.cos()) as f32, y as f32, (rc * a.sin()) as f32])
        };
        let normal = stl_io::Normal::new([0.0, 0.0, 0.0]);
        tris.push(stl_io::Triangle {
            normal,
            vertices: [p(a0, y0), p(a1, y0), p(a1, y1)],
        });
        tris.push(stl_io::Triangle {
            normal,
            vertices: [p(a0, y0), p(a1, y1), p(a0, y1)],
        });
    }
    let mut out = Vec::new();
    stl_io::write_stl(&mut out, tris.iter()).unwrap();
    out
}

#[test]
fn mesh_substrate_from_stl_matches_the_analytic_cylinder() {
    let part = load_part("torus-on-cylinder.toml");
    let bytes = cylinder_stl(32.0, -40.0, 40.0, 2000);
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("cylinder.stl");
    std::fs::write(&file, &bytes).unwrap();
    let mesh = MeshSubstrate::from_stl_file(&file).unwrap();
    assert_eq!(mesh.num_triangles(), 4000);
    let sub = Substrate::Mesh(Box::new(mesh));
    let layer = sub.first_layer(&part.tube, 90).unwrap();
    // Facet sagitta 32 (1 - cos(pi/2000)) = 4e-5 mm, plus f32 rounding of the file.
    for p in &layer {
        assert!(
            (p.t - u0(p.v)).abs() < 5e-5,
            "v = {}: {} vs {}",
            p.v,
            p.t,
            u0(p.v)
        );
    }
}

#[test]
fn bad_stl_files_are_refused_with_their_reason() {
    let err = MeshSubstrate::from_stl_bytes(&[], "empty.stl").unwrap_err();
    assert!(
        err.to_string().contains("empty.stl") && err.to_string().contains("empty"),
        "{err}"
    );
    let mut bytes = cylinder_stl(32.0, -1.0, 1.0, 8);
    bytes[80] = 200; // announce 200 triangles, hold 16
    let err = MeshSubstrate::from_stl_bytes(&bytes, "count.stl").unwrap_err();
    assert!(err.to_string().contains("announces 200 triangles"), "{err}");
    let err =
        MeshSubstrate::from_stl_bytes(b"solid x\nfacet normal 0 0 1\n outer loop\n", "trunc.stl")
            .unwrap_err();
    assert!(err.to_string().contains("trunc.stl"), "{err}");
    let header_only = {
        let mut b = vec![0u8; 84];
        b[..3].copy_from_slice(b"abc");
        b
    };
    let err = MeshSubstrate::from_stl_bytes(&header_only, "zero.stl").unwrap_err();
    assert!(err.to_string().contains("no triangles"), "{err}");
}

#[test]
fn substrate_that_misses_the_tube_is_an_error_naming_v() {
    let part = load_part("hemisphere.toml");
    let above = Substrate::Plane {
        point: Point3::new(0.0, 0.0, -10.0),
        normal: UnitVector3::new_normalize(Vector3::z()),
    };
    match above.first_layer(&part.tube, 16) {
        Err(GeometryError::SubstrateMiss { v, .. }) => assert_eq!(v, 0.0),
        other => panic!("expected a miss, got {other:?}"),
    }
    let far = Substrate::Cylinder {
        axis_point: Point3::new(1000.0, 0.0, 0.0),
        axis: Vector3::y_axis(),
        radius: 5.0,
    };
    let err = far.first_layer(&part.tube, 16).unwrap_err();
    assert!(err.to_string().contains("v = 0.000000"), "{err}");
}
