//! **Stage 6a — the positioner's laws: their SQP.** Gauss–Newton steps on
//! the law's spline coefficients (rad per unit basis value) within a trust
//! region, each an elastic QP of the `R_Z` driver's (so an infeasible law
//! ends at its least violation), accepted on an l∞ merit. Not the `R_Z`
//! driver's SQP: no secant correction, no ratio test, no polish.

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
        let Some(qp) = solve_qp(&p, &g, &model.rows, rho, bound) else {
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
        }
        // the layers exercise binding rows and the elastic variable
        assert!(compared >= 20, "{compared} QPs");
        assert!(binding >= 5, "{binding} QPs with a binding row");
        assert!(elastic >= 1, "{elastic} QPs with t > 0");
    }
}
