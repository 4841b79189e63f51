//! **Stage 6a — the positioner's laws: the starts and the law kept.** The
//! starts of a layer's law (the hold pose, the lazy follower, the thesis's
//! exact vertical, the arm's start, the pose grid's path; joints in rad),
//! each fitted on a spline, solved on samples grown with its worst points,
//! on knots uniform in the abscissa, then crowding where `b` turns; the best
//! law and the other feasible ones, best first.

use crate::math::{tol, UnitVector3, Vector3};
use crate::optimise::parameterisation::Basis;
use crate::robot::cell::{CellPoint, TorchCarriedCell};
use crate::robot::positioner::PositionerJoints;

use super::grid::{cheaply_proven, grid_path};
use super::outcome::PositionerSeed;
use super::problem::{check, objective, LawProblem};
use super::sqp::sqp;

/// The sum of the build directions (unit vectors) shorter than this has no
/// mean direction: no hold seed (unitless).
const MIN_BUILD_SUM: f64 = 1e-9;
/// A feasible seed whose objective is at most this (objective units) cannot
/// be beaten: the remaining seeds are skipped.
const ZERO_OBJECTIVE: f64 = 1e-14;
/// A violation left on the samples above this (constraint units) means
/// the SQP is stuck: more samples cannot help.
const STUCK_VIOLATION: f64 = 1e-9;

/// Two laws within this of each other at every point (rad, each axis) are
/// the same law (an alternative is kept once).
const SAME_LAW_RAD: f64 = 1e-6;

/// Laws whose violations of the arm's rows differ by less than this are
/// ranked by their objective (rad).
const ARM_TIE_RAD: f64 = 1e-4;

/// Feasible laws whose objectives are within this fraction of the lowest
/// (relative), plus [`OBJECTIVE_TIE_ABS`], are a tie, kept in the order
/// solved ([`kept`]).
const OBJECTIVE_TIE_REL: f64 = 1e-3;
/// The absolute part of a tie (objective units, rad²): the laws of a
/// straight leg's layer end at 1e-11–1e-6, where the starts differ by
/// nothing an axis could show.
const OBJECTIVE_TIE_ABS: f64 = 1e-9;

/// The thesis's positioner joints turning every point's `b` exactly
/// vertical, the turn continued from `q8_hint` (rad); `None` where a point
/// cannot be turned vertical.
pub fn vertical_joints(
    cell: &TorchCarriedCell,
    points: &[CellPoint],
    q8_hint: f64,
) -> Option<Vec<PositionerJoints>> {
    let mut hint = q8_hint;
    points
        .iter()
        .map(|p| {
            let cp = CellPoint {
                positioner: None,
                ..*p
            };
            let q = cell.positioner_angles(&cp, hint).ok()?;
            hint = q[1];
            Some(q)
        })
        .collect()
}

/// The lazy follower's joints: the positioner holds its pose while `b`
/// stays within `hold_rad` of the vertical, and otherwise moves just enough to
/// bring it back to `hold_rad`, leaning the way it leans (the pose turning
/// `b` onto that leaning direction, the turn nearest the last). Smooth
/// through the pole, where the exact vertical spins. `None` where no pose
/// is found.
fn lazy_joints(
    pb: &LawProblem,
    start: PositionerJoints,
    hold_rad: f64,
) -> Option<Vec<PositionerJoints>> {
    let r0t = pb.r0.transpose();
    let mut q = start;
    let mut out = Vec::with_capacity(pb.b.len());
    for m in 0..pb.b.len() {
        let b_w = pb.world(m, &q).b[0];
        let tilt = b_w.xy().norm().atan2(b_w.z);
        if tilt > hold_rad {
            // the world direction at hold_rad from the vertical, towards b_w
            let h = b_w.xy().normalize();
            let target = Vector3::new(h.x * hold_rad.sin(), h.y * hold_rad.sin(), hold_rad.cos());
            let up = UnitVector3::new_normalize(r0t * target);
            let b = UnitVector3::try_new(pb.b[m], tol::DEGENERATE)?;
            q = pb
                .cell
                .positioner
                .angles_for_vertical(&b, &up, q[1], 0.5 * hold_rad)
                .ok()?;
        }
        out.push(q);
    }
    Some(out)
}

/// Share of the spline's abscissa given to the turning of `b` (unitless):
/// the knots, uniform in the blended abscissa, crowd where `b` turns fast.
const TURNING_SHARE: f64 = 0.5;

