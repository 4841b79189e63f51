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
use crate::optimise::qp::{solve_qp, unconstrained, QpMethod};

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
    let run = Run {
        problem,
        basis,
        smoothness,
        scale,
        opts,
    };
    // `start` is the evaluation at `basis.eval(&c0)` when the caller has it
    // (a degree raised with its new coefficient at 0 leaves `R_Z` unchanged)
    let e = match start {
        Some(e) => e,
        None => problem.evaluate(&basis.eval(&c0))?,
    };
    let mut at = run.iterate(c0, e);
    let mut model = Model::new(&run, &at.e);
    let counts = run.descend(&mut at, &mut model);
    if at.v <= 0.0 && basis.len() <= 16 {
        run.polish(&mut at);
    }
    Ok(SqpResult {
        c: at.c,
        eval: at.e,
        objective: at.f,
        violation: at.v,
        iterations: counts.iterations,
        qp_solves: counts.qp_solves,
        qp_failures: counts.qp_failures,
        converged: counts.converged,
    })
}

/// What one SQP run works on: the layer's problem over `basis`, the
/// objective's smoothness weight, the scale dividing it, the options.
struct Run<'r, 'p> {
    problem: &'r LayerProblem<'p>,
    basis: &'r Basis,
    smoothness: f64,
    scale: f64,
    opts: &'r SqpOptions,
}

/// A point of the SQP: coefficients, their evaluation, the objective
/// (unscaled), the largest violation and the merit `f / scale + ρ v`.
struct Iterate {
    c: Vec<f64>,
    e: Evaluation,
    f: f64,
    v: f64,
    merit: f64,
}

/// The counts of [`SqpResult`].
#[derive(Default)]
struct Counts {
    iterations: usize,
    qp_solves: usize,
    qp_failures: usize,
    converged: bool,
}

/// The QPs' model of the merit: the Gauss–Newton matrix `P` and gradient at
/// the current point (dense, row-major `k × k`), the structured secant
/// correction `S` (PSB update on the gradient differences of every trial,
/// accepted or not: the centring residuals are large, and Gauss–Newton
/// alone overshoots and zig-zags on them; only for few coefficients), and
/// the same at the trial point.
struct Model {
    k: usize,
    p_dense: Vec<f64>,
    grad: Vec<f64>,
    secant: bool,
    corr: Vec<f64>,
    /// `P + S`, the matrix of the QP.
    p_model: Vec<f64>,
    p_new: Vec<f64>,
    grad_new: Vec<f64>,
}

impl Model {
    /// The Gauss–Newton model at `e`, no correction yet.
    fn new(run: &Run, e: &Evaluation) -> Self {
        let k = run.basis.len();
        let mut p_dense = vec![0.0; k * k];
        let mut grad = vec![0.0; k];
        run.gauss_newton(e, &mut p_dense, &mut grad);
        let secant = k <= 16;
        Model {
            k,
            p_dense,
            grad,
            secant,
            corr: vec![0.0; if secant { k * k } else { 0 }],
            p_model: vec![0.0; k * k],
            p_new: vec![0.0; k * k],
            grad_new: vec![0.0; k],
        }
    }

    /// `P + S` into the QP's matrix; the correction dropped where the sum
    /// is not positive definite.
    fn prepare(&mut self) {
        self.p_model.copy_from_slice(&self.p_dense);
        if self.secant {
            for (m, s) in self.p_model.iter_mut().zip(&self.corr) {
                *m += s;
            }
            if self.corr.iter().any(|x| *x != 0.0) && !positive_definite(self.k, &self.p_model) {
                self.corr.iter_mut().for_each(|x| *x = 0.0);
                self.p_model.copy_from_slice(&self.p_dense);
            }
        }
    }

    /// The model's change of the scaled objective over a step `dc`:
    /// `gᵀδ + ½ δᵀ(P + S)δ`.
    fn quadratic(&self, dc: &[f64]) -> f64 {
        let k = self.k;
        let mut quad = 0.0;
        for i in 0..k {
            quad += self.grad[i] * dc[i];
            for j in 0..k {
                quad += 0.5 * dc[i] * self.p_model[i * k + j] * dc[j];
            }
        }
        quad
    }

    /// The secant correction updated over the step `dc` to the trial point
    /// (whose model is in `p_new`, `grad_new`), against the trial's matrix
    /// where `accepted`, else the current one.
    fn update_secant(&mut self, accepted: bool, dc: &[f64]) {
        if self.secant {
            let p_ref = if accepted { &self.p_new } else { &self.p_dense };
            psb_update(
                self.k,
                &mut self.corr,
                p_ref,
                dc,
                &self.grad,
                &self.grad_new,
            );
        }
    }

    /// The trial's model becomes the current one.
    fn accept(&mut self) {
        std::mem::swap(&mut self.p_dense, &mut self.p_new);
        std::mem::swap(&mut self.grad, &mut self.grad_new);
    }
}

impl Run<'_, '_> {
    /// The point at coefficients `c` evaluated as `e`.
    fn iterate(&self, c: Vec<f64>, e: Evaluation) -> Iterate {
        let f = self.problem.objective(&e, self.smoothness);
        let v = self.problem.max_violation(&e);
        let merit = f / self.scale + self.opts.penalty * v;
        Iterate { c, e, f, v, merit }
    }

    /// [`gauss_newton`] of this run at `e`.
    fn gauss_newton(&self, e: &Evaluation, p_dense: &mut [f64], grad: &mut [f64]) {
        gauss_newton(
            self.problem,
            e,
            self.smoothness,
            self.basis,
            self.scale,
            p_dense,
            grad,
        );
    }

