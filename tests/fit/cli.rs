//! `waam fit`: writes part.toml and fit.json that `waam slice` takes; refuses
//! a blob with exit 1, naming the file.

use crate::common::waam;
use crate::gen;

#[test]
fn fit_writes_a_part_that_slices() {
    let dir = tempfile::tempdir().unwrap();
    let (v, f) = gen::mesh(&gen::s_bend(), 1.5, 0.05, 0.0, 2);
    let stl = dir.path().join("s-bend.stl");
    std::fs::write(&stl, gen::binary_stl(&v, &f)).unwrap();
    let out = dir.path().join("fit");
    let done = waam()
        .args(["--quiet", "fit"])
        .arg(&stl)
        .arg("--out")
        .arg(&out)
        .args(["--start", "lowest"])
        .output()
        .unwrap();
    assert!(
        done.status.success(),
        "{}",
        String::from_utf8_lossy(&done.stderr)
    );
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("fit.json")).unwrap()).unwrap();
    assert!(report["rms_mm"].as_f64().unwrap() < 0.1, "{report}");
    assert_eq!(report["start"]["kind"], "open", "{report}");
    assert_eq!(report["end"]["oblique"], false, "{report}");
    let text = std::fs::read_to_string(out.join("part.toml")).unwrap();
    assert!(
        text.contains("kind = \"spline\"") && text.contains("name = \"s-bend\""),
        "{text}"
    );
    slices_and_plans(dir.path(), &out.join("part.toml"), &["--no-wall"], "part");
}

/// `slice` slices the fitted `part` (with `flags`) and `plan` takes it as
/// it is in the `carried`-carried RoboWAM cell: planned (exit 0) or refused
/// by the cell (exit 2), never bad input (exit 1).
fn slices_and_plans(dir: &std::path::Path, part: &std::path::Path, flags: &[&str], carried: &str) {
    let sliced = dir.join("sliced");
    let done = waam()
        .args(["--quiet", "slice"])
        .arg(part)
        .args(["--points", "60"])
        .args(flags)
        .arg("--out")
        .arg(&sliced)
        .output()
        .unwrap();
    assert!(
        done.status.success(),
        "{}",
        String::from_utf8_lossy(&done.stderr)
    );
    assert!(sliced.join("path.csv").exists());
    let planned = dir.join("planned");
    let done = waam()
        .args(["--quiet", "plan"])
        .arg(part)
        .arg("--cell")
        .arg(crate::common::part_path(&format!(
            "cells/robowam_{carried}_carried.toml"
        )))
        .args(["--points", "40", "--delta", "6", "--out"])
        .arg(&planned)
        .output()
        .unwrap();
    assert!(
        matches!(done.status.code(), Some(0 | 2)),
        "{}",
        String::from_utf8_lossy(&done.stderr)
    );
    assert!(planned.join("summary.json").exists());
}

/// The printout names each end's kind and cut.
#[test]
fn fit_prints_the_ends() {
    let dir = tempfile::tempdir().unwrap();
    let (v, f) = gen::oblique_pipe(12.0, 60.0, 30.0, 96, 1.0);
    let stl = dir.path().join("oblique.stl");
    std::fs::write(&stl, gen::binary_stl(&v, &f)).unwrap();
    let done = waam()
        .arg("fit")
        .arg(&stl)
        .arg("--out")
        .arg(dir.path().join("o"))
        .output()
        .unwrap();
    let out = String::from_utf8_lossy(&done.stdout);
    assert!(
        done.status.success(),
        "{}",
        String::from_utf8_lossy(&done.stderr)
    );
    assert!(
        out.contains("start       open, square (tilt 0.0 deg), station 0")
            && out.contains("end         open, cut obliquely (tilt 30.0 deg), station "),
        "{out}"
    );
}

