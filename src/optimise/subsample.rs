//! The polynomial law optimised on a subsample of a long layer and
//! certified on every point [issue 21; SPEC §7].
//!
//! A polynomial `R_Z` law has at most nine coefficients, so a layer of
//! thousands of points over-determines it: the SQP's cost (an IK, Jacobian
//! and LU per point per iteration, tens of iterations per layer) buys
//! nothing over a few dozen well-spread points. Here the degree loop runs on
//! [`OptimiseOptions::subsample_points`](super::OptimiseOptions::subsample_points)
//! samples (half spread evenly by point index, half by the turning of the
//! tool axis and build direction, so that corners of the path get more), the
//! objective weighted as the whole layer's estimate
//! ([`SampleWeights`](super::problem::SampleWeights)). The law of each
//! degree is then evaluated on every point (one IK pass) and every
//! constraint checked there; where one is violated or within half the
//! solver's margin of its bound, the worst point of each such run of points
//! (and the point before it, for the speed bounds) joins the samples and the
//! degree is re-solved from where it was. The degree loop decides on the
//! objective and violation of every point, as on the whole layer. A layer
//! the samples cannot certify — infeasible at every degree, a point without
//! joint solution, a joint representation that differs from the whole
//! layer's, or still violating after [`MAX_ROUNDS`] refinements — goes back
//! to the whole-layer optimisation, so its verdict is the whole layer's.
//! What the layer reports (joints, constraints, status, quality) is always
//! computed on every point by the caller.

use super::branch_types::{Best, BranchOutcome, Degrees};
use super::degree::{raise_again, record, STALLED_DEGREES};
use super::parameterisation::Basis;
use super::problem::{LayerProblem, SOLVER_MARGIN};
use super::setup::LayerSetup;
use super::sqp;
use crate::math::tol;
use crate::robot::cell::CellPoint;

/// A layer whose tool axis and build direction turn by less than this in
/// total (rad) has samples spread by point count alone.
const MIN_TOTAL_TURN_RAD: f64 = 1e-9;
/// Slack on the sample quantile test (unitless, in `[0, 1]`): rounding does
/// not push a sample one point further.
const QUANTILE_SLACK: f64 = 1e-12;

/// Refinements of the samples before a layer goes back to the whole-layer
/// optimisation.
const MAX_ROUNDS: usize = 6;

/// A point of the whole layer counts as violating when a constraint is
/// closer than this to its bound, or beyond it (rad, or relative for the
/// dexterity): half the margin the SQP aims for on its samples, so that a
/// certified layer is inside every bound by at least that much.
const CERTIFY_TOLERANCE: f64 = -0.5 * SOLVER_MARGIN;

/// Largest difference (rad) between a sample's joints on the samples and
/// on the whole layer for the two to be the same representation (the
/// unwrapping of J4/J6 and of the positioner along the samples can differ
/// from the one along every point when a joint turns by half a turn
/// between two samples).
const SAME_JOINTS_RAD: f64 = 1e-6;

/// Optimises `problem`'s polynomial law (the whole layer; `basis` of degree
/// `degrees.start` over every point, from coefficients `c0`) on a subsample
/// and certifies it on every point; `true` when it did, with the law and
/// the whole layer's evaluation recorded in `outcome` (the SQP counts are
/// added either way). `false`: the layer is not long enough to subsample,
/// or the subsample could not certify it (solve it whole).
///
/// The degree loop is the whole layer's
/// ([`degree_loop`](super::degree::degree_loop)), every degree certified
/// on every point before its objective and violation there decide whether
/// to raise it.
pub(super) fn solve(
    setup: &LayerSetup,
    problem: &LayerProblem,
    basis: &Basis,
    c0: &[f64],
    degrees: &Degrees,
    outcome: &mut BranchOutcome,
) -> bool {
    let n = setup.opts.subsample_points;
    let p = setup.points.len();
    if n == 0 || p <= 2 * n {
        return false;
    }
    let mut samples = Samples::new(setup.points, initial_samples(setup.points, n));
    match degree_loop(problem, &mut samples, basis, c0, degrees, setup, outcome) {
        Some((best, history)) if best.res.violation <= 0.0 => {
            record(setup, best, history, outcome);
            outcome.samples = Some(samples.idx.len());
            true
        }
        // infeasible at every degree, or not certified: the whole layer decides
        _ => false,
    }
}

