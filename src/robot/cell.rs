//! The two cell configurations of the thesis: part carried (fixed vertical
//! torch, the robot holds the part) and torch carried (the part on a 2-axis
//! positioner, the robot holds the torch). Each turns one path point (part
//! frame: position mm, tool axis, free angle `R_Z` rad) into a flange pose in
//! the robot base frame, joints, and the flange twist per unit `R_Z` that the
//! optimiser needs. SPEC §6.4, thesis §3.1.2.2 eq. 3.4–3.13, §4.2.

use serde::{Deserialize, Serialize};

use crate::math::{
    Isometry3, Matrix3, Point3, Rotation3, Translation3, UnitQuaternion, UnitVector3, Vector3,
};
use crate::robot::error::OutOfReach;
use crate::robot::ik::Configuration;
use crate::robot::jacobian::{twist_about_axis, Twist};
use crate::robot::kinematics::{rot_x, rot_y, rot_z};
use crate::robot::model::{Joints, RobotModel};
use crate::robot::orientation::Bryant;
use crate::robot::positioner::{Positioner, PositionerJoints};
use crate::robot::RobotError;

/// Slack on the shoulder-circle reach test, as a fraction of the arm's
/// longest reach (relative): rounding of the FK/IK chain.
const REACH_SLACK_REL: f64 = 1e-6;
/// `t_z² + u²` below this (unitless, a squared sine) means `R_X = ±90°`: the
/// rate of the pose in `R_Z` is undefined.
const MIN_TILT_DEN: f64 = 1e-14;
/// Dexterity at 1000 mm (unitless) below which the Jacobian is singular and
/// its LU solution meaningless.
const SINGULAR_DEXTERITY: f64 = 1e-12;
/// Dexterity bound (unitless) 100 times [`SINGULAR_DEXTERITY`]: a pose whose
/// already known dexterity, rescaled to 1000 mm, is above it skips the
/// singularity test (it would pass).
const REGULAR_DEXTERITY: f64 = 1e-10;

/// One path point as the cells see it (part frame).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CellPoint {
    /// Deposition point, part frame (mm).
    pub position_mm: Point3,
    /// Tool axis `T` (from the deposition point towards the torch), part frame.
    pub tool_axis: UnitVector3,
    /// Build direction `b`, part frame: what the positioner turns vertical in
    /// the torch-carried cell. `None`: the tool axis is used.
    pub build_direction: Option<UnitVector3>,
    /// Positioner joints `[q7, q8]` (rad) planned for this point (torch-carried
    /// cell, [`crate::optimise::positioner`]); `None`: the positioner turns
    /// `b` exactly vertical ([`TorchCarriedCell::positioner_angles`]).
    pub positioner: Option<PositionerJoints>,
    /// Travel speed of the deposition point on the way into this point
    /// from the previous point of its bead (mm/s, along the chord); unused
    /// at a bead's first point. What the joint speeds are measured at.
    pub travel_speed_mm_s: f64,
}

/// Where one path point puts the cell.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CellPose {
    /// Flange pose `base_from_flange` (mm).
    pub base_from_flange: Isometry3,
    /// Positioner joints `[q7, q8]` (rad); `None` in the part-carried cell.
    pub positioner: Option<PositionerJoints>,
    /// Flange twist per radian of `R_Z` at constant everything else: angular
    /// part (rad/rad) and the linear velocity of the flange origin (mm/rad),
    /// base frame. A rotation about the torch axis through the deposition point.
    pub flange_twist_per_rz: Twist,
}

/// Bryant angles `(R_X, R_Y)` of the part in the part-carried cell
/// [eq. 3.6–3.7], such that `A = Rx(R_X)·Ry(R_Y)·Rz(R_Z)` satisfies `A·T = +Z`.
pub fn part_carried_angles(t: &UnitVector3, r_z: f64) -> Bryant {
    let (s, c) = r_z.sin_cos();
    let sx = t.y * c + t.x * s;
    let u = t.x * c - t.y * s;
    let cx = (u * u + t.z * t.z).sqrt();
    Bryant {
        rx: sx.atan2(cx),
        ry: (-u).atan2(t.z),
        rz: r_z,
    }
}

