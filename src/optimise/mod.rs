//! **Stage 5 — layer-by-layer optimisation of the free rotation `R_Z`.**
//! Takes the layers of a path as cell points (part frame: position mm, tool
//! axis, build direction) and a [`Cell`], and returns a [`Plan`]: per layer
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
//! | `R_Z = B c`: polynomials (eq. 4.1–4.2), per point | [`parameterisation`] | [`parameterisation::Basis`] |
//! | the per-layer problem (objective, constraints, `dq/dR_Z`) | `problem` | — |
//! | sequential QP with clarabel, trust region, elastic mode | `sqp` | — |
//! | outcomes as data | [`outcome`] | [`Plan`], [`LayerPlan`], [`LayerStatus`] |
//! | the driver | here | [`optimise`], [`optimise_spiral`], [`layer_points`] |
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
//!    ([`Cell::pose`]'s flange twist through `J⁻¹`), chained through the
//!    basis; each QP (closed form when no row binds, clarabel on a working
//!    set otherwise) has an l∞ elastic variable, so an infeasible layer ends
//!    at the least violation with the binding constraint named. The
//!    dexterity's SVD runs only where a cheap bound cannot show the point
//!    well above its floor, warm-started along the layer.
//! 4. **Transitions**: every layer starts from the joint representation inside
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
//! use waam_slicer::robot::{Cell, CellPoint, Configuration, PartCarriedCell, RobotModel};
//!
//! let cell = Cell::PartCarried(PartCarriedCell {
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
//!         }
//!     })
//!     .collect();
//! let plan = optimise(&cell, &[LayerPoints { layer: 0, points }], &OptimiseOptions::default()).unwrap();
//! assert!(plan.is_feasible());
//! ```

pub mod options;
pub mod outcome;
pub mod parameterisation;
pub mod place;
mod problem;
mod sqp;

pub use options::{
    Abscissa, ConfigurationChoice, DexterityFloor, Objective, OptimiseOptions, Parameterisation,
    SqpOptions,
};
pub use outcome::{
    Binding, ConfigurationChoiceReport, Constraint, LayerPlan, LayerQuality, LayerStatus,
    ObjectiveReport, OptimiseError, Plan, PlannedPoint, RzLaw, SolverReport, Transition,
};

use std::f64::consts::{PI, TAU};
use std::time::Instant;

use rayon::prelude::*;

use crate::math::UnitVector3;
use crate::path::Path;
use crate::robot::cell::{Cell, CellPoint};
use crate::robot::ik::{unwrap_near, Configuration};
use crate::robot::model::Joints;
use crate::robot::trajectory::{joint_trajectory, PathPointInput, ViolationKind};
use crate::toolaxis::LocalFrame;

use parameterisation::{cylindrical_angles, turns_about_z, Basis};
use problem::{Evaluation, LayerProblem, PointFailure, ARCMATE_SIGMA_DEG};

/// The points of one layer, as the cells see them (part frame).
#[derive(Debug, Clone, PartialEq)]
pub struct LayerPoints {
    /// Layer index (reported back).
    pub layer: usize,
    /// The points in deposition order.
    pub points: Vec<CellPoint>,
}

/// Layers of `path` with the tool axes and build directions of `frames`
/// (from [`toolaxis::local_frames`](crate::toolaxis::local_frames)).
pub fn layer_points(path: &Path, frames: &[Vec<LocalFrame>]) -> Vec<LayerPoints> {
    path.layers
        .iter()
        .zip(frames)
        .enumerate()
        .map(|(i, (layer, fr))| LayerPoints {
            layer: i,
            points: layer
                .points
                .iter()
                .zip(fr)
                .map(|(p, f)| CellPoint {
                    position_mm: p.position,
                    tool_axis: UnitVector3::new_normalize(f.tool),
                    build_direction: Some(UnitVector3::new_normalize(f.build)),
                })
                .collect(),
        })
        .collect()
}

/// The input of [`joint_trajectory`] and of the program stage: every point
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
                .map(move |(m, (cp, pp))| path_point(lp.layer, m, cp, pp.r_z))
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
    }
}

/// Optimises `R_Z` layer by layer [SPEC §7].
///
/// # Errors
/// Bad input only: [`OptimiseError::InvalidOption`], [`OptimiseError::Cell`],
/// [`OptimiseError::TooFewPoints`], [`OptimiseError::BadPoint`]. Layers that
/// cannot be built are reported in the plan ([`LayerStatus`]).
pub fn optimise(
    cell: &Cell,
    layers: &[LayerPoints],
    opts: &OptimiseOptions,
) -> Result<Plan, OptimiseError> {
    validate_input(cell, layers, opts)?;
    let t0 = Instant::now();
    let plans: Vec<LayerPlan> = if opts.parallel {
        layers
            .par_iter()
            .map(|l| optimise_layer(cell, l, opts, None).0)
            .collect()
    } else {
        layers
            .iter()
            .map(|l| optimise_layer(cell, l, opts, None).0)
            .collect()
    };
    let transitions = transitions(cell, &plans);
    Ok(Plan {
        layers: plans,
        transitions,
        time_s: t0.elapsed().as_secs_f64(),
    })
}

