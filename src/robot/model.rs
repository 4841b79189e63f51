//! A 6R arm with a spherical wrist described as data: geometry (OPW-like
//! lengths, mm), the vendor's joint conventions (signs, zero offsets, FANUC
//! J2/J3 coupling, flange axes), joint limits (rad), maximum joint speeds
//! (rad/s) and encoder resolution (rad). SPEC §6.1, thesis table 3.3, A.1, 4.2.
//!
//! # The canonical arm
//!
//! Every arm is computed through one canonical chain (base frame: X forward,
//! Z up, origin on the J1 axis at the height given by `shoulder_height_mm`
//! below the J2 axis):
//!
//! ```text
//! wrist centre = Rz(t1)·[a1, b, c1] + Rz(t1)·Ry(t2)·[0, 0, c2] + Rz(t1)·Ry(f3)·[c3, 0, e]
//! wrist frame  = Rz(t1)·Ry(f3)·Rx(t4)·Ry(t5)·Rx(t6)        (x = approach axis)
//! flange       = wrist centre + c4 · approach,   flange rotation = wrist frame · wrist_from_flange
//! ```
//!
//! with `a1` the shoulder offset, `b` a lateral offset, `c1` the shoulder
//! height, `c2` the upper arm, `c3` the forearm, `e` the elbow offset (upward
//! at zero) and `c4` wrist centre → flange. `t2 > 0` leans the upper arm
//! forward, `f3` is the forearm's attitude (`f3 > 0` lowers it), `t5 > 0`
//! tilts the approach axis down. This is the OPW parameterisation of
//! Brandstötter et al. (2014) with the forearm horizontal at zero; OPW's
//! `a2` is `-e`.
//!
//! Controller joint values `q` (what a robot program contains) map to the
//! canonical angles through [`JointConvention`]: `t_i = sign_i·q_i + offset_i`,
//! and for the forearm `f3 = t2 + sign_3·q_3 + offset_3`, or, on arms whose J3
//! is measured from the horizontal (FANUC's J2/J3 interaction),
//! `f3 = sign_3·q_3 + offset_3`.

use serde::{Deserialize, Serialize};

use crate::math::{Matrix3, Rotation3};
use crate::robot::RobotError;

/// Encoder resolutions of the ArcMate 120iC [thesis table 4.2] (deg, joints
/// 1–6): measured data, not a tolerance. The nominal model carries them; the
/// optimiser falls back on them for a model without its own.
pub(crate) const ARCMATE_120IC_ENCODER_SIGMA_DEG: [f64; 6] =
    [3.63e-8, 3.63e-8, 3.81e-8, 16.45e-8, 14.12e-8, 63.18e-8];
/// `wrist_from_flange` is a rotation when `MᵀM - I` and `det M - 1` are both
/// below this (unitless, per entry).
const ROTATION_TOL: f64 = 1e-9;

/// Six joint values in controller convention (rad), J1 first.
pub type Joints = [f64; 6];

/// Lengths of the canonical arm (mm). See the module doc for the chain.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ArmGeometry {
    /// Forward offset from the J1 axis to the J2 axis (mm). FANUC `d2`, OPW `a1`.
    pub shoulder_offset_mm: f64,
    /// Lateral offset of the arm plane from the J1 axis, along +Y at J1 = 0 (mm). OPW `b`.
    #[serde(default)]
    pub lateral_offset_mm: f64,
    /// Height of the J2 axis above the base frame origin (mm). OPW `c1`; 0 for the
    /// thesis's FANUC model, whose frame 0 is at the J2 height.
    #[serde(default)]
    pub shoulder_height_mm: f64,
    /// Upper arm, J2 axis → J3 axis (mm). FANUC `d3`, OPW `c2`.
    pub upper_arm_mm: f64,
    /// Elbow offset, J3 axis → forearm axis, upward when the forearm is
    /// horizontal (mm). FANUC `d4`, OPW `-a2`.
    pub elbow_offset_mm: f64,
    /// Forearm, along the forearm axis from the J3 offset point to the wrist centre (mm).
    /// FANUC `r4`, OPW `c3`.
    pub forearm_mm: f64,
    /// Wrist centre → flange along the approach axis (mm). FANUC `r6`, OPW `c4`.
    pub wrist_to_flange_mm: f64,
}

