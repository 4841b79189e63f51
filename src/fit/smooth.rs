//! **The smoothing fit**: values at stations fitted in least squares by a
//! natural cubic spline with given knots — the same spline the part files'
//! `spline` guide interpolates (zero second derivative at both ends), so that
//! the fitted values at the knots, written as guide points or as a piecewise
//! cubic radius law, reproduce the fitted curve exactly. A small penalty on
//! the second differences keeps knot intervals without data determined.
//! Solved by nalgebra's Cholesky factorisation of the normal equations.

use crate::math::{Point3, Vector3};
use nalgebra::{DMatrix, DVector};

/// Second derivatives of the natural cubic spline through `(knots, values)`.
/// `knots` strictly increasing, at least 2.
pub fn natural_second_derivatives(knots: &[f64], values: &[f64]) -> Vec<f64> {
    let n = knots.len();
    let mut m = vec![0.0; n];
    if n < 3 {
        return m;
    }
    let h: Vec<f64> = knots.windows(2).map(|w| w[1] - w[0]).collect();
    // Thomas algorithm on rows 1..n-1 (natural ends: m_0 = m_{n-1} = 0).
    let mut c = vec![0.0; n];
    let mut d = vec![0.0; n];
    for i in 1..n - 1 {
        let rhs =
            6.0 * ((values[i + 1] - values[i]) / h[i] - (values[i] - values[i - 1]) / h[i - 1]);
        let a = if i == 1 { 0.0 } else { h[i - 1] };
        let diag = 2.0 * (h[i - 1] + h[i]) - a * c[i - 1];
        c[i] = if i + 1 < n - 1 { h[i] / diag } else { 0.0 };
        d[i] = (rhs - a * d[i - 1]) / diag;
    }
    for i in (1..n - 1).rev() {
        m[i] = d[i] - c[i] * m[i + 1];
    }
    m
}

/// Index of the knot interval holding `t` (clamped to the end intervals).
pub fn interval(knots: &[f64], t: f64) -> usize {
    let n = knots.len();
    knots
        .partition_point(|&k| k <= t)
        .saturating_sub(1)
        .min(n - 2)
}

/// Value at `t` of the natural spline with knot values `values` and second
/// derivatives `m`; outside the knots it continues as the end interval's
/// cubic.
pub fn eval(knots: &[f64], values: &[f64], m: &[f64], t: f64) -> f64 {
    let i = interval(knots, t);
    let h = knots[i + 1] - knots[i];
    let a = (knots[i + 1] - t) / h;
    let b = (t - knots[i]) / h;
    values[i] * a
        + values[i + 1] * b
        + (m[i] * (a * a * a - a) + m[i + 1] * (b * b * b - b)) * (h * h / 6.0)
}

/// The cubic of knot interval `i` as coefficients of `(t - knots[i])^k`,
/// `k = 0..=3`.
pub fn interval_cubic(knots: &[f64], values: &[f64], m: &[f64], i: usize) -> [f64; 4] {
    let h = knots[i + 1] - knots[i];
    let (y0, y1, m0, m1) = (values[i], values[i + 1], m[i], m[i + 1]);
    [
        y0,
        (y1 - y0) / h - h * (2.0 * m0 + m1) / 6.0,
        0.5 * m0,
        (m1 - m0) / (6.0 * h),
    ]
}

/// Least-squares natural-spline fit: knot values minimising
/// `sum w_i |s(t_i) - y_i|² + lambda |D2 s|²`, one column per coordinate of
/// `ys` (rows = stations). `None` when the system is singular or the
/// result not finite.
pub fn fit(
    knots: &[f64],
    ts: &[f64],
    ys: &DMatrix<f64>,
    weights: &[f64],
    lambda: f64,
) -> Option<DMatrix<f64>> {
    let nk = knots.len();
    if nk < 2 || ts.len() != ys.nrows() || ts.len() != weights.len() {
        return None;
    }
    // Basis: the natural spline of each unit vector of knot values.
    let mut basis = DMatrix::zeros(ts.len(), nk);
    let mut unit = vec![0.0; nk];
    for j in 0..nk {
        unit[j] = 1.0;
        let m = natural_second_derivatives(knots, &unit);
        for (i, &t) in ts.iter().enumerate() {
            basis[(i, j)] = eval(knots, &unit, &m, t);
        }
        unit[j] = 0.0;
    }
    let w = DVector::from_column_slice(weights);
    let mut bw = basis.clone();
    for (i, mut row) in bw.row_iter_mut().enumerate() {
        row *= w[i];
    }
    let mut normal = bw.transpose() * &basis;
    let rhs = bw.transpose() * ys;
    // Second differences of the knot values (per mm²), scaled to the data.
    let scale = lambda * weights.iter().sum::<f64>().max(1.0) / nk as f64;
    for j in 1..nk.saturating_sub(1) {
        let (h0, h1) = (knots[j] - knots[j - 1], knots[j + 1] - knots[j]);
        let hm = 0.5 * (h0 + h1);
        let row = [
            1.0 / (h0 * hm),
            -(1.0 / h0 + 1.0 / h1) / hm,
            1.0 / (h1 * hm),
        ];
        for (a, ra) in row.iter().enumerate() {
            for (b, rb) in row.iter().enumerate() {
                normal[(j - 1 + a, j - 1 + b)] += scale * ra * rb * hm.powi(4);
            }
        }
    }
    // Third differences over the first and last four knots, weighted as one
    // average station: past the data, the curve goes on with the curvature
    // it has at its ends (a circle's third derivative is small; a natural
    // end's zero curvature is not imposed).
    if nk >= 4 {
        let station = weights.iter().sum::<f64>() / weights.len().max(1) as f64;
        for first in [0, nk - 4] {
            let x = &knots[first..first + 4];
            let h = (x[3] - x[0]) / 3.0;
            let row: Vec<f64> = (0..4)
                .map(|i| {
                    let den: f64 = (0..4).filter(|&j| j != i).map(|j| x[i] - x[j]).product();
                    6.0 * h * h * h / den
                })
                .collect();
            for (a, ra) in row.iter().enumerate() {
                for (b, rb) in row.iter().enumerate() {
                    normal[(first + a, first + b)] += station * ra * rb;
                }
            }
        }
    }
    let sol = normal.cholesky()?.solve(&rhs);
    sol.iter().all(|x| x.is_finite()).then_some(sol)
}

