//! Rules that set the tool axis point by point, the projection of build
//! directions into a plane, and the smoothing of tool axes along a layer
//! [SPEC §4; thesis eq. 3.20–3.21, §3.3.1]. Angles in rad, lengths in mm,
//! part frame.

use super::lead_tilt::tool_axis;
use super::{LocalFrame, ToolAxisError};
use crate::math::{self, tol, Point3, Vector3};
use crate::path::Path;
use serde::{Deserialize, Serialize};

/// Slack on the cosine test of the cone rule (unitless): an axis this close
/// to the cone's edge is inside and left unchanged.
const CONE_COS_SLACK: f64 = 1e-15;
/// The lean rule's angle is clamped this far inside ±π/2 (rad) so that its
/// tangent stays finite.
const TAN_CLAMP_MARGIN_RAD: f64 = 1e-6;
/// Two unit axes closer than this (rad) are the same: [`slerp`] returns the
/// target unchanged.
const SAME_DIRECTION_RAD: f64 = 1e-15;
/// A lead or tilt angle changed by more than this (rad) by the envelope
/// smoothing counts as moved.
const LEAD_TILT_MOVED_RAD: f64 = 1e-15;
/// Relative slack on the axis-rate bound: a rate within `1 + RATE_SLACK_REL`
/// times the bound meets it (rounding of the angle and length).
const RATE_SLACK_REL: f64 = 1e-9;
/// The rate relaxation aims this fraction below the bound (relative), so a
/// corrected pair lands inside it despite rounding.
const RATE_TARGET_MARGIN_REL: f64 = 1e-6;

/// How the lead/tilt angles of each point are chosen.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case", tag = "kind")]
pub enum AxisRule {
    /// The constant angles of the options everywhere.
    #[default]
    None,
    /// The tool axis never leans more than `max_angle_rad` from `axis` (part
    /// frame): where it would, the tilt `theta_t` is changed so that it leans
    /// exactly `max_angle_rad` (the lead is kept). The thesis's rule for the
    /// hemisphere top is `axis = Z`, 50° (eq. 3.20–3.21, whose printed
    /// inequality is garbled: as printed it would tilt the axes that are
    /// already within 50°).
    MaxAngleFromAxis {
        /// The cone axis (part frame, need not be unit).
        axis: [f64; 3],
        /// The cone half-angle (rad, in (0, π/2)).
        max_angle_rad: f64,
    },
    /// Given `(theta_n, theta_t)` (rad) per point, `angles[layer][point]`,
    /// replacing the constants.
    PerPoint {
        /// Lead and tilt per point.
        angles: Vec<Vec<[f64; 2]>>,
    },
}

/// What a rule decided at one point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RuleOutcome {
    /// Lead `theta_n` (rad).
    pub lead_rad: f64,
    /// Tilt `theta_t` (rad).
    pub tilt_rad: f64,
    /// Whether the rule changed the angles.
    pub active: bool,
    /// Whether the rule's target was met (false: best effort).
    pub reached: bool,
}

impl AxisRule {
    /// The thesis's 50° rule: `T` within 50° of the part's +Z (eq. 3.20–3.21).
    pub fn thesis_50_deg() -> Self {
        AxisRule::MaxAngleFromAxis {
            axis: [0.0, 0.0, 1.0],
            max_angle_rad: 50f64.to_radians(),
        }
    }

