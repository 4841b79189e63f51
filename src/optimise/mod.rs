//! **Stage 6 — layer-by-layer optimisation of the free rotation `R_Z`.**
//! Takes the layers of a path as cell points (part frame: position mm, tool
//! axis, build direction) and a [`CellLayout`], and returns a [`Plan`]: per layer
//! the IK branch (and why), the `R_Z` law (rad), joints per point (rad),
//! a status naming the binding constraint when the layer cannot be built,
//! and the trajectory quality at the programmed travel speed (mm/s).
//! SPEC §7, thesis chapter 4.
//!
//! Per layer `C`, choose `R_Z` at every point to minimise the weighted joint
//! displacement (eq. 4.3) or the positioning uncertainty (eq. 4.13), subject
//! per point to the joint travel (eq. 4.5), a dexterity floor (eq. 4.6), the
//! hose torsion in the torch-carried cell (eq. 4.8) and the joint speeds.
//!
//! | piece | module | entry points |
//! |---|---|---|
//! | options (plain data, `validate`) | [`options`] | [`OptimiseOptions`], [`Parameterisation`] |
//! | torch-carried cell: the positioner's laws within the cone, solved before `R_Z` (stage 5a) | [`positioner`] | [`positioner::positioner_law`], [`positioner::required_rotation_rate`] |
//! | `R_Z = B c`: polynomials (eq. 4.1–4.2), per point | [`parameterisation`] | [`parameterisation::Basis`] |
//! | the per-layer problem (objective, constraints, `dq/dR_Z`) | `problem` | — |
//! | sequential QP, trust region, elastic mode | `sqp` | — |
//! | the elastic QP both SQPs solve (closed form, else clarabel on a working set; a leaf) | `qp` | — |
//! | outcomes as data | [`outcome`] | [`Plan`], [`LayerPlan`], [`LayerStatus`] |
//! | a layer's setup: times, angles, problem per branch, dexterity floors | `setup` | — |
//! | seeds scored in every branch | `seed` | — |
//! | branch choice and the per-branch solve | `branch` | — |
//! | the polynomial degree loop | `degree` | — |
//! | a long layer's law on a subsample, certified on every point | `subsample` | [`OptimiseOptions::subsample_points`] |
//! | the point-by-point baseline [§4.1.4] | `point_by_point` | — |
//! | a layer's status, objective figures and quality | `report` | — |
//! | spiral paths, turn by turn | `spiral` | [`optimise_spiral`] |
//! | a refused layer split into beads at its corners (torch-carried cell) | [`split`] | [`split_refused_layers`] |
//! | the driver | here | [`optimise`], [`layer_points`], [`trajectory_inputs`] |
//!
//! How a layer is solved:
//! 1. **Branch.** Every IK branch (FANUC `N/F U/D T/B`) is scored on a few
//!    points of the layer for a coarse set of seeds (constant `R_Z`, and
//!    `c − theta` on layers turning about the part Z axis); the branch whose
//!    best seed is feasible and most centred in the joint ranges is kept for
//!    the whole layer (the cell's own branch wins unless another is 1.5 times
//!    more centred) — see
//!    [`ConfigurationChoiceReport`]. If its optimisation ends infeasible the
//!    next branches are tried.
//! 2. **Polynomial degree** raised from the seed's with warm starts (the new
//!    coefficient starts at 0) until the objective stops improving [§4.2.1]
//!    — or, with no constraint in reach, until the Gauss–Newton model at the
//!    current optimum bounds the next degree's gain far below that criterion
//!    (the next degree is then not solved).
//! 3. **SQP**: the joints are linearised with the analytic `dq/dR_Z`
//!    ([`CellLayout::pose`]'s flange twist through `J⁻¹`), chained through the
//!    basis; each QP (closed form when no row binds, clarabel on a working
//!    set otherwise) has an l∞ elastic variable, so an infeasible layer ends
//!    at the least violation with the binding constraint named. The
//!    dexterity's SVD runs only where a cheap bound cannot show the point
//!    well above its floor, warm-started along the layer.
//! 4. **Subsample, then every point.** On a layer of more than twice
//!    [`OptimiseOptions::subsample_points`] points, steps 2–3 run on about
//!    that many points (spread along the layer, denser where the tool axis
//!    turns; the objective weighted as the whole layer's estimate, the
//!    speed bound on the mean speed between samples). The law found is
//!    evaluated on every point (one IK pass) and every constraint checked
//!    there; where one is violated or within half the solver's margin of
//!    its bound the worst point (and the one before it) joins the samples
//!    and the law is re-solved at the same degree. A layer the subsample
//!    cannot certify is solved on every point, so the verdict is the whole
//!    layer's; the plan's joints, status and quality always are. The SQP's
//!    cost is then bounded per layer and the planning time grows linearly
//!    with the points (the passes over every point: the floor, the
//!    certification, the trajectory re-check and the report).
//! 5. **Transitions**: every layer starts from the joint representation inside
//!    the travel (J4/J6 rewound with the arc off), and the centring term of
//!    [`OptimiseOptions::centring_weight`] keeps each layer well inside the
//!    ranges; [`Transition`] reports the arc-off moves.
//!
//! Layers are independent and solved in parallel (rayon, order preserved;
//! each layer's computation is single-threaded, so results do not depend on
//! the thread count).
//!
//! Program emission (FANUC `.ls` and others) is another stage: it takes the
//! [`Plan`] (joints per point, branch per layer) and must refuse a plan that
//! is not [`Plan::is_feasible`].
//!
//! # Example
//! ```
//! use waam_slicer::math::{Point3, UnitVector3, Vector3};
//! use waam_slicer::optimise::{optimise, LayerPoints, OptimiseOptions};
//! use waam_slicer::robot::{CellLayout, CellPoint, Configuration, PartCarriedCell, RobotModel};
//!
//! let cell = CellLayout::PartCarried(PartCarriedCell {
//!     name: "ROBOWAM".into(),
//!     robot: RobotModel::arcmate_120ic_nominal().with_j5_travel_deg(135.0),
//!     deposition_point_mm: Point3::new(1045.747, -630.155, 653.167),
//!     configuration: Configuration::from_fanuc("F U T").unwrap(),
//!     flange_from_part: waam_slicer::math::Isometry3::identity(),
//! });
//! // one layer of a cylinder of radius 40 mm at Z = 10 mm, tool axis up
//! let points = (0..60)
//!     .map(|k| {
//!         let v = std::f64::consts::TAU * k as f64 / 60.0;
//!         CellPoint {
//!             position_mm: Point3::new(40.0 * v.cos(), 40.0 * v.sin(), 10.0),
//!             tool_axis: UnitVector3::new_normalize(Vector3::z()),
//!             build_direction: None,
//!             positioner: None,
//!             travel_speed_mm_s: 6.0,
//!         }
//!     })
//!     .collect();
//! let plan = optimise(&cell, &[LayerPoints::whole(0, points)], &OptimiseOptions::default()).unwrap();
//! assert!(plan.is_feasible());
//! ```