/// Optimises a spiral path (one continuous layer, `per_turn` points a turn,
/// as [`Path::spiral`](crate::path::Path) gives it) turn by turn [SPEC §7]:
/// the arc never stops, so every turn continues the one before — same IK
/// branch, its first point's joints unwrapped from the previous turn's last
/// joints, and `R_Z` held at the previous turn's last value on that joint
/// point (the polynomial of [`Basis::anchored_polynomial`]: `R_Z` continuous,
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
/// As [`optimise`]; [`OptimiseError::InvalidOption`] when `per_turn < 2`.
pub fn optimise_spiral(
    cell: &Cell,
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
        let turn = LayerPoints {
            layer: k,
            points: spiral.points[from..b].to_vec(),
        };
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

fn validate_input(
    cell: &Cell,
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
        }
    }
    Ok(())
}

/// Where a spiral turn starts: the previous turn's last point.
#[derive(Debug, Clone, Copy)]
struct Anchor {
    r_z: f64,
    joints: Joints,
    configuration: Configuration,
    /// The previous turn's dexterity floor at its last point.
    floor: f64,
}

fn transitions(cell: &Cell, plans: &[LayerPlan]) -> Vec<Transition> {
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

/// Smallest distance to a stop over the limited joints (rad) and its joint (1-based).
fn limit_distance(robot: &crate::robot::RobotModel, q: &Joints) -> (f64, usize) {
    let mut best = (f64::INFINITY, 0);
    for (j, l) in robot.limits.iter().enumerate() {
        if l.is_unlimited() {
            continue;
        }
        let d = (q[j] - l.lower_rad).min(l.upper_rad - q[j]);
        if d < best.0 {
            best = (d, j + 1);
        }
    }
    best
}

/// A seed: `R_Z` at every point and the polynomial degree that holds it.
#[derive(Debug, Clone)]
struct Seed {
    r: Vec<f64>,
    degree: usize,
    violation: f64,
    estimate: f64,
    centring: f64,
}

struct LayerSetup<'a> {
    cell: &'a Cell,
    opts: &'a OptimiseOptions,
    points: &'a [CellPoint],
    dt: Vec<f64>,
    theta: Vec<f64>,
    turning: bool,
    cylindrical: bool,
    anchor: Option<Anchor>,
}

