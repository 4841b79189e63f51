//! **Stage 6 — slowing down where an axis cannot keep up.** Takes a
//! [`Plan`] and its layers ([`LayerPoints`], part frame, each point at the
//! travel speed the process asks for), and for each entry (a layer, or a
//! bead of a split layer) the plan could not build, plans it again with
//! every point at the slowest speed of the process window, `floor_mm_s`.
//! Where it then plans, each point gets the fastest speed within
//! `[floor_mm_s, its own]` at which every joint, arm and positioner, keeps
//! its speed bound from the previous point, and the arm is planned again at
//! those speeds on the same positioner law (the plan at the floor speed is
//! kept when that fails). So the torch slows only where an axis binds, and
//! only on layers that cannot be built at the process's speed; the wire feed
//! follows the speed downstream, so that the bead's cross-section stays
//! (SPEC §5: `A = pi d^2/4 · WFS/TS`). mm, mm/s, rad.

use crate::robot::cell::{CellLayout, CellPoint};

use super::split::shift_turns;
use super::{optimise, transitions, LayerPlan, LayerPoints, OptimiseError, OptimiseOptions, Plan};

/// A slowed step's joints turn at most this fraction of their maximum speed
/// on average from point to point: the controller interpolates the tool
/// between the points (a straight line, the orientation by slerp), and the
/// joints' speed peaks within a step above their average there, most near
/// the wrist singularity where the steps slow down.
const SPEED_FRACTION: f64 = 0.8;

/// Slowed speeds are rounded down to whole steps of this fraction of the
/// point's own speed: a slowed bead runs at a few speeds (at most
/// `1 / SPEED_STEP`) rather than one a point, so its program changes speed
/// and wire feed (a FANUC weld schedule, a KUKA analog command, an ABB
/// welddata) a few times, not at every move. Rounding down keeps the bound.
const SPEED_STEP: f64 = 0.05;

/// One entry of a plan slowed down by [`slow_refused_layers`].
#[derive(Debug, Clone, PartialEq)]
pub struct SlowedBead {
    /// Layer index.
    pub layer: usize,
    /// The bead within the layer (0 for a whole layer).
    pub bead: usize,
    /// Points (of the bead) reached slower than the process asks.
    pub points_slowed: usize,
    /// The slowest speed of the bead (mm/s).
    pub slowest_mm_s: f64,
    /// The point of the bead (index in the layer) reached at that speed.
    pub slowest_point: usize,
    /// Why: how the plan at the process's speed failed.
    pub why: String,
}

/// The layers and plan of [`slow_refused_layers`], with the entries slowed.
#[derive(Debug, Clone, PartialEq)]
pub struct SlowPlan {
    /// The layers, the slowed ones with their points' new speeds.
    pub layers: Vec<LayerPoints>,
    /// The plan, one entry per entry of `layers`.
    pub plan: Plan,
    /// The entries slowed, in path order.
    pub slowed: Vec<SlowedBead>,
}

/// Slows down the entries of `layers` that `plan` (made from them) could
/// not build, where they then plan in `cell` ([module doc](self)); the
/// others are left as they are. `floor_mm_s`: the slowest admissible travel
/// speed (mm/s), at most every point's own.
///
/// # Errors
/// As [`optimise`]; [`OptimiseError::InvalidOption`] for a floor that is
/// not finite and positive.
pub fn slow_refused_layers(
    cell: &CellLayout,
    layers: Vec<LayerPoints>,
    plan: Plan,
    floor_mm_s: f64,
    opts: &OptimiseOptions,
) -> Result<SlowPlan, OptimiseError> {
    if !(floor_mm_s > 0.0 && floor_mm_s.is_finite()) {
        return Err(OptimiseError::InvalidOption {
            field: "travel_speed_min_mm_s",
            value: floor_mm_s,
            reason: "must be finite and > 0",
        });
    }
    let refused: Vec<usize> = (0..layers.len())
        .filter(|&k| !plan.layers[k].status.is_feasible())
        .collect();
    let at_floor: Vec<LayerPoints> = refused
        .iter()
        .map(|&k| with_speeds(&layers[k], |p| p.travel_speed_mm_s.min(floor_mm_s)))
        .collect();
    if at_floor.is_empty() {
        return Ok(SlowPlan {
            layers,
            plan,
            slowed: Vec::new(),
        });
    }
    let floor_plan = optimise(cell, &at_floor, opts)?;
    let mut time_s = plan.time_s + floor_plan.time_s;
    // the entries that plan at the floor, with the speeds their joints allow
    let mut planned: Vec<(usize, LayerPoints, LayerPlan)> = Vec::new();
    for ((&k, lp), pl) in refused.iter().zip(&at_floor).zip(floor_plan.layers) {
        if !pl.status.is_feasible() {
            continue;
        }
        let sped = with_joint_speeds(cell, &layers[k], &pl, floor_mm_s);
        planned.push((k, sped.unwrap_or_else(|| lp.clone()), pl));
    }
    // the arm again at those speeds, on the floor plan's positioner law
    let again: Vec<LayerPoints> = planned
        .iter()
        .map(|(_, lp, pl)| match pl.positioner.as_ref() {
            Some(law) => lp.with_positioner(&law.joints),
            None => lp.clone(),
        })
        .collect();
    if !again.is_empty() {
        let replanned = optimise(cell, &again, opts)?;
        time_s += replanned.time_s;
        for ((entry, sped), mut p) in planned.iter_mut().zip(again).zip(replanned.layers) {
            let (k, lp, pl) = entry;
            if p.status.is_feasible() {
                p.positioner = pl.positioner.take();
                *lp = sped;
                *pl = p;
            } else {
                // the plan at the floor speed, every point at it
                *lp = at_floor[refused.iter().position(|r| r == k).unwrap_or(0)].clone();
            }
        }
    }
    let mut out_layers = layers;
    let mut out_plans = plan.layers;
    let mut slowed = Vec::with_capacity(planned.len());
    let mut touched = vec![false; out_layers.len()];
    for (k, lp, pl) in planned {
        slowed.push(slowed_bead(&out_layers[k], &lp, &out_plans[k]));
        touched[k] = true;
        if k + 1 < touched.len() {
            touched[k + 1] = true;
        }
        out_layers[k] = lp;
        out_plans[k] = pl;
    }
    shift_turns(cell, &mut out_plans, &|k| touched[k]);
    let plan = Plan {
        transitions: transitions(cell, &out_plans),
        layers: out_plans,
        time_s,
    };
    Ok(SlowPlan {
        layers: out_layers,
        plan,
        slowed,
    })
}

