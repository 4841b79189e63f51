//! `R_Z` along a layer as a linear function of a few coefficients:
//! `R = B c`, `B` the basis (points × coefficients). Polynomials in a scaled
//! abscissa [eq. 4.1–4.2] and one value per point (smoothing spline) share
//! this form, so the SQP sees only `B` (the chain rule `dq/dc = dq/dR_Z · B`).

use std::f64::consts::TAU;

use crate::math::{tol, Point3};

/// Ridge added to the spline fit's normal equations, relative to their mean
/// diagonal: a span without points takes its coefficient from its
/// neighbours instead of making the system singular (relative).
const RIDGE_REL: f64 = 1e-14;

/// Cylindrical angle of each point about the part Z axis (rad), unwrapped
/// along the layer (continuous, starting in `(-π, π]`).
pub fn cylindrical_angles(points: &[Point3]) -> Vec<f64> {
    let mut out = Vec::with_capacity(points.len());
    let mut prev: Option<f64> = None;
    for p in points {
        let a = p.y.atan2(p.x);
        let a = match prev {
            Some(pr) => a + TAU * ((pr - a) / TAU).round(),
            None => a,
        };
        out.push(a);
        prev = Some(a);
    }
    out
}

/// `true` when the unwrapped angles run monotonically through at least half a
/// turn (the layer turns about the part Z axis, as on a part of revolution).
pub fn turns_about_z(theta: &[f64]) -> bool {
    if theta.len() < 3 {
        return false;
    }
    let d: Vec<f64> = theta.windows(2).map(|w| w[1] - w[0]).collect();
    let monotone = d.iter().all(|x| *x > 0.0) || d.iter().all(|x| *x < 0.0);
    monotone && (theta[theta.len() - 1] - theta[0]).abs() >= std::f64::consts::PI
}

/// The basis of a layer.
#[derive(Debug, Clone, PartialEq)]
pub enum Basis {
    /// Monomials `1, s, …, s^n` of the abscissa scaled to `s ∈ [-1, 1]`.
    Polynomial {
        /// Scaled abscissa per point.
        s: Vec<f64>,
        /// Abscissa at `s = -1` (point index or rad).
        x_min: f64,
        /// Abscissa at `s = +1`.
        x_max: f64,
        /// Number of coefficients (degree + 1; degree when anchored).
        coefficients: usize,
        /// `Some(r0)`: `R` at point 0 is held at `r0` (rad): the abscissa is
        /// scaled to `s = (x − x_0) / max|x − x_0|` and the constant term is
        /// replaced by `r0`, so `R = r0 + Σ_{i≥1} c_i s^i` (the turns of a
        /// spiral, each continuing the one before).
        anchor: Option<f64>,
    },
    /// One coefficient per point.
    PerPoint {
        /// Number of points.
        points: usize,
    },
    /// Uniform cubic B-spline in the abscissa: `segments` equal spans over
    /// its range, `segments + 3` coefficients (control values, rad); it
    /// reproduces constant and linear laws exactly (the positioner's laws,
    /// [`crate::optimise::positioner`]).
    Spline {
        /// Abscissa per point scaled to `u ∈ [0, segments]`.
        u: Vec<f64>,
        /// Number of spans.
        segments: usize,
    },
}

/// The four uniform cubic B-spline weights at `t ∈ [0, 1]` within a span.
fn cubic_bspline_weights(t: f64) -> [f64; 4] {
    let t2 = t * t;
    let t3 = t2 * t;
    let s = 1.0 - t;
    [
        s * s * s / 6.0,
        (3.0 * t3 - 6.0 * t2 + 4.0) / 6.0,
        (-3.0 * t3 + 3.0 * t2 + 3.0 * t + 1.0) / 6.0,
        t3 / 6.0,
    ]
}

impl Basis {
    /// Polynomial basis of `coefficients` terms on abscissa `x` (one per point).
    pub fn polynomial(x: &[f64], coefficients: usize) -> Self {
        let x_min = x.iter().copied().fold(f64::INFINITY, f64::min);
        let x_max = x.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        let h = 0.5 * (x_max - x_min);
        let s = x
            .iter()
            .map(|v| if h > 0.0 { (v - x_min) / h - 1.0 } else { 0.0 })
            .collect();
        Self::Polynomial {
            s,
            x_min,
            x_max,
            coefficients,
            anchor: None,
        }
    }

