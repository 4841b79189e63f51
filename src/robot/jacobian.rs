//! Geometric Jacobian of a [`RobotModel`] with respect to the controller
//! joints (FANUC J2/J3 coupling included). Rows 0..3: linear velocity of a
//! point rigidly attached to the flange (mm/rad, base frame); rows 3..6:
//! angular velocity (rad/rad, base frame). SPEC §6.5, §7.

use nalgebra::{Matrix6, Vector6};

use crate::math::{Point3, Vector3};
use crate::robot::model::{Joints, RobotModel};

/// A 6×6 geometric Jacobian: `[v; omega] = J · dq`, v in mm/rad, omega in rad/rad,
/// base frame.
pub type Jacobian = Matrix6<f64>;

/// A twist `[v; omega]`: linear velocity of a reference point (mm per unit)
/// and angular velocity (rad per unit), base frame.
pub type Twist = Vector6<f64>;

impl RobotModel {
    /// Geometric Jacobian at `q` (rad) for the flange origin.
    pub fn jacobian(&self, q: &Joints) -> Jacobian {
        self.jacobian_at(q, &Vector3::zeros())
    }

    /// Geometric Jacobian at `q` (rad) for the point `point_in_flange`
    /// (flange frame, mm), e.g. a TCP.
    pub fn jacobian_at(&self, q: &Joints, point_in_flange: &Vector3) -> Jacobian {
        let st = self.chain_state(q);
        let p: Point3 = st.base_from_flange * Point3::from(*point_in_flange);
        // Columns for the canonical angles (t1, t2, f3, t4, t5, t6). The forearm
        // attitude f3 is absolute, so t2 at constant f3 translates the forearm:
        // its column is the elbow's velocity, with no rotation.
        let mut jt = Matrix6::zeros();
        for i in 0..6 {
            let a = st.axis_dirs[i];
            let (v, w) = if i == 1 {
                (
                    a.cross(&(st.axis_points[2] - st.axis_points[1])),
                    Vector3::zeros(),
                )
            } else {
                (a.cross(&(p - st.axis_points[i])), a)
            };
            jt.fixed_view_mut::<3, 1>(0, i).copy_from(&v);
            jt.fixed_view_mut::<3, 1>(3, i).copy_from(&w);
        }
        jt * self.canonical_jacobian()
    }
}

/// A twist of a rigid motion: rotation `omega` (rad per unit) about the axis
/// through `centre` (mm), expressed as the velocity of `point` (mm) and
/// `omega`. `v = omega × (point − centre)`.
pub fn twist_about_axis(omega: &Vector3, centre: &Point3, point: &Point3) -> Twist {
    let v = omega.cross(&(point - centre));
    Twist::new(v.x, v.y, v.z, omega.x, omega.y, omega.z)
}