    /// Checks the rule's own numbers.
    ///
    /// # Errors
    /// [`ToolAxisError::InvalidOption`] naming the field.
    pub fn validate(&self) -> Result<(), ToolAxisError> {
        let bad = |field: &'static str, reason: String| {
            Err(ToolAxisError::InvalidOption { field, reason })
        };
        match self {
            AxisRule::None => Ok(()),
            AxisRule::MaxAngleFromAxis {
                axis,
                max_angle_rad,
            } => {
                let a = Vector3::from(*axis);
                if !(a.iter().all(|c| c.is_finite()) && a.norm() > 0.0) {
                    return bad(
                        "rule.axis",
                        format!("must be finite and non-zero, got {axis:?}"),
                    );
                }
                if !(*max_angle_rad > 0.0 && *max_angle_rad < std::f64::consts::FRAC_PI_2) {
                    return bad(
                        "rule.max_angle_rad",
                        format!("must be in (0, π/2), got {max_angle_rad}"),
                    );
                }
                Ok(())
            }
            AxisRule::PerPoint { angles } => {
                for (li, l) in angles.iter().enumerate() {
                    for (pi, a) in l.iter().enumerate() {
                        if !a
                            .iter()
                            .all(|x| x.is_finite() && x.abs() < std::f64::consts::FRAC_PI_2)
                        {
                            return bad(
                                "rule.angles",
                                format!(
                                    "layer {li}, point {pi}: angles must be finite and within (-π/2, π/2), got {a:?}"
                                ),
                            );
                        }
                    }
                }
                Ok(())
            }
        }
    }

    /// The angles at point `(layer, point)` of a frame, given the constant
    /// angles of the options.
    pub fn apply(
        &self,
        frame: &LocalFrame,
        lead_rad: f64,
        tilt_rad: f64,
        layer: usize,
        point: usize,
    ) -> RuleOutcome {
        let unchanged = RuleOutcome {
            lead_rad,
            tilt_rad,
            active: false,
            reached: true,
        };
        match self {
            AxisRule::None => unchanged,
            AxisRule::PerPoint { angles } => {
                let [lead_rad, tilt_rad] = angles[layer][point];
                RuleOutcome {
                    lead_rad,
                    tilt_rad,
                    active: true,
                    reached: true,
                }
            }
            AxisRule::MaxAngleFromAxis {
                axis,
                max_angle_rad,
            } => {
                let a = Vector3::from(*axis).normalize();
                let t0 = tool_axis(frame, lead_rad, tilt_rad);
                let cos_max = max_angle_rad.cos();
                if t0.dot(&a) >= cos_max - CONE_COS_SLACK {
                    return unchanged;
                }
                match tilt_into_cone(frame, lead_rad, tilt_rad, &a, cos_max) {
                    Ok(tilt) => RuleOutcome {
                        lead_rad,
                        tilt_rad: tilt,
                        active: true,
                        reached: true,
                    },
                    Err(best) => RuleOutcome {
                        lead_rad,
                        tilt_rad: best,
                        active: true,
                        reached: false,
                    },
                }
            }
        }
    }
}

/// The tilt `theta_t` (rad) closest to `tilt_rad` that puts the tool axis at
/// exactly `acos(cos_max)` from the unit `axis`, keeping the lead. In the
/// normal plane `T(psi) = cos psi û + sin psi n` with `û ∝ b + tan(theta_n) t`
/// and `tan theta_t = |b + tan(theta_n) t| tan psi`; `axis · T(psi) =
/// rho cos(psi − phi)`. `Err(best tilt)` when the cone cannot be reached by
/// tilting alone.
fn tilt_into_cone(
    frame: &LocalFrame,
    lead_rad: f64,
    tilt_rad: f64,
    axis: &Vector3,
    cos_max: f64,
) -> Result<f64, f64> {
    let u = frame.build + frame.tangent * lead_rad.tan();
    let l = u.norm();
    let uh = u / l;
    let (au, an) = (axis.dot(&uh), axis.dot(&frame.normal));
    let rho = au.hypot(an);
    let phi = an.atan2(au);
    let lim = std::f64::consts::FRAC_PI_2 - TAN_CLAMP_MARGIN_RAD;
    let to_tilt = |psi: f64| (l * psi.clamp(-lim, lim).tan()).atan();
    if rho < cos_max {
        return Err(to_tilt(phi));
    }
    let psi0 = (tilt_rad.tan() / l).atan();
    let d = (cos_max / rho).clamp(-1.0, 1.0).acos();
    let psi = [phi - d, phi + d]
        .into_iter()
        .filter(|p| p.abs() < lim)
        .min_by(|x, y| (x - psi0).abs().total_cmp(&(y - psi0).abs()));
    match psi {
        Some(p) => Ok(to_tilt(p)),
        None => Err(to_tilt(phi)),
    }
}

