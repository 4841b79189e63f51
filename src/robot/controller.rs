//! Facts about each vendor's robot controller that the program stage's
//! emitters, decoders and checker share: how it names an arm's
//! configuration ([`elbow_positive_cos`]) and whether it moves a
//! part-carried arm about a fixed tool ([`Vendor::moves_about_fixed_tool`])
//! and its name in messages ([`Vendor::display_name`]).
//! They belong with the robot presets ([`Vendor`], [`JointConvention`](crate::robot::JointConvention)):
//! a new vendor states them here next to its preset.

use crate::robot::{ArmSide, Configuration, Elbow, Vendor};

impl Vendor {
    /// The vendor's name as written in messages (`FANUC`, `KUKA`, `ABB`).
    pub fn display_name(self) -> &'static str {
        match self {
            Vendor::Fanuc => "FANUC",
            Vendor::Kuka => "KUKA",
            Vendor::Abb => "ABB",
        }
    }

    /// `true` when the controller always moves a part-carried arm's linear
    /// moves about the fixed torch (KUKA's external TCP, ABB's stationary
    /// tool): the path is linear over the part. `false` (FANUC): only with
    /// [`ProgramOptions::remote_tcp`](crate::program::ProgramOptions::remote_tcp)
    /// (`RTCP`), else the held tool's pose is interpolated in the robot base
    /// frame.
    pub fn moves_about_fixed_tool(self) -> bool {
        matches!(self, Vendor::Kuka | Vendor::Abb)
    }
}

/// The elbow joint test of a configuration: `true` on the side of the
/// stretched elbow where the arm is in the usual elbow-up posture with the
/// wrist centre in front of J1 (KUKA `A3 >= phi`, ABB wrist centre in front
/// of the lower arm). [`Configuration`]'s elbow is geometric (above or
/// below the shoulder-wrist line), which swaps when the wrist centre goes
/// behind J1; this test does not.
pub fn elbow_positive_cos(c: &Configuration) -> bool {
    (c.side == ArmSide::Front) == (c.elbow == Elbow::Up)
}
