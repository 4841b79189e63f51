//! What the placement search gives back, as data: the placement found (or
//! the best tried), its margins, the search's account and, when no
//! placement was found, the binding constraint with the phase it was found
//! in.

use std::fmt;
use std::sync::Arc;

use super::bounds::PlacementValues;
use crate::optimise::{Constraint, OptimiseError, Plan};
use crate::program::ProgramError;
use crate::robot::{CellLayout, RobotError};

/// The worst layer's margins of a plan.
#[derive(Debug, Clone, Copy, PartialEq, Default, serde::Serialize)]
pub struct Margins {
    /// Smallest distance to a joint stop over every layer (deg).
    pub joint_limit_deg: f64,
    /// Smallest `1 − peak speed / max speed` over every joint and layer.
    pub speed_headroom: f64,
    /// Smallest dexterity over every layer (0 singular, 1 isotropic).
    pub dexterity: f64,
    /// Smallest distance (mm) of the robot's wrist centre inside the arm's
    /// reach over every planned point: from the J2 axis, in the arm plane,
    /// to the stretched arm's reach or the folded arm's (the annulus of
    /// [`RobotError::Unreachable`]).
    pub reach_mm: f64,
    /// Layers infeasible.
    pub infeasible_layers: usize,
}

/// Wall times of the search's phases, summed over the rounds (s).
#[derive(Debug, Clone, Copy, PartialEq, Default, serde::Serialize)]
pub struct PlaceTimes {
    /// Screening and re-judging candidates on the subsample (s).
    pub screening_s: f64,
    /// Compass refinement on the subsample (s).
    pub refinement_s: f64,
    /// Full-path certification, the caller's check included (s).
    pub certification_s: f64,
}

/// What bound one candidate: the constraint that made its plan infeasible,
/// or why it was not planned.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub enum Limit {
    /// A constraint of the per-layer problem (joint travel or speed named
    /// by its joint, dexterity floor, hose torsion, cone of the vertical),
    /// the first infeasible layer's.
    Layer(Constraint),
    /// A point of the first such layer has no joint solution.
    NoJointSolution(RobotError),
    /// The deposition point (positioner origin) lies in the keep-out box.
    KeepOut,
    /// The optimiser refused the candidate's cell.
    Optimiser(OptimiseError),
    /// Feasible on the subsample, refused there by the caller's check (the
    /// program stage's transits or set-up).
    ProgramCheck,
}

impl fmt::Display for Limit {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Limit::Layer(c) => write!(f, "{c}"),
            Limit::NoJointSolution(e) => write!(f, "no joint solution ({e})"),
            Limit::KeepOut => write!(f, "keep-out box"),
            Limit::Optimiser(e) => write!(f, "{e}"),
            Limit::ProgramCheck => write!(f, "program check on the subsample (transit or set-up)"),
        }
    }
}

/// Why no placement was found: the binding constraint, with the phase of
/// the search it was found in and the share it bound.
#[derive(Debug, Clone)]
#[non_exhaustive]
pub enum Binding {
    /// No candidate was feasible on the subsample: the constraint that
    /// bound most of them (their first infeasible layer's).
    Subsample {
        /// The constraint.
        limit: Limit,
        /// Share of the screened candidates it bound (0–1).
        share: f64,
        /// When `limit` is [`Limit::ProgramCheck`]: the first refusal.
        example: Option<Arc<ProgramError>>,
    },
    /// The best candidate feasible on the subsample failed on the full
    /// path: its plan's first binding constraint.
    FullPath {
        /// The constraint.
        limit: Limit,
        /// Share of the layers checked that are infeasible (0–1).
        share: f64,
        /// The caller's check's refusal of another candidate, if any (it
        /// may be what bound the rest of the search).
        refused: Option<Arc<ProgramError>>,
    },
    /// The caller's check refused every candidate feasible on the full
    /// path: its first refusal (it bound them all).
    ProgramCheck {
        /// The refusal.
        refusal: Arc<ProgramError>,
    },
}

impl Binding {
    /// Share of the candidates (subsample) or of the layers checked (full
    /// path) the constraint bound; 1 for the program check.
    pub fn share(&self) -> f64 {
        match self {
            Binding::Subsample { share, .. } | Binding::FullPath { share, .. } => *share,
            Binding::ProgramCheck { .. } => 1.0,
        }
    }

    /// The constraint, when the optimiser or the keep-out box bound
    /// (not the caller's check).
    pub fn limit(&self) -> Option<&Limit> {
        match self {
            Binding::Subsample { limit, .. } | Binding::FullPath { limit, .. } => Some(limit),
            Binding::ProgramCheck { .. } => None,
        }
    }
}

impl fmt::Display for Binding {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Binding::Subsample {
                limit,
                example: Some(r),
                ..
            } if *limit == Limit::ProgramCheck => write!(f, "{limit}, e.g. {r}"),
            Binding::Subsample { limit, .. } => write!(f, "{limit}"),
            Binding::FullPath { limit, refused, .. } => {
                write!(f, "{limit} (on the full path)")?;
                if let Some(r) = refused {
                    write!(
                        f,
                        "; another candidate was refused by the program check: {r}"
                    )?;
                }
                Ok(())
            }
            Binding::ProgramCheck { refusal } => write!(f, "{refusal} (program check)"),
        }
    }
}

/// What [`place`](super::place) found.
#[derive(Debug, Clone)]
pub struct Placement {
    /// The cell with the placement found (or the best tried when none is
    /// feasible).
    pub cell: CellLayout,
    /// The placement's values (robot base frame; mm, rad).
    pub values: PlacementValues,
    /// `true` when the full plan in the placed cell is feasible (and passed
    /// the caller's check).
    pub feasible: bool,
    /// Margins of [`Placement::plan`].
    pub margins: Margins,
    /// Margins of the cell as given, on the final subsample.
    pub margins_before: Margins,
    /// Candidates evaluated on the subsample.
    pub candidates: usize,
    /// Fraction of the coarse global samples feasible on the first subsample.
    pub feasible_fraction: f64,
    /// Candidates certified on the full path.
    pub certified: usize,
    /// Rounds run.
    pub rounds: usize,
    /// The constraint the rounds stopped on, when they stopped before
    /// [`PlaceOptions::rounds`](super::PlaceOptions::rounds) because every
    /// candidate judged again after a feedback was infeasible on the
    /// subsample, bound by it.
    pub stopped_on: Option<Limit>,
    /// Layers of the final subsample, and of them at full resolution.
    pub subsample_layers: (usize, usize),
    /// Why no placement was found (`None` when found).
    pub binding: Option<Binding>,
    /// The plan in the placed cell: every layer when feasible; otherwise
    /// the layers checked before certification stopped, or the subsample's
    /// plan when no candidate reached certification.
    pub plan: Plan,
    /// Phase times (s).
    pub times: PlaceTimes,
    /// Wall time (s).
    pub time_s: f64,
}
