//! Meshes made elsewhere (`tests/fit/data/`, README there): the helical
//! coil as exported, by its residual; a nozzle built from its author's
//! exported wall profile as an untidy export in metres, against that profile.

use crate::gen;
use std::f64::consts::TAU;
use waam_slicer::fit::{EndKind, TubeMesh, Units};
use waam_slicer::math::{Point3, Vector3};
use waam_slicer::{FitOptions, Part};

fn data(name: &str) -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/fit/data")
        .join(name)
}

#[test]
fn the_helical_coil_fits_within_five_hundredths_rms() {
    let fitted = Part::from_mesh(data("cal-helical-coil.stl"), &FitOptions::default()).unwrap();
    let r = fitted.report();
    assert!(r.rms_mm <= 0.05, "{} mm RMS", r.rms_mm);
    // Wire radius about 0.31 mm, centreline about 86 mm long (SOURCES.md).
    assert!((r.radius_min_mm - 0.31).abs() < 0.02, "{}", r.radius_min_mm);
    assert!(r.length_mm > 70.0 && r.length_mm < 90.0, "{}", r.length_mm);
}

/// The author's wall profile: (x, radius) in mm.
fn nozzle_profile() -> Vec<(f64, f64)> {
    let text = std::fs::read_to_string(data("rao-nozzle.profile.csv")).unwrap();
    text.lines()
        .skip(1)
        .map(|l| {
            let mut it = l
                .split(',')
                .map(|x| x.trim().parse::<f64>().unwrap() * 1000.0);
            (it.next().unwrap(), it.next().unwrap())
        })
        .collect()
}

fn radius_at(profile: &[(f64, f64)], x: f64) -> Option<(f64, f64)> {
    let i = profile
        .windows(2)
        .position(|w| w[0].0 <= x && x <= w[1].0)?;
    let ((x0, r0), (x1, r1)) = (profile[i], profile[i + 1]);
    let slope = (r1 - r0) / (x1 - x0);
    Some((r0 + slope * (x - x0), slope))
}

#[test]
fn a_nozzle_exported_untidily_in_metres_lies_on_its_authors_profile() {
    let profile = nozzle_profile();
    let around = 65;
    // Rings at the author's profile points, the axis along x, in metres.
    let mut v = Vec::new();
    for &(x, r) in &profile {
        for j in 0..around {
            let a = TAU * j as f64 / around as f64;
            v.push(Point3::new(x, r * a.cos(), r * a.sin()) / 1000.0);
        }
    }
    let id = |i: usize, j: usize| (i * around + j % around) as u32;
    let mut f = Vec::new();
    for i in 0..profile.len() - 1 {
        for j in 0..around {
            // Wound so that the normals point inward, as the author's export.
            f.push([id(i, j), id(i + 1, j), id(i, j + 1)]);
            f.push([id(i, j + 1), id(i + 1, j), id(i + 1, j + 1)]);
        }
    }
    let (v, f) = gen::untidy(&v, &f, around, Point3::new(0.2, 0.2, 0.2), 1e-4);
    let mesh = TubeMesh::new(v, f, "rao-nozzle-like.stl").unwrap();
    let opts = FitOptions {
        units: Units::M,
        ..FitOptions::default()
    };
    let fitted = Part::from_tube_mesh(&mesh, &opts).unwrap();
    let rep = fitted.report();
    assert_eq!(
        rep.repair.welded_vertices,
        profile.len(),
        "{:?}",
        rep.repair
    );
    assert_eq!(rep.repair.left_out.len(), 1, "{:?}", rep.repair);
    let stray = rep.repair.left_out[0].centroid_mm;
    assert!((stray[0] - 200.0).abs() < 1.0, "{stray:?}");
    assert!(rep.warnings.is_empty(), "{:?}", rep.warnings);
    // A surface of revolution cut at two x: two open square ends.
    for e in [&rep.start, &rep.end] {
        assert!(e.kind == EndKind::Open && e.tilt_deg < 1.0, "{e:?}");
    }
    let (rms, max, n) = against_profile(&fitted.fit, &profile);
    eprintln!("nozzle against its profile: {rms:.4} mm RMS, {max:.4} mm at most, {n} points; fit residual {:.4} mm RMS", rep.rms_mm);
    assert!(n > 10_000, "{n}");
    assert!(rms <= 0.1 && max <= 0.3, "{rms} mm RMS, {max} mm at most");
}

