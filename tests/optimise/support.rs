//! Shared helpers: plan a sample part in the ROBOWAM part-carried cell.

use crate::common::{load_part, part_path};
use waam_slicer::io::cell_file::read_cell_file;
use waam_slicer::optimise::{layer_points, optimise, LayerPoints, OptimiseOptions, Plan};
use waam_slicer::path::slice;
use waam_slicer::robot::CellLayout;
use waam_slicer::toolaxis::local_frames;

pub fn cell(name: &str) -> CellLayout {
    read_cell_file(part_path(&format!("cells/{name}")))
        .unwrap_or_else(|e| panic!("{e}"))
        .cell
        .unwrap()
}

/// Slices `part` at `delta` (mm) and optimises it in the part-carried cell.
pub fn plan_part(part: &str, delta: f64, opts: &OptimiseOptions) -> Plan {
    optimise(
        &cell("robowam_part_carried.toml"),
        &part_layers(part, delta, 1),
        opts,
    )
    .unwrap()
}

/// The layers of `part` sliced at `delta` (mm), every `every`-th one.
pub fn part_layers(part: &str, delta: f64, every: usize) -> Vec<LayerPoints> {
    let part = load_part(part);
    let mut so = part.slice_options();
    so.delta_mm = delta;
    let path = slice(&part.tube, &part.substrate, &so).unwrap();
    let frames = local_frames(&path, &part.tube);
    layer_points(&path, &frames, 6.0)
        .into_iter()
        .step_by(every)
        .collect()
}

/// Summed |joint acceleration| × time (rad/s) over the joints `joints`
/// (0-based) at the travel speed `ts` (mm/s), central differences on the
/// non-uniform time grid, over every layer of `plan` (planned on `layers`).
pub fn summed_acceleration(
    plan: &Plan,
    layers: &[LayerPoints],
    ts: f64,
    joints: std::ops::Range<usize>,
) -> f64 {
    let mut sum = 0.0;
    for (l, lp) in plan.layers.iter().zip(layers) {
        let q: Vec<[f64; 6]> = l.points.iter().map(|p| p.joints.unwrap()).collect();
        let dt = |m: usize| (lp.points[m].position_mm - lp.points[m - 1].position_mm).norm() / ts;
        for m in 2..q.len() {
            let (d1, d0) = (dt(m), dt(m - 1));
            let h = 0.5 * (d1 + d0);
            for j in joints.clone() {
                let a = ((q[m][j] - q[m - 1][j]) / d1 - (q[m - 1][j] - q[m - 2][j]) / d0) / h;
                sum += a.abs() * h;
            }
        }
    }
    sum
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