    /// Polynomial of degree `degree` (≥ 1) on abscissa `x` with `R` held at
    /// `r0` (rad) on point 0 (see [`Basis::Polynomial`]'s `anchor`).
    pub fn anchored_polynomial(x: &[f64], degree: usize, r0: f64) -> Self {
        let x0 = x.first().copied().unwrap_or(0.0);
        let h = x.iter().map(|v| (v - x0).abs()).fold(0.0, f64::max);
        let s = x
            .iter()
            .map(|v| if h > 0.0 { (v - x0) / h } else { 0.0 })
            .collect();
        Self::Polynomial {
            s,
            x_min: x0,
            x_max: x0 + h,
            coefficients: degree.max(1),
            anchor: Some(r0),
        }
    }

    /// Uniform cubic B-spline basis of `segments` (≥ 1) spans on abscissa
    /// `x` (one per point), see [`Basis::Spline`].
    pub fn spline(x: &[f64], segments: usize) -> Self {
        let segments = segments.max(1);
        let x_min = x.iter().copied().fold(f64::INFINITY, f64::min);
        let x_max = x.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        let h = x_max - x_min;
        let u = x
            .iter()
            .map(|v| {
                if h > 0.0 {
                    ((v - x_min) / h * segments as f64).clamp(0.0, segments as f64)
                } else {
                    0.0
                }
            })
            .collect();
        Self::Spline { u, segments }
    }

    /// Number of coefficients.
    pub fn len(&self) -> usize {
        match self {
            Self::Polynomial { coefficients, .. } => *coefficients,
            Self::PerPoint { points } => *points,
            Self::Spline { segments, .. } => segments + 3,
        }
    }

    /// `true` with no coefficient.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Number of points.
    pub fn points(&self) -> usize {
        match self {
            Self::Polynomial { s, .. } => s.len(),
            Self::PerPoint { points } => *points,
            Self::Spline { u, .. } => u.len(),
        }
    }

    /// Row `m` of `B` as `(coefficient, value)` pairs, into `out` (cleared).
    pub fn row(&self, m: usize, out: &mut Vec<(usize, f64)>) {
        out.clear();
        match self {
            Self::Polynomial {
                s,
                coefficients,
                anchor,
                ..
            } => {
                let mut v = if anchor.is_some() { s[m] } else { 1.0 };
                for i in 0..*coefficients {
                    out.push((i, v));
                    v *= s[m];
                }
            }
            Self::PerPoint { .. } => out.push((m, 1.0)),
            Self::Spline { u, segments } => {
                let span = (u[m].floor() as usize).min(segments - 1);
                let w = cubic_bspline_weights(u[m] - span as f64);
                out.extend(w.iter().enumerate().map(|(i, v)| (span + i, *v)));
            }
        }
    }

    /// `max_m Σ_i |B_mi|`: a box `|δc_i| ≤ Δ / L` keeps every `|δR_m| ≤ Δ`.
    pub fn row_l1_bound(&self) -> f64 {
        match self {
            Self::Polynomial { coefficients, .. } => *coefficients as f64,
            // non-negative weights summing to 1
            Self::PerPoint { .. } | Self::Spline { .. } => 1.0,
        }
    }

    /// `R = B c` (rad).
    pub fn eval(&self, c: &[f64]) -> Vec<f64> {
        match self {
            Self::Polynomial {
                s, anchor: None, ..
            } => s
                .iter()
                .map(|x| c.iter().rev().fold(0.0, |acc, ci| acc * x + ci))
                .collect(),
            Self::Polynomial {
                s,
                anchor: Some(r0),
                ..
            } => s
                .iter()
                .map(|x| r0 + x * c.iter().rev().fold(0.0, |acc, ci| acc * x + ci))
                .collect(),
            Self::PerPoint { .. } => c.to_vec(),
            Self::Spline { .. } => {
                let mut row = Vec::with_capacity(4);
                (0..self.points())
                    .map(|m| {
                        self.row(m, &mut row);
                        row.iter().map(|&(i, v)| v * c[i]).sum()
                    })
                    .collect()
            }
        }
    }

