//! Corners of constant-distance layers (SPEC §3.4, §9) and the seams put on
//! them (§3.3): the elbow's layers list their corners, and a closed layer
//! with corners starts and ends at its sharpest one.

use crate::common::{load_part, part_path};
use waam_slicer::io::part_file::parse_part;
use waam_slicer::path::{Corner, Layer, SEAM_CORNER_RAD};
use waam_slicer::{slice_part, slice_part_with, Control, SliceOverrides};

/// The sharpest corner of `layer` above the default threshold, if any.
fn sharpest(layer: &Layer) -> Option<Corner> {
    layer
        .corners(SEAM_CORNER_RAD)
        .into_iter()
        .reduce(|a, b| if b.turn_rad > a.turn_rad { b } else { a })
}

/// The elbow at its own grid (Delta 2 mm, 400 points, 62 layers): where the
/// fronts from either side of the bend meet, its layers 46–61 each turn one
/// corner, 16° on layer 46 growing to 113° on layer 61 (the refused
/// layers 47–59 turn 41–111°). `summary.json` lists each with the jump of
/// the build direction across it, and each of those closed layers starts
/// and ends on it: the bead (first point to last) does not turn it, so its
/// ends take one-sided build directions. With the option off, the seams
/// are today's (aligned on the end of the layer below): the corner of
/// layers 46–59 lies inside the bead, on 60 and 61 it falls on the seam.
/// Either way the layers are the same loops of points.
#[test]
fn the_elbows_corner_layers_list_their_corners_and_start_on_them() {
    let part = load_part("elbow.toml");
    let sliced = slice_part(&part).unwrap();
    let layers = &sliced.path.layers;
    assert_eq!(layers.len(), 62);
    let with: Vec<usize> = (0..layers.len())
        .filter(|&li| !layers[li].corners(SEAM_CORNER_RAD).is_empty())
        .collect();
    assert_eq!(with, (46..=61).collect::<Vec<_>>());
    let json = serde_json::to_value(sliced.summary()).unwrap();
    let listed = &json["corners"];
    assert_eq!(listed["layers_with_corners"], 16);
    assert_eq!(listed["threshold_deg"], 10.0);
    for li in 46..=61 {
        let l = &layers[li];
        let n = l.points.len();
        assert!(l.closed, "layer {li}");
        let c = sharpest(l).unwrap();
        assert!(c.on_seam(n), "layer {li}: {c:?}");
        assert!(!l.bead_wraps(), "layer {li}");
        let turn = c.turn_rad.to_degrees();
        if (47..=59).contains(&li) {
            assert!((40.0..=112.0).contains(&turn), "layer {li}: {turn}");
        }
        let entry = &listed["per_layer"][li][0];
        assert_eq!(entry["on_seam"], true, "layer {li}");
        assert_eq!(entry["point"], c.point, "layer {li}");
        assert!((entry["turning_deg"].as_f64().unwrap() - turn).abs() < 1e-9);
        // the build direction turns at least as much as the polyline
        let jump = entry["build_jump_deg"].as_f64().unwrap();
        assert!(
            jump >= turn && jump < turn + 11.0,
            "layer {li}: {jump} {turn}"
        );
    }

    let off = SliceOverrides {
        seams_on_corners: Some(false),
        ..SliceOverrides::default()
    };
    let today = slice_part_with(&part, &off, &Control::default()).unwrap();
    let json = serde_json::to_value(today.summary()).unwrap();
    assert_eq!(json["corners"]["seams_on_corners"], false);
    for (li, (a, b)) in layers.iter().zip(&today.path.layers).enumerate() {
        let n = a.points.len();
        if li < 46 {
            assert_eq!(a, b, "layer {li}");
            continue;
        }
        let c = sharpest(b).unwrap();
        assert_eq!(c.on_seam(n), li >= 60, "layer {li}: {c:?}");
        // the same loop, started elsewhere
        let k = (0..n)
            .find(|&k| b.points[k].position == a.points[0].position)
            .unwrap();
        let mut turned = b.points.clone();
        turned.rotate_left(k);
        assert_eq!(turned, a.points, "layer {li}");
    }
}

