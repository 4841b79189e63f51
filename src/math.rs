//! Scalar and vector types used across the crate, named tolerances, and the
//! small numerical helpers (bracketed root finding, Gauss–Legendre quadrature)
//! every stage shares. All lengths in mm, angles in rad.

/// A point in 3-D space (mm), frame given by the owner.
pub type Point3 = nalgebra::Point3<f64>;
/// A free vector in 3-D space (mm, or unitless for directions).
pub type Vector3 = nalgebra::Vector3<f64>;
/// A unit-length 3-D direction.
pub type UnitVector3 = nalgebra::Unit<Vector3>;
/// A 3×3 matrix.
pub type Matrix3 = nalgebra::Matrix3<f64>;
/// A 3-D rotation.
pub type Rotation3 = nalgebra::Rotation3<f64>;
/// A unit quaternion (3-D rotation).
pub type UnitQuaternion = nalgebra::UnitQuaternion<f64>;
/// A rigid transform (rotation then translation, mm).
pub type Isometry3 = nalgebra::Isometry3<f64>;
/// A 3-D translation (mm).
pub type Translation3 = nalgebra::Translation3<f64>;

/// Named tolerances shared by more than one stage, each with what it guards.
///
/// Lengths in mm, angles in rad; "relative" ones multiply a scale the call
/// site names. A tolerance used by one module only is a named `const` at the
/// top of that module instead. The values are the ones the code has always
/// used: changing one changes output.
pub mod tol {
    /// Two points closer than this are the same point (mm): coincident spline
    /// control points, a start point already on the substrate.
    pub const LENGTH_MM: f64 = 1e-9;
    /// Angular tolerance for parallel / perpendicular tests (rad, or the sine
    /// or cosine of the angle between unit vectors): a unit vector with a
    /// direction projected out that is shorter than this is parallel to that
    /// direction; two unit directions whose dot product is below it are
    /// perpendicular.
    pub const ANGLE_RAD: f64 = 1e-9;
    /// Relative tolerance used when a vector is normalised: below this norm
    /// (relative to the scale of the problem) it is treated as zero. Also the
    /// norm below which `Unit::try_new` refuses a direction read from input.
    pub const DEGENERATE: f64 = 1e-12;
    /// Tolerance on a curve parameter `t` found by root finding, relative to
    /// `1 + |t|` (parameter units): the constant-distance layer step.
    pub const PARAM: f64 = 1e-12;
    /// The finer tolerance on a curve parameter `t` found by Brent's method
    /// (parameter units; relative to `1 + |t|` in the layer strategies,
    /// absolute where the first layer meets a mesh substrate): iso-parametric,
    /// planar and spiral steps, substrate hits.
    pub const PARAM_FINE: f64 = 1e-13;
    /// Distance between two consecutive path points (mm) below which they are
    /// treated as one: no chord direction or rate per mm is taken over it.
    pub const ZERO_LENGTH_MM: f64 = 1e-12;
    /// Angle (rad) a tool axis must have turned by to count as changed by a
    /// rule (rate bound, collision avoidance) in the point counts reported.
    pub const AXIS_MOVED_RAD: f64 = 1e-12;
    /// Floor of a divisor that may be exactly zero (same unit as the divisor):
    /// keeps a ratio finite without changing any divisor of real size.
    pub const DIV_FLOOR: f64 = 1e-300;
    /// Floor of an objective value used as a scale (the objective's units):
    /// relative gains of a layer's optimisation are measured against at least
    /// this, so a seed already at zero does not divide by zero.
    pub const OBJECTIVE_SCALE_FLOOR: f64 = 1e-6;
}

/// Outcome of a bracketed 1-D root find.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Root {
    /// The abscissa found.
    pub x: f64,
    /// The function value there.
    pub residual: f64,
    /// Function evaluations made by the solver inside the bracket.
    pub iterations: usize,
}

/// Why a bracketed 1-D root find failed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RootFailure {
    /// `f(a)` and `f(b)` have the same sign.
    NotBracketed,
    /// The function returned a non-finite value.
    NonFinite,
    /// The iteration limit was reached.
    NotConverged,
}

struct Convergence {
    x_tol: f64,
    y_tol: f64,
    max_iter: usize,
    iterations: usize,
}

impl roots::Convergency<f64> for Convergence {
    fn is_root_found(&mut self, y: f64) -> bool {
        y.abs() <= self.y_tol
    }
    fn is_converged(&mut self, x1: f64, x2: f64) -> bool {
        (x1 - x2).abs() <= self.x_tol
    }
    fn is_iteration_limit_reached(&mut self, iter: usize) -> bool {
        self.iterations = iter;
        iter >= self.max_iter
    }
}

/// Brent's method on a bracket `[a, b]` where `f(a)` and `f(b)` differ in sign.
///
/// `x_tol` is the tolerance on the abscissa, `y_tol` on the residual. Uses the
/// `roots` crate; wraps it so that non-finite values are reported instead of
/// propagated.
pub fn brent(
    mut f: impl FnMut(f64) -> f64,
    a: f64,
    b: f64,
    x_tol: f64,
    y_tol: f64,
) -> Result<Root, RootFailure> {
    let fa = f(a);
    let fb = f(b);
    brent_bracketed(f, (a, fa), (b, fb), x_tol, y_tol)
}

