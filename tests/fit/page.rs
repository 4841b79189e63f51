//! `waam fit` writes `report.html`: its page data holds one distance per
//! mesh vertex, and these distances, recomputed here from the vertices and
//! the written part (guide and radius law, not the fit's code), give the
//! RMS and largest distance that `fit.json` reports.

use crate::common::waam;
use crate::gen;
use waam_slicer::io::part_file::read_part_file;
use waam_slicer::math::Point3;

/// The page's embedded data object.
pub fn page_data(html: &str) -> serde_json::Value {
    let open = "<script type=\"application/json\" id=\"report-data\">";
    let start = html.find(open).expect("no page data") + open.len();
    let end = start + html[start..].find("</script>").expect("unclosed page data");
    serde_json::from_str(&html[start..end]).expect("page data is JSON")
}

/// Standard base64 (RFC 4648, padded), decoded by hand.
fn base64(text: &str) -> Vec<u8> {
    let value = |c: u8| -> u32 {
        match c {
            b'A'..=b'Z' => u32::from(c - b'A'),
            b'a'..=b'z' => u32::from(c - b'a') + 26,
            b'0'..=b'9' => u32::from(c - b'0') + 52,
            b'+' => 62,
            b'/' => 63,
            other => panic!("not base64: {}", other as char),
        }
    };
    let mut out = Vec::new();
    for chunk in text.as_bytes().chunks(4) {
        let pad = chunk.iter().filter(|&&c| c == b'=').count();
        let n = chunk
            .iter()
            .map(|&c| if c == b'=' { 0 } else { value(c) })
            .fold(0u32, |a, v| (a << 6) | v);
        out.extend(&n.to_be_bytes()[1..4 - pad]);
    }
    out
}

/// A base64 little-endian `Float32Array`.
pub fn f32s(text: &str) -> Vec<f32> {
    base64(text)
        .chunks_exact(4)
        .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
        .collect()
}

/// Distance of `p` to the tube of `part` (guide and radius law as read
/// from the part file): the nearest guide point by a scan every 0.05 mm
/// over the range and 2 radii past each end, then golden-section search.
fn distance_to_tube(part: &waam_slicer::io::part_file::Part, p: &Point3, margin: f64) -> f64 {
    let tube = &part.tube;
    let g = tube.guide();
    let r = tube.range();
    let (lo, hi) = (r.t_min - margin, r.t_max + margin);
    let n = ((hi - lo) / 0.05).ceil() as usize;
    let d2 = |t: f64| (g.point(t) - p).norm_squared();
    let best = (0..=n)
        .map(|i| lo + (hi - lo) * i as f64 / n as f64)
        .min_by(|a, b| d2(*a).total_cmp(&d2(*b)))
        .unwrap();
    let h = (hi - lo) / n as f64;
    let (mut a, mut b) = ((best - h).max(lo), (best + h).min(hi));
    let phi = 0.5 * (5f64.sqrt() - 1.0);
    for _ in 0..60 {
        let (c, d) = (b - phi * (b - a), a + phi * (b - a));
        if d2(c) < d2(d) {
            b = d;
        } else {
            a = c;
        }
    }
    let t = 0.5 * (a + b);
    ((g.point(t) - p).norm() - tube.radius(t)).abs()
}

#[test]
fn the_fit_page_holds_one_distance_per_vertex_matching_fit_json() {
    let dir = tempfile::tempdir().unwrap();
    let truth = gen::elbow();
    let (v, f) = gen::mesh(&truth, 1.5, 0.05, 0.0, 11);
    let stl = dir.path().join("elbow.stl");
    std::fs::write(&stl, gen::binary_stl(&v, &f)).unwrap();
    let out = dir.path().join("fit");
    let done = waam()
        .args(["--quiet", "fit"])
        .arg(&stl)
        .arg("--out")
        .arg(&out)
        .output()
        .unwrap();
    assert!(
        done.status.success(),
        "{}",
        String::from_utf8_lossy(&done.stderr)
    );
    let html = std::fs::read_to_string(out.join("report.html")).unwrap();
    assert!(!html.contains("http://") && !html.contains("https://"));
    let data = page_data(&html);
    let fit = &data["fit"];
    let vertices = f32s(fit["vertices"].as_str().unwrap());
    let field = data["fields"]
        .as_array()
        .unwrap()
        .iter()
        .find(|f| f["key"] == "distance")
        .expect("a distance field");
    assert_eq!(field["mesh"], true, "{field}");
    let dist = f32s(field["data"].as_str().unwrap());
    // One vertex and one distance per vertex of the mesh written.
    assert_eq!(vertices.len(), 3 * v.len());
    assert_eq!(dist.len(), v.len());
    assert_eq!(fit["vertices_total"].as_u64(), Some(v.len() as u64));
    assert!(dist.iter().all(|d| d.is_finite() && *d >= 0.0));

    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("fit.json")).unwrap()).unwrap();
    let (rms_json, max_json) = (
        report["rms_mm"].as_f64().unwrap(),
        report["max_mm"].as_f64().unwrap(),
    );
    // The page's distances give fit.json's figures (f32 rounding).
    let rms_page =
        (dist.iter().map(|&d| f64::from(d).powi(2)).sum::<f64>() / dist.len() as f64).sqrt();
    let max_page = dist.iter().copied().fold(0.0f32, f32::max) as f64;
    assert!((rms_page - rms_json).abs() < 1e-6, "{rms_page} {rms_json}");
    assert!((max_page - max_json).abs() < 1e-6, "{max_page} {max_json}");

    // Recomputed here from the vertices and the written part.
    let part = read_part_file(&out.join("part.toml")).unwrap();
    let ours: Vec<f64> = vertices
        .chunks_exact(3)
        .map(|c| {
            let p = Point3::new(f64::from(c[0]), f64::from(c[1]), f64::from(c[2]));
            distance_to_tube(&part, &p, 24.0)
        })
        .collect();
    let worst = ours
        .iter()
        .zip(&dist)
        .map(|(a, &b)| (a - f64::from(b)).abs())
        .fold(0.0, f64::max);
    let rms_ours = (ours.iter().map(|d| d * d).sum::<f64>() / ours.len() as f64).sqrt();
    let max_ours = ours.iter().copied().fold(0.0, f64::max);
    eprintln!(
        "fit page: {} vertices; RMS {rms_json:.5} (ours {rms_ours:.5}), max {max_json:.5} (ours {max_ours:.5}) mm; largest per-vertex difference {worst:.2e} mm",
        v.len()
    );
    assert!(worst < 1e-3, "per-vertex distances differ by {worst} mm");
    assert!((rms_ours - rms_json).abs() < 1e-4, "{rms_ours} {rms_json}");
    assert!((max_ours - max_json).abs() < 1e-3, "{max_ours} {max_json}");
    // The noise is seen: the distances are not all zero.
    assert!(rms_json > 0.02 && max_json > 2.0 * rms_json, "{report}");
}
