//! Stage 7, the program's options: [`ProgramOptions`] (the vendor-neutral
//! keys of a cell file's `[program]` table: approach and retract, home,
//! set-up before each bead, thinning, transits; mm, deg, s) and
//! [`ProcessControl`] (how a bead is started and stopped).

use serde::{Deserialize, Serialize};

use crate::program::{cell_check, ProgramError};
use crate::robot::positioner::PositionerJoints;
use crate::robot::CellLayout;
use crate::robot::Joints;

/// Options of [`build_program_with`](crate::program::build_program_with), and the vendor-independent keys of a
/// cell file's `[program]` table (see [`ProgramSettings`](crate::program::ProgramSettings)). Plain data.
///
/// Every program is built the same way whatever the controller: an optional
/// home move first and last, one bead per layer between an approach and a
/// retract point, and before each bead the set-up of its [`BeadSetup`](crate::program::BeadSetup)
/// (payload update, interlayer dwell, interpass wait). The emitters write
/// them in each controller's instructions; the validators read them back and
/// check them against these options (the `common` field of each vendor's
/// options).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ProgramOptions {
    /// Distance of the approach and retract points from the part along the
    /// tool axis (mm, ≥ 0; 0: no approach or retract points, each bead is
    /// reached by a joint move to its first point). Default 20 mm; where a
    /// point at that distance leaves a joint's travel, a half, a quarter or
    /// an eighth of it is used.
    pub clearance_mm: f64,
    /// Linear speed of the moves into and out of a bead (approach point →
    /// first point, last point → retract point), relative to the part
    /// (mm/s, > 0). Default 20 mm/s.
    pub approach_speed_mm_s: f64,
    /// Home position of the arm, joints in the controller's convention
    /// (deg): the program's first and last motion, a joint move with the arc
    /// off. `None` (default): no home moves (the program starts with the
    /// first bead's approach; the cell file should say where home is).
    pub home_deg: Option<[f64; 6]>,
    /// Positioner joints `[q7, q8]` at home (deg), torch-carried cells;
    /// `None`: `[0, 0]`.
    pub home_positioner_deg: Option<[f64; 2]>,
    /// Interlayer dwell (s, ≥ 0): before each bead after the first, the
    /// program waits this long with the arc off at the previous bead's
    /// retract point, so that the wall cools. Default 0.
    pub dwell_s: f64,
    /// Interpass wait: before each bead after the first, the program waits
    /// for this digital input to be on (the interpass temperature is
    /// reached): FANUC `DI[n]`, KUKA `$IN[n]`, ABB the signal of
    /// [`abb::AbbOptions`](crate::program::abb::AbbOptions). `None` (default): no wait.
    pub interpass_input: Option<u32>,
    /// Payload update every this many layers in the part-carried cell (the
    /// robot carries the part as it grows; 0: never). Before bead 0 and
    /// before every `N`-th bead the program sets the payload to the
    /// substrate and fixture ([`ProgramOptions::payload_base_kg`]) plus the
    /// metal deposited so far. Default 0.
    pub payload_every_layers: u32,
    /// Mass carried on the flange before the first layer: substrate and
    /// fixture (kg, ≥ 0). Default 0.
    pub payload_base_kg: f64,
    /// Centre of gravity of that mass, flange frame (mm). Default origin.
    pub payload_base_cog_mm: [f64; 3],
    /// Check every arc-off joint move (retract → next approach, home moves)
    /// against the wall deposited so far with the torch's collision model
    /// ([`crate::toolaxis::collision`]), and where one collides move the
    /// retract and approach points of that transition further along the tool
    /// axis, up to [`ProgramOptions::transit_max_clearance_mm`]. Default on.
    pub transit_check: bool,
    /// Largest retract and approach distance a transit may use (mm, ≥
    /// `clearance_mm`). Default 160 mm.
    pub transit_max_clearance_mm: f64,
    /// Radius of the deposited beads in the transit check (mm, > 0): the
    /// wall is the bead points as capsules of this radius. Default 2 mm.
    pub bead_radius_mm: f64,
    /// Positioner motion coordinated with the arm in torch-carried cells
    /// (FANUC `COORD`, KUKA math-coupled base, ABB `ufmec` work object).
    /// Default on.
    pub coordinated: bool,
    /// FANUC remote TCP (`RTCP`) in the part-carried cell: linear moves are
    /// about the fixed torch (joint positions only; a paid option that
    /// cannot be loaded with Coordinated Motion, whose Cartesian `RX…RR`
    /// positions are not publicly specified). Default off.
    pub remote_tcp: bool,
    /// Largest distance between the controller's interpolated path and the
    /// planned points, over the part (mm): each bead is written with the
    /// fewest linear moves within it ([`moves::thin_beads`](crate::program::moves::thin_beads)). 0: every
    /// planned point is a move. Default 0.05 mm.
    pub path_tolerance_mm: f64,
    /// Largest angle between the interpolated and the planned torch axis
    /// (deg, > 0) when beads are thinned. Default 0.5°.
    pub orientation_tolerance_deg: f64,
    /// Thinned beads may use circular moves (FANUC `C`, KUKA `CIRC`, ABB
    /// `ArcC`) where a stretch is a circle arc within the tolerances and
    /// that takes fewer positions than linear moves (a circular move writes
    /// two: its via and its end). Default on.
    pub circular_moves: bool,
    /// Smallest distance two bodies of the cell may come to along any
    /// motion (mm, ≥ 0; [`cell_check`]): arm links, positioner, keep-out
    /// boxes, the part. Default 10 mm.
    pub collision_clearance_mm: f64,
}

