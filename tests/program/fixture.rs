//! A few layers of the hemisphere (R_s = 45 mm, Delta = 5 mm, closed form
//! of SPEC §2.1) in the ROBOWAM cells (FANUC) and the KUKA and ABB example
//! cells, with a law `R_Z(v)` feasible in each ([`law`]).

use waam_slicer::io::cell_file::read_cell_file;
use waam_slicer::program::{build_program, PointFeed, Program};
use waam_slicer::robot::trajectory::{
    joint_trajectory, JointTrajectory, PathPointInput, TrajectoryOptions,
};
use waam_slicer::robot::{CellLayout, Vendor};

/// TS 36 cm/min = 6 mm/s [thesis table 3.1].
pub const TS_MM_S: f64 = 6.0;

/// WFS 10 mm/s with TS 6 mm/s [thesis table 3.1].
pub const WFS_MM_S: f64 = 10.0;

/// Layers `layers` of the hemisphere, `points` per layer, `R_Z = r_z(v)`.
pub fn hemisphere(
    layers: std::ops::Range<usize>,
    points: usize,
    r_z: impl Fn(f64) -> f64,
) -> Vec<PathPointInput> {
    crate::shared::hemisphere_cell_points(layers, points, |_, v| r_z(v))
}

/// A cell from `parts/cells/`.
pub fn cell(file: &str) -> CellLayout {
    let p = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("parts/cells")
        .join(file);
    read_cell_file(&p)
        .unwrap_or_else(|e| panic!("{e}"))
        .cell
        .expect("a cell")
}

pub fn part_carried() -> CellLayout {
    cell("robowam_part_carried.toml")
}

pub fn trajectory(cell: &CellLayout, path: &[PathPointInput]) -> JointTrajectory {
    joint_trajectory(cell, path, &TrajectoryOptions::default()).unwrap()
}

/// The law of each cell. ROBOWAM (FANUC): `R_Z = −v` where the robot holds
/// the part (J1–J5 still), `R_Z = 0` where the positioner turns it (hose
/// torsion bounded). The KUKA and ABB example cells: `R_Z = 0` where the
/// robot holds the part (with `−v`, J5 leaves its ±120°/±130° travel half
/// way round), `R_Z = π` where it carries the torch (with 0 the hose
/// torsion |J4 + J6| is 180°: their flange axes differ from FANUC's).
pub fn law(cell: &CellLayout) -> fn(f64) -> f64 {
    let fanuc = cell.robot().vendor == Vendor::Fanuc;
    match (cell, fanuc) {
        (CellLayout::PartCarried(_), true) => |v| -v,
        (CellLayout::PartCarried(_), false) => |_| 0.0,
        (CellLayout::TorchCarried(_), true) => |_| 0.0,
        (CellLayout::TorchCarried(_), false) => |_| std::f64::consts::PI,
    }
}

/// The KUKA example cells: torch carried (positioner as `E1`, `E2`) and
/// part carried (fixed-tool mode).
pub const KUKA_CELLS: [&str; 2] = [
    "kuka_kr16_2_torch_carried.toml",
    "kuka_kr16_2_part_carried.toml",
];

/// The ABB example cells: part carried (stationary tool) and torch carried.
pub const ABB_CELLS: [&str; 2] = [
    "abb_irb2600_part_carried.toml",
    "abb_irb2600_torch_carried.toml",
];

/// The ROBOWAM cells (FANUC ArcMate 120iC).
pub const FANUC_CELLS: [&str; 3] = [
    "robowam_part_carried.toml",
    "robowam_part_carried_second_position.toml",
    "robowam_torch_carried.toml",
];

/// The program of layers `layers` (`points` per layer) in `cell`.
pub fn program(
    cell: &CellLayout,
    layers: std::ops::Range<usize>,
    points: usize,
) -> (Program, Vec<PathPointInput>) {
    let path = hemisphere(layers, points, law(cell));
    let tr = trajectory(cell, &path);
    let prog = build_program(
        "HEMI",
        cell,
        &path,
        &tr,
        &PointFeed::constant(TS_MM_S, crate::fixture::WFS_MM_S, path.len()),
    )
    .unwrap_or_else(|e| panic!("{e}"));
    (prog, path)
}

#[test]
fn the_test_layers_are_feasible_in_every_cell() {
    for file in FANUC_CELLS.iter().chain(&KUKA_CELLS).chain(&ABB_CELLS) {
        let cell = cell(file);
        let path = hemisphere(0..4, 24, law(&cell));
        let tr = trajectory(&cell, &path);
        assert!(tr.report.is_clean(), "{file}: {}", tr.report);
    }
}

/// The plan of `path` at the fixture's constant speed and wire feed, as a
/// checker takes it.
pub fn planned_of(path: &[PathPointInput]) -> Vec<waam_slicer::program::PlannedPoint> {
    path.iter()
        .map(|p| waam_slicer::program::PlannedPoint {
            position_mm: p.position_mm,
            feed: PointFeed {
                travel_speed_mm_s: TS_MM_S,
                wire_feed_mm_s: WFS_MM_S,
            },
        })
        .collect()
}

/// The positions of the beads of layers `0..layers` of `prog` (part frame,
/// mm), one list per layer.
pub fn bead_positions(prog: &Program, layers: usize) -> Vec<Vec<waam_slicer::math::Point3>> {
    (0..layers)
        .map(|l| {
            prog.bead_points()
                .filter(|p| p.layer == l)
                .map(|p| p.position_mm)
                .collect()
        })
        .collect()
}
