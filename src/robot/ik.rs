//! Analytic inverse kinematics: flange pose in the robot base frame (mm) →
//! controller joints (rad), in one of the eight configurations or all of
//! them. SPEC §6.2, thesis appendix C.2 (Paul's method: wrist-centre position
//! problem for J1..J3, then the orientation problem for J4..J6), re-derived
//! for the canonical chain of [`model`](crate::robot::model).
//!
//! Configurations follow FANUC's `CONFIG` string `'N U T, t1, t4, t6'`:
//! * wrist `N`/`F` ([`Wrist`]): no flip when the canonical `t5 > 0`
//!   (FANUC `J5 < 0`, the tool-down home posture of every vendor), flip otherwise;
//! * elbow `U`/`D` ([`Elbow`]): the elbow (J3 axis) above or below the line
//!   from the J2 axis to the wrist centre, seen from the side the arm reaches to;
//! * arm `T`/`B` ([`ArmSide`]): wrist centre in front of or behind the J1 axis.
//!
//! Unreachable poses and singular ones (wrist centre on the J1 axis, `J5 = 0`)
//! are [`RobotError`]s; no NaN leaves this module.

use std::f64::consts::{PI, TAU};
use std::fmt;

use serde::{Deserialize, Serialize};

use crate::math::{Isometry3, Matrix3, Vector3};
use crate::robot::kinematics::{rot_y, rot_z, CanonicalAngles};
use crate::robot::model::{Joints, RobotModel};
use crate::robot::RobotError;

/// Wrist flip (FANUC `N`/`F`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Wrist {
    /// `N`: canonical `t5 > 0` (FANUC `J5 < 0`).
    NoFlip,
    /// `F`: canonical `t5 < 0` (FANUC `J5 > 0`).
    Flip,
}

/// Elbow up or down (FANUC `U`/`D`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Elbow {
    /// `U`: elbow above the shoulder–wrist line.
    Up,
    /// `D`: elbow below it.
    Down,
}

/// Wrist centre in front of or behind the J1 axis (FANUC `T`/`B`; the
/// thesis's "épaule haut/bas").
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ArmSide {
    /// `T`: in front.
    Front,
    /// `B`: behind.
    Back,
}

/// One of the eight IK branches.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Configuration {
    /// `N`/`F`.
    pub wrist: Wrist,
    /// `U`/`D`.
    pub elbow: Elbow,
    /// `T`/`B`.
    pub side: ArmSide,
}

impl Configuration {
    /// FANUC `N U T`: no flip, elbow up, front — the usual working posture.
    pub const NUT: Self = Self {
        wrist: Wrist::NoFlip,
        elbow: Elbow::Up,
        side: ArmSide::Front,
    };

    /// All eight, in the order of [`Configuration::index`].
    pub const ALL: [Self; 8] = {
        let mut all = [Self::NUT; 8];
        let mut i = 0;
        while i < 8 {
            all[i] = Self::from_index(i);
            i += 1;
        }
        all
    };

    /// Index 0..8: bit 0 wrist flip, bit 1 elbow down, bit 2 back.
    pub const fn index(&self) -> usize {
        (matches!(self.wrist, Wrist::Flip) as usize)
            | ((matches!(self.elbow, Elbow::Down) as usize) << 1)
            | ((matches!(self.side, ArmSide::Back) as usize) << 2)
    }

    /// Inverse of [`Configuration::index`] (`i` taken modulo 8).
    pub const fn from_index(i: usize) -> Self {
        Self {
            wrist: if i & 1 == 0 {
                Wrist::NoFlip
            } else {
                Wrist::Flip
            },
            elbow: if i & 2 == 0 { Elbow::Up } else { Elbow::Down },
            side: if i & 4 == 0 {
                ArmSide::Front
            } else {
                ArmSide::Back
            },
        }
    }

    /// Parses FANUC's three letters (`"N U T"`, `"FDB"`, case-insensitive, spaces and commas ignored).
    pub fn from_fanuc(s: &str) -> Option<Self> {
        let letters: Vec<char> = s
            .chars()
            .filter(|c| !c.is_whitespace() && *c != ',')
            .map(|c| c.to_ascii_uppercase())
            .collect();
        if letters.len() != 3 {
            return None;
        }
        let wrist = match letters[0] {
            'N' => Wrist::NoFlip,
            'F' => Wrist::Flip,
            _ => return None,
        };
        let elbow = match letters[1] {
            'U' => Elbow::Up,
            'D' => Elbow::Down,
            _ => return None,
        };
        let side = match letters[2] {
            'T' => ArmSide::Front,
            'B' => ArmSide::Back,
            _ => return None,
        };
        Some(Self { wrist, elbow, side })
    }
}

