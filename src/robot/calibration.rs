//! Geometric calibration of the segment lengths `d2, d3, d4, r4, r6` from
//! measured flange positions (robot base frame, mm) and joint readings (rad)
//! by least squares [thesis §3.2.2.3, eq. 3.17]. Gauss–Newton on the
//! position residuals (the flange position is linear in the lengths, so it
//! converges in one step; the loop guards against rounding), with the
//! residual statistics and the parameters' standard deviations.
//!
//! Eq. 3.17 minimises the *sum of distances*; this minimises the sum of
//! squared distances, whose optimum is the maximum-likelihood estimate for
//! Gaussian measurement noise and has a covariance. Both are reported.

use nalgebra::{DMatrix, DVector};
use serde::{Deserialize, Serialize};

use crate::math::{Point3, Vector3};
use crate::robot::kinematics::{rot_y, rot_z};
use crate::robot::model::{Joints, RobotModel};
use crate::robot::RobotError;

/// Default of [`CalibrationOptions::step_tolerance_mm`] (mm).
const DEFAULT_STEP_TOLERANCE_MM: f64 = 1e-10;
/// The identification Jacobian is rank deficient (a length is not
/// observable from the measurements) when its smallest singular value is
/// below this fraction of its largest (relative).
const RANK_REL_TOL: f64 = 1e-10;
/// Singular values below this are treated as zero by the least-squares step
/// (units of the Jacobian, mm per mm).
const SVD_SOLVE_EPS: f64 = 1e-14;

/// One measurement: joint readings and the measured flange position.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct CalibrationMeasurement {
    /// Joints as the controller reports them (rad).
    pub joints: Joints,
    /// Measured flange centre, robot base frame (mm).
    pub flange_position_mm: Point3,
}

/// Options of [`calibrate_lengths`]. Plain data.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct CalibrationOptions {
    /// Maximum Gauss–Newton iterations. Default 20.
    pub max_iterations: usize,
    /// Stop when the largest length update is below this (mm). Default 1e-10.
    pub step_tolerance_mm: f64,
}

impl Default for CalibrationOptions {
    fn default() -> Self {
        Self {
            max_iterations: 20,
            step_tolerance_mm: DEFAULT_STEP_TOLERANCE_MM,
        }
    }
}

/// Outcome of a calibration.
#[derive(Debug, Clone, PartialEq)]
pub struct CalibrationResult {
    /// Identified `[d2, d3, d4, r4, r6]` (mm).
    pub lengths_mm: [f64; 5],
    /// Their standard deviations (mm), from `s² (JᵀJ)⁻¹`.
    pub std_dev_mm: [f64; 5],
    /// Root mean square of the distances |M_th M_mes| (mm).
    pub rms_residual_mm: f64,
    /// Mean of the distances: eq. 3.17's objective divided by the count (mm).
    pub mean_distance_mm: f64,
    /// Largest distance (mm).
    pub max_distance_mm: f64,
    /// `s = sqrt(SSR / (3n − 5))`: estimated per-coordinate noise (mm).
    pub sigma_mm: f64,
    /// Gauss–Newton iterations done.
    pub iterations: usize,
    /// The initial model with the identified lengths.
    pub model: RobotModel,
}

/// Columns `d p / d [d2, d3, d4, r4, r6]` of the flange position at `q` (unitless).
fn position_gradient(model: &RobotModel, q: &Joints) -> [Vector3; 5] {
    let t = model.canonical_from_joints(q).0;
    let (s1, c1) = t[0].sin_cos();
    let (s2, c2) = t[1].sin_cos();
    let (s3, c3) = t[2].sin_cos();
    let rz = rot_z(s1, c1);
    let r_arm = rz * rot_y(s3, c3);
    let approach = {
        let (s4, c4) = t[3].sin_cos();
        let (s5, c5) = t[4].sin_cos();
        r_arm * Vector3::new(c5, s4 * s5, -c4 * s5)
    };
    [
        rz.column(0).into_owned(),
        rz * Vector3::new(s2, 0.0, c2),
        r_arm.column(2).into_owned(),
        r_arm.column(0).into_owned(),
        approach,
    ]
}