/// Bryant angles `(R_X, R_Y)` of the torch in the torch-carried cell
/// [eq. 3.12–3.13], such that `B = Rx(R_X)·Ry(R_Y)·Rz(R_Z)` has its z axis along
/// `t` (base frame).
///
/// Eq. 3.13 is printed `R_Y = atan2(-T_X, ...)`; solving eq. 3.11 gives
/// `+T_X` (with the printed sign `B·z` is `T` mirrored in X), used here.
pub fn torch_carried_angles(t: &UnitVector3, r_z: f64) -> Bryant {
    let rx = (-t.y).atan2(t.z);
    let (s, c) = rx.sin_cos();
    Bryant {
        rx,
        ry: t.x.atan2(c * t.z - s * t.y),
        rz: r_z,
    }
}

fn bryant_matrix(b: &Bryant) -> Matrix3 {
    let (sx, cx) = b.rx.sin_cos();
    let (sy, cy) = b.ry.sin_cos();
    let (sz, cz) = b.rz.sin_cos();
    rot_x(sx, cx) * rot_y(sy, cy) * rot_z(sz, cz)
}

fn iso(r: Matrix3, p: Vector3) -> Isometry3 {
    Isometry3::from_parts(
        Translation3::from(p),
        UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(r)),
    )
}

/// Largest translation accepted in a cell's mounts (mm): 100 m. No cell is
/// that large; a larger number is a typo or a unit mistake (`1e308` would
/// overflow to infinity in the first product).
pub const MAX_MOUNT_MM: f64 = 1.0e5;

/// Checks that a rigid transform is finite and its translation within
/// [`MAX_MOUNT_MM`], naming the cell-file `field`.
fn check_mount(what: &str, field: &'static str, iso: &Isometry3) -> Result<(), RobotError> {
    let t = iso.translation.vector;
    let q = iso.rotation.coords;
    if !(t.iter().chain(q.iter()).all(|v| v.is_finite())) {
        return Err(RobotError::InvalidParameter {
            what: what.to_string(),
            field,
            value: t
                .iter()
                .copied()
                .find(|v| !v.is_finite())
                .unwrap_or(f64::NAN),
            reason: "must be finite",
        });
    }
    let worst = t.amax();
    if worst > MAX_MOUNT_MM {
        return Err(RobotError::InvalidParameter {
            what: what.to_string(),
            field,
            value: worst,
            reason: "a translation beyond 100 m (1e5 mm) is not a robot cell",
        });
    }
    Ok(())
}

/// Smallest and largest distance (mm) from `p` (base frame) to the circle
/// the shoulder point (on the J2 axis, in the arm plane) describes as J1
/// turns: radius `hypot(shoulder_offset, lateral_offset)` about the base Z
/// axis at the shoulder height.
fn shoulder_circle_distances(robot: &RobotModel, p: &Point3) -> (f64, f64) {
    let g = &robot.geometry;
    let radius = g.shoulder_offset_mm.hypot(g.lateral_offset_mm);
    let rho = p.x.hypot(p.y);
    let dz = p.z - g.shoulder_height_mm;
    ((rho - radius).hypot(dz), (rho + radius).hypot(dz))
}

/// The reach test shared by both cells: the wrist centre is within
/// `allowance_mm` of `anchor`, and within `[|c2 − k|, c2 + k]` of the
/// shoulder point (`c2` the upper arm, `k` the J3 → wrist-centre distance),
/// so the anchor must be within `allowance_mm` of that shell.
fn check_anchor_reach(
    robot: &RobotModel,
    what: &str,
    field: &'static str,
    anchor: &Point3,
    allowance_mm: f64,
) -> Result<(), RobotError> {
    let g = &robot.geometry;
    let k = g.forearm_mm.hypot(g.elbow_offset_mm);
    let arm_max = g.upper_arm_mm + k;
    let arm_min = (g.upper_arm_mm - k).abs();
    // rounding of the FK/IK chain; the test is a bound, not a decision at the edge
    let slack = REACH_SLACK_REL * arm_max;
    let (near, far) = shoulder_circle_distances(robot, anchor);
    let max_reach = arm_max + allowance_mm + slack;
    let min_reach = (arm_min - allowance_mm - slack).max(0.0);
    let distance = if !(near <= max_reach) {
        near
    } else if far < min_reach {
        far
    } else {
        return Ok(());
    };
    Err(RobotError::OutOfReach(Box::new(OutOfReach {
        what: what.to_string(),
        field,
        point_mm: [anchor.x, anchor.y, anchor.z],
        distance_mm: distance,
        min_reach_mm: min_reach,
        max_reach_mm: max_reach,
        arm_min_mm: arm_min,
        arm_max_mm: arm_max,
    })))
}

