//! A few layers of the hemisphere (R_s = 45 mm, Delta = 5 mm, closed form
//! of SPEC §2.1) in the ROBOWAM cells, with `R_Z = c − v` (J1–J5 still
//! within a layer in the part-carried cell).

use waam_slicer::io::cell_file::read_cell_file;
use waam_slicer::program::{build_program, Program, TravelSpeed};
use waam_slicer::robot::trajectory::{
    joint_trajectory, JointTrajectory, PathPointInput, TrajectoryOptions,
};
use waam_slicer::robot::Cell;

/// TS 36 cm/min = 6 mm/s [thesis table 3.1].
pub const TS_MM_S: f64 = 6.0;

/// Layers `layers` of the hemisphere, `points` per layer, `R_Z = r_z(v)`.
pub fn hemisphere(
    layers: std::ops::Range<usize>,
    points: usize,
    r_z: impl Fn(f64) -> f64,
) -> Vec<PathPointInput> {
    crate::shared::hemisphere_cell_points(layers, points, |_, v| r_z(v))
}

/// A cell from `parts/cells/`.
pub fn cell(file: &str) -> Cell {
    let p = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("parts/cells")
        .join(file);
    read_cell_file(&p)
        .unwrap_or_else(|e| panic!("{e}"))
        .cell
        .expect("a cell")
}

pub fn part_carried() -> Cell {
    cell("robowam_part_carried.toml")
}

pub fn trajectory(cell: &Cell, path: &[PathPointInput]) -> JointTrajectory {
    joint_trajectory(cell, path, TS_MM_S, &TrajectoryOptions::default()).unwrap()
}

/// The law of each cell: `R_Z = −v` where the robot holds the part (J1–J5
/// still), `R_Z = 0` where the positioner turns it (hose torsion bounded).
pub fn law(cell: &Cell) -> fn(f64) -> f64 {
    match cell {
        Cell::PartCarried(_) => |v| -v,
        Cell::TorchCarried(_) => |_| 0.0,
    }
}

/// The program of layers `layers` (`points` per layer) in `cell`.
pub fn program(
    cell: &Cell,
    layers: std::ops::Range<usize>,
    points: usize,
) -> (Program, Vec<PathPointInput>) {
    let path = hemisphere(layers, points, law(cell));
    let tr = trajectory(cell, &path);
    let prog = build_program("HEMI", cell, &path, &tr, &TravelSpeed::Constant(TS_MM_S))
        .unwrap_or_else(|e| panic!("{e}"));
    (prog, path)
}

#[test]
fn the_test_layers_are_feasible_in_every_cell() {
    for file in [
        "robowam_part_carried.toml",
        "robowam_part_carried_second_position.toml",
        "robowam_torch_carried.toml",
    ] {
        let cell = cell(file);
        let path = hemisphere(0..4, 24, law(&cell));
        let tr = trajectory(&cell, &path);
        assert!(tr.report.is_clean(), "{file}: {}", tr.report);
    }
}
