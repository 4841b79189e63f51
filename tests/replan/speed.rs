//! Correction (a), speed: the elbow measured after layer 10 in the ROBOWAM
//! part-carried cell, +0.8 mm over a quarter of the circumference and
//! −0.5 mm elsewhere (issue 29's field).

use crate::common::part_path;
use crate::support::*;
use waam_slicer::replan::{replan_planned, ReplanOptions};
use waam_slicer::{plan_part, replan_part, Cell, Measured};

#[test]
fn speed_follows_the_error_and_the_top_returns_to_nominal_where_the_window_allows() {
    let part = part("elbow.toml");
    let cell_file = part_path("cells/robowam_part_carried.toml");
    let cell = Cell::read(&cell_file).unwrap();
    let opts = elbow_opts(120, 20);
    let sliced = nominal(&part, &opts);
    let field = Field {
        high: 0.8,
        low: -0.5,
    };
    let (scan, truth) = synthetic_scan(&sliced, K, &field, 7);
    let r = replan_part(&part, &cell, &Measured::Points(scan), K, &opts).unwrap();

    // the stray points are outliers, named in the summary
    assert_eq!(r.scan.outlier_count, STRAYS);
    let summary = serde_json::to_value(r.summary()).unwrap();
    assert_eq!(
        summary["replan"]["scan"]["outliers_listed"]
            .as_array()
            .unwrap()
            .len(),
        STRAYS
    );
    // the error read from the scan is the field (noise 0.05 mm averaged)
    for (i, (e, t)) in r.scan.error_mm.iter().zip(&truth).enumerate() {
        assert!((e - t).abs() < 0.06, "point {i}: read {e:.3}, true {t:.3}");
    }

    let delta = sliced.path.delta_mm;
    let p = &sliced.process;
    let (v_nom, v_min, v_max) = (
        p.travel_speed_mm_s,
        p.travel_speed_min_mm_s,
        p.travel_speed_max_mm_s,
    );
    let (h_lo, h_hi) = (
        law_height(v_max, v_nom, delta),
        law_height(v_min, v_nom, delta),
    );
    let first = &r.corrections[0];
    assert_eq!(first.layer, K + 1);
    let (lk, next) = (&sliced.path.layers[K], &sliced.path.layers[K + 1]);
    let frames = &sliced.axes.frames[K];
    // the true top of layer K (its points moved by the field along b)
    let true_top: Vec<_> = (0..lk.points.len())
        .map(|i| lk.points[i].position + frames[i].build * truth[i])
        .collect();
    let (mut fast_high, mut n_high, mut slow_low, mut n_low, mut inside) = (0.0, 0, 0.0, 0, 0);
    for (m, pt) in next.points.iter().enumerate() {
        let e = truth[column(&sliced, K, pt.v)];
        // the bead height from the true top to the nominal layer K+1: the
        // local distance, as the slicer defines a layer's height
        let needed = distance_to_closed(&pt.position, &true_top);
        let expected = law_speed(needed, v_nom, delta).clamp(v_min, v_max);
        let v = first.speed_mm_s[m];
        assert!(
            (v - expected).abs() < 0.03 * expected,
            "point {m}: speed {v:.3} mm/s, expected {expected:.3} (error {e:.3} mm)"
        );
        // the top predicted after layer K+1 with the speed planned
        let predicted = law_height(v, v_nom, delta) - needed;
        if needed > h_lo + 0.05 && needed < h_hi - 0.05 {
            assert!(
                predicted.abs() < 0.1,
                "point {m}: the top after layer {} is {predicted:+.3} mm off nominal",
                K + 1
            );
            inside += 1;
        }
        if e > 0.7 {
            // high wall: as fast as the window allows
            assert!((v - v_max).abs() < 1e-9, "point {m}: {v}");
            fast_high += v;
            n_high += 1;
        }
        if e < -0.45 {
            assert!(v < v_nom, "point {m}: {v} on a low wall");
            slow_low += v;
            n_low += 1;
        }
    }
    assert!(
        n_high > 10 && n_low > 40 && inside > 60,
        "{n_high} {n_low} {inside}"
    );
    assert!(fast_high / n_high as f64 > slow_low / n_low as f64 + 3.0);

    // where the window cannot absorb +0.8 mm the layers are rebuilt, each
    // within the window, until they rejoin the nominal layers: the high
    // side loses Delta - h_lo per layer
    let absorb = (0.8 / (delta - h_lo)).ceil() as usize;
    let rejoined = r.rejoined_at.expect("rejoins within the part");
    assert!(
        rejoined <= K + absorb + 1,
        "rejoined at {rejoined}, bound {}",
        K + absorb + 1
    );
    assert!(rejoined > K + 1, "+0.8 mm needs more than one layer");
    let path = &r.planned.sliced.path;
    let mut below: Vec<_> = (0..lk.points.len())
        .map(|i| lk.points[i].position + frames[i].build * truth[i])
        .collect();
    let mut last_max = f64::INFINITY;
    for c in &r.corrections {
        let layer = &path.layers[c.layer];
        if c.layer <= rejoined {
            assert!(c.corrected);
            let tol = if c.layer == K + 1 { 0.08 } else { 1e-6 };
            for (m, pt) in layer.points.iter().enumerate() {
                let h = distance_to_closed(&pt.position, &below);
                assert!(
                    h > h_lo - tol && h < h_hi + tol,
                    "layer {}, point {m}: bead {h:.3} mm outside [{h_lo:.3}, {h_hi:.3}]",
                    c.layer
                );
                assert!(c.speed_mm_s[m] >= v_min - 1e-9 && c.speed_mm_s[m] <= v_max + 1e-9);
            }
            let worst = c.error_after_mm.iter().copied().fold(0.0, f64::max);
            assert!(
                worst < last_max,
                "layer {}: {worst} not below {last_max}",
                c.layer
            );
            last_max = worst;
        } else {
            assert!(!c.corrected);
            for (a, b) in layer.points.iter().zip(&sliced.path.layers[c.layer].points) {
                assert_eq!(a.position, b.position);
            }
            assert!(c.speed_mm_s.iter().all(|v| *v == v_nom));
        }
        // the columns of layer K keep their order (the polyline below)
        let mut next_below = vec![below[0]; below.len()];
        for pt in &layer.points {
            next_below[column(&sliced, K, pt.v)] = pt.position;
        }
        below = next_below;
    }
    // the summary gives the error before and after per layer
    let layers = summary["replan"]["layers"].as_array().unwrap();
    let l1 = &layers[0];
    assert!(l1["error_before"]["max_mm"].as_f64().unwrap() > 0.7);
    assert!(l1["error_after"]["max_mm"].as_f64().unwrap() < 0.7);
    let rj = &layers[rejoined - K - 1];
    assert!(rj["error_after"]["max_abs_mm"].as_f64().unwrap() < 1e-9);

    // the joints of the replanned layers pass the independent FK check
    assert!(r.is_feasible(), "{:?}", r.planned.refusal());
    let text = std::fs::read_to_string(&cell_file).unwrap();
    let checked = fk_check_part_carried(&text, &r.planned);
    assert_eq!(checked, (20 - K - 1) * 120);

    // the program resumes the build: its beads are layers K+1.., the payload
    // holds the deposited layers, and it reads back clean
    let program = r.planned.program.as_ref().unwrap();
    let beads: Vec<usize> = program.bead_setup.iter().map(|b| b.layer).collect();
    assert_eq!(beads, (K + 1..20).collect::<Vec<_>>());
    let (mass, _) = r.resume_payload.unwrap();
    assert!(mass > cell.program.common.payload_base_kg + 0.05, "{mass}");
    let first_payload = program.bead_setup[0].payload.unwrap();
    assert!((first_payload.mass_kg - mass).abs() < 1e-12);
    let dir = tempfile::tempdir().unwrap();
    let files = r.write_programs(dir.path()).unwrap();
    assert!(files[0].ends_with("ELBOW_FROM_11.ls"), "{files:?}");
    let report = waam_slicer::check_program(&files[0], &cell).unwrap();
    assert!(report.problems.is_empty(), "{:?}", report.problems);

    // joints.csv: the corrected speeds and heights per point
    let mut buf = Vec::new();
    r.write_joints_csv(&mut buf).unwrap();
    let rows =
        waam_slicer::io::joints_csv::read_joints_csv(std::str::from_utf8(&buf).unwrap(), "j")
            .unwrap();
    assert_eq!(rows[0].layer, K + 1);
    for (row, v) in rows.iter().zip(first.speed_mm_s.iter()) {
        assert!((row.travel_speed_mm_s.unwrap() - v).abs() < 1e-6);
    }
    for (row, h) in rows.iter().zip(first.height_mm.iter()) {
        assert!((row.bead_height_mm.unwrap() - h).abs() < 1e-6);
    }

    // the same replan from the nominal plan reuses its unchanged layers and
    // gives the same speeds and joints (differential test)
    let planned = plan_part(&part, &cell, &opts).unwrap();
    let (scan, _) = synthetic_scan(&sliced, K, &field, 7);
    let fast = replan_planned(
        &part,
        &planned,
        &Measured::Points(scan),
        K,
        &ReplanOptions::default(),
    )
    .unwrap();
    assert_eq!(fast.corrections, r.corrections);
    for (a, b) in fast.planned.plan.layers.iter().zip(&r.planned.plan.layers) {
        for (p, q) in a.points.iter().zip(&b.points) {
            let (p, q) = (p.joints.unwrap(), q.joints.unwrap());
            assert!(p.iter().zip(&q).all(|(x, y)| (x - y).abs() < 1e-9));
        }
    }
}