/// The samples of a layer: their indices (increasing) and points.
struct Samples {
    idx: Vec<usize>,
    points: Vec<CellPoint>,
}

impl Samples {
    fn new(all: &[CellPoint], idx: Vec<usize>) -> Self {
        let points = gather(all, &idx);
        Samples { idx, points }
    }

    /// Adds the points `more`; `false` when they were all samples already.
    fn add(&mut self, all: &[CellPoint], more: &[usize]) -> bool {
        let before = self.idx.len();
        self.idx.extend_from_slice(more);
        self.idx.sort_unstable();
        self.idx.dedup();
        self.points = gather(all, &self.idx);
        self.idx.len() > before
    }
}

/// [`degree_loop`](super::degree::degree_loop) on the samples, each degree
/// certified on every point by [`certify`]. `None`: a degree could not be
/// certified (or the start has no joint solution on the samples).
fn degree_loop(
    problem: &LayerProblem,
    samples: &mut Samples,
    basis: &Basis,
    c0: &[f64],
    degrees: &Degrees,
    setup: &LayerSetup,
    counts: &mut BranchOutcome,
) -> Option<(Best, Vec<(usize, f64)>)> {
    let mut full_basis = basis.clone();
    let mut c = c0.to_vec();
    let scale = {
        let sub = problem.restricted(&samples.idx, &samples.points);
        let e0 = sub
            .evaluate(&full_basis.restricted(&samples.idx)?.eval(&c))
            .ok()?;
        sub.objective(&e0, 0.0).max(tol::OBJECTIVE_SCALE_FLOOR)
    };
    let mut history = Vec::new();
    let mut best: Option<Best> = None;
    let mut stalled = 0;
    // the previous degree's evaluations (samples, every point): where a
    // constraint holds the law, the raised degree's new coefficient stays 0
    // and its `R_Z` is the previous one to the bit, so neither is repeated
    let mut previous: Option<Evaluations> = None;
    for degree in degrees.start..=degrees.max.max(degrees.start) {
        let done = certify(
            problem,
            samples,
            &full_basis,
            c,
            scale,
            setup,
            counts,
            previous.take(),
        );
        let Some(done) = done else {
            // not certified: the whole layer decides
            return None;
        };
        let Certified {
            res,
            sub_eval,
            sub_c,
        } = done;
        c = sub_c;
        let whole = res.eval.clone();
        history.push((degree, res.objective));
        let gain = Best::offer(&mut best, degree, &c, &full_basis, res);
        stalled = if gain < degrees.stop_relative_gain {
            stalled + 1
        } else {
            0
        };
        let Some(raised) = full_basis.raised() else {
            break;
        };
        let sub = problem.restricted(&samples.idx, &samples.points);
        let last = Best::key(&best);
        let sub_raised = raised.restricted(&samples.idx)?;
        if stalled >= STALLED_DEGREES
            || !raise_again(
                &sub,
                Some(&sub_eval),
                &sub_raised,
                degree + 1,
                gain,
                degrees,
                last,
            )
        {
            break;
        }
        full_basis = raised;
        c.push(0.0);
        previous = Some(Evaluations {
            samples: sub_eval,
            whole,
        });
    }
    best.map(|b| (b, history))
}

/// A law's evaluations on the samples (as they were when it was certified)
/// and on every point, kept for the next degree's start.
struct Evaluations {
    samples: super::problem::Evaluation,
    whole: super::problem::Evaluation,
}

/// `e` when it was evaluated at exactly `r` (every value to the bit):
/// [`LayerProblem::evaluate`] is a function of `r` on a given problem, so
/// it stands for evaluating `r` again.
fn at_same_r(
    e: Option<super::problem::Evaluation>,
    r: &[f64],
) -> Option<super::problem::Evaluation> {
    e.filter(|e| e.r.len() == r.len() && e.r.iter().zip(r).all(|(a, b)| a.to_bits() == b.to_bits()))
}

/// One degree solved on the samples and certified on every point.
struct Certified {
    /// The law on every point: its evaluation, objective and violation
    /// (0 when certified, the largest violation of the SQP's bounds on
    /// every point when the samples could not make it feasible).
    res: sqp::SqpResult,
    /// The samples' evaluation at the law (the next degree's start).
    sub_eval: super::problem::Evaluation,
    /// The law's coefficients.
    sub_c: Vec<f64>,
}

