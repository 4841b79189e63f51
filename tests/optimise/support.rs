//! Shared helpers: plan a sample part in the ROBOWAM part-carried cell.

use crate::common::{load_part, part_path};
use waam_slicer::io::cell_file::read_cell_file;
use waam_slicer::optimise::{layer_points, optimise, OptimiseOptions, Plan};
use waam_slicer::path::slice;
use waam_slicer::robot::Cell;
use waam_slicer::toolaxis::local_frames;

pub fn cell(name: &str) -> Cell {
    read_cell_file(part_path(&format!("cells/{name}")))
        .unwrap_or_else(|e| panic!("{e}"))
        .cell
        .unwrap()
}

/// Slices `part` at `delta` (mm) and optimises it in the part-carried cell.
pub fn plan_part(part: &str, delta: f64, opts: &OptimiseOptions) -> Plan {
    let part = load_part(part);
    let mut so = part.slice_options();
    so.delta_mm = delta;
    let path = slice(&part.tube, &part.substrate, &so).unwrap();
    let frames = local_frames(&path, &part.tube);
    let layers = layer_points(&path, &frames);
    optimise(&cell("robowam_part_carried.toml"), &layers, opts).unwrap()
}

/// Largest motion (rad) of joint `j` within any layer.
pub fn max_motion_within_layers(plan: &Plan, j: usize) -> (f64, usize) {
    let mut worst = (0.0, 0);
    for l in &plan.layers {
        let v: Vec<f64> = l.points.iter().map(|p| p.joints.unwrap()[j]).collect();
        let lo = v.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = v.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        if hi - lo > worst.0 {
            worst = (hi - lo, l.layer);
        }
    }
    worst
}
