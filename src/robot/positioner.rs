//! Two-axis positioner (tilt `q7` about Y, then table turn `q8` about the
//! table normal): forward kinematics and the angles that turn a build
//! direction vertical. SPEC §6.4, thesis eq. C.5–C.6 (FK) and C.24–C.25.
//!
//! Frames: the *positioner frame* is the frame whose pose in the robot base
//! frame the controller stores (thesis table 3.7); its origin is the tilt
//! centre C7. The *table frame* has its origin at the table centre C8, at
//! `|C7C8|` along the positioner's Z at zero, and Z along the table normal.
//! `positioner_from_table = Ry(q7) · Trans(0, 0, |C7C8|) · Rz(q8)`.
//!
//! The angles for a build direction are solved from this FK (not from the
//! printed eq. C.24–C.25, which name the components of `b` as angles; they
//! agree with the solution here for the `q7 >= 0` branch when the
//! positioner is level).

use serde::{Deserialize, Serialize};

use crate::math::{tol, Isometry3, Rotation3, Translation3, UnitQuaternion, UnitVector3, Vector3};
use crate::robot::ik::wrap_pi;
use crate::robot::kinematics::{rot_y, rot_z};
use crate::robot::model::JointLimit;
use crate::robot::RobotError;
use std::f64::consts::TAU;

/// Floor of the accepted build-direction error (rad): an exact solution is
/// not refused for rounding when the cell asks for zero error.
const MIN_ERROR_RAD: f64 = 1e-12;

/// A two-axis tilt-and-turn positioner, as data.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Positioner {
    /// Human-readable name.
    pub name: String,
    /// `|C7C8|`: tilt centre → table centre (mm) [thesis §3.2.2.4: 150 nominal, 149.631 identified].
    pub tilt_to_table_mm: f64,
    /// Travel of `q7` (tilt) and `q8` (turn) (rad).
    pub limits: [JointLimit; 2],
    /// Maximum speeds of `q7`, `q8` (rad/s); `inf` if unknown.
    pub max_speed_rad_s: [f64; 2],
    /// The values of the turn `q8` (rad) the controller accepts when the
    /// turn is endless (`limits[1]` unlimited): planning treats the turn as
    /// endless, and the program stage shifts each bead's block of points by
    /// whole turns into this stroke, unwinding the table during the arc-off
    /// move between beads. `None`: [`DEFAULT_TURN_STROKE_RAD`]. Ignored
    /// when the turn has a finite travel: that travel is then the stroke.
    #[serde(default)]
    pub turn_stroke: Option<JointLimit>,
}

/// The stroke of an endless turn when the cell states none: ±360° (rad).
/// Every bead turning the table through at most 720° fits in it, and a
/// limited rotary axis (KUKA: software limits within ±358°) can be set to
/// hold a one-turn layer.
pub const DEFAULT_TURN_STROKE_RAD: f64 = TAU;

/// Joint values of the positioner `[q7, q8]` (rad).
pub type PositionerJoints = [f64; 2];

impl Positioner {
    /// The programmed values the turn `q8` may take (rad) on a controller
    /// that needs a stroke: its travel when finite, else the stated
    /// [`turn_stroke`](Self::turn_stroke), else ±[`DEFAULT_TURN_STROKE_RAD`].
    /// `modulo`: the controller turns an endless axis modulo 360° (KUKA's
    /// infinitely rotating axes, [`Vendor::turns_endless_axes_modulo`](crate::robot::Vendor::turns_endless_axes_modulo)):
    /// an endless turn without a stated stroke then has none (`UNLIMITED`).
    pub fn turn_stroke(&self, modulo: bool) -> JointLimit {
        let travel = self.limits[1];
        if travel.lower_rad.is_finite() || travel.upper_rad.is_finite() {
            travel
        } else {
            match self.turn_stroke {
                Some(s) => s,
                None if modulo => JointLimit::UNLIMITED,
                None => JointLimit {
                    lower_rad: -DEFAULT_TURN_STROKE_RAD,
                    upper_rad: DEFAULT_TURN_STROKE_RAD,
                },
            }
        }
    }

