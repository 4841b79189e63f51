//! **Stage 6a — the positioner's laws: their SQP.** Gauss–Newton steps on
//! the law's spline coefficients (rad per unit basis value) within a trust
//! region, each an elastic QP of the `R_Z` driver's (so an infeasible law
//! ends at its least violation), accepted on an l∞ merit. Not the `R_Z`
//! driver's SQP: no secant correction, no ratio test, no polish.

use crate::optimise::parameterisation::Basis;
use crate::optimise::qp::solve_qp;

use super::problem::{build_model, LawProblem, Model};

/// Ridge added to the positioner SQP's Gauss–Newton matrix, relative to its
/// mean diagonal (relative).
const RIDGE_REL: f64 = 1e-9;
/// Floor of the mean diagonal the ridge scales with (units of `JᵀJ`).
const RIDGE_TRACE_FLOOR: f64 = 1e-12;
/// Trust bound on the positioner joints' coefficients (rad) below which the
/// SQP stops.
const MIN_TRUST_RAD: f64 = 1e-9;
/// Largest coefficient change (rad) of a refused step below which the SQP
/// stops: shrinking the trust region further changes nothing.
const MIN_STEP_RAD: f64 = 1e-10;
/// A trial is accepted when it lowers the merit by more than this fraction of
/// it (relative): more than rounding.
const ACCEPT_GAIN_REL: f64 = 1e-14;
/// An accepted gain below this fraction of the merit (relative) is flat: the
/// SQP stops.
const FLAT_GAIN_REL: f64 = 1e-9;
/// Floor of the merit the two relative gains above scale with (merit units).
const MERIT_FLOOR: f64 = 1e-12;

fn merit(model: &Model, rho: f64) -> f64 {
    0.5 * model.r.iter().map(|v| v * v).sum::<f64>() + rho * model.violation
}

/// Gauss–Newton SQP with a trust region on the coefficients (rad per unit
/// basis value); returns the coefficients, the iterations made and the
/// largest violation of a linearised row left on the samples.
pub(super) fn sqp(
    pb: &LawProblem,
    basis: &Basis,
    idx: &[usize],
    x0: Vec<f64>,
) -> (Vec<f64>, usize, f64) {
    let n = x0.len();
    let rho = 1e2;
    let mut x = x0;
    let mut model = build_model(pb, basis, idx, &x, true);
    let mut cur = merit(&model, rho);
    let mut bound = 0.3 / basis.row_l1_bound();
    let mut iterations = 0;
    for _ in 0..pb.opts.max_iterations {
        iterations += 1;
        // P = JᵀJ (+ a small ridge), g = Jᵀr
        // (over each row's non-zero entries: the zero ones add nothing)
        let mut p = vec![0.0; n * n];
        let mut g = vec![0.0; n];
        for (i_r, ri) in model.r.iter().enumerate() {
            let row = model.jac.row(i_r);
            for &(i, vi) in row {
                g[i] += vi * ri;
                for &(j, vj) in row {
                    p[i * n + j] += vi * vj;
                }
            }
        }
        let trace: f64 = (0..n).map(|i| p[i * n + i]).sum::<f64>() / n as f64;
        for i in 0..n {
            p[i * n + i] += RIDGE_REL * trace.max(RIDGE_TRACE_FLOOR);
        }
        let Some(qp) = solve_qp(n, &p, &g, &model.rows, rho, bound) else {
            bound *= 0.25;
            if bound < MIN_TRUST_RAD {
                break;
            }
            continue;
        };
        let trial: Vec<f64> = x.iter().zip(&qp.x).map(|(a, d)| a + d).collect();
        let tm = build_model(pb, basis, idx, &trial, true);
        let new = merit(&tm, rho);
        let step = qp.x.iter().fold(0.0f64, |a, v| a.max(v.abs()));
        if new.is_finite() && new < cur - ACCEPT_GAIN_REL * cur.abs().max(MERIT_FLOOR) {
            let gain = cur - new;
            x = trial;
            model = tm;
            cur = new;
            if step > 0.9 * bound {
                bound *= 2.0;
            }
            // flat: a relative gain this small moves no axis by a
            // measurable amount (feasible or at the least violation)
            if gain < FLAT_GAIN_REL * cur.abs().max(MERIT_FLOOR) {
                break;
            }
        } else {
            bound *= 0.25;
            if bound < MIN_TRUST_RAD || step < MIN_STEP_RAD {
                break;
            }
        }
    }
    (x, iterations, model.violation)
}
