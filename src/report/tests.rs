use super::cell_view::snapshot;
use super::encode::base64;
use super::page::{kept, script_safe_json, stride};
use super::*;
use crate::io::cell_file::read_cell_file;
use crate::math::{Point3, UnitVector3, Vector3};
use crate::path::{Layer, PathPoint, SliceReport, Strategy};
use crate::robot::chain::arm_chain;
use crate::robot::CellPoint;

fn cell(name: &str) -> CellLayout {
    let file = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("parts/cells")
        .join(name);
    read_cell_file(&file).unwrap().cell.unwrap()
}

/// A cylinder of radius `r`: `layers` circles of `n` points, `delta` apart,
/// with frames (normal radial, build and tool +Z) and a distance map whose
/// layer `k` is `delta + 0.01 k` (mm).
fn cylinder(
    layers: usize,
    n: usize,
    r: f64,
    delta: f64,
) -> (Path, Vec<Vec<LocalFrame>>, DistanceMap) {
    let mut ls = vec![];
    let mut frames = vec![];
    let mut dm = vec![];
    for k in 0..layers {
        let mut pts = vec![];
        let mut fr = vec![];
        let mut d = vec![];
        for i in 0..n {
            let v = std::f64::consts::TAU * i as f64 / n as f64;
            let (s, c) = v.sin_cos();
            pts.push(PathPoint {
                t: k as f64 * delta,
                v,
                position: Point3::new(r * c, r * s, delta * (k + 1) as f64),
                delta: (k > 0).then_some(delta + 0.01 * k as f64),
            });
            fr.push(LocalFrame {
                tangent: Vector3::new(-s, c, 0.0),
                normal: Vector3::new(c, s, 0.0),
                build: Vector3::z(),
                tool: Vector3::z(),
            });
            d.push((k > 0).then_some((delta + 0.01 * k as f64, false)));
        }
        ls.push(Layer {
            slice: k,
            points: pts,
            closed: true,
        });
        frames.push(fr);
        dm.push(d);
    }
    let path = Path {
        strategy: Strategy::Constant,
        delta_mm: delta,
        layers: ls,
        report: SliceReport::default(),
        spiral: None,
    };
    let map = DistanceMap {
        per_layer: vec![None; layers],
        overall: None,
        points: dm,
    };
    (path, frames, map)
}

#[test]
fn base64_matches_rfc_4648_vectors() {
    // RFC 4648 §10 test vectors.
    for (plain, coded) in [
        ("", ""),
        ("f", "Zg=="),
        ("fo", "Zm8="),
        ("foo", "Zm9v"),
        ("foob", "Zm9vYg=="),
        ("fooba", "Zm9vYmE="),
        ("foobar", "Zm9vYmFy"),
    ] {
        assert_eq!(base64(plain.as_bytes()), coded);
    }
    // 1.0f32 little-endian is 00 00 80 3F
    assert_eq!(super::encode::f32s(&[1.0]), base64(&[0, 0, 0x80, 0x3f]));
}

