//! **Stage 6a — the positioner's laws (torch-carried cell).** Takes the
//! points of one layer (part frame: position mm, tool axis, build direction)
//! and a [`TorchCarriedCell`], and returns the tilt `q7` and turn `q8` of its
//! 2-axis positioner at every point (rad) as smooth laws along the layer
//! (cubic splines in the point index, or in the cylindrical angle on a layer
//! that turns about the part Z axis, the abscissae of `R_Z`'s [eq. 4.1–4.2]:
//! a bent tube's `b` swings in several lobes per layer, which a low-degree
//! polynomial does not follow). The `R_Z`
//! optimisation (stage 5) then plans the arm against them. Issue 33, SPEC §9.
//!
//! The thesis turns `b` exactly vertical at every point (SPEC §6.4), which
//! fixes both axes: where `b` passes near the turn axis the turn spins, and a
//! bent tube's `b` varies by up to ~60° within a layer, so the table must
//! follow it point by point. WAAM deposits sound beads with `b` within a
//! qualified cone of the vertical (the cell's `max_vertical_error_deg`), which
//! leaves the positioner two free axes. Per layer this stage solves
//!
//! ```text
//! min  Σ_steps [ γ7 Δq7² + γ8 Δq8² + γ_arm (|Δp_w|²/L² + |ΔT_w|²) ]  +  λ mean_m |b_w,m × z|²
//! s.t. b_w,m · z ≥ cos(cone)                 (b seen in the world within the cone)
//!      q_k,m inside the positioner's travel  (k = 7, 8; with the plan's margin)
//!      |Δq_k| ≤ v_max,k · Δs / TS            (speeds at the programmed travel speed)
//! ```
//!
//! `γ_k = 1/range_k` (0 for an endless axis, as J6 in eq. 4.3); `p_w`, `T_w`
//! the deposition point and tool axis in the robot base frame, which the arm
//! must follow: `γ_arm` (the mean `1/range` of J1–J5) and `L` (the arm's
//! reach, mm) turn their motion into an estimate of the arm's joint
//! displacement, so that the table turns the part under a still torch on a
//! part of revolution and holds still on a bend's layer whose centre is off
//! its axis. `λ` ([`PositionerOptions::tilt_weight`]) keeps the tilt at zero
//! wherever it costs nothing. Derivatives are analytic (the positioner's FK,
//! [`Positioner::positioner_from_table_derivatives`]); the QPs are the
//! elastic ones of the `R_Z` driver, so an infeasible layer ends at its least
//! violation with the binding constraint named. Where `b` stays within the
//! cone of the turn axis the turn is free and is held still (the pole).
//!
//! Three seeds are solved and the best kept: the positioner held at the pose
//! that turns the layer's mean `b` vertical; a lazy follower that holds its
//! pose while `b` stays within 70 % of the cone and moves just enough where
//! it would leave it; and the thesis's pose that turns every point's `b`
//! exactly vertical (each fitted by the law). The knots are uniform in the
//! abscissa first; where no seed keeps the cone, the seeds are solved again
//! with knots crowding where `b` turns (`following_turning`), the better
//! law kept. The other starts' laws that also keep the cone are returned as
//! [`PositionerLaw::alternatives`]: where the arm cannot follow the best
//! one (hose torsion, a joint's speed: the proxy above does not see them),
//! the layer is planned on them, best first; where none serves, the law is
//! solved again under the arm's own hose and joint limits, linearised
//! through its inverse kinematics at the points where it broke them
//! ([`ArmRow`], [`positioner_law_for_arm`]). A bead's turn stays within the
//! controller's stroke modulo whole turns ([`TorchCarriedCell::turn_stroke`]).
//! A law is solved on
//! at most [`PositionerOptions::sample_points`] points, then checked on every
//! point; the worst violated points join the samples and it is solved again.

use serde::{Deserialize, Serialize};

use crate::math::{tol, Matrix3, Point3, UnitVector3, Vector3};
use crate::optimise::parameterisation::{cylindrical_angles, turns_about_z, Basis};
use crate::optimise::problem::Row;
use crate::optimise::sqp::solve_qp;
use crate::robot::cell::{CellPoint, TorchCarriedCell};
use crate::robot::positioner::{Positioner, PositionerJoints};

/// Ridge added to the positioner SQP's Gauss–Newton matrix, relative to its
/// mean diagonal (relative).
const RIDGE_REL: f64 = 1e-9;
/// Floor of the mean diagonal the ridge scales with (units of `JᵀJ`).
const RIDGE_TRACE_FLOOR: f64 = 1e-12;
/// Trust bound on the positioner joints' coefficients (rad) below which the
/// SQP stops.
const MIN_TRUST_RAD: f64 = 1e-9;
/// Largest coefficient change (rad) of a refused step below which the SQP
/// stops: shrinking the trust region further changes nothing.
const MIN_STEP_RAD: f64 = 1e-10;
/// A trial is accepted when it lowers the merit by more than this fraction of
/// it (relative): more than rounding.
const ACCEPT_GAIN_REL: f64 = 1e-14;
/// An accepted gain below this fraction of the merit (relative) is flat: the
/// SQP stops.
const FLAT_GAIN_REL: f64 = 1e-9;
/// Floor of the merit the two relative gains above scale with (merit units).
const MERIT_FLOOR: f64 = 1e-12;
/// The sum of the build directions (unit vectors) shorter than this has no
/// mean direction: no hold seed (unitless).
const MIN_BUILD_SUM: f64 = 1e-9;
/// A feasible seed whose objective is at most this (objective units) cannot
/// be beaten: the remaining seeds are skipped.
const ZERO_OBJECTIVE: f64 = 1e-14;
/// A violation left on the samples above this (constraint units) means
/// the SQP is stuck: more samples cannot help.
const STUCK_VIOLATION: f64 = 1e-9;

/// [`required_rotation_rate`] skips a pair whose build directions' cosine
/// is this much above the cone's width's (unitless): they need no rotation.
const PAIR_SKIP_COS: f64 = 1e-12;

/// Two laws within this of each other at every point (rad, each axis) are
/// the same law (an alternative is kept once).
const SAME_LAW_RAD: f64 = 1e-6;

/// Laws whose violations of the arm's rows differ by less than this are
/// ranked by their objective (rad).
const ARM_TIE_RAD: f64 = 1e-4;

/// How the torch-carried cell's positioner moves.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum PositionerMode {
    /// Smooth laws optimised within the cone of the vertical (this module).
    #[default]
    Optimised,
    /// The thesis's: `b` turned exactly vertical at every point (SPEC §6.4,
    /// eq. C.24–C.25 solved from the FK), the cone only a tolerance.
    Vertical,
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

/// Which positioner constraint binds a law.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum PositionerBinding {
    /// `b` leaves the cone of the vertical (rad over the cone).
    Cone {
        /// Point index within the layer.
        point: usize,
        /// Angle of `b` from the vertical (rad).
        tilt_rad: f64,
        /// The cone's half angle (rad).
        max_rad: f64,
    },
    /// An axis outside its travel.
    Travel {
        /// 7 (tilt) or 8 (turn).
        joint: usize,
        /// Point index within the layer.
        point: usize,
        /// Value (rad).
        value_rad: f64,
    },
    /// The endless turn leaves the window of the controller's stroke the
    /// bead was shifted into ([`TorchCarriedCell::turn_stroke`], less the
    /// plan's margin, moved by whole turns): the bead turns the table
    /// through more than the program can hold.
    Stroke {
        /// Point index within the layer.
        point: usize,
        /// Value (rad).
        value_rad: f64,
        /// The window's lower bound (rad).
        lower_rad: f64,
        /// The window's upper bound (rad).
        upper_rad: f64,
    },
    /// An axis faster than its maximum at the programmed travel speed.
    Speed {
        /// 7 (tilt) or 8 (turn).
        joint: usize,
        /// Point index within the layer (the step from the point before).
        point: usize,
        /// Speed needed (rad/s).
        speed_rad_s: f64,
        /// Maximum (rad/s).
        max_rad_s: f64,
    },
}

impl std::fmt::Display for PositionerBinding {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match *self {
            Self::Cone {
                point,
                tilt_rad,
                max_rad,
            } => write!(
                f,
                "build direction {:.2}° from the vertical at point {point} (cone {:.1}°)",
                tilt_rad.to_degrees(),
                max_rad.to_degrees()
            ),
            Self::Travel {
                joint,
                point,
                value_rad,
            } => write!(
                f,
                "positioner J{joint} = {:.2}° outside its travel at point {point}",
                value_rad.to_degrees()
            ),
            Self::Stroke {
                point,
                value_rad,
                lower_rad,
                upper_rad,
            } => write!(
                f,
                "positioner J8 = {:.1}° at point {point} outside the turn's stroke [{:.1}°, {:.1}°] (shifted by whole turns): the bead turns the table through more than the program holds",
                value_rad.to_degrees(),
                lower_rad.to_degrees(),
                upper_rad.to_degrees()
            ),
            Self::Speed {
                joint,
                point,
                speed_rad_s,
                max_rad_s,
            } => write!(
                f,
                "positioner J{joint} needs {:.1}°/s at point {point}, maximum {:.1}°/s",
                speed_rad_s.to_degrees(),
                max_rad_s.to_degrees()
            ),
        }
    }
}

/// Which start the kept law came from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum PositionerSeed {
    /// Held at the pose that turns the layer's mean `b` vertical.
    Hold,
    /// Every point's `b` exactly vertical (the thesis), fitted by the law.
    Follow,
    /// The pose held while `b` stays well inside the cone, moved just
    /// enough where it would leave it, fitted by the law.
    Lazy,
    /// Every point's `b` exactly vertical, not fitted: with
    /// [`PositionerMode::Vertical`], or where no smooth law keeps the cone
    /// (a corner of `b`) and the positioner's speeds allow it.
    Vertical,
    /// The law the arm could not follow, solved again under the arm's
    /// linearised constraints ([`ArmRow`], [`positioner_law_for_arm`]).
    Arm,
    /// A path of positioner poses over a grid of 0.25–2° cells that keeps
    /// `b` inside the cone at every point of the layer within the axes'
    /// speeds (the reachable poses propagated point to point, followed back
    /// with the least motion and relaxed), fitted by the law, or kept as it
    /// is where no fit keeps the constraints: where no other start's law
    /// keeps the cone (a layer whose `b` passes the pole and swings far off
    /// it, or turns a corner off the pole, where the smooth starts fall into
    /// a local minimum).
    Grid,
}

/// A linearised constraint of the arm on one point's positioner joints:
/// `grad · (q − q0) ≤ slack` (rad). At `q0` the arm, with the `R_Z` planned
/// there, has a quantity (hose torsion, a joint) `slack` from its bound;
/// `grad` is that quantity's derivative in `[q7, q8]` (unitless), through
/// the arm's inverse kinematics. The positioner's laws see the arm only
/// through a proxy; these rows put the arm's own limits into them where
/// the arm could not follow a law.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ArmRow {
    /// Point index within the layer.
    pub point: usize,
    /// The positioner joints the row is linearised at (rad).
    pub q0: PositionerJoints,
    /// Derivative of the bounded quantity in `q7`, `q8` (unitless).
    pub grad: [f64; 2],
    /// How far the quantity is inside its bound at `q0` (rad; negative
    /// when violated).
    pub slack_rad: f64,
}

impl ArmRow {
    /// How far `q` breaks the row (rad; 0 when it holds).
    fn violation(&self, q: &PositionerJoints) -> f64 {
        let d = self.grad[0] * (q[0] - self.q0[0]) + self.grad[1] * (q[1] - self.q0[1]);
        (d - self.slack_rad).max(0.0)
    }
}

