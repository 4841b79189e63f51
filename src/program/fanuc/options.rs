//! FANUC TP options: [`FanucOptions`] (the `[program.fanuc]` table) with
//! its speed unit and motion timing, and their validation. Stage 7
//! (controller programs); the [vendor module](super) describes the format.

use serde::{Deserialize, Serialize};

use crate::math::Isometry3;
use crate::program::frames::{fixed_torch_at, held_tool};
use crate::program::kinds::PositionMode;
use crate::program::split::DEFAULT_MAX_POSITIONS;
use crate::program::{positioner_moves, ProcessControl, Program, ProgramError};
use crate::robot::orientation::FanucPose;
use crate::robot::CellLayout;

/// Unit of linear speeds.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum SpeedUnit {
    /// `mm/sec`.
    MmPerSec,
    /// `cm/min` (the unit of the thesis's process tables).
    #[default]
    CmPerMin,
}

/// How linear moves carry their speed (module doc, "What the speed means").
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum MotionTiming {
    /// Time-based (`msec`) in the part-carried cell; in the torch-carried
    /// cell time-based on every segment where the positioner moves
    /// ([`positioner_moves`]), TCP speed
    /// elsewhere.
    #[default]
    Auto,
    /// TCP speed (`mm/sec` or `cm/min`) everywhere: only right in the
    /// part-carried cell if the controller moves relative to the fixed torch
    /// (remote TCP).
    TcpSpeed,
    /// Segment times (`msec`) everywhere.
    Time,
}

/// Options of the FANUC emitter. Plain data.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct FanucOptions {
    /// Joint or Cartesian positions. Default joint.
    pub positions: PositionMode,
    /// Unit of the linear speeds. Default cm/min.
    pub speed_unit: SpeedUnit,
    /// Speeds or segment times on linear moves. Default
    /// [`MotionTiming::Auto`].
    pub timing: MotionTiming,
    /// `CNT` value (0–100) of the blended moves inside a bead. Default 100.
    pub cnt: u8,
    /// Joint speed of the move to each bead's approach point (or first point
    /// without approach points) (%, 1–100). Default 10.
    pub approach_percent: u8,
    /// Arc instructions or user-given start/end lines. Default `Arc Start[1]`.
    pub process: ProcessControl,
    /// `UFRAME_NUM` (0 = world). Default 0.
    pub user_frame: u8,
    /// `UTOOL_NUM` (1–10). Default 1.
    pub tool_frame: u8,
    /// The user frame's pose in the robot base frame, as stored in the
    /// controller's `UFRAME[user_frame]` (mm). Default identity.
    pub base_from_user: Isometry3,
    /// The tool frame on the flange, as stored in `UTOOL[tool_frame]` (mm).
    /// `None`: the cell's torch (`flange_from_tcp`) in the torch-carried
    /// cell, the flange itself in the part-carried cell.
    pub flange_from_tool: Option<Isometry3>,
    /// `Weld Start[p,s]`/`Weld End[p,s]` (ArcTool weld procedure `p`,
    /// schedule `s` = the process's schedule) instead of `Arc Start[s]`/`Arc
    /// End[s]`. `None` (default): `Arc Start[s]`.
    pub weld_procedure: Option<u32>,
    /// `UFRAME_NUM` of the remote TCP frame in the part-carried cell with
    /// remote TCP (`common.remote_tcp`): the user frame taught at the fixed
    /// torch's tip (1–9). Default 1.
    pub remote_tcp_frame: u8,
    /// The remote TCP frame's pose in the robot base frame, as stored in
    /// `UFRAME[remote_tcp_frame]` (mm). `None`: the cell's fixed torch at
    /// `D_R`, z towards the part ([`fixed_torch_at`]).
    pub base_from_torch: Option<Isometry3>,
    /// Payload schedule (`PAYLOAD[n]`, `$PLST_GRP1[n]`, 1–10) the program
    /// rewrites and selects at each payload update. Default 1.
    pub payload_schedule: u8,
    /// The controller's TP program space: the most positions (`P[]`
    /// records, home included) of every program resident at once. A build
    /// with more is cut between layers into groups the cell loads in turn
    /// (`NAME_P01.ls`, `NAME_P02.ls`, …, [`split`](crate::program::split)),
    /// each within it; a layer that does not fit alone is refused. Default
    /// 15 000: the standard program space of a one-group R-30iB (more
    /// needs the R709 TP DRAM/FILE storage option; FANUC R-30iB operator's
    /// manual, optional functions, B-83284EN-2/05 ch. 29).
    pub max_positions: usize,
    /// The vendor-independent options (home, dwell, interpass wait,
    /// payload, transit, coordination) the validator checks the file
    /// against; not a key of `[program.<vendor>]` (set from `[program]` by
    /// [`crate::program::ProgramSettings`]).
    #[serde(skip)]
    pub common: crate::program::ProgramOptions,
}