/// Solves the law over `full_basis` on the samples from `c`, evaluates it on
/// every point, and while a point is past [`CERTIFY_TOLERANCE`] adds the
/// worst points to the samples and solves again. `None` when it cannot
/// tell: a point without joint solution, a joint representation on the
/// samples that is not the whole layer's, or no certificate after
/// [`MAX_ROUNDS`] refinements. A law the samples cannot make feasible is
/// returned with its violation on every point. `previous`: the previous
/// degree's evaluations, used in place of evaluating the same `R_Z` again
/// (on the same samples, which it was certified on).
#[allow(clippy::too_many_arguments)]
fn certify(
    problem: &LayerProblem,
    samples: &mut Samples,
    full_basis: &Basis,
    c: Vec<f64>,
    scale: f64,
    setup: &LayerSetup,
    counts: &mut BranchOutcome,
    previous: Option<Evaluations>,
) -> Option<Certified> {
    let mut c = c;
    let (mut last_samples, mut last_whole) = match previous {
        Some(l) => (Some(l.samples), Some(l.whole)),
        None => (None, None),
    };
    for round in 0..=MAX_ROUNDS {
        let sub = problem.restricted(&samples.idx, &samples.points);
        let sub_basis = full_basis.restricted(&samples.idx)?;
        // only the first round runs on the samples the last degree's were
        let start = at_same_r(last_samples.take(), &sub_basis.eval(&c));
        let res = sqp::solve(&sub, &sub_basis, c, start, 0.0, scale, &setup.opts.sqp).ok()?;
        counts.iterations += res.iterations;
        counts.qp_solves += res.qp_solves;
        counts.qp_failures += res.qp_failures;
        c = res.c.clone();
        let r = full_basis.eval(&c);
        let e = match at_same_r(last_whole.take(), &r) {
            Some(e) => e,
            None => problem.evaluate(&r).ok()?,
        };
        let same = samples.idx.iter().zip(&res.eval.q).all(|(&m, qs)| {
            e.q[m]
                .iter()
                .zip(qs)
                .all(|(a, b)| (a - b).abs() <= SAME_JOINTS_RAD)
        });
        if !same {
            return None;
        }
        let feasible_on_samples = res.violation <= 0.0;
        let mut worst = worst_points(problem, &e);
        let objective = problem.objective(&e, 0.0);
        if worst.is_empty() && feasible_on_samples && round < MAX_ROUNDS {
            // the samples' estimate of the objective must hold too: where
            // the joints move fast between two samples (a corner of the
            // path) the estimate misses it, and the law would be tuned to
            // the wrong objective
            worst = poorly_estimated(problem, &e, &samples.idx, objective);
            if !worst.is_empty() && samples.add(setup.points, &worst) {
                continue;
            }
            worst.clear();
        }
        if worst.is_empty() || !feasible_on_samples {
            let violation = if worst.is_empty() {
                0.0
            } else {
                problem.max_violation(&e).max(f64::MIN_POSITIVE)
            };
            return Some(Certified {
                res: sqp::SqpResult {
                    c: c.clone(),
                    eval: e,
                    objective,
                    violation,
                    iterations: res.iterations,
                    qp_solves: res.qp_solves,
                    qp_failures: res.qp_failures,
                    converged: res.converged,
                },
                sub_eval: res.eval,
                sub_c: c,
            });
        }
        if round == MAX_ROUNDS || !samples.add(setup.points, &worst) {
            return None;
        }
    }
    None
}

/// Share of the layer's objective by which the joint displacement of one
/// gap between samples may exceed its estimate `(Δq)² / L` before the
/// gap's fastest step joins the samples.
const GAP_ESTIMATE_TOLERANCE: f64 = 2e-3;

/// Gaps between samples held at most this many at a time.
const GAPS_PER_ROUND: usize = 16;

