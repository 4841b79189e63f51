//! Options of the optimisation stage: plain data with defaults and a
//! `validate()` naming the field (SPEC §7, thesis §4.1.2–4.1.3).

use serde::{Deserialize, Serialize};

use crate::optimise::OptimiseError;
use crate::robot::trajectory::TrajectoryOptions;

/// Default `stop_relative_gain` of [`Parameterisation::Polynomial`]
/// (relative objective gain): raising the degree stops when it gains less
/// than 0.1 %.
pub const DEFAULT_STOP_RELATIVE_GAIN: f64 = 1e-3;
/// Default [`SqpOptions::min_trust_rad`] (rad).
const DEFAULT_MIN_TRUST_RAD: f64 = 1e-9;
/// Default [`SqpOptions::step_tolerance_rad`] (rad).
const DEFAULT_STEP_TOLERANCE_RAD: f64 = 1e-7;
/// Default [`SqpOptions::relative_tolerance`] (relative merit gain).
const DEFAULT_RELATIVE_TOLERANCE: f64 = 1e-9;
/// Default [`OptimiseOptions::centring_weight`] (unitless).
const DEFAULT_CENTRING_WEIGHT: f64 = 1e-3;

/// Abscissa of the polynomial `R_Z` of a layer.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Abscissa {
    /// The point index `m` [eq. 4.1].
    PointIndex,
    /// The point's cylindrical angle about the part Z axis, unwrapped along
    /// the layer (rad) [eq. 4.2]: for parts of revolution.
    CylindricalAngle,
    /// Cylindrical angle when every layer turns about the part Z axis (its
    /// unwrapped angle grows or falls monotonically), point index otherwise.
    #[default]
    Auto,
}

/// How `R_Z` varies along a layer.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Parameterisation {
    /// No optimisation: `R_Z` constant (rad) on every point. The unoptimised
    /// path of the thesis is `Fixed { r_z_rad: 0.0 }`.
    Fixed {
        /// The constant `R_Z` (rad).
        r_z_rad: f64,
    },
    /// `R_Z` a polynomial of degree `n` in the abscissa [eq. 4.1–4.2]. The
    /// degree is raised from the seed's (0 or 1) with warm starts up to
    /// `max_degree`, stopping early when the objective stops improving
    /// (relative gain below `stop_relative_gain`) [§4.2.1], or before
    /// solving the next degree when, with no constraint in reach, the
    /// Gauss–Newton model at the optimum predicts a relative gain below a
    /// hundredth of `stop_relative_gain`.
    Polynomial {
        /// Highest degree tried (0..=8).
        max_degree: usize,
        /// The abscissa.
        abscissa: Abscissa,
        /// Relative objective gain under which raising the degree stops;
        /// negative: always go up to `max_degree`.
        stop_relative_gain: f64,
    },
    /// One `R_Z` per point with the smoothness penalty
    /// `smoothness · Σ_m (R_{m+1} − 2 R_m + R_{m−1})²` (rad²): a discrete
    /// smoothing spline, for free-form layers a polynomial cannot follow.
    SmoothingSpline {
        /// Weight of the second differences (per rad²), relative to the
        /// objective's own weights; > 0.
        smoothness: f64,
    },
    /// The thesis's baseline [§4.1.4]: each point's `R_Z` chosen on its own,
    /// in deposition order, minimising the joint displacement from the
    /// previous point (eq. 4.3 restricted to one step) under the same
    /// constraints. No anticipation: rougher joint motion.
    PointByPoint,
}

impl Default for Parameterisation {
    fn default() -> Self {
        Self::Polynomial {
            max_degree: 4,
            abscissa: Abscissa::Auto,
            stop_relative_gain: DEFAULT_STOP_RELATIVE_GAIN,
        }
    }
}

/// What is minimised along each layer.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Objective {
    /// Weighted joint displacement `Σ_m Σ_j gamma_j (q_{m,j} − q_{m−1,j})²`,
    /// `gamma_j = 1/range_j` (rad⁻¹), `gamma_j = 0` for unlimited joints [eq. 4.3].
    #[default]
    JointDisplacement,
    /// Positioning uncertainty `Σ_m I_m²` (mm²) [eq. 4.13], `I` as
    /// [`UncertaintyFormula::RootTrace`](crate::robot::indices::UncertaintyFormula)
    /// with the robot's encoder resolutions (ArcMate table 4.2 if absent).
    PositioningUncertainty,
}