mod branch;
mod branch_types;
mod degree;
pub mod options;
pub mod outcome;
pub mod parameterisation;
mod point_by_point;
pub mod positioner;
mod problem;
mod qp;
mod report;
mod seed;
mod setup;
pub mod slow;
mod spiral;
pub mod split;
mod sqp;
mod subsample;
#[cfg(test)]
mod tests;

pub use options::{
    Abscissa, ConfigurationChoice, DexterityFloor, Objective, OptimiseOptions, Parameterisation,
    SqpOptions, DEFAULT_STOP_RELATIVE_GAIN,
};
pub use outcome::{
    BindingConstraint, ConfigurationChoiceReport, Constraint, LayerPlan, LayerQuality, LayerStatus,
    ObjectiveReport, OptimiseError, Plan, PlannedPoint, SolvedRzLaw, SolverReport, Transition,
};

pub use slow::{slow_refused_layers, SlowPlan, SlowedBead};
pub use spiral::optimise_spiral;
pub use split::{split_refused_layers, BeadSplit, SplitPlan};

use std::time::Instant;

use rayon::prelude::*;

use crate::math::UnitVector3;
use crate::path::Path;
use crate::robot::cell::{CellLayout, CellPoint};
use crate::robot::trajectory::PathPointInput;
use crate::toolaxis::LocalFrame;