impl Default for ProgramOptions {
    fn default() -> Self {
        Self {
            clearance_mm: 20.0,
            approach_speed_mm_s: 20.0,
            home_deg: None,
            home_positioner_deg: None,
            dwell_s: 0.0,
            interpass_input: None,
            payload_every_layers: 0,
            payload_base_kg: 0.0,
            payload_base_cog_mm: [0.0; 3],
            transit_check: true,
            transit_max_clearance_mm: 160.0,
            bead_radius_mm: 2.0,
            coordinated: true,
            remote_tcp: false,
            path_tolerance_mm: 0.05,
            orientation_tolerance_deg: 0.5,
            circular_moves: true,
            collision_clearance_mm: cell_check::DEFAULT_CLEARANCE_MM,
        }
    }
}

impl ProgramOptions {
    /// Checks every field.
    ///
    /// # Errors
    /// [`ProgramError::InvalidOptions`] naming the field.
    pub fn validate(&self) -> Result<(), ProgramError> {
        let bad = |field: &'static str, value: String, reason: &'static str| {
            Err(ProgramError::InvalidOptions {
                field,
                value,
                reason,
            })
        };
        if !(self.clearance_mm.is_finite() && self.clearance_mm >= 0.0) {
            return bad(
                "clearance_mm",
                self.clearance_mm.to_string(),
                "must be finite and >= 0",
            );
        }
        if !(self.path_tolerance_mm.is_finite() && self.path_tolerance_mm >= 0.0) {
            return bad(
                "path_tolerance_mm",
                self.path_tolerance_mm.to_string(),
                "must be finite and >= 0 (0: every planned point is a move)",
            );
        }
        if !(self.orientation_tolerance_deg.is_finite() && self.orientation_tolerance_deg > 0.0) {
            return bad(
                "orientation_tolerance_deg",
                self.orientation_tolerance_deg.to_string(),
                "must be finite and > 0",
            );
        }
        if !(self.approach_speed_mm_s.is_finite() && self.approach_speed_mm_s > 0.0) {
            return bad(
                "approach_speed_mm_s",
                self.approach_speed_mm_s.to_string(),
                "must be finite and > 0",
            );
        }
        if let Some(h) = self.home_deg {
            if !h.iter().all(|v| v.is_finite()) {
                return bad("home_deg", format!("{h:?}"), "must be finite");
            }
        }
        if let Some(h) = self.home_positioner_deg {
            if !h.iter().all(|v| v.is_finite()) {
                return bad("home_positioner_deg", format!("{h:?}"), "must be finite");
            }
        }
        if !(self.dwell_s.is_finite() && (0.0..=86_400.0).contains(&self.dwell_s)) {
            return bad(
                "dwell_s",
                self.dwell_s.to_string(),
                "must be between 0 and 86400 s",
            );
        }
        if self.interpass_input == Some(0) {
            return bad("interpass_input", "0".into(), "must be >= 1");
        }
        if !(self.payload_base_kg.is_finite() && self.payload_base_kg >= 0.0) {
            return bad(
                "payload_base_kg",
                self.payload_base_kg.to_string(),
                "must be finite and >= 0",
            );
        }
        if !self.payload_base_cog_mm.iter().all(|v| v.is_finite()) {
            return bad(
                "payload_base_cog_mm",
                format!("{:?}", self.payload_base_cog_mm),
                "must be finite",
            );
        }
        if !(self.transit_max_clearance_mm.is_finite()
            && self.transit_max_clearance_mm >= self.clearance_mm)
        {
            return bad(
                "transit_max_clearance_mm",
                self.transit_max_clearance_mm.to_string(),
                "must be finite and >= clearance_mm",
            );
        }
        if !(self.collision_clearance_mm.is_finite() && self.collision_clearance_mm >= 0.0) {
            return bad(
                "collision_clearance_mm",
                self.collision_clearance_mm.to_string(),
                "must be finite and >= 0",
            );
        }
        if !(self.bead_radius_mm.is_finite() && self.bead_radius_mm > 0.0) {
            return bad(
                "bead_radius_mm",
                self.bead_radius_mm.to_string(),
                "must be finite and > 0",
            );
        }
        Ok(())
    }

