//! `FitOptions::units` and `waam fit --units`: a mesh in metres fits as the
//! same mesh in mm, every length of the fit in mm; a size that suggests
//! another unit is named.

use crate::common::waam;
use crate::gen;
use waam_slicer::fit::{FitError, TubeMesh, Units};
use waam_slicer::{Error, FitOptions, Part};

#[test]
fn a_mesh_in_metres_fits_as_the_same_mesh_in_mm() {
    let truth = gen::s_bend();
    let (v, f) = gen::mesh(&truth, 1.5, 0.0, 0.0, 5);
    let mm = TubeMesh::new(v.clone(), f.clone(), "s-bend-mm.stl").unwrap();
    let m = TubeMesh::new(gen::in_metres(&v), f, "s-bend-m.stl").unwrap();
    let a = Part::from_tube_mesh(&mm, &FitOptions::default()).unwrap();
    let opts = FitOptions {
        units: Units::M,
        ..FitOptions::default()
    };
    let b = Part::from_tube_mesh(&m, &opts).unwrap();
    let (ra, rb) = (a.report(), b.report());
    assert_eq!(rb.units, Units::M);
    assert!(rb.warnings.is_empty(), "{:?}", rb.warnings);
    assert!((ra.length_mm - rb.length_mm).abs() < 1e-3, "{ra:?} {rb:?}");
    assert!((ra.radius_max_mm - rb.radius_max_mm).abs() < 1e-3);
    assert!((ra.rms_mm - rb.rms_mm).abs() < 1e-3);
    // The stored mesh (for the report page) is in mm too.
    assert!((b.mesh.vertices[7] - mm.vertices[7]).norm() < 1e-9);
    for (p, q) in a.fit.guide_points.iter().zip(&b.fit.guide_points) {
        assert!((p - q).norm() < 1e-3, "{p} {q}");
    }
}

#[test]
fn a_mesh_in_metres_read_as_mm_names_the_likely_unit() {
    let truth = gen::straight();
    let (v, f) = gen::mesh(&truth, 1.0, 0.0, 0.0, 6);
    let m = TubeMesh::new(gen::in_metres(&v), f, "pipe.stl").unwrap();
    // A 0.16 mm pipe of radius 0.015 mm: refused or fitted, the unit is named.
    match Part::from_tube_mesh(&m, &FitOptions::default()) {
        Ok(fitted) => {
            let w = &fitted.report().warnings;
            assert!(
                w.len() == 1 && w[0].contains("looks like a mesh in m "),
                "{w:?}"
            );
        }
        Err(e) => {
            let text = e.to_string();
            assert!(matches!(e, Error::Fit(FitError::Units { .. })), "{text}");
            assert!(
                text.contains("pipe.stl") && text.contains("looks like a mesh in m "),
                "{text}"
            );
        }
    }
}

#[test]
fn a_mesh_in_mm_read_as_metres_or_too_large_in_mm_is_named() {
    let truth = gen::straight();
    let (v, f) = gen::mesh(&truth, 1.0, 0.0, 0.0, 6);
    // 12 000 mm long: read as metres it looks like mm; read as mm it is
    // larger than any part.
    let big: Vec<_> = v.iter().map(|p| p * 150.0).collect();
    let mesh = TubeMesh::new(big, f, "big.stl").unwrap();
    for (units, expected) in [
        (Units::M, "looks like a mesh in mm "),
        (Units::Mm, "unit smaller than mm"),
    ] {
        let opts = FitOptions {
            units,
            max_rms_mm: 1e6,
            ..FitOptions::default()
        };
        match Part::from_tube_mesh(&mesh, &opts) {
            Ok(fitted) => {
                let w = &fitted.report().warnings;
                assert!(w.len() == 1 && w[0].contains(expected), "{units}: {w:?}");
            }
            Err(e) => assert!(e.to_string().contains(expected), "{units}: {e}"),
        }
    }
}

#[test]
fn units_with_a_substrate_mesh_are_refused_naming_the_field() {
    let opts = FitOptions {
        units: Units::In,
        substrate: Some("plate.stl".into()),
        ..FitOptions::default()
    };
    let e = opts.validate("tube.stl").unwrap_err();
    assert!(e.to_string().contains("`units`"), "{e}");
}

#[test]
fn cli_units_m_takes_start_in_mm_and_writes_mm() {
    let dir = tempfile::tempdir().unwrap();
    let truth = gen::s_bend();
    let (v, f) = gen::mesh(&truth, 1.5, 0.0, 0.0, 2);
    let stl = dir.path().join("s-bend-m.stl");
    std::fs::write(&stl, gen::binary_stl(&gen::in_metres(&v), &f)).unwrap();
    // The far end's centre, in mm: the start end chosen by a point in mm.
    let end = (truth.centre)(truth.length);
    let out = dir.path().join("fit");
    let done = waam()
        .args(["--quiet", "fit"])
        .arg(&stl)
        .arg("--out")
        .arg(&out)
        .args(["--units", "m", "--start"])
        .arg(format!("{},{},{}", end.x, end.y, end.z))
        .output()
        .unwrap();
    assert!(
        done.status.success(),
        "{}",
        String::from_utf8_lossy(&done.stderr)
    );
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("fit.json")).unwrap()).unwrap();
    assert_eq!(report["units"], "m");
    let start: Vec<f64> = report["start"]["centre_mm"]
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect();
    let d = ((start[0] - end.x).powi(2) + (start[1] - end.y).powi(2) + (start[2] - end.z).powi(2))
        .sqrt();
    assert!(d < 0.5, "start end {start:?}, expected {end}");
    assert!(
        (report["length_mm"].as_f64().unwrap() - truth.length).abs() < 1.0,
        "{report}"
    );
    // A unit that is not one is refused naming it.
    let done = waam()
        .args(["--quiet", "fit"])
        .arg(&stl)
        .args(["--units", "furlong"])
        .output()
        .unwrap();
    assert!(!done.status.success());
    assert!(String::from_utf8_lossy(&done.stderr).contains("furlong"));
}

/// A mesh over 10 km across (after its unit) is refused naming the file,
/// its size and the limit, and the likely unit: the fuzzer's mesh 1.2e29 mm
/// across had made the guide's spline overflow to NaN and parry's polyline
/// projection panic.
#[test]
fn a_mesh_larger_than_any_cell_is_refused_not_a_panic() {
    let truth = gen::straight();
    let (v, f) = gen::mesh(&truth, 1.0, 0.0, 0.0, 6);
    for scale in [2e5, 1e27] {
        let huge: Vec<_> = v.iter().map(|p| p * scale).collect();
        let mesh = TubeMesh::new(huge, f.clone(), "huge.stl").unwrap();
        let e = Part::from_tube_mesh(&mesh, &FitOptions::default())
            .err()
            .unwrap_or_else(|| panic!("{scale}: a mesh that large fitted"));
        let text = e.to_string();
        assert!(
            text.contains("huge.stl")
                && text.contains("over the 10000000 mm")
                && text.contains("unit smaller than mm"),
            "{scale}: {text}"
        );
    }
}
