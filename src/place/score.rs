//! The score of a candidate: its plan's worst-layer margins (joint stops,
//! speed headroom, reach, dexterity) scaled to one scalar to maximise, and
//! the constraint that binds an infeasible plan.

use super::outcome::{Limit, Margins};
use crate::optimise::{LayerStatus, Plan};
use crate::robot::{CellLayout, Joints, RobotModel};

/// The reach margin (mm) the score calls comfortable. The full path's
/// layers and laws (each layer re-optimised on every point) take the wrist
/// centre further out than the subsample's: the S-bend at Delta 2 mm, 400
/// points a layer, had a candidate 51 mm inside the reach on the subsample
/// and 6.7 mm beyond it at layer 192 on the full path, between two layers
/// of the subsample.
pub const REACH_COMFORT_MM: f64 = 50.0;

/// Distance from a joint stop (deg) the score calls comfortable.
pub(crate) const JOINT_COMFORT_DEG: f64 = 10.0;

/// Speed headroom (`1 − peak / max`) the score calls comfortable.
pub(crate) const SPEED_COMFORT: f64 = 0.2;

/// Dexterity at which the score's tie-breaking reward saturates (our arms'
/// dexterity values are ~1e-3).
const DEXTERITY_SCALE: f64 = 2e-3;

/// The worst layer's margins of `plan` in `cell`.
pub fn margins(plan: &Plan, cell: &CellLayout) -> Margins {
    let robot = cell.robot();
    let mut m = Margins {
        joint_limit_deg: f64::INFINITY,
        speed_headroom: f64::INFINITY,
        dexterity: f64::INFINITY,
        reach_mm: f64::INFINITY,
        infeasible_layers: 0,
    };
    for l in &plan.layers {
        if !l.status.is_feasible() {
            m.infeasible_layers += 1;
        }
        for q in l.points.iter().filter_map(|p| p.joints.as_ref()) {
            m.reach_mm = m.reach_mm.min(reach_margin_mm(robot, q));
        }
        let q = &l.quality;
        m.joint_limit_deg = m.joint_limit_deg.min(q.min_limit_distance_rad.to_degrees());
        m.dexterity = m.dexterity.min(q.min_dexterity);
        for j in 0..6 {
            let vmax = robot.max_speed_rad_s[j];
            if vmax.is_finite() && vmax > 0.0 {
                m.speed_headroom = m.speed_headroom.min(1.0 - q.peak_speed_rad_s[j] / vmax);
            }
        }
    }
    for v in [
        &mut m.joint_limit_deg,
        &mut m.speed_headroom,
        &mut m.dexterity,
        &mut m.reach_mm,
    ] {
        if !v.is_finite() {
            *v = 0.0;
        }
    }
    m
}

/// Distance (mm) of the wrist centre at joints `q` (rad) inside the arm's
/// reach annulus `[|c2 − k|, c2 + k]` about the J2 axis (`c2` the upper arm,
/// `k` the J3 → wrist-centre distance), as the inverse kinematics tests it;
/// negative outside.
pub(crate) fn reach_margin_mm(robot: &RobotModel, q: &Joints) -> f64 {
    let s = robot.chain_state(q);
    let d = (s.wrist_centre - s.axis_points[1]).norm();
    let g = &robot.geometry;
    let k = g.forearm_mm.hypot(g.elbow_offset_mm);
    (d - (g.upper_arm_mm - k).abs()).min(g.upper_arm_mm + k - d)
}

/// The joint-stop, speed and reach margins of `m`, each scaled to 1 at its
/// comfortable value ([`JOINT_COMFORT_DEG`], [`SPEED_COMFORT`],
/// [`REACH_COMFORT_MM`]).
pub(crate) fn scaled(m: &Margins) -> [f64; 3] {
    [
        m.joint_limit_deg / JOINT_COMFORT_DEG,
        m.speed_headroom / SPEED_COMFORT,
        m.reach_mm / REACH_COMFORT_MM,
    ]
}

/// One scalar to maximise: for a feasible plan the worst of the joint-limit,
/// speed and reach margins, each scaled to 1 at a comfortable value (10°
/// from a stop, 20 % speed headroom, [`REACH_COMFORT_MM`] inside the arm's
/// reach) and capped at 1, plus a small reward for
/// dexterity (the floor itself is a constraint of every layer; dexterity
/// mixes mm and rad, its values are ~1e-3 on our arms, so it only breaks
/// ties); for an infeasible plan minus the share of infeasible layers minus
/// a bounded measure of the violations.
pub(crate) fn score(plan: &Plan, cell: &CellLayout) -> f64 {
    let m = margins(plan, cell);
    if m.infeasible_layers == 0 {
        let [a, b, r] = scaled(&m).map(|v| v.min(1.0));
        let c = (m.dexterity / DEXTERITY_SCALE).min(1.0);
        return a.min(b).min(r).max(0.0) + 0.01 * c.max(0.0);
    }
    let n = plan.layers.len().max(1) as f64;
    let violation: f64 = plan
        .layers
        .iter()
        .map(|l| match &l.status {
            LayerStatus::Infeasible { binding } | LayerStatus::FixedViolates { binding } => {
                binding.violation.abs().min(1.0)
            }
            LayerStatus::NoSolution { .. } => 1.0,
            _ => 0.0,
        })
        .sum::<f64>()
        / n;
    -(m.infeasible_layers as f64 / n) - 0.5 * violation
}

/// The first infeasible layer's binding constraint.
pub(crate) fn binding_of(plan: &Plan) -> Option<Limit> {
    plan.layers.iter().find_map(|l| match &l.status {
        LayerStatus::Infeasible { binding } | LayerStatus::FixedViolates { binding } => {
            Some(Limit::Layer(binding.constraint))
        }
        LayerStatus::NoSolution { error, .. } => Some(Limit::NoJointSolution(error.clone())),
        _ => None,
    })
}
