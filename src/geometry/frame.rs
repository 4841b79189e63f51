//! Moving frames `(T, N, B)` along a guide curve (part frame, unitless):
//! rotation-minimising (double reflection, Wang et al. 2008; the default) or
//! Frenet (thesis eq. 2.24, undefined where the curvature vanishes).

use super::guide::GuideCurve;
use super::GeometryError;
use crate::math::{any_perpendicular, tol, Vector3};
use serde::{Deserialize, Serialize};

/// Curvature (1/mm) below which the Frenet frame is undefined: the principal
/// normal of a straight stretch is rounding noise.
const FRENET_MIN_CURVATURE_PER_MM: f64 = 1e-9;

/// How the profile's `v = 0` direction is carried along the guide.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
pub enum FrameMethod {
    /// Rotation-minimising frame (no twist about the tangent), built by the
    /// double-reflection method. Defined on any regular curve.
    #[default]
    #[serde(rename = "rmf")]
    RotationMinimising,
    /// Frenet frame: `N` toward the centre of curvature. Undefined on straight
    /// segments; flips at inflection points.
    #[serde(rename = "frenet")]
    Frenet,
}

/// An orthonormal right-handed frame at one point of the guide (part frame).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Frame {
    /// Unit tangent `T` (direction of increasing `t`).
    pub tangent: Vector3,
    /// Unit normal `N`: the profile direction `v = 0`.
    pub normal: Vector3,
    /// Unit binormal `B = T × N`: the profile direction `v = π/2`.
    pub binormal: Vector3,
}

/// Number of tabulation intervals for the rotation-minimising frame.
const RMF_INTERVALS: usize = 4096;

/// A frame field along a guide curve over a parameter range, tabulated once.
#[derive(Debug, Clone)]
pub struct FrameField {
    method: FrameMethod,
    t_lo: f64,
    h: f64,
    /// RMF normals at `t_lo + i h` (empty for Frenet).
    normals: Vec<Vector3>,
    /// Their derivatives `dN/dt = -(T'·N) T` (for Hermite interpolation).
    slopes: Vec<Vector3>,
    /// RMF binormals `B = T × N` at the same samples, and their derivatives
    /// `dB/dt = -(T'·B) T` (for the fast profile basis).
    binormals: Vec<Vector3>,
    /// Derivatives of the binormals.
    binormal_slopes: Vec<Vector3>,
}

impl FrameField {
    /// Builds the frame field on `[t_lo, t_hi]`.
    ///
    /// `reference` (part frame) fixes the RMF's `v = 0` direction at `t_lo`: its
    /// component perpendicular to the tangent. Without it, the Frenet normal at
    /// `t_lo` is used where defined, else the world axis least aligned with the
    /// tangent (X for a vertical guide).
    ///
    /// # Errors
    /// [`GeometryError::FrenetUndefined`] naming the first sampled `t` where the
    /// curvature vanishes (Frenet only); [`GeometryError::InvalidField`] if the
    /// reference is parallel to the tangent.
    pub fn new(
        curve: &dyn GuideCurve,
        method: FrameMethod,
        t_lo: f64,
        t_hi: f64,
        reference: Option<Vector3>,
    ) -> Result<Self, GeometryError> {
        let h = (t_hi - t_lo) / RMF_INTERVALS as f64;
        match method {
            FrameMethod::Frenet => {
                for i in 0..=RMF_INTERVALS {
                    let t = t_lo + i as f64 * h;
                    if frenet(curve, t).is_none() {
                        return Err(GeometryError::FrenetUndefined { t });
                    }
                }
                Ok(Self {
                    method,
                    t_lo,
                    h,
                    normals: Vec::new(),
                    slopes: Vec::new(),
                    binormals: Vec::new(),
                    binormal_slopes: Vec::new(),
                })
            }
            FrameMethod::RotationMinimising => {
                let t0 = unit(curve.d1(t_lo));
                let r0 = match reference {
                    Some(r) => {
                        let p = r - t0 * t0.dot(&r);
                        if !(p.norm() > tol::ANGLE_RAD * r.norm()) {
                            return Err(GeometryError::InvalidField {
                                field: "frame.reference".into(),
                                reason: "is parallel to the guide tangent at t_min".into(),
                            });
                        }
                        p.normalize()
                    }
                    None => frenet(curve, t_lo)
                        .map(|f| f.normal)
                        .unwrap_or_else(|| any_perpendicular(&t0)),
                };
                let mut normals = Vec::with_capacity(RMF_INTERVALS + 1);
                normals.push(r0);
                let mut r = r0;
                for i in 0..RMF_INTERVALS {
                    let ta = t_lo + i as f64 * h;
                    r = reflect_step(curve, ta, ta + h, r);
                    normals.push(r);
                }
                let slopes = normals
                    .iter()
                    .enumerate()
                    .map(|(i, n)| rmf_slope(curve, t_lo + i as f64 * h, n))
                    .collect();
                let binormals: Vec<Vector3> = normals
                    .iter()
                    .enumerate()
                    .map(|(i, n)| unit(curve.d1(t_lo + i as f64 * h)).cross(n))
                    .collect();
                let binormal_slopes = binormals
                    .iter()
                    .enumerate()
                    .map(|(i, b)| rmf_slope(curve, t_lo + i as f64 * h, b))
                    .collect();
                Ok(Self {
                    method,
                    t_lo,
                    h,
                    normals,
                    slopes,
                    binormals,
                    binormal_slopes,
                })
            }
        }
    }