/// The positioner's laws of one layer and how they were found.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PositionerLaw {
    /// `[q7, q8]` per point of the layer (rad).
    pub joints: Vec<PositionerJoints>,
    /// Largest angle of `b` (robot base frame) from the vertical (rad).
    pub max_tilt_rad: f64,
    /// The point where it is reached.
    pub max_tilt_point: usize,
    /// The seed kept.
    pub seed: PositionerSeed,
    /// `true` when cone, travel and speeds hold at every point.
    pub feasible: bool,
    /// The most violated constraint when not feasible.
    pub binding: Option<PositionerBinding>,
    /// SQP iterations (both seeds, all rounds).
    pub iterations: usize,
    /// Points the law was solved on.
    pub samples: usize,
    /// The objective of the module doc at the law kept (rad², eq. 4.3
    /// form; 0 in [`PositionerMode::Vertical`]).
    pub objective: f64,
    /// A bound from the geometry alone: the positioner must turn the part
    /// at least this fast (rad/s) somewhere on the layer to keep `b` within
    /// the cone ([`required_rotation_rate`]); `inf` at a corner of `b`.
    pub required_rate_rad_s: f64,
    /// The fastest the positioner can turn the part, `v7 + v8` (rad/s; `inf`
    /// when a speed is unknown).
    pub available_rate_rad_s: f64,
    /// `true` when the geometry proves the layer cannot be built in this
    /// cell whatever the arm and the positioner do: the rate bound
    /// (`required > available`), or no positioner path reaches
    /// [`PositionerLaw::unreachable_point`].
    pub proven_infeasible: bool,
    /// Where a layer the laws could not keep in the cone was also searched
    /// on a grid of positioner poses ([`unreachable_point`]): the first point
    /// that no positioner motion within its travel and speeds reaches with
    /// `b` inside the cone. `None`: not searched, or reached.
    pub unreachable_point: Option<usize>,
    /// The stretch of the layer `(i, j)` (point indices) where the bound is reached.
    pub required_between: (usize, usize),
    /// The other starts' laws that also hold cone, travel and speeds, best
    /// objective first: the positioner sees the arm only through a proxy,
    /// so where the arm cannot follow the kept law (hose torsion, a joint's
    /// speed) the layer is planned again on these. Not serialised.
    #[serde(skip)]
    pub alternatives: Vec<PositionerLaw>,
}

/// The slowest rotation (rad/s) of the positioner that can keep every
/// build direction of a layer within `cone_rad` of the vertical, from the
/// geometry alone, with the points `(i, j)` where it binds.
///
/// Between points `i` and `j` the part-frame directions `b_i`, `b_j` are
/// `θ_ij` apart; seen in the world both are within the cone, so within
/// `2·cone` of each other, and the positioner's rotation between the two
/// poses is at least `θ_ij − 2·cone` (the triangle inequality of angles). A
/// tilt-turn table turns the part by at most `|Δq7| + |Δq8|`, so over the
/// stretch's time `t_ij` (its length over the travel speed) it needs
/// `v7 + v8 ≥ (θ_ij − 2·cone) / t_ij`. `b` unit vectors (part frame), `dt`
/// the time of the step into each point (s, `dt[0]` unused).
pub fn required_rotation_rate(b: &[Vector3], dt: &[f64], cone_rad: f64) -> (f64, (usize, usize)) {
    let n = b.len();
    let mut time = vec![0.0; n];
    for m in 1..n {
        time[m] = time[m - 1] + dt[m];
    }
    let mut best = (0.0f64, (0, 0));
    let reach = std::f64::consts::PI - 2.0 * cone_rad;
    if reach <= 0.0 {
        return best;
    }
    // pairs closer than the cone's width need no rotation: skipped before
    // the angle (a hair inside, so that rounding cannot skip a pair in need)
    let within = (2.0 * cone_rad).cos() + PAIR_SKIP_COS;
    for i in 0..n {
        // per block of j, the widest angle a pair of the block needs to beat
        // the best so far at the block's first (shortest) time: pairs within
        // it cannot, and are skipped before the angle
        let mut skip_above = within;
        for j in i + 1..n {
            let t = time[j] - time[i];
            // no later j can need more: θ ≤ π
            if t > 0.0 && reach / t <= best.0 {
                break;
            }
            if (j - i - 1) % RATE_BLOCK == 0 {
                let beat = 2.0 * cone_rad + best.0 * t;
                // (beat ≥ 2·cone: never fewer skipped than `within`)
                skip_above = if beat < std::f64::consts::PI {
                    beat.cos() + PAIR_SKIP_COS
                } else {
                    -2.0
                };
            }
            if b[i].dot(&b[j]) > skip_above {
                continue;
            }
            let theta = b[i].cross(&b[j]).norm().atan2(b[i].dot(&b[j]));
            let need = theta - 2.0 * cone_rad;
            if need > 0.0 {
                let rate = if t > 0.0 { need / t } else { f64::INFINITY };
                if rate > best.0 {
                    best = (rate, (i, j));
                }
            }
        }
    }
    best
}

/// Pairs of [`required_rotation_rate`] that share one skipping bound.
const RATE_BLOCK: usize = 16;

/// What a law is solved against: the layer in the table frame.
struct LawProblem<'a> {
    cell: &'a TorchCarriedCell,
    /// Deposition points, table frame (mm).
    m: Vec<Vector3>,
    /// Tool axes, table frame.
    t: Vec<Vector3>,
    /// Build directions, table frame.
    b: Vec<Vector3>,
    /// `base_from_positioner` rotation.
    r0: Matrix3,
    /// Time of the step into each point (s); 0 for point 0.
    dt: Vec<f64>,
    cos_cone: f64,
    cone: f64,
    gamma: [f64; 2],
    gamma_arm: f64,
    lower: [f64; 2],
    upper: [f64; 2],
    /// `true` when `lower[1]..upper[1]` is the controller's stroke window
    /// ([`stroke_window`]), not the turn's travel.
    stroke_window: bool,
    /// The arm's linearised constraints ([`positioner_law_for_arm`]).
    arm: Vec<ArmRow>,
    max_speed: [f64; 2],
    opts: PositionerOptions,
}

impl<'a> LawProblem<'a> {
    /// The layer `points` (part frame) in `cell`'s table frame, at
    /// `travel_speed_mm_s`, each travel narrowed by `margin_rad`, with the
    /// arm's rows `arm`.
    fn new(
        cell: &'a TorchCarriedCell,
        points: &[CellPoint],
        travel_speed_mm_s: f64,
        margin_rad: f64,
        opts: &PositionerOptions,
        arm: &[ArmRow],
    ) -> Self {
        let pos: &Positioner = &cell.positioner;
        let r_tp = cell.table_from_part.rotation;
        LawProblem {
            cell,
            m: points
                .iter()
                .map(|p| (cell.table_from_part * p.position_mm).coords)
                .collect(),
            t: points
                .iter()
                .map(|p| r_tp * p.tool_axis.into_inner())
                .collect(),
            b: points
                .iter()
                .map(|p| r_tp * p.build_direction.unwrap_or(p.tool_axis).into_inner())
                .collect(),
            r0: *cell
                .base_from_positioner
                .rotation
                .to_rotation_matrix()
                .matrix(),
            dt: std::iter::once(0.0)
                .chain(
                    points
                        .windows(2)
                        .map(|w| (w[1].position_mm - w[0].position_mm).norm() / travel_speed_mm_s),
                )
                .collect(),
            cos_cone: (0.99 * cell.max_vertical_error_rad.min(std::f64::consts::PI)).cos(),
            cone: cell.max_vertical_error_rad.min(std::f64::consts::PI),
            gamma: std::array::from_fn(|a| {
                inverse_range(pos.limits[a].lower_rad, pos.limits[a].upper_rad)
            }),
            gamma_arm: {
                let l = &cell.robot.limits;
                (0..5)
                    .map(|j| inverse_range(l[j].lower_rad, l[j].upper_rad))
                    .sum::<f64>()
                    / 5.0
            },
            lower: std::array::from_fn(|a| pos.limits[a].lower_rad + margin_rad),
            upper: std::array::from_fn(|a| pos.limits[a].upper_rad - margin_rad),
            stroke_window: false,
            arm: arm.to_vec(),
            max_speed: pos.max_speed_rad_s,
            opts: *opts,
        }
    }

    /// The first point [`unreachable_point`] proves out of reach on the
    /// first of the grids `cells_deg` (deg) that proves one.
    fn unreachable_on(&self, cells_deg: &[f64]) -> Option<usize> {
        cells_deg.iter().find_map(|cell_deg| {
            unreachable_point(
                &self.cell.positioner,
                &self.r0,
                &self.b,
                &self.dt,
                self.cone,
                cell_deg.to_radians(),
            )
        })
    }
}

/// `1/range` of a travel, 0 when unlimited.
fn inverse_range(lo: f64, hi: f64) -> f64 {
    let r = hi - lo;
    if r.is_finite() && r > 0.0 {
        1.0 / r
    } else {
        0.0
    }
}

/// World (base-frame) deposition point, tool axis and build direction at
/// positioner joints `q`, with their derivatives in `q7` and `q8`.
struct WorldPoint {
    p: [Vector3; 3],
    t: [Vector3; 3],
    b: [Vector3; 3],
}

impl LawProblem<'_> {
    /// The largest violation of the arm's rows by `joints` (rad; 0 without
    /// rows).
    fn arm_violation(&self, joints: &[PositionerJoints]) -> f64 {
        self.arm
            .iter()
            .filter_map(|a| joints.get(a.point).map(|q| a.violation(q)))
            .fold(0.0, f64::max)
    }

    /// Bounds the turn to the controller's stroke window `w` (rad,
    /// [`stroke_window`]).
    fn within_stroke(&mut self, w: (f64, f64)) {
        self.lower[1] = w.0;
        self.upper[1] = w.1;
        self.stroke_window = true;
    }

    fn world(&self, m: usize, q: &PositionerJoints) -> WorldPoint {
        let d = self.cell.positioner.positioner_from_table_derivatives(q);
        let f = |k: usize| {
            let (r, tr) = &d[k];
            (
                self.r0 * (r * self.m[m] + tr),
                self.r0 * (r * self.t[m]),
                self.r0 * (r * self.b[m]),
            )
        };
        let (p0, t0, b0) = f(0);
        let (p7, t7, b7) = f(1);
        let (p8, t8, b8) = f(2);
        WorldPoint {
            p: [p0, p7, p8],
            t: [t0, t7, t8],
            b: [b0, b7, b8],
        }
    }

    fn tilt(&self, m: usize, q: &PositionerJoints) -> f64 {
        let b = self.world(m, q).b[0];
        b.xy().norm().atan2(b.z)
    }
}

/// The laws' value and the linear model at `x = [c7; c8]` on samples `idx`.
struct Model {
    /// Residuals (the objective is `½|r|²`).
    r: Vec<f64>,
    /// Jacobian rows, dense `r.len() × 2K`.
    jac: Vec<Vec<f64>>,
    rows: Vec<Row>,
    /// Largest violation of a linearised row at `δ = 0` (its own units).
    violation: f64,
}

/// The previous sample: its index, world quantities and basis row.
type Previous = (usize, WorldPoint, Vec<(usize, f64)>);

/// The non-zero entries of a dense gradient, optionally negated.
fn sparse(g: &[f64], sign: f64) -> Vec<(usize, f64)> {
    g.iter()
        .enumerate()
        .filter(|(_, v)| **v != 0.0)
        .map(|(i, v)| (i, sign * v))
        .collect()
}