/// The threshold from the part file's `[slicing]` and from the options: at
/// 50° the elbow's corners are those of layers 48–61 (58–113°), at 100°
/// those of the 7 layers 55–61; a threshold out of (0, 180) degrees, or
/// not a number, names its field.
#[test]
fn the_corner_threshold_is_read_from_the_part_file_and_the_options() {
    let text = std::fs::read_to_string(part_path("elbow.toml")).unwrap();
    let with = |table: &str| text.replace("points = 400", &format!("points = 400\n{table}"));
    let part = parse_part(
        &with("corner_threshold_deg = 50\nseams_on_corners = false"),
        "elbow50.toml",
        std::path::Path::new("parts"),
    )
    .unwrap();
    let o = part.slice_options();
    assert!((o.corner_threshold_rad - 50f64.to_radians()).abs() < 1e-15);
    assert!(!o.seams_on_corners);
    let sliced = slice_part(&part).unwrap();
    let json = serde_json::to_value(sliced.summary()).unwrap();
    let per_layer = json["corners"]["per_layer"].as_array().unwrap();
    let listed: Vec<usize> = (0..per_layer.len())
        .filter(|&li| !per_layer[li].as_array().unwrap().is_empty())
        .collect();
    assert_eq!(listed, (48..=61).collect::<Vec<_>>());
    // the options override the file
    let over = SliceOverrides {
        corner_threshold_rad: Some(100f64.to_radians()),
        ..SliceOverrides::default()
    };
    let sliced = slice_part_with(&part, &over, &Control::default()).unwrap();
    assert_eq!(sliced.corners_summary().layers_with_corners, 7);
    for bad in ["0", "-5", "180", "nan"] {
        let e = parse_part(
            &with(&format!("corner_threshold_deg = {bad}")),
            "bad.toml",
            std::path::Path::new("parts"),
        )
        .unwrap_err();
        assert!(
            e.to_string().contains("slicing.corner_threshold_deg"),
            "{bad}: {e}"
        );
    }
}

/// A layer with two corners gets one split: the S-bend at its own grid
/// (213 closed layers of 400 points) has two corners on each of its layers
/// 168–175 and on no other; the seam lies on the sharper one (23–59°, or
/// 14° on layer 168), so exactly one corner (10–13°) lies inside the bead,
/// where the bead may be split: the layer's points split there give two
/// beads, which share the corner point. The quarter torus's open layers
/// 11–16 each turn one corner (77–112°), inside their bead (not on an end).
#[test]
fn a_layer_with_two_corners_has_one_inside_its_bead() {
    use waam_slicer::optimise::{layer_points, LayerPoints};
    let sliced = slice_part(&load_part("s-bend.toml")).unwrap();
    let layers = &sliced.path.layers;
    assert_eq!(layers.len(), 213);
    let two: Vec<usize> = (0..layers.len())
        .filter(|&li| layers[li].corners(SEAM_CORNER_RAD).len() >= 2)
        .collect();
    assert_eq!(two, (168..=175).collect::<Vec<_>>());
    let whole = layer_points(&sliced.path, &sliced.axes.frames, 6.0);
    for li in two {
        let l = &layers[li];
        let n = l.points.len();
        assert!(l.closed, "layer {li}");
        let corners = l.corners(SEAM_CORNER_RAD);
        assert_eq!(corners.iter().filter(|c| c.on_seam(n)).count(), 1);
        let inside = l.inside_corners(SEAM_CORNER_RAD);
        assert_eq!(inside.len(), 1, "layer {li}: {corners:?}");
        let c = inside[0];
        assert!(!c.on_seam(n) && c.point > 0 && c.point + 1 < n);
        let sharper = sharpest(l).unwrap();
        assert!(sharper.on_seam(n) && sharper.turn_rad > c.turn_rad);
        let beads: Vec<LayerPoints> = whole[li].split_at(&[c.point]);
        assert_eq!(beads.len(), 2, "layer {li}");
        assert_eq!(
            (beads[0].bead, beads[1].bead, beads[1].first_point),
            (0, 1, c.point)
        );
        assert_eq!(beads[0].points.len() + beads[1].points.len(), n + 1);
        assert_eq!(
            beads[0].points.last().unwrap().position_mm,
            beads[1].points[0].position_mm
        );
    }
    let torus = slice_part(&load_part("quarter-torus.toml")).unwrap();
    for li in 11..=16 {
        let l = &torus.path.layers[li];
        assert!(!l.closed, "layer {li}");
        let inside = l.inside_corners(SEAM_CORNER_RAD);
        assert_eq!(inside.len(), 1, "layer {li}");
        let turn = inside[0].turn_rad.to_degrees();
        assert!((75.0..115.0).contains(&turn), "layer {li}: {turn}");
    }
}