    /// The same law on the points `idx` only (a polynomial keeps its
    /// abscissa scaling, so equal coefficients give equal `R_Z` there);
    /// `None` for the per-point basis.
    pub fn restricted(&self, idx: &[usize]) -> Option<Self> {
        match self {
            Self::Polynomial {
                s,
                x_min,
                x_max,
                coefficients,
                anchor,
            } => Some(Self::Polynomial {
                s: idx.iter().map(|&m| s[m]).collect(),
                x_min: *x_min,
                x_max: *x_max,
                coefficients: *coefficients,
                anchor: *anchor,
            }),
            Self::Spline { u, segments } => Some(Self::Spline {
                u: idx.iter().map(|&m| u[m]).collect(),
                segments: *segments,
            }),
            Self::PerPoint { .. } => None,
        }
    }

    /// The same polynomial with `coefficients` terms (`None` for the
    /// per-point basis).
    pub fn with_coefficients(&self, coefficients: usize) -> Option<Self> {
        match self {
            Self::Polynomial {
                s,
                x_min,
                x_max,
                anchor,
                ..
            } => Some(Self::Polynomial {
                s: s.clone(),
                x_min: *x_min,
                x_max: *x_max,
                coefficients,
                anchor: *anchor,
            }),
            Self::PerPoint { .. } | Self::Spline { .. } => None,
        }
    }

    /// Same polynomial, one more coefficient (zero): warm start of the next degree.
    pub fn raised(&self) -> Option<Self> {
        self.with_coefficients(self.len() + 1)
    }

    /// `BᵀB` and `Bᵀ(r − r0)`: the normal equations of a fit to `r`.
    fn normal_equations(
        &self,
        r: &[f64],
        r0: f64,
    ) -> (nalgebra::DMatrix<f64>, nalgebra::DVector<f64>) {
        let k = self.len();
        let mut ata = nalgebra::DMatrix::<f64>::zeros(k, k);
        let mut atb = nalgebra::DVector::<f64>::zeros(k);
        let mut row = Vec::new();
        for (m, rm) in r.iter().enumerate() {
            self.row(m, &mut row);
            for &(i, a) in &row {
                atb[i] += a * (rm - r0);
                for &(j, b) in &row {
                    ata[(i, j)] += a * b;
                }
            }
        }
        (ata, atb)
    }

    /// Least-squares coefficients reproducing the values `r` (rad) per point
    /// (normal equations; exact when `r` is in the span).
    pub fn fit(&self, r: &[f64]) -> Vec<f64> {
        match self {
            Self::PerPoint { .. } => r.to_vec(),
            Self::Spline { .. } => {
                // a tiny ridge: a span without points leaves its
                // coefficient to its neighbours
                let (mut ata, atb) = self.normal_equations(r, 0.0);
                let k = self.len();
                let ridge = RIDGE_REL * (ata.trace() / k as f64).max(tol::DIV_FLOOR);
                for i in 0..k {
                    ata[(i, i)] += ridge;
                }
                match ata.cholesky() {
                    Some(ch) => ch.solve(&atb).iter().copied().collect(),
                    None => vec![r.iter().sum::<f64>() / r.len().max(1) as f64; k],
                }
            }
            Self::Polynomial {
                coefficients,
                anchor,
                ..
            } => {
                let k = *coefficients;
                let (ata, atb) = self.normal_equations(r, anchor.unwrap_or(0.0));
                match ata.cholesky() {
                    Some(ch) => ch.solve(&atb).iter().copied().collect(),
                    None => {
                        let mut c = vec![0.0; k];
                        if anchor.is_none() {
                            c[0] = r.iter().sum::<f64>() / r.len().max(1) as f64;
                        }
                        c
                    }
                }
            }
        }
    }

