//! Unit tests of the process stage: regressions, inversions, validation.

use super::bead::{xiong_travel_speed_cm_min, XIONG_RANGE};
use super::*;

#[test]
fn area_is_volume_conservation() {
    // A_c · TS = π d² / 4 · WFS.
    let (d, wfs, ts) = (1.2, 80.0, 7.0);
    assert!(
        (bead_area_mm2(d, wfs, ts) * ts - std::f64::consts::PI * d * d / 4.0 * wfs).abs() < 1e-12
    );
}

#[test]
fn xiong_inversion_round_trips_on_the_fitted_range() {
    for ts in [15.0, 25.0, 35.0, 45.0] {
        let h = xiong_height_mm(4.0, ts, 19.0, 12.0);
        let back = xiong_travel_speed_cm_min(4.0, 19.0, 12.0, h).unwrap();
        assert!((back - ts).abs() < 1e-9, "{ts} -> {back}");
    }
    // Below the parabola's minimum: no speed.
    assert!(xiong_travel_speed_cm_min(4.0, 19.0, 12.0, 0.5).is_none());
    assert!(XIONG_RANGE.contains(4.0, 30.0, 19.0, 12.0));
    assert!(!XIONG_RANGE.contains(4.0, 60.0, 19.0, 12.0));
}

#[test]
fn constant_width_inversion() {
    let pla = ProcessParameters::pla_table_3_1();
    let ts = pla.travel_speed_for_height(0.5).unwrap();
    assert!((pla.bead_at(ts).height_mm - 0.5).abs() < 1e-12);
    assert!((ts - 12.0).abs() < 1e-12);
    assert!(pla.travel_speed_for_height(0.0).is_none());
}

#[test]
fn presets_are_valid() {
    for p in [
        ProcessParameters::pla_table_3_1(),
        ProcessParameters::cmt_steel_er70s6(),
        ProcessParameters::mag_steel_xiong(),
        ProcessParameters::default(),
    ] {
        p.validate()
            .unwrap_or_else(|e| panic!("{}: {e}", p.material));
    }
    assert!(ProcessParameters::mag_steel_xiong().model_in_range(5.0));
}

#[test]
fn invalid_fields_are_named() {
    let base = ProcessParameters::cmt_steel_er70s6();
    let cases: Vec<(&str, ProcessParameters)> = vec![
        (
            "wire_feed_speed_mm_s",
            ProcessParameters {
                wire_feed_speed_mm_s: f64::NAN,
                ..base.clone()
            },
        ),
        (
            "density_kg_m3",
            ProcessParameters {
                density_kg_m3: -1.0,
                ..base.clone()
            },
        ),
        (
            "voltage_v",
            ProcessParameters {
                voltage_v: -1.0,
                ..base.clone()
            },
        ),
        (
            "travel_speed_min_mm_s",
            ProcessParameters {
                travel_speed_min_mm_s: 20.0,
                ..base.clone()
            },
        ),
        (
            "bead_model.width_mm",
            ProcessParameters {
                bead_model: BeadModel::ConstantWidth { width_mm: 0.0 },
                ..base.clone()
            },
        ),
    ];
    for (field, p) in cases {
        let e = p.validate().unwrap_err();
        assert!(e.to_string().contains(field), "{field}: {e}");
    }
}