#[test]
fn height_errors_per_point_give_the_speeds_of_the_points() {
    let part = part("elbow.toml");
    let cell = Cell::read(part_path("cells/robowam_part_carried.toml")).unwrap();
    let opts = elbow_opts(120, 14);
    let sliced = nominal(&part, &opts);
    let field = Field {
        high: 0.8,
        low: -0.5,
    };
    let (scan, _) = synthetic_scan(&sliced, K, &field, 11);
    let from_points = replan_part(&part, &cell, &Measured::Points(scan), K, &opts).unwrap();
    // every fifth point missing: interpolated along the layer
    let rows: Vec<_> = sliced.path.layers[K]
        .points
        .iter()
        .enumerate()
        .filter(|(m, _)| m % 5 != 3)
        .map(|(m, p)| waam_slicer::replan::HeightError {
            layer: K,
            point: m,
            dh_mm: field.at(p.v),
        })
        .collect();
    let from_errors = replan_part(&part, &cell, &Measured::HeightErrors(rows), K, &opts).unwrap();
    assert_eq!(from_errors.scan.outlier_count, 0);
    let (a, b) = (&from_points.corrections[0], &from_errors.corrections[0]);
    for (m, (x, y)) in a.speed_mm_s.iter().zip(&b.speed_mm_s).enumerate() {
        assert!((x - y).abs() < 0.05 * y, "point {m}: {x} vs {y}");
    }
}