impl Default for FanucOptions {
    fn default() -> Self {
        Self {
            positions: PositionMode::Joint,
            speed_unit: SpeedUnit::CmPerMin,
            timing: MotionTiming::Auto,
            cnt: 100,
            approach_percent: 10,
            process: ProcessControl::default(),
            user_frame: 0,
            tool_frame: 1,
            base_from_user: Isometry3::identity(),
            flange_from_tool: None,
            weld_procedure: None,
            remote_tcp_frame: 1,
            base_from_torch: None,
            payload_schedule: 1,
            max_positions: DEFAULT_MAX_POSITIONS,
            // remote TCP off by default (module doc, "Remote TCP")
            common: crate::program::ProgramOptions {
                remote_tcp: false,
                ..Default::default()
            },
        }
    }
}

impl FanucOptions {
    /// Checks every field.
    ///
    /// # Errors
    /// [`ProgramError::InvalidOptions`] naming the field.
    pub fn validate(&self) -> Result<(), ProgramError> {
        let bad = |field, value: String, reason| ProgramError::InvalidOptions {
            field,
            value,
            reason,
        };
        if self.cnt > 100 {
            return Err(bad("cnt", self.cnt.to_string(), "must be in 0..=100"));
        }
        if !(1..=100).contains(&self.approach_percent) {
            return Err(bad(
                "approach_percent",
                self.approach_percent.to_string(),
                "must be in 1..=100",
            ));
        }
        if self.user_frame > 9 {
            return Err(bad(
                "user_frame",
                self.user_frame.to_string(),
                "must be in 0..=9",
            ));
        }
        if !(1..=10).contains(&self.tool_frame) {
            return Err(bad(
                "tool_frame",
                self.tool_frame.to_string(),
                "must be in 1..=10",
            ));
        }
        if self.max_positions < 2 {
            return Err(bad(
                "max_positions",
                self.max_positions.to_string(),
                "must be >= 2 (a bead has at least two positions)",
            ));
        }
        if !(1..=9).contains(&self.remote_tcp_frame) {
            return Err(bad(
                "remote_tcp_frame",
                self.remote_tcp_frame.to_string(),
                "must be in 1..=9 (a user frame; UFRAME 0 is the world frame)",
            ));
        }
        if !(1..=10).contains(&self.payload_schedule) {
            return Err(bad(
                "payload_schedule",
                self.payload_schedule.to_string(),
                "must be in 1..=10",
            ));
        }
        if self.weld_procedure == Some(0) {
            return Err(bad("weld_procedure", "0".into(), "must be >= 1"));
        }
        if self.user_frame == 0 && !is_identity(&self.base_from_user) {
            return Err(bad(
                "base_from_user",
                format!(
                    "{:?}",
                    FanucPose::from_isometry(&self.base_from_user).to_xyzwpr_deg()
                ),
                "UFRAME 0 is the world frame: `user_frame` = 0 needs the identity",
            ));
        }
        for (field, iso) in [
            ("base_from_user", Some(self.base_from_user)),
            ("base_from_torch", self.base_from_torch),
            ("flange_from_tool", self.flange_from_tool),
        ] {
            if let Some(iso) = iso {
                let finite = iso.translation.vector.iter().all(|v| v.is_finite())
                    && iso.rotation.coords.iter().all(|v| v.is_finite());
                if !finite {
                    return Err(bad(field, format!("{iso:?}"), "must be finite"));
                }
            }
        }
        self.common.validate()?;
        self.process.validate()
    }

