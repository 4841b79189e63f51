//! Unit tests of the positioner's laws: the driver on layers of the sample
//! cells (the pole, the controller's stroke), and the fixtures the other
//! files' tests share.

use super::*;
use crate::math::{Isometry3, Translation3, UnitQuaternion, UnitVector3, Vector3};

/// A torch-carried sample cell of `parts/cells`.
pub(super) fn sample_cell(file: &str) -> TorchCarriedCell {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("parts/cells")
        .join(file);
    match crate::io::cell_file::read_cell_file(&path)
        .expect("sample cell")
        .cell
    {
        Some(crate::robot::CellLayout::TorchCarried(c)) => c,
        other => panic!("not a torch-carried sample cell: {other:?}"),
    }
}

pub(super) fn cell(cone_deg: f64) -> TorchCarriedCell {
    let mut c = sample_cell("kuka_kr16_2_torch_carried.toml");
    c.max_vertical_error_rad = cone_deg.to_radians();
    c.table_from_part =
        Isometry3::from_parts(Translation3::new(0.0, 0.0, 0.0), UnitQuaternion::identity());
    c
}

/// A layer whose build direction crosses the table normal (the pole):
/// `b` tilts 10° from +Z along X, through Z, to 10° along −X and back,
/// around a small circle off the turn axis. The exact-vertical turn
/// turns the table by ~180° near the pole; within a 15° cone the turn
/// holds (within a few degrees).
#[test]
fn the_turn_holds_still_at_the_pole() {
    let c = cell(15.0);
    let n = 200;
    let points: Vec<CellPoint> = (0..n)
        .map(|m| {
            let v = std::f64::consts::TAU * m as f64 / n as f64;
            let a = 10f64.to_radians() * v.cos();
            let b = Vector3::new(a.sin(), 0.02 * v.sin(), a.cos());
            CellPoint {
                position_mm: Point3::new(60.0 + 20.0 * v.cos(), 20.0 * v.sin(), 50.0),
                tool_axis: UnitVector3::new_normalize(b),
                build_direction: Some(UnitVector3::new_normalize(b)),
                positioner: None,
                travel_speed_mm_s: 6.0,
            }
        })
        .collect();
    let exact = vertical_joints(&c, &points, 0.0).expect("vertical joints");
    let range = |q: &[PositionerJoints]| {
        let (lo, hi) = q
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
                (a.min(v[1]), b.max(v[1]))
            });
        hi - lo
    };
    let spin = range(&exact);
    assert!(
        spin > 3.0,
        "the exact vertical turns the table by {spin} rad"
    );
    let law = positioner_law(&c, &points, 0.0, 0.0, &PositionerOptions::default());
    assert!(law.feasible, "{:?}", law.binding);
    // the turn only trims the tilt (±5° here), it does not follow b round
    let turn = range(&law.joints);
    assert!(turn < 0.2, "the turn moves by {turn} rad");
    assert!(law.max_tilt_rad <= 15f64.to_radians() + 1e-9);
}

/// A flat circle about the turn axis, `b` vertical: the law turns the
/// table the whole turn under a still torch (the arm's motion costs,
/// the endless turn does not). With the controller's stroke narrowed to
/// ±100° the program could not hold that bead; the law is solved again
/// within the stroke and stays within its 200° (the arm takes the rest).
#[test]
fn the_turn_stays_within_the_controllers_stroke() {
    let mut c = sample_cell("robowam_torch_carried.toml");
    let n = 120;
    let points: Vec<CellPoint> = (0..n)
        .map(|m| {
            let v = std::f64::consts::TAU * m as f64 / n as f64;
            CellPoint {
                position_mm: Point3::new(100.0 * v.cos(), 100.0 * v.sin(), 20.0),
                tool_axis: Vector3::z_axis(),
                build_direction: Some(Vector3::z_axis()),
                positioner: None,
                travel_speed_mm_s: 6.0,
            }
        })
        .collect();
    let span = |law: &PositionerLaw| {
        let (lo, hi) = law
            .joints
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
                (a.min(v[1]), b.max(v[1]))
            });
        (lo, hi)
    };
    let free = positioner_law(&c, &points, 0.0, 0.0, &PositionerOptions::default());
    let (lo, hi) = span(&free);
    assert!(free.feasible, "{:?}", free.binding);
    assert!(
        hi - lo > 300f64.to_radians(),
        "the table turns {} rad",
        hi - lo
    );
    let stroke = 100f64.to_radians();
    c.positioner.turn_stroke = Some(crate::robot::JointLimit {
        lower_rad: -stroke,
        upper_rad: stroke,
    });
    let law = positioner_law(&c, &points, 0.0, 0.0, &PositionerOptions::default());
    let (lo, hi) = span(&law);
    assert!(law.feasible, "{:?}", law.binding);
    let shifts = c.turn_stroke().whole_turn_shifts(lo, hi);
    assert!(shifts.is_some(), "[{lo}, {hi}] rad does not fit ±{stroke}");
    assert!(law.max_tilt_rad <= 15f64.to_radians() + 1e-9);
}