    /// The home position in controller units inside (rad), if any.
    pub fn home(&self, cell: &CellLayout) -> Option<HomePosition> {
        let h = self.home_deg?;
        Some(HomePosition {
            joints: h.map(f64::to_radians),
            positioner: matches!(cell, CellLayout::TorchCarried(_)).then(|| {
                self.home_positioner_deg
                    .unwrap_or([0.0; 2])
                    .map(f64::to_radians)
            }),
        })
    }
}

/// The arm's (and positioner's) home position: the first and last motion of
/// a program, a joint move with the arc off.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct HomePosition {
    /// Robot joints, controller convention (rad).
    pub joints: Joints,
    /// Positioner joints `[q7, q8]` (rad), torch-carried cell only.
    pub positioner: Option<PositionerJoints>,
}

/// How a bead is started and stopped (SPEC §8).
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ProcessControl {
    /// Welding: the controller's arc instructions with weld schedule `schedule`
    /// (FANUC `Arc Start[n]`/`Arc End[n]`, ABB `weld<n>`, KUKA output `n`).
    Arc {
        /// Weld schedule (procedure) number, ≥ 1.
        schedule: u32,
    },
    /// User-given instruction lines (e.g. a polymer extruder's I/O), written
    /// as they are where the bead starts and stops.
    Custom {
        /// Instruction starting a bead, e.g. `DO[1]=ON`.
        start: String,
        /// Instruction stopping a bead, e.g. `DO[1]=OFF`.
        end: String,
    },
}

impl Default for ProcessControl {
    fn default() -> Self {
        ProcessControl::Arc { schedule: 1 }
    }
}

impl ProcessControl {
    /// Checks the schedule number and that custom lines are single, non-empty
    /// ASCII lines (controllers reject other bytes).
    ///
    /// # Errors
    /// [`ProgramError::InvalidOptions`] naming the field.
    pub fn validate(&self) -> Result<(), ProgramError> {
        match self {
            ProcessControl::Arc { schedule } if *schedule == 0 => {
                Err(ProgramError::InvalidOptions {
                    field: "process.schedule",
                    value: "0".into(),
                    reason: "must be >= 1",
                })
            }
            ProcessControl::Custom { start, end } => {
                for (field, s) in [("process.start", start), ("process.end", end)] {
                    if s.trim().is_empty() || s.contains(['\n', '\r', ';']) || !s.is_ascii() {
                        return Err(ProgramError::InvalidOptions {
                            field,
                            value: s.clone(),
                            reason: "must be one non-empty ASCII line without `;`",
                        });
                    }
                }
                Ok(())
            }
            _ => Ok(()),
        }
    }
}
