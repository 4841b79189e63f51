//! Correction (b), geometry: errors of 2 mm, more than the speed window can
//! absorb in one layer. Every rebuilt layer stays within the window (bead
//! heights measured here against the layer below, brute force) and the
//! nominal layers are rejoined as soon as the window allows: within three
//! layers for a wall 2 mm low (the slow end of the window lays up to
//! 1.83 Delta); a wall 2 mm high needs 2 / (Delta - h(v_max)) layers with
//! the default law (a = -0.5, the fast end lays 0.91 Delta).

use crate::common::part_path;
use crate::support::*;
use waam_slicer::{replan_part, Cell, Measured};

/// Replans after `k` with `field`, checks every rebuilt layer's heights
/// against the window, and returns the layer where the nominal is rejoined.
fn replan_and_check(field: Field, layers: usize, k: usize) -> usize {
    let part = part("elbow.toml");
    let cell_file = part_path("cells/robowam_part_carried.toml");
    let cell = Cell::read(&cell_file).unwrap();
    let opts = elbow_opts(96, layers);
    let sliced = nominal(&part, &opts);
    let (scan, truth) = synthetic_scan(&sliced, k, &field, 3);
    let r = replan_part(&part, &cell, &Measured::Points(scan), k, &opts).unwrap();
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
        let tol = if c.layer == k + 1 { 0.08 } else { 1e-6 };
        for pt in &path.layers[c.layer].points {
            let h = distance_to_closed(&pt.position, &below);
            assert!(
                h > h_lo - tol && h < h_hi + tol,
                "layer {}: bead {h:.3} mm outside the window [{h_lo:.3}, {h_hi:.3}]",
                c.layer
            );
        }
        if c.clamped.iter().any(|x| *x) {
            clamped_layers += 1;
        }
        let mut next = vec![below[0]; below.len()];
        for pt in &path.layers[c.layer].points {
            next[column(&sliced, k, pt.v)] = pt.position;
        }
        below = next;
    }
    assert!(clamped_layers >= 1, "a 2 mm error must need the geometry");
    // from the rejoined layer on, the nominal positions
    for l in rejoined..path.layers.len() {
        for (a, b) in path.layers[l]
            .points
            .iter()
            .zip(&sliced.path.layers[l].points)
        {
            assert_eq!(a.position, b.position, "layer {l}");
        }
    }
    assert!(r.is_feasible(), "{:?}", r.planned.refusal());
    let text = std::fs::read_to_string(&cell_file).unwrap();
    assert!(fk_check_part_carried(&text, &r.planned) > 0);
    rejoined
}

#[test]
fn a_wall_2_mm_low_is_rebuilt_within_the_window_and_rejoins_within_three_layers() {
    let rejoined = replan_and_check(
        Field {
            high: -2.0,
            low: 0.0,
        },
        16,
        K,
    );
    assert!(rejoined <= K + 3, "rejoined at layer {rejoined}");
}

#[test]
fn in_the_bend_a_wall_2_mm_low_is_rebuilt_within_the_window_and_rejoins_within_three_layers() {
    // layer 25 lies in the elbow's bend: columns lean from the build direction
    let rejoined = replan_and_check(
        Field {
            high: -2.0,
            low: 0.0,
        },
        30,
        25,
    );
    assert!(rejoined <= 25 + 3, "rejoined at layer {rejoined}");
}

#[test]
fn a_wall_2_mm_high_is_rebuilt_within_the_window_and_rejoins_when_the_window_has_absorbed_it() {
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
    let rejoined = replan_and_check(
        Field {
            high: 2.0,
            low: 0.0,
        },
        K + bound + 3,
        K,
    );
    assert!(
        rejoined <= K + bound + 1,
        "rejoined at layer {rejoined}, bound {}",
        K + bound + 1
    );
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
    let r = replan_part(&part, &cell, &Measured::Points(scan), k, &opts).unwrap();
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