/// The law's residuals, Jacobian (where `jacobian`; else rows and
/// gradients are left empty) and linearised rows at coefficients `x` on
/// `basis`, over the samples `idx`.
// the axes' loops index several per-axis arrays together
#[allow(clippy::needless_range_loop)]
fn build_model(pb: &LawProblem, basis: &Basis, idx: &[usize], x: &[f64], jacobian: bool) -> Model {
    let k = basis.len();
    let (c7, c8) = x.split_at(k);
    let q7 = basis.eval(c7);
    let q8 = basis.eval(c8);
    let mut row = Vec::new();
    let mut r = Vec::new();
    let mut jac: Vec<Vec<f64>> = Vec::new();
    let mut rows = Vec::new();
    let mut violation: f64 = 0.0;
    let n_all = basis.points().max(1) as f64;
    let cone_target = pb.cos_cone;
    let mut push_row = |rows: &mut Vec<Row>, a: Vec<(usize, f64)>, b: f64| {
        violation = violation.max(-b);
        rows.push(Row { a, b });
    };
    let mut prev: Option<Previous> = None;
    for (si, &m) in idx.iter().enumerate() {
        let q = [q7[m], q8[m]];
        let w = pb.world(m, &q);
        basis.row(m, &mut row);
        let brow = row.clone();
        // d/dx of a quantity with d/dq7 = a7, d/dq8 = a8
        let grad = |a7: f64, a8: f64| {
            if !jacobian {
                return Vec::new();
            }
            let mut g = vec![0.0; 2 * k];
            for &(i, v) in &brow {
                g[i] += a7 * v;
                g[k + i] += a8 * v;
            }
            g
        };
        // samples' share of the layer's points
        let lo = if si == 0 { 0 } else { idx[si - 1] };
        let hi = idx.get(si + 1).copied().unwrap_or(basis.points() - 1);
        let share = ((hi - lo) as f64 * 0.5
            + if si == 0 || si + 1 == idx.len() {
                0.5
            } else {
                0.0
            })
        .max(0.5)
            / n_all;
        // tilt: λ·share·(b_x² + b_y²)
        let wt = (pb.opts.tilt_weight * share).sqrt();
        for c in 0..2 {
            r.push(wt * w.b[0][c]);
            jac.push(grad(wt * w.b[1][c], wt * w.b[2][c]));
        }
        // cone: b_z >= cos(cone)
        let gz = grad(w.b[1].z, w.b[2].z);
        push_row(&mut rows, sparse(&gz, -1.0), w.b[0].z - cone_target);
        // travel
        for a in 0..2 {
            let g = grad(
                if a == 0 { 1.0 } else { 0.0 },
                if a == 1 { 1.0 } else { 0.0 },
            );
            if pb.upper[a].is_finite() {
                push_row(&mut rows, sparse(&g, 1.0), pb.upper[a] - q[a]);
            }
            if pb.lower[a].is_finite() {
                push_row(&mut rows, sparse(&g, -1.0), q[a] - pb.lower[a]);
            }
        }
        // the arm's rows at this point: grad·(q + δ − q0) ≤ slack
        for a in pb.arm.iter().filter(|a| a.point == m) {
            let g = grad(a.grad[0], a.grad[1]);
            let at = a.grad[0] * (q[0] - a.q0[0]) + a.grad[1] * (q[1] - a.q0[1]);
            push_row(&mut rows, sparse(&g, 1.0), a.slack_rad - at);
        }
        if let Some((mp, wp, rowp)) = &prev {
            let gap = (m - mp) as f64;
            let dq = [q7[m] - q7[*mp], q8[m] - q8[*mp]];
            // d(Δ)/dx = row_m − row_prev
            let diff = |a7: f64, a8: f64, b7: f64, b8: f64| {
                let mut g = grad(a7, a8);
                for &(i, v) in rowp.iter().filter(|_| jacobian) {
                    g[i] -= b7 * v;
                    g[k + i] -= b8 * v;
                }
                g
            };
            let s = 1.0 / gap.sqrt();
            for a in 0..2 {
                let wa = pb.gamma[a].sqrt() * s;
                if wa > 0.0 {
                    r.push(wa * dq[a]);
                    let (a7, a8) = if a == 0 { (1.0, 0.0) } else { (0.0, 1.0) };
                    jac.push(diff(wa * a7, wa * a8, wa * a7, wa * a8));
                }
            }
            let wp_ = pb.gamma_arm.sqrt() * s / pb.opts.arm_length_mm;
            let wtv = pb.gamma_arm.sqrt() * s;
            for c in 0..3 {
                r.push(wp_ * (w.p[0][c] - wp.p[0][c]));
                jac.push(diff(
                    wp_ * w.p[1][c],
                    wp_ * w.p[2][c],
                    wp_ * wp.p[1][c],
                    wp_ * wp.p[2][c],
                ));
                r.push(wtv * (w.t[0][c] - wp.t[0][c]));
                jac.push(diff(
                    wtv * w.t[1][c],
                    wtv * w.t[2][c],
                    wtv * wp.t[1][c],
                    wtv * wp.t[2][c],
                ));
            }
            // speeds over the samples' time
            let time: f64 = pb.dt[mp + 1..=m].iter().sum();
            for a in 0..2 {
                if pb.max_speed[a].is_finite() && time > 0.0 {
                    let cap = 0.98 * pb.max_speed[a] * time;
                    let (a7, a8) = if a == 0 { (1.0, 0.0) } else { (0.0, 1.0) };
                    let g = diff(a7, a8, a7, a8);
                    push_row(&mut rows, sparse(&g, 1.0), cap - dq[a]);
                    push_row(&mut rows, sparse(&g, -1.0), cap + dq[a]);
                }
            }
        }
        prev = Some((m, w, brow));
    }
    Model {
        r,
        jac,
        rows,
        violation,
    }
}

/// `½|r|²` of a law given per point (rad), over every point: the
/// objective the SQP minimises, without its derivatives.
fn objective(pb: &LawProblem, joints: &[PositionerJoints]) -> f64 {
    let n = joints.len();
    let x: Vec<f64> = joints
        .iter()
        .map(|q| q[0])
        .chain(joints.iter().map(|q| q[1]))
        .collect();
    let all: Vec<usize> = (0..n).collect();
    let model = build_model(pb, &Basis::PerPoint { points: n }, &all, &x, false);
    0.5 * model.r.iter().map(|v| v * v).sum::<f64>()
}

fn merit(model: &Model, rho: f64) -> f64 {
    0.5 * model.r.iter().map(|v| v * v).sum::<f64>() + rho * model.violation
}

/// Gauss–Newton SQP with a trust region on the coefficients (rad per unit
/// basis value); returns the coefficients, the iterations made and the
/// largest violation of a linearised row left on the samples.
fn sqp(pb: &LawProblem, basis: &Basis, idx: &[usize], x0: Vec<f64>) -> (Vec<f64>, usize, f64) {
    let n = x0.len();
    let rho = 1e2;
    let mut x = x0;
    let mut model = build_model(pb, basis, idx, &x, true);
    let mut cur = merit(&model, rho);
    let mut bound = 0.3 / basis.row_l1_bound();
    let mut iterations = 0;
    for _ in 0..pb.opts.max_iterations {
        iterations += 1;
        // P = JᵀJ (+ a small ridge), g = Jᵀr
        let mut p = vec![0.0; n * n];
        let mut g = vec![0.0; n];
        for (ri, row) in model.r.iter().zip(&model.jac) {
            for i in 0..n {
                if row[i] == 0.0 {
                    continue;
                }
                g[i] += row[i] * ri;
                for j in 0..n {
                    p[i * n + j] += row[i] * row[j];
                }
            }
        }
        let trace: f64 = (0..n).map(|i| p[i * n + i]).sum::<f64>() / n as f64;
        for i in 0..n {
            p[i * n + i] += RIDGE_REL * trace.max(RIDGE_TRACE_FLOOR);
        }
        let Some(qp) = solve_qp(n, &p, &g, &model.rows, rho, bound) else {
            bound *= 0.25;
            if bound < MIN_TRUST_RAD {
                break;
            }
            continue;
        };
        let trial: Vec<f64> = x.iter().zip(&qp.x).map(|(a, d)| a + d).collect();
        let tm = build_model(pb, basis, idx, &trial, true);
        let new = merit(&tm, rho);
        let step = qp.x.iter().fold(0.0f64, |a, v| a.max(v.abs()));
        if new.is_finite() && new < cur - ACCEPT_GAIN_REL * cur.abs().max(MERIT_FLOOR) {
            let gain = cur - new;
            x = trial;
            model = tm;
            cur = new;
            if step > 0.9 * bound {
                bound *= 2.0;
            }
            // flat: a relative gain this small moves no axis by a
            // measurable amount (feasible or at the least violation)
            if gain < FLAT_GAIN_REL * cur.abs().max(MERIT_FLOOR) {
                break;
            }
        } else {
            bound *= 0.25;
            if bound < MIN_TRUST_RAD || step < MIN_STEP_RAD {
                break;
            }
        }
    }
    (x, iterations, model.violation)
}

/// Every point's positioner joints, checked: the worst violation (in its
/// own units scaled to radians) and its binding, the max tilt and where.
struct Check {
    binding: Option<(f64, PositionerBinding)>,
    max_tilt: (f64, usize),
    /// Points whose constraints are violated, worst first.
    worst: Vec<usize>,
}

fn check(pb: &LawProblem, q: &[PositionerJoints]) -> Check {
    let mut binding: Option<(f64, PositionerBinding)> = None;
    let mut max_tilt = (0.0, 0);
    let mut bad: Vec<(f64, usize)> = Vec::new();
    let mut offer = |v: f64, b: PositionerBinding, m: usize, bad: &mut Vec<(f64, usize)>| {
        if v > 0.0 {
            bad.push((v, m));
            if binding.is_none_or(|(w, _)| v > w) {
                binding = Some((v, b));
            }
        }
    };
    for (m, qm) in q.iter().enumerate() {
        let tilt = pb.tilt(m, qm);
        if tilt > max_tilt.0 {
            max_tilt = (tilt, m);
        }
        offer(
            tilt - pb.cone,
            PositionerBinding::Cone {
                point: m,
                tilt_rad: tilt,
                max_rad: pb.cone,
            },
            m,
            &mut bad,
        );
        for a in 0..2 {
            let over = (pb.lower[a] - qm[a]).max(qm[a] - pb.upper[a]);
            let b = if a == 1 && pb.stroke_window {
                PositionerBinding::Stroke {
                    point: m,
                    value_rad: qm[a],
                    lower_rad: pb.lower[a],
                    upper_rad: pb.upper[a],
                }
            } else {
                PositionerBinding::Travel {
                    joint: 7 + a,
                    point: m,
                    value_rad: qm[a],
                }
            };
            offer(over, b, m, &mut bad);
            if m > 0 && pb.dt[m] > 0.0 && pb.max_speed[a].is_finite() {
                let speed = (qm[a] - q[m - 1][a]).abs() / pb.dt[m];
                offer(
                    (speed - pb.max_speed[a]) * pb.dt[m],
                    PositionerBinding::Speed {
                        joint: 7 + a,
                        point: m,
                        speed_rad_s: speed,
                        max_rad_s: pb.max_speed[a],
                    },
                    m,
                    &mut bad,
                );
            }
        }
    }
    bad.sort_by(|a, b| b.0.total_cmp(&a.0).then(a.1.cmp(&b.1)));
    let mut worst: Vec<usize> = Vec::new();
    for (_, m) in bad {
        if !worst.contains(&m) {
            worst.push(m);
        }
        if worst.len() >= 8 {
            break;
        }
    }
    Check {
        binding,
        max_tilt,
        worst,
    }
}

/// The thesis's positioner joints turning every point's `b` exactly
/// vertical, the turn continued from `q8_hint` (rad); `None` where a point
/// cannot be turned vertical.
pub fn vertical_joints(
    cell: &TorchCarriedCell,
    points: &[CellPoint],
    q8_hint: f64,
) -> Option<Vec<PositionerJoints>> {
    let mut hint = q8_hint;
    points
        .iter()
        .map(|p| {
            let cp = CellPoint {
                positioner: None,
                ..*p
            };
            let q = cell.positioner_angles(&cp, hint).ok()?;
            hint = q[1];
            Some(q)
        })
        .collect()
}