/// Identifies `[d2, d3, d4, r4, r6]` starting from `initial` (whose other
/// fields are kept) [eq. 3.17].
///
/// # Errors
/// [`RobotError::Calibration`] with fewer than 2 measurements, non-finite
/// data, or measurements that do not determine all five lengths.
pub fn calibrate_lengths(
    initial: &RobotModel,
    measurements: &[CalibrationMeasurement],
    opts: &CalibrationOptions,
) -> Result<CalibrationResult, RobotError> {
    let n = measurements.len();
    let err = |reason| RobotError::Calibration { reason, count: n };
    if n < 2 {
        return Err(err("at least 2 measurements are needed for 5 lengths"));
    }
    if measurements.iter().any(|m| {
        !(m.joints.iter().all(|v| v.is_finite())
            && m.flange_position_mm.iter().all(|v| v.is_finite()))
    }) {
        return Err(err("non-finite joint reading or measured position"));
    }
    let mut model = initial.clone();
    let mut iterations = 0;
    let mut jac = DMatrix::<f64>::zeros(3 * n, 5);
    let mut res = DVector::<f64>::zeros(3 * n);
    let fill = |model: &RobotModel, jac: &mut DMatrix<f64>, res: &mut DVector<f64>| {
        for (i, m) in measurements.iter().enumerate() {
            let p = model.flange_position(&m.joints);
            let r = m.flange_position_mm - p;
            let g = position_gradient(model, &m.joints);
            for k in 0..3 {
                res[3 * i + k] = r[k];
                for (c, gc) in g.iter().enumerate() {
                    jac[(3 * i + k, c)] = gc[k];
                }
            }
        }
    };
    for _ in 0..opts.max_iterations.max(1) {
        fill(&model, &mut jac, &mut res);
        let svd = jac.clone().svd(true, true);
        let smax = svd.singular_values.max();
        let smin = svd.singular_values.min();
        if smin.is_nan() || smin <= RANK_REL_TOL * smax {
            return Err(err(
                "the measurements do not determine all five lengths (rank-deficient)",
            ));
        }
        let step = svd
            .solve(&res, SVD_SOLVE_EPS)
            .map_err(|_| err("least-squares solve failed"))?;
        let mut l = model.geometry.segment_lengths();
        for k in 0..5 {
            l[k] += step[k];
        }
        model.geometry = model.geometry.with_segment_lengths(l);
        iterations += 1;
        if step.amax() < opts.step_tolerance_mm {
            break;
        }
    }
    fill(&model, &mut jac, &mut res);
    let dists: Vec<f64> = (0..n)
        .map(|i| Vector3::new(res[3 * i], res[3 * i + 1], res[3 * i + 2]).norm())
        .collect();
    let ssr: f64 = res.norm_squared();
    let dof = (3 * n).saturating_sub(5).max(1) as f64;
    let s2 = ssr / dof;
    let jtj = jac.transpose() * &jac;
    let cov = jtj
        .try_inverse()
        .ok_or_else(|| err("normal matrix not invertible"))?
        * s2;
    let std_dev_mm = std::array::from_fn(|k| cov[(k, k)].max(0.0).sqrt());
    Ok(CalibrationResult {
        lengths_mm: model.geometry.segment_lengths(),
        std_dev_mm,
        rms_residual_mm: (ssr / n as f64).sqrt(),
        mean_distance_mm: dists.iter().sum::<f64>() / n as f64,
        max_distance_mm: dists.iter().cloned().fold(0.0, f64::max),
        sigma_mm: s2.sqrt(),
        iterations,
        model,
    })
}

/// The joint readings of the thesis's random-motion design [§3.2.2.3]:
/// `q1 ∈ {-22.5°, 0}`, `q2, q3 ∈ {-22.5°, 0, 22.5°}`, `q4, q5, q6 ∈ {-45°, 0, 45°}`:
/// 2·3·3·27 = 486 joint vectors (rad).
pub fn thesis_random_motion_design() -> Vec<Joints> {
    let d = f64::to_radians;
    let mut out = Vec::with_capacity(486);
    for q1 in [-22.5, 0.0] {
        for q2 in [-22.5, 0.0, 22.5] {
            for q3 in [-22.5, 0.0, 22.5] {
                for q4 in [-45.0, 0.0, 45.0] {
                    for q5 in [-45.0, 0.0, 45.0] {
                        for q6 in [-45.0, 0.0, 45.0] {
                            out.push([d(q1), d(q2), d(q3), d(q4), d(q5), d(q6)]);
                        }
                    }
                }
            }
        }
    }
    out
}
