//! Random cells, as a user would type them (issue 22): part-carried and
//! torch-carried cell files with the deposition point or the positioner
//! anywhere in a box around the robot, random mounts, joint limits and
//! speeds. Each is read by the cell-file reader, then a small hemisphere
//! slice (Delta 5, 36 points a layer, 3 layers) is planned in it with the
//! library's `optimise`. Every case must end in bounded time with a cell
//! error naming the file, a typed optimiser error, or a plan whose numbers
//! are finite wherever it has joints — never a panic, never a hang.

use std::sync::OnceLock;
use std::time::{Duration, Instant};

use proptest::prelude::*;
use waam_slicer::io::cell_file::parse_cell_file;
use waam_slicer::optimise::{layer_points, optimise, LayerPoints, OptimiseOptions};
use waam_slicer::path::{slice, Discretisation};
use waam_slicer::toolaxis::tool_axes;

use crate::common::load_part;

/// Longest a case may take (dev profile, 2 shared cores, both cells' worst).
const CASE_BUDGET: Duration = Duration::from_secs(20);

/// Three layers of the hemisphere, 36 points each, with their tool axes.
pub(crate) fn hemisphere_layers() -> &'static [LayerPoints] {
    static LAYERS: OnceLock<Vec<LayerPoints>> = OnceLock::new();
    LAYERS.get_or_init(|| {
        let part = load_part("hemisphere.toml");
        let mut so = part.slice_options();
        so.delta_mm = 5.0;
        so.discretisation = Discretisation::Points(36);
        so.max_layers = Some(3);
        let path = slice(&part.tube, &part.substrate, &so).expect("hemisphere slices");
        let axes = tool_axes(
            &path,
            Some(&part.tube),
            Some(&part.substrate),
            &part.tool_axis,
        )
        .expect("hemisphere tool axes");
        layer_points(&path, &axes.frames, 6.0)
    })
}

fn list(v: &[f64]) -> String {
    let items: Vec<String> = v.iter().map(|x| format!("{x:?}")).collect();
    format!("[{}]", items.join(", "))
}

const PRESETS: [&str; 3] = ["arcmate120ic_nominal", "kuka_kr16_2", "abb_irb2600_12_185"];

/// The `[robot]` section: a preset with its own or random limits and speeds.
fn robot_section() -> impl Strategy<Value = String> {
    (
        0..PRESETS.len(),
        prop::array::uniform6(-220.0f64..-5.0),
        prop::array::uniform6(5.0f64..220.0),
        prop::array::uniform6(1.0f64..400.0),
        0..3u8,
    )
        .prop_map(|(p, lower, upper, speed, limits)| {
            if limits == 0 {
                // the preset's own limits and speeds
                return format!("[robot]\npreset = \"{}\"\n", PRESETS[p]);
            }
            let unlimited_j6 = limits == 2;
            let (mut lower, mut upper) = (lower.map(|v| format!("{v:?}")), upper.map(|v| format!("{v:?}")));
            if unlimited_j6 {
                lower[5] = "-inf".into();
                upper[5] = "inf".into();
            }
            format!(
                "[robot]\npreset = \"{}\"\nlower_deg = [{}]\nupper_deg = [{}]\nmax_speed_deg_s = {}\n",
                PRESETS[p],
                lower.join(", "),
                upper.join(", "),
                list(&speed)
            )
        })
}

fn configuration() -> impl Strategy<Value = String> {
    (any::<bool>(), any::<bool>(), any::<bool>()).prop_map(|(w, e, s)| {
        format!(
            "{} {} {}",
            if w { "N" } else { "F" },
            if e { "U" } else { "D" },
            if s { "T" } else { "B" }
        )
    })
}

/// A pose `[X, Y, Z, W, P, R]` (mm, deg) with the translation in `±reach`.
fn pose(reach: f64) -> impl Strategy<Value = [f64; 6]> {
    (
        prop::array::uniform3(-reach..reach),
        prop::array::uniform3(-180.0f64..180.0),
    )
        .prop_map(|(t, r)| [t[0], t[1], t[2], r[0], r[1], r[2]])
}

/// A part-carried cell file: the deposition point anywhere in a 5 × 5 × 3 m
/// box around the robot, a random part mount.
fn part_carried() -> impl Strategy<Value = String> {
    (
        robot_section(),
        (-2500.0f64..2500.0, -2500.0f64..2500.0, -1000.0f64..2000.0),
        configuration(),
        prop::option::of(pose(300.0)),
    )
        .prop_map(|(robot, (x, y, z), cfg, mount)| {
            let mount = mount.map_or(String::new(), |m| {
                format!("flange_from_part_xyzwpr = {}\n", list(&m))
            });
            format!(
                "name = \"random part carried\"\n{robot}\n[part_carried]\n\
                 deposition_point_mm = {}\nconfiguration = \"{cfg}\"\n{mount}",
                list(&[x, y, z])
            )
        })
}