impl<'a> LayerSetup<'a> {
    fn problem(&self, cfg: Configuration, psi: Vec<f64>) -> LayerProblem<'a> {
        let robot = self.cell.robot();
        let margin = self.opts.joint_limit_margin_rad;
        let gamma = std::array::from_fn(|j| {
            let l = &robot.limits[j];
            if l.is_unlimited() {
                0.0
            } else {
                1.0 / l.range_rad()
            }
        });
        let sigma_rad = robot
            .encoder_sigma_rad
            .unwrap_or(ARCMATE_SIGMA_DEG.map(f64::to_radians));
        LayerProblem {
            cell: self.cell,
            configuration: cfg,
            points: self.points,
            dt: self.dt.clone(),
            psi,
            gamma,
            lower: std::array::from_fn(|j| robot.limits[j].lower_rad + margin),
            upper: std::array::from_fn(|j| robot.limits[j].upper_rad - margin),
            wrist_margin: self.opts.trajectory.wrist_singularity_margin_rad,
            hose: match self.cell {
                Cell::TorchCarried(c) => Some(c.max_hose_torsion_rad),
                Cell::PartCarried(_) => None,
            },
            max_speed: robot.max_speed_rad_s,
            centring: self.opts.centring_weight / self.points.len() as f64,
            objective: self.opts.objective,
            // I in micrometres·1e3 (thesis §4.2.2 scales sigma by 1e6 too)
            sigma: sigma_rad.map(|s| s * 1e6),
            dex_scale: self.opts.trajectory.dexterity_length_scale_mm,
            start_near: self.anchor.map(|a| a.joints),
        }
    }

    /// The seed families on a layer.
    fn seed_laws(&self) -> Vec<(Vec<f64>, usize)> {
        let p = self.points.len();
        if let Some(a) = self.anchor {
            // continue the previous turn: R_Z held, then constant or `− theta`
            let mut out = vec![(vec![a.r_z; p], 1)];
            if self.turning {
                let r = self
                    .theta
                    .iter()
                    .map(|t| a.r_z - (t - self.theta[0]))
                    .collect();
                out.push((r, 1));
            }
            return out;
        }
        let n = self.opts.seeds;
        let mut out = Vec::new();
        for i in 0..n {
            let c = -PI + TAU * i as f64 / n as f64;
            out.push((vec![c; p], 0));
            if self.turning {
                let r = self.theta.iter().map(|t| c - (t - self.theta[0])).collect();
                out.push((r, 1));
            }
        }
        out
    }

    /// Scores every seed in each branch of `cfgs` on the sample points; per
    /// branch, its best seed. The cell poses of a seed's sample points do not
    /// depend on the branch: they are computed once and every branch's IK is
    /// solved from them ([`RobotModel::inverse_all`](crate::robot::RobotModel::inverse_all)).
    fn best_seeds(&self, cfgs: &[Configuration]) -> Vec<Seed> {
        let p = self.points.len();
        let ns = self.opts.seed_points.min(p);
        let idx: Vec<usize> = (0..ns)
            .map(|i| ((i as f64) * (p - 1) as f64 / (ns - 1).max(1) as f64).round() as usize)
            .collect();
        let prob = self.problem(cfgs[0], vec![0.0; p]);
        let robot = self.cell.robot();
        let mut best: Vec<Option<Seed>> = vec![None; cfgs.len()];
        for (r, degree) in self.seed_laws() {
            // per branch: (violation, displacement estimate, centring, previous joints)
            let mut acc: Vec<(f64, f64, f64, Option<Joints>)> =
                vec![(0.0, 0.0, 0.0, prob.start_near); cfgs.len()];
            let mut q8 = 0.0;
            for &m in &idx {
                let pose = match self.cell.pose(&self.points[m], r[m], q8) {
                    Ok(pose) => pose,
                    Err(_) => {
                        for a in &mut acc {
                            a.0 = f64::INFINITY;
                        }
                        break;
                    }
                };
                let all = robot.inverse_all(&pose.base_from_flange);
                let mut any = false;
                for (a, cfg) in acc.iter_mut().zip(cfgs) {
                    if a.0 == f64::INFINITY {
                        continue;
                    }
                    let q = match &all[cfg.index()] {
                        Ok(q) => match a.3 {
                            Some(n) => std::array::from_fn(|j| unwrap_near(q[j], n[j])),
                            None => *q,
                        },
                        Err(_) => {
                            a.0 = f64::INFINITY;
                            continue;
                        }
                    };
                    any = true;
                    let (viol, est, cen, prev) = a;
                    for j in 0..6 {
                        let (lo, hi) = if j == 4 {
                            prob.j5_bounds(q[4])
                        } else {
                            (prob.lower[j], prob.upper[j])
                        };
                        *viol = viol.max(q[j] - hi).max(lo - q[j]);
                        if prob.gamma[j] > 0.0 {
                            let l = &robot.limits[j];
                            *cen += ((q[j] - l.mid_rad()) / l.range_rad()).powi(2);
                            if let Some(qq) = prev {
                                *est += prob.gamma[j] * (q[j] - qq[j]).powi(2);
                            }
                        }
                    }
                    if let Some(h) = prob.hose {
                        *viol = viol.max((q[3] + q[5]).abs() - h);
                    }
                    *prev = Some(q);
                }
                if !any {
                    break;
                }
                if let Some(qp) = pose.positioner {
                    q8 = qp[1];
                }
            }
            for (b, (viol, est, cen, _)) in best.iter_mut().zip(acc) {
                let cen = cen / ns as f64;
                // displacement between samples ≈ (ns−1)/(p−1) of the full sum
                let est = est * (ns - 1) as f64 / (p - 1) as f64;
                let seed = Seed {
                    r: r.clone(),
                    degree,
                    violation: viol.max(0.0),
                    estimate: est + self.opts.centring_weight * cen,
                    centring: cen,
                };
                // the first of equal seeds wins (a stable sort's order)
                let better = b.as_ref().is_none_or(|s| {
                    seed.violation
                        .total_cmp(&s.violation)
                        .then(seed.estimate.total_cmp(&s.estimate))
                        .is_lt()
                });
                if better {
                    *b = Some(seed);
                }
            }
        }
        best.into_iter()
            .map(|b| b.expect("at least one seed law"))
            .collect()
    }

    /// Dexterity floor per point from the unoptimised path (`R_Z = 0`).
    fn floors(&self, cfg: Configuration) -> Vec<f64> {
        let p = self.points.len();
        match self.opts.dexterity_floor {
            options::DexterityFloor::Off => vec![0.0; p],
            options::DexterityFloor::Absolute { dexterity } => vec![dexterity; p],
            options::DexterityFloor::FractionOfUnoptimised { fraction } => {
                let prob = self.problem(cfg, vec![0.0; p]);
                let robot = self.cell.robot();
                let mut q8 = 0.0;
                let mut warm = crate::robot::indices::SvdWarmStart::default();
                let d: Vec<f64> = (0..p)
                    .map(|m| match prob.joints_at(m, 0.0, None, q8) {
                        Ok((q, pose)) => {
                            if let Some(qp) = pose.positioner {
                                q8 = qp[1];
                            }
                            crate::robot::indices::dexterity_warm(
                                &robot.jacobian(&q),
                                prob.dex_scale,
                                &mut warm,
                            )
                        }
                        Err(_) => f64::NAN,
                    })
                    .collect();
                let fallback = d
                    .iter()
                    .copied()
                    .filter(|x| x.is_finite())
                    .fold(f64::INFINITY, f64::min);
                let fallback = if fallback.is_finite() { fallback } else { 0.0 };
                // one floor per layer: the mean over the layer (see the
                // option's doc for why not the thesis's per-point value)
                let mean = d
                    .iter()
                    .map(|x| if x.is_finite() { *x } else { fallback })
                    .sum::<f64>()
                    / p as f64;
                vec![fraction * mean; p]
            }
        }
    }
}

/// What one branch gave.
struct BranchOutcome {
    cfg: Configuration,
    eval: Result<Evaluation, PointFailure>,
    law: RzLaw,
    violation: f64,
    converged: bool,
    iterations: usize,
    qp_solves: usize,
    qp_failures: usize,
    problem_psi: Vec<f64>,
}