/// The points to add where the samples misjudge the joint displacement
/// (eq. 4.3) of the whole layer's evaluation `e` (objective `f`): in each
/// gap whose displacement exceeds its estimate by more than
/// [`GAP_ESTIMATE_TOLERANCE`]` · f` (the worst [`GAPS_PER_ROUND`]), the
/// step that moves the joints most (both its points).
fn poorly_estimated(
    problem: &LayerProblem,
    e: &super::problem::Evaluation,
    idx: &[usize],
    f: f64,
) -> Vec<usize> {
    if problem.objective != super::Objective::JointDisplacement || !(f > 0.0) {
        return Vec::new();
    }
    let step = |a: usize, b: usize| -> f64 {
        (0..6)
            .map(|j| problem.gamma[j] * (e.q[b][j] - e.q[a][j]).powi(2))
            .sum()
    };
    let mut bad: Vec<(f64, usize)> = Vec::new();
    for w in idx.windows(2) {
        let (a, b) = (w[0], w[1]);
        if b - a < 2 {
            continue;
        }
        let mut exact = 0.0;
        let mut fastest = (f64::NEG_INFINITY, b);
        for m in a + 1..=b {
            let d = step(m - 1, m);
            exact += d;
            if d > fastest.0 {
                fastest = (d, m);
            }
        }
        let excess = exact - step(a, b) / (b - a) as f64;
        if excess > GAP_ESTIMATE_TOLERANCE * f {
            bad.push((excess, fastest.1));
        }
    }
    bad.sort_by(|x, y| y.0.total_cmp(&x.0));
    bad.truncate(GAPS_PER_ROUND);
    bad.into_iter().flat_map(|(_, m)| [m - 1, m]).collect()
}

/// The points of `points` at `idx`.
fn gather(points: &[CellPoint], idx: &[usize]) -> Vec<CellPoint> {
    idx.iter().map(|&m| points[m]).collect()
}

/// The points to add after the whole layer's evaluation `e`: of every run
/// of successive points with a constraint past [`CERTIFY_TOLERANCE`], the
/// worst one and the one before it (a speed bound involves both).
fn worst_points(problem: &LayerProblem, e: &super::problem::Evaluation) -> Vec<usize> {
    let p = e.q.len();
    let mut worst = vec![f64::NEG_INFINITY; p];
    problem.constraints(e, false, false, &mut |m, _, v, _, _| {
        if v > worst[m] {
            worst[m] = v;
        }
    });
    let mut out = Vec::new();
    let mut run: Option<(usize, f64)> = None;
    for (m, &v) in worst.iter().enumerate() {
        if v > CERTIFY_TOLERANCE {
            if run.is_none_or(|(_, w)| v > w) {
                run = Some((m, v));
            }
        } else if let Some((k, _)) = run.take() {
            out.extend(k.checked_sub(1));
            out.push(k);
        }
    }
    if let Some((k, _)) = run {
        out.extend(k.checked_sub(1));
        out.push(k);
    }
    out
}

/// About `n` sample indices of a layer of `points` (first and last
/// included, increasing): equally spaced in a measure that is half the
/// point index and half the turning (rad) of the tool axis and build
/// direction along the layer, so that corners get more samples.
pub(super) fn initial_samples(points: &[CellPoint], n: usize) -> Vec<usize> {
    let p = points.len();
    let mut turn = vec![0.0; p];
    for m in 1..p {
        let (a, b) = (&points[m - 1], &points[m]);
        let mut t = a.tool_axis.angle(&b.tool_axis);
        if let (Some(x), Some(y)) = (a.build_direction, b.build_direction) {
            t += x.angle(&y);
        }
        turn[m] = turn[m - 1] + if t.is_finite() { t } else { 0.0 };
    }
    let total = turn[p - 1];
    let last = (p - 1) as f64;
    let u = |m: usize| {
        if total > MIN_TOTAL_TURN_RAD {
            0.5 * m as f64 / last + 0.5 * turn[m] / total
        } else {
            m as f64 / last
        }
    };
    let mut idx: Vec<usize> = Vec::with_capacity(n + 1);
    let mut m = 0;
    for k in 0..n {
        let target = k as f64 / (n - 1) as f64;
        while m < p - 1 && u(m) < target - QUANTILE_SLACK {
            m += 1;
        }
        if idx.last() != Some(&m) {
            idx.push(m);
        }
    }
    if idx.last() != Some(&(p - 1)) {
        idx.push(p - 1);
    }
    idx
}