/// The fitted surface against the author's profile: 400 stations, 36
/// points around, each one's distance to the profile's surface of
/// revolution (normal to the profile): RMS and largest (mm), and how many.
fn against_profile(fit: &waam_slicer::fit::TubeFit, profile: &[(f64, f64)]) -> (f64, f64, usize) {
    let guide = fit.guide();
    let (mut sum, mut n, mut max) = (0.0, 0usize, 0.0_f64);
    for i in 0..=400 {
        let t = fit.t_min + (fit.t_max - fit.t_min) * i as f64 / 400.0;
        let c = waam_slicer::geometry::guide::GuideCurve::point(&guide, t);
        for k in 0..36 {
            let a = TAU * k as f64 / 36.0;
            let p = c + Vector3::new(0.0, a.cos(), a.sin()) * fit.radius(t);
            let Some((r, slope)) = radius_at(profile, p.x) else {
                continue;
            };
            let d = (p.y.hypot(p.z) - r).abs() / (1.0 + slope * slope).sqrt();
            sum += d * d;
            n += 1;
            max = max.max(d);
        }
    }
    ((sum / n.max(1) as f64).sqrt(), max, n)
}

/// The author's own nozzle mesh (not in the repository: 3.9 MB), from the
/// shared folder (`$WAAM_REAL_MESHES`, or `../shared/real-meshes` or
/// `../../shared/real-meshes` from the clone):
/// `cargo test --test fit -- --ignored real_nozzle`.
#[test]
#[ignore]
fn real_nozzle_from_the_shared_folder_lies_on_its_authors_profile() {
    // `$WAAM_REAL_MESHES`, or `shared/real-meshes` next to the clone or
    // next to its worktrees' folder.
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let path = std::env::var_os("WAAM_REAL_MESHES")
        .map(std::path::PathBuf::from)
        .into_iter()
        .chain([
            root.join("../shared/real-meshes"),
            root.join("../../shared/real-meshes"),
        ])
        .map(|d| d.join("rao-nozzle.stl"))
        .find(|p| p.exists())
        .expect("rao-nozzle.stl: set WAAM_REAL_MESHES to the shared real-meshes folder");
    let opts = FitOptions {
        units: Units::M,
        ..FitOptions::default()
    };
    let fitted = Part::from_mesh(&path, &opts).unwrap();
    // Both ends open (SOURCES.md: two boundary loops of 65 vertices), at
    // x = -21.21 and 89.41 mm, normal to the axis.
    for e in [&fitted.report().start, &fitted.report().end] {
        assert!(e.kind == EndKind::Open && e.tilt_deg < 1.0, "{e:?}");
    }
    let (rms, max, n) = against_profile(&fitted.fit, &nozzle_profile());
    eprintln!("real nozzle against its profile: {rms:.4} mm RMS, {max:.4} mm at most, {n} points; fit residual {:.4} mm RMS, repair {:?}", fitted.report().rms_mm, fitted.report().repair);
    assert!(rms <= 0.1 && max <= 0.3, "{rms} mm RMS, {max} mm at most");
}

#[test]
fn an_untidy_export_fits_as_the_clean_mesh() {
    let truth = gen::elbow();
    let around = 64;
    let (v, f) = gen::mesh_around(&truth, 1.0, around, 0.0, 0.0, 9);
    let clean = Part::from_tube_mesh(
        &TubeMesh::new(v.clone(), f.clone(), "clean.stl").unwrap(),
        &FitOptions::default(),
    )
    .unwrap();
    let (uv, uf) = gen::untidy(&v, &f, around, Point3::new(300.0, 0.0, 0.0), 0.1);
    let n_read = uv.len();
    let untidy = Part::from_tube_mesh(
        &TubeMesh::new(uv, uf, "untidy.stl").unwrap(),
        &FitOptions::default(),
    )
    .unwrap();
    let rep = untidy.report();
    assert_eq!(
        rep.repair.welded_vertices,
        v.len() / around,
        "{:?}",
        rep.repair
    );
    assert_eq!(rep.repair.left_out.len(), 1, "{:?}", rep.repair);
    assert_eq!(rep.repair.left_out[0].triangles, 1);
    // One distance per vertex read; none for the stray piece's.
    assert_eq!(untidy.fit.vertex_distance_mm.len(), n_read);
    assert!(untidy.fit.vertex_distance_mm[n_read - 1].is_none());
    assert!(
        (rep.rms_mm - clean.report().rms_mm).abs() < 1e-6,
        "{} {}",
        rep.rms_mm,
        clean.report().rms_mm
    );
    for (p, q) in clean.fit.guide_points.iter().zip(&untidy.fit.guide_points) {
        assert!((p - q).norm() < 1e-6, "{p} {q}");
    }
}

