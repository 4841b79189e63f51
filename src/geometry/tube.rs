//! The tube surface `M(t, v) = Mg(t) + A(t) (cos v N(t) + sin v B(t))` (part
//! frame, mm) with its analytic partial derivatives and unit normal
//! [SPEC §2; thesis eq. 2.1, 2.22–2.25, 2.33].

use super::frame::{Frame, FrameField, FrameMethod};
use super::guide::GuideCurve;
use super::profile::ProfileLaw;
use super::GeometryError;
use crate::math::{self, Point3, UnitVector3, Vector3};
use std::sync::Arc;

/// A guide whose speed times the parameter span is below this fraction of
/// its size (relative) has a zero derivative there: no frame can be built.
const ZERO_SPEED_REL: f64 = 1e-9;
/// Newton on the arc length ([`Tube::t_at_arc_length`]) stops when its step is
/// below this fraction of `1 + |t|` (relative, parameter units).
const ARC_STEP_REL_TOL: f64 = 1e-14;

/// Number of samples of the validity check along the guide (plus the range ends).
const VALIDITY_SAMPLES: usize = 4096;

/// The parameter range of a tube: the part runs over `[t_min, t_max]`; the
/// surface may also be evaluated `extend_before` below and `extend_after`
/// above it (guide parameter units), for paths generated past the end and
/// truncated (SPEC §3.5).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TubeRange {
    /// First guide parameter of the part.
    pub t_min: f64,
    /// Last guide parameter of the part.
    pub t_max: f64,
    /// Extra range evaluable before `t_min` (≥ 0).
    pub extend_before: f64,
    /// Extra range evaluable after `t_max` (≥ 0).
    pub extend_after: f64,
}

impl TubeRange {
    /// The part range `[t_min, t_max]` with no extension.
    pub fn new(t_min: f64, t_max: f64) -> Self {
        Self {
            t_min,
            t_max,
            extend_before: 0.0,
            extend_after: 0.0,
        }
    }
    /// Lowest evaluable parameter.
    pub fn eval_min(&self) -> f64 {
        self.t_min - self.extend_before
    }
    /// Highest evaluable parameter.
    pub fn eval_max(&self) -> f64 {
        self.t_max + self.extend_after
    }
}

/// A surface point with its first partial derivatives (part frame).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SurfacePoint {
    /// `M(t, v)` (mm).
    pub position: Point3,
    /// `∂M/∂t` (mm per parameter unit).
    pub d_dt: Vector3,
    /// `∂M/∂v` (mm/rad).
    pub d_dv: Vector3,
    /// Unit normal pointing away from the guide (outward).
    pub normal: UnitVector3,
}

/// A validated tube: guide curve, frame field, profile law and range.
///
/// Built once by [`Tube::new`], which checks the profile radius is positive and
/// below the guide's radius of curvature everywhere on the evaluable range;
/// later stages trust it.
#[derive(Debug, Clone)]
pub struct Tube {
    guide: Arc<dyn GuideCurve>,
    frames: FrameField,
    profile: ProfileLaw,
    range: TubeRange,
    /// Cumulative arc length at the validity samples (mm from `eval_min`).
    arc_table: Vec<f64>,
    arc_h: f64,
}