    /// `true` when every linear move is written as a segment time in
    /// `cell` (see [`FanucOptions::segment_time_based`] for single
    /// segments): with [`MotionTiming::Auto`], the part-carried cell
    /// without remote TCP.
    pub fn time_based(&self, cell: &CellLayout) -> bool {
        match self.timing {
            MotionTiming::Auto => {
                matches!(cell, CellLayout::PartCarried(_)) && !self.remote_tcp(cell)
            }
            MotionTiming::TcpSpeed => false,
            MotionTiming::Time => true,
        }
    }

    /// `true` when the linear move into point `i` of `program` is written
    /// as a segment time: [`FanucOptions::time_based`], or with
    /// [`MotionTiming::Auto`] a segment where the positioner moves and the
    /// moves are not coordinated (`COORD` makes the speed relative to the
    /// positioner, the planned travel speed over the part).
    pub fn segment_time_based(&self, program: &Program, i: usize) -> bool {
        self.time_based(&program.cell)
            || (self.timing == MotionTiming::Auto
                && !self.coordinated(&program.cell)
                && positioner_moves(program, i))
    }

    /// `true` when linear moves carry the `RTCP` motion option in `cell`:
    /// the part-carried cell with `common.remote_tcp`.
    pub fn remote_tcp(&self, cell: &CellLayout) -> bool {
        matches!(cell, CellLayout::PartCarried(_)) && self.common.remote_tcp
    }

    /// `true` when linear moves carry the `COORD` motion option in `cell`:
    /// the torch-carried cell (positioner = group 2, the leader) with
    /// `common.coordinated`.
    pub fn coordinated(&self, cell: &CellLayout) -> bool {
        matches!(cell, CellLayout::TorchCarried(_)) && self.common.coordinated
    }

    /// The tool frame used for Cartesian positions in `cell` (mm).
    pub fn tool_in(&self, cell: &CellLayout) -> Isometry3 {
        held_tool(cell, self.flange_from_tool)
    }

    /// The user and tool frames the positions of `cell`'s programs are in
    /// (module doc, "Frames"): with remote TCP the remote TCP frame at the
    /// fixed torch, else `user_frame`/`base_from_user`; the tool
    /// [`FanucOptions::tool_in`].
    pub fn frames(&self, cell: &CellLayout) -> FanucFrames {
        let (user_frame, base_from_user) = match cell {
            CellLayout::PartCarried(c) if self.remote_tcp(cell) => (
                self.remote_tcp_frame,
                self.base_from_torch
                    .unwrap_or_else(|| fixed_torch_at(&c.deposition_point_mm)),
            ),
            _ => (self.user_frame, self.base_from_user),
        };
        FanucFrames {
            user_frame,
            base_from_user,
            tool_frame: self.tool_frame,
            flange_from_tool: self.tool_in(cell),
        }
    }
}

/// `true` when `iso` is the identity within 1e-9 (mm, rad).
pub(super) fn is_identity(iso: &Isometry3) -> bool {
    iso.translation.vector.norm() < 1e-9 && iso.rotation.angle() < 1e-9
}

/// The frames a set of TP programs assumes (mm): `UFRAME[user_frame]` =
/// `base_from_user` (robot base = world frame), `UTOOL[tool_frame]` =
/// `flange_from_tool` (flange = FANUC faceplate frame). Stated in each
/// program's header remarks ([`frame_remarks`](super::emit::frame_remarks)) and checked by the
/// validator.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FanucFrames {
    /// `UFRAME_NUM` (0 = world).
    pub user_frame: u8,
    /// The user frame in the robot base frame (mm).
    pub base_from_user: Isometry3,
    /// `UTOOL_NUM`.
    pub tool_frame: u8,
    /// The tool frame on the flange (mm).
    pub flange_from_tool: Isometry3,
}
