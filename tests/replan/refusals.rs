//! A scan of the wrong layer or of the wrong part is refused, the message
//! naming the distance that gave it away; bad scan files name the line.

use crate::support::*;
use waam_slicer::math::Point3;
use waam_slicer::replan::{HeightError, ReplanError};
use waam_slicer::{replan_part, Cell, Error, ErrorKind, Measured};

fn refusal(measured: &Measured) -> (ReplanError, String) {
    let part = part("elbow.toml");
    let cell = Cell::read(crate::common::part_path("cells/robowam_part_carried.toml")).unwrap();
    let opts = elbow_opts(96, 14);
    let e = replan_part(&part, &cell, measured, K, &opts).unwrap_err();
    assert_eq!(e.kind(), ErrorKind::Input, "{e}");
    let m = e.to_string();
    match e {
        Error::Replan(r) => (r, m),
        other => panic!("not a replan refusal: {other}"),
    }
}

fn layer_points(l: usize) -> Vec<Point3> {
    let part = part("elbow.toml");
    let sliced = nominal(&part, &elbow_opts(96, 14));
    sliced.path.layers[l]
        .points
        .iter()
        .map(|p| p.position)
        .collect()
}

#[test]
fn a_scan_of_the_next_layer_is_refused_naming_the_median_error_and_the_layer() {
    let (e, m) = refusal(&Measured::Points(layer_points(K + 1)));
    assert!(matches!(e, ReplanError::WrongLayer { .. }), "{m}");
    assert!(m.contains("+2.000 mm") && m.contains("layer 11"), "{m}");
}

#[test]
fn a_scan_two_layers_below_is_refused() {
    let (e, m) = refusal(&Measured::Points(layer_points(K - 2)));
    assert!(matches!(e, ReplanError::WrongLayer { .. }), "{m}");
    assert!(m.contains("-4.000 mm") && m.contains("layer 8"), "{m}");
}

/// A ring of radius `r` about the elbow's first leg at layer K's height.
fn ring(r: f64) -> Vec<Point3> {
    (0..300)
        .map(|i| {
            let a = std::f64::consts::TAU * i as f64 / 300.0;
            Point3::new(r * a.cos(), r * a.sin(), 2.0 * K as f64)
        })
        .collect()
}

#[test]
fn a_scan_of_another_part_is_refused_naming_the_distance() {
    // a tube of radius 30 instead of 20: every point 10 mm off
    let (e, m) = refusal(&Measured::Points(ring(30.0)));
    assert!(matches!(e, ReplanError::WrongPart { .. }), "{m}");
    assert!(
        m.contains("300 of 300") && m.contains("median distance 10.0"),
        "{m}"
    );
    // radius 23: within the outlier distance, but 3 mm beside the wall
    let (e, m) = refusal(&Measured::Points(ring(23.0)));
    assert!(matches!(e, ReplanError::WallOffset { .. }), "{m}");
    assert!(m.contains("+3.0"), "{m}");
}

#[test]
fn height_errors_of_another_layer_or_point_and_partial_scans_are_refused() {
    let rows = |layer, point| {
        Measured::HeightErrors(vec![HeightError {
            layer,
            point,
            dh_mm: 0.1,
        }])
    };
    let (e, m) = refusal(&rows(K - 1, 0));
    assert!(matches!(e, ReplanError::ScanOfAnotherLayer { .. }), "{m}");
    assert!(m.contains("layer 9") && m.contains("after layer 10"), "{m}");
    let (_, m) = refusal(&rows(K, 96));
    assert!(m.contains("point 96") && m.contains("96 points"), "{m}");
    // a quarter of the layer seen
    let pts = layer_points(K);
    let (e, m) = refusal(&Measured::Points(pts[..24].to_vec()));
    assert!(matches!(e, ReplanError::TooLittleCoverage { .. }), "{m}");
    // nothing left after the last layer
    let (e, m) = {
        let part = part("elbow.toml");
        let cell = Cell::read(crate::common::part_path("cells/robowam_part_carried.toml")).unwrap();
        let e = replan_part(
            &part,
            &cell,
            &Measured::Points(pts),
            13,
            &elbow_opts(96, 14),
        )
        .unwrap_err();
        let m = e.to_string();
        (e, m)
    };
    assert!(
        matches!(e, Error::Replan(ReplanError::NothingToReplan { .. })),
        "{m}"
    );
}