/// [`brent`] on a bracket whose end values are already known: no function
/// evaluation is repeated (the solver's own calls at the ends and the final
/// residual are answered from a small cache).
pub fn brent_bracketed(
    mut f: impl FnMut(f64) -> f64,
    (a, fa): (f64, f64),
    (b, fb): (f64, f64),
    x_tol: f64,
    y_tol: f64,
) -> Result<Root, RootFailure> {
    if !fa.is_finite() || !fb.is_finite() {
        return Err(RootFailure::NonFinite);
    }
    if fa == 0.0 {
        return Ok(Root {
            x: a,
            residual: 0.0,
            iterations: 0,
        });
    }
    if fb == 0.0 {
        return Ok(Root {
            x: b,
            residual: 0.0,
            iterations: 0,
        });
    }
    if fa * fb > 0.0 {
        return Err(RootFailure::NotBracketed);
    }
    let mut conv = Convergence {
        x_tol,
        y_tol,
        max_iter: 200,
        iterations: 0,
    };
    let mut non_finite = false;
    let mut cache = [(a, fa), (b, fb), (f64::NAN, f64::NAN)];
    let mut next_slot = 2;
    let mut evaluations = 0;
    let mut g = |x: f64| {
        if let Some(&(_, y)) = cache.iter().find(|(cx, _)| *cx == x) {
            return y;
        }
        let y = f(x);
        evaluations += 1;
        cache[next_slot] = (x, y);
        next_slot = if next_slot == 2 { 0 } else { next_slot + 1 };
        if y.is_finite() {
            y
        } else {
            non_finite = true;
            0.0
        }
    };
    let result = roots::find_root_brent(a, b, &mut g, &mut conv);
    let residual = result.as_ref().map(|&x| g(x)).ok();
    if non_finite {
        return Err(RootFailure::NonFinite);
    }
    match (result, residual) {
        (Ok(x), Some(r)) => Ok(Root {
            x,
            residual: r,
            iterations: evaluations,
        }),
        (Err(roots::SearchError::NoBracketing), _) => Err(RootFailure::NotBracketed),
        _ => Err(RootFailure::NotConverged),
    }
}

/// Nodes and weights of 8-point Gauss–Legendre quadrature on `[-1, 1]`.
const GL8: [(f64, f64); 8] = [
    (-0.960_289_856_497_536_3, 0.101_228_536_290_376_26),
    (-0.796_666_477_413_626_7, 0.222_381_034_453_374_47),
    (-0.525_532_409_916_329, 0.313_706_645_877_887_3),
    (-0.183_434_642_495_649_8, 0.362_683_783_378_362),
    (0.183_434_642_495_649_8, 0.362_683_783_378_362),
    (0.525_532_409_916_329, 0.313_706_645_877_887_3),
    (0.796_666_477_413_626_7, 0.222_381_034_453_374_47),
    (0.960_289_856_497_536_3, 0.101_228_536_290_376_26),
];

/// Integral of `f` over `[a, b]` by composite 8-point Gauss–Legendre on
/// `panels` equal panels. Exact for polynomials of degree 15 per panel.
pub fn gauss_legendre(f: impl Fn(f64) -> f64, a: f64, b: f64, panels: usize) -> f64 {
    let panels = panels.max(1);
    let h = (b - a) / panels as f64;
    let mut sum = 0.0;
    for k in 0..panels {
        let mid = a + (k as f64 + 0.5) * h;
        for (x, w) in GL8 {
            sum += w * f(mid + 0.5 * h * x);
        }
    }
    sum * 0.5 * h
}

/// A unit vector perpendicular to `v` (not normalised input accepted),
/// chosen as the world axis least aligned with `v`, projected.
pub fn any_perpendicular(v: &Vector3) -> Vector3 {
    let a = v.abs();
    let axis = if a.x <= a.y && a.x <= a.z {
        Vector3::x()
    } else if a.y <= a.z {
        Vector3::y()
    } else {
        Vector3::z()
    };
    let u = v.normalize();
    (axis - u * u.dot(&axis)).normalize()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn brent_finds_cos_root() {
        let r = brent(f64::cos, 0.0, 3.0, 1e-14, 0.0).unwrap();
        assert!((r.x - std::f64::consts::FRAC_PI_2).abs() < 1e-12);
    }

    #[test]
    fn brent_reports_missing_bracket_and_nan() {
        assert_eq!(
            brent(|x| x * x + 1.0, -1.0, 1.0, 1e-12, 0.0),
            Err(RootFailure::NotBracketed)
        );
        assert_eq!(
            brent(|_| f64::NAN, -1.0, 1.0, 1e-12, 0.0),
            Err(RootFailure::NonFinite)
        );
    }

    #[test]
    fn gauss_legendre_integrates_sin() {
        let i = gauss_legendre(f64::sin, 0.0, std::f64::consts::PI, 4);
        assert!((i - 2.0).abs() < 1e-13);
    }

    #[test]
    fn perpendicular_is_unit_and_orthogonal() {
        for v in [
            Vector3::z(),
            Vector3::new(1.0, 2.0, 3.0),
            Vector3::new(-5.0, 0.1, 0.0),
        ] {
            let p = any_perpendicular(&v);
            assert!((p.norm() - 1.0).abs() < 1e-15);
            assert!(p.dot(&v).abs() < 1e-12);
        }
        assert_eq!(any_perpendicular(&Vector3::z()), Vector3::x());
    }
}
