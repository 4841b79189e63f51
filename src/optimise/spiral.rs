//! Spiral paths [SPEC §7]: one continuous layer solved turn by turn, each
//! turn continuing the one before (same branch, `R_Z` and joints held on the
//! shared point, a continuous dexterity floor).

use std::time::Instant;

use super::branch::optimise_layer;
use super::branch_types::Anchor;
use super::{
    transitions, validate_input, LayerPlan, LayerPoints, LayerStatus, OptimiseError,
    OptimiseOptions, Plan,
};
use crate::robot::cell::CellLayout;

/// Optimises a spiral path (one continuous layer, `per_turn` points a turn,
/// as [`Path::spiral`](crate::path::Path) gives it) turn by turn [SPEC §7]:
/// the arc never stops, so every turn continues the one before — same IK
/// branch, its first point's joints unwrapped from the previous turn's last
/// joints, and `R_Z` held at the previous turn's last value on that joint
/// point (the polynomial of [`Basis::anchored_polynomial`](super::parameterisation::Basis::anchored_polynomial): `R_Z` continuous,
/// its slope free). Each turn is solved as a layer of its own, including that
/// shared point, so the junction step counts in its objective and quality.
/// The dexterity floor is continuous along the spiral: over each turn it
/// goes linearly from the previous turn's floor to the turn's own.
/// The plan has one [`LayerPlan`] per turn (`layer` = turn number, points
/// of that turn only); turns are solved in order, not in parallel. The
/// smoothing spline and the point-by-point baseline hold the joints
/// continuous but leave `R_Z` free on the shared point.
///
/// # Errors
/// As [`optimise`](super::optimise()); [`OptimiseError::InvalidOption`] when `per_turn < 2`.
pub fn optimise_spiral(
    cell: &CellLayout,
    spiral: &LayerPoints,
    per_turn: usize,
    opts: &OptimiseOptions,
) -> Result<Plan, OptimiseError> {
    validate_input(cell, std::slice::from_ref(spiral), opts)?;
    if per_turn < 2 {
        return Err(OptimiseError::InvalidOption {
            field: "per_turn",
            value: per_turn as f64,
            reason: "must be at least 2",
        });
    }
    let t0 = Instant::now();
    let n = spiral.points.len();
    let mut starts: Vec<usize> = (0..n).step_by(per_turn).collect();
    // a last turn of fewer than 2 points joins the one before
    if starts.len() > 1 && n - starts[starts.len() - 1] < 2 {
        starts.pop();
    }
    let mut plans: Vec<LayerPlan> = Vec::with_capacity(starts.len());
    let mut floor = 0.0;
    for (k, &a) in starts.iter().enumerate() {
        let b = starts.get(k + 1).copied().unwrap_or(n);
        let anchor = plans.last().and_then(|prev: &LayerPlan| {
            let last = prev.points.last()?;
            Some(Anchor {
                r_z: last.r_z,
                joints: last.joints?,
                configuration: prev.configuration.chosen,
                floor,
            })
        });
        let from = if anchor.is_some() { a - 1 } else { a };
        let turn = LayerPoints::whole(k, spiral.points[from..b].to_vec());
        let (mut plan, end_floor) = optimise_layer(cell, &turn, opts, anchor);
        floor = end_floor;
        if anchor.is_some() {
            strip_shared_point(&mut plan);
        }
        plans.push(plan);
    }
    let transitions = transitions(cell, &plans);
    Ok(Plan {
        layers: plans,
        transitions,
        time_s: t0.elapsed().as_secs_f64(),
    })
}

/// Drops point 0 (the previous turn's last point) from a turn's plan and
/// renumbers the reported points.
fn strip_shared_point(plan: &mut LayerPlan) {
    if !plan.points.is_empty() {
        plan.points.remove(0);
    }
    plan.violations.retain(|v| v.point > 0);
    for v in &mut plan.violations {
        v.point -= 1;
    }
    match &mut plan.status {
        LayerStatus::Infeasible { binding } | LayerStatus::FixedViolates { binding } => {
            binding.point = binding.point.saturating_sub(1);
        }
        LayerStatus::NoSolution { point, .. } => *point = point.saturating_sub(1),
        _ => {}
    }
}
