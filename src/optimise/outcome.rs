//! What the optimisation gives back: per layer the chosen branch and why,
//! the `R_Z` law, joints per point, a status (optimal, infeasible naming the
//! binding constraint, not converged, no IK solution) and the trajectory
//! quality figures next to the objective. Outcomes are data, not errors.

use std::fmt;

use crate::robot::ik::Configuration;
use crate::robot::model::Joints;
use crate::robot::positioner::PositionerJoints;
use crate::robot::trajectory::Violation;
use crate::robot::RobotError;

/// The error of the optimisation stage: bad input only. A layer that cannot
/// be made feasible is an outcome ([`LayerStatus`]), not an error.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum OptimiseError {
    /// An option is out of its domain.
    #[error("optimisation options: `{field}` = {value} is invalid ({reason})")]
    InvalidOption {
        /// The field, dotted.
        field: &'static str,
        /// The offending value.
        value: f64,
        /// Why.
        reason: &'static str,
    },
    /// A layer has fewer than two points.
    #[error("layer {layer}: {points} point(s), at least 2 are needed to optimise R_Z")]
    TooFewPoints {
        /// Layer index.
        layer: usize,
        /// Its number of points.
        points: usize,
    },
    /// A point is not finite.
    #[error("layer {layer}, point {point}: {reason}")]
    BadPoint {
        /// Layer index.
        layer: usize,
        /// Point index within the layer.
        point: usize,
        /// What is wrong.
        reason: &'static str,
    },
    /// The cell is invalid.
    #[error("cell: {0}")]
    Cell(#[from] RobotError),
    /// The host asked to stop (see [`optimise_with`](crate::optimise::optimise_with)).
    #[error("cancelled after {layers_done} of {layers} layers")]
    Cancelled {
        /// Layers solved when the run stopped.
        layers_done: usize,
        /// Layers in all.
        layers: usize,
    },
    /// A placement bound or setting is invalid (see
    /// [`place`](crate::place::place)).
    #[error("placement: `{field}`: {reason}")]
    InvalidPlacement {
        /// The variable or setting, as in the cell file's `[placement]` table.
        field: String,
        /// What is wrong.
        reason: String,
    },
}

/// A constraint of the per-layer problem [eq. 4.5–4.8].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Constraint {
    /// Joint travel (1-based joint), eq. 4.5, with the options' margin; for
    /// J5 also the wrist-singularity margin on the branch's side.
    JointLimit {
        /// Joint number, 1-based.
        joint: usize,
    },
    /// Dexterity floor `psi_max`, eq. 4.6.
    Dexterity,
    /// Hose torsion `|q4 + q6|`, eq. 4.8 (torch-carried cell).
    HoseTorsion,
    /// Joint speed at the programmed travel speed, from the previous point.
    JointSpeed {
        /// Joint number, 1-based.
        joint: usize,
    },
    /// The build direction outside the cell's cone of the vertical
    /// (torch-carried cell; the violation in rad).
    BuildTilt,
}

impl fmt::Display for Constraint {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Constraint::JointLimit { joint } => write!(f, "J{joint} travel"),
            Constraint::Dexterity => write!(f, "dexterity floor"),
            Constraint::HoseTorsion => write!(f, "hose torsion |J4 + J6|"),
            Constraint::JointSpeed { joint } => write!(f, "J{joint} speed"),
            Constraint::BuildTilt => write!(f, "build direction outside the cone of the vertical"),
        }
    }
}

/// The most violated constraint of a layer.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BindingConstraint {
    /// Point index within the layer.
    pub point: usize,
    /// Which constraint.
    pub constraint: Constraint,
    /// By how much (rad for joints, hose and speeds over one step; relative
    /// to the floor for dexterity).
    pub violation: f64,
}

impl fmt::Display for BindingConstraint {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.constraint {
            Constraint::Dexterity => write!(
                f,
                "{} at point {} (short by {:.2} % of the floor)",
                self.constraint,
                self.point,
                100.0 * self.violation
            ),
            _ => write!(
                f,
                "{} at point {} (over by {:.4}°)",
                self.constraint,
                self.point,
                self.violation.to_degrees()
            ),
        }
    }
}