use branch::optimise_layer;
use report::limit_distance;

/// The points of one layer, or of one bead of a layer split at its corners
/// ([`LayerPoints::split_at`]), as the cells see them (part frame).
#[derive(Debug, Clone, PartialEq)]
pub struct LayerPoints {
    /// Layer index (reported back).
    pub layer: usize,
    /// The bead within the layer: 0 for a layer's first (or only) bead, one
    /// more at each split.
    pub bead: usize,
    /// Index, in the layer, of the first of `points` (0 for a whole layer).
    pub first_point: usize,
    /// The points in deposition order.
    pub points: Vec<CellPoint>,
}

impl LayerPoints {
    /// A whole layer: bead 0 from the layer's first point.
    pub fn whole(layer: usize, points: Vec<CellPoint>) -> Self {
        Self {
            layer,
            bead: 0,
            first_point: 0,
            points,
        }
    }

    /// This whole layer split into beads at its points `splits` (indices in
    /// the layer, increasing, each with a point either side): bead `k` ends
    /// on split `k` and bead `k + 1` starts there, so the split point is in
    /// both. The split point's tool axis and build direction in each bead
    /// are its neighbour's within that bead (the one before it in the bead
    /// that ends there, the one after in the bead that starts): one-sided,
    /// so that neither bead's end takes a frame half way round the corner.
    pub fn split_at(&self, splits: &[usize]) -> Vec<LayerPoints> {
        let n = self.points.len();
        let mut bounds: Vec<usize> = splits
            .iter()
            .copied()
            .filter(|&s| s > 0 && s + 1 < n)
            .collect();
        bounds.dedup();
        let mut beads = Vec::with_capacity(bounds.len() + 1);
        let mut start = 0;
        for (k, end) in bounds
            .iter()
            .copied()
            .chain(std::iter::once(n - 1))
            .enumerate()
        {
            let mut points = self.points[start..=end].to_vec();
            let frame_of = |p: &CellPoint, from: &CellPoint| CellPoint {
                tool_axis: from.tool_axis,
                build_direction: from.build_direction,
                ..*p
            };
            if k > 0 {
                points[0] = frame_of(&points[0], &self.points[start + 1]);
            }
            if end + 1 < n {
                let last = points.len() - 1;
                points[last] = frame_of(&points[last], &self.points[end - 1]);
            }
            beads.push(LayerPoints {
                layer: self.layer,
                bead: k,
                first_point: self.first_point + start,
                points,
            });
            start = end;
        }
        beads
    }

    /// The same layer with the positioner joints `[q7, q8]` (rad) planned
    /// for its points, one per point.
    pub fn with_positioner(&self, joints: &[crate::robot::positioner::PositionerJoints]) -> Self {
        Self {
            layer: self.layer,
            bead: self.bead,
            first_point: self.first_point,
            points: self
                .points
                .iter()
                .zip(joints)
                .map(|(p, q)| CellPoint {
                    positioner: Some(*q),
                    ..*p
                })
                .collect(),
        }
    }
}

