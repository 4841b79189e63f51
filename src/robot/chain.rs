//! **Stage 5 — the arm drawn as a chain.** The arm's joint frame origins at
//! controller joints (rad), robot base frame (mm): the forward kinematics
//! ([`RobotModel::chain_state`]) read out as the seven points between which
//! the arm's links run. The whole-cell check
//! ([`program::cell_check`](crate::program::cell_check)) puts its link
//! capsules on them and the report
//! ([`report::cell_view`](crate::report::cell_view)) draws them.

use crate::math::{Isometry3, Point3, Rotation3, Vector3};
use crate::robot::model::{Joints, RobotModel};

/// Joint frame origins of `robot` at controller joints `q` (rad), base frame (mm).
pub fn arm_chain(robot: &RobotModel, q: &Joints) -> [Point3; 7] {
    arm_chain_and_flange(robot, q).0
}

/// [`arm_chain`] and the flange's pose (`base_from_flange`, mm) from the
/// same forward kinematics: the pose is [`RobotModel::flange_pose`]'s to
/// the bit (the same products in the same order).
pub fn arm_chain_and_flange(robot: &RobotModel, q: &Joints) -> ([Point3; 7], Isometry3) {
    let g = &robot.geometry;
    let s = robot.chain_state(q);
    let t = s.angles.0;
    let rz = Rotation3::from_axis_angle(&Vector3::z_axis(), t[0]);
    let (s3, c3) = t[2].sin_cos();
    let shoulder = s.axis_points[1];
    let elbow = s.axis_points[2];
    let offset_end = elbow + rz * Vector3::new(g.elbow_offset_mm * s3, 0.0, g.elbow_offset_mm * c3);
    let chain = [
        Point3::origin(),
        Point3::new(0.0, 0.0, g.shoulder_height_mm),
        shoulder,
        elbow,
        offset_end,
        s.wrist_centre,
        Point3::from(s.base_from_flange.translation.vector),
    ];
    (chain, s.base_from_flange)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The flange pose read off the chain is `flange_pose`'s to the bit,
    /// for every preset arm at joints spread over their travel and beyond.
    #[test]
    fn chain_flange_is_flange_pose() {
        let mut next = crate::util::uniform(0x9e37_79b9_7f4a_7c15, -4.0, 4.0);
        for robot in [
            RobotModel::arcmate_120ic_nominal(),
            RobotModel::arcmate_120ic_axis_by_axis(),
            RobotModel::kuka_kr16_2(),
            RobotModel::abb_irb2600_12_185(),
        ] {
            for _ in 0..2000 {
                let q: Joints = std::array::from_fn(|_| next());
                let (chain, flange) = arm_chain_and_flange(&robot, &q);
                let pose = robot.flange_pose(&q);
                let bits = |p: &Isometry3| {
                    let t = p.translation.vector;
                    let r = p.rotation.coords;
                    [t.x, t.y, t.z, r.x, r.y, r.z, r.w].map(f64::to_bits)
                };
                assert_eq!(bits(&flange), bits(&pose), "{} at {q:?}", robot.name);
                assert_eq!(chain, arm_chain(&robot, &q));
            }
        }
    }
}