/// One layer (or spiral turn, `anchor` given); also returns the dexterity
/// floor at its last point (the next spiral turn starts from it).
fn optimise_layer(
    cell: &Cell,
    lp: &LayerPoints,
    opts: &OptimiseOptions,
    anchor: Option<Anchor>,
) -> (LayerPlan, f64) {
    let t0 = Instant::now();
    let points = &lp.points;
    let p = points.len();
    let mut dt = vec![0.0; p];
    for m in 1..p {
        dt[m] = (points[m].position_mm - points[m - 1].position_mm).norm() / opts.travel_speed_mm_s;
    }
    let theta = cylindrical_angles(&points.iter().map(|c| c.position_mm).collect::<Vec<_>>());
    let turning = turns_about_z(&theta);
    let cylindrical = match opts.parameterisation {
        Parameterisation::Polynomial { abscissa, .. } => match abscissa {
            Abscissa::PointIndex => false,
            Abscissa::CylindricalAngle => true,
            Abscissa::Auto => turning,
        },
        _ => false,
    };
    let setup = LayerSetup {
        cell,
        opts,
        points,
        dt,
        theta,
        turning,
        cylindrical,
        anchor,
    };

    // 1. branches
    let fixed = matches!(opts.parameterisation, Parameterisation::Fixed { .. });
    let candidates: Vec<Configuration> = if let Some(a) = anchor {
        vec![a.configuration]
    } else if fixed || opts.configuration == ConfigurationChoice::Cell {
        vec![cell.configuration()]
    } else {
        Configuration::ALL.to_vec()
    };
    let mut ranked: Vec<(Configuration, Seed)> = candidates
        .iter()
        .copied()
        .zip(setup.best_seeds(&candidates))
        .collect();
    let own = cell.configuration();
    ranked.sort_by(|a, b| {
        let key = |x: &(Configuration, Seed)| {
            let bonus = if x.0 == own { 1.0 / 1.5 } else { 1.0 };
            (x.1.violation, x.1.centring * bonus)
        };
        let (va, ca) = key(a);
        let (vb, cb) = key(b);
        va.total_cmp(&vb).then(ca.total_cmp(&cb))
    });
    let ranking: Vec<(Configuration, f64, f64)> = ranked
        .iter()
        .map(|(c, s)| {
            (
                *c,
                s.violation,
                if s.violation.is_finite() {
                    s.centring
                } else {
                    f64::INFINITY
                },
            )
        })
        .collect();

    // 2. optimise the best branch, then the next ones while infeasible
    let mut outcomes: Vec<BranchOutcome> = Vec::new();
    for (cfg, seed) in &ranked {
        if !seed.violation.is_finite() && !outcomes.is_empty() {
            break;
        }
        let out = optimise_branch(&setup, *cfg, seed);
        let done = out.eval.is_ok() && out.violation <= 0.0;
        outcomes.push(out);
        if done || fixed {
            break;
        }
    }
    let branches_tried = outcomes.len();
    let (iterations, qp_solves, qp_failures) = outcomes.iter().fold((0, 0, 0), |a, o| {
        (a.0 + o.iterations, a.1 + o.qp_solves, a.2 + o.qp_failures)
    });
    // keep the first feasible, else the least violating with a solution
    let pick = outcomes
        .iter()
        .position(|o| o.eval.is_ok() && o.violation <= 0.0)
        .or_else(|| {
            outcomes
                .iter()
                .enumerate()
                .filter(|(_, o)| o.eval.is_ok())
                .min_by(|a, b| a.1.violation.total_cmp(&b.1.violation))
                .map(|(i, _)| i)
        })
        .unwrap_or(0);
    let out = outcomes.swap_remove(pick);
    let chosen = out.cfg;
    let reason = match anchor {
        Some(_) => format!("{chosen}: the previous spiral turn's branch (the arc does not stop)"),
        None => choice_reason(&ranking, chosen, own, branches_tried, fixed, opts),
    };
    let configuration = ConfigurationChoiceReport {
        chosen,
        ranking,
        reason,
    };
    let solver = |time_s| SolverReport {
        iterations,
        qp_solves,
        qp_failures,
        branches_tried,
        time_s,
    };
    let end_floor = out.problem_psi.last().copied().unwrap_or(0.0);
    let eval = match out.eval {
        Ok(e) => e,
        Err(f) => {
            let plan = LayerPlan {
                layer: lp.layer,
                status: LayerStatus::NoSolution {
                    point: f.point,
                    error: f.error,
                },
                configuration,
                law: out.law,
                points: Vec::new(),
                objective: ObjectiveReport::default(),
                quality: LayerQuality::default(),
                solver: solver(t0.elapsed().as_secs_f64()),
                violations: Vec::new(),
            };
            return (plan, end_floor);
        }
    };
    let problem = setup.problem(chosen, out.problem_psi);
    let plan = finish(
        &setup,
        lp.layer,
        &problem,
        eval,
        out.law,
        out.converged,
        out.iterations,
        fixed,
        configuration,
        solver,
        t0,
    );
    (plan, end_floor)
}