/// The lazy follower's joints: the positioner holds its pose while `b`
/// stays within `hold_rad` of the vertical, and otherwise moves just enough to
/// bring it back to `hold_rad`, leaning the way it leans (the pose turning
/// `b` onto that leaning direction, the turn nearest the last). Smooth
/// through the pole, where the exact vertical spins. `None` where no pose
/// is found.
fn lazy_joints(
    pb: &LawProblem,
    start: PositionerJoints,
    hold_rad: f64,
) -> Option<Vec<PositionerJoints>> {
    let r0t = pb.r0.transpose();
    let mut q = start;
    let mut out = Vec::with_capacity(pb.b.len());
    for m in 0..pb.b.len() {
        let b_w = pb.world(m, &q).b[0];
        let tilt = b_w.xy().norm().atan2(b_w.z);
        if tilt > hold_rad {
            // the world direction at hold_rad from the vertical, towards b_w
            let h = b_w.xy().normalize();
            let target = Vector3::new(h.x * hold_rad.sin(), h.y * hold_rad.sin(), hold_rad.cos());
            let up = UnitVector3::new_normalize(r0t * target);
            let b = UnitVector3::try_new(pb.b[m], tol::DEGENERATE)?;
            q = pb
                .cell
                .positioner
                .angles_for_vertical(&b, &up, q[1], 0.5 * hold_rad)
                .ok()?;
        }
        out.push(q);
    }
    Some(out)
}

/// The first point of a layer that no motion of the positioner reaches
/// with its build direction inside the cone, searched on a grid of poses of
/// `cell_rad` (rad) — a proof: `None` when some path may exist.
///
/// Reachable sets are propagated along the layer: the poses at point `m`
/// are those within `v_k·(t_m − t_a)` (each axis) of a pose reachable at an
/// anchor point `a ≤ m` that keep `b_m` within the cone. On the grid both
/// tests are relaxed so that no real path is lost: the angle of `b` from the
/// vertical moves by at most `|Δq7| + |Δq8|` when the axes move (a rotation
/// moves a direction by at most its angle, and the table's pose is two
/// rotations), so a cell is kept when its centre is within `cone + cell/2 +
/// cell/2` of the vertical; cells join when their centres are up to
/// `v·(t_m − t_a) + cell` apart per axis. The anchor moves on once the
/// slower bounded axis could have moved four cells, so that the cell of
/// slack added per anchor stays a quarter of the motion. The tilt
/// is searched within its travel, the turn modulo a whole turn (a superset
/// of any travel). An empty set at point `m` is then a proof for the layer,
/// up to nothing but rounding. `r0`: `base_from_positioner`'s rotation; `b`
/// in the table frame; `dt` the step times (s).
pub fn unreachable_point(
    positioner: &Positioner,
    r0: &Matrix3,
    b: &[Vector3],
    dt: &[f64],
    cone_rad: f64,
    cell_rad: f64,
) -> Option<usize> {
    let l7 = positioner.limits[0];
    let grid = PoseGrid::new(r0, l7.lower_rad, l7.upper_rad, cell_rad);
    let (n7, n8, h7, h8) = (grid.n7, grid.n8, grid.h7, grid.h8);
    let min_cos = (cone_rad + 0.5 * (h7 + h8)).min(std::f64::consts::PI).cos();
    // the set reachable at the anchor point, dilated by the motion since
    // (one cell of slack per anchor, re-anchored every 4 cells of motion of
    // the slower bounded axis, so that the slack stays a quarter at most)
    let mut anchor = vec![true; n7 * n8];
    let mut t_anchor = 0.0;
    let mut t = 0.0;
    let mut reach = vec![true; n7 * n8];
    // the anchor's reached tilt rows, first and last
    let mut band: (usize, usize) = (0, n7 - 1);
    let mut scratch = Dilation::new(&grid);
    let (v7, v8) = (positioner.max_speed_rad_s[0], positioner.max_speed_rad_s[1]);
    for (m, bm) in b.iter().enumerate() {
        if m > 0 {
            t += dt[m];
            let span = t - t_anchor;
            let cells = |v: f64, h: f64| -> usize {
                if v.is_finite() {
                    ((v * span + h) / h).floor() as usize
                } else {
                    usize::MAX
                }
            };
            scratch.dilate(
                &grid,
                &anchor,
                band,
                cells(v7, h7),
                cells(v8, h8),
                &mut reach,
            );
        }
        let Some(rows) = grid.keep_within(&mut reach, bm, min_cos) else {
            return Some(m);
        };
        let moved = |v: f64, h: f64| !v.is_finite() || v * (t - t_anchor) >= 4.0 * h;
        if m == 0 || (moved(v7, h7) && moved(v8, h8)) {
            anchor.copy_from_slice(&reach);
            band = rows;
            t_anchor = t;
        }
    }
    None
}

/// A grid of positioner poses: tilt rows of `h7` over the tilt's travel
/// (a whole turn where it is unlimited), turn columns of `h8` over a whole
/// turn (periodic: a superset of any travel), each cell stood for by its
/// centre. Cell `(i, j)` is index `i·n8 + j`.
struct PoseGrid {
    n7: usize,
    n8: usize,
    /// Tilt of row 0's lower edge (rad).
    lo7: f64,
    h7: f64,
    h8: f64,
    /// Per row, the world's up turned back by the row's tilt ([`tilted_back`]).
    tilted: Vec<Vector3>,
    /// Per column, the sine and cosine of its turn.
    turns: Vec<(f64, f64)>,
}

impl PoseGrid {
    /// Cells of at most `cell_rad` over the tilt travel `lo..hi` (rad);
    /// `r0`: `base_from_positioner`'s rotation.
    fn new(r0: &Matrix3, lo: f64, hi: f64, cell_rad: f64) -> Self {
        use std::f64::consts::{PI, TAU};
        let (lo7, hi7) = if lo.is_finite() && hi.is_finite() && hi > lo {
            (lo, hi)
        } else {
            (-PI, PI)
        };
        let n7 = (((hi7 - lo7) / cell_rad).ceil() as usize).max(1);
        let h7 = (hi7 - lo7) / n7 as f64;
        let n8 = ((TAU / cell_rad).ceil() as usize).max(1);
        let h8 = TAU / n8 as f64;
        // up in the positioner frame, turned back by each tilt: b_w·z = (Ry(−q7)·up)·(Rz(q8)·b)
        let up = r0.transpose() * Vector3::z();
        PoseGrid {
            n7,
            n8,
            lo7,
            h7,
            h8,
            tilted: (0..n7)
                .map(|i| {
                    let (s, c) = (lo7 + (i as f64 + 0.5) * h7).sin_cos();
                    tilted_back(&up, s, c)
                })
                .collect(),
            turns: (0..n8).map(|j| ((j as f64 + 0.5) * h8).sin_cos()).collect(),
        }
    }

    /// The joints at cell `(i, j)`'s centre (rad).
    fn pose(&self, i: usize, j: usize) -> PositionerJoints {
        [
            self.lo7 + (i as f64 + 0.5) * self.h7,
            (j as f64 + 0.5) * self.h8,
        ]
    }

    /// `b`'s cosine with the vertical at cell `(i, j)` (`b` table frame).
    fn up_cos(&self, b: &Vector3, i: usize, j: usize) -> f64 {
        let (s, c) = self.turns[j];
        self.tilted[i].dot(&turned(b, s, c))
    }

    /// Clears the cells of `set` where `b` is further than `min_cos` from
    /// the vertical; the first and last rows left, `None` when none is.
    fn keep_within(&self, set: &mut [bool], b: &Vector3, min_cos: f64) -> Option<(usize, usize)> {
        let n8 = self.n8;
        let mut rows = None;
        for (i, tilted) in self.tilted.iter().enumerate() {
            let row = &mut set[i * n8..(i + 1) * n8];
            if !row.contains(&true) {
                continue;
            }
            let mut any = false;
            for (cell, (s, c)) in row.iter_mut().zip(&self.turns) {
                if *cell {
                    *cell = tilted.dot(&turned(b, *s, *c)) >= min_cos;
                    any |= *cell;
                }
            }
            if any {
                rows = Some(rows.map_or((i, i), |(lo, _): (usize, usize)| (lo, i)));
            }
        }
        rows
    }
}

/// Scratch of [`Dilation::dilate`].
struct Dilation {
    /// The source dilated along the turn.
    next: Vec<bool>,
    /// Prefix counts along a row.
    count: Vec<usize>,
    /// Set cells per column within the tilt's window.
    columns: Vec<u32>,
}

impl Dilation {
    fn new(grid: &PoseGrid) -> Self {
        Dilation {
            next: vec![false; grid.n7 * grid.n8],
            count: Vec::with_capacity(3 * grid.n8 + 1),
            columns: Vec::with_capacity(grid.n8),
        }
    }

    /// `out` ← the cells within `d7` rows and `d8` columns (the turn
    /// periodic) of a set cell of `src`, whose set cells lie in the rows
    /// `band` (first, last): the turn's window by prefix counts along each
    /// row, then the tilt's by running counts per column, row after row.
    fn dilate(
        &mut self,
        grid: &PoseGrid,
        src: &[bool],
        band: (usize, usize),
        d7: usize,
        d8: usize,
        out: &mut [bool],
    ) {
        let (n7, n8) = (grid.n7, grid.n8);
        let (next, count, columns) = (&mut self.next, &mut self.count, &mut self.columns);
        let (lo, hi) = band;
        let (out_lo, out_hi) = (lo.saturating_sub(d7), hi.saturating_add(d7).min(n7 - 1));
        out[..out_lo * n8].fill(false);
        out[(out_hi + 1) * n8..].fill(false);
        for i in lo..=hi {
            let row = &src[i * n8..(i + 1) * n8];
            let dilated = &mut next[i * n8..(i + 1) * n8];
            if !row.contains(&true) || d8 >= n8 / 2 {
                let any = row.contains(&true);
                dilated.fill(any);
                continue;
            }
            count.clear();
            count.push(0);
            for k in 0..3 * n8 {
                let c = count[k] + usize::from(row[k % n8]);
                count.push(c);
            }
            for (j, cell) in dilated.iter_mut().enumerate() {
                // cells j − d8 ..= j + d8, shifted by one turn
                let (a, z) = (j + n8 - d8, j + n8 + d8 + 1);
                *cell = count[z] > count[a];
            }
        }
        // rows max(i − d7, lo) ..= min(i + d7, hi) counted per column: never
        // empty, as out_lo ..= out_hi is the band widened by d7
        columns.clear();
        columns.resize(n8, 0);
        let (mut entered, mut left) = (lo, lo);
        for i in out_lo..=out_hi {
            let last = i.saturating_add(d7).min(hi);
            while entered <= last {
                let row = &next[entered * n8..(entered + 1) * n8];
                for (c, x) in columns.iter_mut().zip(row) {
                    *c += u32::from(*x);
                }
                entered += 1;
            }
            let first = i.saturating_sub(d7).max(lo);
            while left < first {
                let row = &next[left * n8..(left + 1) * n8];
                for (c, x) in columns.iter_mut().zip(row) {
                    *c -= u32::from(*x);
                }
                left += 1;
            }
            for (o, c) in out[i * n8..(i + 1) * n8].iter_mut().zip(columns.iter()) {
                *o = *c > 0;
            }
        }
    }
}

/// The world's up in the table frame's tilt-turned coordinates of the
/// pose grids: `up` (the vertical in the positioner frame) turned back by a
/// tilt whose sine and cosine are `s`, `c` (`Ry(−q7)·up`). With [`turned`],
/// `b` is within the cone at `(q7, q8)` where their dot product is at least
/// the cone's cosine.
fn tilted_back(up: &Vector3, s: f64, c: f64) -> Vector3 {
    Vector3::new(c * up.x - s * up.z, up.y, s * up.x + c * up.z)
}

/// `b` (table frame) turned by a turn whose sine and cosine are `s`, `c`
/// (`Rz(q8)·b`).
fn turned(b: &Vector3, s: f64, c: f64) -> Vector3 {
    Vector3::new(c * b.x - s * b.y, s * b.x + c * b.y, b.z)
}

/// Cells of motion the slower axis makes in one of a layer's short steps
/// (its tenth shortest percentile) on [`grid_path`]'s grid: the rounding of
/// each step's motion to whole cells is then a small share of it.
const GRID_PATH_STEP_CELLS: f64 = 8.0;

