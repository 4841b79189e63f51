//! The `waam plan` command of the CLI example.

use crate::common::{part_path, waam};

fn plan(rz: &str, out: &std::path::Path) -> std::process::ExitStatus {
    plan_at(rz, 120, out)
}

fn plan_at(rz: &str, points: usize, out: &std::path::Path) -> std::process::ExitStatus {
    waam()
        .args(["--quiet", "plan"])
        .arg(part_path("hemisphere.toml"))
        .arg("--cell")
        .arg(part_path("cells/robowam_part_carried.toml"))
        .args(["--points", &points.to_string(), "--rz", rz, "--out"])
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
        "layer,point,x,y,z,tx,ty,tz,rz_deg,j1,j2,j3,j4,j5,j6,travel_speed_mm_s,bead_height_mm,bead,wire_feed_mm_s"
    );
    assert!(text.lines().count() > 14 * 120);
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(good.join("summary.json")).unwrap()).unwrap();
    assert_eq!(summary["feasible"], true);
    // 120 points a layer: every layer optimised on every point.
    let layers = summary["layer_plans"].as_array().unwrap();
    assert!(layers.iter().all(|l| l["solver"]["samples"].is_null()));
    // Every stage and writer timed.
    for stage in [
        "read",
        "slice",
        "tool_axes",
        "optimise",
        "program",
        "joints_csv",
        "pictures",
        "report_html",
        "program_files",
    ] {
        let t = summary["run_time_s"][stage].as_f64();
        assert!(t.is_some_and(|t| t >= 0.0), "run_time_s.{stage}: {t:?}");
    }

    // 400 points a layer: subsampled (more than 128), fewer samples than
    // points on every layer, certified: feasible with a program.
    let many = dir.path().join("many");
    assert_eq!(plan_at("poly:1", 400, &many).code(), Some(0));
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(many.join("summary.json")).unwrap()).unwrap();
    let layers = summary["layer_plans"].as_array().unwrap();
    for l in layers {
        let n = l["solver"]["samples"].as_u64().expect("subsampled layer");
        assert!((3..400).contains(&n), "{l}");
    }
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

/// Issue 4's "every sample part that should be feasible is": all eight
/// sample parts, sliced at Delta = 5 mm with their own `[tool_axis]` and
/// `[process]` tables, plan in the ROBOWAM part-carried cell (the cell the
/// thesis built its tubes in) and get a FANUC program that `check` accepts.
/// Without the tool-axis rate bound (`--plain-axes`) the wrist would have to
/// turn faster than J4/J6 can at the cusps of the quarter torus's upper
/// layers: the torch slows there (issue 45; before, exit 2).
#[test]
fn every_sample_part_plans_in_the_part_carried_cell() {
    let dir = tempfile::tempdir().unwrap();
    let cell = part_path("cells/robowam_part_carried.toml");
    for part in crate::common::SAMPLE_PARTS {
        let out = dir.path().join(part);
        let status = waam()
            .args(["--quiet", "plan"])
            .arg(part_path(part))
            .arg("--cell")
            .arg(&cell)
            .args(["--delta", "5", "--out"])
            .arg(&out)
            .status()
            .unwrap();
        let summary = std::fs::read_to_string(out.join("summary.json")).unwrap();
        assert_eq!(status.code(), Some(0), "{part}: {summary}");
        checks_clean(&out, &cell, part);
    }
    let out = dir.path().join("plain");
    let status = waam()
        .args(["--quiet", "plan"])
        .arg(part_path("quarter-torus.toml"))
        .arg("--cell")
        .arg(&cell)
        .args(["--plain-axes", "--out"])
        .arg(&out)
        .status()
        .unwrap();
    // with the tool axis along the build direction, the wrist cannot turn
    // through the quarter torus's corners at the process's speed: the torch
    // slows there (before the slowdown, exit 2 on "J4 needs"/"J6 needs"),
    // within the PLA window (3–12 mm/s), and the checker reads the program's
    // slower moves back clean
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    assert_eq!(status.code(), Some(0), "{summary}");
    let slowed = summary["slowed"].as_array().expect("slowed beads");
    assert!(!slowed.is_empty(), "{summary}");
    for s in slowed {
        let why = s["why"].as_str().unwrap();
        assert!(why.contains("J4 speed") || why.contains("J6 speed"), "{s}");
        let v = s["slowest_mm_s"].as_f64().unwrap();
        assert!((3.0..6.0).contains(&v), "{s}");
    }
    checks_clean(&out, &cell, "quarter torus, --plain-axes");
}