impl ArmGeometry {
    /// The five lengths fitted by calibration (thesis eq. 3.17), in the order
    /// `[d2, d3, d4, r4, r6]` = `[shoulder_offset, upper_arm, elbow_offset, forearm, wrist_to_flange]` (mm).
    pub fn segment_lengths(&self) -> [f64; 5] {
        [
            self.shoulder_offset_mm,
            self.upper_arm_mm,
            self.elbow_offset_mm,
            self.forearm_mm,
            self.wrist_to_flange_mm,
        ]
    }

    /// Same geometry with the five calibrated lengths replaced, order as in
    /// [`ArmGeometry::segment_lengths`] (mm).
    pub fn with_segment_lengths(&self, l: [f64; 5]) -> Self {
        Self {
            shoulder_offset_mm: l[0],
            upper_arm_mm: l[1],
            elbow_offset_mm: l[2],
            forearm_mm: l[3],
            wrist_to_flange_mm: l[4],
            ..*self
        }
    }
}

/// Which vendor's conventions a model follows (closed set; the numbers are in
/// [`JointConvention`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Vendor {
    /// FANUC: J3 from the horizontal (J2/J3 coupling), J3..J6 senses reversed,
    /// flange x up and z along the approach axis at zero.
    Fanuc,
    /// KUKA: A1, A4, A6 reversed, A2 = -90° with the upper arm vertical,
    /// A3 = +90° with the forearm horizontal; `$FLANGE` z along the approach axis.
    Kuka,
    /// ABB: all senses positive, zero with upper arm vertical and forearm
    /// horizontal; `tool0` z along the approach axis, x down at zero.
    Abb,
}

impl Vendor {
    /// `true` when the vendor's controller turns an endless external axis
    /// modulo 360°, the shortest way, at most 180° a motion (KUKA: infinitely
    /// rotating axis, KR C2 machine data §2.1.4). An endless positioner turn
    /// without a stated stroke is then written modulo 360°; on the others it
    /// is unwound by whole turns into a stroke.
    pub fn turns_endless_axes_modulo(self) -> bool {
        matches!(self, Vendor::Kuka)
    }
}

/// How controller joint values map to the canonical arm (module doc).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct JointConvention {
    /// `+1` or `-1` per joint: sense of the controller's joint relative to the canonical one.
    pub sign: [f64; 6],
    /// Canonical angle at controller zero, per joint (rad).
    pub offset_rad: [f64; 6],
    /// `true` when J3 is measured from the horizontal, independently of J2
    /// (FANUC's J2/J3 interaction, thesis table 3.3 note 1).
    pub j2_j3_coupled: bool,
    /// `wrist_from_flange`: the controller's flange axes expressed in the
    /// canonical wrist frame (x = approach). Rotation, unitless.
    pub wrist_from_flange: Matrix3,
}

impl JointConvention {
    /// The conventions of a vendor (SPEC §6.1 for FANUC; ROS-Industrial URDFs
    /// `kuka_kr16_support` and `abb_irb2600_support` for KUKA and ABB).
    pub fn of(vendor: Vendor) -> Self {
        use std::f64::consts::FRAC_PI_2;
        match vendor {
            Vendor::Fanuc => Self {
                sign: [1.0, 1.0, -1.0, -1.0, -1.0, -1.0],
                offset_rad: [0.0; 6],
                j2_j3_coupled: true,
                // flange x = wrist z (up at zero), y = -wrist y, z = wrist x (approach)
                wrist_from_flange: Matrix3::new(0.0, 0.0, 1.0, 0.0, -1.0, 0.0, 1.0, 0.0, 0.0),
            },
            Vendor::Kuka => Self {
                sign: [-1.0, 1.0, 1.0, -1.0, 1.0, -1.0],
                offset_rad: [0.0, FRAC_PI_2, -FRAC_PI_2, 0.0, 0.0, 0.0],
                j2_j3_coupled: false,
                wrist_from_flange: Rotation3::from_axis_angle(
                    &crate::math::Vector3::y_axis(),
                    FRAC_PI_2,
                )
                .into_inner(),
            },
            Vendor::Abb => Self {
                sign: [1.0; 6],
                offset_rad: [0.0; 6],
                j2_j3_coupled: false,
                wrist_from_flange: Rotation3::from_axis_angle(
                    &crate::math::Vector3::y_axis(),
                    FRAC_PI_2,
                )
                .into_inner(),
            },
        }
    }
}

