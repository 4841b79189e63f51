//! The `waam slice` command of the CLI example writes `path.csv` with the
//! contract's columns for every strategy; reading it back gives the same
//! distance map (so anyone can check the figures from outside).

use crate::common::{part_path, waam};
use waam_slicer::io::path_csv::{read_path_csv, HEADER};
use waam_slicer::path::distance_map::distance_map_of;

#[test]
fn slice_writes_path_csv_for_every_strategy() {
    let dir = tempfile::tempdir().unwrap();
    for strategy in ["constant", "iso", "perpendicular", "planar"] {
        let out = dir.path().join(strategy);
        let status = waam()
            .args(["--quiet", "slice"])
            .arg(part_path("quarter-torus.toml"))
            .args([
                "--strategy",
                strategy,
                "--delta",
                "5",
                "--points",
                "120",
                "--out",
            ])
            .arg(&out)
            .status()
            .unwrap();
        assert!(status.success(), "{strategy}");
        let text = std::fs::read_to_string(out.join("path.csv")).unwrap();
        assert_eq!(text.lines().next().unwrap(), HEADER);
        let first = text.lines().nth(1).unwrap();
        assert_eq!(
            first.split(',').nth(7),
            Some(""),
            "delta empty on the first layer"
        );
        let layers = read_path_csv(&text, "path.csv").unwrap();
        assert!(layers.len() > 5);
        // Distances recomputed from the file match the column written.
        let map = distance_map_of(&layers, 5.0);
        let written: Vec<Option<f64>> = text
            .lines()
            .skip(1)
            .map(|l| l.split(',').nth(7).unwrap().parse::<f64>().ok())
            .collect();
        let recomputed: Vec<Option<f64>> = map
            .points
            .iter()
            .flatten()
            .map(|d| d.map(|d| d.0))
            .collect();
        assert_eq!(written.len(), recomputed.len());
        for (w, r) in written.iter().zip(&recomputed) {
            match (w, r) {
                (Some(w), Some(r)) => assert!((w - r).abs() < 1e-5, "{strategy}: {w} vs {r}"),
                (None, None) => {}
                other => panic!("{strategy}: {other:?}"),
            }
        }
        // The other outputs: pictures and the wall mesh, which reads back as an STL.
        for f in ["path.svg", "distance.svg"] {
            let svg = std::fs::read_to_string(out.join(f)).unwrap();
            assert!(
                svg.starts_with("<svg") && svg.trim_end().ends_with("</svg>"),
                "{f}"
            );
        }
        let stl = std::fs::read(out.join("wall.stl")).unwrap();
        let mesh = waam_slicer::geometry::MeshSubstrate::from_stl_bytes(&stl, "wall.stl").unwrap();
        assert!(
            mesh.num_triangles()
                >= 8 * (layers.iter().map(|l| l.points.len()).sum::<usize>() - layers.len())
        );
        let summary: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap())
                .unwrap();
        assert_eq!(summary["strategy"], strategy);
        assert!(summary["points"].as_u64().unwrap() > 0);
    }
}

#[test]
fn slice_reports_bad_input_with_exit_code_1() {
    let dir = tempfile::tempdir().unwrap();
    let bad = dir.path().join("bad.toml");
    std::fs::write(&bad, "name = \"x\"\n[guide]\nkind = \"line\"\n").unwrap();
    let out = waam().args(["slice"]).arg(&bad).output().unwrap();
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("bad.toml"), "{err}");
    let out = waam()
        .args(["slice"])
        .arg(part_path("hemisphere.toml"))
        .args(["--delta=-2"])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr).contains("delta_mm"));
}

#[test]
fn path_csv_reader_names_the_bad_line() {
    let e = read_path_csv("layer,x,y,z\n0,1,2,3\n0,1,x,3\n", "p.csv").unwrap_err();
    assert_eq!(e.line, 3);
    assert!(e.to_string().contains("p.csv, line 3"));
    let e = read_path_csv("layer,x,y,z\n1,1,2,3\n0,1,2,3\n", "p.csv").unwrap_err();
    assert!(e.to_string().contains("layer 0 after layer 1"));
    assert!(read_path_csv("a,b\n", "p.csv").is_err());
}