/// Layers of `path` with the tool axes and build directions of `frames`
/// (from [`toolaxis::local_frames`](crate::toolaxis::local_frames)), every
/// point reached at `travel_speed_mm_s` (mm/s).
pub fn layer_points(
    path: &Path,
    frames: &[Vec<LocalFrame>],
    travel_speed_mm_s: f64,
) -> Vec<LayerPoints> {
    path.layers
        .iter()
        .zip(frames)
        .enumerate()
        .map(|(i, (layer, fr))| LayerPoints {
            layer: i,
            bead: 0,
            first_point: 0,
            points: layer
                .points
                .iter()
                .zip(fr)
                .map(|(p, f)| CellPoint {
                    position_mm: p.position,
                    tool_axis: UnitVector3::new_normalize(f.tool),
                    build_direction: Some(UnitVector3::new_normalize(f.build)),
                    positioner: None,
                    travel_speed_mm_s,
                })
                .collect(),
        })
        .collect()
}

/// The input of [`joint_trajectory`](crate::robot::trajectory::joint_trajectory) and of the program stage: every point
/// of `layers`, in order, with the `R_Z` that `plan` chose for it (`plan`
/// made from the same `layers`).
pub fn trajectory_inputs(layers: &[LayerPoints], plan: &Plan) -> Vec<PathPointInput> {
    layers
        .iter()
        .zip(&plan.layers)
        .flat_map(|(lp, pl)| {
            lp.points
                .iter()
                .zip(&pl.points)
                .enumerate()
                .map(move |(m, (cp, pp))| {
                    let mut p = path_point(lp.layer, lp.first_point + m, cp, pp.r_z);
                    p.bead = lp.bead;
                    // the positioner as planned (its laws live in the plan)
                    p.positioner = pp.positioner.or(p.positioner);
                    p
                })
        })
        .collect()
}

/// One point of a layer as the trajectory stage takes it.
fn path_point(layer: usize, point: usize, cp: &CellPoint, r_z: f64) -> PathPointInput {
    PathPointInput {
        layer,
        point,
        position_mm: cp.position_mm,
        tool_axis: cp.tool_axis,
        build_direction: cp.build_direction,
        r_z,
        positioner: cp.positioner,
        bead: 0,
        travel_speed_mm_s: cp.travel_speed_mm_s,
    }
}

/// Optimises `R_Z` layer by layer [SPEC §7].
///
/// # Errors
/// Bad input only: [`OptimiseError::InvalidOption`], [`OptimiseError::Cell`],
/// [`OptimiseError::TooFewPoints`], [`OptimiseError::BadPoint`]. Layers that
/// cannot be built are reported in the plan ([`LayerStatus`]).
pub fn optimise(
    cell: &CellLayout,
    layers: &[LayerPoints],
    opts: &OptimiseOptions,
) -> Result<Plan, OptimiseError> {
    optimise_with(cell, layers, opts, &|_, _| true)
}

