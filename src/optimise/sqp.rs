//! The sequential-QP driver of one layer: Gauss–Newton model of the
//! objective, constraints linearised with the analytic `dq/dR_Z` through the
//! basis, an l∞ elastic variable so that every QP is feasible (a layer that
//! cannot be made feasible ends at the least violation instead of failing),
//! and a trust region on the change of `R_Z` at any point. Each QP is solved
//! in closed form when its unconstrained minimiser breaks no row (the usual
//! case: few constraints bind among the hundreds linearised), otherwise with
//! clarabel on a working set grown until no row is broken. With few
//! coefficients the Gauss–Newton matrix gets a structured secant (PSB)
//! correction, which the large centring residuals need.

use crate::optimise::options::SqpOptions;
use crate::optimise::parameterisation::Basis;
use crate::optimise::problem::{Evaluation, LayerProblem, PointFailure};
use crate::optimise::qp::{solve_qp, unconstrained};

/// A step is accepted when the merit falls by at least this fraction of the
/// model's predicted decrease (unitless, the trust-region ratio).
const ACCEPT_RATIO: f64 = 1e-4;
/// The polish takes Gauss–Newton steps of at most this (rad of `R_Z`) and
/// stops where a constraint is within reach of such a step.
const POLISH_MAX_STEP_RAD: f64 = 1e-3;
/// The polish stops after a step below this (rad of `R_Z`).
const POLISH_MIN_STEP_RAD: f64 = 1e-12;

/// The polish stops when the Gauss–Newton model predicts a relative
/// decrease of the objective below this: it is flat there, and such steps
/// (of at most ~1e-4 rad of `R_Z` on the sample parts) are refused about
/// as often as they are taken.
const POLISH_MIN_GAIN: f64 = 1e-10;

/// Result of one SQP run.
#[derive(Debug, Clone)]
pub(crate) struct SqpResult {
    pub c: Vec<f64>,
    pub eval: Evaluation,
    /// Objective (unscaled).
    pub objective: f64,
    /// Largest constraint violation (0 when feasible).
    pub violation: f64,
    pub iterations: usize,
    pub qp_solves: usize,
    pub qp_failures: usize,
    pub converged: bool,
}