/// The dexterity floor `psi_max` of eq. 4.6.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum DexterityFloor {
    /// `fraction ×` the dexterity of the unoptimised path (`R_Z = 0`), one
    /// floor per layer: the fraction of the layer's mean unoptimised
    /// dexterity (the thesis: a quarter, §4.1.3). The thesis takes the
    /// floor point by point; but the unoptimised dexterity varies along a
    /// layer only because `R_Z = 0` turns the wrist, and a floor that varies
    /// with it, once active, bends trajectories that could stay still.
    FractionOfUnoptimised {
        /// The fraction (0..1).
        fraction: f64,
    },
    /// The same floor at every point (unitless, 0..1).
    Absolute {
        /// The floor.
        dexterity: f64,
    },
    /// No dexterity constraint.
    Off,
}

impl Default for DexterityFloor {
    fn default() -> Self {
        Self::FractionOfUnoptimised { fraction: 0.25 }
    }
}

/// Which IK branch each layer uses.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ConfigurationChoice {
    /// Evaluate the eight branches on every layer and keep the one whose
    /// seed is feasible and most centred in the joint ranges; the cell's own
    /// branch is kept while its centring score is within 1.5 times the best
    /// (changing branch between layers means reconfiguring the arm).
    #[default]
    BestPerLayer,
    /// The cell's configuration on every layer.
    Cell,
}

/// Settings of the sequential-QP driver.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct SqpOptions {
    /// Most SQP iterations per degree (and per layer for the spline).
    pub max_iterations: usize,
    /// Initial trust radius on the change of `R_Z` at any point (rad).
    pub initial_trust_rad: f64,
    /// Below this trust radius (rad) the driver stops.
    pub min_trust_rad: f64,
    /// Converged when the largest change of `R_Z` in a step is below this (rad).
    pub step_tolerance_rad: f64,
    /// ... or when the merit improves by less than this, relatively.
    pub relative_tolerance: f64,
    /// Weight of the (normalised) largest constraint violation in the merit
    /// function; large enough to make the l∞ penalty exact.
    pub penalty: f64,
}

impl Default for SqpOptions {
    fn default() -> Self {
        Self {
            max_iterations: 60,
            initial_trust_rad: 0.5,
            min_trust_rad: DEFAULT_MIN_TRUST_RAD,
            step_tolerance_rad: DEFAULT_STEP_TOLERANCE_RAD,
            relative_tolerance: DEFAULT_RELATIVE_TOLERANCE,
            penalty: 1e3,
        }
    }
}

/// Options of [`optimise`](crate::optimise::optimise). Plain data.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct OptimiseOptions {
    /// How `R_Z` varies along a layer.
    pub parameterisation: Parameterisation,
    /// What is minimised.
    pub objective: Objective,
    /// The dexterity floor (eq. 4.6).
    pub dexterity_floor: DexterityFloor,
    /// IK branch per layer.
    pub configuration: ConfigurationChoice,
    /// Joints must stay this far inside their travel (rad). Default 0.5°.
    pub joint_limit_margin_rad: f64,
    /// Weight of the secondary objective that keeps the joints centred in
    /// their ranges: `w · (1/p) Σ_m Σ_j ((q_{m,j} − mid_j)/range_j)²`
    /// (unitless). It decides between equally good trajectories (on a part
    /// of revolution every `R_Z = c − theta` moves no joint but J6) so that
    /// each layer starts well inside the ranges; 0 switches it off.
    pub centring_weight: f64,
    /// Constant `R_Z` values tried per branch for the coarse seed (and as many
    /// `c − theta` seeds on layers that turn about the part Z axis).
    pub seeds: usize,
    /// Points of a layer sampled when ranking seeds and branches.
    pub seed_points: usize,
    /// The SQP driver.
    pub sqp: SqpOptions,
    /// Singularity margins and the dexterity length scale of the trajectory
    /// stage, used for the report.
    pub trajectory: TrajectoryOptions,
    /// Solve the layers in parallel (rayon, order preserved; same result).
    pub parallel: bool,
    /// Points of a layer the polynomial law's SQP works on (0: every
    /// point). A layer of more than twice this many points is optimised on
    /// a subsample of about this many (spread along the layer and denser
    /// where the tool axis turns), then the law is certified on every point
    /// with one IK pass; points where a constraint is violated or within the
    /// solver's margin of its bound are added to the subsample and the law
    /// re-solved, and a layer that the subsample cannot certify is solved
    /// on every point as without it. Joints, constraints, status and quality
    /// are always those of every point. Ignored by the fixed law, the
    /// smoothing spline and the point-by-point baseline.
    pub subsample_points: usize,
    /// The torch-carried cell's positioner: optimised laws within the cone
    /// of the vertical (default) or the thesis's exact vertical.
    pub positioner: crate::optimise::positioner::PositionerOptions,
}