/// Checks that per-point data has the shape of `path.layers`.
pub(crate) fn check_shape(
    path: &Path,
    lens: impl Iterator<Item = usize>,
) -> Result<(), ToolAxisError> {
    let lens: Vec<usize> = lens.collect();
    for (li, l) in path.layers.iter().enumerate() {
        let got = lens.get(li).copied().unwrap_or(0);
        if got != l.points.len() {
            return Err(ToolAxisError::ShapeMismatch {
                layer: li,
                frames: got,
                points: l.points.len(),
            });
        }
    }
    if lens.len() > path.layers.len() {
        return Err(ToolAxisError::ShapeMismatch {
            layer: path.layers.len(),
            frames: lens[path.layers.len()],
            points: 0,
        });
    }
    Ok(())
}

/// Projects every build direction into the plane of unit normal `p`
/// (thesis §3.3.1) and re-orthonormalises `t` and `n` against it; the tool
/// axis is reset to the projected `b`. A `b` within `full_rad` of the plane
/// is projected fully; beyond it, at an angle `α` from the plane, it is left
/// at `π/2 · (α - full_rad) / (π/2 - full_rad)` from the plane, toward `b`
/// (so `full_rad = π/2` projects fully everywhere). A `b` along `p` is left
/// as is.
pub(crate) fn project_build(frames: &mut [Vec<LocalFrame>], p: &Vector3, full_rad: f64) {
    use std::f64::consts::FRAC_PI_2;
    for f in frames.iter_mut().flatten() {
        let along = f.build.dot(p);
        let b = f.build - p * along;
        if b.norm() < tol::ANGLE_RAD {
            continue;
        }
        let alpha = along.abs().min(1.0).asin();
        let b = if alpha <= full_rad {
            b.normalize()
        } else {
            let left = FRAC_PI_2 * (alpha - full_rad) / (FRAC_PI_2 - full_rad);
            b.normalize() * left.cos() + p * (left.sin() * along.signum())
        };
        let b = b.normalize();
        let t = f.tangent - b * f.tangent.dot(&b);
        let t = if t.norm() > tol::ANGLE_RAD {
            t.normalize()
        } else {
            math::any_perpendicular(&b)
        };
        let n = f.normal - b * f.normal.dot(&b) - t * f.normal.dot(&t);
        let n = if n.norm() > tol::ANGLE_RAD {
            n.normalize()
        } else {
            b.cross(&t)
        };
        *f = LocalFrame {
            tangent: t,
            normal: n,
            build: b,
            tool: b,
        };
    }
}

/// Angle (rad) between two unit vectors, robust near 0 and π.
pub(crate) fn angle(a: &Vector3, b: &Vector3) -> f64 {
    a.cross(b).norm().atan2(a.dot(b))
}

/// Rotates unit `a` toward unit `b` by `fraction` of the angle between them.
pub(crate) fn slerp(a: &Vector3, b: &Vector3, fraction: f64) -> Vector3 {
    let theta = angle(a, b);
    if theta < SAME_DIRECTION_RAD {
        return *b;
    }
    let mut k = a.cross(b);
    if k.norm() < tol::DEGENERATE {
        k = math::any_perpendicular(a);
    }
    let k = k.normalize();
    let r = super::lead_tilt::rodrigues(&k, theta * fraction);
    (r * a).normalize()
}

/// Largest angular rate of consecutive axes (rad/mm); pairs of coincident
/// points are skipped.
pub fn max_rate(positions: &[Point3], axes: &[Vector3], closed: bool) -> f64 {
    max_pair_rate(positions, closed, |i, j| angle(&axes[i], &axes[j]))
}

