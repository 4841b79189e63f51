//! The robot cell at one planned point, as the viewer draws it: the arm's
//! joint frame origins from the library's forward kinematics, the torch, the
//! positioner and the pose of the part (robot base frame, mm).

use crate::math::{Isometry3, Point3, Vector3};
use crate::robot::chain::arm_chain;
use crate::robot::model::Joints;
use crate::robot::positioner::PositionerJoints;
use crate::robot::CellLayout;

/// Points of the arm drawn as solids between consecutive entries.
pub const CHAIN_POINTS: usize = 8;

/// The cell at one point (robot base frame, mm).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CellSnapshot {
    /// The arm, base to flange: base origin, top of the J1 column, shoulder
    /// (J2 axis), elbow (J3 axis), end of the elbow offset, wrist centre,
    /// flange, and the TCP (torch tip) on a torch-carried cell or the flange
    /// again on a part-carried one. `None` without joints.
    pub chain: Option<[Point3; CHAIN_POINTS]>,
    /// The torch as a segment, tip first.
    pub torch: [Point3; 2],
    /// Positioner: tilt centre C7, table centre C8, unit table normal.
    pub positioner: Option<(Point3, Point3, Vector3)>,
    /// `base_from_part`: where the part is. `None` when it cannot be placed
    /// (a part-carried point without joints is placed by the cell's pose
    /// law instead, so this is `None` only if that fails too).
    pub base_from_part: Option<Isometry3>,
}

/// Length of the drawn torch body (mm).
pub const TORCH_LENGTH_MM: f64 = 180.0;

/// The cell at one point: joints `q` (rad, `None` when the plan has none),
/// positioner joints `e` (rad), the point `m` and tool axis of the point for
/// the part-carried pose law, and `r_z` (rad).
pub fn snapshot(
    cell: &CellLayout,
    q: Option<&Joints>,
    e: Option<&PositionerJoints>,
    point: &crate::robot::CellPoint,
    r_z: f64,
) -> CellSnapshot {
    let chain7 = q.map(|q| arm_chain(cell.robot(), q));
    match cell {
        CellLayout::PartCarried(c) => {
            let base_from_part = match q {
                Some(q) => Some(c.robot.flange_pose(q) * c.flange_from_part),
                None => Some(c.base_from_part(&point.position_mm, &point.tool_axis, r_z)),
            };
            let d = c.deposition_point_mm;
            CellSnapshot {
                chain: chain7.map(|a| [a[0], a[1], a[2], a[3], a[4], a[5], a[6], a[6]]),
                torch: [d, d + Vector3::z() * TORCH_LENGTH_MM],
                positioner: None,
                base_from_part,
            }
        }
        CellLayout::TorchCarried(c) => {
            let positioner = e.map(|e| {
                let base_from_table =
                    c.base_from_positioner * c.positioner.positioner_from_table(e);
                (
                    Point3::from(c.base_from_positioner.translation.vector),
                    Point3::from(base_from_table.translation.vector),
                    base_from_table.rotation * Vector3::z(),
                )
            });
            let tcp = q.map(|q| c.robot.flange_pose(q) * c.flange_from_tcp);
            let torch = match tcp {
                Some(tcp) => {
                    let tip = Point3::from(tcp.translation.vector);
                    [tip, tip + tcp.rotation * Vector3::z() * TORCH_LENGTH_MM]
                }
                None => [Point3::origin(), Point3::origin()],
            };
            CellSnapshot {
                chain: chain7.zip(tcp).map(|(a, tcp)| {
                    [
                        a[0],
                        a[1],
                        a[2],
                        a[3],
                        a[4],
                        a[5],
                        a[6],
                        Point3::from(tcp.translation.vector),
                    ]
                }),
                torch,
                positioner,
                base_from_part: e.map(|e| c.base_from_part(e)),
            }
        }
    }
}