/// [`optimise`] with a host's hook: `on_layer(done, total)` is called as
/// each layer is solved (from the worker threads, in any order); once it
/// returns `false` the layers not yet started are skipped and the run ends
/// with [`OptimiseError::Cancelled`]. The plan, when there is one, is the
/// same as [`optimise`]'s.
///
/// # Errors
/// As [`optimise`]; [`OptimiseError::Cancelled`].
pub fn optimise_with(
    cell: &CellLayout,
    layers: &[LayerPoints],
    opts: &OptimiseOptions,
    on_layer: &(dyn Fn(usize, usize) -> bool + Sync),
) -> Result<Plan, OptimiseError> {
    use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
    validate_input(cell, layers, opts)?;
    let t0 = Instant::now();
    let (scheduled, laws) = schedule_positioner(cell, layers, opts);
    let given = layers;
    let layers: &[LayerPoints] = scheduled.as_deref().unwrap_or(layers);
    let (done, stop) = (AtomicUsize::new(0), AtomicBool::new(false));
    let total = layers.len();
    let solve = |(i, l): (usize, &LayerPoints)| -> Option<LayerPlan> {
        if stop.load(Ordering::Relaxed) {
            return None;
        }
        let mut plan = optimise_layer(cell, l, opts, None).0;
        if let (CellLayout::TorchCarried(c), Some(laws)) = (cell, &laws) {
            plan.positioner = Some(laws[i].clone());
            // the positioner's laws see the arm only through a proxy: where
            // the arm cannot follow the law, the other laws that keep the
            // cone (the thesis's exact vertical first), best first
            if !plan.status.is_feasible() {
                for alt in &laws[i].alternatives {
                    let p =
                        optimise_layer(cell, &given[i].with_positioner(&alt.joints), opts, None).0;
                    if p.status.is_feasible() {
                        plan = p;
                        plan.positioner = Some(alt.clone());
                        break;
                    }
                }
            }
            // then the law solved again under the arm's own limits
            let law_holds = plan.positioner.as_ref().is_some_and(|l| l.feasible);
            if !plan.status.is_feasible() && law_holds {
                if let Some((p, law)) = arm_coupled(c, cell, &given[i], &plan, opts) {
                    plan = p;
                    plan.positioner = Some(law);
                }
            }
        }
        if !on_layer(done.fetch_add(1, Ordering::Relaxed) + 1, total) {
            stop.store(true, Ordering::Relaxed);
        }
        Some(plan)
    };
    let plans: Vec<Option<LayerPlan>> = if opts.parallel {
        layers.par_iter().enumerate().map(solve).collect()
    } else {
        layers.iter().enumerate().map(solve).collect()
    };
    if stop.load(Ordering::Relaxed) {
        return Err(OptimiseError::Cancelled {
            layers_done: done.load(Ordering::Relaxed),
            layers: total,
        });
    }
    let plans: Vec<LayerPlan> = plans.into_iter().flatten().collect();
    let transitions = transitions(cell, &plans);
    Ok(Plan {
        layers: plans,
        transitions,
        time_s: t0.elapsed().as_secs_f64(),
    })
}

/// Rounds of [`arm_coupled`]: each adds the arm's rows at the points where
/// the last plan broke or neared its limits.
const ARM_ROUNDS: usize = 3;

/// The arm's quantities within this of their bound get a row (rad).
const ARM_BAND_RAD: f64 = 0.05;

/// At most this many rows a round, the nearest their bounds first.
const ARM_ROWS_MAX: usize = 24;

/// Finite-difference step of the positioner joints for the arm's
/// derivatives (rad).
const ARM_FD_RAD: f64 = 1e-6;

/// The arm in the positioner's loop: where the arm cannot follow a layer's
/// positioner law (hose torsion, a joint's travel), the law is solved again
/// ([`positioner::positioner_law_for_arm`]) with rows that hold the arm's
/// hose and joints at the points where `plan` broke or neared them,
/// linearised through the arm's inverse kinematics at the planned `R_Z`
/// (finite differences of the positioner joints), and the layer planned
/// again on it; a few rounds, the rows accumulating. Returns the first
/// feasible plan with its law.
fn arm_coupled(
    c: &crate::robot::cell::TorchCarriedCell,
    cell: &CellLayout,
    layer: &LayerPoints,
    plan: &LayerPlan,
    opts: &OptimiseOptions,
) -> Option<(LayerPlan, positioner::PositionerLaw)> {
    let mut rows: Vec<positioner::ArmRow> = Vec::new();
    let mut current = plan.clone();
    for _ in 0..ARM_ROUNDS {
        let new = arm_rows(c, layer, &current, opts);
        if new.is_empty() {
            return None;
        }
        rows.extend(new);
        let start: Vec<_> = current
            .points
            .iter()
            .map(|p| p.positioner)
            .collect::<Option<_>>()?;
        let law = positioner::positioner_law_for_arm(
            c,
            &layer.points,
            opts.joint_limit_margin_rad,
            &opts.positioner,
            &rows,
            &start,
        );
        if !law.feasible {
            return None;
        }
        let p = optimise_layer(cell, &layer.with_positioner(&law.joints), opts, None).0;
        if p.status.is_feasible() {
            return Some((p, law));
        }
        current = p;
    }
    None
}