/// Bounds of [`grid_path`]'s cell (deg).
const GRID_PATH_CELL_DEG: (f64, f64) = (0.25, 2.0);

/// Most cells [`grid_path`] keeps in memory, over all points (one bit
/// each, 50 MB): the cell grows past [`GRID_PATH_CELL_DEG`]'s lower bound
/// to stay under it.
const GRID_PATH_MAX_CELLS: f64 = 4e8;

/// Shares of the cone [`grid_path`] tries to keep `b` within, in order
/// (unitless): first the whole cone (where no path keeps it, none is
/// looked for further), then with room for the law's fit, the largest
/// room first.
const GRID_PATH_CONE_SHARES: [f64; 3] = [1.0, 0.8, 0.9];

/// A path of positioner joints (rad, one per point of the layer, on the
/// centres of a grid of poses) that keeps `b` within the cone at every
/// point and moves each axis within its speed between them, found by
/// propagating the poses reachable from point to point and following them
/// back from the last point, each step the least range-weighted move (the
/// path holds still where it can), then relaxed ([`relax`]). The grid's
/// cell is set by the layer's short steps ([`GRID_PATH_STEP_CELLS`]); each
/// axis moves at each step the whole cells its speed allows (an inner
/// approximation: the path between cell centres keeps every speed). The
/// cone is tried whole, then with room ([`GRID_PATH_CONE_SHARES`]). `None`
/// where the grid holds no path. A start for the law
/// ([`PositionerSeed::Grid`]), fitted and solved; where no fit keeps the
/// constraints, the path itself is a law (it keeps them at every point).
fn grid_path(pb: &LawProblem) -> Option<Vec<PositionerJoints>> {
    let n = pb.b.len();
    if n == 0 {
        return None;
    }
    let (v7, v8) = (pb.max_speed[0], pb.max_speed[1]);
    let mut steps: Vec<f64> = pb.dt.iter().skip(1).copied().filter(|d| *d > 0.0).collect();
    steps.sort_by(f64::total_cmp);
    let short = steps.get(steps.len() / 10).copied().unwrap_or(0.0);
    let slow = v7.min(v8) * short;
    let (min_cell, max_cell) = (
        GRID_PATH_CELL_DEG.0.to_radians(),
        GRID_PATH_CELL_DEG.1.to_radians(),
    );
    let mut cell = if slow.is_finite() && slow > 0.0 {
        (slow / GRID_PATH_STEP_CELLS).clamp(min_cell, max_cell)
    } else {
        max_cell
    };
    let tilt_range = if pb.lower[0].is_finite() && pb.upper[0].is_finite() {
        (pb.upper[0] - pb.lower[0]).max(0.0)
    } else {
        std::f64::consts::TAU
    };
    if !(tilt_range > 0.0) {
        return None;
    }
    // the cells of every point within memory
    let area = tilt_range * std::f64::consts::TAU * n as f64;
    cell = cell.max((area / GRID_PATH_MAX_CELLS).sqrt());
    let grid = PoseGrid::new(&pb.r0, pb.lower[0], pb.upper[0], cell);
    // each axis's whole cells of motion within its speed at each step
    let moves: Vec<(usize, usize)> = pb
        .dt
        .iter()
        .map(|dt| {
            let step = |v: f64, h: f64, cap: usize| -> usize {
                if v.is_finite() {
                    ((v * dt / h).floor() as usize).min(cap)
                } else {
                    cap
                }
            };
            (step(v7, grid.h7, grid.n7), step(v8, grid.h8, grid.n8))
        })
        .collect();
    let reach = |share: f64| -> Option<Vec<Packed>> {
        let min_cos = (share * pb.cone).cos();
        let mut sets: Vec<Packed> = Vec::with_capacity(n);
        let mut set = vec![true; grid.n7 * grid.n8];
        let mut prev = vec![false; grid.n7 * grid.n8];
        let mut band = (0, grid.n7 - 1);
        let mut scratch = Dilation::new(&grid);
        for (m, b) in pb.b.iter().enumerate() {
            if m > 0 {
                std::mem::swap(&mut set, &mut prev);
                let (d7, d8) = moves[m];
                scratch.dilate(&grid, &prev, band, d7, d8, &mut set);
            }
            band = grid.keep_within(&mut set, b, min_cos)?;
            sets.push(Packed::of(&set, band, grid.n8));
        }
        Some(sets)
    };
    let mut sets = reach(GRID_PATH_CONE_SHARES[0])?;
    let mut share = GRID_PATH_CONE_SHARES[0];
    for s in &GRID_PATH_CONE_SHARES[1..] {
        if let Some(r) = reach(*s) {
            (sets, share) = (r, *s);
            break;
        }
    }
    // back from the last point: its cell nearest the vertical, then at each
    // point the reachable cell the least weighted move away
    let n8 = grid.n8;
    let weight = |g: f64| {
        if g > 0.0 {
            g
        } else {
            1.0 / std::f64::consts::TAU
        }
    };
    let (w7, w8) = (weight(pb.gamma[0]) * grid.h7, weight(pb.gamma[1]) * grid.h8);
    let last = (0..grid.n7 * n8)
        .filter(|&k| sets[n - 1].has(k))
        .max_by(|&a, &b| {
            let up = |k: usize| grid.up_cos(&pb.b[n - 1], k / n8, k % n8);
            up(a).total_cmp(&up(b))
        })?;
    let mut cells = vec![(last / n8, last % n8); n];
    for m in (1..n).rev() {
        let (i, j) = cells[m];
        let (d7, d8) = moves[m];
        let d8 = d8.min(n8 / 2);
        let mut best = (f64::INFINITY, (i, j));
        for ii in i.saturating_sub(d7)..=(i + d7).min(grid.n7 - 1) {
            for dj in -(d8 as isize)..=d8 as isize {
                let jj = (j as isize + dj).rem_euclid(n8 as isize) as usize;
                if sets[m - 1].has(ii * n8 + jj) {
                    let cost = w7 * ii.abs_diff(i) as f64 + w8 * dj.unsigned_abs() as f64;
                    if cost < best.0 {
                        best = (cost, (ii, jj));
                    }
                }
            }
        }
        // the sets are the reachable ones: a predecessor always exists
        cells[m - 1] = best.1;
    }
    // the turn unwrapped along the path
    let mut joints: Vec<PositionerJoints> = Vec::with_capacity(n);
    for &(i, j) in &cells {
        let mut q = grid.pose(i, j);
        if let Some(prev) = joints.last() {
            q[1] += ((prev[1] - q[1]) / std::f64::consts::TAU).round() * std::f64::consts::TAU;
        }
        joints.push(q);
    }
    relax(pb, &mut joints, share * pb.cone);
    Some(joints)
}

/// A set of a [`PoseGrid`]'s cells, one bit each, over the rows it holds.
struct Packed {
    /// First cell of the first row held.
    from: usize,
    /// One past the last row's last cell.
    to: usize,
    bits: Vec<u64>,
}

impl Packed {
    /// The cells of `set` in rows `band` (first, last) of `n8` cells.
    fn of(set: &[bool], band: (usize, usize), n8: usize) -> Self {
        let (from, to) = (band.0 * n8, (band.1 + 1) * n8);
        let mut bits = vec![0u64; (to - from).div_ceil(64)];
        for (k, _) in set[from..to].iter().enumerate().filter(|(_, x)| **x) {
            bits[k / 64] |= 1 << (k % 64);
        }
        Packed { from, to, bits }
    }

    /// Whether cell `k` is in the set.
    fn has(&self, k: usize) -> bool {
        k >= self.from && k < self.to && {
            let k = k - self.from;
            self.bits[k / 64] & (1 << (k % 64)) != 0
        }
    }
}

/// Whether the rate bound ([`required_rotation_rate`]) or the coarsest
/// two grids of [`GRID_CELLS_DEG`] prove that no positioner path keeps the
/// layer's `b` within the cone: then [`grid_path`], whose grid is finer
/// and whose approximation is inner, finds none either, and is not run.
fn cheaply_proven(pb: &LawProblem) -> bool {
    let available = pb.max_speed[0] + pb.max_speed[1];
    required_rotation_rate(&pb.b, &pb.dt, pb.cone).0 > available
        || pb.unreachable_on(&GRID_CELLS_DEG[..2]).is_some()
}

/// Sweeps of [`relax`].
const RELAX_SWEEPS: usize = 200;

/// Smooths a path of positioner joints (rad per point) that keeps `b`
/// within `cone_rad` and each axis within its travel and speed, keeping
/// all three: each sweep moves every point towards the middle of its
/// neighbours (the whole way, else half, else a quarter) where the move
/// keeps them. A lazy grid path holds still, then moves at full speed; the
/// relaxed one spreads its motion.
fn relax(pb: &LawProblem, q: &mut [PositionerJoints], cone_rad: f64) {
    let n = q.len();
    if n < 3 {
        return;
    }
    let within = |m: usize, p: &PositionerJoints, q: &[PositionerJoints]| -> bool {
        if pb.tilt(m, p) > cone_rad {
            return false;
        }
        (0..2).all(|a| {
            let speed_ok = |k: usize, x: f64, y: f64| {
                !pb.max_speed[a].is_finite() || (y - x).abs() <= pb.max_speed[a] * pb.dt[k]
            };
            p[a] >= pb.lower[a]
                && p[a] <= pb.upper[a]
                && (m == 0 || speed_ok(m, q[m - 1][a], p[a]))
                && (m + 1 == n || speed_ok(m + 1, p[a], q[m + 1][a]))
        })
    };
    for _ in 0..RELAX_SWEEPS {
        let mut moved = false;
        for m in 0..n {
            let target: PositionerJoints = match m {
                0 => q[1],
                _ if m + 1 == n => q[m - 1],
                _ => std::array::from_fn(|a| 0.5 * (q[m - 1][a] + q[m + 1][a])),
            };
            for f in [1.0, 0.5, 0.25] {
                let p: PositionerJoints =
                    std::array::from_fn(|a| q[m][a] + f * (target[a] - q[m][a]));
                if within(m, &p, q) {
                    moved |= p != q[m];
                    q[m] = p;
                    break;
                }
            }
        }
        if !moved {
            break;
        }
    }
}

/// The grids of positioner poses [`unreachable_point`] searches, coarse to
/// fine (deg): each is tried where the coarser one proved nothing. The
/// 0.5° grid costs about 0.3 s a 400-point layer (16 times the coarsest),
/// the 0.25° grid about 4 times that; they run only on a layer whose law
/// failed and that no coarser grid proved.
const GRID_CELLS_DEG: [f64; 4] = [2.0, 1.0, 0.5, 0.25];

/// Share of the spline's abscissa given to the turning of `b` (unitless):
/// the knots, uniform in the blended abscissa, crowd where `b` turns fast.
const TURNING_SHARE: f64 = 0.5;

/// The spline's abscissa: `x` (point index or cylindrical angle) scaled to
/// `[0, 1]`, blended with the cumulative angle `b` turns through along the
/// layer, also scaled to `[0, 1]` ([`TURNING_SHARE`] of it). A bent tube's
/// layer turns `b` through most of its swing in a few points (a corner of the
/// constant-distance layer); uniform knots in the point index leave those few
/// points one span, too stiff for the table to follow `b` there. On a part
/// of revolution `b` turns evenly with the angle and nothing changes.
fn following_turning(x: &[f64], b: &[Vector3]) -> Vec<f64> {
    let n = x.len();
    let span = x[n - 1] - x[0];
    let mut turned = Vec::with_capacity(n);
    let mut sum = 0.0;
    for m in 0..n {
        if m > 0 {
            sum += b[m - 1].angle(&b[m]);
        }
        turned.push(sum);
    }
    if !(span.abs() > 0.0 && sum > tol::DEGENERATE) {
        return x.to_vec();
    }
    (0..n)
        .map(|m| (1.0 - TURNING_SHARE) * (x[m] - x[0]) / span + TURNING_SHARE * turned[m] / sum)
        .collect()
}

