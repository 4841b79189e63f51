//! The thesis's point-by-point baseline [SPEC §7; thesis §4.1.4]: `R_Z`
//! chosen one point after the other by a local 1-D search, each point's
//! constraints penalised.

use std::f64::consts::PI;

use super::problem::{Evaluation, LayerProblem, PointFailure};
use crate::robot::model::Joints;

/// Bracket width (rad) at which the one-point `R_Z` line search stops.
const LINE_SEARCH_TOL_RAD: f64 = 1e-7;

/// Point by point: every constraint is penalised from `PBP_MARGIN` inside
/// its bound (rad, rad per step, or relative for the dexterity), so that the
/// 1-D search's tolerance (1e-7 rad) cannot leave a point a hair outside.
const PBP_MARGIN: f64 = 1e-6;

/// The thesis's point-by-point baseline [§4.1.4]: point 0 minimises the
/// centring term, each next point the weighted displacement from the
/// previous point, each under that point's constraints (penalised), by a
/// local 1-D search started from the previous point's `R_Z`.
pub(super) fn point_by_point(
    problem: &LayerProblem,
    r0: f64,
    held: Option<f64>,
) -> Result<Evaluation, PointFailure> {
    let p = problem.points.len();
    let robot = problem.cell.robot();
    let rho = 1e3;
    let mut r = vec![0.0; p];
    let mut prev: Option<Joints> = problem.start_near;
    let mut q8 = 0.0;
    for m in 0..p {
        let f = |x: f64| -> f64 {
            let Ok((q, _)) = problem.joints_at(m, x, prev.as_ref(), q8) else {
                return f64::INFINITY;
            };
            // point 0 (no previous joints) minimises the centring term
            let mut obj = match prev {
                Some(_) => 0.0,
                None => problem.centring_of(&q),
            };
            let mut viol: f64 = 0.0;
            for j in 0..6 {
                let (lo, hi) = problem.joint_bounds(j, &q);
                viol = viol.max(q[j] - hi + PBP_MARGIN).max(lo - q[j] + PBP_MARGIN);
                if let Some(qp) = prev {
                    obj += problem.gamma[j] * (q[j] - qp[j]).powi(2);
                    if problem.dt[m] > 0.0 {
                        viol = viol.max(
                            (q[j] - qp[j]).abs() - problem.max_speed[j] * problem.dt[m]
                                + PBP_MARGIN,
                        );
                    }
                }
            }
            if let Some(h) = problem.hose {
                viol = viol.max((q[3] + q[5]).abs() - h + PBP_MARGIN);
            }
            if problem.psi[m] > 0.0 {
                let d = crate::robot::indices::dexterity(&robot.jacobian(&q), problem.dex_scale);
                viol = viol.max((problem.psi[m] - d) / problem.psi[m] + PBP_MARGIN);
            }
            obj + rho * viol
        };
        let start = match m {
            0 => r0,
            1 => r[0],
            _ => 2.0 * r[m - 1] - r[m - 2],
        };
        let x = match held {
            Some(h) if m == 0 => h,
            _ => minimise_1d(&f, start, 0.02, LINE_SEARCH_TOL_RAD),
        };
        r[m] = x;
        let (q, pose) = problem
            .joints_at(m, x, prev.as_ref(), q8)
            .map_err(|error| PointFailure { point: m, error })?;
        if let Some(qp) = pose.positioner {
            q8 = qp[1];
        }
        prev = Some(q);
    }
    problem.evaluate(&r)
}

/// Local 1-D minimisation: downhill bracketing from `x0` with step `h`
/// (doubling), then golden-section search to `tol`.
fn minimise_1d(f: &dyn Fn(f64) -> f64, x0: f64, h: f64, tol: f64) -> f64 {
    let f0 = f(x0);
    let (fp, fm) = (f(x0 + h), f(x0 - h));
    if !(fp < f0) && !(fm < f0) {
        return golden(f, x0 - h, x0 + h, tol);
    }
    let dir = if fp < fm { 1.0 } else { -1.0 };
    let (mut a, mut b, mut fb) = (x0, x0 + dir * h, fp.min(fm));
    let mut step = h;
    for _ in 0..40 {
        step *= 2.0;
        let c = b + dir * step;
        let fc = f(c);
        if !(fc < fb) {
            return golden(f, a.min(c), a.max(c), tol);
        }
        a = b;
        b = c;
        fb = fc;
        if (b - x0).abs() > PI {
            break;
        }
    }
    b
}

fn golden(f: &dyn Fn(f64) -> f64, mut a: f64, mut b: f64, tol: f64) -> f64 {
    let g = 0.5 * (5f64.sqrt() - 1.0);
    let mut c = b - g * (b - a);
    let mut d = a + g * (b - a);
    let (mut fc, mut fd) = (f(c), f(d));
    while (b - a).abs() > tol {
        if fc < fd {
            b = d;
            d = c;
            fd = fc;
            c = b - g * (b - a);
            fc = f(c);
        } else {
            a = c;
            c = d;
            fc = fd;
            d = a + g * (b - a);
            fd = f(d);
        }
    }
    0.5 * (a + b)
}