/// `layer` with each point's speed `speed(point)` (mm/s).
fn with_speeds(layer: &LayerPoints, speed: impl Fn(&CellPoint) -> f64) -> LayerPoints {
    LayerPoints {
        points: layer
            .points
            .iter()
            .map(|p| CellPoint {
                travel_speed_mm_s: speed(p),
                ..*p
            })
            .collect(),
        ..layer.clone()
    }
}

/// `layer` (each point at the speed the process asks) with each point at
/// the fastest speed within `[floor_mm_s, its own]` at which the joints
/// `plan` planned for it (arm and positioner) keep their speed bounds from
/// the previous point; `None` when the plan lacks a point's joints.
fn with_joint_speeds(
    cell: &CellLayout,
    layer: &LayerPoints,
    plan: &LayerPlan,
    floor_mm_s: f64,
) -> Option<LayerPoints> {
    let arm_max = cell.robot().max_speed_rad_s;
    let positioner_max = match cell {
        CellLayout::TorchCarried(c) => Some(c.positioner.max_speed_rad_s),
        CellLayout::PartCarried(_) => None,
    };
    let mut out = layer.clone();
    for m in 1..layer.points.len().min(plan.points.len()) {
        let (a, b) = (&plan.points[m - 1], &plan.points[m]);
        let (qa, qb) = (a.joints?, b.joints?);
        // the time the slowest joint needs for the step (s)
        let mut need: f64 = 0.0;
        for j in 0..6 {
            need = need.max((qb[j] - qa[j]).abs() / arm_max[j]);
        }
        if let (Some(max), Some(ea), Some(eb)) = (positioner_max, a.positioner, b.positioner) {
            for k in 0..2 {
                need = need.max((eb[k] - ea[k]).abs() / max[k]);
            }
        }
        let d = (layer.points[m].position_mm - layer.points[m - 1].position_mm).norm();
        let own = layer.points[m].travel_speed_mm_s;
        let v = if need > 0.0 {
            let step = SPEED_STEP * own;
            ((SPEED_FRACTION * d / need / step).floor() * step).min(own)
        } else {
            own
        };
        out.points[m].travel_speed_mm_s = v.max(floor_mm_s.min(own));
    }
    if let (Some(first), Some(second)) = (out.points.first().copied(), out.points.get(1)) {
        // a bead's first point has no step into it: its speed is the next one's
        out.points[0].travel_speed_mm_s = second.travel_speed_mm_s.min(first.travel_speed_mm_s);
    }
    Some(out)
}

/// What [`SlowedBead`] says of `slowed`, the entry `asked` slowed down;
/// `refused`: the plan of `asked`.
fn slowed_bead(asked: &LayerPoints, slowed: &LayerPoints, refused: &LayerPlan) -> SlowedBead {
    let mut points_slowed = 0;
    let (mut slowest_mm_s, mut slowest_point) = (f64::INFINITY, asked.first_point);
    for (m, (a, s)) in asked.points.iter().zip(&slowed.points).enumerate().skip(1) {
        if s.travel_speed_mm_s < a.travel_speed_mm_s {
            points_slowed += 1;
        }
        if s.travel_speed_mm_s < slowest_mm_s {
            slowest_mm_s = s.travel_speed_mm_s;
            slowest_point = asked.first_point + m;
        }
    }
    SlowedBead {
        layer: asked.layer,
        bead: asked.bead,
        points_slowed,
        slowest_mm_s,
        slowest_point,
        why: refused.status.to_string(),
    }
}