/// Travel of one joint (rad, controller convention). Infinite bounds mean unlimited.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct JointLimit {
    /// Lower bound (rad); `-inf` if unlimited.
    pub lower_rad: f64,
    /// Upper bound (rad); `+inf` if unlimited.
    pub upper_rad: f64,
}

impl JointLimit {
    /// An unlimited joint.
    pub const UNLIMITED: Self = Self {
        lower_rad: f64::NEG_INFINITY,
        upper_rad: f64::INFINITY,
    };

    /// From bounds in degrees.
    pub fn from_degrees(lower_deg: f64, upper_deg: f64) -> Self {
        Self {
            lower_rad: lower_deg.to_radians(),
            upper_rad: upper_deg.to_radians(),
        }
    }

    /// Symmetric bounds `±deg`.
    pub fn symmetric_deg(deg: f64) -> Self {
        Self::from_degrees(-deg, deg)
    }

    /// `true` when both bounds are infinite.
    pub fn is_unlimited(&self) -> bool {
        self.lower_rad == f64::NEG_INFINITY && self.upper_rad == f64::INFINITY
    }

    /// Middle of the travel (rad); 0 for an unlimited joint.
    pub fn mid_rad(&self) -> f64 {
        if self.lower_rad.is_finite() && self.upper_rad.is_finite() {
            0.5 * (self.lower_rad + self.upper_rad)
        } else {
            0.0
        }
    }

    /// Travel `upper - lower` (rad); `inf` if unlimited.
    pub fn range_rad(&self) -> f64 {
        self.upper_rad - self.lower_rad
    }

    /// The whole turns `k` (as `k_min..=k_max`) that shift values spanning
    /// `[lo, hi]` (rad) into this travel: `lower <= lo + 2πk` and
    /// `hi + 2πk <= upper`; `None` when no whole turn fits them (the span
    /// is too wide, or falls badly against the travel modulo a turn).
    pub fn whole_turn_shifts(&self, lo: f64, hi: f64) -> Option<(f64, f64)> {
        use std::f64::consts::TAU;
        if self.is_unlimited() {
            return Some((0.0, 0.0));
        }
        let k_min = ((self.lower_rad - lo) / TAU).ceil();
        let k_max = ((self.upper_rad - hi) / TAU).floor();
        (k_min <= k_max).then_some((k_min, k_max))
    }

    /// `true` when `q` (rad) is inside the travel (bounds included).
    pub fn contains(&self, q: f64) -> bool {
        q >= self.lower_rad && q <= self.upper_rad
    }
}

/// Named parameter sets of the arms shipped with the crate.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum RobotPreset {
    /// FANUC ArcMate 120iC, nominal lengths (thesis table 3.3).
    Arcmate120icNominal,
    /// FANUC ArcMate 120iC, lengths identified axis by axis (thesis table 3.5).
    Arcmate120icAxisByAxis,
    /// FANUC ArcMate 120iC, lengths identified by random motions (thesis table 3.6).
    Arcmate120icRandomMotions,
    /// KUKA KR 16-2 (ROS-Industrial `kuka_kr16_support`, from the KUKA data sheet).
    KukaKr16_2,
    /// ABB IRB 2600-12/1.85 (ROS-Industrial `abb_irb2600_support`, from the ABB data sheet).
    AbbIrb2600_12_185,
}

