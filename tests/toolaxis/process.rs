//! The process stage against hand computations (SPEC §5; thesis eq. 1.1–1.3,
//! tables 1.2 and 3.1).

use crate::common::load_part;
use waam_slicer::math::Point3;
use waam_slicer::path::{
    distance_map, slice, Discretisation, Layer, Path, PathPoint, SliceReport, StopReason, Strategy,
};
use waam_slicer::process::{
    plan_process, xiong_height_mm, xiong_width_mm, ProcessOptions, ProcessParameters, SpeedLaw,
    WindowSide,
};

/// Two square layers (side 10 mm, closed: 40 mm each), the second with the
/// given local distances at its four corners.
fn squares(deltas: [f64; 4]) -> Path {
    let square = |z: f64, d: Option<[f64; 4]>| Layer {
        slice: usize::from(z > 0.0),
        points: [(0.0, 0.0), (10.0, 0.0), (10.0, 10.0), (0.0, 10.0)]
            .iter()
            .enumerate()
            .map(|(i, &(x, y))| PathPoint {
                t: z,
                v: 0.0,
                position: Point3::new(x, y, z),
                delta: d.map(|d| d[i]),
            })
            .collect(),
        closed: true,
    };
    Path {
        strategy: Strategy::Constant,
        delta_mm: 5.0,
        layers: vec![square(0.0, None), square(5.0, Some(deltas))],
        report: SliceReport {
            stop: StopReason::ReachedEnd,
            ..SliceReport::default()
        },
        spiral: None,
    }
}

/// PLA, table 3.1: TS 36 cm/min = 6 mm/s, WFS 10 mm/s, Ø 1 mm.
/// By hand: eta = 10/6 = 1.666667; A_c = π · 1.666667 · 1² / 4 = 1.308997 mm²;
/// 1 mm high → 1.308997 mm wide. Two 40 mm layers at 6 mm/s: 13.333 s; wire
/// 133.333 mm; volume 133.333 · π/4 = 104.720 mm³; mass · 1.24 g/cm³ =
/// 0.129852 g; 2 arc starts.
#[test]
fn pla_numbers_match_hand_computation() {
    let pla = ProcessParameters::pla_table_3_1();
    assert!((pla.travel_speed_mm_s - 6.0).abs() < 1e-12);
    assert!((pla.eta(6.0) - 1.666_666_666_666_7).abs() < 1e-12);
    let bead = pla.bead_at(6.0);
    assert!((bead.area_mm2 - 1.308_996_938_995_747).abs() < 1e-12);
    assert!((bead.height_mm - 1.0).abs() < 1e-12);
    assert!((bead.width_mm - 1.308_996_938_995_747).abs() < 1e-12);
    let plan = plan_process(
        &squares([5.0; 4]),
        &pla,
        &ProcessOptions {
            speed_law: SpeedLaw::Constant,
            ..ProcessOptions::default()
        },
    )
    .unwrap();
    let e = plan.estimates;
    assert_eq!((e.layers, e.arc_starts), (2, 2));
    assert!((e.path_length_mm - 80.0).abs() < 1e-12);
    assert!((e.deposition_time_s - 13.333_333_333_333).abs() < 1e-9);
    assert!((e.wire_length_mm - 133.333_333_333_33).abs() < 1e-9);
    assert!((e.wire_volume_mm3 - 104.719_755_119_66).abs() < 1e-9);
    assert!((e.deposited_mass_g - 0.129_852_496_348_38).abs() < 1e-12);
    assert_eq!(plan.violation_count, 0);
}