impl Tube {
    /// Builds and validates a tube.
    ///
    /// # Errors
    /// * [`GeometryError::EmptyRange`] if `t_min >= t_max` or a bound is not finite;
    /// * [`GeometryError::ZeroDerivative`] where the guide stops (`|Mg'| ≈ 0`);
    /// * [`GeometryError::NonFinite`] where the guide or the radius is undefined;
    /// * [`GeometryError::NonPositiveRadius`] where `A(t) <= 0`;
    /// * [`GeometryError::Folds`] where `A(t) κ(t) >= 1` (the surface folds);
    /// * [`GeometryError::FrenetUndefined`] for Frenet frames on straight parts.
    ///
    /// Each names the first offending `t` found on a grid of 4096 samples.
    pub fn new(
        guide: Arc<dyn GuideCurve>,
        frame_method: FrameMethod,
        frame_reference: Option<Vector3>,
        profile: ProfileLaw,
        range: TubeRange,
    ) -> Result<Self, GeometryError> {
        let ok = |x: f64| x.is_finite();
        let bounds_ok = ok(range.t_min) && ok(range.t_max) && range.t_min < range.t_max;
        let extensions_ok = ok(range.extend_before)
            && range.extend_before >= 0.0
            && ok(range.extend_after)
            && range.extend_after >= 0.0;
        if !bounds_ok || !extensions_ok {
            return Err(GeometryError::EmptyRange {
                t_min: range.t_min,
                t_max: range.t_max,
            });
        }
        let (lo, hi) = (range.eval_min(), range.eval_max());
        let h = (hi - lo) / VALIDITY_SAMPLES as f64;
        let mut samples: Vec<f64> = (0..=VALIDITY_SAMPLES).map(|i| lo + i as f64 * h).collect();
        samples.extend([range.t_min, range.t_max]);
        // Scale for "zero" derivative: the guide's size.
        let span = (guide.point(hi) - guide.point(lo)).norm().max(1.0);
        for &t in &samples {
            let p = guide.point(t);
            let d1 = guide.d1(t);
            let d2 = guide.d2(t);
            if !p
                .coords
                .iter()
                .chain(d1.iter())
                .chain(d2.iter())
                .all(|c| c.is_finite())
            {
                return Err(GeometryError::NonFinite {
                    what: "guide curve or its derivatives",
                    t,
                });
            }
            if d1.norm() * (hi - lo) <= ZERO_SPEED_REL * span {
                return Err(GeometryError::ZeroDerivative { t });
            }
            let a = profile.radius(t);
            let da = profile.radius_derivative(t);
            if !a.is_finite() || !da.is_finite() {
                return Err(GeometryError::NonFinite {
                    what: "profile radius A(t) or dA/dt",
                    t,
                });
            }
            if a <= 0.0 {
                return Err(GeometryError::NonPositiveRadius { t, radius: a });
            }
            let kappa = guide.curvature(t);
            if kappa * a >= 1.0 {
                return Err(GeometryError::Folds {
                    t,
                    radius: a,
                    radius_of_curvature: 1.0 / kappa,
                });
            }
        }
        let frames = FrameField::new(guide.as_ref(), frame_method, lo, hi, frame_reference)?;
        let mut arc_table = Vec::with_capacity(VALIDITY_SAMPLES + 1);
        arc_table.push(0.0);
        for i in 0..VALIDITY_SAMPLES {
            let a = lo + i as f64 * h;
            let ds = math::gauss_legendre(|t| guide.d1(t).norm(), a, a + h, 1);
            arc_table.push(arc_table[i] + ds);
        }
        Ok(Self {
            guide,
            frames,
            profile,
            range,
            arc_table,
            arc_h: h,
        })
    }

    /// The guide curve.
    pub fn guide(&self) -> &dyn GuideCurve {
        self.guide.as_ref()
    }

    /// The profile radius law.
    pub fn profile(&self) -> &ProfileLaw {
        &self.profile
    }

    /// The parameter range.
    pub fn range(&self) -> TubeRange {
        self.range
    }

    /// The frame method in use.
    pub fn frame_method(&self) -> FrameMethod {
        self.frames.method()
    }

    /// Guide frame `(T, N, B)` at `t` (part frame).
    pub fn frame(&self, t: f64) -> Frame {
        self.frames.frame(self.guide.as_ref(), t)
    }

    /// Profile radius `A(t)` (mm).
    pub fn radius(&self, t: f64) -> f64 {
        self.profile.radius(t)
    }

