//! Forward kinematics of a [`RobotModel`]: controller joints (rad) → flange
//! pose in the robot base frame (mm). SPEC §6.1; the chain is in the
//! [`model`](crate::robot::model) module doc.

use crate::math::{Isometry3, Matrix3, Point3, Rotation3, Translation3, UnitQuaternion, Vector3};
use crate::robot::model::{Joints, RobotModel};

/// Canonical joint angles (rad): `t1`, `t2`, forearm attitude `f3`, `t4`, `t5`, `t6`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CanonicalAngles(pub [f64; 6]);

/// Rotation about x by `a` (rad), from its sine and cosine.
#[inline]
pub(crate) fn rot_x(s: f64, c: f64) -> Matrix3 {
    Matrix3::new(1.0, 0.0, 0.0, 0.0, c, -s, 0.0, s, c)
}

/// Rotation about y, from sine and cosine.
#[inline]
pub(crate) fn rot_y(s: f64, c: f64) -> Matrix3 {
    Matrix3::new(c, 0.0, s, 0.0, 1.0, 0.0, -s, 0.0, c)
}

/// Rotation about z, from sine and cosine.
#[inline]
pub(crate) fn rot_z(s: f64, c: f64) -> Matrix3 {
    Matrix3::new(c, -s, 0.0, s, c, 0.0, 0.0, 0.0, 1.0)
}

/// Positions and axes of the six joints and the wrist frame at one joint
/// vector, base frame. Used by the Jacobian.
#[derive(Debug, Clone, Copy)]
pub struct ChainState {
    /// Canonical angles (rad).
    pub angles: CanonicalAngles,
    /// A point of each joint axis, base frame (mm).
    pub axis_points: [Point3; 6],
    /// Unit direction of each canonical joint axis, base frame.
    pub axis_dirs: [Vector3; 6],
    /// Wrist centre, base frame (mm).
    pub wrist_centre: Point3,
    /// Canonical wrist frame rotation (x = approach), base frame.
    pub base_from_wrist: Matrix3,
    /// Flange pose `base_from_flange` (mm).
    pub base_from_flange: Isometry3,
}

impl RobotModel {
    /// Canonical angles of controller joints `q` (rad).
    #[inline]
    pub fn canonical_from_joints(&self, q: &Joints) -> CanonicalAngles {
        let c = &self.convention;
        let mut t = [0.0; 6];
        for i in 0..6 {
            t[i] = c.sign[i] * q[i] + c.offset_rad[i];
        }
        if !c.j2_j3_coupled {
            t[2] += t[1];
        }
        CanonicalAngles(t)
    }

    /// Controller joints (rad) of canonical angles, each in the turn the
    /// canonical angle gives (no wrapping).
    #[inline]
    pub fn joints_from_canonical(&self, t: &CanonicalAngles) -> Joints {
        let c = &self.convention;
        let t = t.0;
        let mut q = [0.0; 6];
        for i in 0..6 {
            let ti = if i == 2 && !c.j2_j3_coupled {
                t[2] - t[1]
            } else {
                t[i]
            };
            q[i] = (ti - c.offset_rad[i]) * c.sign[i];
        }
        q
    }

    /// `d(canonical)/d(joints)`: 6×6, diagonal signs plus the J2 term of the
    /// forearm attitude on uncoupled arms.
    pub fn canonical_jacobian(&self) -> nalgebra::Matrix6<f64> {
        let c = &self.convention;
        let mut m = nalgebra::Matrix6::zeros();
        for i in 0..6 {
            m[(i, i)] = c.sign[i];
        }
        if !c.j2_j3_coupled {
            m[(2, 1)] = c.sign[1];
        }
        m
    }

    /// Wrist centre (base frame, mm) and the arm rotation `Rz(t1)·Ry(f3)` of canonical angles.
    #[inline]
    pub(crate) fn arm_canonical(&self, t: &[f64; 6]) -> (Vector3, Matrix3) {
        let g = &self.geometry;
        let (s1, c1) = t[0].sin_cos();
        let (s2, c2) = t[1].sin_cos();
        let (s3, c3) = t[2].sin_cos();
        // in the arm plane (after Rz(t1)): x forward, y lateral, z up
        let x =
            g.shoulder_offset_mm + g.upper_arm_mm * s2 + g.forearm_mm * c3 + g.elbow_offset_mm * s3;
        let z =
            g.shoulder_height_mm + g.upper_arm_mm * c2 - g.forearm_mm * s3 + g.elbow_offset_mm * c3;
        let y = g.lateral_offset_mm;
        let w = Vector3::new(c1 * x - s1 * y, s1 * x + c1 * y, z);
        let r_arm = rot_z(s1, c1) * rot_y(s3, c3);
        (w, r_arm)
    }

