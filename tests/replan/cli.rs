//! `waam replan`: a good scan writes joints.csv with the corrected speeds,
//! summary.json with the error per layer and the program that resumes the
//! build (exit 0); a scan of another layer is refused (exit 1) naming the
//! distance.

use crate::common::{part_path, waam};
use crate::support::*;
use std::io::Write;

fn write_scan(path: &std::path::Path, points: &[waam_slicer::math::Point3]) {
    let mut f = std::fs::File::create(path).unwrap();
    writeln!(f, "# synthetic scan\nx,y,z").unwrap();
    for p in points {
        writeln!(f, "{:.4},{:.4},{:.4}", p.x, p.y, p.z).unwrap();
    }
}

#[test]
fn replan_writes_the_remaining_layers_and_refuses_a_scan_of_another_layer() {
    let part = part("elbow.toml");
    let sliced = nominal(&part, &elbow_opts(96, 14));
    let (scan, _) = synthetic_scan(
        &sliced,
        K,
        &Field {
            high: 0.8,
            low: -0.5,
        },
        1,
    );
    let dir = tempfile::tempdir().unwrap();
    let good = dir.path().join("scan.csv");
    write_scan(&good, &scan);
    let out = dir.path().join("out");
    let run = |scan: &std::path::Path| {
        waam()
            .args(["replan", "--quiet"])
            .arg(part_path("elbow.toml"))
            .arg("--cell")
            .arg(part_path("cells/robowam_part_carried.toml"))
            .arg("--measured")
            .arg(scan)
            .args([
                "--after-layer",
                "10",
                "--points",
                "96",
                "--max-layers",
                "14",
                "--out",
            ])
            .arg(&out)
            .output()
            .unwrap()
    };
    let o = run(&good);
    assert_eq!(
        o.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    let csv = std::fs::read_to_string(out.join("joints.csv")).unwrap();
    let mut lines = csv.lines();
    assert_eq!(
        lines.next().unwrap(),
        "layer,point,x,y,z,tx,ty,tz,rz_deg,j1,j2,j3,j4,j5,j6,travel_speed_mm_s,bead_height_mm,bead,wire_feed_mm_s"
    );
    assert!(lines.next().unwrap().starts_with("11,0,"));
    assert_eq!(csv.lines().count(), 1 + 3 * 96);
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    let layers = summary["replan"]["layers"].as_array().unwrap();
    assert_eq!(layers.len(), 3);
    assert_eq!(summary["replan"]["scan"]["outliers"], STRAYS);
    assert!(layers[0]["error_before"]["max_mm"].as_f64().unwrap() > 0.7);
    assert!(out.join("ELBOW_FROM_11.ls").exists());
    let html = std::fs::read_to_string(out.join("report.html")).unwrap();
    assert!(html.contains("replanned from the scan of layer 10"));

    // the scan of layer 11 given as layer 10's
    let wrong = dir.path().join("wrong.csv");
    let pts: Vec<_> = sliced.path.layers[K + 1]
        .points
        .iter()
        .map(|p| p.position)
        .collect();
    write_scan(&wrong, &pts);
    let o = run(&wrong);
    assert_eq!(o.status.code(), Some(1));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("median height error is +2.000 mm"), "{err}");
}