    /// Surface point `M(t, v)` (part frame, mm) [eq. 2.1].
    pub fn point(&self, t: f64, v: f64) -> Point3 {
        let (n, b) = self.frames.profile_basis(self.guide.as_ref(), t);
        let (s, c) = v.sin_cos();
        self.guide.point(t) + (n * c + b * s) * self.profile.radius(t)
    }

    /// Surface point with `∂M/∂t`, `∂M/∂v` and the outward unit normal
    /// (part frame) [eq. 2.33; the thesis's `n = ∂M/∂t × ∂M/∂v` is the
    /// inward normal with this parameterisation, we return its opposite].
    pub fn surface(&self, t: f64, v: f64) -> SurfacePoint {
        let g = self.guide.as_ref();
        let f = self.frame(t);
        let (s, c) = v.sin_cos();
        let e = f.normal * c + f.binormal * s;
        let a = self.profile.radius(t);
        let da = self.profile.radius_derivative(t);
        let d1 = g.d1(t);
        let d2 = g.d2(t);
        let speed = d1.norm();
        // dT/dt = (Mg'' - (Mg''·T) T) / |Mg'|
        let dtan = (d2 - f.tangent * d2.dot(&f.tangent)) / speed;
        let twist = self.frames.twist_rate(g, t);
        let t_cross_e = f.tangent.cross(&e);
        let d_dt = d1 + e * da - f.tangent * (a * dtan.dot(&e)) + t_cross_e * (a * twist);
        let d_dv = t_cross_e * a;
        let normal = UnitVector3::new_normalize(d_dv.cross(&d_dt));
        SurfacePoint {
            position: g.point(t) + e * a,
            d_dt,
            d_dv,
            normal,
        }
    }

    /// Outward unit normal at `(t, v)` (part frame).
    pub fn normal(&self, t: f64, v: f64) -> UnitVector3 {
        self.surface(t, v).normal
    }

    /// Points of the iso-`v` line (a generatrix) at the given parameters.
    pub fn iso_v(&self, v: f64, ts: &[f64]) -> Vec<Point3> {
        ts.iter().map(|&t| self.point(t, v)).collect()
    }

    /// `n` points of the iso-`t` line (the profile circle at `t`), `v = 2πk/n`.
    pub fn iso_t(&self, t: f64, n: usize) -> Vec<Point3> {
        (0..n)
            .map(|k| self.point(t, std::f64::consts::TAU * k as f64 / n as f64))
            .collect()
    }

    /// Guide arc length from `t_min` to `t` (mm, negative below `t_min`)
    /// [eq. 2.26], from a table built once.
    pub fn arc_length(&self, t: f64) -> f64 {
        self.arc_from_eval_min(t) - self.arc_from_eval_min(self.range.t_min)
    }

    fn arc_from_eval_min(&self, t: f64) -> f64 {
        let lo = self.range.eval_min();
        let last = self.arc_table.len() - 1;
        let x = ((t - lo) / self.arc_h).floor();
        let i = if x.is_finite() {
            x.clamp(0.0, last as f64) as usize
        } else {
            0
        };
        let a = lo + i as f64 * self.arc_h;
        self.arc_table[i] + math::gauss_legendre(|u| self.guide.d1(u).norm(), a, t, 1)
    }

    /// The parameter `t` whose guide arc length from `t_min` is `s` (mm).
    pub fn t_at_arc_length(&self, s: f64) -> f64 {
        let target = s + self.arc_from_eval_min(self.range.t_min);
        let i = self
            .arc_table
            .partition_point(|&x| x <= target)
            .saturating_sub(1)
            .min(self.arc_table.len() - 2);
        let lo = self.range.eval_min();
        let mut t = lo + (i as f64 + 0.5) * self.arc_h;
        for _ in 0..50 {
            let f = self.arc_from_eval_min(t) - target;
            let step = f / self.guide.d1(t).norm();
            t -= step;
            if step.abs() < ARC_STEP_REL_TOL * (1.0 + t.abs()) {
                break;
            }
        }
        t
    }
}