/// Positioner laws of one layer [module doc]. `travel_speed_mm_s`: the
/// programmed speed of the torch over the part (mm/s); `margin_rad`: how far
/// inside its travel each axis stays (rad); `q8_hint`: the turn the layer
/// should start near (rad; the previous layer's last).
pub fn positioner_law(
    cell: &TorchCarriedCell,
    points: &[CellPoint],
    travel_speed_mm_s: f64,
    margin_rad: f64,
    q8_hint: f64,
    opts: &PositionerOptions,
) -> PositionerLaw {
    solve_law(
        cell,
        points,
        travel_speed_mm_s,
        margin_rad,
        q8_hint,
        opts,
        &[],
        None,
    )
}

/// [`positioner_law`] under the arm's linearised constraints `arm`, with
/// `start` (the law the arm could not follow, rad per point) as one more
/// start ([`PositionerSeed::Arm`]). Of the laws that keep cone, travel and
/// speeds, the one that breaks the arm's rows least is kept, then the
/// lowest objective.
#[allow(clippy::too_many_arguments)]
pub fn positioner_law_for_arm(
    cell: &TorchCarriedCell,
    points: &[CellPoint],
    travel_speed_mm_s: f64,
    margin_rad: f64,
    opts: &PositionerOptions,
    arm: &[ArmRow],
    start: &[PositionerJoints],
) -> PositionerLaw {
    let hint = start.first().map_or(0.0, |q| q[1]);
    solve_law(
        cell,
        points,
        travel_speed_mm_s,
        margin_rad,
        hint,
        opts,
        arm,
        (start.len() == points.len()).then_some(start),
    )
}

#[allow(clippy::too_many_arguments)]
fn solve_law(
    cell: &TorchCarriedCell,
    points: &[CellPoint],
    travel_speed_mm_s: f64,
    margin_rad: f64,
    q8_hint: f64,
    opts: &PositionerOptions,
    arm: &[ArmRow],
    start: Option<&[PositionerJoints]>,
) -> PositionerLaw {
    let mut pb = LawProblem::new(cell, points, travel_speed_mm_s, margin_rad, opts, arm);
    let n = points.len();
    let follow = vertical_joints(cell, points, q8_hint);
    if opts.mode == PositionerMode::Vertical {
        let joints = follow.unwrap_or_else(|| vec![[0.0, q8_hint]; n]);
        if let Some(w) = stroke_window(cell, &joints, margin_rad) {
            pb.within_stroke(w);
        }
        let rate = required_rotation_rate(&pb.b, &pb.dt, pb.cone);
        return finish(&pb, rate, joints, PositionerSeed::Vertical, 0, n, 0.0);
    }
    let positions: Vec<Point3> = points.iter().map(|p| p.position_mm).collect();
    let theta = cylindrical_angles(&positions);
    let abscissa: Vec<f64> = if turns_about_z(&theta) {
        theta
    } else {
        (0..n).map(|m| m as f64).collect()
    };
    // the exact vertical as a law only where its bead fits the stroke
    let vertical = follow
        .as_deref()
        .filter(|f| stroke_window(cell, f, margin_rad).is_none());
    let mut iterations = 0;
    let (mut best, mut others) = solve_bases(
        &pb,
        &abscissa,
        follow.as_deref(),
        vertical,
        start,
        q8_hint,
        &mut iterations,
    );
    // the program shifts each bead by whole turns into the controller's
    // stroke: a law that turns the table through more is solved again
    // within the stroke, shifted to its middle (near the pole the turn is
    // nearly free and the unbounded law may wind it)
    if let Some(w) = stroke_window(cell, &best.joints, margin_rad) {
        pb.within_stroke(w);
        (best, others) = solve_bases(
            &pb,
            &abscissa,
            follow.as_deref(),
            vertical,
            start,
            q8_hint,
            &mut iterations,
        );
    }
    // the layer's geometry, the same for every law
    let rate = required_rotation_rate(&pb.b, &pb.dt, pb.cone);
    let mut law = finish(
        &pb,
        rate,
        best.joints,
        best.seed,
        iterations,
        best.samples,
        best.objective,
    );
    law.alternatives = others
        .into_iter()
        .map(|s| finish(&pb, rate, s.joints, s.seed, 0, s.samples, s.objective))
        .collect();
    law
}

/// The window of the controller's stroke a law's turn must stay in (rad),
/// where `joints` turn the table through more than the stroke holds modulo
/// whole turns: [`TorchCarriedCell::turn_stroke`] less `margin_rad`, shifted
/// by whole turns to be centred nearest the law's middle. `None` when the
/// law fits, when the turn's travel bounds it already, or when the
/// controller writes an endless turn modulo 360° (no stroke).
fn stroke_window(
    cell: &TorchCarriedCell,
    joints: &[PositionerJoints],
    margin_rad: f64,
) -> Option<(f64, f64)> {
    use crate::robot::JointLimit;
    let travel = cell.positioner.limits[1];
    if travel.lower_rad.is_finite() || travel.upper_rad.is_finite() {
        return None;
    }
    let stroke = cell.turn_stroke();
    if stroke.is_unlimited() {
        return None;
    }
    let inner = JointLimit {
        lower_rad: stroke.lower_rad + margin_rad,
        upper_rad: stroke.upper_rad - margin_rad,
    };
    let (lo, hi) = joints
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), q| {
            (l.min(q[1]), h.max(q[1]))
        });
    if !(lo <= hi) || inner.whole_turn_shifts(lo, hi).is_some() {
        return None;
    }
    let k = ((0.5 * (lo + hi) - inner.mid_rad()) / std::f64::consts::TAU).round();
    let shift = k * std::f64::consts::TAU;
    Some((inner.lower_rad + shift, inner.upper_rad + shift))
}

/// The law of a layer's starts ([`solve_seeds`]): on knots uniform in
/// `abscissa` first; where that law fails, on knots crowding where `b`
/// turns ([`following_turning`]), the better kept; where neither keeps the
/// cone (a corner of `b`), the thesis's exact vertical `vertical` when it
/// breaks no constraint (an unlimited positioner), so that the arm is judged
/// on it. Returns the best law and the other feasible ones, best first
/// (the exact vertical first when it is not the best).
#[allow(clippy::too_many_arguments)]
fn solve_bases(
    pb: &LawProblem,
    abscissa: &[f64],
    follow: Option<&[PositionerJoints]>,
    vertical: Option<&[PositionerJoints]>,
    start: Option<&[PositionerJoints]>,
    q8_hint: f64,
    iterations: &mut usize,
) -> (Solved, Vec<Solved>) {
    let n = pb.b.len();
    let spans = pb.opts.spans.min(n / 4).max(1);
    let mut all = solve_seeds(
        pb,
        &Basis::spline(abscissa, spans),
        follow,
        start,
        q8_hint,
        iterations,
    );
    if !all.iter().any(|s| s.feasible) {
        all.extend(solve_seeds(
            pb,
            &Basis::spline(&following_turning(abscissa, &pb.b), spans),
            follow,
            start,
            q8_hint,
            iterations,
        ));
    }
    // a layer whose b passes the pole and swings far off it, or turns a
    // corner: the smooth starts may all fall into a local minimum; a path
    // over a grid of poses, fitted, on either knot set, else the path
    // itself where it keeps every constraint; not where the cheap proofs
    // already show no path exists
    if !all.iter().any(|s| s.feasible) && !cheaply_proven(pb) {
        if let Some(path) = grid_path(pb) {
            for basis in [
                Basis::spline(abscissa, spans),
                Basis::spline(&following_turning(abscissa, &pb.b), spans),
            ] {
                let x0 = fitted_on(&basis, &path);
                let solved = solve_starts(pb, &basis, vec![(PositionerSeed::Grid, x0)], iterations);
                let feasible = solved.iter().any(|s| s.feasible);
                all.extend(solved);
                if feasible {
                    break;
                }
            }
            if !all.iter().any(|s| s.feasible) && check(pb, &path).binding.is_none() {
                all.push(Solved::unfitted(pb, path, PositionerSeed::Grid));
            }
        }
    }
    // the thesis's exact vertical, unfitted, where it breaks no constraint
    // (an unlimited positioner): the law where no smooth one keeps the cone
    // (a corner of b), else the first alternative (the arm may follow it
    // where it cannot follow the smooth laws)
    let mut vertical = vertical
        .filter(|f| check(pb, f).binding.is_none())
        .map(|f| Solved::unfitted(pb, f.to_vec(), PositionerSeed::Vertical));
    if !all.iter().any(|s| s.feasible) {
        all.extend(vertical.take());
    }
    let mut best = 0;
    for (i, s) in all.iter().enumerate() {
        if s.better_than(&all[best]) {
            best = i;
        }
    }
    let best = all.swap_remove(best);
    // the other feasible laws, best first, each once
    all.retain(|s| s.feasible);
    all.sort_by(|a, b| a.objective.total_cmp(&b.objective));
    let mut others: Vec<Solved> = Vec::new();
    for s in all {
        let same = |o: &Solved| {
            o.joints.iter().zip(&s.joints).all(|(a, b)| {
                (a[0] - b[0]).abs() <= SAME_LAW_RAD && (a[1] - b[1]).abs() <= SAME_LAW_RAD
            })
        };
        if !same(&best) && !others.iter().any(same) {
            others.push(s);
        }
    }
    if let Some(v) = vertical {
        others.insert(0, v);
    }
    (best, others)
}

/// One start's law on one basis.
struct Solved {
    feasible: bool,
    /// The worst violation left (constraint units scaled to rad; 0 feasible).
    violation: f64,
    /// The worst violation of the arm's rows (rad; 0 without rows).
    arm: f64,
    /// `½|r|²` over every point.
    objective: f64,
    seed: PositionerSeed,
    joints: Vec<PositionerJoints>,
    samples: usize,
}

impl Solved {
    /// A law given per point, unfitted, that keeps every constraint.
    fn unfitted(pb: &LawProblem, joints: Vec<PositionerJoints>, seed: PositionerSeed) -> Self {
        Solved {
            feasible: true,
            violation: 0.0,
            arm: pb.arm_violation(&joints),
            objective: objective(pb, &joints),
            seed,
            samples: joints.len(),
            joints,
        }
    }

    /// Feasible beats infeasible; then the one that breaks the arm's rows
    /// less, then the lower objective; or the lower violation.
    fn better_than(&self, other: &Solved) -> bool {
        match (self.feasible, other.feasible) {
            (true, false) => true,
            (false, true) => false,
            (true, true) if (self.arm - other.arm).abs() > ARM_TIE_RAD => self.arm < other.arm,
            (true, true) => self.objective < other.objective,
            (false, false) => self.violation < other.violation,
        }
    }
}

/// The starts of [`positioner_law`] (the exact vertical `follow` fitted,
/// the lazy follower fitted, the hold pose) solved on `basis`, each on
/// samples grown with its worst points; every start's law returned (the
/// hold pose always), in the order solved. `iterations` counts the SQP
/// iterations.
fn solve_seeds(
    pb: &LawProblem,
    basis: &Basis,
    follow: Option<&[PositionerJoints]>,
    arm_start: Option<&[PositionerJoints]>,
    q8_hint: f64,
    iterations: &mut usize,
) -> Vec<Solved> {
    // the hold seed: the pose turning the mean b vertical
    let mean_b = pb.b.iter().fold(Vector3::zeros(), |a, b| a + b);
    let hold = UnitVector3::try_new(mean_b, MIN_BUILD_SUM)
        .and_then(|b| {
            let up = pb.cell.base_from_positioner.rotation.inverse() * Vector3::z_axis();
            pb.cell
                .positioner
                .angles_for_vertical(&b, &up, q8_hint, std::f64::consts::PI)
                .ok()
        })
        .unwrap_or([0.0, q8_hint]);
    let k = basis.len();
    let fitted = |q: &[PositionerJoints]| fitted_on(basis, q);
    let mut seeds: Vec<(PositionerSeed, Vec<f64>)> = Vec::new();
    let mut x_hold = vec![0.0; 2 * k];
    x_hold[0] = hold[0];
    x_hold[k] = hold[1];
    seeds.push((PositionerSeed::Hold, x_hold));
    let start = follow.and_then(|f| f.first().copied()).unwrap_or(hold);
    if let Some(l) = lazy_joints(pb, start, 0.7 * pb.cone) {
        seeds.push((PositionerSeed::Lazy, fitted(&l)));
    }
    if let Some(f) = follow {
        seeds.push((PositionerSeed::Follow, fitted(f)));
    }
    // the thesis's follower first: on a part of revolution it is exact and
    // costs nothing, and no other seed can do better than nothing
    seeds.reverse();
    if let Some(s) = arm_start {
        seeds.insert(0, (PositionerSeed::Arm, fitted(s)));
    }
    solve_starts(pb, basis, seeds, iterations)
}

