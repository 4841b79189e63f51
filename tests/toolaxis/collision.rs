//! The torch against the part built so far: the hemisphere top.

use crate::common::load_part;
use waam_slicer::path::{slice, Discretisation, Path};
use waam_slicer::toolaxis::rules::max_rate;
use waam_slicer::toolaxis::{
    avoid_collisions, check_collisions, tool_axes, AvoidanceOptions, CollisionOptions, LocalFrame,
    ToolAxisOptions, Torch, TorchSpec,
};

fn hemisphere() -> (waam_slicer::io::part_file::Part, Path) {
    let part = load_part("hemisphere.toml");
    let mut o = part.slice_options();
    o.discretisation = Discretisation::Points(100);
    let path = slice(&part.tube, &part.substrate, &o).unwrap();
    (part, path)
}

/// Forced horizontal (the horizontal part of `b`, toward the axis) on the
/// last two layers, the CMT torch collides with the layers below; the
/// avoidance option, within a 60° cone, clears every point, smoothly.
#[test]
fn horizontal_torch_collides_near_the_top_and_avoidance_clears_it() {
    let (part, path) = hemisphere();
    let axes = tool_axes(
        &path,
        Some(&part.tube),
        Some(&part.substrate),
        &ToolAxisOptions::default(),
    )
    .unwrap();
    let last = path.layers.len();
    let mut frames: Vec<Vec<LocalFrame>> = axes.frames.clone();
    for fl in &mut frames[last - 2..] {
        for f in fl.iter_mut() {
            let mut h = f.build;
            h.z = 0.0;
            f.tool = h.normalize();
        }
    }
    let torch = Torch::new(&TorchSpec::cmt_torch()).unwrap();
    let copts = CollisionOptions::default();
    let report = check_collisions(&path, &frames, Some(&part.substrate), &torch, &copts).unwrap();
    assert!(report.substrate_checked);
    let (layer, point) = report
        .first_collision
        .expect("the horizontal torch collides");
    eprintln!(
        "first collision at layer {layer}, point {point}; colliding points {}; min clearance {:.2} mm",
        report.colliding_points, report.min_clearance_mm
    );
    assert!(layer >= last - 2);
    for l in &report.layers[..last - 2] {
        assert_eq!(l.colliding_points, 0, "layer {}", l.layer);
    }
    assert_eq!(report.colliding_points, 2 * 100);

    let aopts = AvoidanceOptions::default();
    let (fixed, av) = avoid_collisions(
        &path,
        &frames,
        Some(&part.substrate),
        &torch,
        &copts,
        &aopts,
    )
    .unwrap();
    eprintln!(
        "avoidance: corrected {} points, max correction {:.1} deg, min clearance after {:.2} mm",
        av.corrected_points,
        av.max_correction_rad.to_degrees(),
        av.after.min_clearance_mm
    );
    assert_eq!(av.before, report);
    assert_eq!(
        av.after.colliding_points, 0,
        "{:?}",
        av.after.first_collision
    );
    assert!(av.unresolved.is_empty(), "{:?}", av.unresolved);
    assert!(av.max_correction_rad <= aopts.cone_half_angle_rad + 1e-9);
    // Smooth along each layer: the corrections change at most at the bound
    // (plus the turn of the local basis), on top of the nominal axes' rate.
    for (l, fl) in path.layers.iter().zip(&fixed) {
        let li = l.slice;
        let p: Vec<_> = l.points.iter().map(|p| p.position).collect();
        let after: Vec<_> = fl.iter().map(|f| f.tool).collect();
        let before: Vec<_> = frames[li].iter().map(|f| f.tool).collect();
        let (ra, rb) = (
            max_rate(&p, &after, l.closed),
            max_rate(&p, &before, l.closed),
        );
        eprintln!("layer {li}: rate before {rb:.4} rad/mm, after {ra:.4} rad/mm");
        assert!(
            ra <= rb + 1.5 * aopts.max_rate_rad_per_mm,
            "layer {li}: {ra} vs {rb}"
        );
    }
    // The independent check agrees.
    let again = check_collisions(&path, &fixed, Some(&part.substrate), &torch, &copts).unwrap();
    assert_eq!(again.colliding_points, 0);
}

/// With `T = b` the CMT torch hits the dome near the top; the thesis's 50°
/// rule (eq. 3.20–3.21) is what made the top buildable.
#[test]
fn fifty_degree_rule_clears_the_hemisphere_top() {
    let (part, path) = hemisphere();
    let torch = Torch::new(&TorchSpec::cmt_torch()).unwrap();
    let copts = CollisionOptions::default();
    let plain = tool_axes(
        &path,
        Some(&part.tube),
        Some(&part.substrate),
        &ToolAxisOptions::default(),
    )
    .unwrap();
    let r = check_collisions(&path, &plain.frames, Some(&part.substrate), &torch, &copts).unwrap();
    eprintln!(
        "T = b: {} colliding points, first {:?}",
        r.colliding_points, r.first_collision
    );
    let ruled = tool_axes(
        &path,
        Some(&part.tube),
        Some(&part.substrate),
        &ToolAxisOptions::thesis_50_deg_rule(),
    )
    .unwrap();
    let r50 =
        check_collisions(&path, &ruled.frames, Some(&part.substrate), &torch, &copts).unwrap();
    eprintln!(
        "50° rule: {} colliding points, min clearance {:.2} mm",
        r50.colliding_points, r50.min_clearance_mm
    );
    assert!(r.colliding_points > 0);
    assert_eq!(r50.colliding_points, 0);
}
