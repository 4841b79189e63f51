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
use crate::robot::ik::Configuration;
use crate::robot::jacobian::{twist_about_axis, Twist};
use crate::robot::kinematics::{rot_x, rot_y, rot_z};
use crate::robot::model::{Joints, RobotModel};
use crate::robot::orientation::Bryant;
use crate::robot::positioner::{Positioner, PositionerJoints};
use crate::robot::RobotError;

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
                value: f64::NAN,
                reason: "must be finite",
            });
        }
        Ok(())
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
        if den.is_nan() || den <= 1e-14 {
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
    /// Largest accepted angle between the build direction and the vertical
    /// when the positioner cannot make it exact (rad); see
    /// [`Positioner::angles_for_vertical`]. 1° in the thesis cell files.
    pub max_vertical_error_rad: f64,
}

impl TorchCarriedCell {
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
        Ok(())
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
        let qp = self.positioner_angles(p, q8_hint)?;
        let base_from_part = self.base_from_part(&qp);
        let m = base_from_part * p.position_mm;
        let t = base_from_part.rotation * p.tool_axis;
        let b = bryant_matrix(&torch_carried_angles(&t, r_z));
        let base_from_tcp = iso(b, m.coords);
        let base_from_flange = base_from_tcp * self.flange_from_tcp.inverse();
        let twist = twist_about_axis(
            &t.into_inner(),
            &m,
            &Point3::from(base_from_flange.translation.vector),
        );
        Ok(CellPose {
            base_from_flange,
            positioner: Some(qp),
            flange_twist_per_rz: twist,
        })
    }
}

/// Either cell (closed set).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub enum Cell {
    /// Fixed torch, the robot holds the part.
    PartCarried(PartCarriedCell),
    /// Part on the positioner, the robot holds the torch.
    TorchCarried(TorchCarriedCell),
}

impl Cell {
    /// The arm of the cell.
    pub fn robot(&self) -> &RobotModel {
        match self {
            Cell::PartCarried(c) => &c.robot,
            Cell::TorchCarried(c) => &c.robot,
        }
    }

    /// The IK branch of the cell.
    pub fn configuration(&self) -> Configuration {
        match self {
            Cell::PartCarried(c) => c.configuration,
            Cell::TorchCarried(c) => c.configuration,
        }
    }

    /// Name of the cell.
    pub fn name(&self) -> &str {
        match self {
            Cell::PartCarried(c) => &c.name,
            Cell::TorchCarried(c) => &c.name,
        }
    }

    /// Checks the cell.
    ///
    /// # Errors
    /// As the cells' `validate`.
    pub fn validate(&self) -> Result<(), RobotError> {
        match self {
            Cell::PartCarried(c) => c.validate(),
            Cell::TorchCarried(c) => c.validate(),
        }
    }

    /// Flange pose, positioner and twist per unit `R_Z` of one point.
    ///
    /// # Errors
    /// As the cells' `pose`.
    pub fn pose(&self, p: &CellPoint, r_z: f64, q8_hint: f64) -> Result<CellPose, RobotError> {
        match self {
            Cell::PartCarried(c) => c.pose(p, r_z),
            Cell::TorchCarried(c) => c.pose(p, r_z, q8_hint),
        }
    }

    /// Joints (rad) for one point in the cell's configuration, unwrapped
    /// towards `near` when given; also returns the cell pose.
    ///
    /// # Errors
    /// As [`Cell::pose`] and [`RobotModel::inverse`].
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
    /// [`RobotError::SingularJacobian`] at a singularity; as [`Cell::pose`].
    pub fn dq_drz(&self, pose: &CellPose, q: &Joints) -> Result<Joints, RobotError> {
        let robot = self.robot();
        let j = robot.jacobian(q);
        // a near-exact singularity can leave a finite but meaningless LU solution
        if crate::robot::indices::dexterity(&j, 1000.0) < 1e-12 {
            return Err(RobotError::SingularJacobian {
                manipulability: crate::robot::indices::manipulability(&j),
            });
        }
        let lu = j.lu();
        let sol = lu.solve(&pose.flange_twist_per_rz);
        match sol {
            Some(x) if x.iter().all(|v| v.is_finite()) => Ok([x[0], x[1], x[2], x[3], x[4], x[5]]),
            _ => Err(RobotError::SingularJacobian {
                manipulability: crate::robot::indices::manipulability(&j),
            }),
        }
    }
}