/// The thesis's proportional law (§3.3.1) with the PLA window 3–12 mm/s and
/// Delta = 5: TS = 6 · 5 / delta. delta = 4 → 7.5 mm/s; 10 → 3 mm/s (the
/// bound, inside); 2 → 15 mm/s, clamped to 12 and reported; 12 → 2.5 mm/s,
/// clamped to 3 and reported. First layer: nominal 6 mm/s.
#[test]
fn proportional_speed_law_and_window() {
    let pla = ProcessParameters::pla_table_3_1();
    let plan = plan_process(
        &squares([4.0, 10.0, 2.0, 12.0]),
        &pla,
        &ProcessOptions::default(),
    )
    .unwrap();
    let ts: Vec<f64> = plan.points[1].iter().map(|p| p.travel_speed_mm_s).collect();
    for (got, want) in ts.iter().zip([7.5, 3.0, 12.0, 3.0]) {
        assert!((got - want).abs() < 1e-12, "{ts:?}");
    }
    assert!(plan.points[0].iter().all(|p| p.travel_speed_mm_s == 6.0));
    assert_eq!(plan.violation_count, 2);
    let v = &plan.violations;
    assert_eq!(
        (v[0].layer, v[0].point, v[0].side),
        (1, 2, WindowSide::AboveMax)
    );
    assert!((v[0].needed_mm_s.unwrap() - 15.0).abs() < 1e-12);
    assert_eq!(
        (v[1].layer, v[1].point, v[1].side),
        (1, 3, WindowSide::BelowMin)
    );
    // The bead height follows delta where the speed is inside the window.
    assert!((plan.points[1][0].bead.height_mm - 4.0 / 5.0).abs() < 1e-12);
    // Time: layer 0 at 6 mm/s (40/6 s); layer 1, each 10 mm side at the mean
    // of the inverse speeds of its ends.
    let inv = [1.0 / 7.5, 1.0 / 3.0, 1.0 / 12.0, 1.0 / 3.0];
    let t1: f64 = (0..4)
        .map(|i| 10.0 * 0.5 * (inv[i] + inv[(i + 1) % 4]))
        .sum();
    assert!((plan.estimates.deposition_time_s - (40.0 / 6.0 + t1)).abs() < 1e-12);
}

/// CMT steel from table 1.2 (ER70S-6, Ø 1.2 mm, WFS 4.8 m/min = 80 mm/s, TS
/// 50 cm/min = 8.333 mm/s, 18 V, stick-out 11 mm). By hand: eta = 9.6;
/// A_c = π · 9.6 · 1.44 / 4 = 10.857344 mm²; Xiong (eq. 1.2) H = −0.3514 +
/// 0.48318·4.8 − 0.08477·50 + 0.4028·18 + 0.01431·11 − 0.006146·4.8·50 +
/// 0.001168·50² − 0.012463·18² = 2.544122 mm; (eq. 1.3) L = 8.9462 +
/// 1.8088·4.8 − 0.3621·50 + 0.1739·18 − 0.5008·11 + 0.003556·50·11 +
/// 0.01667·18·11 − 0.1169·4.8² + 0.003137·50² = 7.550424 mm. Humping limit
/// 60 cm/min = 10 mm/s.
#[test]
fn cmt_steel_numbers_match_hand_computation() {
    let cmt = ProcessParameters::cmt_steel_er70s6();
    assert!((cmt.wire_feed_speed_mm_s - 80.0).abs() < 1e-12);
    assert!((cmt.travel_speed_mm_s - 50.0 / 6.0).abs() < 1e-12);
    assert!((cmt.eta(cmt.travel_speed_mm_s) - 9.6).abs() < 1e-12);
    assert!((cmt.travel_speed_max_mm_s - 10.0).abs() < 1e-12);
    let bead = cmt.bead_at(cmt.travel_speed_mm_s);
    assert!((bead.area_mm2 - 10.857_344_210_806_325).abs() < 1e-9);
    assert!((bead.height_mm - 2.544_122).abs() < 1e-9);
    assert!((bead.width_mm - 7.550_424).abs() < 1e-9);
    assert!((xiong_height_mm(4.8, 50.0, 18.0, 11.0) - 2.544_122).abs() < 1e-12);
    assert!((xiong_width_mm(4.8, 50.0, 18.0, 11.0) - 7.550_424).abs() < 1e-12);
    // TS 50 cm/min is outside Xiong's fitted 15–45 cm/min: flagged.
    assert!(!cmt.model_in_range(cmt.travel_speed_mm_s));
    // Inverting eq. 1.2 gives back the speed (decreasing branch).
    let h30 = xiong_height_mm(4.8, 30.0, 18.0, 11.0);
    let ts = cmt.travel_speed_for_height(h30).unwrap();
    assert!((ts - 30.0 * 10.0 / 60.0).abs() < 1e-9);
    // 1 m of bead: 120 s at 8.333 mm/s, 9600 mm of wire, 10857 mm³, 85.23 g.
    let mut path = squares([5.0; 4]);
    path.layers.truncate(1);
    let scale = 1000.0 / 40.0;
    for p in &mut path.layers[0].points {
        p.position.coords *= scale;
    }
    let e = plan_process(&path, &cmt, &ProcessOptions::default())
        .unwrap()
        .estimates;
    assert!((e.deposition_time_s - 120.0).abs() < 1e-9);
    assert!((e.wire_length_mm - 9600.0).abs() < 1e-9);
    assert!((e.deposited_mass_g - 10_857.344_210_806_325 * 7.85e-3).abs() < 1e-6);
}