/// A 6R arm with a spherical wrist, as data. Built once and validated
/// ([`RobotModel::validate`]); the kinematics functions trust it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RobotModel {
    /// Human-readable name ("FANUC ArcMate 120iC (nominal)").
    pub name: String,
    /// Where the numbers come from (data sheet, thesis table, URDF).
    pub source: String,
    /// Vendor whose conventions `convention` holds.
    pub vendor: Vendor,
    /// Lengths of the canonical arm (mm).
    pub geometry: ArmGeometry,
    /// Controller ↔ canonical joint mapping.
    pub convention: JointConvention,
    /// Joint travel per joint (rad).
    pub limits: [JointLimit; 6],
    /// Maximum joint speed per joint (rad/s).
    pub max_speed_rad_s: [f64; 6],
    /// Maximum joint acceleration per joint (rad/s²), used for the cycle
    /// time's trapezoidal profiles ([`crate::program::cycle`]). `None`: each
    /// joint reaches its maximum speed in [`ASSUMED_RAMP_S`]
    /// ([`RobotModel::max_acceleration`]).
    #[serde(default)]
    pub max_acceleration_rad_s2: Option<[f64; 6]>,
    /// Angular resolution (standard deviation) per joint (rad), if published
    /// [thesis table 4.2].
    pub encoder_sigma_rad: Option<[f64; 6]>,
    /// Identified deviations of the DH twists `alpha_j` from their nominal
    /// ±90°/0° (rad) [thesis table 3.5]. Recorded only: like the thesis
    /// (§3.2.2.5) the kinematics use the nominal twists so that the IK stays
    /// analytic.
    pub twist_deviation_rad: [f64; 6],
}

/// Time (s) in which a joint is assumed to reach its maximum speed from rest
/// at full acceleration, where the vendor publishes no joint acceleration:
/// 0.5 s. FANUC, KUKA and ABB publish maximum joint speeds in their data
/// sheets but no joint accelerations (these depend on the payload and are
/// computed by the controller's dynamic model: FANUC's acceleration
/// override `ACC`, KUKA `$ACC_AXIS`, ABB `AccSet`); 0.5 s is an assumption of
/// the order seen on arms of this size at moderate payload, not a vendor
/// figure. The presets' accelerations are `max_speed / ASSUMED_RAMP_S`.
pub const ASSUMED_RAMP_S: f64 = 0.5;

/// `max_speed / ASSUMED_RAMP_S` per joint (rad/s²): the presets'
/// assumed joint accelerations (see [`ASSUMED_RAMP_S`]).
fn ramp_accelerations(max_speed_rad_s: [f64; 6]) -> Option<[f64; 6]> {
    Some(max_speed_rad_s.map(|v| v / ASSUMED_RAMP_S))
}

fn deg6(a: [f64; 6]) -> [f64; 6] {
    a.map(f64::to_radians)
}

impl RobotModel {
    /// FANUC ArcMate 120iC with the nominal lengths of thesis table 3.3
    /// (`d2 150, d3 790, d4 250, r4 835, r6 100` mm), limits and speeds of
    /// table A.1 with the catalogue J5 travel ±140°, encoder resolution of table 4.2.
    pub fn arcmate_120ic_nominal() -> Self {
        Self {
            name: "FANUC ArcMate 120iC (nominal)".into(),
            source:
                "Chalvin (2020) thesis, table 3.3 (lengths), A.1 (travel, speeds), 4.2 (encoders)"
                    .into(),
            vendor: Vendor::Fanuc,
            geometry: ArmGeometry {
                shoulder_offset_mm: 150.0,
                lateral_offset_mm: 0.0,
                shoulder_height_mm: 0.0,
                upper_arm_mm: 790.0,
                elbow_offset_mm: 250.0,
                forearm_mm: 835.0,
                wrist_to_flange_mm: 100.0,
            },
            convention: JointConvention::of(Vendor::Fanuc),
            limits: [
                JointLimit::symmetric_deg(170.0),
                JointLimit::from_degrees(-100.0, 160.0),
                JointLimit::from_degrees(-185.0, 273.0),
                JointLimit::symmetric_deg(200.0),
                JointLimit::symmetric_deg(140.0),
                JointLimit::UNLIMITED,
            ],
            max_speed_rad_s: deg6([195.0, 175.0, 180.0, 360.0, 360.0, 550.0]),
            // not published (thesis, FANUC data sheet): assumed, ASSUMED_RAMP_S
            max_acceleration_rad_s2: ramp_accelerations(deg6([
                195.0, 175.0, 180.0, 360.0, 360.0, 550.0,
            ])),
            encoder_sigma_rad: Some(deg6(ARCMATE_120IC_ENCODER_SIGMA_DEG)),
            twist_deviation_rad: [0.0; 6],
        }
    }

