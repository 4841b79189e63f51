//! **Stage 5 — the arm drawn as a chain.** The arm's joint frame origins at
//! controller joints (rad), robot base frame (mm): the forward kinematics
//! ([`RobotModel::chain_state`]) read out as the seven points between which
//! the arm's links run. The whole-cell check
//! ([`program::cell_check`](crate::program::cell_check)) puts its link
//! capsules on them and the report
//! ([`report::cell_view`](crate::report::cell_view)) draws them.

use crate::math::{Point3, Rotation3, Vector3};
use crate::robot::model::{Joints, RobotModel};

/// Joint frame origins of `robot` at controller joints `q` (rad), base frame (mm).
pub fn arm_chain(robot: &RobotModel, q: &Joints) -> [Point3; 7] {
    let g = &robot.geometry;
    let s = robot.chain_state(q);
    let t = s.angles.0;
    let rz = Rotation3::from_axis_angle(&Vector3::z_axis(), t[0]);
    let (s3, c3) = t[2].sin_cos();
    let shoulder = s.axis_points[1];
    let elbow = s.axis_points[2];
    let offset_end = elbow + rz * Vector3::new(g.elbow_offset_mm * s3, 0.0, g.elbow_offset_mm * c3);
    [
        Point3::origin(),
        Point3::new(0.0, 0.0, g.shoulder_height_mm),
        shoulder,
        elbow,
        offset_end,
        s.wrist_centre,
        Point3::from(s.base_from_flange.translation.vector),
    ]
}
