//! Local frames: analytic vs numeric normals (eq. 2.36), orientation of `b`,
//! lead/tilt (eq. 2.30–2.32).

use crate::common::{load_part, SAMPLE_PARTS};
use waam_slicer::io::part_file::Part;
use waam_slicer::path::{slice, Discretisation, EndRule, Path};
use waam_slicer::toolaxis::{
    local_frames, mean_normal_difference, mean_normal_difference_per_layer, tool_axes,
    NormalMethod, ToolAxisOptions,
};

fn path_of(part: &Part, delta: f64, points: usize) -> Path {
    let mut o = part.slice_options();
    o.delta_mm = delta;
    o.discretisation = Discretisation::Points(points);
    // Whole layers, as the thesis (§2.3.2): no open pieces cut by the end plane.
    o.end = EndRule::WholeLayers;
    slice(&part.tube, &part.substrate, &o).unwrap_or_else(|e| panic!("{}: {e}", part.name))
}

/// Mean of eq. 2.36 over the whole path and over the one-facet layers.
fn one_facet_and_overall(part: &Part, delta: f64, points: usize) -> (f64, f64) {
    let path = path_of(part, delta, points);
    let a = tool_axes(&path, Some(&part.tube), None, &ToolAxisOptions::default()).unwrap();
    let n = tool_axes(
        &path,
        None,
        None,
        &ToolAxisOptions {
            normals: NormalMethod::Numeric,
            ..ToolAxisOptions::default()
        },
    )
    .unwrap();
    let per = mean_normal_difference_per_layer(&a.frames, &n.frames);
    (
        0.5 * (per[0] + per[per.len() - 1]),
        mean_normal_difference(&a.frames, &n.frames),
    )
}

/// Quarter torus, Delta = 5 mm, 500 points per layer, whole layers: the
/// thesis measured a mean difference (eq. 2.36) "of the order of 4 %"
/// (§2.4.3). We get 3.4 % and 6.7 % on the first and last layers (one facet:
/// a one-sided difference, error ~ Delta / (2 rho)), 0.1–0.4 % on the
/// others (two facets: a central difference), 1.2 % over the path. Halving
/// Delta divides both by two or more.
#[test]
fn quarter_torus_numeric_normals_match_the_thesis() {
    let part = load_part("quarter-torus.toml");
    let (one_facet, overall) = one_facet_and_overall(&part, 5.0, 500);
    eprintln!("Delta 5: one-facet layers {one_facet:.4}, overall {overall:.4}");
    assert!((0.02..0.08).contains(&one_facet), "{one_facet}");
    assert!((0.005..0.06).contains(&overall), "{overall}");
    let (one_facet_2, overall_2) = one_facet_and_overall(&part, 2.5, 500);
    eprintln!("Delta 2.5: one-facet layers {one_facet_2:.4}, overall {overall_2:.4}");
    assert!(one_facet_2 < 0.6 * one_facet && overall_2 < 0.6 * overall);
}

/// `b` of the first layer points away from the substrate on every sample
/// part, with analytic and numeric normals; frames are orthonormal.
#[test]
fn build_direction_leaves_the_substrate_on_every_sample_part() {
    for name in SAMPLE_PARTS {
        let part = load_part(name);
        let mut o = part.slice_options();
        o.discretisation = Discretisation::Points(120);
        o.max_layers = Some(2);
        let path = slice(&part.tube, &part.substrate, &o).unwrap_or_else(|e| panic!("{name}: {e}"));
        for method in [NormalMethod::Analytic, NormalMethod::Numeric] {
            let opts = ToolAxisOptions {
                normals: method,
                ..ToolAxisOptions::default()
            };
            let axes = tool_axes(&path, Some(&part.tube), Some(&part.substrate), &opts)
                .unwrap_or_else(|e| panic!("{name}: {e}"));
            for (l, fl) in path.layers.iter().zip(&axes.frames) {
                for (p, f) in l.points.iter().zip(fl) {
                    for v in [f.tangent, f.normal, f.build] {
                        assert!((v.norm() - 1.0).abs() < 1e-12);
                    }
                    assert!(f.tangent.dot(&f.normal).abs() < 1e-9);
                    assert!(f.tangent.dot(&f.build).abs() < 1e-9);
                    assert!(f.normal.dot(&f.build).abs() < 1e-9);
                    if l.slice == 0 {
                        let out = part.substrate.outward(&p.position).unwrap();
                        assert!(
                            f.build.dot(&out) > 0.0,
                            "{name} {method:?}: b = {:?}",
                            f.build
                        );
                    }
                }
            }
        }
        // The minimal entry point agrees with the analytic stage.
        let legacy = local_frames(&path, &part.tube);
        let stage = tool_axes(
            &path,
            Some(&part.tube),
            Some(&part.substrate),
            &ToolAxisOptions::default(),
        )
        .unwrap();
        assert_eq!(legacy, stage.frames, "{name}");
    }
}