    /// The frame method.
    pub fn method(&self) -> FrameMethod {
        self.method
    }

    /// Frame at parameter `t`. Outside the tabulated range the RMF is carried
    /// on from the nearest end in steps no longer than the table's.
    pub fn frame(&self, curve: &dyn GuideCurve, t: f64) -> Frame {
        match self.method {
            FrameMethod::Frenet => frenet(curve, t).unwrap_or_else(|| {
                // Only reached outside the validated range: fall back to any frame.
                let tan = unit(curve.d1(t));
                let n = any_perpendicular(&tan);
                Frame {
                    tangent: tan,
                    normal: n,
                    binormal: tan.cross(&n),
                }
            }),
            FrameMethod::RotationMinimising => {
                let last = self.normals.len() - 1;
                let x = (t - self.t_lo) / self.h;
                let tan = unit(curve.d1(t));
                let r = if x.is_finite() && x >= 0.0 && x <= last as f64 {
                    // Inside the table: cubic Hermite on the tabulated normals and
                    // their exact derivatives (error O(h^4)).
                    let i = (x.floor() as usize).min(last - 1);
                    let s = x - i as f64;
                    let (s2, s3) = (s * s, s * s * s);
                    let h00 = 2.0 * s3 - 3.0 * s2 + 1.0;
                    let h10 = s3 - 2.0 * s2 + s;
                    let h01 = -2.0 * s3 + 3.0 * s2;
                    let h11 = s3 - s2;
                    self.normals[i] * h00
                        + self.slopes[i] * (h10 * self.h)
                        + self.normals[i + 1] * h01
                        + self.slopes[i + 1] * (h11 * self.h)
                } else {
                    // Outside: carry the nearest end on by double reflection.
                    let i = if x.is_finite() && x > 0.0 { last } else { 0 };
                    let mut ta = self.t_lo + i as f64 * self.h;
                    let mut r = self.normals[i];
                    let steps = ((t - ta).abs() / self.h).ceil().clamp(1.0, 1e6) as usize;
                    let dt = (t - ta) / steps as f64;
                    for _ in 0..steps {
                        r = reflect_step(curve, ta, ta + dt, r);
                        ta += dt;
                    }
                    r
                };
                let n = (r - tan * tan.dot(&r)).normalize();
                Frame {
                    tangent: tan,
                    normal: n,
                    binormal: tan.cross(&n),
                }
            }
        }
    }