/// A variable-distance path (quarter torus sliced perpendicular to the
/// guide, ±30 %) with the thesis's proportional law stays inside the PLA
/// window; following delta with Xiong's steel model at Delta = 3 mm cannot:
/// heights below the parabola's minimum (~2.5 mm) are unreachable and heights
/// above ~3.9 mm need less than 15 cm/min — both reported.
#[test]
fn speed_modulation_on_a_variable_distance_path() {
    let part = load_part("quarter-torus.toml");
    let mut o = part.slice_options();
    o.strategy = Strategy::Perpendicular;
    o.discretisation = Discretisation::Points(100);
    let path = slice(&part.tube, &part.substrate, &o).unwrap();
    let s = distance_map(&path).overall.unwrap();
    assert!(s.variation > 0.5);
    let pla = plan_process(
        &path,
        &ProcessParameters::pla_table_3_1(),
        &ProcessOptions::default(),
    )
    .unwrap();
    assert_eq!(pla.violation_count, 0);
    for (l, pl) in path.layers.iter().zip(&pla.points) {
        for (p, q) in l.points.iter().zip(pl) {
            if let Some(d) = p.delta {
                assert!((q.travel_speed_mm_s - 6.0 * 5.0 / d).abs() < 1e-9);
            }
        }
    }
    o.delta_mm = 3.0;
    let path3 = slice(&part.tube, &part.substrate, &o).unwrap();
    let steel = plan_process(
        &path3,
        &ProcessParameters::cmt_steel_er70s6(),
        &ProcessOptions {
            speed_law: SpeedLaw::BeadModel,
            ..ProcessOptions::default()
        },
    )
    .unwrap();
    let sides: Vec<WindowSide> = steel.violations.iter().map(|v| v.side).collect();
    assert!(sides.contains(&WindowSide::Unreachable));
    assert!(sides.contains(&WindowSide::BelowMin));
    assert!(steel.violation_count > 0 && steel.violation_count < path3.num_points());
    for l in &steel.points {
        for q in l {
            assert!((2.5 - 1e-12..=10.0 + 1e-12).contains(&q.travel_speed_mm_s));
        }
    }
}

/// Bad parameters name the field.
#[test]
fn invalid_parameters_name_the_field() {
    let mut p = ProcessParameters::pla_table_3_1();
    p.wire_diameter_mm = 0.0;
    let e = plan_process(&squares([5.0; 4]), &p, &ProcessOptions::default()).unwrap_err();
    assert!(e.to_string().contains("wire_diameter_mm"), "{e}");
    let mut p = ProcessParameters::cmt_steel_er70s6();
    p.travel_speed_mm_s = 20.0;
    let e = p.validate().unwrap_err();
    assert!(
        e.to_string().contains("outside the admissible window"),
        "{e}"
    );
    let e = plan_process(
        &squares([5.0, f64::NAN, 5.0, 5.0]),
        &ProcessParameters::pla_table_3_1(),
        &ProcessOptions::default(),
    )
    .unwrap_err();
    assert!(e.to_string().starts_with("layer 1, point 1"), "{e}");
    let e = ProcessOptions {
        reference_height_mm: Some(-1.0),
        ..ProcessOptions::default()
    }
    .validate()
    .unwrap_err();
    assert!(e.to_string().contains("reference_height_mm"), "{e}");
    // Serde round trip with units in the field names.
    let s = serde_json::to_string(&ProcessParameters::cmt_steel_er70s6()).unwrap();
    assert!(s.contains("wire_feed_speed_mm_s"));
    let back: ProcessParameters = serde_json::from_str(&s).unwrap();
    assert_eq!(back, ProcessParameters::cmt_steel_er70s6());
}