/// Smooths the lead/tilt angles `(theta_n, theta_t)` (rad) of a layer so that
/// they change by at most `max_rate_rad_per_mm` per mm of path between any
/// two points (Euclidean norm of the angle pair; distances along the layer,
/// wrapping on a closed layer). Each angle is replaced by the mean of its
/// lower and upper Lipschitz envelopes, `(min_j (x_j + L d_ij) + max_j (x_j −
/// L d_ij)) / 2` with `L = rate / √2`: both are `L`-Lipschitz, so is their
/// mean, it is exact in one pass and leaves an already smooth field alone.
/// Returns the number of points whose angles moved.
pub fn smooth_angles(
    positions: &[Point3],
    angles: &mut [(f64, f64)],
    closed: bool,
    max_rate_rad_per_mm: f64,
) -> usize {
    let n = angles.len();
    if n < 2 {
        return 0;
    }
    let mut s = vec![0.0; n];
    for i in 1..n {
        s[i] = s[i - 1] + (positions[i] - positions[i - 1]).norm();
    }
    let total = s[n - 1]
        + if closed {
            (positions[0] - positions[n - 1]).norm()
        } else {
            0.0
        };
    let dist = |i: usize, j: usize| {
        let d = (s[i] - s[j]).abs();
        if closed {
            d.min(total - d)
        } else {
            d
        }
    };
    let l = max_rate_rad_per_mm / std::f64::consts::SQRT_2;
    let envelope = |x: &[f64]| -> Vec<f64> {
        (0..n)
            .map(|i| {
                let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
                for (j, xj) in x.iter().enumerate() {
                    let d = l * dist(i, j);
                    lo = lo.min(xj + d);
                    hi = hi.max(xj - d);
                }
                0.5 * (lo + hi)
            })
            .collect()
    };
    let lead: Vec<f64> = angles.iter().map(|a| a.0).collect();
    let tilt: Vec<f64> = angles.iter().map(|a| a.1).collect();
    let (lead, tilt) = (envelope(&lead), envelope(&tilt));
    let mut moved = 0;
    for (a, (ln, tn)) in angles.iter_mut().zip(lead.into_iter().zip(tilt)) {
        if (a.0 - ln).abs() > LEAD_TILT_MOVED_RAD || (a.1 - tn).abs() > LEAD_TILT_MOVED_RAD {
            moved += 1;
        }
        *a = (ln, tn);
    }
    moved
}

/// Largest rate of change of the lead/tilt pair between consecutive points
/// (rad/mm, Euclidean norm of the pair).
pub fn max_angle_rate(positions: &[Point3], angles: &[(f64, f64)], closed: bool) -> f64 {
    max_pair_rate(positions, closed, |i, j| {
        (angles[j].0 - angles[i].0).hypot(angles[j].1 - angles[i].1)
    })
}

/// Largest `change(i, j) / |p_j − p_i|` over consecutive points (wrapping when
/// `closed`); pairs of coincident points are skipped.
fn max_pair_rate(positions: &[Point3], closed: bool, change: impl Fn(usize, usize) -> f64) -> f64 {
    let n = positions.len();
    let pairs = if closed && n > 2 {
        n
    } else {
        n.saturating_sub(1)
    };
    (0..pairs)
        .filter_map(|i| {
            let j = (i + 1) % n;
            let d = (positions[j] - positions[i]).norm();
            (d > tol::ZERO_LENGTH_MM).then(|| change(i, j) / d)
        })
        .fold(0.0, f64::max)
}

