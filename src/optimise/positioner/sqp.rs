//! **Stage 6a — the positioner's laws: their SQP.** Gauss–Newton steps on
//! the law's spline coefficients (rad per unit basis value) within a trust
//! region, each an elastic QP of the `R_Z` driver's (so an infeasible law
//! ends at its least violation), accepted on an l∞ merit by the ratio of
//! its actual to its predicted decrease, which also sizes the trust region
//! (as the `R_Z` driver's). Stops where the model predicts no decrease
//! worth a step, the step or the gain is below tolerance, or an infeasible
//! run's violation no longer falls. Not the `R_Z` driver's SQP: no secant
//! correction, no polish.

use crate::optimise::parameterisation::Basis;
use crate::optimise::qp::{solve_qp, Qp, QpMethod, Row};

use super::options::PositionerQp;
use super::problem::{build_model, LawProblem, Model};

/// Ridge added to the positioner SQP's Gauss–Newton matrix, relative to its
/// mean diagonal (relative).
const RIDGE_REL: f64 = 1e-9;
/// Floor of the mean diagonal the ridge scales with (units of `JᵀJ`).
const RIDGE_TRACE_FLOOR: f64 = 1e-12;
/// Trust bound on the positioner joints' coefficients (rad) below which the
/// SQP stops.
const MIN_TRUST_RAD: f64 = 1e-9;
/// A QP step whose largest coefficient change is below this (rad; a spline's
/// weights sum to 1, so no axis moves more) ends the SQP: converged.
const MIN_STEP_RAD: f64 = 1e-7;
/// A trial is accepted when the merit falls by at least this fraction of the
/// model's predicted decrease (unitless, the trust-region ratio).
const ACCEPT_RATIO: f64 = 1e-4;
/// The SQP stops when the model predicts a decrease of the merit below this
/// fraction of `1 + merit` (as the `R_Z` driver's relative tolerance; the
/// laws' merits are 1e-6–1e-2 rad², so about an absolute 1e-9 rad²):
/// converged, feasible or at the least violation. Measured on the elbow
/// in the ROBOWAM torch-carried cell: the law of a straight leg's layer,
/// where the turn is nearly free, otherwise wanders along the turn for
/// gains of 1e-9 of a merit of 1e-6.
const PREDICTED_REL: f64 = 1e-9;
/// An accepted gain below this fraction of `1 + merit` is flat: the SQP
/// stops.
const FLAT_GAIN_REL: f64 = 1e-9;
/// Iterations over which an infeasible run must lower its violation by
/// [`STALL_FALL`], or stop at its least violation.
const STALL_WINDOW: usize = 5;
/// Relative fall of the violation an infeasible run must make every
/// [`STALL_WINDOW`] iterations (unitless).
const STALL_FALL: f64 = 0.1;
/// Floor of the merit the QP is scaled by (merit units).
const QP_SCALE_FLOOR: f64 = 1e-12;
/// Weight of the violation in the l∞ merit (merit units per constraint unit).
const RHO: f64 = 1e2;

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
    let method = match pb.opts.qp {
        PositionerQp::Clarabel => QpMethod::Clarabel,
        PositionerQp::Dense => QpMethod::Dense,
    };
    sqp_using(pb, basis, idx, x0, &mut |p, g, rows, rho, bound| {
        solve_qp(g.len(), p, g, rows, rho, bound, method)
    })
}

/// The elastic QP `(P, g, rows, ρ, box)` of one SQP iteration, solved.
type QpSolve<'s> = dyn FnMut(&[f64], &[f64], &[Row], f64, f64) -> Option<Qp> + 's;