/// The arm's rows of [`arm_coupled`] for `plan`: at the points where the
/// hose torsion `|q4 + q6|` or a joint is within [`ARM_BAND_RAD`] of its
/// bound (or past it), the nearest [`ARM_ROWS_MAX`] first.
fn arm_rows(
    c: &crate::robot::cell::TorchCarriedCell,
    layer: &LayerPoints,
    plan: &LayerPlan,
    opts: &OptimiseOptions,
) -> Vec<positioner::ArmRow> {
    // which quantity: the hose (with the sign of q4 + q6), or joint j's
    // upper (+1) or lower (-1) bound
    enum Near {
        Hose(f64),
        Joint(usize, f64),
    }
    let robot = &c.robot;
    let hose_max = c.max_hose_torsion_rad;
    let mut near: Vec<(f64, usize, Near)> = Vec::new();
    for (m, pp) in plan.points.iter().enumerate() {
        let (Some(q), Some(_)) = (pp.joints, pp.positioner) else {
            continue;
        };
        let h = q[3] + q[5];
        if hose_max.is_finite() && hose_max - h.abs() < ARM_BAND_RAD {
            near.push((hose_max - h.abs(), m, Near::Hose(h.signum())));
        }
        for (j, l) in robot.limits.iter().enumerate() {
            let (lo, hi) = (
                l.lower_rad + opts.joint_limit_margin_rad,
                l.upper_rad - opts.joint_limit_margin_rad,
            );
            if hi.is_finite() && hi - q[j] < ARM_BAND_RAD {
                near.push((hi - q[j], m, Near::Joint(j, 1.0)));
            }
            if lo.is_finite() && q[j] - lo < ARM_BAND_RAD {
                near.push((q[j] - lo, m, Near::Joint(j, -1.0)));
            }
        }
    }
    near.sort_by(|a, b| a.0.total_cmp(&b.0));
    near.truncate(ARM_ROWS_MAX);
    let cfg = plan.configuration.chosen;
    near.into_iter()
        .filter_map(|(slack, m, what)| {
            let pp = &plan.points[m];
            let (q, qp) = (pp.joints?, pp.positioner?);
            // the arm's joints' derivatives in q7, q8 at the planned R_Z
            let mut d = [[0.0; 6]; 2];
            for (k, dk) in d.iter_mut().enumerate() {
                let mut moved = qp;
                moved[k] += ARM_FD_RAD;
                let cp = CellPoint {
                    positioner: Some(moved),
                    ..layer.points[m]
                };
                let pose = c.pose(&cp, pp.r_z, moved[1]).ok()?;
                let q1 = robot.inverse_near(&pose.base_from_flange, cfg, &q).ok()?;
                for j in 0..6 {
                    dk[j] = (q1[j] - q[j]) / ARM_FD_RAD;
                }
            }
            let grad = match what {
                Near::Hose(s) => [s * (d[0][3] + d[0][5]), s * (d[1][3] + d[1][5])],
                Near::Joint(j, s) => [s * d[0][j], s * d[1][j]],
            };
            Some(positioner::ArmRow {
                point: m,
                q0: qp,
                grad,
                slack_rad: slack,
            })
        })
        .collect()
}