    /// The profile basis `(N, B)` at `t` without evaluating the guide's
    /// derivative: inside the RMF table both are Hermite-interpolated and
    /// re-orthonormalised (error O(h⁴), ~1e-13 here). Elsewhere, and for
    /// Frenet frames, the same as [`FrameField::frame`].
    pub fn profile_basis(&self, curve: &dyn GuideCurve, t: f64) -> (Vector3, Vector3) {
        let last = self.normals.len().saturating_sub(1);
        let x = (t - self.t_lo) / self.h;
        if self.method == FrameMethod::RotationMinimising
            && x.is_finite()
            && x >= 0.0
            && x <= last as f64
        {
            let i = (x.floor() as usize).min(last - 1);
            let s = x - i as f64;
            let (s2, s3) = (s * s, s * s * s);
            let h00 = 2.0 * s3 - 3.0 * s2 + 1.0;
            let h10 = (s3 - 2.0 * s2 + s) * self.h;
            let h01 = -2.0 * s3 + 3.0 * s2;
            let h11 = (s3 - s2) * self.h;
            let n = self.normals[i] * h00
                + self.slopes[i] * h10
                + self.normals[i + 1] * h01
                + self.slopes[i + 1] * h11;
            let b = self.binormals[i] * h00
                + self.binormal_slopes[i] * h10
                + self.binormals[i + 1] * h01
                + self.binormal_slopes[i + 1] * h11;
            let n = n.normalize();
            let b = (b - n * n.dot(&b)).normalize();
            return (n, b);
        }
        let f = self.frame(curve, t);
        (f.normal, f.binormal)
    }

    /// Rate of rotation of the frame about its own tangent, `ω·T` (rad per
    /// parameter unit): 0 for the RMF, `|Mg'| τ` for Frenet.
    pub fn twist_rate(&self, curve: &dyn GuideCurve, t: f64) -> f64 {
        match self.method {
            FrameMethod::RotationMinimising => 0.0,
            FrameMethod::Frenet => {
                let (d1, d2, d3) = (curve.d1(t), curve.d2(t), curve.d3(t));
                let c = d1.cross(&d2);
                let c2 = c.norm_squared();
                if c2 == 0.0 {
                    0.0
                } else {
                    d1.norm() * c.dot(&d3) / c2
                }
            }
        }
    }
}

fn unit(v: Vector3) -> Vector3 {
    let n = v.norm();
    if n > 0.0 {
        v / n
    } else {
        v
    }
}

/// Frenet frame at `t`, `None` where the curvature is below [`FRENET_MIN_CURVATURE_PER_MM`].
fn frenet(curve: &dyn GuideCurve, t: f64) -> Option<Frame> {
    let d1 = curve.d1(t);
    let d2 = curve.d2(t);
    let speed = d1.norm();
    let c = d1.cross(&d2);
    let cn = c.norm();
    if !(speed > 0.0)
        || !(cn / (speed * speed * speed) > FRENET_MIN_CURVATURE_PER_MM)
        || !cn.is_finite()
    {
        return None;
    }
    let tan = d1 / speed;
    let b = c / cn;
    Some(Frame {
        tangent: tan,
        normal: b.cross(&tan),
        binormal: b,
    })
}

/// `dN/dt = -(T'·N) T` of a rotation-minimising normal `n` at `t`.
fn rmf_slope(curve: &dyn GuideCurve, t: f64, n: &Vector3) -> Vector3 {
    let d1 = curve.d1(t);
    let d2 = curve.d2(t);
    let speed = d1.norm();
    let tan = d1 / speed;
    let dtan = (d2 - tan * d2.dot(&tan)) / speed;
    -tan * dtan.dot(n)
}

/// One double-reflection step carrying the normal `r` from `ta` to `tb`.
fn reflect_step(curve: &dyn GuideCurve, ta: f64, tb: f64, r: Vector3) -> Vector3 {
    let xa = curve.point(ta);
    let xb = curve.point(tb);
    let v1 = xb - xa;
    let c1 = v1.norm_squared();
    if !(c1 > 0.0) {
        return r;
    }
    let tan_a = unit(curve.d1(ta));
    let tan_b = unit(curve.d1(tb));
    let r_l = r - v1 * (2.0 / c1 * v1.dot(&r));
    let t_l = tan_a - v1 * (2.0 / c1 * v1.dot(&tan_a));
    let v2 = tan_b - t_l;
    let c2 = v2.norm_squared();
    if !(c2 > tol::DIV_FLOOR) {
        return r_l;
    }
    r_l - v2 * (2.0 / c2 * v2.dot(&r_l))
}