/// `plan` writes a FANUC program for a feasible plan, `check` accepts it, and
/// rejects it once a joint is pushed out of range (exit 2, naming the line).
#[test]
fn plan_writes_a_program_that_check_accepts_and_a_corrupted_one_it_rejects() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("plan");
    let cell = crate::common::part_path("cells/robowam_part_carried.toml");
    let status = waam()
        .args(["--quiet", "plan"])
        .arg(part_path("hemisphere.toml"))
        .arg("--cell")
        .arg(&cell)
        .args(["--points", "60", "--rz", "poly:1", "--out"])
        .arg(&out)
        .status()
        .unwrap();
    assert_eq!(status.code(), Some(0));
    for f in ["joints.csv", "summary.json", "joints.svg", "speeds.svg"] {
        assert!(out.join(f).exists(), "{f}");
    }
    let ls = out.join("HEMISPHERE.ls");
    let ok = waam()
        .args(["--quiet", "check"])
        .arg(&ls)
        .arg("--cell")
        .arg(&cell)
        .status()
        .unwrap();
    assert_eq!(ok.code(), Some(0));
    let text = std::fs::read_to_string(&ls).unwrap();
    let bad = text.replacen("J5=   ", "J5=   17", 1); // e.g. 119.3 deg becomes 17119.3 deg
    let corrupt = dir.path().join("BAD.ls");
    std::fs::write(&corrupt, bad.replace("/PROG  HEMISPHERE", "/PROG  BAD")).unwrap();
    let out = waam()
        .args(["check"])
        .arg(&corrupt)
        .arg("--cell")
        .arg(&cell)
        .output()
        .unwrap();
    assert_eq!(
        out.status.code(),
        Some(2),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let err = String::from_utf8_lossy(&out.stderr);
    // file:line: what (the first position, an approach point, had J5 = 120.6°)
    assert!(err.contains("J5 = 17") && err.contains("BAD:"), "{err}");
}

/// The tool-axis and process flags reach the outputs: `--max-lean 50` keeps
/// every tool axis of path.csv within 50° of Z (the hemisphere's `b` reaches
/// 86°), `--plain-axes` drops the quarter torus's rate bound (its cusps come
/// back), `--process pla --travel-speed 5` changes the time estimate by the
/// speed ratio.
#[test]
fn slice_applies_the_tool_axis_and_process_settings() {
    let dir = tempfile::tempdir().unwrap();
    let run = |part: &str, out: &str, extra: &[&str]| -> serde_json::Value {
        let out = dir.path().join(out);
        let status = waam()
            .args(["--quiet", "slice"])
            .arg(part_path(part))
            .args(["--points", "120", "--out"])
            .arg(&out)
            .args(extra)
            .status()
            .unwrap();
        assert!(status.success(), "{part} {extra:?}");
        let text = std::fs::read_to_string(out.join("path.csv")).unwrap();
        let mut lean: f64 = 0.0;
        for line in text.lines().skip(1) {
            let tz: f64 = line.split(',').nth(16).unwrap().parse().unwrap();
            lean = lean.max(tz.clamp(-1.0, 1.0).acos().to_degrees());
        }
        let mut s: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap())
                .unwrap();
        s["lean_from_csv_deg"] = lean.into();
        s
    };
    let plain = run("hemisphere.toml", "h0", &[]);
    let ruled = run("hemisphere.toml", "h50", &["--max-lean", "50"]);
    assert!(plain["lean_from_csv_deg"].as_f64().unwrap() > 80.0);
    assert!(ruled["lean_from_csv_deg"].as_f64().unwrap() <= 50.0 + 1e-4);
    assert!(ruled["tool_axes"]["rule_active_points"].as_u64().unwrap() > 0);
    assert_eq!(plain["process"]["material"], "PLA");

    let bounded = run("quarter-torus.toml", "t", &[]);
    let cusps = run("quarter-torus.toml", "t0", &["--plain-axes"]);
    let rate = |s: &serde_json::Value| s["tool_axes"]["max_rate_deg_per_mm"].as_f64().unwrap();
    assert!(rate(&bounded) <= 10.0 * (1.0 + 1e-6), "{}", rate(&bounded));
    assert!(rate(&cusps) > 30.0, "{}", rate(&cusps));

    let slow = run(
        "quarter-torus.toml",
        "t5",
        &["--process", "pla", "--travel-speed", "3"],
    );
    let time = |s: &serde_json::Value| s["process"]["deposition_time_s"].as_f64().unwrap();
    assert!((time(&slow) / time(&bounded) - 2.0).abs() < 1e-9);
}

