//! Cubic spline through points (guide curves coming from CAD data).
//!
//! A natural cubic spline (C², zero second derivative at both ends) per
//! coordinate, parameterised by cumulative chord length so that `t` is close to
//! the arc length (mm). Written here rather than taken from a crate because the
//! spline crates we looked at (`splines`, `bspline`) give no derivatives, and
//! the tube needs the first three analytically.

use super::GuideCurve;
use crate::geometry::GeometryError;
use crate::math::{tol, Point3, Vector3};

/// Natural cubic spline through the given points (part frame, mm), parameter
/// `t` = cumulative chord length (mm) in `[0, total chord]`. Outside that range
/// the curve continues along its end tangents (straight extension).
#[derive(Debug, Clone)]
pub struct CubicSpline {
    knots: Vec<f64>,
    points: Vec<Vector3>,
    /// Second derivatives at the knots.
    second: Vec<Vector3>,
}

impl CubicSpline {
    /// Builds the spline through `points`.
    ///
    /// # Errors
    /// [`GeometryError::Spline`] if there are fewer than 3 points, a
    /// coordinate is not finite, or two consecutive points coincide (names
    /// the point index).
    pub fn new(points: &[Point3]) -> Result<Self, GeometryError> {
        if points.len() < 3 {
            return Err(GeometryError::Spline {
                index: points.len(),
                reason: format!("needs at least 3 points, got {}", points.len()),
            });
        }
        let mut knots = vec![0.0];
        for (i, w) in points.windows(2).enumerate() {
            if !w[1].coords.iter().all(|c| c.is_finite()) {
                return Err(GeometryError::Spline {
                    index: i + 1,
                    reason: "not finite".into(),
                });
            }
            let d = (w[1] - w[0]).norm();
            if d <= tol::LENGTH_MM {
                return Err(GeometryError::Spline {
                    index: i + 1,
                    reason: "coincides with the previous point".into(),
                });
            }
            knots.push(knots[i] + d);
        }
        let n = points.len();
        let p: Vec<Vector3> = points.iter().map(|q| q.coords).collect();
        // Tridiagonal system for the second derivatives M_i (natural: M_0 = M_{n-1} = 0).
        let h: Vec<f64> = knots.windows(2).map(|w| w[1] - w[0]).collect();
        let mut diag = vec![0.0; n];
        let mut rhs = vec![Vector3::zeros(); n];
        let mut sub = vec![0.0; n];
        for i in 1..n - 1 {
            sub[i] = h[i - 1];
            diag[i] = 2.0 * (h[i - 1] + h[i]);
            rhs[i] = 6.0 * ((p[i + 1] - p[i]) / h[i] - (p[i] - p[i - 1]) / h[i - 1]);
        }
        // Thomas algorithm on rows 1..n-1 (the super-diagonal of row i is h[i]).
        let mut second = vec![Vector3::zeros(); n];
        let mut c_prime = vec![0.0; n];
        let mut d_prime = vec![Vector3::zeros(); n];
        for i in 1..n - 1 {
            let (c_prev, d_prev) = if i == 1 {
                (0.0, Vector3::zeros())
            } else {
                (c_prime[i - 1], d_prime[i - 1])
            };
            let a = if i == 1 { 0.0 } else { sub[i] };
            let m = diag[i] - a * c_prev;
            c_prime[i] = if i + 1 < n - 1 { h[i] / m } else { 0.0 };
            d_prime[i] = (rhs[i] - d_prev * a) / m;
        }
        for i in (1..n - 1).rev() {
            let next = if i + 1 < n - 1 {
                second[i + 1]
            } else {
                Vector3::zeros()
            };
            second[i] = d_prime[i] - next * c_prime[i];
        }
        Ok(Self {
            knots,
            points: p,
            second,
        })
    }

    /// Total chord length: the parameter range is `[0, length]` (mm).
    pub fn length(&self) -> f64 {
        *self.knots.last().expect("at least 3 knots")
    }

    fn segment(&self, t: f64) -> usize {
        let n = self.knots.len();
        match self.knots.binary_search_by(|k| k.total_cmp(&t)) {
            Ok(i) => i.min(n - 2),
            Err(i) => i.saturating_sub(1).min(n - 2),
        }
    }

    /// Derivative `order` (0..=3) inside the knot range.
    fn eval_inside(&self, order: usize, t: f64) -> Vector3 {
        let i = self.segment(t);
        let h = self.knots[i + 1] - self.knots[i];
        let a = (self.knots[i + 1] - t) / h;
        let b = (t - self.knots[i]) / h;
        let (p0, p1, m0, m1) = (
            self.points[i],
            self.points[i + 1],
            self.second[i],
            self.second[i + 1],
        );
        match order {
            0 => p0 * a + p1 * b + (m0 * (a * a * a - a) + m1 * (b * b * b - b)) * (h * h / 6.0),
            1 => (p1 - p0) / h + (m1 * (3.0 * b * b - 1.0) - m0 * (3.0 * a * a - 1.0)) * (h / 6.0),
            2 => m0 * a + m1 * b,
            _ => (m1 - m0) / h,
        }
    }

    fn eval(&self, order: usize, t: f64) -> Vector3 {
        let (lo, hi) = (0.0, self.length());
        if t < lo || t > hi {
            let end = if t < lo { lo } else { hi };
            return match order {
                0 => self.eval_inside(0, end) + self.eval_inside(1, end) * (t - end),
                1 => self.eval_inside(1, end),
                _ => Vector3::zeros(),
            };
        }
        self.eval_inside(order, t)
    }
}

impl GuideCurve for CubicSpline {
    fn point(&self, t: f64) -> Point3 {
        Point3::from(self.eval(0, t))
    }
    fn d1(&self, t: f64) -> Vector3 {
        self.eval(1, t)
    }
    fn d2(&self, t: f64) -> Vector3 {
        self.eval(2, t)
    }
    fn d3(&self, t: f64) -> Vector3 {
        self.eval(3, t)
    }
}