/// Runs the SQP from coefficients `c0` (`start`: the evaluation there, if known). `scale` divides the objective (keep
/// it fixed for one layer so that merits compare). `Err` only when the start
/// itself has no joint solution.
pub(crate) fn solve(
    problem: &LayerProblem,
    basis: &Basis,
    c0: Vec<f64>,
    start: Option<Evaluation>,
    smoothness: f64,
    scale: f64,
    opts: &SqpOptions,
) -> Result<SqpResult, PointFailure> {
    let k = basis.len();
    let rho = opts.penalty;
    let mut c = c0;
    // `start` is the evaluation at `basis.eval(&c0)` when the caller has it
    // (a degree raised with its new coefficient at 0 leaves `R_Z` unchanged)
    let mut e = match start {
        Some(e) => e,
        None => problem.evaluate(&basis.eval(&c))?,
    };
    let mut f = problem.objective(&e, smoothness);
    let mut v = problem.max_violation(&e);
    let mut merit = f / scale + rho * v;
    let mut trust = opts.initial_trust_rad;
    let l1 = basis.row_l1_bound();
    let (mut iterations, mut qp_solves, mut qp_failures) = (0, 0, 0);
    let mut converged = false;
    let mut p_dense = vec![0.0; k * k];
    let mut grad = vec![0.0; k];
    gauss_newton(
        problem,
        &e,
        smoothness,
        basis,
        scale,
        &mut p_dense,
        &mut grad,
    );
    // Structured secant correction of the Gauss–Newton matrix (PSB update on
    // the gradient differences of every trial, accepted or not): the
    // centring residuals are large, and Gauss–Newton alone overshoots and
    // zig-zags on them. Only for few coefficients (dense k × k).
    let secant = k <= 16;
    let mut corr = vec![0.0; if secant { k * k } else { 0 }];
    let mut p_model = vec![0.0; k * k];
    let mut p_new = vec![0.0; k * k];
    let mut grad_new = vec![0.0; k];
    while iterations < opts.max_iterations {
        iterations += 1;
        p_model.copy_from_slice(&p_dense);
        if secant {
            for (m, s) in p_model.iter_mut().zip(&corr) {
                *m += s;
            }
            if corr.iter().any(|x| *x != 0.0) && !positive_definite(k, &p_model) {
                corr.iter_mut().for_each(|x| *x = 0.0);
                p_model.copy_from_slice(&p_dense);
            }
        }
        let rows = problem.constraint_rows(&e, basis, trust);
        qp_solves += 1;
        let bound = trust / l1;
        let Some(qp) = solve_qp(k, &p_model, &grad, &rows, rho, bound) else {
            qp_failures += 1;
            trust *= 0.25;
            if trust < opts.min_trust_rad {
                break;
            }
            continue;
        };
        let dc = &qp.x;
        let mut quad = 0.0;
        for i in 0..k {
            quad += grad[i] * dc[i];
            for j in 0..k {
                quad += 0.5 * dc[i] * p_model[i * k + j] * dc[j];
            }
        }
        let predicted = -quad + rho * (v - qp.t);
        let c_new: Vec<f64> = c.iter().zip(dc).map(|(a, b)| a + b).collect();
        let r_new = basis.eval(&c_new);
        let step = r_new
            .iter()
            .zip(&e.r)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        let box_bound = dc.iter().any(|x| x.abs() > 0.99 * bound);
        if !(predicted > 0.1 * opts.relative_tolerance * (1.0 + merit.abs()))
            || step < opts.step_tolerance_rad
        {
            converged = true;
            break;
        }
        let trial = problem.evaluate(&r_new);
        let accepted = match trial {
            Ok(e_new) => {
                let f_new = problem.objective(&e_new, smoothness);
                let v_new = problem.max_violation(&e_new);
                let merit_new = f_new / scale + rho * v_new;
                let ratio = (merit - merit_new) / predicted;
                gauss_newton(
                    problem,
                    &e_new,
                    smoothness,
                    basis,
                    scale,
                    &mut p_new,
                    &mut grad_new,
                );
                let ok = ratio >= ACCEPT_RATIO;
                if secant {
                    let p_ref = if ok { &p_new } else { &p_dense };
                    psb_update(k, &mut corr, p_ref, dc, &grad, &grad_new);
                }
                if ok {
                    let gain = merit - merit_new;
                    if ratio > 0.75 && (step > 0.8 * trust || box_bound) {
                        trust = (2.0 * trust).min(std::f64::consts::PI);
                    } else if ratio < 0.25 {
                        trust = 0.5 * step;
                    }
                    c = c_new;
                    e = e_new;
                    f = f_new;
                    v = v_new;
                    merit = merit_new;
                    std::mem::swap(&mut p_dense, &mut p_new);
                    std::mem::swap(&mut grad, &mut grad_new);
                    if gain <= opts.relative_tolerance * (1.0 + merit.abs()) {
                        converged = true;
                    }
                    true
                } else {
                    false
                }
            }
            Err(_) => false,
        };
        if converged {
            break;
        }
        if !accepted {
            trust = 0.25 * step.min(trust);
            if trust < opts.min_trust_rad {
                converged = true;
                break;
            }
        }
    }
    // Polish: with no constraint in reach, a few exact Gauss–Newton steps
    // (Cholesky) settle the flat directions more precisely than the
    // interior-point QPs (the centring tie-break of a part of revolution).
    if v <= 0.0 && k <= 16 {
        for _ in 0..4 {
            let mut pm = nalgebra::DMatrix::<f64>::zeros(k, k);
            let mut gv = nalgebra::DVector::<f64>::zeros(k);
            problem.residuals(&e, smoothness, Some(basis), &mut |r, a| {
                for &(i, ai) in a {
                    gv[i] += r * ai;
                    for &(j, aj) in a {
                        pm[(i, j)] += ai * aj;
                    }
                }
            });
            let Some(ch) = pm.cholesky() else { break };
            let dc = ch.solve(&(-&gv));
            // the model's decrease of f = Σr², `gᵀP⁻¹g` here: below this
            // fraction of f the step is not worth an evaluation
            if -gv.dot(&dc) < POLISH_MIN_GAIN * f
                || !problem
                    .constraint_rows(&e, basis, POLISH_MAX_STEP_RAD)
                    .is_empty()
            {
                break;
            }
            let c_new: Vec<f64> = c.iter().zip(dc.iter()).map(|(a, b)| a + b).collect();
            let r_new = basis.eval(&c_new);
            let step = r_new
                .iter()
                .zip(&e.r)
                .map(|(a, b)| (a - b).abs())
                .fold(0.0, f64::max);
            // a step below the convergence tolerance is not worth an evaluation
            if step > POLISH_MAX_STEP_RAD || step < opts.step_tolerance_rad {
                break;
            }
            let Ok(e_new) = problem.evaluate(&r_new) else {
                break;
            };
            let f_new = problem.objective(&e_new, smoothness);
            let v_new = problem.max_violation(&e_new);
            if v_new > 0.0 || f_new > f {
                break;
            }
            c = c_new;
            e = e_new;
            f = f_new;
            if step < POLISH_MIN_STEP_RAD {
                break;
            }
        }
    }
    Ok(SqpResult {
        c,
        eval: e,
        objective: f,
        violation: v,
        iterations,
        qp_solves,
        qp_failures,
        converged,
    })
}

