//! **Stage 6a — the positioner's laws: options.** Plain data: how the
//! torch-carried cell's positioner moves ([`PositionerMode`]) and how its
//! laws are solved ([`PositionerOptions`]: spans, weights in rad², the arm's
//! length in mm, samples, iterations), with the check that names a field out
//! of its domain.

use serde::{Deserialize, Serialize};

/// How the torch-carried cell's positioner moves.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum PositionerMode {
    /// Smooth laws optimised within the cone of the vertical ([`super::positioner_law`]).
    #[default]
    Optimised,
    /// The thesis's: `b` turned exactly vertical at every point (SPEC §6.4,
    /// eq. C.24–C.25 solved from the FK), the cone only a tolerance.
    Vertical,
}

/// How the positioner's laws solve their QPs (those whose unconstrained
/// step breaks a row).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum PositionerQp {
    /// clarabel, as the `R_Z` driver.
    Clarabel,
    /// A dense primal–dual interior point for the laws' few dozen
    /// coefficients (the default): the law's QP time about a third of
    /// clarabel's (its set-up per QP, ordering, symbolic factorisation and
    /// equilibration, cost more than the solve). The same optima to the
    /// solvers' tolerances; on the 27 torch-carried sample pairs (2097
    /// beads) the plans' joints agree with clarabel's within 0.01° on all
    /// but 37 beads and within 1° on all but 12: layers whose objective is
    /// flat along the turn (a straight leg's, the elbow's layer 15), or
    /// whose starts end in different local minima of near-equal objective
    /// (the S-bend's layer 80 in the ROBOWAM cell: no smooth law with
    /// clarabel, the hold start's with this one).
    #[default]
    Dense,
}

/// Options of the positioner's laws. Plain data.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct PositionerOptions {
    /// Optimised laws or the thesis's exact vertical.
    pub mode: PositionerMode,
    /// Spans of each axis's cubic spline along the layer (`spans + 3`
    /// coefficients per axis). Default 16.
    pub spans: usize,
    /// `λ`: weight of the mean `sin²` of the tilt of `b` from the vertical
    /// (unitless, against the weighted joint displacement in rad²). Default 0.05.
    pub tilt_weight: f64,
    /// `L`: the length that turns the deposition point's motion in the world
    /// into the arm's joint motion (mm). Default 1000 mm.
    pub arm_length_mm: f64,
    /// Points of a layer the law is solved on (the rest are checked). Default 96.
    pub sample_points: usize,
    /// SQP iterations per seed and round. Default 25.
    pub max_iterations: usize,
    /// How the SQP's QPs are solved. Default dense.
    pub qp: PositionerQp,
}

impl Default for PositionerOptions {
    fn default() -> Self {
        Self {
            mode: PositionerMode::Optimised,
            spans: 16,
            tilt_weight: 0.05,
            arm_length_mm: 1000.0,
            sample_points: 96,
            max_iterations: 25,
            qp: PositionerQp::Dense,
        }
    }
}

impl PositionerOptions {
    /// The first field out of its domain, with its value and why.
    pub(crate) fn invalid(&self) -> Option<(&'static str, f64, &'static str)> {
        if !(1..=64).contains(&self.spans) {
            return Some(("positioner.spans", self.spans as f64, "must be in 1..=64"));
        }
        if !(self.tilt_weight.is_finite() && self.tilt_weight >= 0.0) {
            return Some((
                "positioner.tilt_weight",
                self.tilt_weight,
                "must be finite and >= 0",
            ));
        }
        if !(self.arm_length_mm.is_finite() && self.arm_length_mm > 0.0) {
            return Some((
                "positioner.arm_length_mm",
                self.arm_length_mm,
                "must be finite and > 0",
            ));
        }
        if self.sample_points < 8 {
            return Some((
                "positioner.sample_points",
                self.sample_points as f64,
                "must be >= 8",
            ));
        }
        if self.max_iterations == 0 {
            return Some(("positioner.max_iterations", 0.0, "must be >= 1"));
        }
        None
    }
}