    /// The ROBOWAM positioner with the nominal `|C7C8| = 150` mm [fig. 3.13].
    /// Travel and speeds are not given in the thesis: both unlimited.
    pub fn robowam_nominal() -> Self {
        Self {
            name: "ROBOWAM 2-axis positioner (nominal)".into(),
            tilt_to_table_mm: 150.0,
            limits: [JointLimit::UNLIMITED, JointLimit::UNLIMITED],
            max_speed_rad_s: [f64::INFINITY, f64::INFINITY],
            turn_stroke: None,
        }
    }

    /// The ROBOWAM positioner with the identified `|C7C8| = 149.631` mm [§3.2.2.4].
    pub fn robowam_identified() -> Self {
        Self {
            name: "ROBOWAM 2-axis positioner (identified)".into(),
            tilt_to_table_mm: 149.631,
            ..Self::robowam_nominal()
        }
    }

    /// Checks the fields.
    ///
    /// # Errors
    /// [`RobotError::InvalidParameter`] naming the field.
    pub fn validate(&self) -> Result<(), RobotError> {
        let bad =
            |field: &'static str, value: f64, reason: &'static str| RobotError::InvalidParameter {
                what: self.name.clone(),
                field,
                value,
                reason,
            };
        if !self.tilt_to_table_mm.is_finite() {
            return Err(bad(
                "tilt_to_table_mm",
                self.tilt_to_table_mm,
                "must be finite",
            ));
        }
        for (i, l) in self.limits.iter().enumerate() {
            if l.lower_rad.is_nan() || l.upper_rad.is_nan() || l.lower_rad >= l.upper_rad {
                return Err(bad(
                    ["lower_deg[0]", "lower_deg[1]"][i],
                    l.lower_rad.to_degrees(),
                    "lower bound must be below the upper bound",
                ));
            }
        }
        for (i, v) in self.max_speed_rad_s.iter().enumerate() {
            if v.is_nan() || *v <= 0.0 {
                return Err(bad(
                    ["max_speed_deg_s[0]", "max_speed_deg_s[1]"][i],
                    v.to_degrees(),
                    "must be > 0",
                ));
            }
        }
        Ok(())
    }

