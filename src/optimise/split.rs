//! **Stage 6 — bead splits at corners (torch-carried cell).** Takes a
//! [`Plan`] and its layers ([`LayerPoints`], part frame), and for each layer
//! the plan could not build whole, the points where its bead may be split
//! (its corners inside the bead, from the path stage); returns the layers
//! and the plan with each such layer split into beads there, where every
//! bead then plans, and the splits made ([`BeadSplit`]). A bead ends on the
//! corner and the next starts on it after an arc-off move, during which the
//! positioner and the wrist reorient (the program stage checks that move
//! against the wall and the cell as it checks the moves between layers).
//! Layers that plan whole are left as they are: as few splits as needed.

use crate::robot::cell::CellLayout;

use super::{optimise, transitions, LayerPoints, OptimiseError, OptimiseOptions, Plan};

/// One split of a layer's bead at a corner.
#[derive(Debug, Clone, PartialEq)]
pub struct BeadSplit {
    /// Layer index.
    pub layer: usize,
    /// The layer's point (index in the layer) where one bead ends and the
    /// next starts.
    pub point: usize,
    /// The bead that starts there (1 for the layer's first split).
    pub bead: usize,
    /// Why the layer was split: how its plan as one bead failed.
    pub why: String,
}

/// The layers and plan of [`split_refused_layers`], with its splits.
#[derive(Debug, Clone, PartialEq)]
pub struct SplitPlan {
    /// The layers, each split one as its beads in order.
    pub layers: Vec<LayerPoints>,
    /// The plan, one entry per entry of `layers`.
    pub plan: Plan,
    /// The splits made, in path order.
    pub splits: Vec<BeadSplit>,
}

/// Splits the layers that `plan` (made from `layers`) could not build whole
/// into the beads `beads_of(&layers[k])` gives (in order, each starting
/// where the one before ends, as [`LayerPoints::split_at`] makes them;
/// fewer than two: the layer is left), when every one of its beads then
/// plans in `cell` ([module doc](self)). The beads' turns are shifted by
/// whole turns to start nearest the previous bead's end, within the turn's
/// travel.
///
/// # Errors
/// As [`optimise`] on the beads.
pub fn split_refused_layers(
    cell: &CellLayout,
    layers: Vec<LayerPoints>,
    plan: Plan,
    beads_of: &dyn Fn(&LayerPoints) -> Vec<LayerPoints>,
    opts: &OptimiseOptions,
) -> Result<SplitPlan, OptimiseError> {
    // the beads of every refused layer with corners inside its bead
    let mut candidates: Vec<(usize, Vec<usize>)> = Vec::new();
    let mut beads: Vec<LayerPoints> = Vec::new();
    for (k, (lp, pl)) in layers.iter().zip(&plan.layers).enumerate() {
        if pl.status.is_feasible() || lp.bead != 0 {
            continue;
        }
        let split = beads_of(lp);
        if split.len() < 2 {
            continue;
        }
        candidates.push((k, split.iter().skip(1).map(|b| b.first_point).collect()));
        beads.extend(split);
    }
    if beads.is_empty() {
        return Ok(SplitPlan {
            layers,
            plan,
            splits: Vec::new(),
        });
    }
    let solved = optimise(cell, &beads, opts)?;
    let mut out_layers = Vec::with_capacity(layers.len() + beads.len());
    let mut out_plans = Vec::with_capacity(layers.len() + beads.len());
    let mut splits = Vec::new();
    let mut next = 0; // the first bead of the next candidate in `beads`
    let mut candidate = candidates.iter().peekable();
    for (k, (lp, pl)) in layers.into_iter().zip(plan.layers).enumerate() {
        let Some((_, points)) = candidate.next_if(|(c, _)| *c == k) else {
            out_layers.push(lp);
            out_plans.push(pl);
            continue;
        };
        let range = next..next + points.len() + 1;
        next = range.end;
        if !solved.layers[range.clone()]
            .iter()
            .all(|b| b.status.is_feasible())
        {
            out_layers.push(lp);
            out_plans.push(pl);
            continue;
        }
        let why = pl.status.to_string();
        splits.extend(points.iter().enumerate().map(|(b, &point)| BeadSplit {
            layer: lp.layer,
            point,
            bead: b + 1,
            why: why.clone(),
        }));
        out_layers.extend(beads[range.clone()].iter().cloned());
        out_plans.extend(solved.layers[range].iter().cloned());
    }
    // every split bead (bead > 0, and the first bead of a split layer)
    let split =
        |k: usize| out_layers[k].bead > 0 || out_layers.get(k + 1).is_some_and(|l| l.bead > 0);
    shift_turns(cell, &mut out_plans, &split);
    let plan = Plan {
        transitions: transitions(cell, &out_plans),
        layers: out_plans,
        time_s: plan.time_s + solved.time_s,
    };
    Ok(SplitPlan {
        layers: out_layers,
        plan,
        splits,
    })
}

/// Shifts the positioner's turn of every entry `k > 0` that `which(k)`
/// names by whole turns to start nearest the end of the entry before it,
/// where the entry stays within the turn's travel.
pub(super) fn shift_turns(
    cell: &CellLayout,
    plans: &mut [super::LayerPlan],
    which: &dyn Fn(usize) -> bool,
) {
    use std::f64::consts::TAU;
    let CellLayout::TorchCarried(c) = cell else {
        return;
    };
    let turn = c.positioner.limits[1];
    for k in 1..plans.len() {
        if !which(k) {
            continue;
        }
        let prev = plans[k - 1].points.last().and_then(|p| p.positioner);
        let first = plans[k].points.first().and_then(|p| p.positioner);
        let (Some(prev), Some(first)) = (prev, first) else {
            continue;
        };
        let n = ((prev[1] - first[1]) / TAU).round();
        if n == 0.0 {
            continue;
        }
        let fits = plans[k]
            .points
            .iter()
            .filter_map(|p| p.positioner)
            .all(|q| turn.contains(q[1] + n * TAU));
        if !fits {
            continue;
        }
        for p in &mut plans[k].points {
            if let Some(q) = p.positioner.as_mut() {
                q[1] += n * TAU;
            }
        }
        if let Some(law) = plans[k].positioner.as_mut() {
            for q in &mut law.joints {
                q[1] += n * TAU;
            }
        }
    }
}