fn choice_reason(
    ranking: &[(Configuration, f64, f64)],
    chosen: Configuration,
    own: Configuration,
    tried: usize,
    fixed: bool,
    opts: &OptimiseOptions,
) -> String {
    if fixed {
        return format!("R_Z fixed (no optimisation): the cell's branch {own}");
    }
    if opts.configuration == ConfigurationChoice::Cell {
        return format!("the cell's branch {own}, as asked");
    }
    let r = ranking.iter().find(|r| r.0 == chosen);
    let mut s = match r {
        Some((_, v, c)) if *v <= 0.0 => format!(
            "{chosen}: a seed keeps every joint inside its travel and it is the most centred \
             of those (mean Σ((q − mid)/range)² = {c:.4})"
        ),
        Some((_, v, _)) if v.is_finite() => format!(
            "{chosen}: no branch has a feasible seed; this one violates least ({:.3}°)",
            v.to_degrees()
        ),
        _ => format!("{chosen}"),
    };
    if chosen == own {
        s.push_str("; it is the cell's branch");
    } else if let Some((_, v, c)) = ranking.iter().find(|r| r.0 == own) {
        if v.is_finite() {
            s.push_str(&format!(
                "; the cell's branch {own} scores violation {:.3}°, centring {c:.4}",
                v.to_degrees()
            ));
        } else {
            s.push_str(&format!("; the cell's branch {own} has no solution here"));
        }
    }
    if tried > 1 {
        s.push_str(&format!(
            "; {tried} branches optimised (the better-ranked ones ended infeasible)"
        ));
    }
    s
}

fn optimise_branch(setup: &LayerSetup, cfg: Configuration, seed: &Seed) -> BranchOutcome {
    let opts = setup.opts;
    let p = setup.points.len();
    let mut psi = setup.floors(cfg);
    if let Some(a) = setup.anchor {
        // A continuous floor along the spiral: from the previous turn's at
        // the shared point to this turn's own at its last point. A step at
        // the junction would leave the shared point, held where the
        // previous turn put it (on its floor, when that was active), below
        // the new floor, and the turn would have to bend R_Z steeply away
        // from it.
        let n = (p - 1).max(1) as f64;
        for (m, x) in psi.iter_mut().enumerate() {
            *x = a.floor + (*x - a.floor) * m as f64 / n;
        }
    }
    if setup.anchor.is_some() {
        // the shared point of a spiral turn was checked against the
        // previous turn's floor, and cannot move
        psi[0] = 0.0;
    }
    let problem = setup.problem(cfg, psi.clone());
    let mut outcome = BranchOutcome {
        cfg,
        eval: Err(PointFailure {
            point: 0,
            error: crate::robot::RobotError::NonFinite { what: "not solved" },
        }),
        law: RzLaw::PointByPoint,
        violation: f64::INFINITY,
        converged: true,
        iterations: 0,
        qp_solves: 0,
        qp_failures: 0,
        problem_psi: psi,
    };
    match opts.parameterisation {
        Parameterisation::Fixed { r_z_rad } => {
            outcome.law = RzLaw::Fixed(r_z_rad);
            outcome.eval = problem.evaluate(&vec![r_z_rad; p]);
        }
        Parameterisation::PointByPoint => {
            outcome.law = RzLaw::PointByPoint;
            outcome.eval = point_by_point(&problem, seed.r[0], setup.anchor.map(|a| a.r_z));
        }
        Parameterisation::SmoothingSpline { smoothness } => {
            outcome.law = RzLaw::SmoothingSpline;
            let basis = Basis::PerPoint { points: p };
            let scale = scale_of(&problem, &seed.r, smoothness);
            match sqp::solve(
                &problem,
                &basis,
                seed.r.clone(),
                None,
                smoothness,
                scale,
                &opts.sqp,
            ) {
                Ok(res) => {
                    outcome.iterations = res.iterations;
                    outcome.qp_solves = res.qp_solves;
                    outcome.qp_failures = res.qp_failures;
                    outcome.converged = res.converged;
                    outcome.eval = Ok(res.eval);
                }
                Err(f) => outcome.eval = Err(f),
            }
        }
        Parameterisation::Polynomial {
            max_degree,
            stop_relative_gain,
            ..
        } => {
            let x: Vec<f64> = if setup.cylindrical {
                setup.theta.clone()
            } else {
                (0..p).map(|m| m as f64).collect()
            };
            let (start, mut basis) = match setup.anchor {
                // continuity: R_Z held on the shared point, degree ≥ 1
                Some(a) => {
                    let d = seed.degree.min(max_degree).max(1);
                    (d, Basis::anchored_polynomial(&x, d, a.r_z))
                }
                None => {
                    let d = seed.degree.min(max_degree);
                    (d, Basis::polynomial(&x, d + 1))
                }
            };
            let mut c = basis.fit(&seed.r);
            let e0 = problem.evaluate(&basis.eval(&c)).ok();
            let scale = match &e0 {
                Some(e) => problem.objective(e, 0.0).max(1e-6),
                None => 1.0,
            };
            let mut history = Vec::new();
            let mut best: Option<(usize, Vec<f64>, Basis, sqp::SqpResult)> = None;
            let mut at_c: Option<Evaluation> = e0;
            for degree in start..=max_degree.max(start) {
                match sqp::solve(
                    &problem,
                    &basis,
                    c.clone(),
                    at_c.take(),
                    0.0,
                    scale,
                    &opts.sqp,
                ) {
                    Ok(res) => {
                        at_c = Some(res.eval.clone());
                        outcome.iterations += res.iterations;
                        outcome.qp_solves += res.qp_solves;
                        outcome.qp_failures += res.qp_failures;
                        history.push((degree, res.objective));
                        c = res.c.clone();
                        let improved = match &best {
                            None => true,
                            Some((_, _, _, b)) => {
                                res.violation < b.violation
                                    || (res.violation <= b.violation && res.objective < b.objective)
                            }
                        };
                        let gain = match &best {
                            Some((_, _, _, b)) if b.violation <= 0.0 && res.violation <= 0.0 => {
                                (b.objective - res.objective) / b.objective.abs().max(1e-300)
                            }
                            _ => f64::INFINITY,
                        };
                        if improved {
                            best = Some((degree, c.clone(), basis.clone(), res));
                        }
                        if gain < stop_relative_gain {
                            break;
                        }
                    }
                    Err(f) => {
                        if best.is_none() {
                            outcome.eval = Err(f);
                            return outcome;
                        }
                        break;
                    }
                }
                match basis.raised() {
                    Some(b) => {
                        // The Gauss–Newton model at this optimum bounds what
                        // the next degree can gain while no constraint is in
                        // reach of its step: far below the stop criterion,
                        // solving it is not worth its evaluations.
                        if let (Some(e), Some((_, _, _, bst))) = (&at_c, &best) {
                            if bst.violation <= 0.0
                                && skip_raise(&problem, e, &b, stop_relative_gain * bst.objective)
                            {
                                break;
                            }
                        }
                        basis = b;
                        c.push(0.0);
                    }
                    None => break,
                }
            }
            if let Some((degree, c, basis, res)) = best {
                outcome.converged = res.converged;
                outcome.law = RzLaw::Polynomial {
                    degree,
                    cylindrical: setup.cylindrical,
                    coefficients_deg: basis
                        .thesis_coefficients_deg(&c, !setup.cylindrical)
                        .unwrap_or_default(),
                    objective_per_degree: history,
                };
                outcome.eval = Ok(res.eval);
            }
        }
    }
    if let Ok(e) = &outcome.eval {
        outcome.violation = problem.max_violation_of_bounds(e);
    }
    outcome
}