fn check_part_radius(what: &str, part_radius_mm: f64) -> Result<(), RobotError> {
    if part_radius_mm.is_finite() && part_radius_mm >= 0.0 {
        Ok(())
    } else {
        Err(RobotError::InvalidParameter {
            what: what.to_string(),
            field: "part_radius_mm",
            value: part_radius_mm,
            reason: "must be finite and >= 0",
        })
    }
}

/// Part carried ("pièce portée", fig. 3.2a, 3.5): the torch is fixed and
/// vertical at `D_R`; the robot holds the part, whose frame is fixed to the flange.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PartCarriedCell {
    /// Human-readable name.
    pub name: String,
    /// The arm.
    pub robot: RobotModel,
    /// Deposition point `D_R`, robot base frame (mm) [eq. 3.8, 3.18].
    pub deposition_point_mm: Point3,
    /// IK branch used for the whole path.
    pub configuration: Configuration,
    /// `flange_from_part` (mm): identity in the thesis (part frame = flange
    /// frame, part Z along the approach axis).
    pub flange_from_part: Isometry3,
}

impl PartCarriedCell {
    /// Checks the robot and the pose data.
    ///
    /// # Errors
    /// [`RobotError::InvalidParameter`] naming the field.
    pub fn validate(&self) -> Result<(), RobotError> {
        self.robot.validate()?;
        if !self.deposition_point_mm.iter().all(|v| v.is_finite()) {
            return Err(RobotError::InvalidParameter {
                what: self.name.clone(),
                field: "deposition_point_mm",
                value: self
                    .deposition_point_mm
                    .iter()
                    .copied()
                    .find(|v| !v.is_finite())
                    .unwrap_or(f64::NAN),
                reason: "must be finite",
            });
        }
        check_mount(
            &self.name,
            "flange_from_part_xyzwpr",
            &self.flange_from_part,
        )
    }

    /// Refuses a cell that cannot reach its deposition point `D_R` for any
    /// path point within `part_radius_mm` of the part frame origin.
    ///
    /// A sound bound, from the arm's lengths only: the deposition point is
    /// a path point `M`, so the flange origin is within
    /// `|M| + |flange_from_part|` of `D_R` and the wrist centre another
    /// `wrist_to_flange_mm` away; the wrist centre is within
    /// `[|c2 − k|, c2 + k]` of the shoulder point (`c2` upper arm,
    /// `k = hypot(forearm, elbow_offset)`), which J1 turns on a circle. A
    /// cell this refuses has no IK solution at any point of any such part;
    /// one it accepts may still fail at some points (orientation, limits).
    ///
    /// `part_radius_mm`: the largest distance of a path point from the part
    /// frame origin (mm); for a plan, the path's own.
    ///
    /// # Errors
    /// [`RobotError::OutOfReach`] naming `deposition_point_mm`, its
    /// distance from the shoulder circle and the arm's reach;
    /// [`RobotError::InvalidParameter`] for a negative or non-finite radius.
    pub fn check_reach(&self, part_radius_mm: f64) -> Result<(), RobotError> {
        check_part_radius(&self.name, part_radius_mm)?;
        let allowance = part_radius_mm
            + self.flange_from_part.translation.vector.norm()
            + self.robot.geometry.wrist_to_flange_mm;
        check_anchor_reach(
            &self.robot,
            &self.name,
            "deposition_point_mm",
            &self.deposition_point_mm,
            allowance,
        )
    }

    /// `base_from_part` for path point `m` with tool axis `t` (part frame)
    /// and free angle `r_z` (rad): rotation `A` with `A·T = +Z`, translation
    /// `D_R − A·M` [eq. 3.8–3.10].
    pub fn base_from_part(&self, m: &Point3, t: &UnitVector3, r_z: f64) -> Isometry3 {
        let a = bryant_matrix(&part_carried_angles(t, r_z));
        iso(a, self.deposition_point_mm.coords - a * m.coords)
    }