    /// ArcMate 120iC with the lengths identified axis by axis [thesis table 3.5]:
    /// `d2 149.661, d3 789.883, d4 250.129, r4 835.687, r6 99.965` mm; the
    /// identified twists `0, -89.991, 0.009, 90.013, -89.998, 89.946`° are
    /// recorded as deviations from the nominal `0, -90, 0, 90, -90, 90`°.
    pub fn arcmate_120ic_axis_by_axis() -> Self {
        let mut m = Self::arcmate_120ic_nominal();
        m.name = "FANUC ArcMate 120iC (identified axis by axis)".into();
        m.source = "Chalvin (2020) thesis, table 3.5".into();
        m.geometry = m
            .geometry
            .with_segment_lengths([149.661, 789.883, 250.129, 835.687, 99.965]);
        m.twist_deviation_rad = deg6([0.0, 0.009, 0.009, 0.013, 0.002, -0.054]);
        m
    }

    /// ArcMate 120iC with the lengths identified by random motions [thesis
    /// table 3.6]: `d2 149.417, d3 790.404, d4 248.771, r4 834.177, r6 100.648` mm.
    pub fn arcmate_120ic_random_motions() -> Self {
        let mut m = Self::arcmate_120ic_nominal();
        m.name = "FANUC ArcMate 120iC (identified by random motions)".into();
        m.source = "Chalvin (2020) thesis, table 3.6".into();
        m.geometry = m
            .geometry
            .with_segment_lengths([149.417, 790.404, 248.771, 834.177, 100.648]);
        m
    }

    /// KUKA KR 16-2: lengths, travel and speeds of the ROS-Industrial URDF
    /// `kuka_experimental/kuka_kr16_support/urdf/kr16_2_macro.xacro` (built
    /// from the KUKA KR 16-2 data sheet): `a1 260, c1 675, c2 680, c3 670,
    /// e -35, c4 158` mm. Encoder resolution not published.
    pub fn kuka_kr16_2() -> Self {
        Self {
            name: "KUKA KR 16-2".into(),
            source: "ROS-Industrial kuka_experimental, kuka_kr16_support/urdf/kr16_2_macro.xacro and config/opw_parameters_kr16_2.yaml".into(),
            vendor: Vendor::Kuka,
            geometry: ArmGeometry {
                shoulder_offset_mm: 260.0,
                lateral_offset_mm: 0.0,
                shoulder_height_mm: 675.0,
                upper_arm_mm: 680.0,
                elbow_offset_mm: -35.0,
                forearm_mm: 670.0,
                wrist_to_flange_mm: 158.0,
            },
            convention: JointConvention::of(Vendor::Kuka),
            limits: [
                JointLimit::symmetric_deg(185.0),
                JointLimit::from_degrees(-155.0, 35.0),
                JointLimit::from_degrees(-130.0, 154.0),
                JointLimit::symmetric_deg(350.0),
                JointLimit::symmetric_deg(130.0),
                JointLimit::symmetric_deg(350.0),
            ],
            max_speed_rad_s: deg6([156.0, 156.0, 156.0, 330.0, 330.0, 615.0]),
            // not in the URDF nor the KUKA data sheet: assumed, ASSUMED_RAMP_S
            max_acceleration_rad_s2: ramp_accelerations(deg6([
                156.0, 156.0, 156.0, 330.0, 330.0, 615.0,
            ])),
            encoder_sigma_rad: None,
            twist_deviation_rad: [0.0; 6],
        }
    }

