//! The tube's ends (issue 47, deliverable 4): open, flat-capped,
//! ring-capped (two skins) and obliquely cut ends recognised in generated
//! meshes and in the shared meshes, each kind stated from the geometry the
//! mesh was made with; an end that is none of these refused naming the end
//! and its station.

use crate::gen;
use std::f64::consts::TAU;
use waam_slicer::fit::{EndKind, EndReport, FitError, TubeMesh};
use waam_slicer::math::Point3;
use waam_slicer::{Error, FitOptions, FittedPart, Part};

fn fit(v: Vec<Point3>, f: Vec<[u32; 3]>, name: &str) -> Result<FittedPart, Error> {
    Part::from_tube_mesh(&TubeMesh::new(v, f, name).unwrap(), &FitOptions::default())
}

fn data(name: &str) -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/fit/data")
        .join(name)
}

/// Checks an end's kind, cut and tilt (degrees, within `tol_deg`).
fn check(e: &EndReport, kind: EndKind, tilt_deg: f64, tol_deg: f64, what: &str) {
    assert_eq!(e.kind, kind, "{what}: {e:?}");
    assert!((e.tilt_deg - tilt_deg).abs() <= tol_deg, "{what}: {e:?}");
    assert_eq!(e.oblique, tilt_deg > 5.0, "{what}: {e:?}");
}

/// The ends are stations 0 and the last.
fn check_stations(p: &FittedPart) {
    let r = p.report();
    assert_eq!(r.start.station, 0);
    assert_eq!(r.end.station, r.stations.len() - 1);
    assert!((r.end.t_mm - r.stations[r.end.station].t_mm).abs() < 1e-9);
}

#[test]
fn an_open_pipe_has_two_open_square_ends() {
    let (v, f) = gen::mesh(&gen::straight(), 1.0, 0.0, 0.0, 0);
    let p = fit(v, f, "pipe.stl").unwrap();
    check(&p.report().start, EndKind::Open, 0.0, 0.5, "start");
    check(&p.report().end, EndKind::Open, 0.0, 0.5, "end");
    check_stations(&p);
}

/// A solid rod: a pipe closed by a flat disc at each end.
#[test]
fn a_rod_has_two_flat_capped_ends() {
    let around = 80;
    let (mut v, mut f) = gen::lofted(&gen::pipe_rings(around, 10.0, 0.0, 50.0, 1.0));
    let last = (v.len() - around) as u32;
    gen::fan_cap(&mut v, &mut f, 0, around as u32, Point3::origin());
    gen::fan_cap(
        &mut v,
        &mut f,
        last,
        around as u32,
        Point3::new(0.0, 0.0, 50.0),
    );
    let p = fit(v, f, "rod.stl").unwrap();
    check(&p.report().start, EndKind::FlatCapped, 0.0, 0.5, "start");
    check(&p.report().end, EndKind::FlatCapped, 0.0, 0.5, "end");
    assert!(p.report().start.capped && p.report().end.capped);
    check_stations(&p);
}

/// A wall of two skins (radii 9 and 11) joined at each end by a flat ring.
#[test]
fn a_closed_wall_has_two_ring_capped_ends() {
    let around = 80u32;
    let rings = |r| gen::pipe_rings(around as usize, r, 0.0, 50.0, 1.0);
    let (mut v, mut f) = gen::lofted(&rings(11.0));
    let (vi, fi) = gen::lofted(&rings(9.0));
    let base = v.len() as u32;
    v.extend(vi);
    f.extend(fi.into_iter().map(|t| t.map(|i| i + base)));
    for first in [0, base - around] {
        for j in 0..around {
            let (o0, o1) = (first + j, first + (j + 1) % around);
            f.push([o0, base + o0, o1]);
            f.push([o1, base + o0, base + o1]);
        }
    }
    let p = fit(v, f, "wall.stl").unwrap();
    check(&p.report().start, EndKind::RingCapped, 0.0, 0.5, "start");
    check(&p.report().end, EndKind::RingCapped, 0.0, 0.5, "end");
    check_stations(&p);
}

/// A pipe of radius 12 whose top is cut by a plane tilted 30 degrees from
/// its normal plane: the end's tilt, and its radius seen along the guide
/// (the rim is an ellipse of half-axes 12 and 12 / cos 30 in its plane).
#[test]
fn an_oblique_cut_is_named_with_its_tilt() {
    for tilt in [10.0, 30.0] {
        let (v, f) = gen::oblique_pipe(12.0, 60.0, tilt, 96, 1.0);
        let p = fit(v, f, "oblique.stl").unwrap();
        let r = p.report();
        check(&r.start, EndKind::Open, 0.0, 0.5, "start");
        check(&r.end, EndKind::Open, tilt, 0.5, "end");
        assert!((r.end.radius_mm - 12.0).abs() < 0.05, "{:?}", r.end);
        check_stations(&p);
    }
}