    /// Flange pose, positioner (none) and flange twist per unit `R_Z` for one point.
    ///
    /// The twist is a rotation about the vertical through `D_R` at the rate
    /// `dpsi/dR_Z = T_Z / (T_Z² + (T_X cos R_Z − T_Y sin R_Z)²)` (the
    /// derivative of eq. 3.6–3.7; 1 for a vertical tool axis), which is what
    /// changing `R_Z` does to the part.
    ///
    /// # Errors
    /// [`RobotError::DegenerateToolAxis`] when that rate is undefined (`R_X = ±90°`).
    pub fn pose(&self, p: &CellPoint, r_z: f64) -> Result<CellPose, RobotError> {
        let t = &p.tool_axis;
        let (s, c) = r_z.sin_cos();
        let u = t.x * c - t.y * s;
        let den = t.z * t.z + u * u;
        if den.is_nan() || den <= MIN_TILT_DEN {
            return Err(RobotError::DegenerateToolAxis {
                tx: t.x,
                ty: t.y,
                tz: t.z,
                r_z,
            });
        }
        let rate = t.z / den;
        let base_from_part = self.base_from_part(&p.position_mm, t, r_z);
        let base_from_flange = base_from_part * self.flange_from_part.inverse();
        let omega = Vector3::z() * rate;
        let twist = twist_about_axis(
            &omega,
            &self.deposition_point_mm,
            &Point3::from(base_from_flange.translation.vector),
        );
        Ok(CellPose {
            base_from_flange,
            positioner: None,
            flange_twist_per_rz: twist,
        })
    }
}

/// Torch carried ("dispositif de dépôt porté", fig. 3.2b, 3.7): the part is
/// on the positioner, which turns the build direction vertical; the robot
/// carries the torch along the tool axis with the free angle `R_Z`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TorchCarriedCell {
    /// Human-readable name.
    pub name: String,
    /// The arm.
    pub robot: RobotModel,
    /// The positioner.
    pub positioner: Positioner,
    /// `base_from_positioner` (mm): the positioner frame in the robot base frame [table 3.7].
    pub base_from_positioner: Isometry3,
    /// `flange_from_tcp` (mm): the torch [eq. 4.9]. The TCP z axis is the
    /// torch axis, pointing from the wire tip into the torch (along `T`).
    pub flange_from_tcp: Isometry3,
    /// `table_from_part` (mm): the part frame on the table (identity: part
    /// frame = table frame, origin at the table centre C8).
    pub table_from_part: Isometry3,
    /// IK branch used for the whole path.
    pub configuration: Configuration,
    /// Largest admissible hose torsion `|q4 + q6|` (rad) [eq. 4.8: 120°].
    pub max_hose_torsion_rad: f64,
    /// Half angle of the cone about the vertical within which the build
    /// direction `b` must stay, seen in the robot base frame (rad): the
    /// positioner's laws ([`crate::optimise::positioner`]) move within it, and
    /// the thesis's exact-vertical mode accepts this much error where the
    /// positioner cannot make `b` exactly vertical. Set from the process
    /// qualification; 15° in the sample cells.
    pub max_vertical_error_rad: f64,
}

impl TorchCarriedCell {
    /// The values the positioner's turn may take in a program (rad): its
    /// travel when finite, else the stated stroke, else none on a controller
    /// that turns endless axes modulo 360° ([`Vendor::turns_endless_axes_modulo`](crate::robot::Vendor::turns_endless_axes_modulo)),
    /// else ±1 turn ([`Positioner::turn_stroke`]). Each bead is shifted by
    /// whole turns into it, so a bead's turn must span less than it holds.
    pub fn turn_stroke(&self) -> crate::robot::JointLimit {
        self.positioner
            .turn_stroke(self.robot.vendor.turns_endless_axes_modulo())
    }