    /// `positioner_from_table` at `q = [q7, q8]` (rad) [eq. C.5–C.6] (mm).
    pub fn positioner_from_table(&self, q: &PositionerJoints) -> Isometry3 {
        let (s7, c7) = q[0].sin_cos();
        let (s8, c8) = q[1].sin_cos();
        let r = rot_y(s7, c7) * rot_z(s8, c8);
        let l = self.tilt_to_table_mm;
        Isometry3::from_parts(
            Translation3::new(l * s7, 0.0, l * c7),
            UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(r)),
        )
    }

    /// Angles `[q7, q8]` (rad) turning the build direction `b` (table frame)
    /// onto `up` (positioner frame; `+Z` for a level positioner). Of the two
    /// tilt solutions the one inside the travel with the smaller `|q7|` is
    /// returned; `q8` is the turn angle inside its travel nearest `q8_hint`
    /// (rad; pass the previous point's, so that the table turns continuously
    /// past ±180°), and when `b` is along the table normal `q8` is free and
    /// `q8_hint` is returned for it.
    ///
    /// When `up` is not in the positioner's XZ plane (a positioner mounted
    /// slightly out of level, like table 3.7's `W = 0.412°`) some directions
    /// cannot be turned exactly vertical; the closest tilt is then accepted if
    /// the remaining angle is at most `max_error_rad` (rad).
    ///
    /// # Errors
    /// [`RobotError::PositionerUnreachable`] when no tilt comes within
    /// `max_error_rad`, or both solutions are outside the travel.
    pub fn angles_for_vertical(
        &self,
        b: &UnitVector3,
        up: &UnitVector3,
        q8_hint: f64,
        max_error_rad: f64,
    ) -> Result<PositionerJoints, RobotError> {
        let unreachable = || RobotError::PositionerUnreachable {
            bx: b.x,
            by: b.y,
            bz: b.z,
        };
        // Ry(q7) Rz(q8) b = up  <=>  Rz(q8) b = Ry(-q7) up; z rows: b_z = sin q7 u_x + cos q7 u_z
        let rho = up.x.hypot(up.z);
        if rho.is_nan() || rho <= 0.0 {
            return Err(unreachable());
        }
        let ratio = b.z / rho;
        if ratio.is_nan() {
            return Err(unreachable());
        }
        let alpha = up.x.atan2(up.z);
        let delta = ratio.clamp(-1.0, 1.0).acos();
        let b_xy = b.x.hypot(b.y);
        let mut best: Option<PositionerJoints> = None;
        for q7 in [wrap_pi(alpha + delta), wrap_pi(alpha - delta)] {
            let (s7, c7) = q7.sin_cos();
            let w = rot_y(-s7, c7) * up.into_inner();
            // The turn is a rotary table: of the angles 2π apart, take the
            // one inside the travel nearest the hint (the previous point's),
            // so that a layer going round a part of revolution turns the
            // table continuously instead of jumping back by 360°.
            let q8 = if b_xy > tol::DEGENERATE {
                let a = wrap_pi(w.y.atan2(w.x) - b.y.atan2(b.x));
                let k = ((q8_hint - a) / TAU).round();
                [k, k - 1.0, k + 1.0]
                    .into_iter()
                    .map(|k| a + k * TAU)
                    .filter(|q| self.limits[1].contains(*q))
                    .min_by(|x, y| (x - q8_hint).abs().total_cmp(&(y - q8_hint).abs()))
                    .unwrap_or(a)
            } else {
                q8_hint
            };
            let cand = [q7, q8];
            let reached = self.positioner_from_table(&cand).rotation * b.into_inner();
            let error = reached.cross(up).norm().atan2(reached.dot(up));
            if error.is_nan() || error > max_error_rad.max(MIN_ERROR_RAD) {
                continue;
            }
            let inside = self.limits[0].contains(q7) && self.limits[1].contains(q8);
            if inside && best.is_none_or(|bst| q7.abs() < bst[0].abs()) {
                best = Some(cand);
            }
        }
        best.ok_or_else(unreachable)
    }

    /// `positioner_from_table` at `q` and its derivatives with respect to
    /// `q7` and `q8` [eq. C.5–C.6 differentiated], as `(R, t)` pairs: the
    /// rotation matrix (unitless, per rad) and the translation (mm, mm/rad).
    /// `R = Ry(q7)·Rz(q8)`, `t = Ry(q7)·(0, 0, |C7C8|)`.
    pub fn positioner_from_table_derivatives(
        &self,
        q: &PositionerJoints,
    ) -> [(crate::math::Matrix3, Vector3); 3] {
        let (s7, c7) = q[0].sin_cos();
        let (s8, c8) = q[1].sin_cos();
        let ry = rot_y(s7, c7);
        let rz = rot_z(s8, c8);
        // d/dq Ry(q) = Ry(q + π/2) with the middle row zeroed; likewise Rz
        let mut dry = rot_y(c7, -s7);
        dry[(1, 1)] = 0.0;
        let mut drz = rot_z(c8, -s8);
        drz[(2, 2)] = 0.0;
        let l = self.tilt_to_table_mm;
        [
            (ry * rz, Vector3::new(l * s7, 0.0, l * c7)),
            (dry * rz, Vector3::new(l * c7, 0.0, -l * s7)),
            (ry * drz, Vector3::zeros()),
        ]
    }

    /// Table-frame build direction seen in the positioner frame at `q` (helper for checks).
    pub fn direction_in_positioner(&self, q: &PositionerJoints, v_table: &Vector3) -> Vector3 {
        self.positioner_from_table(q).rotation * v_table
    }
}