impl fmt::Display for Configuration {
    /// FANUC letters, e.g. `N U T`.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let w = match self.wrist {
            Wrist::NoFlip => 'N',
            Wrist::Flip => 'F',
        };
        let e = match self.elbow {
            Elbow::Up => 'U',
            Elbow::Down => 'D',
        };
        let s = match self.side {
            ArmSide::Front => 'T',
            ArmSide::Back => 'B',
        };
        write!(f, "{w} {e} {s}")
    }
}

/// FANUC's full `CONFIG`: configuration letters plus the turn numbers of J1, J4, J6.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct FanucConfig {
    /// The branch.
    pub configuration: Configuration,
    /// Turn number of J1.
    pub turn_j1: i32,
    /// Turn number of J4.
    pub turn_j4: i32,
    /// Turn number of J6.
    pub turn_j6: i32,
}

impl fmt::Display for FanucConfig {
    /// `N U T, 0, 0, 1`.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{}, {}, {}, {}",
            self.configuration, self.turn_j1, self.turn_j4, self.turn_j6
        )
    }
}

/// Turn number of a joint value (rad): 0 on `(-180°, 180°]`, 1 on `(180°, 540°]`, -1 on `(-540°, -180°]`.
pub fn turn_number(q: f64) -> i32 {
    ((q - PI) / TAU).ceil() as i32
}

/// `q` wrapped to `(-π, π]` (rad).
#[inline]
pub fn wrap_pi(q: f64) -> f64 {
    let r = q - TAU * (q / TAU).round();
    if r <= -PI {
        r + TAU
    } else if r > PI {
        r - TAU
    } else {
        r
    }
}

/// `q` shifted by whole turns to be nearest `reference` (rad).
#[inline]
pub fn unwrap_near(q: f64, reference: f64) -> f64 {
    q - TAU * ((q - reference) / TAU).round()
}

/// Relative tolerance below which the wrist centre is on the J1 axis (mm).
const SHOULDER_SINGULAR_MM: f64 = 1e-9;
/// Below this `|sin t5|` J4 and J6 are not separable.
const WRIST_SINGULAR_SIN: f64 = 1e-12;
/// Reach slack (relative `sin`) accepted as rounding at full stretch/fold.
const REACH_SLACK: f64 = 1e-12;

/// Precomputed, pose-independent constants of the position problem.
#[derive(Debug, Clone, Copy)]
struct ArmConsts {
    k: f64,
    psi: f64,
}

impl RobotModel {
    #[inline]
    fn arm_consts(&self) -> ArmConsts {
        let g = &self.geometry;
        ArmConsts {
            k: g.forearm_mm.hypot(g.elbow_offset_mm),
            psi: g.elbow_offset_mm.atan2(g.forearm_mm),
        }
    }

    /// Wrist centre (base frame, mm) and canonical wrist rotation of a flange pose.
    #[inline]
    fn wrist_of(&self, base_from_flange: &Isometry3) -> (Vector3, Matrix3) {
        let r_f = base_from_flange.rotation.to_rotation_matrix().into_inner();
        let r_w = r_f * self.convention.wrist_from_flange.transpose();
        let p = base_from_flange.translation.vector;
        let w = p - r_w.column(0) * self.geometry.wrist_to_flange_mm;
        (w, r_w)
    }

