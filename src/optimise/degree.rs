//! The polynomial law's degree loop [SPEC §7; thesis §4.2.1]: from the
//! seed's degree, each degree solved by the SQP with a warm start (the new
//! coefficient starts at 0), until the objective stops improving or the
//! Gauss–Newton model bounds the next degree's gain below the criterion.

use super::branch_types::{Best, BranchOutcome, Degrees};
use super::parameterisation::Basis;
use super::problem::{Evaluation, LayerProblem, PointFailure};
use super::setup::LayerSetup;
use super::{sqp, SolvedRzLaw, SqpOptions};
use crate::math::tol;

/// Floor of the model step (rad) within whose reach constraints are looked
/// for before skipping a degree raise: a zero step still sees the constraints
/// at the edge.
const MIN_REACH_STEP_RAD: f64 = 1e-6;

/// Consecutive degrees that gained less than the stop criterion after which
/// the loop ends whatever the Gauss–Newton model predicts: the model is
/// unconstrained, and where a constraint holds the law (a torch-carried
/// part of revolution: the table turns the part, the arm stands still) it
/// keeps predicting a gain that no degree realises. Two, as the look-ahead
/// of [`raise_again`]: an odd degree that adds nothing before an even one
/// that does is still solved.
pub(super) const STALLED_DEGREES: usize = 2;

/// Records `best` (with the objective of every degree solved, `history`)
/// as `outcome`'s law and evaluation.
pub(super) fn record(
    setup: &LayerSetup,
    best: Best,
    history: Vec<(usize, f64)>,
    outcome: &mut BranchOutcome,
) {
    outcome.converged = best.res.converged;
    outcome.law = SolvedRzLaw::Polynomial {
        degree: best.degree,
        cylindrical: setup.cylindrical,
        coefficients_deg: best
            .basis
            .thesis_coefficients_deg(&best.c, !setup.cylindrical)
            .unwrap_or_default(),
        objective_per_degree: history,
    };
    outcome.eval = Ok(best.res.eval);
}

/// The degree loop on `problem` (a whole layer or a subsample of it) from
/// coefficients `c` over `basis` (of degree `degrees.start`): the best
/// degree and the objective of every degree solved; the SQP's counts are
/// added to `counts`. `Err` when the start has no joint solution.
pub(super) fn degree_loop(
    problem: &LayerProblem,
    mut basis: Basis,
    mut c: Vec<f64>,
    degrees: &Degrees,
    sqp_opts: &SqpOptions,
    counts: &mut BranchOutcome,
) -> Result<(Best, Vec<(usize, f64)>), PointFailure> {
    let e0 = problem.evaluate(&basis.eval(&c)).ok();
    let scale = match &e0 {
        Some(e) => problem.objective(e, 0.0).max(tol::OBJECTIVE_SCALE_FLOOR),
        None => 1.0,
    };
    let mut history = Vec::new();
    let mut best: Option<Best> = None;
    let mut at_c: Option<Evaluation> = e0;
    let mut stalled = 0;
    for degree in degrees.start..=degrees.max.max(degrees.start) {
        let gain = match sqp::solve(
            problem,
            &basis,
            c.clone(),
            at_c.take(),
            0.0,
            scale,
            sqp_opts,
        ) {
            Ok(res) => {
                at_c = Some(res.eval.clone());
                counts.iterations += res.iterations;
                counts.qp_solves += res.qp_solves;
                counts.qp_failures += res.qp_failures;
                history.push((degree, res.objective));
                c = res.c.clone();
                Best::offer(&mut best, degree, &c, &basis, res)
            }
            Err(f) => match best {
                None => return Err(f),
                Some(_) => break,
            },
        };
        stalled = if gain < degrees.stop_relative_gain {
            stalled + 1
        } else {
            0
        };
        let Some(raised) = basis.raised() else {
            break;
        };
        let last = Best::key(&best);
        if stalled >= STALLED_DEGREES
            || !raise_again(
                problem,
                at_c.as_ref(),
                &raised,
                degree + 1,
                gain,
                degrees,
                last,
            )
        {
            break;
        }
        basis = raised;
        c.push(0.0);
    }
    // the first degree either failed (returned above) or set `best`
    best.map(|b| (b, history)).ok_or(PointFailure {
        point: 0,
        error: crate::robot::RobotError::NonFinite { what: "not solved" },
    })
}

/// Whether to solve degree `next` (basis `raised`) after one whose relative
/// gain over the best before it was `gain` (`best`: the best `(violation,
/// objective)` now; `e`: the evaluation at the degree just solved).
///
/// A gain below the stop criterion [§4.2.1] ends the loop unless the
/// Gauss–Newton model at this optimum predicts that the next two degrees
/// gain at least the criterion; a gain above it goes on unless
/// [`skip_raise`] shows that they cannot pay. The look-ahead is two degrees
/// because one is myopic: the odd term of a layer whose best law is nearly
/// even adds nothing where the even term after it does, and whether such a
/// degree is solved at all then hangs on residues (a 1e-9 rad violation
/// of the degree before, the model's 1e-8 gain on a subsample against
/// 1e-6 on every point).
pub(super) fn raise_again(
    problem: &LayerProblem,
    e: Option<&Evaluation>,
    raised: &Basis,
    next: usize,
    gain: f64,
    degrees: &Degrees,
    best: Option<(f64, f64)>,
) -> bool {
    let Some((violation, objective)) = best else {
        return true;
    };
    let stop = degrees.stop_relative_gain;
    let threshold = stop * objective;
    let Some(e) = e else {
        return gain >= stop;
    };
    if violation > 0.0 {
        return true;
    }
    let twice = (next < degrees.max).then(|| raised.raised()).flatten();
    let raised = twice.as_ref().unwrap_or(raised);
    if gain < stop {
        return sqp::predicted_gain(problem, e, 0.0, raised).is_some_and(|(g, _)| g >= threshold);
    }
    !skip_raise(problem, e, raised, threshold)
}

/// Fraction of the stop criterion (relative gain) below which the
/// Gauss–Newton model's gain from one more degree skips that degree.
const RAISE_MODEL_FRACTION: f64 = 1e-2;

/// `true` when raising to `raised` cannot pay: at the current optimum `e`
/// the unconstrained Gauss–Newton model of the raised problem predicts a
/// decrease below `RAISE_MODEL_FRACTION × threshold` (objective units), and
/// no constraint is within reach of that model step (with one, the model
/// would not bound the gain).
pub(super) fn skip_raise(
    problem: &LayerProblem,
    e: &Evaluation,
    raised: &Basis,
    threshold: f64,
) -> bool {
    let Some((gain, step)) = sqp::predicted_gain(problem, e, 0.0, raised) else {
        return false;
    };
    gain < RAISE_MODEL_FRACTION * threshold
        && problem
            .constraint_rows(e, raised, step.max(MIN_REACH_STEP_RAD))
            .is_empty()
}