/// The spline's abscissa: `x` (point index or cylindrical angle) scaled to
/// `[0, 1]`, blended with the cumulative angle `b` turns through along the
/// layer, also scaled to `[0, 1]` ([`TURNING_SHARE`] of it). A bent tube's
/// layer turns `b` through most of its swing in a few points (a corner of the
/// constant-distance layer); uniform knots in the point index leave those few
/// points one span, too stiff for the table to follow `b` there. On a part
/// of revolution `b` turns evenly with the angle and nothing changes.
fn following_turning(x: &[f64], b: &[Vector3]) -> Vec<f64> {
    let n = x.len();
    let span = x[n - 1] - x[0];
    let mut turned = Vec::with_capacity(n);
    let mut sum = 0.0;
    for m in 0..n {
        if m > 0 {
            sum += b[m - 1].angle(&b[m]);
        }
        turned.push(sum);
    }
    if !(span.abs() > 0.0 && sum > tol::DEGENERATE) {
        return x.to_vec();
    }
    (0..n)
        .map(|m| (1.0 - TURNING_SHARE) * (x[m] - x[0]) / span + TURNING_SHARE * turned[m] / sum)
        .collect()
}

/// The law of a layer's starts ([`solve_seeds`]): on knots uniform in
/// `abscissa` first; where that law fails, on knots crowding where `b`
/// turns ([`following_turning`]), the better kept; where neither keeps the
/// cone (a corner of `b`), the thesis's exact vertical `vertical` when it
/// breaks no constraint (an unlimited positioner), so that the arm is judged
/// on it. Returns the best law and the other feasible ones, best first
/// (the exact vertical first when it is not the best).
#[allow(clippy::too_many_arguments)]
pub(super) fn solve_bases(
    pb: &LawProblem,
    abscissa: &[f64],
    follow: Option<&[PositionerJoints]>,
    vertical: Option<&[PositionerJoints]>,
    start: Option<&[PositionerJoints]>,
    q8_hint: f64,
    iterations: &mut usize,
) -> (Solved, Vec<Solved>) {
    let n = pb.b.len();
    let spans = pb.opts.spans.min(n / 4).max(1);
    let mut all = solve_seeds(
        pb,
        &Basis::spline(abscissa, spans),
        follow,
        start,
        q8_hint,
        iterations,
    );
    if !all.iter().any(|s| s.feasible) {
        all.extend(solve_seeds(
            pb,
            &Basis::spline(&following_turning(abscissa, &pb.b), spans),
            follow,
            start,
            q8_hint,
            iterations,
        ));
    }
    // a layer whose b passes the pole and swings far off it, or turns a
    // corner: the smooth starts may all fall into a local minimum; a path
    // over a grid of poses, fitted, on either knot set, else the path
    // itself where it keeps every constraint; not where the cheap proofs
    // already show no path exists
    if !all.iter().any(|s| s.feasible) && !cheaply_proven(pb) {
        if let Some(path) = grid_path(pb) {
            for basis in [
                Basis::spline(abscissa, spans),
                Basis::spline(&following_turning(abscissa, &pb.b), spans),
            ] {
                let x0 = fitted_on(&basis, &path);
                let solved = solve_starts(pb, &basis, vec![(PositionerSeed::Grid, x0)], iterations);
                let feasible = solved.iter().any(|s| s.feasible);
                all.extend(solved);
                if feasible {
                    break;
                }
            }
            if !all.iter().any(|s| s.feasible) && check(pb, &path).binding.is_none() {
                all.push(Solved::unfitted(pb, path, PositionerSeed::Grid));
            }
        }
    }
    // the thesis's exact vertical, unfitted, where it breaks no constraint
    // (an unlimited positioner): the law where no smooth one keeps the cone
    // (a corner of b), else the first alternative (the arm may follow it
    // where it cannot follow the smooth laws)
    let mut vertical = vertical
        .filter(|f| check(pb, f).binding.is_none())
        .map(|f| Solved::unfitted(pb, f.to_vec(), PositionerSeed::Vertical));
    if !all.iter().any(|s| s.feasible) {
        all.extend(vertical.take());
    }
    let best = all.remove(kept(&all, true));
    // the other feasible laws, best first (ties in the order solved), each once
    all.retain(|s| s.feasible);
    let mut others: Vec<Solved> = Vec::new();
    while !all.is_empty() {
        let s = all.remove(kept(&all, false));
        let same = |o: &Solved| {
            o.joints.iter().zip(&s.joints).all(|(a, b)| {
                (a[0] - b[0]).abs() <= SAME_LAW_RAD && (a[1] - b[1]).abs() <= SAME_LAW_RAD
            })
        };
        if !same(&best) && !others.iter().any(same) {
            others.push(s);
        }
    }
    if let Some(v) = vertical {
        others.insert(0, v);
    }
    (best, others)
}