    /// Canonical solution for one branch.
    #[inline]
    fn solve_branch(
        &self,
        w: &Vector3,
        r_w: &Matrix3,
        ac: ArmConsts,
        cfg: Configuration,
    ) -> Result<CanonicalAngles, RobotError> {
        let g = &self.geometry;
        let b = g.lateral_offset_mm;
        let rho2 = w.x * w.x + w.y * w.y;
        let x1_abs2 = rho2 - b * b;
        let scale = g.upper_arm_mm + ac.k;
        if x1_abs2.is_nan() {
            return Err(RobotError::NonFinite {
                what: "flange pose",
            });
        }
        if x1_abs2 <= (SHOULDER_SINGULAR_MM * scale).powi(2) {
            return Err(RobotError::ShoulderSingularity {
                distance_mm: x1_abs2.max(0.0).sqrt(),
            });
        }
        let x1 = match cfg.side {
            ArmSide::Front => x1_abs2.sqrt(),
            ArmSide::Back => -x1_abs2.sqrt(),
        };
        let t1 = w.y.atan2(w.x) - b.atan2(x1);
        let r = x1 - g.shoulder_offset_mm;
        let z = w.z - g.shoulder_height_mm;
        let d2 = r * r + z * z;
        let c2 = g.upper_arm_mm;
        let s = (d2 - c2 * c2 - ac.k * ac.k) / (2.0 * c2 * ac.k);
        if s.is_nan() || s.abs() > 1.0 + REACH_SLACK {
            return Err(RobotError::Unreachable {
                wrist_x_mm: w.x,
                wrist_y_mm: w.y,
                wrist_z_mm: w.z,
                distance_mm: d2.sqrt(),
                min_reach_mm: (c2 - ac.k).abs(),
                max_reach_mm: c2 + ac.k,
            });
        }
        let s = s.clamp(-1.0, 1.0);
        let cos_abs = (1.0 - s * s).sqrt();
        // Up in front (and Down behind) is the branch with cos(gamma) > 0.
        let positive_cos = matches!(
            (cfg.side, cfg.elbow),
            (ArmSide::Front, Elbow::Up) | (ArmSide::Back, Elbow::Down)
        );
        let cos_g = if positive_cos { cos_abs } else { -cos_abs };
        let gamma = s.atan2(cos_g);
        let aa = c2 + ac.k * s;
        let bb = ac.k * cos_g;
        let t2 = (aa * r - bb * z).atan2(bb * r + aa * z);
        let f3 = t2 - gamma + ac.psi;

        // orientation problem: M = (Rz(t1) Ry(f3))^T R_w = Rx(t4) Ry(t5) Rx(t6)
        let (s1, c1) = t1.sin_cos();
        let (s3, c3) = f3.sin_cos();
        let m = (rot_z(s1, c1) * rot_y(s3, c3)).transpose() * r_w;
        let sin5 = m[(1, 0)].hypot(m[(2, 0)]);
        let sin5_b = m[(0, 1)].hypot(m[(0, 2)]);
        if sin5.max(sin5_b) < WRIST_SINGULAR_SIN {
            return Err(RobotError::WristSingularity {
                sin_j5: sin5.max(sin5_b),
            });
        }
        let sin5 = 0.5 * (sin5 + sin5_b);
        let (t4, t5, t6) = match cfg.wrist {
            Wrist::NoFlip => (
                m[(1, 0)].atan2(-m[(2, 0)]),
                sin5.atan2(m[(0, 0)]),
                m[(0, 1)].atan2(m[(0, 2)]),
            ),
            Wrist::Flip => (
                (-m[(1, 0)]).atan2(m[(2, 0)]),
                (-sin5).atan2(m[(0, 0)]),
                (-m[(0, 1)]).atan2(-m[(0, 2)]),
            ),
        };
        Ok(CanonicalAngles([t1, t2, f3, t4, t5, t6]))
    }

    /// Controller joints of canonical angles, each joint wrapped to `(-π, π]`
    /// and, if that is outside its travel, shifted by a turn into it when possible.
    #[inline]
    fn joints_in_travel(&self, t: &CanonicalAngles) -> Joints {
        let mut q = self.joints_from_canonical(t);
        for (j, qj) in q.iter_mut().enumerate() {
            let l = &self.limits[j];
            let w = wrap_pi(*qj);
            *qj = if l.contains(w) {
                w
            } else if l.contains(w + TAU) {
                w + TAU
            } else if l.contains(w - TAU) {
                w - TAU
            } else {
                w
            };
        }
        q
    }

    /// Joints (rad) placing the flange at `base_from_flange` (mm) in configuration `cfg`.
    ///
    /// Each joint is returned in `(-180°, 180°]` unless only another turn is
    /// inside its travel (FANUC J3 up to 273°). Joint limits are not enforced:
    /// check them with [`RobotModel::limit_violations`].
    ///
    /// # Errors
    /// [`RobotError::Unreachable`], [`RobotError::ShoulderSingularity`],
    /// [`RobotError::WristSingularity`], [`RobotError::NonFinite`].
    pub fn inverse(
        &self,
        base_from_flange: &Isometry3,
        cfg: Configuration,
    ) -> Result<Joints, RobotError> {
        let (w, r_w) = self.wrist_of(base_from_flange);
        if !(w.iter().all(|v| v.is_finite()) && r_w.iter().all(|v| v.is_finite())) {
            return Err(RobotError::NonFinite {
                what: "flange pose",
            });
        }
        let t = self.solve_branch(&w, &r_w, self.arm_consts(), cfg)?;
        Ok(self.joints_in_travel(&t))
    }

