//! Correction (b), geometry: errors of 2 mm, more than the speed window can
//! absorb in one layer. Every rebuilt layer stays within the window (bead
//! heights measured here against the layer below, brute force) and the
//! nominal layers are rejoined as soon as the window allows: within three
//! layers for a wall 2 mm low (the slow end of the window lays up to
//! 1.83 Delta); a wall 2 mm high, aimed at the next nominal layers, needs
//! 2 / (Delta - h(v_max)) layers with the default law (a = -0.5, the fast
//! end lays 0.91 Delta), but it already stands where nominal layer K+1
//! would: aimed one nominal layer further on (K+1 skipped), it rejoins
//! within three layers with every bead inside the window.

use crate::common::part_path;
use crate::support::*;
use waam_slicer::replan::{replan_part_with, ReplanOptions, ReplannedPart};
use waam_slicer::{Cell, Measured};

/// Replans after `k` with `field` and `ropts`, checks every rebuilt layer's
/// heights against the window (computed here from the law and the speed
/// bounds), the layers after the rejoin against the nominal ones (renumbered
/// after the skipped ones), the joints (FK) and the program's layer
/// numbering, and returns the layer where the nominal is rejoined and the
/// replan.
fn replan_and_check(
    field: Field,
    layers: usize,
    k: usize,
    ropts: &ReplanOptions,
) -> (usize, ReplannedPart) {
    let part = part("elbow.toml");
    let cell_file = part_path("cells/robowam_part_carried.toml");
    let cell = Cell::read(&cell_file).unwrap();
    let opts = elbow_opts(96, layers);
    let sliced = nominal(&part, &opts);
    let (scan, truth) = synthetic_scan(&sliced, k, &field, 3);
    let r = replan_part_with(&part, &cell, &Measured::Points(scan), k, &opts, ropts).unwrap();
    let skipped = r.skipped.len();
    assert_eq!(r.skipped, (k + 1..=k + skipped).collect::<Vec<_>>());
    let delta = sliced.path.delta_mm;
    let p = &sliced.process;
    let v_nom = p.travel_speed_mm_s;
    let (h_lo, h_hi) = (
        law_height(p.travel_speed_max_mm_s, v_nom, delta),
        law_height(p.travel_speed_min_mm_s, v_nom, delta),
    );
    let lk = &sliced.path.layers[k];
    let frames = &sliced.axes.frames[k];
    let mut below: Vec<_> = (0..lk.points.len())
        .map(|i| lk.points[i].position + frames[i].build * truth[i])
        .collect();
    let rejoined = r.rejoined_at.expect("the nominal layers are rejoined");
    let path = &r.planned.sliced.path;
    let mut clamped_layers = 0;
    for c in r.corrections.iter().take_while(|c| c.layer <= rejoined) {
        assert_eq!(c.nominal_layer, c.layer + skipped);
        let tol = if c.layer == k + 1 { 0.08 } else { 1e-6 };
        let (mut lo, mut hi) = (f64::INFINITY, 0.0_f64);
        for (m, pt) in path.layers[c.layer].points.iter().enumerate() {
            let h = distance_to_closed(&pt.position, &below);
            (lo, hi) = (lo.min(h), hi.max(h));
            assert!(
                h > h_lo - tol && h < h_hi + tol,
                "layer {}: bead {h:.3} mm outside the window [{h_lo:.3}, {h_hi:.3}]",
                c.layer
            );
            // the speed that lays it, inside the speed window
            let v = c.speed_mm_s[m];
            assert!(v >= p.travel_speed_min_mm_s - 1e-9 && v <= p.travel_speed_max_mm_s + 1e-9);
        }
        // what was measured (`cargo test -- --nocapture`)
        eprintln!(
            "after layer {k}, field {field:?}: layer {} (nominal {}) beads {lo:.3}..{hi:.3} mm, window [{h_lo:.3}, {h_hi:.3}]",
            c.layer, c.nominal_layer
        );
        if c.clamped.iter().any(|x| *x) {
            clamped_layers += 1;
        }
        let mut next = vec![below[0]; below.len()];
        for pt in &path.layers[c.layer].points {
            next[column(&sliced, k, pt.v)] = pt.position;
        }
        below = next;
    }
    assert!(
        clamped_layers >= 1 || skipped > 0,
        "a 2 mm error must need the geometry"
    );
    // from the rejoined layer on, the nominal positions (nominal layer
    // l + skipped laid as layer l), to the part's last nominal layer
    assert_eq!(path.layers.len() + skipped, sliced.path.layers.len());
    for l in rejoined..path.layers.len() {
        for (a, b) in path.layers[l]
            .points
            .iter()
            .zip(&sliced.path.layers[l + skipped].points)
        {
            assert_eq!(a.position, b.position, "layer {l}");
        }
    }
    assert!(r.is_feasible(), "{:?}", r.planned.refusal());
    let text = std::fs::read_to_string(&cell_file).unwrap();
    assert!(fk_check_part_carried(&text, &r.planned) > 0);
    // the program's beads run on from K+1 without a gap
    let beads: Vec<usize> = r
        .planned
        .program
        .as_ref()
        .unwrap()
        .bead_setup
        .iter()
        .map(|b| b.layer)
        .collect();
    assert_eq!(beads, (k + 1..path.layers.len()).collect::<Vec<_>>());
    // the summary names the skipped nominal layers and the one rejoined
    let summary = r.summary().replan;
    assert_eq!(summary.nominal_layers_skipped, r.skipped);
    assert_eq!(summary.rejoined_at_layer, Some(rejoined));
    assert_eq!(summary.rejoined_at_nominal_layer, Some(rejoined + skipped));
    (rejoined, r)
}

