//! Stages 5 and 7 alone, without the optimiser (robot programs,
//! [`waam_slicer::program`]): the first layers of the hemisphere in the
//! thesis's part-carried cell with the thesis's law `R_Z = −v` (the robot
//! turns the part under the torch about the tool axis, thesis §4.3), the
//! joint trajectory, a FANUC program emitted, read back and checked against
//! the cell and the planned points as the controller would interpolate it.
//!
//! ```text
//! cargo run --example stage_emit
//! ```

use waam_slicer::math::UnitVector3;
use waam_slicer::path::slice;
use waam_slicer::program::contract::Controller;
use waam_slicer::program::fanuc::Fanuc;
use waam_slicer::program::fanuc::FanucOptions;
use waam_slicer::program::{build_program, PointFeed};
use waam_slicer::robot::trajectory::{joint_trajectory, PathPointInput, TrajectoryOptions};
use waam_slicer::toolaxis::local_frames;
use waam_slicer::{Cell, Part};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let root = env!("CARGO_MANIFEST_DIR");
    let part = Part::read(format!("{root}/parts/hemisphere.toml"))?;
    let cell = Cell::read(format!("{root}/parts/cells/robowam_part_carried.toml"))?;
    let mut opts = part.slice_options();
    opts.max_layers = Some(3);
    let path = slice(&part.tube, &part.substrate, &opts)?;
    let frames = local_frames(&path, &part.tube);

    // TS = 36 cm/min [thesis table 3.1]
    let speed = 6.0;
    // R_Z = −v, v the point's angle about the part's axis, unwrapped
    let mut points = Vec::new();
    for (l, (layer, frames)) in path.layers.iter().zip(&frames).enumerate() {
        let mut last: Option<f64> = None;
        for (m, (p, f)) in layer.points.iter().zip(frames).enumerate() {
            let mut v = p.position.y.atan2(p.position.x);
            if let Some(prev) = last {
                v = prev + (v - prev + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU)
                    - std::f64::consts::PI;
            }
            last = Some(v);
            points.push(PathPointInput {
                layer: l,
                point: m,
                position_mm: p.position,
                tool_axis: UnitVector3::new_normalize(f.tool),
                build_direction: Some(UnitVector3::new_normalize(f.build)),
                r_z: -v,
                positioner: None,
                bead: 0,
                travel_speed_mm_s: speed,
            });
        }
    }
    let traj = joint_trajectory(&cell.layout, &points, &TrajectoryOptions::default())?;
    assert!(
        traj.report.is_clean(),
        "the thesis's law is feasible: {}",
        traj.report
    );
    let program = build_program(
        "HEMI",
        &cell.layout,
        &points,
        &traj,
        &PointFeed::constant(speed, 10.0, points.len()),
    )?;

    let fanuc = FanucOptions::default();
    let files = Fanuc::emit(&program, &fanuc)?;
    let read = Fanuc::read(&files)?;
    let report = Fanuc::validate(&read, &cell.layout, &fanuc, Some(&program.planned));
    println!(
        "{} planned points, {} motions written in {} file(s); check: {} problem(s)",
        points.len(),
        report.motions,
        files.len(),
        report.problems.len()
    );
    assert!(report.is_ok(), "{report}");
    assert_eq!(report.beads, path.layers.len(), "one bead per layer");
    Ok(())
}
