//! Shared helpers: a small deterministic RNG and comparisons.

use waam_slicer::math::{Isometry3, Vector3};
use waam_slicer::robot::{Joints, RobotModel};

/// SplitMix64: deterministic, dependency-free.
pub struct Rng(u64);

impl Rng {
    pub fn new(seed: u64) -> Self {
        Self(seed)
    }
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    /// Uniform in [0, 1).
    pub fn uniform(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }
    pub fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.uniform()
    }
    /// Standard normal (Box–Muller).
    pub fn normal(&mut self) -> f64 {
        let u1 = self.uniform().max(1e-300);
        let u2 = self.uniform();
        (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()
    }
    /// Random unit vector.
    pub fn unit(&mut self) -> Vector3 {
        loop {
            let v = Vector3::new(self.normal(), self.normal(), self.normal());
            if v.norm() > 1e-6 {
                return v.normalize();
            }
        }
    }
    /// Random joints inside the travel (unlimited joints in ±180°).
    pub fn joints(&mut self, robot: &RobotModel) -> Joints {
        std::array::from_fn(|j| {
            let l = robot.limits[j];
            let lo = l.lower_rad.max(-std::f64::consts::PI);
            let hi = l.upper_rad.min(std::f64::consts::PI);
            let lo = if l.lower_rad.is_finite() {
                l.lower_rad
            } else {
                lo
            };
            let hi = if l.upper_rad.is_finite() {
                l.upper_rad
            } else {
                hi
            };
            self.range(lo, hi)
        })
    }
}

/// Position distance (mm) and rotation angle (rad) between two poses.
pub fn pose_error(a: &Isometry3, b: &Isometry3) -> (f64, f64) {
    let dp = (a.translation.vector - b.translation.vector).norm();
    // 2·|imaginary part| of the relative quaternion: accurate for tiny angles
    // (acos-based angles are not below ~1e-8)
    let rel = a.rotation.inverse() * b.rotation;
    let dr = 2.0 * rel.imag().norm().atan2(rel.w.abs());
    (dp, dr)
}

/// Largest joint difference modulo 2π (rad).
pub fn joint_error(a: &Joints, b: &Joints) -> f64 {
    (0..6)
        .map(|j| {
            let d = a[j] - b[j];
            (d - std::f64::consts::TAU * (d / std::f64::consts::TAU).round()).abs()
        })
        .fold(0.0, f64::max)
}

/// The three arms of the crate.
pub fn arms() -> Vec<RobotModel> {
    vec![
        RobotModel::arcmate_120ic_nominal(),
        RobotModel::arcmate_120ic_random_motions(),
        RobotModel::kuka_kr16_2(),
        RobotModel::abb_irb2600_12_185(),
    ]
}
