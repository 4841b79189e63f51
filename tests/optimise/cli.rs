//! The `waam plan` command of the CLI example.

use crate::common::{part_path, waam};

fn plan(rz: &str, out: &std::path::Path) -> std::process::ExitStatus {
    waam()
        .args(["--quiet", "plan"])
        .arg(part_path("hemisphere.toml"))
        .arg("--cell")
        .arg(part_path("cells/robowam_part_carried.toml"))
        .args(["--points", "120", "--rz", rz, "--out"])
        .arg(out)
        .status()
        .unwrap()
}

#[test]
fn plan_refuses_fixed_zero_and_succeeds_with_a_linear_law() {
    let dir = tempfile::tempdir().unwrap();
    let bad = dir.path().join("fixed");
    assert_eq!(plan("fixed:0", &bad).code(), Some(2));
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(bad.join("summary.json")).unwrap()).unwrap();
    assert_eq!(summary["feasible"], false);
    assert!(summary["violations"][0].as_str().unwrap().contains("J5"));
    let programs = std::fs::read_dir(&bad)
        .unwrap()
        .filter(|e| {
            let n = e.as_ref().unwrap().file_name();
            let n = n.to_string_lossy();
            n.ends_with(".ls") || n.ends_with(".src") || n.ends_with(".mod")
        })
        .count();
    assert_eq!(programs, 0);

    let good = dir.path().join("poly");
    assert_eq!(plan("poly:1", &good).code(), Some(0));
    let text = std::fs::read_to_string(good.join("joints.csv")).unwrap();
    assert_eq!(
        text.lines().next().unwrap(),
        "layer,point,x,y,z,tx,ty,tz,rz_deg,j1,j2,j3,j4,j5,j6"
    );
    assert!(text.lines().count() > 14 * 120);
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(good.join("summary.json")).unwrap()).unwrap();
    assert_eq!(summary["feasible"], true);
}

#[test]
fn plan_names_the_bad_file_and_field() {
    let dir = tempfile::tempdir().unwrap();
    let out = waam()
        .args(["plan"])
        .arg(part_path("hemisphere.toml"))
        .arg("--cell")
        .arg(part_path("hemisphere.toml"))
        .arg("--out")
        .arg(dir.path())
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr).contains("hemisphere.toml"));
    let out = waam()
        .args(["plan"])
        .arg(part_path("hemisphere.toml"))
        .arg("--cell")
        .arg(part_path("cells/robowam_part_carried.toml"))
        .args(["--rz", "cubic"])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr).contains("--rz"));
}