    /// The polynomial in the thesis's form: coefficients of the unscaled
    /// abscissa (point index `m` counted from 1 as in eq. 4.1, or the angle in
    /// rad), highest power first, `R_Z` in degrees — `B_{C,n}` of eq. 4.1.
    /// `None` for the per-point and the anchored bases.
    pub fn thesis_coefficients_deg(&self, c: &[f64], one_based_index: bool) -> Option<Vec<f64>> {
        let Self::Polynomial {
            x_min,
            x_max,
            anchor: None,
            ..
        } = self
        else {
            return None;
        };
        let h = 0.5 * (x_max - x_min);
        if !(h > 0.0) {
            return Some(vec![c.first().copied().unwrap_or(0.0).to_degrees()]);
        }
        // s = a x + b with x the unscaled abscissa
        let shift = if one_based_index { 1.0 } else { 0.0 };
        let a = 1.0 / h;
        let b = -(x_min + shift) / h - 1.0;
        // expand Σ c_i (a x + b)^i; out[p] = coefficient of x^p
        let k = c.len();
        let mut out = vec![0.0; k];
        let mut pow = vec![1.0]; // coefficients of (a x + b)^i, ascending
        for (i, ci) in c.iter().enumerate() {
            if i > 0 {
                let mut next = vec![0.0; pow.len() + 1];
                for (p, v) in pow.iter().enumerate() {
                    next[p] += v * b;
                    next[p + 1] += v * a;
                }
                pow = next;
            }
            for (p, v) in pow.iter().enumerate() {
                out[p] += ci * v;
            }
        }
        Some(out.iter().rev().map(|v| v.to_degrees()).collect())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn polynomial_basis_evaluates_and_converts_to_the_thesis_form() {
        let x: Vec<f64> = (0..11).map(|m| m as f64).collect();
        let b = Basis::polynomial(&x, 3);
        // R(m) = 0.1 + 0.02 m − 0.003 m² (rad), m from 0
        let r: Vec<f64> = x.iter().map(|m| 0.1 + 0.02 * m - 0.003 * m * m).collect();
        let c = b.fit(&r);
        for (a, e) in b.eval(&c).iter().zip(&r) {
            assert!((a - e).abs() < 1e-12);
        }
        let t = b.thesis_coefficients_deg(&c, false).unwrap();
        assert!((t[0] - (-0.003f64).to_degrees()).abs() < 1e-9);
        assert!((t[1] - 0.02f64.to_degrees()).abs() < 1e-9);
        assert!((t[2] - 0.1f64.to_degrees()).abs() < 1e-9);
        let raised = b.raised().unwrap();
        let mut c2 = c.clone();
        c2.push(0.0);
        assert_eq!(raised.eval(&c2), b.eval(&c));
    }

    /// The spline reproduces a linear law exactly (uniform cubic B-splines
    /// reproduce degree-1 polynomials), its rows are a partition of unity, and
    /// it follows a three-lobed law a degree-6 polynomial cannot.
    #[test]
    fn spline_basis_reproduces_lines_and_follows_lobes() {
        let x: Vec<f64> = (0..400).map(|m| m as f64).collect();
        let b = Basis::spline(&x, 16);
        assert_eq!(b.len(), 19);
        let line: Vec<f64> = x.iter().map(|m| 0.3 - 0.0157 * m).collect();
        for (a, e) in b.eval(&b.fit(&line)).iter().zip(&line) {
            assert!((a - e).abs() < 1e-9, "{a} {e}");
        }
        let mut row = Vec::new();
        for m in [0, 17, 200, 399] {
            b.row(m, &mut row);
            let s: f64 = row.iter().map(|(_, v)| v).sum();
            assert!((s - 1.0).abs() < 1e-14 && row.iter().all(|(_, v)| *v >= 0.0));
        }
        let lobes: Vec<f64> = x.iter().map(|m| (3.0 * TAU * m / 400.0).sin()).collect();
        let err = |basis: &Basis| {
            basis
                .eval(&basis.fit(&lobes))
                .iter()
                .zip(&lobes)
                .map(|(a, e)| (a - e).abs())
                .fold(0.0, f64::max)
        };
        assert!(err(&b) < 0.01, "spline {}", err(&b));
        assert!(err(&Basis::polynomial(&x, 7)) > 0.1);
        let sub = b.restricted(&[0, 100, 399]).unwrap();
        let c = b.fit(&lobes);
        assert_eq!(
            sub.eval(&c),
            vec![b.eval(&c)[0], b.eval(&c)[100], b.eval(&c)[399]]
        );
    }

    #[test]
    fn angles_unwrap_and_detect_turning() {
        let pts: Vec<Point3> = (0..50)
            .map(|k| {
                let v = 3.0 + TAU * k as f64 / 50.0;
                Point3::new(v.cos(), v.sin(), 0.0)
            })
            .collect();
        let th = cylindrical_angles(&pts);
        assert!(th.windows(2).all(|w| w[1] > w[0]));
        assert!(turns_about_z(&th));
    }
}