#[test]
fn a_wall_2_mm_low_is_rebuilt_within_the_window_and_rejoins_within_three_layers() {
    let (rejoined, r) = replan_and_check(
        Field {
            high: -2.0,
            low: 0.0,
        },
        16,
        K,
        &ReplanOptions::default(),
    );
    assert!(rejoined <= K + 3, "rejoined at layer {rejoined}");
    assert!(r.skipped.is_empty(), "{:?}", r.skipped);
}

#[test]
fn in_the_bend_a_wall_2_mm_low_is_rebuilt_within_the_window_and_rejoins_within_three_layers() {
    // layer 25 lies in the elbow's bend: columns lean from the build direction
    let (rejoined, r) = replan_and_check(
        Field {
            high: -2.0,
            low: 0.0,
        },
        30,
        25,
        &ReplanOptions::default(),
    );
    assert!(rejoined <= 25 + 3, "rejoined at layer {rejoined}");
    assert!(r.skipped.is_empty(), "{:?}", r.skipped);
}

#[test]
fn a_wall_2_mm_high_is_rebuilt_within_the_window_and_rejoins_when_the_window_has_absorbed_it() {
    // aimed at the next nominal layers (no skip): the window's fast end
    // the bound computed from the law and the window, independently
    let process = waam_slicer::process::ProcessParameters::cmt_steel_er70s6();
    let h_lo = law_height(
        process.travel_speed_max_mm_s,
        process.travel_speed_mm_s,
        2.0,
    );
    let bound = (2.0 / (2.0 - h_lo)).ceil() as usize;
    assert!(
        bound > 3,
        "the default window absorbs {:.3} mm a layer",
        2.0 - h_lo
    );
    let (rejoined, r) = replan_and_check(
        Field {
            high: 2.0,
            low: 0.0,
        },
        K + bound + 3,
        K,
        &ReplanOptions {
            skip_nominal_layers: false,
            ..ReplanOptions::default()
        },
    );
    assert!(
        rejoined <= K + bound + 1,
        "rejoined at layer {rejoined}, bound {}",
        K + bound + 1
    );
    assert!(r.skipped.is_empty(), "{:?}", r.skipped);
}

/// The window's bead heights (mm) for Delta 2 mm, from the law and the
/// CMT steel speed bounds, independently of the library's window.
fn window_2mm() -> (f64, f64) {
    let p = waam_slicer::process::ProcessParameters::cmt_steel_er70s6();
    (
        law_height(p.travel_speed_max_mm_s, p.travel_speed_mm_s, 2.0),
        law_height(p.travel_speed_min_mm_s, p.travel_speed_mm_s, 2.0),
    )
}

#[test]
fn a_wall_2_mm_high_all_round_skips_nominal_layer_k1_and_rejoins_in_one_layer() {
    // the wall stands where nominal layer K+1 would: the next bead, Delta
    // high, lays nominal layer K+2. The median error is a whole layer, so
    // the scan would be refused as one of layer K+1: the operator vouches
    // for it by raising the limit.
    let (h_lo, h_hi) = window_2mm();
    assert!(h_lo < 2.0 && 2.0 < h_hi);
    let ropts = ReplanOptions {
        max_median_error_rel: 1.5,
        ..ReplanOptions::default()
    };
    let (rejoined, r) = replan_and_check(
        Field {
            high: 2.0,
            low: 2.0,
        },
        16,
        K,
        &ropts,
    );
    assert_eq!(r.skipped, vec![K + 1]);
    assert!(rejoined <= K + 3, "rejoined at layer {rejoined}");
    assert_eq!(rejoined, K + 1);
    // without the skip, the window's fast end takes more than three layers
    let (no_skip, r) = replan_and_check(
        Field {
            high: 2.0,
            low: 2.0,
        },
        K + 16,
        K,
        &ReplanOptions {
            skip_nominal_layers: false,
            ..ropts
        },
    );
    assert!(no_skip > K + 3 && r.skipped.is_empty(), "{no_skip}");
}