/// Joints `q` (rad per point) fitted on `basis`: `[c7; c8]`.
fn fitted_on(basis: &Basis, q: &[PositionerJoints]) -> Vec<f64> {
    let c7 = basis.fit(&q.iter().map(|q| q[0]).collect::<Vec<_>>());
    let c8 = basis.fit(&q.iter().map(|q| q[1]).collect::<Vec<_>>());
    [c7, c8].concat()
}

/// Each start `seeds` (coefficients on `basis`) solved on samples grown
/// with its worst points, in order, until one keeps every constraint at no
/// cost.
fn solve_starts(
    pb: &LawProblem,
    basis: &Basis,
    seeds: Vec<(PositionerSeed, Vec<f64>)>,
    iterations: &mut usize,
) -> Vec<Solved> {
    let n = pb.b.len();
    let k = basis.len();
    let mut solved_all: Vec<Solved> = Vec::new();
    let target = pb.opts.sample_points.min(n);
    for (seed, x0) in seeds {
        if solved_all
            .iter()
            .any(|b| b.feasible && b.objective <= ZERO_OBJECTIVE)
        {
            break;
        }
        let mut idx: Vec<usize> = (0..target)
            .map(|i| {
                if target <= 1 {
                    0
                } else {
                    (i * (n - 1) + (target - 1) / 2) / (target - 1)
                }
            })
            .collect();
        // the arm's rows' points are always sampled
        idx.extend(pb.arm.iter().map(|a| a.point).filter(|&m| m < n));
        idx.sort_unstable();
        idx.dedup();
        let mut x = x0;
        let mut joints = Vec::new();
        let mut chk = None;
        for _round in 0..4 {
            let (xs, it, left) = sqp(pb, basis, &idx, x);
            *iterations += it;
            x = xs;
            // violated on the samples already: more samples cannot help
            let stuck = left > STUCK_VIOLATION;
            let (c7, c8) = x.split_at(k);
            let (q7, q8) = (basis.eval(c7), basis.eval(c8));
            joints = q7.into_iter().zip(q8).map(|(a, b)| [a, b]).collect();
            let c = check(pb, &joints);
            let done = stuck
                || c.binding.is_none()
                || c.worst.iter().all(|m| idx.binary_search(m).is_ok());
            let add = c.worst.clone();
            chk = Some(c);
            if done {
                break;
            }
            for m in add {
                if let Err(pos) = idx.binary_search(&m) {
                    idx.insert(pos, m);
                }
                if m > 0 {
                    if let Err(pos) = idx.binary_search(&(m - 1)) {
                        idx.insert(pos, m - 1);
                    }
                }
            }
        }
        let c = chk.expect("at least one round");
        let solved = Solved {
            feasible: c.binding.is_none(),
            violation: c.binding.map_or(0.0, |(v, _)| v),
            arm: pb.arm_violation(&joints),
            objective: objective(pb, &joints),
            seed,
            joints,
            samples: idx.len(),
        };
        solved_all.push(solved);
    }
    solved_all
}