/// The positioner's laws of every layer (torch-carried cell, points without
/// planned positioner joints): solved per layer (in parallel with
/// `opts.parallel`), then each layer's turn shifted by whole turns to start
/// nearest the previous layer's last, within the turn's travel. Returns the
/// layers with the joints filled in and the laws; `(None, None)` when there
/// is nothing to plan.
fn schedule_positioner(
    cell: &CellLayout,
    layers: &[LayerPoints],
    opts: &OptimiseOptions,
) -> (
    Option<Vec<LayerPoints>>,
    Option<Vec<positioner::PositionerLaw>>,
) {
    let CellLayout::TorchCarried(c) = cell else {
        return (None, None);
    };
    if layers
        .iter()
        .any(|l| l.points.iter().any(|p| p.positioner.is_some()))
    {
        return (None, None);
    }
    let solve = |l: &LayerPoints| {
        positioner::positioner_law(
            c,
            &l.points,
            opts.joint_limit_margin_rad,
            0.0,
            &opts.positioner,
        )
    };
    let mut laws: Vec<positioner::PositionerLaw> = if opts.parallel {
        layers.par_iter().map(solve).collect()
    } else {
        layers.iter().map(solve).collect()
    };
    let turn = c.positioner.limits[1];
    let mut last: Option<f64> = None;
    for law in &mut laws {
        if let (Some(prev), Some(first)) = (last, law.joints.first()) {
            let k = ((prev - first[1]) / std::f64::consts::TAU).round();
            let fits = |k: f64| {
                law.joints
                    .iter()
                    .all(|q| turn.contains(q[1] + k * std::f64::consts::TAU))
            };
            let shift = [k, k - 1.0, k + 1.0, 0.0].into_iter().find(|&k| fits(k));
            if let Some(k) = shift.filter(|k| *k != 0.0) {
                for q in &mut law.joints {
                    q[1] += k * std::f64::consts::TAU;
                }
            }
        }
        // the alternatives start by whole turns nearest the law's start
        if let Some(first) = law.joints.first().map(|q| q[1]) {
            for alt in &mut law.alternatives {
                let Some(a) = alt.joints.first().map(|q| q[1]) else {
                    continue;
                };
                let k = ((first - a) / std::f64::consts::TAU).round();
                if k != 0.0
                    && alt
                        .joints
                        .iter()
                        .all(|q| turn.contains(q[1] + k * std::f64::consts::TAU))
                {
                    for q in &mut alt.joints {
                        q[1] += k * std::f64::consts::TAU;
                    }
                }
            }
        }
        last = law.joints.last().map(|q| q[1]);
    }
    let scheduled = layers
        .iter()
        .zip(&laws)
        .map(|(l, law)| l.with_positioner(&law.joints))
        .collect();
    (Some(scheduled), Some(laws))
}

fn validate_input(
    cell: &CellLayout,
    layers: &[LayerPoints],
    opts: &OptimiseOptions,
) -> Result<(), OptimiseError> {
    opts.validate()?;
    cell.validate()?;
    for l in layers {
        if l.points.len() < 2 {
            return Err(OptimiseError::TooFewPoints {
                layer: l.layer,
                points: l.points.len(),
            });
        }
        for (i, p) in l.points.iter().enumerate() {
            let finite = p.position_mm.iter().all(|v| v.is_finite())
                && p.tool_axis.iter().all(|v| v.is_finite())
                && p.build_direction
                    .is_none_or(|b| b.iter().all(|v| v.is_finite()));
            if !finite {
                return Err(OptimiseError::BadPoint {
                    layer: l.layer,
                    point: i,
                    reason: "non-finite position, tool axis or build direction",
                });
            }
            if !(p.travel_speed_mm_s > 0.0 && p.travel_speed_mm_s.is_finite()) {
                return Err(OptimiseError::BadPoint {
                    layer: l.layer,
                    point: i,
                    reason: "travel_speed_mm_s not finite and > 0",
                });
            }
        }
    }
    Ok(())
}

/// Arc-off moves between consecutive planned layers: the joint change
/// (rad) from each layer's last point to the next one's first, whether the
/// branch changes, and how far the next layer's first point is from a
/// joint's limit (rad). What [`Plan::transitions`] holds; a plan assembled
/// from layers planned apart (replan) takes it from here.
pub fn transitions(cell: &CellLayout, plans: &[LayerPlan]) -> Vec<Transition> {
    let robot = cell.robot();
    plans
        .windows(2)
        .filter_map(|w| {
            let last = w[0].points.last()?.joints?;
            let first = w[1].points.first()?.joints?;
            Some(Transition {
                from_layer: w[0].layer,
                to_layer: w[1].layer,
                joint_change_rad: std::array::from_fn(|j| first[j] - last[j]),
                branch_change: w[0].configuration.chosen != w[1].configuration.chosen,
                start_limit_distance_rad: limit_distance(robot, &first).0,
            })
        })
        .collect()
}