/// One start's law on one basis.
pub(super) struct Solved {
    pub(super) feasible: bool,
    /// The worst violation left (constraint units scaled to rad; 0 feasible).
    pub(super) violation: f64,
    /// The worst violation of the arm's rows (rad; 0 without rows).
    pub(super) arm: f64,
    /// `½|r|²` over every point.
    pub(super) objective: f64,
    pub(super) seed: PositionerSeed,
    pub(super) joints: Vec<PositionerJoints>,
    pub(super) samples: usize,
}

impl Solved {
    /// A law given per point, unfitted, that keeps every constraint.
    fn unfitted(pb: &LawProblem, joints: Vec<PositionerJoints>, seed: PositionerSeed) -> Self {
        Solved {
            feasible: true,
            violation: 0.0,
            arm: pb.arm_violation(&joints),
            objective: objective(pb, &joints),
            seed,
            samples: joints.len(),
            joints,
        }
    }
}

/// The law kept of `laws` (in the order solved; not empty): the feasible
/// ones first, of those the ones that break the arm's rows least (within
/// [`ARM_TIE_RAD`], where `arm`), of those the lowest objective, a tie
/// within [`OBJECTIVE_TIE_REL`] going to the one solved first; with no
/// feasible law, the least violation. Laws at near-equal objectives are
/// alike to the axes, and which one comes out lowest is up to the QPs'
/// tolerances: the fixed rule keeps the same one whichever solver.
fn kept(laws: &[Solved], arm: bool) -> usize {
    let feasible = laws.iter().any(|s| s.feasible);
    if !feasible {
        let mut best = 0;
        for (i, s) in laws.iter().enumerate() {
            if s.violation < laws[best].violation {
                best = i;
            }
        }
        return best;
    }
    let least_arm = laws
        .iter()
        .filter(|s| s.feasible)
        .map(|s| s.arm)
        .fold(f64::INFINITY, f64::min);
    let candidate = |s: &Solved| s.feasible && (!arm || s.arm <= least_arm + ARM_TIE_RAD);
    let lowest = laws
        .iter()
        .filter(|s| candidate(s))
        .map(|s| s.objective)
        .fold(f64::INFINITY, f64::min);
    let tie = lowest + OBJECTIVE_TIE_REL * lowest.abs() + OBJECTIVE_TIE_ABS;
    laws.iter()
        .position(|s| candidate(s) && s.objective <= tie)
        .unwrap_or(0)
}

/// The starts of [`positioner_law`](super::positioner_law) (the exact vertical `follow` fitted,
/// the lazy follower fitted, the hold pose) solved on `basis`, each on
/// samples grown with its worst points; every start's law returned (the
/// hold pose always), in the order solved. `iterations` counts the SQP
/// iterations.
fn solve_seeds(
    pb: &LawProblem,
    basis: &Basis,
    follow: Option<&[PositionerJoints]>,
    arm_start: Option<&[PositionerJoints]>,
    q8_hint: f64,
    iterations: &mut usize,
) -> Vec<Solved> {
    // the hold seed: the pose turning the mean b vertical
    let mean_b = pb.b.iter().fold(Vector3::zeros(), |a, b| a + b);
    let hold = UnitVector3::try_new(mean_b, MIN_BUILD_SUM)
        .and_then(|b| {
            let up = pb.cell.base_from_positioner.rotation.inverse() * Vector3::z_axis();
            pb.cell
                .positioner
                .angles_for_vertical(&b, &up, q8_hint, std::f64::consts::PI)
                .ok()
        })
        .unwrap_or([0.0, q8_hint]);
    let k = basis.len();
    let fitted = |q: &[PositionerJoints]| fitted_on(basis, q);
    let mut seeds: Vec<(PositionerSeed, Vec<f64>)> = Vec::new();
    let mut x_hold = vec![0.0; 2 * k];
    x_hold[0] = hold[0];
    x_hold[k] = hold[1];
    seeds.push((PositionerSeed::Hold, x_hold));
    let start = follow.and_then(|f| f.first().copied()).unwrap_or(hold);
    if let Some(l) = lazy_joints(pb, start, 0.7 * pb.cone) {
        seeds.push((PositionerSeed::Lazy, fitted(&l)));
    }
    if let Some(f) = follow {
        seeds.push((PositionerSeed::Follow, fitted(f)));
    }
    // the thesis's follower first: on a part of revolution it is exact and
    // costs nothing, and no other seed can do better than nothing
    seeds.reverse();
    if let Some(s) = arm_start {
        seeds.insert(0, (PositionerSeed::Arm, fitted(s)));
    }
    solve_starts(pb, basis, seeds, iterations)
}