/// KUKA and ABB end to end: the nozzle planned in the example KUKA
/// torch-carried cell (`--format kuka`) and the example ABB part-carried
/// cell (`--format abb`) gives programs that `check` accepts; a joint pushed
/// out of its travel in the KUKA `.dat` is named by file and line (exit 2).
/// Without `--format` the cell robot's vendor's format is written; another
/// vendor's format is refused before planning (exit 2, no program).
#[test]
fn kuka_and_abb_plans_pass_check() {
    let dir = tempfile::tempdir().unwrap();
    for (format, cell, vendor) in [
        ("fanuc", "cells/kuka_kr16_2_torch_carried.toml", "KUKA"),
        ("abb", "cells/kuka_kr16_2_torch_carried.toml", "KUKA"),
        ("kuka", "cells/robowam_part_carried.toml", "FANUC"),
    ] {
        let out = dir.path().join(format!("mismatch_{format}"));
        let run = waam()
            .args(["--quiet", "plan"])
            .arg(part_path("nozzle.toml"))
            .arg("--cell")
            .arg(part_path(cell))
            .args(["--delta", "5", "--points", "60", "--format", format])
            .arg("--out")
            .arg(&out)
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&run.stderr);
        assert_eq!(run.status.code(), Some(2), "{format} in {cell}: {err}");
        assert!(
            err.contains(&format!("--format {format}"))
                && err.contains(&format!("has vendor {vendor} ")),
            "{err}"
        );
        assert!(
            !out.exists(),
            "{format} in {cell}: nothing planned or written"
        );
    }
    for (format, cell, program) in [
        ("kuka", "cells/kuka_kr16_2_torch_carried.toml", "NOZZLE.src"),
        ("abb", "cells/abb_irb2600_part_carried.toml", "NOZZLE.mod"),
    ] {
        let out = dir.path().join(format);
        let cell = part_path(cell);
        // the KUKA cell without `--format`: the default follows the vendor
        let format_args: &[&str] = if format == "kuka" {
            &[]
        } else {
            &["--format", format]
        };
        let status = waam()
            .args(["--quiet", "plan"])
            .arg(part_path("nozzle.toml"))
            .arg("--cell")
            .arg(&cell)
            .args(["--delta", "5", "--points", "60"])
            .args(format_args)
            .arg("--out")
            .arg(&out)
            .status()
            .unwrap();
        assert_eq!(status.code(), Some(0), "{format}");
        let check = |file: &std::path::Path| {
            waam()
                .args(["check"])
                .arg(file)
                .arg("--cell")
                .arg(&cell)
                .output()
                .unwrap()
        };
        let ok = check(&out.join(program));
        assert_eq!(
            ok.status.code(),
            Some(0),
            "{format}: {}",
            String::from_utf8_lossy(&ok.stderr)
        );
        if format == "kuka" {
            let dat = out.join("NOZZLE.dat");
            let text = std::fs::read_to_string(&dat).unwrap();
            let at = text.find("A5 ").expect("an E6AXIS or E6POS with A5") + 3;
            let end = at + text[at..].find([',', '}']).unwrap();
            std::fs::write(&dat, format!("{}175.0{}", &text[..at], &text[end..])).unwrap();
            let bad = check(&out.join(program));
            let err = String::from_utf8_lossy(&bad.stderr);
            assert_eq!(bad.status.code(), Some(2), "{err}");
            assert!(
                err.contains("NOZZLE.dat:") && err.contains("J5 = 175"),
                "{err}"
            );
        }
    }
}