/// The law of `joints` checked against every constraint, with the layer's
/// rate bound `(required, between)` ([`required_rotation_rate`], computed
/// once a layer) and, where the law fails, the grids' proof
/// ([`unreachable_point`]).
fn finish(
    pb: &LawProblem,
    (required, between): (f64, (usize, usize)),
    joints: Vec<PositionerJoints>,
    seed: PositionerSeed,
    iterations: usize,
    samples: usize,
    objective: f64,
) -> PositionerLaw {
    let c = check(pb, &joints);
    let available = pb.max_speed[0] + pb.max_speed[1];
    // a law that leaves the cone, or keeps it only faster than the axes
    // go, not proven by the rate: search every positioner path on a grid
    // (only where a speed is bounded: an unlimited positioner reaches any
    // pose at every point); not again under the arm's rows, searched when
    // the layer's law was first solved
    let failed = c.binding.is_some() && pb.arm.is_empty();
    let unreachable =
        if failed && required <= available && pb.max_speed.iter().any(|v| v.is_finite()) {
            // coarse first (cheap, proves the clear cases), then finer:
            // the relaxation's slack is a cell, so a finer grid proves a
            // layer that misses the cone by less
            pb.unreachable_on(&GRID_CELLS_DEG)
        } else {
            None
        };
    PositionerLaw {
        required_rate_rad_s: required,
        available_rate_rad_s: available,
        proven_infeasible: required > available || unreachable.is_some(),
        unreachable_point: unreachable,
        required_between: between,
        alternatives: Vec::new(),
        max_tilt_rad: c.max_tilt.0,
        max_tilt_point: c.max_tilt.1,
        feasible: c.binding.is_none(),
        binding: c.binding.map(|(_, b)| b),
        joints,
        seed,
        iterations,
        samples,
        objective: 2.0 * objective,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::{Isometry3, Rotation3, Translation3, UnitQuaternion};

    /// The FK derivatives against central differences.
    #[test]
    fn positioner_derivatives_match_finite_differences() {
        let pos = Positioner::robowam_nominal();
        for q in [[0.3, -1.2], [-1.1, 2.5], [0.0, 0.0], [1.4, 0.7]] {
            let d = pos.positioner_from_table_derivatives(&q);
            let h = 1e-6;
            for a in 0..2 {
                let mut qp = q;
                let mut qm = q;
                qp[a] += h;
                qm[a] -= h;
                let fp = pos.positioner_from_table(&qp);
                let fm = pos.positioner_from_table(&qm);
                let dr = (fp.rotation.to_rotation_matrix().matrix()
                    - fm.rotation.to_rotation_matrix().matrix())
                    / (2.0 * h);
                let dt = (fp.translation.vector - fm.translation.vector) / (2.0 * h);
                assert!((dr - d[a + 1].0).amax() < 1e-8, "q {q:?} axis {a}");
                assert!((dt - d[a + 1].1).amax() < 1e-6, "q {q:?} axis {a}");
            }
            let f = pos.positioner_from_table(&q);
            assert!((f.rotation.to_rotation_matrix().matrix() - d[0].0).amax() < 1e-12);
        }
    }

    /// The bound against its closed form: `b` turning at a constant
    /// `ω` per mm along a straight layer needs `TS·(ω − 2·cone/S)` over the
    /// whole length `S` (the longest stretch binds when `ω·S > 2·cone`); a
    /// corner (a turn over no length) needs an infinite rate.
    #[test]
    fn the_geometric_rate_bound_matches_its_closed_form() {
        let (omega, step, n, ts) = (2f64.to_radians(), 0.5, 100, 6.0);
        let b: Vec<Vector3> = (0..n)
            .map(|m| {
                let a = omega * step * m as f64;
                Vector3::new(0.0, a.sin(), a.cos())
            })
            .collect();
        let dt = vec![step / ts; n];
        let cone = 15f64.to_radians();
        let (rate, (i, j)) = required_rotation_rate(&b, &dt, cone);
        let s = step * (n - 1) as f64;
        let expected = ts * (omega - 2.0 * cone / s);
        assert!(
            (rate - expected).abs() < 1e-9 * expected,
            "{rate} vs {expected}"
        );
        assert_eq!((i, j), (0, n - 1));
        // within the cone everywhere: no rate needed
        let (rate, _) = required_rotation_rate(&b[..20], &dt[..20], cone);
        assert_eq!(rate, 0.0);
        // a corner: 40° between two points at the same place
        let mut corner = b[..10].to_vec();
        let last = corner[9];
        corner.push(Rotation3::from_axis_angle(&Vector3::x_axis(), 0.7) * last);
        let mut dt2 = dt[..11].to_vec();
        dt2[10] = 0.0;
        assert!(required_rotation_rate(&corner, &dt2, cone).0.is_infinite());
    }

    /// The bound's skipping (the early break, the cone's width, the blocks'
    /// bound) against every pair computed: the same rate and the same pair,
    /// on `b` round a cone of 10–80° about the vertical (a dome's layers)
    /// with a wobble, at uneven steps.
    #[test]
    fn the_rate_bound_skips_no_pair_that_binds() {
        let cone = 15f64.to_radians();
        for half_angle in [10.0, 25.0, 40.0, 55.0, 80.0] {
            let n = 300;
            let b: Vec<Vector3> = (0..n)
                .map(|m| {
                    let v = std::f64::consts::TAU * m as f64 / n as f64;
                    let a = f64::to_radians(half_angle) * (1.0 + 0.2 * (5.0 * v).sin());
                    Vector3::new(a.sin() * v.cos(), a.sin() * v.sin(), a.cos())
                })
                .collect();
            let dt: Vec<f64> = (0..n).map(|m| 0.05 + 0.03 * (m % 7) as f64 / 7.0).collect();
            let mut time = vec![0.0; n];
            for m in 1..n {
                time[m] = time[m - 1] + dt[m];
            }
            let mut brute = (0.0f64, (0, 0));
            for i in 0..n {
                for j in i + 1..n {
                    let theta = b[i].angle(&b[j]);
                    let rate = (theta - 2.0 * cone) / (time[j] - time[i]);
                    if rate > brute.0 {
                        brute = (rate, (i, j));
                    }
                }
            }
            let (rate, pair) = required_rotation_rate(&b, &dt, cone);
            approx::assert_relative_eq!(rate, brute.0, max_relative = 1e-12);
            assert_eq!(pair, brute.1, "half angle {half_angle}°");
        }
    }

    /// A ROBOWAM positioner with a ±135° tilt, and a layer of 51 points
    /// whose `b` tilts from −40° to +40° about the table's Y axis in 1 s
    /// (0.02 s a step).
    fn tilting_layer() -> (Positioner, Vec<Vector3>, Vec<f64>) {
        let mut pos = Positioner::robowam_nominal();
        pos.limits[0] = crate::robot::model::JointLimit {
            lower_rad: -135f64.to_radians(),
            upper_rad: 135f64.to_radians(),
        };
        let n = 51;
        let b: Vec<Vector3> = (0..n)
            .map(|m| {
                let a = (-40.0 + 80.0 * m as f64 / (n - 1) as f64).to_radians();
                Vector3::new(a.sin(), 0.0, a.cos())
            })
            .collect();
        (pos, b, vec![0.02; n])
    }

    /// The grid search proves what the rate bound cannot: `b` tilting from
    /// −40° to +40° about the table's Y axis in 1 s needs the tilt to move
    /// by 50° (the turn cannot lessen a tilt from the table normal), which a
    /// 10°/s tilt cannot, however fast the turn (the rate bound sees
    /// 10 + 1000°/s); at 100°/s a path exists and none is claimed.
    #[test]
    fn the_grid_search_proves_a_tilt_too_slow_for_the_layer() {
        let (mut pos, b, dt) = tilting_layer();
        let n = b.len();
        let cone = 15f64.to_radians();
        let r0 = Matrix3::identity();
        let cell = 1f64.to_radians();
        pos.max_speed_rad_s = [10f64.to_radians(), 1000f64.to_radians()];
        let (rate, _) = required_rotation_rate(&b, &dt, cone);
        assert!(rate < pos.max_speed_rad_s[0] + pos.max_speed_rad_s[1]);
        let at = unreachable_point(&pos, &r0, &b, &dt, cone, cell);
        assert!(at.is_some_and(|m| m > 0 && m < n), "{at:?}");
        pos.max_speed_rad_s = [100f64.to_radians(), 1000f64.to_radians()];
        assert_eq!(unreachable_point(&pos, &r0, &b, &dt, cone, cell), None);
    }

    /// The grid's relaxation keeps a cell of slack on the cone and a cell
    /// of motion per anchor, so a finer grid proves layers a coarser one
    /// cannot. The layer of the test above (`b` tilting from −40° to +40° in
    /// 1 s, a 15° cone): with a 14°/s tilt the 2° grid proves nothing and
    /// the 1° grid proves it; with 16°/s only the 0.5° and 0.25° grids do;
    /// on this layer the 0.5° grid is already tight (both prove 16.6°/s,
    /// neither 16.7°/s; the S-bend's layer 92 is one the 0.25° grid proves
    /// and the 0.5° grid does not, `tests/optimise/torch_carried.rs`). The
    /// proof falls where `b` crosses the table normal (point 25 of 51). The
    /// rate bound proves none of them (the turn's 1000°/s).
    #[test]
    fn a_finer_grid_proves_what_the_coarse_one_cannot() {
        let (mut pos, b, dt) = tilting_layer();
        let cone = 15f64.to_radians();
        let r0 = Matrix3::identity();
        let proven = |pos: &Positioner| -> Vec<bool> {
            GRID_CELLS_DEG
                .iter()
                .map(|c| unreachable_point(pos, &r0, &b, &dt, cone, c.to_radians()).is_some())
                .collect()
        };
        for (v7, expected) in [
            (14.0, [false, true, true, true]),
            (16.0, [false, false, true, true]),
            (16.6, [false, false, true, true]),
            (16.7, [false, false, false, false]),
            (18.0, [false, false, false, false]),
        ] {
            pos.max_speed_rad_s = [f64::to_radians(v7), 1000f64.to_radians()];
            let (rate, _) = required_rotation_rate(&b, &dt, cone);
            assert!(rate < pos.max_speed_rad_s[0] + pos.max_speed_rad_s[1]);
            assert_eq!(proven(&pos), expected, "tilt at {v7}°/s");
        }
    }

    /// The spline's abscissa: unchanged where `b` turns evenly along the
    /// layer; where `b` turns through all of its swing between two points
    /// (a corner), half the abscissa is spent there.
    #[test]
    fn the_knots_crowd_where_b_turns() {
        let n = 11;
        let x: Vec<f64> = (0..n).map(|m| m as f64).collect();
        let even: Vec<Vector3> = (0..n)
            .map(|m| {
                let a = (3.0 * m as f64).to_radians();
                Vector3::new(a.sin(), 0.0, a.cos())
            })
            .collect();
        for (m, s) in following_turning(&x, &even).iter().enumerate() {
            approx::assert_relative_eq!(*s, m as f64 / 10.0, epsilon = 1e-12);
        }
        let corner: Vec<Vector3> = (0..n)
            .map(|m| if m < 5 { Vector3::z() } else { Vector3::x() })
            .collect();
        let s = following_turning(&x, &corner);
        approx::assert_relative_eq!(s[5] - s[4], 0.5 + 0.05, epsilon = 1e-12);
        approx::assert_relative_eq!(s[4] - s[3], 0.05, epsilon = 1e-12);
        approx::assert_relative_eq!(s[10], 1.0, epsilon = 1e-12);
        // b that does not turn: the abscissa as given
        assert_eq!(following_turning(&x, &vec![Vector3::z(); n]), x);
    }

    /// A torch-carried sample cell of `parts/cells`.
    fn sample_cell(file: &str) -> TorchCarriedCell {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("parts/cells")
            .join(file);
        match crate::io::cell_file::read_cell_file(&path)
            .expect("sample cell")
            .cell
        {
            Some(crate::robot::CellLayout::TorchCarried(c)) => c,
            other => panic!("not a torch-carried sample cell: {other:?}"),
        }
    }

    fn cell(cone_deg: f64) -> TorchCarriedCell {
        let mut c = sample_cell("kuka_kr16_2_torch_carried.toml");
        c.max_vertical_error_rad = cone_deg.to_radians();
        c.table_from_part =
            Isometry3::from_parts(Translation3::new(0.0, 0.0, 0.0), UnitQuaternion::identity());
        c
    }

    /// A layer whose build direction crosses the table normal (the pole):
    /// `b` tilts 10° from +Z along X, through Z, to 10° along −X and back,
    /// around a small circle off the turn axis. The exact-vertical turn
    /// turns the table by ~180° near the pole; within a 15° cone the turn
    /// holds (within a few degrees).
    #[test]
    fn the_turn_holds_still_at_the_pole() {
        let c = cell(15.0);
        let n = 200;
        let points: Vec<CellPoint> = (0..n)
            .map(|m| {
                let v = std::f64::consts::TAU * m as f64 / n as f64;
                let a = 10f64.to_radians() * v.cos();
                let b = Vector3::new(a.sin(), 0.02 * v.sin(), a.cos());
                CellPoint {
                    position_mm: Point3::new(60.0 + 20.0 * v.cos(), 20.0 * v.sin(), 50.0),
                    tool_axis: UnitVector3::new_normalize(b),
                    build_direction: Some(UnitVector3::new_normalize(b)),
                    positioner: None,
                }
            })
            .collect();
        let exact = vertical_joints(&c, &points, 0.0).expect("vertical joints");
        let range = |q: &[PositionerJoints]| {
            let (lo, hi) = q
                .iter()
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
                    (a.min(v[1]), b.max(v[1]))
                });
            hi - lo
        };
        let spin = range(&exact);
        assert!(
            spin > 3.0,
            "the exact vertical turns the table by {spin} rad"
        );
        let law = positioner_law(&c, &points, 6.0, 0.0, 0.0, &PositionerOptions::default());
        assert!(law.feasible, "{:?}", law.binding);
        // the turn only trims the tilt (±5° here), it does not follow b round
        let turn = range(&law.joints);
        assert!(turn < 0.2, "the turn moves by {turn} rad");
        assert!(law.max_tilt_rad <= 15f64.to_radians() + 1e-9);
    }

    /// A flat circle about the turn axis, `b` vertical: the law turns the
    /// table the whole turn under a still torch (the arm's motion costs,
    /// the endless turn does not). With the controller's stroke narrowed to
    /// ±100° the program could not hold that bead; the law is solved again
    /// within the stroke and stays within its 200° (the arm takes the rest).
    #[test]
    fn the_turn_stays_within_the_controllers_stroke() {
        let mut c = sample_cell("robowam_torch_carried.toml");
        let n = 120;
        let points: Vec<CellPoint> = (0..n)
            .map(|m| {
                let v = std::f64::consts::TAU * m as f64 / n as f64;
                CellPoint {
                    position_mm: Point3::new(100.0 * v.cos(), 100.0 * v.sin(), 20.0),
                    tool_axis: Vector3::z_axis(),
                    build_direction: Some(Vector3::z_axis()),
                    positioner: None,
                }
            })
            .collect();
        let span = |law: &PositionerLaw| {
            let (lo, hi) = law
                .joints
                .iter()
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
                    (a.min(v[1]), b.max(v[1]))
                });
            (lo, hi)
        };
        let free = positioner_law(&c, &points, 6.0, 0.0, 0.0, &PositionerOptions::default());
        let (lo, hi) = span(&free);
        assert!(free.feasible, "{:?}", free.binding);
        assert!(
            hi - lo > 300f64.to_radians(),
            "the table turns {} rad",
            hi - lo
        );
        let stroke = 100f64.to_radians();
        c.positioner.turn_stroke = Some(crate::robot::JointLimit {
            lower_rad: -stroke,
            upper_rad: stroke,
        });
        let law = positioner_law(&c, &points, 6.0, 0.0, 0.0, &PositionerOptions::default());
        let (lo, hi) = span(&law);
        assert!(law.feasible, "{:?}", law.binding);
        let shifts = c.turn_stroke().whole_turn_shifts(lo, hi);
        assert!(shifts.is_some(), "[{lo}, {hi}] rad does not fit ±{stroke}");
        assert!(law.max_tilt_rad <= 15f64.to_radians() + 1e-9);
    }

    /// The grid's path against the closed form of a layer whose `b` tilts
    /// from −40° to +40° about the tilt axis in 1 s (11 points, 0.1 s a
    /// step; the turn at 1000°/s aligns `b`'s azimuth for free). Within a
    /// 15° cone the tilt must be at least 25° at both ends and at most 15°
    /// where `b` crosses the table normal half way: 10° in 0.5 s, 20°/s.
    /// At 25°/s the path keeps the cone, the travels and the speeds at
    /// every point (the law's own check); at 15°/s there is no path, and
    /// the proof's outer grid agrees.
    #[test]
    fn the_grids_path_keeps_every_constraint_where_the_closed_form_allows_one() {
        let mut c = cell(15.0);
        let n = 11;
        let points: Vec<CellPoint> = (0..n)
            .map(|m| {
                let a = (-40.0 + 8.0 * m as f64).to_radians();
                let b = UnitVector3::new_normalize(Vector3::new(a.sin(), 0.0, a.cos()));
                CellPoint {
                    position_mm: Point3::new(m as f64, 0.0, 0.0),
                    tool_axis: b,
                    build_direction: Some(b),
                    positioner: None,
                }
            })
            .collect();
        let opts = PositionerOptions::default();
        c.positioner.max_speed_rad_s = [25f64.to_radians(), 1000f64.to_radians()];
        let pb = LawProblem::new(&c, &points, 10.0, 0.0, &opts, &[]);
        let path = grid_path(&pb).expect("a path at 25°/s");
        assert_eq!(path.len(), n);
        assert!(
            check(&pb, &path).binding.is_none(),
            "{:?}",
            check(&pb, &path).binding
        );
        c.positioner.max_speed_rad_s = [15f64.to_radians(), 1000f64.to_radians()];
        let pb = LawProblem::new(&c, &points, 10.0, 0.0, &opts, &[]);
        assert!(grid_path(&pb).is_none());
        let r0 = Matrix3::identity();
        let at = unreachable_point(
            &c.positioner,
            &r0,
            &pb.b,
            &pb.dt,
            pb.cone,
            0.25f64.to_radians(),
        );
        assert!(at.is_some(), "the outer grid proves 15°/s too slow");
    }

    /// Relaxing a path keeps what it kept and spreads its motion: on a
    /// layer whose `b` stays on the table normal (any tilt within 15° keeps
    /// the cone), a path that holds, then tilts 8° in one step, comes out
    /// with a fifth of the squared motion or less and every constraint
    /// kept.
    #[test]
    fn relaxing_a_path_keeps_its_constraints_and_spreads_its_motion() {
        let c = cell(15.0);
        let n = 41;
        let points: Vec<CellPoint> = (0..n)
            .map(|m| CellPoint {
                position_mm: Point3::new(m as f64, 0.0, 0.0),
                tool_axis: Vector3::z_axis(),
                build_direction: Some(Vector3::z_axis()),
                positioner: None,
            })
            .collect();
        let pb = LawProblem::new(&c, &points, 10.0, 0.0, &PositionerOptions::default(), &[]);
        // tilt 0 → 8° in one step at the middle (within 90°/s · 0.1 s)
        let mut q: Vec<PositionerJoints> = (0..n)
            .map(|m| [if m < n / 2 { 0.0 } else { 8f64.to_radians() }, 0.0])
            .collect();
        assert!(check(&pb, &q).binding.is_none());
        let squared = |q: &[PositionerJoints]| -> f64 {
            q.windows(2).map(|w| (w[1][0] - w[0][0]).powi(2)).sum()
        };
        let before = squared(&q);
        relax(&pb, &mut q, pb.cone);
        assert!(
            check(&pb, &q).binding.is_none(),
            "{:?}",
            check(&pb, &q).binding
        );
        assert!(squared(&q) < 0.2 * before, "{} vs {before}", squared(&q));
    }
}