/// Fraction of the stop criterion (relative gain) below which the
/// Gauss–Newton model's gain from one more degree skips that degree.
const RAISE_MODEL_FRACTION: f64 = 1e-2;

/// `true` when raising to `raised` cannot pay: at the current optimum `e`
/// the unconstrained Gauss–Newton model of the raised problem predicts a
/// decrease below `RAISE_MODEL_FRACTION × threshold` (objective units), and
/// no constraint is within reach of that model step (with one, the model
/// would not bound the gain).
fn skip_raise(problem: &LayerProblem, e: &Evaluation, raised: &Basis, threshold: f64) -> bool {
    let Some((gain, step)) = sqp::predicted_gain(problem, e, 0.0, raised) else {
        return false;
    };
    gain < RAISE_MODEL_FRACTION * threshold
        && problem
            .constraint_rows(e, raised, step.max(1e-6))
            .is_empty()
}

/// Objective scale of a layer: its value at the seed (bounded below).
fn scale_of(problem: &LayerProblem, r: &[f64], smoothness: f64) -> f64 {
    match problem.evaluate(r) {
        Ok(e) => problem.objective(&e, smoothness).max(1e-6),
        Err(_) => 1.0,
    }
}

/// Point by point: every constraint is penalised from `PBP_MARGIN` inside
/// its bound (rad, rad per step, or relative for the dexterity), so that the
/// 1-D search's tolerance (1e-7 rad) cannot leave a point a hair outside.
const PBP_MARGIN: f64 = 1e-6;