/// A pipe whose top rim is a saddle (z = 60 + 3 cos 2a): not a plane.
#[test]
fn a_saddle_cut_end_is_refused_naming_the_end_and_its_station() {
    let (v, f) = gen::saddle_pipe(12.0, 60.0, 3.0, 96, 1.0);
    let e = fit(v, f, "saddle.stl").unwrap_err();
    let msg = e.to_string();
    let Error::Fit(FitError::UnknownEnd {
        ref end,
        station,
        t_mm,
        ..
    }) = e
    else {
        panic!("{msg}")
    };
    assert_eq!(end, "end", "{msg}");
    // The rim's mean height is z = 60, 60 mm from the start along the axis.
    assert!(station > 20 && (t_mm - 60.0).abs() < 3.0, "{msg}");
    assert!(
        msg.starts_with("saddle.stl: the tube's end (station") && msg.contains("not flat"),
        "{msg}"
    );
}

/// A pipe closed by a hemisphere at z = 60: the closed end begins there.
#[test]
fn a_domed_end_is_refused_naming_the_end_and_where_it_begins() {
    let (v, f) = gen::domed_pipe(12.0, 60.0, 96, 1.0);
    let e = fit(v, f, "dome.stl").unwrap_err();
    let msg = e.to_string();
    let Error::Fit(FitError::UnknownEnd { ref end, t_mm, .. }) = e else {
        panic!("{msg}")
    };
    assert_eq!(end, "end", "{msg}");
    // Level sets 4 mm apart (a third of the radius): within one of z = 60,
    // plus the dome's first stretch that is still nearly as wide (0.97 r).
    assert!((t_mm - 60.0).abs() <= 4.0 + 0.25 * 12.0, "{msg}");
    assert!(msg.contains("not flat (a dome"), "{msg}");
}

/// A wall of two open skins (radii 11 and 9) whose inner skin only is
/// closed at the top by a flat disc: neither open nor a ring cap.
#[test]
fn a_wall_with_one_skin_capped_is_refused_naming_the_end() {
    let around = 80u32;
    let rings = |r| gen::pipe_rings(around as usize, r, 0.0, 50.0, 1.0);
    let (mut v, mut f) = gen::lofted(&rings(11.0));
    let (vi, fi) = gen::lofted(&rings(9.0));
    let base = v.len() as u32;
    v.extend(vi);
    f.extend(fi.into_iter().map(|t| t.map(|i| i + base)));
    let top = v.len() as u32 - around;
    gen::fan_cap(&mut v, &mut f, top, around, Point3::new(0.0, 0.0, 50.0));
    let msg = fit(v, f, "one-capped.stl").unwrap_err().to_string();
    assert!(
        msg.starts_with("one-capped.stl: the tube's end (station")
            && msg.contains("a flat face covers 0 % of skin"),
        "{msg}"
    );
}

/// The author's elbow: two skins joined at each end by a flat ring in a
/// plane through the bend's axis (normal to the bend: tilt 0).
#[test]
fn the_shared_elbow_has_two_ring_capped_square_ends() {
    let p = Part::from_mesh(data("breakout-coin-elbow-70.stl"), &FitOptions::default()).unwrap();
    check(&p.report().start, EndKind::RingCapped, 0.0, 1.0, "start");
    check(&p.report().end, EndKind::RingCapped, 0.0, 1.0, "end");
    check_stations(&p);
}

/// The coil: a solid wire whose ends are flat cuts in the plane through the
/// helix axis (SOURCES.md), tilted from the wire's normal plane by at most
/// the helix's pitch angle atan(1.0 / (2 pi 2.74)) = 3.3 degrees (its CAD
/// tool swept a circle drawn in that plane, so the rim is a circle there):
/// flat-capped, square.
#[test]
fn the_shared_coil_has_two_flat_capped_ends_tilted_by_its_pitch() {
    let p = Part::from_mesh(data("cal-helical-coil.stl"), &FitOptions::default()).unwrap();
    let pitch = (1.0 / (TAU * 2.74)).atan().to_degrees();
    for e in [&p.report().start, &p.report().end] {
        check(
            e,
            EndKind::FlatCapped,
            0.5 * pitch,
            0.5 * pitch + 0.2,
            "coil",
        );
    }
    check_stations(&p);
}
