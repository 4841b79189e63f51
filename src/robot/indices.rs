//! Performance indices of a pose: manipulability, dexterity, joint-limit
//! distance, positioning uncertainty. SPEC §6.5, thesis §1.4.2 eq. 1.4–1.8 and
//! §4.2.2 eq. 4.10–4.12.

use nalgebra::{Matrix3, Matrix6};

use crate::robot::model::{JointLimit, Joints};

/// Manipulability `sqrt(det(J Jᵀ))` [eq. 1.7] of a 6×6 Jacobian (units of J
/// multiplied: mm³ for a Jacobian in mm/rad and rad/rad). 0 at a singularity.
pub fn manipulability(j: &Matrix6<f64>) -> f64 {
    (j * j.transpose()).determinant().max(0.0).sqrt()
}

/// Singular values `(xi_min, xi_max)` of `J` with its linear rows divided by
/// `length_scale_mm` (pass 1 for the thesis's raw Jacobian in mm/rad and rad/rad).
pub fn singular_value_range(j: &Matrix6<f64>, length_scale_mm: f64) -> (f64, f64) {
    let mut js = *j;
    for r in 0..3 {
        for c in 0..6 {
            js[(r, c)] /= length_scale_mm;
        }
    }
    let sv = js.singular_values();
    let max = sv.max();
    let min = sv.min();
    (min, max)
}

/// Dexterity `xi_min / xi_max` [eq. 1.8]: inverse condition number of `J`
/// (linear rows divided by `length_scale_mm`), in `[0, 1]`: 0 at a
/// singularity, 1 isotropic. The thesis uses the raw Jacobian
/// (`length_scale_mm = 1`), whose values are of order 1e-3 for an arm of 1 m reach.
pub fn dexterity(j: &Matrix6<f64>, length_scale_mm: f64) -> f64 {
    let (min, max) = singular_value_range(j, length_scale_mm);
    if max > 0.0 {
        min / max
    } else {
        0.0
    }
}

/// Which joint-limit distance of thesis §1.4.2.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum LimitDistance {
    /// Liégeois [eq. 1.4]: `Σ ((q_j − q_mid_j)/(q_mid_j − q_max_j))²` (0 at mid-range, 1 per joint at a stop).
    Liegeois,
    /// Fournier [eq. 1.5]: `Σ ((q_j − q_mid_j)/Δq_j)²` with `Δq_j` the travel (0.25 per joint at a stop).
    Fournier,
    /// Klein [eq. 1.6]: `max |q_j − q_mid_j| / |Δq_j|` (0.5 at a stop).
    Klein,
}

/// Joint-limit distance `Γ(q)` [eq. 1.4–1.6], unitless. Unlimited joints
/// contribute 0.
pub fn joint_limit_distance(q: &Joints, limits: &[JointLimit; 6], kind: LimitDistance) -> f64 {
    let terms = (0..6).filter(|&j| !limits[j].is_unlimited()).map(|j| {
        let l = &limits[j];
        let dev = q[j] - l.mid_rad();
        match kind {
            LimitDistance::Liegeois => (dev / (l.mid_rad() - l.upper_rad)).powi(2),
            LimitDistance::Fournier => (dev / l.range_rad()).powi(2),
            LimitDistance::Klein => (dev / l.range_rad()).abs(),
        }
    });
    match kind {
        LimitDistance::Klein => terms.fold(0.0, f64::max),
        _ => terms.sum(),
    }
}

/// How eq. 4.10–4.12 are read.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum UncertaintyFormula {
    /// `I = sqrt(λ1 + λ2 + λ3)` (mm), `λ` the eigenvalues of the position
    /// covariance `C = J_v diag(sigma_j²) J_vᵀ`: the radius of the RMS
    /// uncertainty sphere. Dimensionally consistent.
    RootTrace,
    /// `I = sqrt(√λ1 + √λ2 + √λ3)` (mm^½): the square root of the sum of the
    /// ellipsoid's semi-axis lengths, which is what reproduces the thesis's
    /// figures (mean 0.0744 mm on the Ø600 circle at 1e-4° resolution, §4.2.2;
    /// this crate gets 0.0765 mm on its own reconstruction of that circle).
    ThesisSemiAxes,
}

/// Positioning uncertainty `I` [eq. 4.10–4.12] at the point whose Jacobian
/// is `j` (linear rows in mm/rad), for joint resolutions `sigma_rad` (rad).
///
/// Eq. 4.11 prints `D = diag(sigma_j)` and eq. 4.12 `I = sqrt(Σ|λ̃_j|)` with
/// `λ̃_j` called the semi-axis lengths; read literally that is dimensionally
/// inconsistent. Both readings that make sense are offered, see
/// [`UncertaintyFormula`]; `D` is the joint covariance `diag(sigma_j²)` in both.
pub fn positioning_uncertainty(
    j: &Matrix6<f64>,
    sigma_rad: &[f64; 6],
    formula: UncertaintyFormula,
) -> f64 {
    let jv = j.fixed_view::<3, 6>(0, 0);
    let mut c = Matrix3::zeros();
    for (k, s) in sigma_rad.iter().enumerate() {
        let col = jv.column(k);
        c += col * col.transpose() * (s * s);
    }
    let eig = c.symmetric_eigenvalues();
    match formula {
        UncertaintyFormula::RootTrace => eig.iter().map(|l| l.abs()).sum::<f64>().sqrt(),
        UncertaintyFormula::ThesisSemiAxes => {
            eig.iter().map(|l| l.abs().sqrt()).sum::<f64>().sqrt()
        }
    }
}