#[test]
fn a_quarter_2_mm_high_and_the_rest_half_a_mm_low_skips_nominal_layer_k1_and_rejoins_within_three_layers(
) {
    // high quarter: 2 mm to nominal K+2, 2 mm more to K+3; the rest 4.5 mm
    // to K+2 (more than the window's 3.65), 6.5 mm to K+3 in two beads
    let (h_lo, h_hi) = window_2mm();
    assert!(4.5 > h_hi && 6.5 < 2.0 * h_hi && 4.0 > 2.0 * h_lo);
    let field = Field {
        high: 2.0,
        low: -0.5,
    };
    let (rejoined, r) = replan_and_check(field, 16, K, &ReplanOptions::default());
    assert_eq!(r.skipped, vec![K + 1]);
    assert!(rejoined <= K + 3, "rejoined at layer {rejoined}");
    // the low side laid thick (slow) and the high side thin (fast)
    let first = &r.corrections[0];
    assert!(first.clamped.iter().any(|c| *c));
    let json = serde_json::to_value(r.summary()).unwrap();
    assert_eq!(json["replan"]["nominal_layers_skipped"][0], K + 1);
}

#[test]
fn in_the_bend_a_quarter_2_mm_high_skips_a_nominal_layer_and_rejoins_within_three_layers() {
    let (rejoined, r) = replan_and_check(
        Field {
            high: 2.0,
            low: -0.5,
        },
        30,
        25,
        &ReplanOptions::default(),
    );
    assert_eq!(r.skipped, vec![26]);
    assert!(rejoined <= 25 + 3, "rejoined at layer {rejoined}");
}

#[test]
fn a_wall_still_too_high_at_the_top_drops_the_layers_that_no_longer_fit() {
    let part = part("elbow.toml");
    let cell = Cell::read(part_path("cells/robowam_part_carried.toml")).unwrap();
    let opts = crate::support::elbow_opts(96, 200);
    let sliced = nominal(&part, &opts);
    let last = sliced.path.layers.len() - 1;
    let k = last - 2;
    let field = Field {
        high: 2.0,
        low: 0.0,
    };
    let (scan, _) = synthetic_scan(&sliced, k, &field, 9);
    let r = waam_slicer::replan_part(&part, &cell, &Measured::Points(scan), k, &opts).unwrap();
    // the high quarter is still 1.65 mm high after layer k + 1: layer k + 2
    // would pass the part's end there (less than Delta of tube above it)
    assert_eq!(r.dropped_from, Some(k + 2), "{:?}", r.rejoined_at);
    assert_eq!(r.corrections.len(), 1);
    assert_eq!(r.planned.sliced.path.layers.len(), k + 2);
    assert!(r.is_feasible(), "{:?}", r.planned.refusal());
    let beads: Vec<usize> = r
        .planned
        .program
        .as_ref()
        .unwrap()
        .bead_setup
        .iter()
        .map(|b| b.layer)
        .collect();
    assert_eq!(beads, vec![k + 1]);
    assert_eq!(r.summary().replan.layers_dropped_from, Some(k + 2));
}

#[test]
fn from_the_nominal_plan_a_skip_reuses_the_renumbered_layers_and_gives_the_same_replan() {
    // differential: replan_planned (reusing the nominal plan's layers, now
    // renumbered after the skipped one) against replan_part
    let part = part("elbow.toml");
    let cell = Cell::read(part_path("cells/robowam_part_carried.toml")).unwrap();
    let opts = elbow_opts(96, 16);
    let sliced = nominal(&part, &opts);
    let field = Field {
        high: 2.0,
        low: -0.5,
    };
    let (scan, _) = synthetic_scan(&sliced, K, &field, 3);
    let fresh =
        waam_slicer::replan_part(&part, &cell, &Measured::Points(scan.clone()), K, &opts).unwrap();
    let planned = waam_slicer::plan_part(&part, &cell, &opts).unwrap();
    let fast = waam_slicer::replan_planned(
        &part,
        &planned,
        &Measured::Points(scan),
        K,
        &ReplanOptions::default(),
    )
    .unwrap();
    assert_eq!(fast.skipped, vec![K + 1]);
    assert_eq!(fast.corrections, fresh.corrections);
    assert!(fast.is_feasible(), "{:?}", fast.planned.refusal());
    let layers: Vec<usize> = fast.planned.plan.layers.iter().map(|l| l.layer).collect();
    assert_eq!(layers, (K + 1..15).collect::<Vec<_>>());
    for (a, b) in fast
        .planned
        .plan
        .layers
        .iter()
        .zip(&fresh.planned.plan.layers)
    {
        assert_eq!(a.layer, b.layer);
        for (p, q) in a.points.iter().zip(&b.points) {
            let (p, q) = (p.joints.unwrap(), q.joints.unwrap());
            assert!(p.iter().zip(&q).all(|(x, y)| (x - y).abs() < 1e-9));
        }
    }
    // the reused layers are the nominal plan's, one layer further on
    let last = fast.planned.plan.layers.last().unwrap();
    let nominal_last = planned.plan.layers.iter().find(|l| l.layer == 15).unwrap();
    assert_eq!(last.points, nominal_last.points);
}