impl Default for OptimiseOptions {
    fn default() -> Self {
        Self {
            parameterisation: Parameterisation::default(),
            objective: Objective::default(),
            dexterity_floor: DexterityFloor::default(),
            configuration: ConfigurationChoice::default(),
            joint_limit_margin_rad: 0.5f64.to_radians(),
            centring_weight: DEFAULT_CENTRING_WEIGHT,
            seeds: 12,
            seed_points: 12,
            sqp: SqpOptions::default(),
            trajectory: TrajectoryOptions::default(),
            parallel: true,
            subsample_points: 64,
            positioner: Default::default(),
        }
    }
}

impl OptimiseOptions {
    /// Checks every field.
    ///
    /// # Errors
    /// [`OptimiseError::InvalidOption`] naming the field.
    pub fn validate(&self) -> Result<(), OptimiseError> {
        let bad = |field: &'static str, value: f64, reason: &'static str| {
            Err(OptimiseError::InvalidOption {
                field,
                value,
                reason,
            })
        };
        if let Some((field, value, reason)) = self.positioner.invalid() {
            return bad(field, value, reason);
        }
        match self.parameterisation {
            Parameterisation::Fixed { r_z_rad } if !r_z_rad.is_finite() => {
                return bad("parameterisation.r_z_rad", r_z_rad, "must be finite")
            }
            Parameterisation::Polynomial {
                max_degree,
                stop_relative_gain,
                ..
            } => {
                if max_degree > 8 {
                    return bad(
                        "parameterisation.max_degree",
                        max_degree as f64,
                        "must be in 0..=8",
                    );
                }
                if !stop_relative_gain.is_finite() {
                    return bad(
                        "parameterisation.stop_relative_gain",
                        stop_relative_gain,
                        "must be finite",
                    );
                }
            }
            Parameterisation::SmoothingSpline { smoothness }
                if !(smoothness > 0.0 && smoothness.is_finite()) =>
            {
                return bad(
                    "parameterisation.smoothness",
                    smoothness,
                    "must be finite and > 0",
                )
            }
            _ => {}
        }
        match self.dexterity_floor {
            DexterityFloor::FractionOfUnoptimised { fraction }
                if !(0.0..1.0).contains(&fraction) =>
            {
                return bad("dexterity_floor.fraction", fraction, "must be in [0, 1)")
            }
            DexterityFloor::Absolute { dexterity } if !(0.0..1.0).contains(&dexterity) => {
                return bad("dexterity_floor.dexterity", dexterity, "must be in [0, 1)")
            }
            _ => {}
        }
        if !(0.0..0.5).contains(&self.joint_limit_margin_rad) {
            return bad(
                "joint_limit_margin_rad",
                self.joint_limit_margin_rad,
                "must be in [0, 0.5)",
            );
        }
        if !(self.centring_weight >= 0.0 && self.centring_weight.is_finite()) {
            return bad(
                "centring_weight",
                self.centring_weight,
                "must be finite and >= 0",
            );
        }
        if self.seeds == 0 {
            return bad("seeds", 0.0, "must be at least 1");
        }
        if self.subsample_points != 0 && self.subsample_points < 8 {
            return bad(
                "subsample_points",
                self.subsample_points as f64,
                "must be 0 (off) or at least 8",
            );
        }
        if self.seed_points < 2 {
            return bad("seed_points", self.seed_points as f64, "must be at least 2");
        }
        let s = &self.sqp;
        if s.max_iterations == 0 {
            return bad("sqp.max_iterations", 0.0, "must be at least 1");
        }
        for (field, v) in [
            ("sqp.initial_trust_rad", s.initial_trust_rad),
            ("sqp.min_trust_rad", s.min_trust_rad),
            ("sqp.step_tolerance_rad", s.step_tolerance_rad),
            ("sqp.penalty", s.penalty),
        ] {
            if !(v > 0.0 && v.is_finite()) {
                return bad(field, v, "must be finite and > 0");
            }
        }
        if !(s.relative_tolerance >= 0.0 && s.relative_tolerance.is_finite()) {
            return bad(
                "sqp.relative_tolerance",
                s.relative_tolerance,
                "must be finite and >= 0",
            );
        }
        if s.min_trust_rad > s.initial_trust_rad {
            return bad(
                "sqp.min_trust_rad",
                s.min_trust_rad,
                "must not exceed sqp.initial_trust_rad",
            );
        }
        self.trajectory
            .validate()
            .map_err(|_| OptimiseError::InvalidOption {
                field: "trajectory",
                value: f64::NAN,
                reason: "invalid trajectory options (see TrajectoryOptions::validate)",
            })?;
        Ok(())
    }
}