/// The thesis's point-by-point baseline [§4.1.4]: point 0 minimises the
/// centring term, each next point the weighted displacement from the
/// previous point, each under that point's constraints (penalised), by a
/// local 1-D search started from the previous point's `R_Z`.
fn point_by_point(
    problem: &LayerProblem,
    r0: f64,
    held: Option<f64>,
) -> Result<Evaluation, PointFailure> {
    let p = problem.points.len();
    let robot = problem.cell.robot();
    let rho = 1e3;
    let mut r = vec![0.0; p];
    let mut prev: Option<Joints> = problem.start_near;
    let mut q8 = 0.0;
    for m in 0..p {
        let f = |x: f64| -> f64 {
            let Ok((q, _)) = problem.joints_at(m, x, prev.as_ref(), q8) else {
                return f64::INFINITY;
            };
            let mut obj = 0.0;
            let mut viol: f64 = 0.0;
            for j in 0..6 {
                let (lo, hi) = if j == 4 && q[4] >= 0.0 {
                    (problem.lower[4].max(problem.wrist_margin), problem.upper[4])
                } else if j == 4 {
                    (
                        problem.lower[4],
                        problem.upper[4].min(-problem.wrist_margin),
                    )
                } else {
                    (problem.lower[j], problem.upper[j])
                };
                viol = viol.max(q[j] - hi + PBP_MARGIN).max(lo - q[j] + PBP_MARGIN);
                match prev {
                    Some(qp) => {
                        obj += problem.gamma[j] * (q[j] - qp[j]).powi(2);
                        if problem.dt[m] > 0.0 {
                            viol = viol.max(
                                (q[j] - qp[j]).abs() - problem.max_speed[j] * problem.dt[m]
                                    + PBP_MARGIN,
                            );
                        }
                    }
                    None if problem.gamma[j] > 0.0 => {
                        let l = &robot.limits[j];
                        obj += ((q[j] - l.mid_rad()) / l.range_rad()).powi(2);
                    }
                    None => {}
                }
            }
            if let Some(h) = problem.hose {
                viol = viol.max((q[3] + q[5]).abs() - h + PBP_MARGIN);
            }
            if problem.psi[m] > 0.0 {
                let d = crate::robot::indices::dexterity(&robot.jacobian(&q), problem.dex_scale);
                viol = viol.max((problem.psi[m] - d) / problem.psi[m] + PBP_MARGIN);
            }
            obj + rho * viol
        };
        let start = match m {
            0 => r0,
            1 => r[0],
            _ => 2.0 * r[m - 1] - r[m - 2],
        };
        let x = match held {
            Some(h) if m == 0 => h,
            _ => minimise_1d(&f, start, 0.02, 1e-7),
        };
        r[m] = x;
        let (q, pose) = problem
            .joints_at(m, x, prev.as_ref(), q8)
            .map_err(|error| PointFailure { point: m, error })?;
        if let Some(qp) = pose.positioner {
            q8 = qp[1];
        }
        prev = Some(q);
    }
    problem.evaluate(&r)
}

/// Local 1-D minimisation: downhill bracketing from `x0` with step `h`
/// (doubling), then golden-section search to `tol`.
fn minimise_1d(f: &dyn Fn(f64) -> f64, x0: f64, h: f64, tol: f64) -> f64 {
    let f0 = f(x0);
    let (fp, fm) = (f(x0 + h), f(x0 - h));
    if !(fp < f0) && !(fm < f0) {
        return golden(f, x0 - h, x0 + h, tol);
    }
    let dir = if fp < fm { 1.0 } else { -1.0 };
    let (mut a, mut b, mut fb) = (x0, x0 + dir * h, fp.min(fm));
    let mut step = h;
    for _ in 0..40 {
        step *= 2.0;
        let c = b + dir * step;
        let fc = f(c);
        if !(fc < fb) {
            return golden(f, a.min(c), a.max(c), tol);
        }
        a = b;
        b = c;
        fb = fc;
        if (b - x0).abs() > PI {
            break;
        }
    }
    b
}

fn golden(f: &dyn Fn(f64) -> f64, mut a: f64, mut b: f64, tol: f64) -> f64 {
    let g = 0.5 * (5f64.sqrt() - 1.0);
    let mut c = b - g * (b - a);
    let mut d = a + g * (b - a);
    let (mut fc, mut fd) = (f(c), f(d));
    while (b - a).abs() > tol {
        if fc < fd {
            b = d;
            d = c;
            fd = fc;
            c = b - g * (b - a);
            fc = f(c);
        } else {
            a = c;
            c = d;
            fc = fd;
            d = a + g * (b - a);
            fd = f(d);
        }
    }
    0.5 * (a + b)
}

