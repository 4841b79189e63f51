//! A layer's plan from its solution: the trajectory stage's re-check in
//! the chosen branch, the status naming the binding constraint, the
//! objective figures and the trajectory quality at the travel speed.

use std::time::Instant;

use super::problem::{encoder_sigma_rad, Evaluation, LayerProblem};
use super::setup::LayerSetup;
use super::{
    path_point, BindingConstraint, ConfigurationChoiceReport, Constraint, LayerPlan, LayerQuality,
    LayerStatus, ObjectiveReport, PlannedPoint, SolvedRzLaw, SolverReport,
};
use crate::robot::cell::CellLayout;
use crate::robot::model::Joints;
use crate::robot::trajectory::{joint_trajectory, PathPointInput, SolvedBead, ViolationKind};

/// A constraint violated by more than this (its own units, as
/// [`LayerProblem::binding`] takes them) is reported as binding.
const BINDING_VIOLATION: f64 = 1e-9;
/// A joint step (rad) smaller than this has no direction: it neither starts
/// nor ends a reversal in the counts.
const REVERSAL_MIN_STEP_RAD: f64 = 1e-7;

/// Smallest distance to a stop over the limited joints (rad) and its joint (1-based).
pub(super) fn limit_distance(robot: &crate::robot::RobotModel, q: &Joints) -> (f64, usize) {
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

#[allow(clippy::too_many_arguments)]
pub(super) fn finish(
    setup: &LayerSetup,
    layer: usize,
    problem: &LayerProblem,
    e: Evaluation,
    law: SolvedRzLaw,
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
        CellLayout::PartCarried(c) => c.configuration = configuration.chosen,
        CellLayout::TorchCarried(c) => c.configuration = configuration.chosen,
    }
    let inputs: Vec<PathPointInput> = setup
        .points
        .iter()
        .enumerate()
        .map(|(m, cp)| path_point(layer, m, cp, e.r[m]))
        .collect();
    let mut topts = opts.trajectory;
    topts.with_derivatives = false;
    let (violations, solved) = match joint_trajectory(&cell, &inputs, &topts) {
        Ok(t) => {
            // its dexterity is the exact value the plan reports, wherever
            // it solved the same joints (it does everywhere: same IK, same
            // unwrapping); the SVD is not repeated there
            for (m, jp) in t.points.iter().enumerate().take(p) {
                if !e.dex_exact[m] && jp.joints == Some(e.q[m]) {
                    e.set_exact_dexterity(m, jp.dexterity);
                }
            }
            let violations = t.report.violations.clone();
            let solved = SolvedBead::new(&cell, &topts, inputs.clone(), t);
            (violations, Some(std::sync::Arc::new(solved)))
        }
        Err(_) => (Vec::new(), None),
    };
    problem.exact_dexterity(&mut e);
    let binding = problem.binding(&e, BINDING_VIOLATION).or_else(|| {
        violations.first().map(|v| {
            // the amount in the units of `BindingConstraint::violation`: rad past a
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
                        (speed_rad_s - max_rad_s) * step_mm / inputs[v.point].travel_speed_mm_s,
                    )
                }
                ViolationKind::HoseTorsion {
                    torsion_rad,
                    max_rad,
                } => (Constraint::HoseTorsion, torsion_rad - max_rad),
                ViolationKind::BuildTilt { tilt_rad, max_rad } => {
                    (Constraint::BuildTilt, tilt_rad - max_rad)
                }
                _ => (Constraint::Dexterity, 0.0),
            };
            BindingConstraint {
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
            &encoder_sigma_rad(robot),
            crate::robot::indices::UncertaintyFormula::RootTrace,
        );
        unc_sum += i * i;
    }
    let centring: f64 = e.q.iter().map(|q| problem.centring_of(q)).sum();
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
        positioner: None,
        solved,
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
            if dq.abs() > REVERSAL_MIN_STEP_RAD {
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
