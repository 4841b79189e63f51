//! Travel-speed modulation: the speed at each point so that the bead height
//! follows the local interlayer distance `delta` of variable-distance paths,
//! clamped to the admissible window (humping above) [SPEC §5; thesis §1.2.3,
//! §3.3.1]. mm, mm/s.

use super::ProcessParameters;
use serde::{Deserialize, Serialize};

/// How the travel speed follows `delta`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum SpeedLaw {
    /// The nominal travel speed everywhere.
    Constant,
    /// The thesis's law (§3.3.1): `TS = TS_nominal · h_ref / delta`, the bead
    /// height taken proportional to the inverse of the travel speed (constant
    /// width) and equal to `h_ref` at the nominal speed.
    #[default]
    Proportional,
    /// Invert the bead model: the speed at which the model's height equals
    /// `delta` (Xiong's eq. 1.2 solved for TS, or `h = A_c/w`).
    BeadModel,
}

/// Which side of the admissible window a needed speed falls on.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum WindowSide {
    /// Slower than the minimum (bead too high / too wide).
    BelowMin,
    /// Faster than the maximum (humping).
    AboveMax,
    /// No speed gives the height (e.g. below the minimum of Xiong's parabola,
    /// or `delta <= 0`).
    Unreachable,
}

/// A point whose needed speed leaves the admissible window.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SpeedViolation {
    /// Layer index in `path.layers`.
    pub layer: usize,
    /// Point index.
    pub point: usize,
    /// Local interlayer distance there (mm).
    pub delta_mm: f64,
    /// Speed the law asks for (mm/s); `None` when unreachable.
    pub needed_mm_s: Option<f64>,
    /// Which limit.
    pub side: WindowSide,
}

/// The speed a law asks for at a point of distance `delta_mm` (mm/s), `None`
/// when no speed gives it.
pub(crate) fn needed_speed(
    params: &ProcessParameters,
    law: SpeedLaw,
    delta_mm: f64,
    reference_height_mm: f64,
) -> Option<f64> {
    if !(delta_mm > 0.0) {
        return None;
    }
    match law {
        SpeedLaw::Constant => Some(params.travel_speed_mm_s),
        SpeedLaw::Proportional => Some(params.travel_speed_mm_s * reference_height_mm / delta_mm),
        SpeedLaw::BeadModel => params.travel_speed_for_height(delta_mm),
    }
}