#[allow(clippy::too_many_arguments)]
fn finish(
    setup: &LayerSetup,
    layer: usize,
    problem: &LayerProblem,
    e: Evaluation,
    law: RzLaw,
    converged: bool,
    iterations: usize,
    fixed: bool,
    configuration: ConfigurationChoiceReport,
    solver: impl Fn(f64) -> SolverReport,
    t0: Instant,
) -> LayerPlan {
    let opts = setup.opts;
    let robot = setup.cell.robot();
    let p = e.q.len();
    let mut e = e;
    // the trajectory stage's own check, in the chosen branch
    let mut cell = setup.cell.clone();
    match &mut cell {
        Cell::PartCarried(c) => c.configuration = configuration.chosen,
        Cell::TorchCarried(c) => c.configuration = configuration.chosen,
    }
    let inputs: Vec<PathPointInput> = setup
        .points
        .iter()
        .enumerate()
        .map(|(m, cp)| path_point(layer, m, cp, e.r[m]))
        .collect();
    let mut topts = opts.trajectory;
    topts.with_derivatives = false;
    let violations = match joint_trajectory(&cell, &inputs, opts.travel_speed_mm_s, &topts) {
        Ok(t) => {
            // its dexterity is the exact value the plan reports, wherever
            // it solved the same joints (it does everywhere: same IK, same
            // unwrapping); the SVD is not repeated there
            for (m, jp) in t.points.iter().enumerate().take(p) {
                if !e.dex_exact[m] && jp.joints == Some(e.q[m]) {
                    e.dex[m] = jp.dexterity;
                    e.dex_exact[m] = true;
                }
            }
            t.report.violations
        }
        Err(_) => Vec::new(),
    };
    problem.exact_dexterity(&mut e);
    let binding = problem.binding(&e, 1e-9).or_else(|| {
        violations.first().map(|v| {
            // the amount in the units of `Binding::violation`: rad past a
            // bound, rad over one step for a speed, relative for dexterity
            let (constraint, violation) = match v.kind {
                ViolationKind::JointLimit {
                    joint,
                    value_rad,
                    lower_rad,
                    upper_rad,
                } => (
                    Constraint::JointLimit { joint },
                    (lower_rad - value_rad).max(value_rad - upper_rad),
                ),
                ViolationKind::JointSpeed {
                    joint,
                    speed_rad_s,
                    max_rad_s,
                } => {
                    let step_mm = v.point.checked_sub(1).map_or(0.0, |k| {
                        (inputs[v.point].position_mm - inputs[k].position_mm).norm()
                    });
                    (
                        Constraint::JointSpeed { joint },
                        (speed_rad_s - max_rad_s) * step_mm / opts.travel_speed_mm_s,
                    )
                }
                ViolationKind::HoseTorsion {
                    torsion_rad,
                    max_rad,
                } => (Constraint::HoseTorsion, torsion_rad - max_rad),
                _ => (Constraint::Dexterity, 0.0),
            };
            Binding {
                point: v.point,
                constraint,
                violation,
            }
        })
    });
    let status = match binding {
        Some(b) if fixed => LayerStatus::FixedViolates { binding: b },
        Some(b) => LayerStatus::Infeasible { binding: b },
        None if converged => LayerStatus::Optimal,
        None => LayerStatus::NotConverged { iterations },
    };
    // objective figures
    let mut unc_sum = 0.0;
    for q in &e.q {
        let i = crate::robot::indices::positioning_uncertainty(
            &robot.jacobian(q),
            &robot
                .encoder_sigma_rad
                .unwrap_or(ARCMATE_SIGMA_DEG.map(f64::to_radians)),
            crate::robot::indices::UncertaintyFormula::RootTrace,
        );
        unc_sum += i * i;
    }
    let mut centring = 0.0;
    for q in &e.q {
        for (j, qj) in q.iter().enumerate() {
            if problem.gamma[j] > 0.0 {
                let l = &robot.limits[j];
                centring += ((qj - l.mid_rad()) / l.range_rad()).powi(2);
            }
        }
    }
    let objective = ObjectiveReport {
        joint_displacement: problem.displacement(&e),
        uncertainty_sum_sq_mm2: unc_sum,
        mean_uncertainty_mm: (unc_sum / p as f64).sqrt(),
        centring: centring / p as f64,
    };
    let quality = quality(problem, &e);
    let points = (0..p)
        .map(|m| PlannedPoint {
            r_z: e.r[m],
            joints: Some(e.q[m]),
            positioner: e.positioner[m],
            dexterity: e.dex[m],
        })
        .collect();
    LayerPlan {
        layer,
        status,
        configuration,
        law,
        points,
        objective,
        quality,
        solver: solver(t0.elapsed().as_secs_f64()),
        violations,
    }
}

/// Quality figures of a layer at the travel speed.
#[allow(clippy::needless_range_loop)]
fn quality(problem: &LayerProblem, e: &Evaluation) -> LayerQuality {
    let p = e.q.len();
    let robot = problem.cell.robot();
    let mut out = LayerQuality {
        min_dexterity: e.dex.iter().copied().fold(f64::INFINITY, f64::min),
        min_limit_distance_rad: f64::INFINITY,
        ..Default::default()
    };
    let mut speed_prev: Option<(Joints, f64)> = None;
    let mut last_dir = [0i8; 6];
    for m in 0..p {
        let q = &e.q[m];
        let (d, j) = limit_distance(robot, q);
        if d < out.min_limit_distance_rad {
            out.min_limit_distance_rad = d;
            out.min_limit_distance_joint = j;
        }
        out.max_hose_torsion_rad = out.max_hose_torsion_rad.max((q[3] + q[5]).abs());
        if m == 0 || problem.dt[m] <= 0.0 {
            continue;
        }
        let dt = problem.dt[m];
        let v: Joints = std::array::from_fn(|j| (q[j] - e.q[m - 1][j]) / dt);
        for j in 0..6 {
            let dq = q[j] - e.q[m - 1][j];
            out.joint_travel_rad[j] += dq.abs();
            out.peak_speed_rad_s[j] = out.peak_speed_rad_s[j].max(v[j].abs());
            if dq.abs() > 1e-7 {
                let dir = if dq > 0.0 { 1 } else { -1 };
                if last_dir[j] != 0 && dir != last_dir[j] {
                    out.direction_reversals[j] += 1;
                }
                last_dir[j] = dir;
            }
        }
        if let Some((vp, dtp)) = speed_prev {
            let h = 0.5 * (dt + dtp);
            for j in 0..6 {
                let a = (v[j] - vp[j]) / h;
                out.peak_acceleration_rad_s2[j] = out.peak_acceleration_rad_s2[j].max(a.abs());
                if j < 5 {
                    out.summed_acceleration_rad_s += a.abs() * h;
                }
            }
        }
        speed_prev = Some((v, dt));
    }
    out
}
