//! Helpers shared by the integration tests.
#![allow(dead_code)]

use std::path::PathBuf;
use waam_slicer::io::part_file::{read_part_file, Part};

/// Path of a file in `parts/`.
pub fn part_path(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("parts")
        .join(name)
}

/// Reads a sample part, panicking with the error message if it fails.
pub fn load_part(name: &str) -> Part {
    read_part_file(&part_path(name)).unwrap_or_else(|e| panic!("{e}"))
}

/// Every sample part file.
pub const SAMPLE_PARTS: [&str; 8] = [
    "hemisphere.toml",
    "nozzle.toml",
    "half-catenoid.toml",
    "quarter-torus.toml",
    "general-tube.toml",
    "torus-on-cylinder.toml",
    "elbow.toml",
    "helix.toml",
];

/// Every sample cell file in `parts/cells/` with a robot and a layout (the
/// robot-only files `abb_irb2600_12_185` and `kuka_kr16_2` cannot plan).
pub const SAMPLE_CELLS: [&str; 7] = [
    "robowam_part_carried.toml",
    "robowam_part_carried_second_position.toml",
    "robowam_torch_carried.toml",
    "kuka_kr16_2_part_carried.toml",
    "kuka_kr16_2_torch_carried.toml",
    "abb_irb2600_part_carried.toml",
    "abb_irb2600_torch_carried.toml",
];

/// A straight cylinder of the given radius and height on a plate, as part-file
/// text: the smallest valid part, for tests that edit one field.
pub fn cylinder_part_text(name: &str, radius: f64, height: f64, delta: f64) -> String {
    format!(
        r#"
name = "{name}"
[guide]
kind = "line"
origin = [0, 0, 0]
direction = [0, 0, 1]
[profile]
kind = "constant"
radius = {radius}
[range]
t_min = 0
t_max = {height}
[substrate]
kind = "plane"
point = [0, 0, 0]
normal = [0, 0, 1]
[slicing]
delta_mm = {delta}
"#
    )
}

/// The `waam` example binary, built by `cargo test` next to the test executables.
pub fn waam() -> std::process::Command {
    let exe = std::env::current_exe().expect("test executable path");
    let dir = exe
        .parent()
        .and_then(|d| d.parent())
        .expect("target folder");
    let bin = dir
        .join("examples")
        .join(format!("waam{}", std::env::consts::EXE_SUFFIX));
    assert!(bin.exists(), "example not built at {}", bin.display());
    std::process::Command::new(bin)
}

/// Hemisphere R_s = 45 mm, layers at constant meridian arc spacing Delta = 5 mm
/// from Z = 0 (closed form of SPEC §2.1), as cell input points: layer `l` at
/// latitude `phi = l Delta / R_s`, `points` per layer at `v = 2 pi k / points`,
/// tool axis = the meridian tangent pointing up, `R_Z = r_z(layer, v)`.
pub fn hemisphere_cell_points(
    layers: std::ops::Range<usize>,
    points: usize,
    r_z: impl Fn(usize, f64) -> f64,
) -> Vec<waam_slicer::robot::trajectory::PathPointInput> {
    use waam_slicer::math::{Point3, UnitVector3, Vector3};
    let (r_s, delta) = (45.0_f64, 5.0_f64);
    let mut out = Vec::new();
    for layer in layers {
        let phi = layer as f64 * delta / r_s;
        assert!(
            phi < std::f64::consts::FRAC_PI_2,
            "layer {layer} is past the pole"
        );
        let (a, z) = (r_s * phi.cos(), r_s * phi.sin());
        for k in 0..points {
            let v = std::f64::consts::TAU * k as f64 / points as f64;
            let t = Vector3::new(-phi.sin() * v.cos(), -phi.sin() * v.sin(), phi.cos());
            out.push(waam_slicer::robot::trajectory::PathPointInput {
                layer,
                point: k,
                position_mm: Point3::new(a * v.cos(), a * v.sin(), z),
                tool_axis: UnitVector3::new_normalize(t),
                build_direction: None,
                positioner: None,
                r_z: r_z(layer, v),
                bead: 0,
                travel_speed_mm_s: 6.0,
            });
        }
    }
    out
}

/// Rotation about x by `a` (rad), written out for the independent checks.
pub fn rx(a: f64) -> waam_slicer::math::Matrix3 {
    let (s, c) = a.sin_cos();
    waam_slicer::math::Matrix3::new(1.0, 0.0, 0.0, 0.0, c, -s, 0.0, s, c)
}

/// Rotation about y by `a` (rad).
pub fn ry(a: f64) -> waam_slicer::math::Matrix3 {
    let (s, c) = a.sin_cos();
    waam_slicer::math::Matrix3::new(c, 0.0, s, 0.0, 1.0, 0.0, -s, 0.0, c)
}

/// Rotation about z by `a` (rad).
pub fn rz(a: f64) -> waam_slicer::math::Matrix3 {
    let (s, c) = a.sin_cos();
    waam_slicer::math::Matrix3::new(c, -s, 0.0, s, c, 0.0, 0.0, 0.0, 1.0)
}

/// ArcMate 120iC flange pose from controller joints (rad), SPEC §6.1,
/// written out independently of the library's model:
/// p = Rz(J1)[150,0,0] + Rz(J1)Ry(J2)[0,0,790] + Rz(J1)Ry(-J3)[835,0,250] + R6[100,0,0],
/// flange rotation R6·[[0,0,1],[0,-1,0],[1,0,0]].
pub fn spec_fk(q: &[f64; 6]) -> (waam_slicer::math::Matrix3, waam_slicer::math::Vector3) {
    use waam_slicer::math::{Matrix3, Vector3};
    let r1 = rz(q[0]);
    let r3 = r1 * ry(-q[2]);
    let r6 = r3 * rx(-q[3]) * ry(-q[4]) * rx(-q[5]);
    let p = r1 * Vector3::new(150.0, 0.0, 0.0)
        + r1 * ry(q[1]) * Vector3::new(0.0, 0.0, 790.0)
        + r3 * Vector3::new(835.0, 0.0, 250.0)
        + r6 * Vector3::new(100.0, 0.0, 0.0);
    let flange = r6 * Matrix3::new(0.0, 0.0, 1.0, 0.0, -1.0, 0.0, 1.0, 0.0, 0.0);
    (flange, p)
}
