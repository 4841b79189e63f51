//! The polynomial law's degree loop [SPEC §7; thesis §4.2.1]: from the
//! seed's degree, each degree solved by the SQP with a warm start (the new
//! coefficient starts at 0), until the objective stops improving or the
//! Gauss–Newton model bounds the next degree's gain below the criterion.

use super::branch::BranchOutcome;
use super::parameterisation::Basis;
use super::problem::{Evaluation, LayerProblem};
use super::seed::Seed;
use super::setup::LayerSetup;
use super::{sqp, RzLaw};

/// Raises the degree of the polynomial `R_Z` law of `setup`'s layer from
/// `seed`'s up to `max_degree` while the relative objective gain is at least
/// `stop_relative_gain`, and records the best degree's law and evaluation
/// (and the SQP's counts) in `outcome`. Spiral turns hold `R_Z` on their
/// shared point (degree at least 1).
pub(super) fn raise_degrees(
    setup: &LayerSetup,
    problem: &LayerProblem,
    seed: &Seed,
    max_degree: usize,
    stop_relative_gain: f64,
    outcome: &mut BranchOutcome,
) {
    let opts = setup.opts;
    let p = setup.points.len();
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
            problem,
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
                    return;
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
                        && skip_raise(problem, e, &b, stop_relative_gain * bst.objective)
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
