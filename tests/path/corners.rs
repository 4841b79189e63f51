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