/// How the optimisation of one layer ended.
#[derive(Debug, Clone, PartialEq)]
pub enum LayerStatus {
    /// Every constraint holds and the SQP converged.
    Optimal,
    /// Every constraint holds at the trajectory kept, but the SQP stopped at
    /// its iteration limit before converging.
    NotConverged {
        /// SQP iterations made.
        iterations: usize,
    },
    /// No `R_Z` law found keeps every constraint; the least-violating one is
    /// kept and its binding constraint named.
    Infeasible {
        /// The most violated constraint.
        binding: BindingConstraint,
    },
    /// `R_Z` was not optimised (fixed) and a constraint fails.
    FixedViolates {
        /// The most violated constraint.
        binding: BindingConstraint,
    },
    /// No branch has a joint solution at some point of the layer.
    NoSolution {
        /// Point index within the layer.
        point: usize,
        /// Why (unreachable, singular...).
        error: RobotError,
    },
}

impl LayerStatus {
    /// `true` when the layer can be built as planned.
    pub fn is_feasible(&self) -> bool {
        matches!(
            self,
            LayerStatus::Optimal | LayerStatus::NotConverged { .. }
        )
    }
}

/// Why a branch was chosen for a layer.
#[derive(Debug, Clone, PartialEq)]
pub struct ConfigurationChoiceReport {
    /// The branch kept for the whole layer.
    pub chosen: Configuration,
    /// Every branch evaluated, best first: `(branch, seed violation (rad or
    /// relative), centring score Σ((q − mid)/range)² averaged over the seed
    /// points; infinite when a point has no solution)`.
    pub ranking: Vec<(Configuration, f64, f64)>,
    /// In words.
    pub reason: String,
}

/// The `R_Z` law of a layer. Serialises (`summary.json`) as an object
/// tagged by `family` (`fixed`, `polynomial`, `smoothing_spline`,
/// `point_by_point`) with the variant's fields.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
#[serde(tag = "family", rename_all = "snake_case")]
pub enum SolvedRzLaw {
    /// Constant.
    Fixed {
        /// `R_Z` (rad).
        r_z_rad: f64,
    },
    /// Polynomial of `degree` [eq. 4.1–4.2]: coefficients of the thesis's
    /// form (highest power first, degrees, abscissa the 1-based point index
    /// or the cylindrical angle in rad).
    Polynomial {
        /// Degree kept.
        degree: usize,
        /// `true`: abscissa = cylindrical angle (rad); `false`: point index (from 1).
        cylindrical: bool,
        /// `B_{C,n}` (deg per abscissa power), highest power first.
        coefficients_deg: Vec<f64>,
        /// Objective after each degree tried (eq. 4.3 or 4.13, as optimised).
        objective_per_degree: Vec<(usize, f64)>,
    },
    /// One value per point with a smoothness penalty.
    SmoothingSpline,
    /// Point by point (thesis §4.1.4).
    PointByPoint,
}

/// One planned point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlannedPoint {
    /// `R_Z` (rad).
    pub r_z: f64,
    /// Robot joints (rad), unwrapped along the layer; `None` without solution.
    pub joints: Option<Joints>,
    /// Positioner joints `[q7, q8]` (rad), torch-carried cell.
    pub positioner: Option<PositionerJoints>,
    /// Dexterity `xi_min/xi_max` [eq. 1.8].
    pub dexterity: f64,
}

/// Objective values of a layer (whatever was optimised, all are reported).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ObjectiveReport {
    /// Weighted joint displacement (eq. 4.3), rad.
    pub joint_displacement: f64,
    /// Positioning uncertainty `Σ I_m²` (eq. 4.13), mm².
    pub uncertainty_sum_sq_mm2: f64,
    /// Mean `I_m` (mm).
    pub mean_uncertainty_mm: f64,
    /// The centring term `(1/p) Σ Σ ((q − mid)/range)²` (unweighted).
    pub centring: f64,
}

/// Trajectory quality of a layer at the programmed travel speed. Speeds are
/// `Δq/Δt` between points, accelerations the differences of those speeds.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct LayerQuality {
    /// `Σ_m |q_{m,j} − q_{m−1,j}|` per joint (rad).
    pub joint_travel_rad: Joints,
    /// Largest `|dq/dt|` per joint (rad/s).
    pub peak_speed_rad_s: Joints,
    /// Largest `|d²q/dt²|` per joint (rad/s²).
    pub peak_acceleration_rad_s2: Joints,
    /// `Σ_m |d²q/dt²|·Δt` over the layer and joints J1–J5 (rad/s): how
    /// much the speeds change (0 for joints at constant speed).
    pub summed_acceleration_rad_s: f64,
    /// Changes of direction per joint (moves below 1e-7 rad ignored).
    pub direction_reversals: [usize; 6],
    /// Smallest dexterity.
    pub min_dexterity: f64,
    /// Smallest distance to a joint stop over the limited joints (rad).
    pub min_limit_distance_rad: f64,
    /// The joint (1-based) where that distance is reached.
    pub min_limit_distance_joint: usize,
    /// Largest `|q4 + q6|` (rad).
    pub max_hose_torsion_rad: f64,
}