/// A torch-carried cell file: the positioner anywhere in a 6 m box, a
/// random torch, positioner travel and speeds.
fn torch_carried() -> impl Strategy<Value = String> {
    (
        robot_section(),
        pose(3000.0),
        pose(500.0),
        configuration(),
        (0.0f64..400.0, 10.0f64..360.0, 0.0f64..5.0),
        (-180.0f64..-1.0, 1.0f64..180.0, 1.0f64..360.0),
    )
        .prop_map(
            |(robot, positioner, tool, cfg, (tilt, hose, vertical), (lo, hi, speed))| {
                format!(
                    "name = \"random torch carried\"\n{robot}\n[torch_carried]\n\
                     configuration = \"{cfg}\"\npositioner_pose_xyzwpr = {}\n\
                     tool_xyzwpr = {}\nmax_hose_torsion_deg = {hose:?}\n\
                     max_vertical_error_deg = {vertical:?}\n\n[torch_carried.positioner]\n\
                     name = \"random\"\ntilt_to_table_mm = {tilt:?}\n\
                     lower_deg = [{lo:?}, -inf]\nupper_deg = [{hi:?}, inf]\n\
                     max_speed_deg_s = [{speed:?}, {speed:?}]\n",
                    list(&positioner),
                    list(&tool)
                )
            },
        )
}

/// Reads `text` as a cell and plans the hemisphere in it; panics (the
/// property fails) on anything but a clean end.
pub(crate) fn plan_in(text: &str) -> Result<(), TestCaseError> {
    let start = Instant::now();
    let cell = match parse_cell_file(text, "random.toml") {
        Ok(f) => f.cell.expect("the file describes a cell"),
        Err(e) => {
            // refused up front (out of reach, bad field): the message names the file
            prop_assert!(e.to_string().starts_with("random.toml: "), "{e}");
            return Ok(());
        }
    };
    let opts = OptimiseOptions {
        parallel: false,
        ..OptimiseOptions::default()
    };
    match optimise(&cell, hemisphere_layers(), &opts) {
        Ok(plan) => {
            prop_assert_eq!(plan.layers.len(), 3);
            for layer in &plan.layers {
                for p in &layer.points {
                    prop_assert!(p.r_z.is_finite(), "layer {}: R_Z {}", layer.layer, p.r_z);
                    if let Some(q) = p.joints {
                        prop_assert!(q.iter().all(|v| v.is_finite()), "{q:?}");
                    }
                }
            }
        }
        Err(e) => prop_assert!(!e.to_string().is_empty()),
    }
    let took = start.elapsed();
    prop_assert!(took < CASE_BUDGET, "took {took:?}:\n{text}");
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 40, failure_persistence: None, .. ProptestConfig::default() })]

    #[test]
    fn random_part_carried_cells_end_cleanly(text in part_carried()) {
        plan_in(&text)?;
    }

    #[test]
    fn random_torch_carried_cells_end_cleanly(text in torch_carried()) {
        plan_in(&text)?;
    }
}

/// Extreme numbers a typo gives, in an otherwise valid cell: speeds of
/// 1e-300 and 1e300 deg/s, limits of ±1e300 deg, a hose limit of 1e300 deg.
#[test]
fn extreme_speeds_and_limits_end_cleanly() {
    let base = std::fs::read_to_string(crate::common::part_path("cells/robowam_part_carried.toml"))
        .unwrap();
    for (from, to) in [
        ("preset = \"arcmate120ic_nominal\"", "preset = \"arcmate120ic_nominal\"\nmax_speed_deg_s = [1e-300, 1e-300, 1e-300, 1e-300, 1e-300, 1e-300]"),
        ("preset = \"arcmate120ic_nominal\"", "preset = \"arcmate120ic_nominal\"\nmax_speed_deg_s = [1e300, 1e300, 1e300, 1e300, 1e300, 1e300]"),
        ("lower_deg = [-170, -100, -185, -200, -135, -inf]", "lower_deg = [-1e300, -1e300, -1e300, -1e300, -1e300, -1e300]"),
    ] {
        let text = base.replace(from, to);
        assert_ne!(text, base);
        plan_in(&text).unwrap_or_else(|e| panic!("{to}: {e}"));
    }
    let torch = std::fs::read_to_string(crate::common::part_path(
        "cells/kuka_kr16_2_torch_carried.toml",
    ))
    .unwrap();
    for (from, to) in [
        (
            "max_hose_torsion_deg = 120.0",
            "max_hose_torsion_deg = 1e300",
        ),
        (
            "max_speed_deg_s = [80.2, 160.4]",
            "max_speed_deg_s = [1e-300, 1e-300]",
        ),
        (
            "max_vertical_error_deg = 15.0",
            "max_vertical_error_deg = 1e300",
        ),
    ] {
        let text = torch.replace(from, to);
        assert_ne!(text, torch);
        plan_in(&text).unwrap_or_else(|e| panic!("{to}: {e}"));
    }
}