    /// Checks robot, positioner and the hose limit.
    ///
    /// # Errors
    /// [`RobotError::InvalidParameter`] naming the field.
    pub fn validate(&self) -> Result<(), RobotError> {
        self.robot.validate()?;
        self.positioner.validate()?;
        if self.max_vertical_error_rad.is_nan() || self.max_vertical_error_rad < 0.0 {
            return Err(RobotError::InvalidParameter {
                what: self.name.clone(),
                field: "max_vertical_error_deg",
                value: self.max_vertical_error_rad.to_degrees(),
                reason: "must be >= 0",
            });
        }
        if self.max_hose_torsion_rad.is_nan() || self.max_hose_torsion_rad <= 0.0 {
            return Err(RobotError::InvalidParameter {
                what: self.name.clone(),
                field: "max_hose_torsion_deg",
                value: self.max_hose_torsion_rad.to_degrees(),
                reason: "must be > 0",
            });
        }
        let tilt = self.positioner.tilt_to_table_mm;
        if tilt.abs() > MAX_MOUNT_MM {
            return Err(RobotError::InvalidParameter {
                what: self.name.clone(),
                field: "positioner.tilt_to_table_mm",
                value: tilt,
                reason: "a length beyond 100 m (1e5 mm) is not a positioner",
            });
        }
        check_mount(
            &self.name,
            "positioner_pose_xyzwpr",
            &self.base_from_positioner,
        )?;
        check_mount(&self.name, "tool_xyzwpr", &self.flange_from_tcp)?;
        check_mount(&self.name, "table_from_part_xyzwpr", &self.table_from_part)
    }

    /// Refuses a cell whose arm cannot reach the work on the positioner for
    /// any path point within `part_radius_mm` of the part frame origin.
    ///
    /// A sound bound, from the lengths only: the part origin is within
    /// `|C7C8| + |table_from_part|` of the tilt centre C7 (the positioner
    /// frame origin) at any positioner angles, the TCP is on a path point
    /// (`part_radius_mm` further), the flange `|flange_from_tcp|` from the
    /// TCP and the wrist centre `wrist_to_flange_mm` from the flange; the
    /// arm is bounded as in [`PartCarriedCell::check_reach`].
    ///
    /// # Errors
    /// [`RobotError::OutOfReach`] naming `positioner_pose_xyzwpr`;
    /// [`RobotError::InvalidParameter`] for a negative or non-finite radius.
    pub fn check_reach(&self, part_radius_mm: f64) -> Result<(), RobotError> {
        check_part_radius(&self.name, part_radius_mm)?;
        let allowance = part_radius_mm
            + self.positioner.tilt_to_table_mm.abs()
            + self.table_from_part.translation.vector.norm()
            + self.flange_from_tcp.translation.vector.norm()
            + self.robot.geometry.wrist_to_flange_mm;
        check_anchor_reach(
            &self.robot,
            &self.name,
            "positioner_pose_xyzwpr",
            &Point3::from(self.base_from_positioner.translation.vector),
            allowance,
        )
    }

    /// Angle (rad) between the point's build direction, seen in the robot
    /// base frame at positioner joints `q`, and the vertical.
    pub fn build_tilt(&self, p: &CellPoint, q: &PositionerJoints) -> f64 {
        let b_part = p.build_direction.unwrap_or(p.tool_axis);
        let b = self.base_from_part(q).rotation * b_part.into_inner();
        b.xy().norm().atan2(b.z)
    }

    /// Positioner angles that turn the point's build direction vertical,
    /// `q8_hint` (rad) used when `q8` is free.
    ///
    /// # Errors
    /// [`RobotError::PositionerUnreachable`].
    pub fn positioner_angles(
        &self,
        p: &CellPoint,
        q8_hint: f64,
    ) -> Result<PositionerJoints, RobotError> {
        let b_part = p.build_direction.unwrap_or(p.tool_axis);
        let b_table = self.table_from_part.rotation * b_part;
        let up = self.base_from_positioner.rotation.inverse() * Vector3::z_axis();
        self.positioner
            .angles_for_vertical(&b_table, &up, q8_hint, self.max_vertical_error_rad)
    }

    /// `base_from_part` at positioner joints `q` (mm).
    pub fn base_from_part(&self, q: &PositionerJoints) -> Isometry3 {
        self.base_from_positioner * self.positioner.positioner_from_table(q) * self.table_from_part
    }

    /// Flange pose, positioner joints and flange twist per unit `R_Z` for one
    /// point (`q8_hint` as in [`TorchCarriedCell::positioner_angles`]). The
    /// twist is a unit rotation about the torch axis through the TCP.
    ///
    /// # Errors
    /// [`RobotError::PositionerUnreachable`].
    pub fn pose(&self, p: &CellPoint, r_z: f64, q8_hint: f64) -> Result<CellPose, RobotError> {
        Ok(self.pose_in(&self.point_frame(p, q8_hint)?, r_z))
    }