/// Knots over `[0, length]` (mm): `spacing` inside, a quarter and a half of
/// it next to each end (the natural end condition then costs little on a
/// bent end), never closer than `min_gap`.
pub fn graded_knots(length: f64, spacing: f64, min_gap: f64) -> Vec<f64> {
    let h = spacing.max(min_gap);
    let end_steps = [(0.25 * h).max(min_gap), (0.5 * h).max(min_gap)];
    let graded: f64 = end_steps.iter().sum();
    if length < 2.0 * graded + h {
        let n = ((length / h).ceil() as usize).max(2);
        return (0..=n).map(|i| length * i as f64 / n as f64).collect();
    }
    let inner = length - 2.0 * graded;
    let n = ((inner / h).round() as usize).max(1);
    let mut knots = vec![0.0];
    for s in end_steps {
        knots.push(knots[knots.len() - 1] + s);
    }
    let start = knots[knots.len() - 1];
    for i in 1..=n {
        knots.push(start + inner * i as f64 / n as f64);
    }
    for s in end_steps.iter().rev() {
        knots.push(knots[knots.len() - 1] + s);
    }
    let last = knots.len() - 1;
    knots[last] = length;
    knots
}

/// The cubic Hermite from `p0` to `p1` with end tangents `m0`, `m1` (mm
/// per unit of `u`) at `u` in [0, 1] (mm, the points' frame).
pub(super) fn hermite(p0: &Point3, m0: &Vector3, p1: &Point3, m1: &Vector3, u: f64) -> Point3 {
    let (u2, u3) = (u * u, u * u * u);
    Point3::from(
        p0.coords * (2.0 * u3 - 3.0 * u2 + 1.0)
            + m0 * (u3 - 2.0 * u2 + u)
            + p1.coords * (-2.0 * u3 + 3.0 * u2)
            + m1 * (u3 - u2),
    )
}

/// The end tangents' length (mm) that makes [`hermite`] between two points
/// `chord` mm apart a circular arc when its unit end directions turn by
/// `turn` (rad): 4 tan(turn / 4) R with R = chord / (2 sin(turn / 2));
/// the chord when straight.
pub(super) fn arc_tangent_length(chord: f64, turn: f64) -> f64 {
    if turn < 1e-6 {
        chord
    } else {
        4.0 * (turn / 4.0).tan() * chord / (2.0 * (turn / 2.0).sin())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fit_reproduces_a_line_and_interval_cubics_match() {
        let knots = graded_knots(100.0, 10.0, 1.0);
        assert_eq!(knots[0], 0.0);
        assert_eq!(*knots.last().unwrap(), 100.0);
        assert!(knots.windows(2).all(|w| w[1] > w[0]));
        let ts: Vec<f64> = (0..=200).map(|i| i as f64 * 0.5).collect();
        let ys = DMatrix::from_fn(ts.len(), 1, |i, _| 3.0 + 0.25 * ts[i]);
        let w = vec![1.0; ts.len()];
        let sol = fit(&knots, &ts, &ys, &w, 1e-6).unwrap();
        let values: Vec<f64> = sol.column(0).iter().copied().collect();
        let m = natural_second_derivatives(&knots, &values);
        for &t in &[0.0, 13.3, 57.0, 100.0] {
            assert!((eval(&knots, &values, &m, t) - (3.0 + 0.25 * t)).abs() < 1e-9);
        }
        // A curved spline: the interval cubic gives the same values.
        let vals: Vec<f64> = knots.iter().map(|k| (k / 20.0).sin()).collect();
        let m = natural_second_derivatives(&knots, &vals);
        let i = interval(&knots, 42.0);
        let c = interval_cubic(&knots, &vals, &m, i);
        let x = 42.0 - knots[i];
        let poly = c[0] + c[1] * x + c[2] * x * x + c[3] * x * x * x;
        assert!((poly - eval(&knots, &vals, &m, 42.0)).abs() < 1e-12);
    }
}
