//! The tool and work frames a program is written in, one setup for every
//! emitter (FANUC, KUKA, ABB) and the validator: a tool held by the robot
//! over a fixed work frame, or a stationary torch with the part held by the
//! robot (robot base frame = world frame, flange frame; mm). Defaults come
//! from the cell: the torch-carried cell's torch (`flange_from_tcp`), the
//! part-carried cell's part (`flange_from_part`) and fixed torch at the
//! deposition point `D_R`.
//!
//! **One tool convention in every program**: the torch's tool frame has
//! **+Z along the wire, out of the torch towards the part** (the usual
//! welding-torch convention, so that Cartesian moves, tool jogging,
//! offsets and weaving in the tool frame run the way a welder expects),
//! whether the torch is held by the arm ([`held_tool`]) or fixed in the
//! cell ([`fixed_torch_at`]). The planner's own TCP frame (the cell's
//! `flange_from_tcp`, thesis eq. 4.9) has z the other way, from the wire
//! tip into the torch (along the tool axis `T`); the programs' tool is that
//! frame turned half a turn about its x axis ([`wire_out`]), same origin.

use crate::math::{Isometry3, Point3, Vector3};
use crate::robot::CellLayout;

/// Where a program's tool and work frames are (mm).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ToolFrames {
    /// Robot-held tool `flange_from_tool` (flange frame) over a fixed work
    /// frame `base_from_work` (robot base frame).
    Held {
        /// The tool on the flange (ABB `tWaam.tframe`, KUKA `$TOOL`,
        /// FANUC `UTOOL`).
        flange_from_tool: Isometry3,
        /// The work frame in the robot base frame (ABB `wWaam.uframe`,
        /// KUKA `$BASE`, FANUC `UFRAME`).
        base_from_work: Isometry3,
    },
    /// Stationary tool `base_from_tool` (robot base frame) and a work frame
    /// held by the robot, `flange_from_work` (flange frame).
    Stationary {
        /// The fixed tool in the robot base frame (ABB `tWaam.tframe`,
        /// KUKA `$BASE` in the external-TCP mode).
        base_from_tool: Isometry3,
        /// The work frame on the flange (ABB `wWaam.uframe`, KUKA `$TOOL`
        /// in the external-TCP mode).
        flange_from_work: Isometry3,
    },
}

impl ToolFrames {
    /// The frames for `cell`. `stationary`: a fixed tool at `fixed_tool`
    /// (default: the part-carried cell's [`fixed_torch_at`] `D_R`) with the
    /// work frame `flange_from_tool` on the flange (default: the cell's
    /// `flange_from_part`); otherwise the tool [`held_tool`] over the work
    /// frame `base_from_user`. In the torch-carried cell the stationary
    /// defaults are the identity.
    pub fn new(
        cell: &CellLayout,
        stationary: bool,
        flange_from_tool: Option<Isometry3>,
        fixed_tool: Option<Isometry3>,
        base_from_user: Isometry3,
    ) -> Self {
        if stationary {
            ToolFrames::Stationary {
                base_from_tool: fixed_tool.unwrap_or_else(|| match cell {
                    CellLayout::PartCarried(c) => fixed_torch_at(&c.deposition_point_mm),
                    CellLayout::TorchCarried(_) => Isometry3::identity(),
                }),
                flange_from_work: flange_from_tool.unwrap_or(match cell {
                    CellLayout::PartCarried(c) => c.flange_from_part,
                    CellLayout::TorchCarried(_) => Isometry3::identity(),
                }),
            }
        } else {
            ToolFrames::Held {
                flange_from_tool: held_tool(cell, flange_from_tool),
                base_from_work: base_from_user,
            }
        }
    }

    /// The tool's pose in the work frame (ABB `robtarget`) at flange pose
    /// `base_from_flange`.
    pub fn target(&self, base_from_flange: &Isometry3) -> Isometry3 {
        match self {
            ToolFrames::Held {
                flange_from_tool,
                base_from_work,
            } => base_from_work.inverse() * base_from_flange * flange_from_tool,
            ToolFrames::Stationary {
                base_from_tool,
                flange_from_work,
            } => (base_from_flange * flange_from_work).inverse() * base_from_tool,
        }
    }

    /// The flange pose reaching [`ToolFrames::target`] pose `target`.
    pub fn flange(&self, target: &Isometry3) -> Isometry3 {
        match self {
            ToolFrames::Held {
                flange_from_tool,
                base_from_work,
            } => base_from_work * target * flange_from_tool.inverse(),
            ToolFrames::Stationary {
                base_from_tool,
                flange_from_work,
            } => base_from_tool * target.inverse() * flange_from_work.inverse(),
        }
    }
}

/// The tool held on the flange (mm): `flange_from_tool` when given (the
/// user's own tool, written as given), else the torch-carried cell's torch
/// with +Z along the wire out of the torch (`flange_from_tcp ·`
/// [`wire_out`]) or, in the part-carried cell, the flange itself.
pub fn held_tool(cell: &CellLayout, flange_from_tool: Option<Isometry3>) -> Isometry3 {
    match (flange_from_tool, cell) {
        (Some(t), _) => t,
        (None, CellLayout::TorchCarried(c)) => c.flange_from_tcp * wire_out(),
        (None, CellLayout::PartCarried(_)) => Isometry3::identity(),
    }
}

/// Half a turn about x: from the planner's TCP frame (z from the wire tip
/// into the torch, along `T`) to the programs' tool frame (z along the
/// wire, out of the torch), same origin, x kept, y reversed.
pub fn wire_out() -> Isometry3 {
    Isometry3::from_parts(
        nalgebra::Translation3::identity(),
        nalgebra::UnitQuaternion::from_axis_angle(&Vector3::x_axis(), std::f64::consts::PI),
    )
}

/// A fixed torch at `d` (robot base frame, mm): z down, along the wire out
/// of the torch towards the part (the programs' convention, module doc), x
/// along the base X, y along −Y.
pub fn fixed_torch_at(d: &Point3) -> Isometry3 {
    Isometry3::from_parts(
        nalgebra::Translation3::from(d.coords),
        nalgebra::UnitQuaternion::identity(),
    ) * wire_out()
}