    /// ABB IRB 2600-12/1.85: lengths, travel and speeds of the ROS-Industrial
    /// URDF `abb_experimental/abb_irb2600_support/urdf/irb2600_12_185_macro.xacro`
    /// (built from the ABB product specification): `a1 150, c1 445, c2 900,
    /// c3 795, e 115, c4 85` mm. Encoder resolution not published.
    #[allow(clippy::approx_constant)] // travel and speeds as printed in the URDF (rad, rad/s)
    pub fn abb_irb2600_12_185() -> Self {
        Self {
            name: "ABB IRB 2600-12/1.85".into(),
            source: "ROS-Industrial abb_experimental, abb_irb2600_support/urdf/irb2600_12_185_macro.xacro".into(),
            vendor: Vendor::Abb,
            geometry: ArmGeometry {
                shoulder_offset_mm: 150.0,
                lateral_offset_mm: 0.0,
                shoulder_height_mm: 445.0,
                upper_arm_mm: 900.0,
                elbow_offset_mm: 115.0,
                forearm_mm: 795.0,
                wrist_to_flange_mm: 85.0,
            },
            convention: JointConvention::of(Vendor::Abb),
            limits: [
                JointLimit { lower_rad: -3.14159, upper_rad: 3.14159 },
                JointLimit { lower_rad: -2.705, upper_rad: 1.658 },
                JointLimit { lower_rad: -2.705, upper_rad: 1.309 },
                JointLimit { lower_rad: -6.981, upper_rad: 6.981 },
                JointLimit { lower_rad: -2.094, upper_rad: 2.094 },
                JointLimit { lower_rad: -6.981, upper_rad: 6.981 },
            ],
            max_speed_rad_s: [3.054, 3.054, 3.054, 6.283, 6.283, 8.727],
            // not in the URDF nor the ABB product specification: assumed,
            // ASSUMED_RAMP_S
            max_acceleration_rad_s2: ramp_accelerations([
                3.054, 3.054, 3.054, 6.283, 6.283, 8.727,
            ]),
            encoder_sigma_rad: None,
            twist_deviation_rad: [0.0; 6],
        }
    }

    /// Maximum joint accelerations (rad/s²): [`RobotModel::max_acceleration_rad_s2`],
    /// else `max_speed_rad_s / ASSUMED_RAMP_S` per joint.
    pub fn max_acceleration(&self) -> [f64; 6] {
        self.max_acceleration_rad_s2
            .unwrap_or_else(|| self.max_speed_rad_s.map(|v| v / ASSUMED_RAMP_S))
    }

    /// The model of a named preset.
    pub fn preset(p: RobotPreset) -> Self {
        match p {
            RobotPreset::Arcmate120icNominal => Self::arcmate_120ic_nominal(),
            RobotPreset::Arcmate120icAxisByAxis => Self::arcmate_120ic_axis_by_axis(),
            RobotPreset::Arcmate120icRandomMotions => Self::arcmate_120ic_random_motions(),
            RobotPreset::KukaKr16_2 => Self::kuka_kr16_2(),
            RobotPreset::AbbIrb2600_12_185 => Self::abb_irb2600_12_185(),
        }
    }

    /// Same model with J5's travel set to `±deg` (the thesis's part-carried
    /// cell restricts it to ±135° to avoid collisions, table A.1 note 1).
    pub fn with_j5_travel_deg(mut self, deg: f64) -> Self {
        self.limits[4] = JointLimit::symmetric_deg(deg);
        self
    }