    /// Flange pose `base_from_flange` (mm) of controller joints `q` (rad).
    /// Thesis eq. C.1–C.3 with SPEC §6.1's conventions.
    pub fn flange_pose(&self, q: &Joints) -> Isometry3 {
        let t = self.canonical_from_joints(q).0;
        let (w, r_arm) = self.arm_canonical(&t);
        let (s4, c4) = t[3].sin_cos();
        let (s5, c5) = t[4].sin_cos();
        let (s6, c6) = t[5].sin_cos();
        let r_w = r_arm * rot_x(s4, c4) * rot_y(s5, c5) * rot_x(s6, c6);
        let p = w + r_w.column(0) * self.geometry.wrist_to_flange_mm;
        let r_f = r_w * self.convention.wrist_from_flange;
        Isometry3::from_parts(
            Translation3::from(p),
            UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(r_f)),
        )
    }

    /// Flange position only (base frame, mm): cheaper than [`RobotModel::flange_pose`].
    pub fn flange_position(&self, q: &Joints) -> Point3 {
        let t = self.canonical_from_joints(q).0;
        let (w, r_arm) = self.arm_canonical(&t);
        let (s4, c4) = t[3].sin_cos();
        let (s5, c5) = t[4].sin_cos();
        // approach = R_arm Rx(t4) Ry(t5) e_x (Rx(t6) keeps e_x)
        let a_local = Vector3::new(c5, s4 * s5, -c4 * s5);
        Point3::from(w + r_arm * a_local * self.geometry.wrist_to_flange_mm)
    }

    /// Pose of a tool centre point: `base_from_flange · flange_from_tcp` (mm).
    pub fn tcp_pose(&self, q: &Joints, flange_from_tcp: &Isometry3) -> Isometry3 {
        self.flange_pose(q) * flange_from_tcp
    }

    /// Joint axes, wrist and flange at `q` (base frame): everything the
    /// Jacobian needs.
    pub fn chain_state(&self, q: &Joints) -> ChainState {
        let g = &self.geometry;
        let angles = self.canonical_from_joints(q);
        let t = angles.0;
        let (s1, c1) = t[0].sin_cos();
        let (s2, c2) = t[1].sin_cos();
        let (s4, c4) = t[3].sin_cos();
        let (s5, c5) = t[4].sin_cos();
        let (s6, c6) = t[5].sin_cos();
        let rz = rot_z(s1, c1);
        let shoulder = Point3::from(
            rz * Vector3::new(
                g.shoulder_offset_mm,
                g.lateral_offset_mm,
                g.shoulder_height_mm,
            ),
        );
        let elbow = shoulder + rz * Vector3::new(g.upper_arm_mm * s2, 0.0, g.upper_arm_mm * c2);
        let (w, r_arm) = self.arm_canonical(&t);
        let wrist = Point3::from(w);
        let r4 = r_arm * rot_x(s4, c4);
        let r5 = r4 * rot_y(s5, c5);
        let r_w = r5 * rot_x(s6, c6);
        let y1 = rz.column(1).into_owned();
        let p = wrist + r_w.column(0) * g.wrist_to_flange_mm;
        let r_f = r_w * self.convention.wrist_from_flange;
        ChainState {
            angles,
            axis_points: [Point3::origin(), shoulder, elbow, wrist, wrist, wrist],
            axis_dirs: [
                Vector3::z(),
                y1,
                y1,
                r_arm.column(0).into_owned(),
                r4.column(1).into_owned(),
                r5.column(0).into_owned(),
            ],
            wrist_centre: wrist,
            base_from_wrist: r_w,
            base_from_flange: Isometry3::from_parts(
                Translation3::from(p.coords),
                UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(r_f)),
            ),
        }
    }
}
