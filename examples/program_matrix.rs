//! Issue 32's acceptance, by hand and in CI: the nozzle and the hemisphere
//! in every sample cell — placed by `place` where the cell refuses the part
//! as it stands — planned, their programs written in the cell robot's
//! format, read back and checked by the same checker as `waam check` (joints,
//! limits, speeds, strokes, the memory budget, and the controller's path
//! between the moves against the planned points). Prints per pair the
//! planned points, the motions written, their ratio and the files.
//!
//! ```text
//! cargo run --release --example program_matrix -- --full   # the part files' own grids (minutes)
//! cargo run --example program_matrix                       # 48 points a layer (CI, via cargo test)
//! ```
//!
//! Asserts that every pair ends with a program that reads back clean;
//! `cargo test` runs it at the coarse grid.

use waam_slicer::path::Discretisation;
use waam_slicer::{
    check_program, place_part, plan_part, Cell, Part, PlaceRequest, PlanOptions, SliceOverrides,
};

const PARTS: [&str; 2] = ["hemisphere", "nozzle"];
const CELLS: [&str; 7] = [
    "robowam_part_carried",
    "robowam_part_carried_second_position",
    "robowam_torch_carried",
    "kuka_kr16_2_part_carried",
    "kuka_kr16_2_torch_carried",
    "abb_irb2600_part_carried",
    "abb_irb2600_torch_carried",
];

fn main() -> Result<(), waam_slicer::Error> {
    let full = std::env::args().any(|a| a == "--full");
    let root = env!("CARGO_MANIFEST_DIR");
    let slice = if full {
        SliceOverrides::default()
    } else {
        SliceOverrides {
            discretisation: Some(Discretisation::Points(48)),
            ..SliceOverrides::default()
        }
    };
    let out = std::env::temp_dir().join(format!("waam-program-matrix-{}", std::process::id()));
    let mut failures = Vec::new();
    println!("part, cell, placed, planned points, motions, ratio, files");
    for part_name in PARTS {
        let part = Part::read(format!("{root}/parts/{part_name}.toml"))?;
        for cell_name in CELLS {
            let cell = Cell::read(format!("{root}/parts/cells/{cell_name}.toml"))?;
            let opts = PlanOptions {
                slice: slice.clone(),
                ..PlanOptions::default()
            };
            let mut planned = plan_part(&part, &cell, &opts)?;
            let mut placed = false;
            let mut cell_used = cell.clone();
            if !planned.is_feasible() {
                let req = PlaceRequest {
                    slice: slice.clone(),
                    ..PlaceRequest::default()
                };
                let p = place_part(&part, &cell, &req)?;
                if p.placement.feasible {
                    planned = plan_part(&part, &p.cell, &opts)?;
                    cell_used = p.cell;
                    placed = true;
                }
            }
            let what = format!("{part_name} in {cell_name}");
            if !planned.is_feasible() {
                let why = planned
                    .refusal()
                    .map_or("an infeasible layer".to_string(), |e| e.to_string());
                println!("{part_name}, {cell_name}, {placed}, refused: {why}");
                failures.push(format!("{what}: refused even after placement: {why}"));
                continue;
            }
            let dir = out.join(cell_name).join(part_name);
            let files = planned.write_programs(&dir)?;
            let report = check_program(&files[0], &cell_used)?;
            let points: usize = planned.layers.iter().map(|l| l.points.len()).sum();
            let names: Vec<String> = files
                .iter()
                .filter_map(|f| f.file_name().map(|n| n.to_string_lossy().into_owned()))
                .collect();
            println!(
                "{part_name}, {cell_name}, {placed}, {points}, {}, {:.1}, {}",
                report.motions,
                points as f64 / report.motions.max(1) as f64,
                names.join(" ")
            );
            if !report.is_ok() {
                failures.push(format!("{what}:\n{report}"));
            }
        }
    }
    let _ = std::fs::remove_dir_all(&out);
    assert!(
        failures.is_empty(),
        "{} pair(s) failed:\n{}",
        failures.len(),
        failures.join("\n")
    );
    Ok(())
}