/// Lead/tilt (0, 0) gives `T = b`; (10°, 0) tilts `T` by 10° in the feed
/// plane `(t, b)`, toward the feed direction; (0, 10°) in the normal plane
/// (eq. 2.30–2.32). To 1e-9 on the hemisphere.
#[test]
fn lead_and_tilt_angles() {
    let part = load_part("hemisphere.toml");
    let mut o = part.slice_options();
    o.discretisation = Discretisation::Points(100);
    let path = slice(&part.tube, &part.substrate, &o).unwrap();
    let zero = tool_axes(
        &path,
        Some(&part.tube),
        Some(&part.substrate),
        &ToolAxisOptions::default(),
    )
    .unwrap();
    for f in zero.frames.iter().flatten() {
        assert_eq!(f.tool, f.build);
    }
    let ten = 10f64.to_radians();
    let lead = tool_axes(
        &path,
        Some(&part.tube),
        Some(&part.substrate),
        &ToolAxisOptions {
            lead_rad: ten,
            ..ToolAxisOptions::default()
        },
    )
    .unwrap();
    let tilt = tool_axes(
        &path,
        Some(&part.tube),
        Some(&part.substrate),
        &ToolAxisOptions {
            tilt_rad: ten,
            ..ToolAxisOptions::default()
        },
    )
    .unwrap();
    for (fl, ft) in lead
        .frames
        .iter()
        .flatten()
        .zip(tilt.frames.iter().flatten())
    {
        let t = fl.tool;
        assert!((t.dot(&fl.build).clamp(-1.0, 1.0).acos() - ten).abs() < 1e-9);
        assert!(t.dot(&fl.normal).abs() < 1e-9, "in the feed plane");
        assert!(
            (t.dot(&fl.tangent) - ten.sin()).abs() < 1e-9,
            "toward the feed direction"
        );
        let t = ft.tool;
        assert!((t.dot(&ft.build).clamp(-1.0, 1.0).acos() - ten).abs() < 1e-9);
        assert!(t.dot(&ft.tangent).abs() < 1e-9, "in the normal plane");
        assert!(
            (t.dot(&ft.normal) - ten.sin()).abs() < 1e-9,
            "toward the outside"
        );
    }
}

/// The helix at its own settings: constant-distance layers grow corners
/// (SPEC §3.4) and the aligned seams (§3.3) settle on them. Where a closed
/// layer's seam turns more than 10° the bead (first point to last) does not
/// turn that corner, so its ends take the build direction of eq. 2.35 from a
/// one-sided chord (recomputed here from the positions and normals); a
/// smooth seam keeps the wrapped central difference of eq. 2.34. Before, the
/// first point's `b` was half way round the corner.
#[test]
fn a_corner_at_the_seam_leaves_the_beads_ends_their_own_build_directions() {
    let part = load_part("helix.toml");
    let sliced = waam_slicer::slice_part(&part).unwrap();
    let angle = |a: &waam_slicer::math::Vector3, b: &waam_slicer::math::Vector3| {
        (a.dot(b) / (a.norm() * b.norm())).clamp(-1.0, 1.0).acos()
    };
    // eq. 2.35 from the chord `c`: the tangent in the surface, crossed with
    // the normal, oriented as the stage's own b
    let b_of = |c: waam_slicer::math::Vector3, f: &waam_slicer::toolaxis::LocalFrame| {
        let t = (c - f.normal * c.dot(&f.normal)).normalize();
        let b = t.cross(&f.normal);
        if b.dot(&f.build) < 0.0 {
            -b
        } else {
            b
        }
    };
    let mut corners = 0;
    for (li, (l, fr)) in sliced
        .path
        .layers
        .iter()
        .zip(&sliced.axes.frames)
        .enumerate()
    {
        let n = l.points.len();
        if !l.closed || n < 5 {
            continue;
        }
        let p = |i: usize| l.points[i % n].position;
        let turn = |i: usize| angle(&(p(i + n) - p(i + n - 1)), &(p(i + 1) - p(i)));
        let (first, last) = if turn(0).max(turn(n - 1)) > 10f64.to_radians() {
            corners += 1;
            (p(1) - p(0), p(n - 1) - p(n - 2))
        } else {
            (p(1) - p(n - 1), p(0) - p(n - 2))
        };
        for (i, c) in [(0, first), (n - 1, last)] {
            let err = (fr[i].build - b_of(c, &fr[i])).norm();
            assert!(err < 1e-9, "layer {li} point {i}: {err}");
        }
    }
    assert!(corners >= 50, "{corners} corner seams");
}