/// `waam check` reads the program `plan` wrote in `out` back clean against
/// `cell` (exit 0): the shortest FANUC `.ls`, KUKA `.src` or ABB `.mod`
/// name (NAME.ls; a build cut to the memory budget is NAME_P01.ls,
/// NAME_P02.ls, …, any of which brings the others to `check`).
fn checks_clean(out: &std::path::Path, cell: &std::path::Path, what: &str) {
    let program = std::fs::read_dir(out)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| {
            p.extension()
                .is_some_and(|e| e == "ls" || e == "src" || e == "mod")
        })
        .min_by_key(|p| p.as_os_str().len())
        .unwrap_or_else(|| panic!("{what}: no program"));
    let check = waam()
        .args(["--quiet", "check"])
        .arg(&program)
        .arg("--cell")
        .arg(cell)
        .output()
        .unwrap();
    assert_eq!(
        check.status.code(),
        Some(0),
        "{what}: {}",
        String::from_utf8_lossy(&check.stderr)
    );
}

/// A layer without any joint solution is an answer, not an error (issue 33):
/// the elbow at its own grid in the KUKA torch-carried cell with the thesis's
/// exact-vertical positioner reaches layers whose points the arm cannot
/// reach (before: exit 1, "report: plan has 0 points where the path has
/// 400 (layer 52)", no summary). Now exit 2 with summary.json naming the
/// layer, the point and why, the report and joints written, and no program;
/// with the optimised positioner summary.json names every refused layer with
/// its binding constraint or the geometric bound that proves it unbuildable.
/// The layers keep their aligned seams (`--no-corner-seams`): with seams on
/// their corners (issue 45, the default in a torch-carried cell) layer 52
/// plans and no layer is left without joints.
#[test]
fn a_layer_without_joints_exits_2_with_its_summary_and_report() {
    let dir = tempfile::tempdir().unwrap();
    for (mode, out) in [("vertical", "v"), ("optimised", "o")] {
        let out = dir.path().join(out);
        let o = waam()
            .args(["--quiet", "plan"])
            .arg(part_path("elbow.toml"))
            .arg("--cell")
            .arg(part_path("cells/kuka_kr16_2_torch_carried.toml"))
            .args(["--positioner", mode, "--no-corner-seams", "--out"])
            .arg(&out)
            .output()
            .unwrap();
        assert_eq!(
            o.status.code(),
            Some(2),
            "{mode}: {}",
            String::from_utf8_lossy(&o.stderr)
        );
        for f in ["summary.json", "joints.csv", "report.html"] {
            assert!(out.join(f).exists(), "{mode}: {f} missing");
        }
        // joints.svg draws the positioner's tilt (J7) and turn (J8) too
        let svg = std::fs::read_to_string(out.join("joints.svg")).unwrap();
        assert!(
            svg.contains("\nJ7\n") && svg.contains("\nJ8\n"),
            "{mode}: no positioner panels"
        );
        assert!(!std::fs::read_dir(&out).unwrap().any(|e| {
            let p = e.unwrap().path();
            p.extension().is_some_and(|x| x == "src" || x == "dat")
        }));
        let s: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap())
                .unwrap();
        let infeasible = s["infeasible_layers"].as_array().unwrap();
        assert!(!infeasible.is_empty());
        let plans = s["layer_plans"].as_array().unwrap();
        for l in infeasible {
            let plan = &plans[l.as_u64().unwrap() as usize];
            let status = plan["status"].as_str().unwrap();
            assert!(
                status.starts_with("infeasible: ")
                    || status.starts_with("no joint solution at point"),
                "{mode}: {status}"
            );
        }
        if mode == "vertical" {
            let status = plans[52]["status"].as_str().unwrap();
            assert!(
                status.starts_with("no joint solution at point") && status.contains("out of reach"),
                "{status}"
            );
            assert_eq!(plans[52]["points"], 400);
        } else {
            // every refused layer of the optimised plan here is a corner of
            // b that the positioner's 90 + 180 °/s cannot turn within the cone
            let unbuildable = s["unbuildable_layers"].as_array().unwrap();
            assert!(!unbuildable.is_empty());
            for u in unbuildable {
                let need = u["required_rate_deg_s"].as_f64().unwrap_or(f64::INFINITY);
                let rate = need > u["available_rate_deg_s"].as_f64().unwrap();
                match u["proof"].as_str().unwrap() {
                    "rate" => assert!(rate, "{u}"),
                    "reachability" => assert!(!rate && u["unreachable_point"].is_u64(), "{u}"),
                    other => panic!("{other}"),
                }
            }
            let tilt = plans[10]["positioner"]["max_tilt_deg"].as_f64().unwrap();
            assert!(tilt <= 15.0 + 1e-6, "{tilt}");
        }
    }
}