/// Smooths unit tool axes along a layer in absolute terms (best effort) so that the angle between consecutive
/// axes is at most `max_rate_rad_per_mm` times their distance (mm): around
/// each pair over the bound, the axes of the narrowest symmetric window whose
/// end axes can be joined within the bound are put on the great-circle arc
/// joining them (evenly in path length); pairs still violating the bound get
/// symmetric relaxation (at most 2000 sweeps), wrapping on a closed layer. Rotating toward a neighbour stays inside any cone of half-angle
/// < 90° holding both (so the 50° rule survives). Returns the number of
/// axes moved.
///
/// The bound must be feasible: the axes of a closed layer that lean `a` from
/// the part's axis turn by about `sin(a) / rho` rad/mm around a part of radius
/// `rho`; below that the sweeps stop after their budget with the bound
/// unmet — check [`max_rate`] (reported by [`super::tool_axes`]).
pub fn smooth_layer(
    positions: &[Point3],
    axes: &mut [Vector3],
    closed: bool,
    max_rate_rad_per_mm: f64,
) -> usize {
    let n = axes.len();
    if n < 2 {
        return 0;
    }
    let original: Vec<Vector3> = axes.to_vec();
    // Symmetric windows first: around the worst pair still over the bound,
    // widen a window one point each side until the great-circle arc from its
    // first to its last axis, spread over the path length between them,
    // meets the bound, and put the inside on that arc. A jump (the cusp of a
    // constant-distance layer) is thus split evenly before and after it.
    let m = n as isize;
    let wrap = |i: isize| -> usize { i.rem_euclid(m) as usize };
    let mut s = vec![0.0; n + 1];
    for i in 1..=n {
        s[i] = s[i - 1] + (positions[i % n] - positions[i - 1]).norm();
    }
    // Path length from index a to b (a <= b, unwrapped indices).
    let length = |a: isize, b: isize| -> f64 {
        let (ta, tb) = (a.div_euclid(m), b.div_euclid(m));
        let (ia, ib) = (wrap(a), wrap(b));
        s[ib] - s[ia] + (tb - ta) as f64 * s[n]
    };
    let pairs = if closed && n > 2 { n } else { n - 1 };
    for _ in 0..n {
        let mut worst = None;
        let mut worst_excess = 1.0 + RATE_SLACK_REL;
        for i in 0..pairs {
            let j = (i + 1) % n;
            let d = (positions[j] - positions[i]).norm();
            if d > tol::ZERO_LENGTH_MM {
                let excess = angle(&axes[i], &axes[j]) / (max_rate_rad_per_mm * d);
                if excess > worst_excess {
                    worst_excess = excess;
                    worst = Some(i as isize);
                }
            }
        }
        let Some(i) = worst else { break };
        let (mut a, mut b) = (i, i + 1);
        let fits = |a: isize, b: isize| {
            angle(&axes[wrap(a)], &axes[wrap(b)]) <= max_rate_rad_per_mm * length(a, b)
        };
        while !fits(a, b) {
            let (can_down, can_up) = if closed {
                (b - a + 2 < m, b - a + 1 < m)
            } else {
                (a > 0, b < m - 1)
            };
            match (can_down, can_up) {
                (true, true) => {
                    a -= 1;
                    b += 1;
                }
                (true, false) => a -= 1,
                (false, true) => b += 1,
                (false, false) => break,
            }
        }
        let total = length(a, b);
        if !(fits(a, b) && total > 0.0) {
            break; // the bound cannot be met here; the relaxation below does its best
        }
        let (first, last) = (axes[wrap(a)], axes[wrap(b)]);
        for k in a + 1..b {
            axes[wrap(k)] = slerp(&first, &last, length(a, k) / total);
        }
    }
    for _ in 0..2000 {
        if max_rate(positions, axes, closed) <= max_rate_rad_per_mm * (1.0 + RATE_SLACK_REL) {
            break;
        }
        for i in 0..pairs {
            let j = (i + 1) % n;
            let d = (positions[j] - positions[i]).norm();
            let target = max_rate_rad_per_mm * d * (1.0 - RATE_TARGET_MARGIN_REL);
            let a = angle(&axes[i], &axes[j]);
            if a > target && a > 0.0 {
                let (ai, aj) = (axes[i], axes[j]);
                let f = 0.5 * (a - target) / a;
                axes[i] = slerp(&ai, &aj, f);
                axes[j] = slerp(&aj, &ai, f);
            }
        }
    }
    axes.iter()
        .zip(&original)
        .filter(|(a, o)| angle(a, o) > tol::AXIS_MOVED_RAD)
        .count()
}