#[test]
fn fit_refuses_a_blob_naming_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let (v, f) = gen::sphere(15.0, 16);
    let stl = dir.path().join("blob.stl");
    std::fs::write(&stl, gen::binary_stl(&v, &f)).unwrap();
    let done = waam()
        .arg("fit")
        .arg(&stl)
        .arg("--out")
        .arg(dir.path().join("o"))
        .output()
        .unwrap();
    assert_eq!(done.status.code(), Some(1));
    let err = String::from_utf8_lossy(&done.stderr);
    assert!(
        err.contains("blob.stl") && err.contains("not a tube"),
        "{err}"
    );
    assert!(!dir.path().join("o").join("part.toml").exists());
}

/// `--trim` fits the pipe beside a flange and names it; without it the
/// flange is refused (exit 1).
#[test]
fn fit_trim_names_the_feature_left_out() {
    let dir = tempfile::tempdir().unwrap();
    let (v, f) = gen::collared_pipe(10.0, 80.0, 25.0, 38.0, 41.0, 64, 1.0);
    let stl = dir.path().join("flange.stl");
    std::fs::write(&stl, gen::binary_stl(&v, &f)).unwrap();
    let run = |trim: bool| {
        let mut c = waam();
        c.arg("fit")
            .arg(&stl)
            .arg("--out")
            .arg(dir.path().join("o"));
        if trim {
            c.arg("--trim");
        }
        c.output().unwrap()
    };
    let refused = run(false);
    assert_eq!(refused.status.code(), Some(1));
    let err = String::from_utf8_lossy(&refused.stderr);
    assert!(err.contains("not a tube: a flange at stations"), "{err}");
    let done = run(true);
    let out = String::from_utf8_lossy(&done.stdout);
    assert!(
        done.status.success(),
        "{}",
        String::from_utf8_lossy(&done.stderr)
    );
    assert!(
        out.contains("left out    a flange from 38.00 to 41.00 mm"),
        "{out}"
    );
    let report: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(dir.path().join("o").join("fit.json")).unwrap(),
    )
    .unwrap();
    assert_eq!(report["features"][0]["kind"], "flange", "{report}");
    assert_eq!(report["start"]["kind"], "trimmed", "{report}");
}

/// A flanged elbow exported as a solid (the generator's elbow as a wall of
/// mid-surface radius 11, 2 mm thick, flanges of radius 30 and 3 mm at both
/// ends), end to end: `fit --trim` names both flanges left out and writes
/// the tube between them with its wall, which `slice` slices and `plan`
/// plans in the torch-carried cell (planned or refused by the cell, exit 0
/// or 2, never bad input).
#[test]
fn a_flanged_solid_elbow_is_trimmed_sliced_and_planned() {
    let dir = tempfile::tempdir().unwrap();
    let truth = gen::elbow_wall();
    let l = truth.length;
    let (v, f) = gen::flanged_wall(&truth, 1.0, &[(0.0, 3.0, 30.0), (l - 3.0, l, 30.0)], 64);
    let stl = dir.path().join("spool.stl");
    std::fs::write(&stl, gen::binary_stl(&v, &f)).unwrap();
    let out = dir.path().join("fit");
    let done = waam()
        .arg("fit")
        .arg(&stl)
        .arg("--trim")
        .arg("--out")
        .arg(&out)
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&done.stdout);
    assert!(
        done.status.success(),
        "{}",
        String::from_utf8_lossy(&done.stderr)
    );
    assert_eq!(
        text.matches("left out    a flange from").count(),
        2,
        "{text}"
    );
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("fit.json")).unwrap()).unwrap();
    assert_eq!(report["start"]["kind"], "trimmed", "{report}");
    assert_eq!(report["end"]["kind"], "trimmed", "{report}");
    let wall = report["wall"]["mean_mm"].as_f64().unwrap();
    assert!((wall - 2.0).abs() < 0.01, "{report}");
    slices_and_plans(dir.path(), &out.join("part.toml"), &[], "torch");
}