    /// What [`TorchCarriedCell::pose`] computes of one point before `R_Z`:
    /// the positioner joints, the point and tool axis in the base frame and
    /// the torch's tilt (`q8_hint` as in [`TorchCarriedCell::pose`]).
    ///
    /// # Errors
    /// [`RobotError::PositionerUnreachable`].
    pub(crate) fn point_frame(
        &self,
        p: &CellPoint,
        q8_hint: f64,
    ) -> Result<TorchPointFrame, RobotError> {
        let positioner = match p.positioner {
            Some(q) => q,
            None => self.positioner_angles(p, q8_hint)?,
        };
        let base_from_part = self.base_from_part(&positioner);
        let point = base_from_part * p.position_mm;
        let axis = base_from_part.rotation * p.tool_axis;
        // R_X and R_Y of eq. 3.12–3.13 do not depend on R_Z
        let b = torch_carried_angles(&axis, 0.0);
        let (sx, cx) = b.rx.sin_cos();
        let (sy, cy) = b.ry.sin_cos();
        Ok(TorchPointFrame {
            positioner,
            point,
            axis,
            tilt: rot_x(sx, cx) * rot_y(sy, cy),
        })
    }

    /// [`TorchCarriedCell::pose`] at `r_z` (rad) from the point's
    /// [`TorchCarriedCell::point_frame`]: the same values to the bit (the
    /// torch's rotation is `(Rx·Ry)·Rz`, the product `bryant_matrix` forms).
    pub(crate) fn pose_in(&self, f: &TorchPointFrame, r_z: f64) -> CellPose {
        let (sz, cz) = r_z.sin_cos();
        let b = f.tilt * rot_z(sz, cz);
        let base_from_tcp = iso(b, f.point.coords);
        let base_from_flange = base_from_tcp * self.flange_from_tcp.inverse();
        let twist = twist_about_axis(
            &f.axis.into_inner(),
            &f.point,
            &Point3::from(base_from_flange.translation.vector),
        );
        CellPose {
            base_from_flange,
            positioner: Some(f.positioner),
            flange_twist_per_rz: twist,
        }
    }
}

/// One point of the torch-carried cell as the arm sees it whatever `R_Z`
/// ([`TorchCarriedCell::point_frame`]): the optimiser computes it once per
/// point of a layer whose positioner joints are planned, instead of in
/// every evaluation of the point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct TorchPointFrame {
    /// Positioner joints `[q7, q8]` (rad).
    pub positioner: PositionerJoints,
    /// Deposition point, robot base frame (mm).
    pub point: Point3,
    /// Tool axis `T`, robot base frame.
    pub axis: UnitVector3,
    /// `Rx(R_X)·Ry(R_Y)` of eq. 3.12–3.13: the torch's rotation at `R_Z = 0`
    /// (base frame).
    pub tilt: Matrix3,
}

/// The physical layout of a cell, either kind (closed set): the robot, the
/// deposition point or positioner, the torch (robot base frame, mm, rad);
/// what the optimiser, trajectory and program stages take. The front door's
/// [`Cell`](crate::Cell) wraps one with the cell file's name, source,
/// placement bounds and program settings.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[allow(
    clippy::large_enum_variant,
    reason = "a handful of cells per run, read by reference in the hot loops; boxing would only add an indirection"
)]
pub enum CellLayout {
    /// Fixed torch, the robot holds the part.
    PartCarried(PartCarriedCell),
    /// Part on the positioner, the robot holds the torch.
    TorchCarried(TorchCarriedCell),
}

impl CellLayout {
    /// The arm of the cell.
    pub fn robot(&self) -> &RobotModel {
        match self {
            CellLayout::PartCarried(c) => &c.robot,
            CellLayout::TorchCarried(c) => &c.robot,
        }
    }

    /// The IK branch of the cell.
    pub fn configuration(&self) -> Configuration {
        match self {
            CellLayout::PartCarried(c) => c.configuration,
            CellLayout::TorchCarried(c) => c.configuration,
        }
    }

    /// Name of the cell.
    pub fn name(&self) -> &str {
        match self {
            CellLayout::PartCarried(c) => &c.name,
            CellLayout::TorchCarried(c) => &c.name,
        }
    }

    /// Checks the cell.
    ///
    /// # Errors
    /// As the cells' `validate`.
    pub fn validate(&self) -> Result<(), RobotError> {
        match self {
            CellLayout::PartCarried(c) => c.validate(),
            CellLayout::TorchCarried(c) => c.validate(),
        }
    }