/// Joints `q` (rad per point) fitted on `basis`: `[c7; c8]`.
fn fitted_on(basis: &Basis, q: &[PositionerJoints]) -> Vec<f64> {
    let c7 = basis.fit(&q.iter().map(|q| q[0]).collect::<Vec<_>>());
    let c8 = basis.fit(&q.iter().map(|q| q[1]).collect::<Vec<_>>());
    [c7, c8].concat()
}

/// Each start `seeds` (coefficients on `basis`) solved on samples grown
/// with its worst points, in order, until one keeps every constraint at no
/// cost.
fn solve_starts(
    pb: &LawProblem,
    basis: &Basis,
    seeds: Vec<(PositionerSeed, Vec<f64>)>,
    iterations: &mut usize,
) -> Vec<Solved> {
    let n = pb.b.len();
    let k = basis.len();
    let mut solved_all: Vec<Solved> = Vec::new();
    let target = pb.opts.sample_points.min(n);
    for (seed, x0) in seeds {
        if solved_all
            .iter()
            .any(|b| b.feasible && b.objective <= ZERO_OBJECTIVE)
        {
            break;
        }
        let mut idx: Vec<usize> = (0..target)
            .map(|i| {
                if target <= 1 {
                    0
                } else {
                    (i * (n - 1) + (target - 1) / 2) / (target - 1)
                }
            })
            .collect();
        // the arm's rows' points are always sampled
        idx.extend(pb.arm.iter().map(|a| a.point).filter(|&m| m < n));
        idx.sort_unstable();
        idx.dedup();
        let mut x = x0;
        let mut joints = Vec::new();
        let mut chk = None;
        for _round in 0..4 {
            let (xs, it, left) = sqp(pb, basis, &idx, x);
            *iterations += it;
            x = xs;
            // violated on the samples already: more samples cannot help
            let stuck = left > STUCK_VIOLATION;
            let (c7, c8) = x.split_at(k);
            let (q7, q8) = (basis.eval(c7), basis.eval(c8));
            joints = q7.into_iter().zip(q8).map(|(a, b)| [a, b]).collect();
            let c = check(pb, &joints);
            let done = stuck
                || c.binding.is_none()
                || c.worst.iter().all(|m| idx.binary_search(m).is_ok());
            let add = c.worst.clone();
            chk = Some(c);
            if done {
                break;
            }
            for m in add {
                if let Err(pos) = idx.binary_search(&m) {
                    idx.insert(pos, m);
                }
                if m > 0 {
                    if let Err(pos) = idx.binary_search(&(m - 1)) {
                        idx.insert(pos, m - 1);
                    }
                }
            }
        }
        let c = chk.expect("at least one round");
        let solved = Solved {
            feasible: c.binding.is_none(),
            violation: c.binding.map_or(0.0, |(v, _)| v),
            arm: pb.arm_violation(&joints),
            objective: objective(pb, &joints),
            seed,
            joints,
            samples: idx.len(),
        };
        solved_all.push(solved);
    }
    solved_all
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The spline's abscissa: unchanged where `b` turns evenly along the
    /// layer; where `b` turns through all of its swing between two points
    /// (a corner), half the abscissa is spent there.
    #[test]
    fn the_knots_crowd_where_b_turns() {
        let n = 11;
        let x: Vec<f64> = (0..n).map(|m| m as f64).collect();
        let even: Vec<Vector3> = (0..n)
            .map(|m| {
                let a = (3.0 * m as f64).to_radians();
                Vector3::new(a.sin(), 0.0, a.cos())
            })
            .collect();
        for (m, s) in following_turning(&x, &even).iter().enumerate() {
            approx::assert_relative_eq!(*s, m as f64 / 10.0, epsilon = 1e-12);
        }
        let corner: Vec<Vector3> = (0..n)
            .map(|m| if m < 5 { Vector3::z() } else { Vector3::x() })
            .collect();
        let s = following_turning(&x, &corner);
        approx::assert_relative_eq!(s[5] - s[4], 0.5 + 0.05, epsilon = 1e-12);
        approx::assert_relative_eq!(s[4] - s[3], 0.05, epsilon = 1e-12);
        approx::assert_relative_eq!(s[10], 1.0, epsilon = 1e-12);
        // b that does not turn: the abscissa as given
        assert_eq!(following_turning(&x, &vec![Vector3::z(); n]), x);
    }
}