    /// The trust-region iterations from `at`: each solves the elastic QP on
    /// the constraints linearised within the trust region (`R_Z`, rad), and
    /// tries its step ([`Run::try_step`]); the region grows after a good
    /// step against its bound and shrinks after a poor or refused one. Stops
    /// where the model predicts no decrease worth a step, the step is below
    /// tolerance, an accepted gain is flat, or the region has shrunk away.
    fn descend(&self, at: &mut Iterate, model: &mut Model) -> Counts {
        let k = self.basis.len();
        let rho = self.opts.penalty;
        let l1 = self.basis.row_l1_bound();
        let mut trust = self.opts.initial_trust_rad;
        let mut n = Counts::default();
        while n.iterations < self.opts.max_iterations {
            n.iterations += 1;
            model.prepare();
            let rows = self.problem.constraint_rows(&at.e, self.basis, trust);
            n.qp_solves += 1;
            let bound = trust / l1;
            let Some(qp) = solve_qp(
                k,
                &model.p_model,
                &model.grad,
                &rows,
                rho,
                bound,
                QpMethod::Clarabel,
            ) else {
                n.qp_failures += 1;
                trust *= 0.25;
                if trust < self.opts.min_trust_rad {
                    break;
                }
                continue;
            };
            let dc = &qp.x;
            let predicted = -model.quadratic(dc) + rho * (at.v - qp.t);
            let c_new: Vec<f64> = at.c.iter().zip(dc).map(|(a, b)| a + b).collect();
            let r_new = self.basis.eval(&c_new);
            let step = largest_change(&r_new, &at.e.r);
            let box_bound = dc.iter().any(|x| x.abs() > 0.99 * bound);
            if !(predicted > 0.1 * self.opts.relative_tolerance * (1.0 + at.merit.abs()))
                || step < self.opts.step_tolerance_rad
            {
                n.converged = true;
                break;
            }
            match self.try_step(at, model, c_new, &r_new, dc, predicted) {
                Some((ratio, gain)) => {
                    if ratio > 0.75 && (step > 0.8 * trust || box_bound) {
                        trust = (2.0 * trust).min(std::f64::consts::PI);
                    } else if ratio < 0.25 {
                        trust = 0.5 * step;
                    }
                    if gain <= self.opts.relative_tolerance * (1.0 + at.merit.abs()) {
                        n.converged = true;
                        break;
                    }
                }
                None => {
                    trust = 0.25 * step.min(trust);
                    if trust < self.opts.min_trust_rad {
                        n.converged = true;
                        break;
                    }
                }
            }
        }
        n
    }

    /// The trial point `c_new` (`R_Z` `r_new`, reached by the step `dc`
    /// whose model decrease is `predicted`) evaluated, its model computed
    /// and the secant updated; accepted — `at` and `model` moved there —
    /// where the merit falls by at least [`ACCEPT_RATIO`] of `predicted`.
    /// Returns the ratio of actual to predicted decrease and the gain of an
    /// accepted step; `None` where refused or without a joint solution.
    fn try_step(
        &self,
        at: &mut Iterate,
        model: &mut Model,
        c_new: Vec<f64>,
        r_new: &[f64],
        dc: &[f64],
        predicted: f64,
    ) -> Option<(f64, f64)> {
        let Ok(e_new) = self.problem.evaluate(r_new) else {
            return None;
        };
        let trial = self.iterate(c_new, e_new);
        let ratio = (at.merit - trial.merit) / predicted;
        self.gauss_newton(&trial.e, &mut model.p_new, &mut model.grad_new);
        let ok = ratio >= ACCEPT_RATIO;
        model.update_secant(ok, dc);
        if !ok {
            return None;
        }
        let gain = at.merit - trial.merit;
        *at = trial;
        model.accept();
        Some((ratio, gain))
    }

    /// Polish: with no constraint in reach, a few exact Gauss–Newton steps
    /// (Cholesky) settle the flat directions more precisely than the
    /// interior-point QPs (the centring tie-break of a part of revolution).
    /// Moves the coefficients, evaluation and objective of `at` (not its
    /// violation, which stays 0, nor its merit).
    fn polish(&self, at: &mut Iterate) {
        let k = self.basis.len();
        for _ in 0..4 {
            let mut pm = nalgebra::DMatrix::<f64>::zeros(k, k);
            let mut gv = nalgebra::DVector::<f64>::zeros(k);
            self.problem
                .residuals(&at.e, self.smoothness, Some(self.basis), &mut |r, a| {
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
            if -gv.dot(&dc) < POLISH_MIN_GAIN * at.f
                || !self
                    .problem
                    .constraint_rows(&at.e, self.basis, POLISH_MAX_STEP_RAD)
                    .is_empty()
            {
                break;
            }
            let c_new: Vec<f64> = at.c.iter().zip(dc.iter()).map(|(a, b)| a + b).collect();
            let r_new = self.basis.eval(&c_new);
            let step = largest_change(&r_new, &at.e.r);
            // a step below the convergence tolerance is not worth an evaluation
            if step > POLISH_MAX_STEP_RAD || step < self.opts.step_tolerance_rad {
                break;
            }
            let Ok(e_new) = self.problem.evaluate(&r_new) else {
                break;
            };
            let f_new = self.problem.objective(&e_new, self.smoothness);
            let v_new = self.problem.max_violation(&e_new);
            if v_new > 0.0 || f_new > at.f {
                break;
            }
            at.c = c_new;
            at.e = e_new;
            at.f = f_new;
            if step < POLISH_MIN_STEP_RAD {
                break;
            }
        }
    }
}

/// The largest change between two `R_Z` laws, point by point (rad).
fn largest_change(r_new: &[f64], r: &[f64]) -> f64 {
    r_new
        .iter()
        .zip(r)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max)
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