/// [`sqp`] with its QPs solved by `solve_qp`.
fn sqp_using(
    pb: &LawProblem,
    basis: &Basis,
    idx: &[usize],
    x0: Vec<f64>,
    solve_qp: &mut QpSolve,
) -> (Vec<f64>, usize, f64) {
    let n = x0.len();
    let rho = RHO;
    let mut x = x0;
    let mut model = build_model(pb, basis, idx, &x, true);
    let mut cur = merit(&model, rho);
    let mut bound = 0.3 / basis.row_l1_bound();
    let mut iterations = 0;
    // the violation at the last check of an infeasible run's progress
    let mut checked_violation = model.violation;
    for it in 0..pb.opts.max_iterations {
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
        // the QP scaled to a merit of 1: its solvers' tolerances are
        // absolute in part (clarabel's duality gap 1e-8), and the laws'
        // merits are 1e-6–1e-2 rad², where a gap of 1e-8 left clarabel's
        // step at half the model's decrease (the general tube's first
        // layer in the ROBOWAM cell)
        let s = 1.0 / cur.max(QP_SCALE_FLOOR);
        let (ps, gs): (Vec<f64>, Vec<f64>) = (
            p.iter().map(|v| v * s).collect(),
            g.iter().map(|v| v * s).collect(),
        );
        let Some(qp) = solve_qp(&ps, &gs, &model.rows, s * rho, bound) else {
            bound *= 0.25;
            if bound < MIN_TRUST_RAD {
                break;
            }
            continue;
        };
        // the model's decrease of the merit: −(gᵀδ + ½δᵀPδ) + ρ(v − t)
        let mut quad = 0.0;
        for i in 0..n {
            quad += g[i] * qp.x[i]
                + 0.5 * qp.x[i] * (0..n).map(|j| p[i * n + j] * qp.x[j]).sum::<f64>();
        }
        // (the step's own linearised violation, not the QP's `t`: an
        // interior point leaves `t` a hair above 0 where every row holds)
        let left = model
            .rows
            .iter()
            .zip(&model.merit_slack)
            .map(|(r, s)| r.a.iter().map(|&(i, v)| v * qp.x[i]).sum::<f64>() - r.b - s)
            .fold(0.0f64, f64::max);
        let predicted = -quad + rho * (model.violation - left);
        let step = qp.x.iter().fold(0.0f64, |a, v| a.max(v.abs()));
        let scale = 1.0 + cur.abs();
        if !(predicted > PREDICTED_REL * scale) || step < MIN_STEP_RAD {
            break;
        }
        let trial: Vec<f64> = x.iter().zip(&qp.x).map(|(a, d)| a + d).collect();
        let tm = build_model(pb, basis, idx, &trial, true);
        let new = merit(&tm, rho);
        let ratio = (cur - new) / predicted;
        if new.is_finite() && ratio >= ACCEPT_RATIO {
            let gain = cur - new;
            x = trial;
            model = tm;
            cur = new;
            if ratio > 0.75 && step > 0.9 * bound {
                bound *= 2.0;
            } else if ratio < 0.25 {
                bound = 0.5 * step;
            }
            // flat: a relative gain this small moves no axis by a
            // measurable amount (feasible or at the least violation)
            if gain < FLAT_GAIN_REL * (1.0 + cur.abs()) {
                break;
            }
        } else {
            bound = 0.25 * step.min(bound);
            if bound < MIN_TRUST_RAD {
                break;
            }
        }
        // an infeasible run whose violation no longer falls: stuck at its
        // least violation (the samples' law is kept as it is)
        if (it + 1) % STALL_WINDOW == 0 {
            if model.violation > 0.0 && model.violation > (1.0 - STALL_FALL) * checked_violation {
                break;
            }
            checked_violation = model.violation;
        }
    }
    (x, iterations, model.violation)
}

#[cfg(test)]
mod tests {
    use super::super::options::PositionerOptions;
    use super::super::tests::sample_cell;
    use super::*;
    use crate::math::{Point3, UnitVector3, Vector3};
    use crate::optimise::qp::{solve_qp_clarabel, solve_qp_dense};
    use crate::robot::cell::CellPoint;

    /// `½ xᵀPx + gᵀx + ρt` of a QP's solution, and its largest row
    /// violation `a·x − t − b` (at most 0 when every row holds).
    fn qp_value(p: &[f64], g: &[f64], rows: &[Row], rho: f64, qp: &Qp) -> (f64, f64) {
        let k = g.len();
        let x = &qp.x;
        let mut f = rho * qp.t;
        for i in 0..k {
            f += g[i] * x[i] + 0.5 * x[i] * (0..k).map(|j| p[i * k + j] * x[j]).sum::<f64>();
        }
        let worst = rows
            .iter()
            .map(|r| r.a.iter().map(|&(i, v)| v * x[i]).sum::<f64>() - qp.t - r.b)
            .fold(f64::NEG_INFINITY, f64::max);
        (f, worst)
    }