/// Largest decrease of the objective (unscaled) that the Gauss–Newton
/// model at `e` predicts over `basis` without constraints, `½ gᵀP⁻¹g`, and
/// the largest change of `R_Z` (rad) of that model step; `None` when `P` is
/// not positive definite. With constraints the model's decrease can only be
/// smaller.
pub(crate) fn predicted_gain(
    problem: &LayerProblem,
    e: &Evaluation,
    smoothness: f64,
    basis: &Basis,
) -> Option<(f64, f64)> {
    let k = basis.len();
    let mut p_dense = vec![0.0; k * k];
    let mut grad = vec![0.0; k];
    gauss_newton(problem, e, smoothness, basis, 1.0, &mut p_dense, &mut grad);
    let x = unconstrained(k, &p_dense, &grad)?;
    let gain = -0.5 * grad.iter().zip(&x).map(|(g, x)| g * x).sum::<f64>();
    // δR = B δc (the anchored basis's constant `r0` cancels)
    let step = basis
        .eval(&x)
        .iter()
        .zip(basis.eval(&vec![0.0; k]))
        .fold(0.0f64, |a, (v, v0)| a.max((v - v0).abs()));
    (gain.is_finite() && step.is_finite()).then_some((gain.max(0.0), step))
}

/// Gauss–Newton model of `f / scale` at `e`: `P = 2 Σ aᵀa / scale` (dense,
/// row-major `k × k`) and the gradient `2 Σ r a / scale`.
fn gauss_newton(
    problem: &LayerProblem,
    e: &Evaluation,
    smoothness: f64,
    basis: &Basis,
    scale: f64,
    p_dense: &mut [f64],
    grad: &mut [f64],
) {
    let k = grad.len();
    p_dense.iter_mut().for_each(|x| *x = 0.0);
    grad.iter_mut().for_each(|x| *x = 0.0);
    problem.residuals(e, smoothness, Some(basis), &mut |r, a| {
        for &(i, ai) in a {
            grad[i] += 2.0 * r * ai / scale;
            for &(j, aj) in a {
                p_dense[i * k + j] += 2.0 * ai * aj / scale;
            }
        }
    });
}

/// `true` when the dense symmetric `k × k` matrix has a Cholesky factor.
fn positive_definite(k: usize, p: &[f64]) -> bool {
    nalgebra::DMatrix::from_row_slice(k, k, p)
        .cholesky()
        .is_some()
}

/// Powell-symmetric-Broyden update of the correction `S` so that
/// `(P_ref + S) s = y`, `y = g_new − g_old` (dense, row-major `k × k`).
fn psb_update(k: usize, corr: &mut [f64], p_ref: &[f64], s: &[f64], g_old: &[f64], g_new: &[f64]) {
    let ss: f64 = s.iter().map(|x| x * x).sum();
    if !(ss > 0.0) {
        return;
    }
    // w = y − P_ref s − S s
    let w: Vec<f64> = (0..k)
        .map(|i| {
            let ps: f64 = (0..k)
                .map(|j| (p_ref[i * k + j] + corr[i * k + j]) * s[j])
                .sum();
            g_new[i] - g_old[i] - ps
        })
        .collect();
    if !w.iter().all(|x| x.is_finite()) {
        return;
    }
    let ws: f64 = w.iter().zip(s).map(|(a, b)| a * b).sum();
    for i in 0..k {
        for j in 0..k {
            corr[i * k + j] += (w[i] * s[j] + s[i] * w[j]) / ss - ws * s[i] * s[j] / (ss * ss);
        }
    }
}