#[test]
fn strings_cannot_close_the_data_script() {
    let s = script_safe_json(&"a</script><!-- \"q\" \\ \n").unwrap();
    assert!(!s.contains('<') && !s.contains('>'));
    assert_eq!(s, r#""a\u003c/script\u003e\u003c!-- \"q\" \\ \n""#);
}

#[test]
fn decimation_keeps_every_kth_point_and_the_last() {
    assert_eq!(kept(10, 3).collect::<Vec<_>>(), [0, 3, 6, 9]);
    assert_eq!(kept(11, 3).collect::<Vec<_>>(), [0, 3, 6, 9, 10]);
    assert_eq!(kept(1, 5).collect::<Vec<_>>(), [0]);
    assert_eq!(kept(0, 5).count(), 0);
    assert_eq!(stride(1_000_000, 200_000), 5);
    assert_eq!(stride(1_000_001, 200_000), 6);
    assert_eq!(stride(10, 200_000), 1);
}

#[test]
fn arm_chain_is_rigid_and_ends_at_the_flange() {
    for name in [
        "robowam_part_carried.toml",
        "kuka_kr16_2_torch_carried.toml",
    ] {
        let robot = cell(name).robot().clone();
        let g = robot.geometry;
        for q in [
            [0.0; 6],
            [0.3, -0.4, 0.2, 1.0, -0.7, 2.0],
            [-1.2, 0.5, -0.3, -2.0, 1.1, -0.5],
        ] {
            let c = arm_chain(&robot, &q);
            let flange = robot.flange_pose(&q).translation.vector;
            assert!((c[6].coords - flange).norm() < 1e-9, "{name}: flange");
            let len = |a: usize, b: usize| (c[b] - c[a]).norm();
            assert!((len(0, 1) - g.shoulder_height_mm).abs() < 1e-9);
            assert!(
                (len(2, 3) - g.upper_arm_mm).abs() < 1e-9,
                "{name}: upper arm"
            );
            assert!((len(3, 4) - g.elbow_offset_mm.abs()).abs() < 1e-9);
            assert!((len(4, 5) - g.forearm_mm).abs() < 1e-9, "{name}: forearm");
            assert!((len(5, 6) - g.wrist_to_flange_mm).abs() < 1e-9);
        }
    }
}

#[test]
fn the_drawn_cell_puts_the_torch_tip_on_the_path_point() {
    let p = CellPoint {
        position_mm: Point3::new(30.0, 10.0, 20.0),
        tool_axis: UnitVector3::new_normalize(Vector3::new(0.2, 0.1, 1.0)),
        build_direction: Some(UnitVector3::new_normalize(Vector3::new(0.2, 0.1, 1.0))),
        positioner: None,
        travel_speed_mm_s: 6.0,
    };
    for name in [
        "robowam_part_carried.toml",
        "robowam_torch_carried.toml",
        "kuka_kr16_2_torch_carried.toml",
    ] {
        let c = cell(name);
        let (q, pose) = c.joints(&p, 0.2, None, 0.0).unwrap();
        let s = snapshot(&c, Some(&q), pose.positioner.as_ref(), &p, 0.2);
        let base_from_part = s.base_from_part.unwrap();
        // the deposition point, where the drawn torch tip is
        let m = base_from_part * p.position_mm;
        assert!(
            (m - s.torch[0]).norm() < 1e-6,
            "{name}: torch tip {m} vs {}",
            s.torch[0]
        );
        let chain = s.chain.unwrap();
        if matches!(c, CellLayout::TorchCarried(_)) {
            assert!((chain[7] - m).norm() < 1e-6, "{name}: TCP on the point");
            // the torch body goes up the tool axis
            let t = base_from_part.rotation * p.tool_axis.into_inner();
            assert!(((s.torch[1] - s.torch[0]).normalize() - t).norm() < 1e-9);
            assert!(s.positioner.is_some());
        }
    }
}

#[test]
fn report_is_self_contained_and_fills_every_slot() {
    let (path, frames, map) = cylinder(6, 40, 20.0, 2.0);
    let input = ReportInput::new("cyl <test> & \"q\"", &path, &frames, &map, 3.0);
    let html = report_html(&input).unwrap();
    assert!(!html.contains("{{"), "a template slot is left");
    for bad in ["http://", "https://", "<link", " src=", "@import", "url("] {
        assert!(!html.contains(bad), "the page contains `{bad}`");
    }
    assert!(
        html.contains("<title>cyl &lt;test&gt; &amp; &quot;q&quot; — waam-slicer report</title>")
    );
    // one data element, one script
    assert_eq!(html.matches("</script>").count(), 2);
    assert!(html.contains("\"points_total\":240"));
    assert!(html.contains("\"plan\":null"));
}

/// `layer_start` holds each layer's first drawn point, then the total: one
/// entry more than the layers, no more (the viewer reads it by layer).
#[test]
fn layer_start_holds_each_layers_first_point_then_the_total() {
    let (path, frames, map) = cylinder(6, 40, 20.0, 2.0);
    let input = ReportInput::new("cyl", &path, &frames, &map, 3.0);
    let data: serde_json::Value = serde_json::from_str(&report_data(&input).unwrap()).unwrap();
    let starts: Vec<u32> = [0, 40, 80, 120, 160, 200, 240].to_vec();
    let bytes: Vec<u8> = starts.iter().flat_map(|v| v.to_le_bytes()).collect();
    assert_eq!(data["layer_start"].as_str().unwrap(), base64(&bytes));
}

#[test]
fn mismatched_inputs_name_the_input_and_layer() {
    let (path, mut frames, map) = cylinder(4, 10, 20.0, 2.0);
    frames[2].pop();
    let e = report_html(&ReportInput::new("x", &path, &frames, &map, 3.0)).unwrap_err();
    assert_eq!(
        e.to_string(),
        "report: frames has 9 points where the path has 10 (layer 2)"
    );
    frames.pop();
    let e = report_html(&ReportInput::new("x", &path, &frames, &map, 3.0)).unwrap_err();
    assert_eq!(
        e.to_string(),
        "report: frames has 3 layers where the path has 4"
    );
    let (path, mut frames, map) = cylinder(4, 10, 20.0, 2.0);
    frames[1][3].tool.x = f64::NAN;
    let e = report_html(&ReportInput::new("x", &path, &frames, &map, 3.0)).unwrap_err();
    assert_eq!(
        e.to_string(),
        "report: layer 1, point 3: tool axis is not finite"
    );
    let (path, frames, map) = cylinder(4, 10, 20.0, 2.0);
    let e = report_html(&ReportInput::new("x", &path, &frames, &map, f64::NAN)).unwrap_err();
    assert!(e.to_string().contains("bead_width_mm"), "{e}");
}

#[test]
fn write_report_leaves_no_file_on_bad_input() {
    let dir = tempfile::tempdir().unwrap();
    let dest = dir.path().join("report.html");
    let (path, frames, map) = cylinder(3, 10, 20.0, 2.0);
    write_report(&dest, &ReportInput::new("x", &path, &frames, &map, 3.0)).unwrap();
    let first = std::fs::read(&dest).unwrap();
    let e = write_report(
        &dest,
        &ReportInput::new("x", &path, &frames[..2], &map, 3.0),
    );
    assert!(e.is_err());
    assert_eq!(std::fs::read(&dest).unwrap(), first, "old report kept");
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
}

/// Size and time of a 1 M-point report: the page must stay small enough to
/// open in seconds. Numbers printed with `--nocapture`.
#[test]
fn a_million_point_path_gives_a_bounded_page() {
    let (path, frames, map) = cylinder(500, 2000, 60.0, 1.0);
    assert_eq!(path.num_points(), 1_000_000);
    let t0 = std::time::Instant::now();
    let html = report_html(&ReportInput::new("big", &path, &frames, &map, 2.0)).unwrap();
    let dt = t0.elapsed().as_secs_f64();
    println!(
        "1 M points: {:.2} MB of HTML in {dt:.2} s",
        html.len() as f64 / 1e6
    );
    assert!(html.len() < 12_000_000, "{} bytes", html.len());
    assert!(html.contains("\"points_shown\":200500"));
    assert!(html.contains("every 5th point of each layer"));
    // generous: debug builds; the release figure is in the report's docs
    assert!(dt < 30.0, "{dt} s");
}
