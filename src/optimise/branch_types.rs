//! The optimiser's shared types of one layer's solve, in one leaf file that
//! imports none of the files using it: what a branch gave
//! ([`BranchOutcome`]), where a spiral turn starts ([`Anchor`]), the degrees
//! a polynomial law goes through and the best one kept ([`Degrees`],
//! [`Best`]). The branch, degree, subsample, setup and spiral files import
//! these instead of each other.

use super::parameterisation::Basis;
use super::problem::{Evaluation, PointFailure};
use super::{sqp, SolvedRzLaw};
use crate::math::tol;
use crate::robot::ik::Configuration;
use crate::robot::Joints;

/// What one branch gave.
pub(super) struct BranchOutcome {
    pub(super) cfg: Configuration,
    pub(super) eval: Result<Evaluation, PointFailure>,
    pub(super) law: SolvedRzLaw,
    pub(super) violation: f64,
    pub(super) converged: bool,
    pub(super) iterations: usize,
    pub(super) qp_solves: usize,
    pub(super) qp_failures: usize,
    pub(super) problem_psi: Vec<f64>,
    /// Points the law was optimised on, when subsampled and certified.
    pub(super) samples: Option<usize>,
}

/// Where a spiral turn starts: the previous turn's last point.
#[derive(Debug, Clone, Copy)]
pub(super) struct Anchor {
    pub(super) r_z: f64,
    pub(super) joints: Joints,
    pub(super) configuration: Configuration,
    /// The previous turn's dexterity floor at its last point.
    pub(super) floor: f64,
}

/// The degrees a polynomial law goes through: from `start` up to `max`,
/// while the relative objective gain is at least `stop_relative_gain`.
pub(super) struct Degrees {
    pub(super) start: usize,
    pub(super) max: usize,
    pub(super) stop_relative_gain: f64,
}

/// The degree kept by [`degree_loop`]: its coefficients, basis and SQP result.
pub(super) struct Best {
    pub(super) degree: usize,
    pub(super) c: Vec<f64>,
    pub(super) basis: Basis,
    pub(super) res: sqp::SqpResult,
}

impl Best {
    /// `(violation, objective)` of `best`, `None` before the first degree.
    pub(super) fn key(best: &Option<Best>) -> Option<(f64, f64)> {
        best.as_ref().map(|b| (b.res.violation, b.res.objective))
    }

    /// Offers degree `degree`'s solution `res` (coefficients `c` over
    /// `basis`) to the best so far: it replaces it when it [`improves`] on
    /// it. Returns its [`relative_gain`] over the best before it.
    pub(super) fn offer(
        best: &mut Option<Best>,
        degree: usize,
        c: &[f64],
        basis: &Basis,
        res: sqp::SqpResult,
    ) -> f64 {
        let last = Best::key(best);
        let new = (res.violation, res.objective);
        if improves(new, last) {
            *best = Some(Best {
                degree,
                c: c.to_vec(),
                basis: basis.clone(),
                res,
            });
        }
        relative_gain(new, last)
    }
}

/// `true` when a degree's `(violation, objective)` is better than the best
/// so far (less violation, or as little and a lower objective).
fn improves(new: (f64, f64), best: Option<(f64, f64)>) -> bool {
    match best {
        None => true,
        Some((bv, bf)) => new.0 < bv || (new.0 <= bv && new.1 < bf),
    }
}

/// Relative objective gain of a degree over the best so far when both are
/// feasible; infinite otherwise (keep raising).
fn relative_gain(new: (f64, f64), best: Option<(f64, f64)>) -> f64 {
    match best {
        Some((bv, bf)) if bv <= 0.0 && new.0 <= 0.0 => (bf - new.1) / bf.abs().max(tol::DIV_FLOOR),
        _ => f64::INFINITY,
    }
}