    /// The dense interior point against clarabel on every QP the law's SQP
    /// meets on a bent layer of the ROBOWAM torch-carried cell: `b` swings
    /// ±`swing_deg` about the table normal while the cone is 15°, with
    /// rows binding (the cone, the speeds) and, where the swing is too fast
    /// for the axes, the elastic variable `t` taking the rest. On each QP,
    /// with all its rows, both solvers' optima have the same value and keep
    /// the rows and the box alike (to their tolerances); the SQP follows
    /// clarabel's steps.
    #[test]
    fn the_dense_qp_solves_the_laws_qps_as_clarabel_does() {
        let cell = sample_cell("robowam_torch_carried.toml");
        let (mut compared, mut binding, mut elastic) = (0, 0, 0);
        for (swing_deg, speed) in [(25.0, 6.0), (40.0, 6.0), (60.0, 60.0)] {
            let n = 160;
            let points: Vec<CellPoint> = (0..n)
                .map(|m| {
                    let v = std::f64::consts::TAU * m as f64 / n as f64;
                    let a = f64::to_radians(swing_deg) * (3.0 * v).sin();
                    let b = Vector3::new(a.sin() * v.cos(), a.sin() * v.sin(), a.cos());
                    CellPoint {
                        position_mm: Point3::new(80.0 * v.cos(), 50.0 * v.sin(), 30.0),
                        tool_axis: UnitVector3::new_normalize(b),
                        build_direction: Some(UnitVector3::new_normalize(b)),
                        positioner: None,
                        travel_speed_mm_s: speed,
                    }
                })
                .collect();
            let opts = PositionerOptions::default();
            let pb = LawProblem::new(&cell, &points, 0.0, &opts, &[]);
            let x: Vec<f64> = (0..n).map(|m| m as f64).collect();
            let basis = Basis::spline(&x, opts.spans);
            let k = basis.len();
            let idx: Vec<usize> = (0..n).step_by(2).collect();
            let mut x0 = vec![0.0; 2 * k];
            x0[k] = 0.5;
            let (_, iterations, _) =
                sqp_using(&pb, &basis, &idx, x0, &mut |p, g, rows, rho, bound| {
                    let all: Vec<&Row> = rows.iter().collect();
                    let reference = solve_qp_clarabel(g.len(), p, g, &all, rho, bound)?;
                    let dense = solve_qp_dense(g.len(), p, g, &all, rho, bound)
                        .expect("the dense QP converges where clarabel does");
                    let (fr, vr) = qp_value(p, g, rows, rho, &reference);
                    let (fd, vd) = qp_value(p, g, rows, rho, &dense);
                    let scale = 1.0 + fr.abs();
                    assert!(
                        (fd - fr).abs() <= 1e-6 * scale,
                        "objective {fd} against clarabel's {fr}"
                    );
                    assert!(vd <= 1e-7 && vr <= 1e-7, "rows broken by {vd}, {vr}");
                    assert!(dense
                        .x
                        .iter()
                        .all(|v| v.abs() <= bound * (1.0 + 1e-7) + 1e-12));
                    assert!((dense.t - reference.t).abs() <= 1e-6 * (1.0 + reference.t));
                    compared += 1;
                    if vr > -1e-9 {
                        binding += 1;
                    }
                    if reference.t > 1e-6 {
                        elastic += 1;
                    }
                    Some(reference)
                });
            // a work count: converged, or stopped at its least violation
            // (the 60° swing), well before the cap of 25 (5 each when
            // written)
            assert!(
                iterations <= 10,
                "swing {swing_deg}°: {iterations} iterations"
            );
        }
        // the layers exercise binding rows and the elastic variable
        assert!(compared >= 10, "{compared} QPs");
        assert!(binding >= 5, "{binding} QPs with a binding row");
        assert!(elastic >= 1, "{elastic} QPs with t > 0");
    }
}