    /// Refuses a cell that cannot reach its work for any path point within
    /// `part_radius_mm` (mm) of the part frame origin; see
    /// [`PartCarriedCell::check_reach`] and [`TorchCarriedCell::check_reach`].
    ///
    /// # Errors
    /// [`RobotError::OutOfReach`] naming the cell-file field, the distance
    /// and the reach.
    pub fn check_reach(&self, part_radius_mm: f64) -> Result<(), RobotError> {
        match self {
            CellLayout::PartCarried(c) => c.check_reach(part_radius_mm),
            CellLayout::TorchCarried(c) => c.check_reach(part_radius_mm),
        }
    }

    /// Flange pose, positioner and twist per unit `R_Z` of one point.
    ///
    /// # Errors
    /// As the cells' `pose`.
    pub fn pose(&self, p: &CellPoint, r_z: f64, q8_hint: f64) -> Result<CellPose, RobotError> {
        match self {
            CellLayout::PartCarried(c) => c.pose(p, r_z),
            CellLayout::TorchCarried(c) => c.pose(p, r_z, q8_hint),
        }
    }

    /// Joints (rad) for one point in the cell's configuration, unwrapped
    /// towards `near` when given; also returns the cell pose.
    ///
    /// # Errors
    /// As [`CellLayout::pose`] and [`RobotModel::inverse`].
    pub fn joints(
        &self,
        p: &CellPoint,
        r_z: f64,
        near: Option<&Joints>,
        q8_hint: f64,
    ) -> Result<(Joints, CellPose), RobotError> {
        let pose = self.pose(p, r_z, q8_hint)?;
        let robot = self.robot();
        let q = match near {
            Some(n) => robot.inverse_near(&pose.base_from_flange, self.configuration(), n)?,
            None => robot.inverse(&pose.base_from_flange, self.configuration())?,
        };
        Ok((q, pose))
    }

    /// `dq/dR_Z` (rad/rad) at joints `q` for one point: `J⁻¹ · twist`, the
    /// flange twist of [`CellPose::flange_twist_per_rz`] [SPEC §7].
    ///
    /// # Errors
    /// [`RobotError::SingularJacobian`] at a singularity; as [`CellLayout::pose`].
    pub fn dq_drz(&self, pose: &CellPose, q: &Joints) -> Result<Joints, RobotError> {
        self.dq_drz_from(pose, &self.robot().jacobian(q), None)
    }

    /// [`CellLayout::dq_drz`] from the robot's Jacobian `j` at the joints
    /// (already computed by the caller) and, when known, a lower bound of
    /// its dexterity at the length scale `length_scale_mm` (`(bound,
    /// scale)`), which can spare the singularity test's SVD.
    ///
    /// # Errors
    /// As [`CellLayout::dq_drz`].
    pub(crate) fn dq_drz_from(
        &self,
        pose: &CellPose,
        j: &crate::robot::jacobian::Jacobian,
        dexterity_at: Option<(f64, f64)>,
    ) -> Result<Joints, RobotError> {
        // Rescaling the Jacobian's position rows from `s` to 1000 mm
        // multiplies them by `k = s/1000`: the smallest singular value is
        // at least min(k, 1)·σ_min, the largest at most max(k, 1)·σ_max, so
        // the dexterity at 1000 mm is at least min(k, 1/k) times the one at
        // `s`. A bound 100 times above the test's 10⁻¹² leaves the SVDs'
        // rounding (~10⁻¹⁵ in dexterity) far behind: the test would pass.
        let regular = dexterity_at.is_some_and(|(dex, s)| {
            let k = s / 1000.0;
            dex * k.min(1.0 / k) > REGULAR_DEXTERITY
        });
        // a near-exact singularity can leave a finite but meaningless LU solution
        if !regular && crate::robot::indices::dexterity(j, 1000.0) < SINGULAR_DEXTERITY {
            return Err(RobotError::SingularJacobian {
                manipulability: crate::robot::indices::manipulability(j),
            });
        }
        let lu = j.lu();
        let sol = lu.solve(&pose.flange_twist_per_rz);
        match sol {
            Some(x) if x.iter().all(|v| v.is_finite()) => Ok([x[0], x[1], x[2], x[3], x[4], x[5]]),
            _ => Err(RobotError::SingularJacobian {
                manipulability: crate::robot::indices::manipulability(j),
            }),
        }
    }
}