    /// Checks every field; names the one at fault.
    ///
    /// # Errors
    /// [`RobotError::InvalidParameter`] for a non-finite or non-positive length,
    /// a sign other than ±1, a non-rotation `wrist_from_flange`, inverted or NaN
    /// limits, non-positive speeds or negative encoder resolutions.
    pub fn validate(&self) -> Result<(), RobotError> {
        let bad =
            |field: &'static str, value: f64, reason: &'static str| RobotError::InvalidParameter {
                what: self.name.clone(),
                field,
                value,
                reason,
            };
        let g = &self.geometry;
        for (field, v) in [
            ("shoulder_offset_mm", g.shoulder_offset_mm),
            ("lateral_offset_mm", g.lateral_offset_mm),
            ("shoulder_height_mm", g.shoulder_height_mm),
            ("elbow_offset_mm", g.elbow_offset_mm),
        ] {
            if !v.is_finite() {
                return Err(bad(field, v, "must be finite"));
            }
        }
        for (field, v) in [
            ("upper_arm_mm", g.upper_arm_mm),
            ("forearm_mm", g.forearm_mm),
        ] {
            if !(v.is_finite() && v > 0.0) {
                return Err(bad(field, v, "must be finite and > 0"));
            }
        }
        if !(g.wrist_to_flange_mm.is_finite() && g.wrist_to_flange_mm >= 0.0) {
            return Err(bad(
                "wrist_to_flange_mm",
                g.wrist_to_flange_mm,
                "must be finite and >= 0",
            ));
        }
        for (i, s) in self.convention.sign.iter().enumerate() {
            if *s != 1.0 && *s != -1.0 {
                return Err(bad(JOINT_SIGN_FIELDS[i], *s, "must be +1 or -1"));
            }
        }
        for (i, o) in self.convention.offset_rad.iter().enumerate() {
            if !o.is_finite() {
                return Err(bad(JOINT_OFFSET_FIELDS[i], *o, "must be finite"));
            }
        }
        let m = &self.convention.wrist_from_flange;
        let err = (m.transpose() * m - Matrix3::identity()).abs().max();
        if !(err < ROTATION_TOL && (m.determinant() - 1.0).abs() < ROTATION_TOL) {
            return Err(bad(
                "wrist_from_flange",
                err,
                "must be a rotation matrix (orthonormal, det +1)",
            ));
        }
        for (i, l) in self.limits.iter().enumerate() {
            if l.lower_rad.is_nan() || l.upper_rad.is_nan() || l.lower_rad >= l.upper_rad {
                return Err(bad(
                    JOINT_LIMIT_FIELDS[i],
                    l.lower_rad.to_degrees(),
                    "lower bound must be below the upper bound",
                ));
            }
        }
        for (i, v) in self.max_speed_rad_s.iter().enumerate() {
            if !(v.is_finite() && *v > 0.0) {
                return Err(bad(
                    JOINT_SPEED_FIELDS[i],
                    v.to_degrees(),
                    "must be finite and > 0",
                ));
            }
        }
        if let Some(a) = &self.max_acceleration_rad_s2 {
            for v in a {
                if !(v.is_finite() && *v > 0.0) {
                    return Err(bad(
                        "max_acceleration_deg_s2",
                        v.to_degrees(),
                        "must be finite and > 0",
                    ));
                }
            }
        }
        if let Some(s) = &self.encoder_sigma_rad {
            for v in s {
                if !(v.is_finite() && *v >= 0.0) {
                    return Err(bad(
                        "encoder_sigma_deg",
                        v.to_degrees(),
                        "must be finite and >= 0",
                    ));
                }
            }
        }
        Ok(())
    }

    /// Joint-limit violations of `q`: `(joint index 0..6, value rad)` for each
    /// joint outside its travel.
    pub fn limit_violations(&self, q: &Joints) -> impl Iterator<Item = (usize, f64)> + '_ {
        let q = *q;
        (0..6).filter_map(move |j| (!self.limits[j].contains(q[j])).then_some((j, q[j])))
    }
}

const JOINT_SIGN_FIELDS: [&str; 6] = [
    "sign[0]", "sign[1]", "sign[2]", "sign[3]", "sign[4]", "sign[5]",
];
const JOINT_OFFSET_FIELDS: [&str; 6] = [
    "offset_deg[0]",
    "offset_deg[1]",
    "offset_deg[2]",
    "offset_deg[3]",
    "offset_deg[4]",
    "offset_deg[5]",
];
const JOINT_LIMIT_FIELDS: [&str; 6] = [
    "lower_deg[0]",
    "lower_deg[1]",
    "lower_deg[2]",
    "lower_deg[3]",
    "lower_deg[4]",
    "lower_deg[5]",
];
const JOINT_SPEED_FIELDS: [&str; 6] = [
    "max_speed_deg_s[0]",
    "max_speed_deg_s[1]",
    "max_speed_deg_s[2]",
    "max_speed_deg_s[3]",
    "max_speed_deg_s[4]",
    "max_speed_deg_s[5]",
];