    /// Like [`RobotModel::inverse`] with every joint shifted by whole turns to
    /// be nearest `near` (rad): the unwrapped solution along a trajectory.
    ///
    /// # Errors
    /// As [`RobotModel::inverse`].
    pub fn inverse_near(
        &self,
        base_from_flange: &Isometry3,
        cfg: Configuration,
        near: &Joints,
    ) -> Result<Joints, RobotError> {
        let mut q = self.inverse(base_from_flange, cfg)?;
        for j in 0..6 {
            q[j] = unwrap_near(q[j], near[j]);
        }
        Ok(q)
    }

    /// All eight configurations, indexed by [`Configuration::index`].
    pub fn inverse_all(&self, base_from_flange: &Isometry3) -> [Result<Joints, RobotError>; 8] {
        let (w, r_w) = self.wrist_of(base_from_flange);
        let finite = w.iter().all(|v| v.is_finite()) && r_w.iter().all(|v| v.is_finite());
        let ac = self.arm_consts();
        std::array::from_fn(|i| {
            if !finite {
                return Err(RobotError::NonFinite {
                    what: "flange pose",
                });
            }
            self.solve_branch(&w, &r_w, ac, Configuration::from_index(i))
                .map(|t| self.joints_in_travel(&t))
        })
    }

    /// Joints placing a tool centre point at `base_from_tcp`, the tool being
    /// `flange_from_tcp` (mm).
    ///
    /// # Errors
    /// As [`RobotModel::inverse`].
    pub fn inverse_tcp(
        &self,
        base_from_tcp: &Isometry3,
        flange_from_tcp: &Isometry3,
        cfg: Configuration,
    ) -> Result<Joints, RobotError> {
        self.inverse(&(base_from_tcp * flange_from_tcp.inverse()), cfg)
    }

    /// The configuration a joint vector is in (module doc for the definitions).
    pub fn configuration_of(&self, q: &Joints) -> Configuration {
        let g = &self.geometry;
        let ac = self.arm_consts();
        let t = self.canonical_from_joints(q).0;
        let (s2, _) = t[1].sin_cos();
        let (s3, c3) = t[2].sin_cos();
        let x1 =
            g.shoulder_offset_mm + g.upper_arm_mm * s2 + g.forearm_mm * c3 + g.elbow_offset_mm * s3;
        let side = if x1 >= 0.0 {
            ArmSide::Front
        } else {
            ArmSide::Back
        };
        let gamma = t[1] - (t[2] - ac.psi);
        let positive_cos = gamma.cos() > 0.0;
        let elbow = match (side, positive_cos) {
            (ArmSide::Front, true) | (ArmSide::Back, false) => Elbow::Up,
            _ => Elbow::Down,
        };
        let wrist = if t[4].sin() > 0.0 {
            Wrist::NoFlip
        } else {
            Wrist::Flip
        };
        Configuration { wrist, elbow, side }
    }

    /// FANUC `CONFIG` of a joint vector: branch and turn numbers of J1, J4, J6.
    pub fn fanuc_config(&self, q: &Joints) -> FanucConfig {
        FanucConfig {
            configuration: self.configuration_of(q),
            turn_j1: turn_number(q[0]),
            turn_j4: turn_number(q[3]),
            turn_j6: turn_number(q[5]),
        }
    }
}

/// How far a joint vector is from the three singularities of a 6R arm with a
/// spherical wrist.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SingularityMeasures {
    /// `|sin J5|`: 0 at the wrist singularity (J4 and J6 aligned).
    pub wrist_sin_j5: f64,
    /// `|cos gamma|`, gamma the elbow angle of the position problem: 0 when
    /// the arm is stretched or folded (elbow singularity).
    pub elbow_cos: f64,
    /// Distance of the wrist centre from the J1 axis, minus the lateral
    /// offset (mm): 0 at the shoulder singularity.
    pub shoulder_distance_mm: f64,
}

impl RobotModel {
    /// Singularity measures at `q` (rad).
    pub fn singularity_measures(&self, q: &Joints) -> SingularityMeasures {
        let g = &self.geometry;
        let ac = self.arm_consts();
        let t = self.canonical_from_joints(q).0;
        let s2 = t[1].sin();
        let (s3, c3) = t[2].sin_cos();
        let x1 =
            g.shoulder_offset_mm + g.upper_arm_mm * s2 + g.forearm_mm * c3 + g.elbow_offset_mm * s3;
        let gamma = t[1] - (t[2] - ac.psi);
        SingularityMeasures {
            wrist_sin_j5: t[4].sin().abs(),
            elbow_cos: gamma.cos().abs(),
            shoulder_distance_mm: x1.abs(),
        }
    }
}