/// The solver's account of a layer.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct SolverReport {
    /// SQP iterations over all degrees and branches tried.
    pub iterations: usize,
    /// QPs solved (clarabel).
    pub qp_solves: usize,
    /// QPs clarabel did not solve to full accuracy (step rejected).
    pub qp_failures: usize,
    /// Branches optimised (more than one when the first was infeasible).
    pub branches_tried: usize,
    /// `Some(n)`: the law kept was optimised on `n` points of the layer and
    /// certified on every point
    /// ([`OptimiseOptions::subsample_points`](super::OptimiseOptions::subsample_points));
    /// `None`: optimised on every point.
    pub samples: Option<usize>,
    /// Wall time (s).
    pub time_s: f64,
}

/// The plan of one layer.
#[derive(Debug, Clone, PartialEq)]
pub struct LayerPlan {
    /// Layer index (as given).
    pub layer: usize,
    /// Status.
    pub status: LayerStatus,
    /// The branch and why.
    pub configuration: ConfigurationChoiceReport,
    /// The `R_Z` law.
    pub law: SolvedRzLaw,
    /// One per point, same order as the input.
    pub points: Vec<PlannedPoint>,
    /// Objective values.
    pub objective: ObjectiveReport,
    /// Quality figures.
    pub quality: LayerQuality,
    /// Solver figures.
    pub solver: SolverReport,
    /// Every violation of the final trajectory (trajectory stage's check,
    /// layer and point named), empty when feasible.
    pub violations: Vec<Violation>,
    /// The positioner's laws (torch-carried cell): seed, largest tilt of
    /// `b` from the vertical and where, binding constraint.
    pub positioner: Option<crate::optimise::positioner::PositionerLaw>,
    /// The trajectory stage's re-check of the layer as solved (joints,
    /// speeds, violations), which the program's trajectory takes where it
    /// would solve the same points in the same cell
    /// ([`SolvedBead::reuse`](crate::robot::trajectory::SolvedBead)); `None`
    /// where the re-check refused its input or the layer has no solution.
    pub(crate) solved: Option<std::sync::Arc<crate::robot::trajectory::SolvedBead>>,
}

/// The arc-off move from the last point of a layer to the first of the next.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Transition {
    /// Layer left.
    pub from_layer: usize,
    /// Layer started.
    pub to_layer: usize,
    /// Joint change (rad), J4/J6 rewound into their travel.
    pub joint_change_rad: Joints,
    /// Whether the branch changes (the robot reconfigures with the arc off).
    pub branch_change: bool,
    /// Smallest distance to a joint stop at the first point of the new layer (rad).
    pub start_limit_distance_rad: f64,
}

/// The whole optimised plan.
#[derive(Debug, Clone, PartialEq)]
pub struct Plan {
    /// One per input layer, same order.
    pub layers: Vec<LayerPlan>,
    /// Between consecutive layers.
    pub transitions: Vec<Transition>,
    /// Wall time of the whole optimisation (s).
    pub time_s: f64,
}

impl Plan {
    /// `true` when every layer is feasible.
    pub fn is_feasible(&self) -> bool {
        self.layers.iter().all(|l| l.status.is_feasible())
    }

    /// Every violation of every layer, in path order.
    pub fn violations(&self) -> impl Iterator<Item = &Violation> {
        self.layers.iter().flat_map(|l| l.violations.iter())
    }

    /// Layers that are not feasible.
    pub fn infeasible_layers(&self) -> impl Iterator<Item = &LayerPlan> {
        self.layers.iter().filter(|l| !l.status.is_feasible())
    }
}

impl fmt::Display for LayerStatus {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            LayerStatus::Optimal => write!(f, "optimal"),
            LayerStatus::NotConverged { iterations } => {
                write!(f, "feasible, not converged after {iterations} iterations")
            }
            LayerStatus::Infeasible { binding } => write!(f, "infeasible: {binding}"),
            LayerStatus::FixedViolates { binding } => {
                write!(f, "fixed R_Z violates {binding}")
            }
            LayerStatus::NoSolution { point, error } => {
                write!(f, "no joint solution at point {point}: {error}")
            }
        }
    }
}