/// Arc-off transits that one joint move would take through the deposited
/// wall go through via points (issue 45): summary.json names the vias on
/// the bead they leave, and `waam check` reads the programs (KUKA `PTP`,
/// ABB `MoveAbsJ`, FANUC `J P[..]` to each via) back clean, its transit
/// check included. The quarter torus is planned in each torch-carried cell
/// with the retract and approach points at 10 mm, raised at most to 20: its
/// transits from layer 5 (KUKA), 10 (ABB) and 14 (ROBOWAM) on need vias.
/// (The elbow's layer 55 → 56 in the KUKA cell and the S-bend's 111 → 112 in
/// the ABB one needed them at the sample clearances until the positioner's
/// laws converged and turned the table less from one layer to the next.)
#[test]
fn transits_through_via_points_plan_and_check_clean() {
    let dir = tempfile::tempdir().unwrap();
    // The sample cells with the retract and approach points held low.
    let low = |cell: &str| {
        let path = dir.path().join(format!("{cell}_low_clearance.toml"));
        let text = std::fs::read_to_string(part_path(&format!("cells/{cell}.toml"))).unwrap();
        assert!(text.contains("\ntransit_max_clearance_mm = 160.0\n"));
        std::fs::write(
            &path,
            text.replace(
                "\ntransit_max_clearance_mm = 160.0\n",
                "\nclearance_mm = 10.0\ntransit_max_clearance_mm = 20.0\n",
            ),
        )
        .unwrap();
        path
    };
    // The quarter torus, all 17 layers, in each torch-carried cell held
    // low, and the first layer that leaves through vias. (The elbow in the
    // KUKA cell and the S-bend in the ABB cell left through vias at their
    // sample clearances until the positioner's laws converged.)
    for (part, cell, layers, leaving) in [
        (
            "quarter-torus.toml",
            low("kuka_kr16_2_torch_carried"),
            17,
            5,
        ),
        (
            "quarter-torus.toml",
            low("abb_irb2600_torch_carried"),
            17,
            10,
        ),
        ("quarter-torus.toml", low("robowam_torch_carried"), 17, 14),
    ] {
        let out = dir.path().join(cell.file_stem().unwrap()).join(part);
        let o = waam()
            .args(["--quiet", "plan"])
            .arg(part_path(part))
            .arg("--cell")
            .arg(&cell)
            .args(["--max-layers", &layers.to_string(), "--out"])
            .arg(&out)
            .output()
            .unwrap();
        assert_eq!(
            o.status.code(),
            Some(0),
            "{part}: {}",
            String::from_utf8_lossy(&o.stderr)
        );
        let s: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap())
                .unwrap();
        let vias: Vec<(u64, u64)> = s["layer_plans"]
            .as_array()
            .unwrap()
            .iter()
            .filter_map(|l| Some((l["layer"].as_u64()?, l["transit_vias"].as_u64()?)))
            .collect();
        assert!(
            vias.iter().any(|&(l, n)| l == leaving && n > 0),
            "{part}: {vias:?}"
        );
        checks_clean(&out, &cell, part);
    }
}