/// The author's elbow (`slide.scad`): a ring of radii 25.1 and 26.5 about a
/// centre circle of radius 56.5 in the z = 0 plane, about the z axis, swept
/// from 0 to 70 degrees. A point's distance from the centre circle (mm).
fn from_elbow_circle(p: &Point3) -> f64 {
    (p.x.hypot(p.y) - 56.5).hypot(p.z)
}

#[test]
fn the_coarse_two_skin_elbow_lies_on_its_authors_torus() {
    let fitted =
        Part::from_mesh(data("breakout-coin-elbow-70.stl"), &FitOptions::default()).unwrap();
    let fit = &fitted.fit;
    let rep = fitted.report();
    assert_eq!(rep.skins, 2);
    // The guide runs along the author's centre circle, from 0 to 70 degrees.
    let guide = fit.guide();
    let (mut g2, mut gmax, mut m) = (0.0, 0.0_f64, 0);
    // The fitted skins (the mid-surface's radius -/+ half the wall) against
    // the author's radii, 36 points around at 200 stations.
    let (mut s2, mut smax, mut n) = (0.0, 0.0_f64, 0);
    for i in 0..=200 {
        let t = fit.t_min + (fit.t_max - fit.t_min) * f64::from(i) / 200.0;
        let c = waam_slicer::geometry::guide::GuideCurve::point(&guide, t);
        let d = (c.x.hypot(c.y) - 56.5).hypot(c.z);
        g2 += d * d;
        gmax = gmax.max(d);
        m += 1;
        let tan = waam_slicer::geometry::guide::GuideCurve::d1(&guide, t).normalize();
        let e1 = tan.cross(&Vector3::z()).normalize();
        let e2 = tan.cross(&e1);
        let half = 0.5 * fit.wall_thickness(t).unwrap();
        for (r, truth) in [(fit.radius(t) - half, 25.1), (fit.radius(t) + half, 26.5)] {
            for k in 0..36 {
                let a = TAU * f64::from(k) / 36.0;
                let p = c + (e1 * a.cos() + e2 * a.sin()) * r;
                let d = from_elbow_circle(&p) - truth;
                s2 += d * d;
                smax = smax.max(d.abs());
                n += 1;
            }
        }
    }
    let ends = [fit.t_min, fit.t_max].map(|t| {
        let c = waam_slicer::geometry::guide::GuideCurve::point(&guide, t);
        c.y.atan2(c.x).to_degrees()
    });
    let (g, s) = ((g2 / f64::from(m)).sqrt(), (s2 / f64::from(n)).sqrt());
    eprintln!(
        "elbow: guide {g:.4} mm RMS {gmax:.4} max; skins {s:.4} mm RMS {smax:.4} max; ends at {ends:?} degrees; fit residual {:.4} mm RMS; {} iterations",
        rep.rms_mm, rep.iterations
    );
    // Either end may be the start (both lie at z = 0).
    let (lo, hi) = (ends[0].min(ends[1]), ends[0].max(ends[1]));
    assert!(lo.abs() < 0.5 && (hi - 70.0).abs() < 0.5, "{ends:?}");
    assert!(s <= 0.1 && smax <= 0.3, "{s} mm RMS, {smax} mm at most");
    // The sliced points lie on the author's mid-surface (radius 25.8).
    let sliced = waam_slicer::slice_part(&fitted.part).unwrap();
    let (mut p2, mut pmax, mut np) = (0.0, 0.0_f64, 0);
    for l in &sliced.path.layers {
        for p in &l.points {
            let d = from_elbow_circle(&p.position) - 25.8;
            p2 += d * d;
            pmax = pmax.max(d.abs());
            np += 1;
        }
    }
    let p = (p2 / np as f64).sqrt();
    eprintln!(
        "elbow sliced: {np} points {p:.4} mm RMS {pmax:.4} max from the author's mid-surface"
    );
    assert!(
        np > 1000 && p <= 0.1 && pmax <= 0.3,
        "{np} points, {p} mm RMS, {pmax} mm at most"
    );
}
