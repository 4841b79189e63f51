//! The typed content of `summary.json` (`slice`, `plan`) and
//! `placement.json` (`place`): plain `#[derive(Serialize)]` structs built from
//! a sliced, planned or placed part, so that a host reads the figures as
//! fields and the JSON follows from the types. Angles in degrees, lengths in
//! mm, rates in deg/s, times in s, unless a field's name says otherwise.

use serde::Serialize;

use crate::optimise::positioner::{PositionerLaw, PositionerSeed};
use crate::optimise::SolvedRzLaw;
use crate::path::distance_map::DistanceStats;
pub use crate::program::cell_check::CollisionSummary;
use crate::toolaxis::NormalMethod;

/// What `slice` and `plan` report of the path (the shared part of
/// `summary.json`).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PathSummary {
    /// The slicing strategy's name.
    pub strategy: &'static str,
    /// Delta, the target interlayer distance (mm).
    pub delta_mm: f64,
    /// Number of layers.
    pub layers: usize,
    /// Number of slices (layers at the same height of a branching path share one).
    pub slices: usize,
    /// Number of path points.
    pub points: usize,
    /// Arc starts (one per layer, or one for a spiral).
    pub arc_starts: usize,
    /// Bead length over the whole path (mm).
    pub length_mm: f64,
    /// The process parameters and estimates.
    pub process: ProcessSummary,
    /// What the tool-axis stage did.
    pub tool_axes: ToolAxesSummary,
    /// The local interlayer distance, overall and per layer (mm; `null` on
    /// the first slice).
    pub distance: DistanceSummary,
    /// The layers' corners (SPEC §3.4, §9).
    pub corners: CornersSummary,
}

/// The layers' corners: where a layer's polyline turns more than the
/// threshold ([`Layer::corners`](crate::path::Layer::corners)).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CornersSummary {
    /// A vertex turning more than this (deg), and more than 4 times its
    /// layer's median turning, is a corner.
    pub threshold_deg: f64,
    /// Closed layers with corners start and end at their sharpest one.
    pub seams_on_corners: bool,
    /// Layers with at least one corner.
    pub layers_with_corners: usize,
    /// Corners in all.
    pub count: usize,
    /// Per layer, in path order, its corners (empty: none).
    pub per_layer: Vec<Vec<CornerSummary>>,
}

/// One corner of a layer.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CornerSummary {
    /// The point where the layer turns most within the corner.
    pub point: usize,
    /// The corner's first and last vertices, in deposition order (equal for
    /// a one-vertex corner; the first above the last where the corner
    /// wraps round a closed layer's seam).
    pub vertices: [usize; 2],
    /// Turning angle of the polyline across the corner (deg).
    pub turning_deg: f64,
    /// Angle between the build directions `b` at the points either side of
    /// the corner (deg): how far the part must turn under the torch across it.
    pub build_jump_deg: f64,
    /// The layer's seam (its last point and its first) lies on the corner.
    pub on_seam: bool,
}

impl CornerSummary {
    /// The summary of `corner` of `layer`, whose frames are `frames` (one
    /// per point, part frame).
    pub fn of(
        layer: &crate::path::Layer,
        frames: &[crate::toolaxis::LocalFrame],
        corner: &crate::path::Corner,
    ) -> Self {
        let n = layer.points.len();
        let (before, after) = if layer.closed {
            ((corner.first + n - 1) % n, (corner.last + 1) % n)
        } else {
            (corner.first.saturating_sub(1), (corner.last + 1).min(n - 1))
        };
        Self {
            point: corner.point,
            vertices: [corner.first, corner.last],
            turning_deg: corner.turn_rad.to_degrees(),
            build_jump_deg: frames[before]
                .build
                .angle(&frames[after].build)
                .to_degrees(),
            on_seam: layer.closed && corner.on_seam(n),
        }
    }
}

/// Process parameters and the build's estimates.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ProcessSummary {
    /// The material's name.
    pub material: String,
    /// Travel speed of the torch over the part (mm/s).
    pub travel_speed_mm_s: f64,
    /// Wire feed speed (mm/s).
    pub wire_feed_speed_mm_s: f64,
    /// Arc-on time (s).
    pub deposition_time_s: f64,
    /// Wire used (mm).
    pub wire_length_mm: f64,
    /// Deposited mass (g).
    pub deposited_mass_g: f64,
    /// Points whose travel speed leaves the process window.
    pub speed_window_violations: usize,
}

/// The tool-axis stage's report.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ToolAxesSummary {
    /// How the wall normals were obtained.
    pub normals: NormalMethod,
    /// Largest angle of a tool axis from the part's Z (deg).
    pub max_angle_from_z_deg: f64,
    /// Largest turning rate of the tool axis along the path (deg/mm).
    pub max_rate_deg_per_mm: f64,
    /// Points where the lead/tilt rule was active.
    pub rule_active_points: usize,
    /// Points where the rule could not be met.
    pub rule_unreachable_points: usize,
    /// Points whose axis was smoothed.
    pub smoothed_points: usize,
}

/// The local interlayer distances (mm).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct DistanceSummary {
    /// Over the whole path (`null` with a single slice).
    pub overall: Option<DistanceStats>,
    /// Per layer, in path order (`null` on the first slice).
    pub per_layer: Vec<Option<DistanceStats>>,
}

/// What the slicer did.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SlicerSummary {
    /// Grid points the layers were sought on.
    pub grid_points: usize,
    /// Root findings run.
    pub root_finds: usize,
    /// Distance evaluations.
    pub evaluations: usize,
    /// Largest residual of a root found (mm).
    pub max_residual_mm: f64,
    /// Points dropped at the part's ends.
    pub truncated_points: usize,
    /// Why the generation stopped.
    pub stop: crate::path::StopReason,
    /// Largest turning angle between consecutive segments before smoothing (deg).
    pub max_turn_before_deg: f64,
    /// The same after smoothing (deg).
    pub max_turn_after_deg: f64,
}

/// `slice`'s `summary.json`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SliceSummary {
    /// The part's name.
    pub part: String,
    /// The part file, as given.
    pub part_file: String,
    /// What the slicer did.
    pub slicer: SlicerSummary,
    /// Run time of each stage (s).
    pub run_time_s: super::SliceTimes,
    /// The path, process, tool axes and distances.
    #[serde(flatten)]
    pub path: PathSummary,
}

/// `plan`'s `summary.json`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PlanSummary {
    /// The part's name.
    pub part: String,
    /// The part file, as given.
    pub part_file: String,
    /// The cell file, as given.
    pub cell_file: String,
    /// The `R_Z` law asked for (its command-line form).
    pub rz: String,
    /// Programmed travel speed (mm/s).
    pub travel_speed_mm_s: f64,
    /// Every layer feasible.
    pub feasible: bool,
    /// The infeasible layers' numbers.
    pub infeasible_layers: Vec<usize>,
    /// Layers that no motion of arm and positioner within the cone can
    /// build, by a bound from the geometry alone (torch-carried cells).
    pub unbuildable_layers: Vec<UnbuildableLayer>,
    /// Every violation, as a sentence naming layer, point and joint.
    pub violations: Vec<String>,
    /// Per layer.
    pub layer_plans: Vec<LayerSummary>,
    /// Between consecutive layers (and the beads of a split layer).
    pub transitions: Vec<TransitionSummary>,
    /// Where a layer's bead was split at a corner (torch-carried cells), in
    /// path order; each split is one more arc start (`arc_starts`).
    pub splits: Vec<SplitSummary>,
    /// Where the torch slows down because an axis cannot keep up at the
    /// process's speed, per bead, in path order.
    pub slowed: Vec<SlowSummary>,
    /// Filled by the writer of the program files (`null` here).
    pub program: Option<()>,
    /// The program stage's refusal of a plan whose layers are all feasible
    /// (`None`: a program was built, or a layer is infeasible).
    pub program_refusal: Option<String>,
    /// A collision in the cell: where, which bodies, how deep.
    pub collision: Option<CollisionSummary>,
    /// What the whole-cell collision check measured (`None` without a
    /// program).
    pub cell_check: Option<CellCheckSummary>,
    /// The build's cycle time (s; `None` without a program).
    pub cycle_time_s: Option<f64>,
    /// The cycle time's parts (`None` without a program).
    pub cycle: Option<CycleSummary>,
    /// Run time of each stage (s).
    pub run_time_s: super::PlanTimes,
    /// The path, process, tool axes and distances.
    #[serde(flatten)]
    pub path: PathSummary,
}

/// `true` for 0.
fn is_zero(k: &usize) -> bool {
    *k == 0
}

/// One split of a layer's bead at a corner
/// ([`BeadSplit`](crate::optimise::BeadSplit)).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SplitSummary {
    /// The layer.
    pub layer: usize,
    /// The layer's point where one bead ends and the next starts.
    pub point: usize,
    /// The bead that starts there (1 for the layer's first split).
    pub bead: usize,
    /// Turning angle of the layer's polyline across the corner (deg).
    pub turning_deg: f64,
    /// Why the layer was split: how its plan as one bead failed.
    pub why: String,
}

/// A bead slowed down ([`SlowedBead`](crate::optimise::SlowedBead)).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SlowSummary {
    /// The layer.
    pub layer: usize,
    /// The bead within the layer (0 for a whole layer).
    pub bead: usize,
    /// Points reached slower than the process's speed.
    pub points_slowed: usize,
    /// The slowest travel speed of the bead (mm/s).
    pub slowest_mm_s: f64,
    /// The layer's point reached at that speed.
    pub slowest_point: usize,
    /// The wire feed there (mm/s): the process's, scaled as the speed.
    pub wire_feed_min_mm_s: f64,
    /// Why: how the plan at the process's speed failed.
    pub why: String,
}

/// The whole-cell check's counts.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CellCheckSummary {
    /// Arm poses checked.
    pub samples: usize,
    /// Pair distances computed exactly.
    pub exact_queries: usize,
    /// Pairs culled by their bounds.
    pub culled: usize,
}

/// The program's cycle time, in parts ([`crate::program::cycle`]).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CycleSummary {
    /// Time with the arc on, summed over the beads (s).
    pub arc_on_s: f64,
    /// The joint move back home after the last bead (s).
    pub home_return_s: f64,
    /// Waits for the interpass input, counted as 0 s each.
    pub interpass_waits: usize,
    /// Fraction of each joint's maximum speed the joint moves run at.
    pub joint_speed_fraction: f64,
    /// The TCP's acceleration along linear moves (mm/s²).
    pub path_acceleration_mm_s2: f64,
    /// Per bead, in program order.
    pub layers: Vec<crate::program::cycle::LayerCycle>,
}

/// A layer proven unbuildable from the geometry.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct UnbuildableLayer {
    /// The layer.
    pub layer: usize,
    /// The proof.
    pub proof: UnbuildableProof,
    /// The positioner rotation rate the layer needs (deg/s; `null`: unbounded).
    pub required_rate_deg_s: Option<f64>,
    /// The rate the positioner can give, `v7 + v8` (deg/s; `null`: unlimited).
    pub available_rate_deg_s: Option<f64>,
    /// The two points the required rate is measured between.
    pub between_points: [usize; 2],
    /// The first point no positioner path reaches within the cone.
    pub unreachable_point: Option<usize>,
}

/// How a layer was proven unbuildable.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum UnbuildableProof {
    /// The positioner cannot turn the part fast enough between two points.
    Rate,
    /// No positioner path reaches a point within the cone.
    Reachability,
}

/// One layer's plan.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct LayerSummary {
    /// The layer.
    pub layer: usize,
    /// The bead of a layer split at its corners (one entry per bead; not
    /// written for a layer's first or only bead).
    #[serde(skip_serializing_if = "is_zero")]
    pub bead: usize,
    /// Its status (`feasible`, or the binding constraint).
    pub status: String,
    /// Feasible.
    pub feasible: bool,
    /// The IK branch kept.
    pub configuration: String,
    /// Why that branch.
    pub configuration_reason: String,
    /// The `R_Z` law found.
    pub law: SolvedRzLaw,
    /// Points in the layer.
    pub points: usize,
    /// The objective's terms.
    pub objective: ObjectiveSummary,
    /// Quality figures of the joint trajectory.
    pub quality: QualitySummary,
    /// The positioner's laws (torch-carried cell).
    pub positioner: Option<PositionerSummary>,
    /// The layer's share of the cycle time (s): the joint move into it,
    /// dwell, approach, bead, retract; `None` without a program.
    pub cycle_time_s: Option<f64>,
    /// The closest two bodies of the cell along the layer's motions (mm;
    /// `None` without a program, or when every pair was culled far apart).
    pub closest_approach_mm: Option<f64>,
    /// The two bodies at that approach.
    pub closest_pair: Option<[String; 2]>,
    /// Via points of the arc-off transit after this bead
    /// ([`ArcFlag::Transit`](crate::program::ArcFlag::Transit)): where the
    /// direct joint move to the next bead (or home) would take the torch
    /// through the deposited wall, the program goes through these (the
    /// torch lifted along the tool axis, the positioner turning alone, or
    /// home); absent when none.
    #[serde(skip_serializing_if = "is_zero")]
    pub transit_vias: usize,
    /// The solver's counts.
    pub solver: SolverSummary,
}

/// The objective's terms for a layer.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ObjectiveSummary {
    /// Weighted joint displacement [eq. 4.3] (rad², weighted).
    pub joint_displacement: f64,
    /// Sum of the squared positioning uncertainties (mm²).
    pub uncertainty_sum_sq_mm2: f64,
    /// Mean positioning uncertainty (mm).
    pub mean_uncertainty_mm: f64,
    /// Centring term (unitless).
    pub centring: f64,
}

/// Quality figures of a layer's joint trajectory (J1–J6).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct QualitySummary {
    /// Travel of each joint (deg).
    pub joint_travel_deg: Vec<f64>,
    /// Peak speed of each joint at the travel speed (deg/s).
    pub peak_speed_deg_s: Vec<f64>,
    /// Peak acceleration of each joint (deg/s²).
    pub peak_acceleration_deg_s2: Vec<f64>,
    /// Summed acceleration of J1–J5 (deg/s).
    pub summed_acceleration_j1_j5_deg_s: f64,
    /// Direction reversals of each joint.
    pub direction_reversals: [usize; 6],
    /// Smallest dexterity (unitless).
    pub min_dexterity: f64,
    /// Smallest distance to a joint stop (deg).
    pub min_limit_distance_deg: f64,
    /// The joint (1-based) at that distance.
    pub min_limit_distance_joint: usize,
    /// Largest hose torsion (deg).
    pub max_hose_torsion_deg: f64,
}

/// One layer's positioner laws (torch-carried cell).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PositionerSummary {
    /// The start the kept law came from.
    pub seed: PositionerSeed,
    /// The law keeps every constraint.
    pub feasible: bool,
    /// Its binding constraint, if any.
    pub binding: Option<String>,
    /// Largest tilt of `b` from the vertical (deg).
    pub max_tilt_deg: f64,
    /// The point of that tilt.
    pub max_tilt_point: usize,
    /// The rotation rate the layer needs (deg/s; `null`: unbounded).
    pub required_rate_deg_s: Option<f64>,
    /// The rate the positioner gives (deg/s; `null`: unlimited).
    pub available_rate_deg_s: Option<f64>,
    /// The points the required rate is measured between.
    pub required_between_points: [usize; 2],
    /// Proven unbuildable from the geometry.
    pub proven_infeasible: bool,
    /// The first point no positioner path reaches within the cone.
    pub unreachable_point: Option<usize>,
    /// SQP iterations.
    pub iterations: usize,
    /// Points the law was solved on.
    pub samples: usize,
}

impl From<&PositionerLaw> for PositionerSummary {
    fn from(law: &PositionerLaw) -> Self {
        Self {
            seed: law.seed,
            feasible: law.feasible,
            binding: law.binding.map(|b| b.to_string()),
            max_tilt_deg: law.max_tilt_rad.to_degrees(),
            max_tilt_point: law.max_tilt_point,
            required_rate_deg_s: finite(law.required_rate_rad_s.to_degrees()),
            available_rate_deg_s: finite(law.available_rate_rad_s.to_degrees()),
            required_between_points: [law.required_between.0, law.required_between.1],
            proven_infeasible: law.proven_infeasible,
            unreachable_point: law.unreachable_point,
            iterations: law.iterations,
            samples: law.samples,
        }
    }
}

/// The solver's counts for a layer.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SolverSummary {
    /// SQP iterations.
    pub iterations: usize,
    /// QPs solved.
    pub qp_solves: usize,
    /// QPs that failed.
    pub qp_failures: usize,
    /// IK branches tried.
    pub branches_tried: usize,
    /// Points the law was optimised on (`null`: every point); it is
    /// certified on every point either way.
    pub samples: Option<usize>,
    /// Time (s).
    pub time_s: f64,
}

/// Between two consecutive layers.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct TransitionSummary {
    /// From this layer.
    pub from_layer: usize,
    /// To this one.
    pub to_layer: usize,
    /// Joint change J1–J6 (deg).
    pub joint_change_deg: Vec<f64>,
    /// The IK branch changes.
    pub branch_change: bool,
    /// Distance to a joint stop at the next layer's start (deg).
    pub start_limit_distance_deg: f64,
}

/// A number, `None` (JSON `null`) when not finite (an unbounded rate).
pub(crate) fn finite(v: f64) -> Option<f64> {
    v.is_finite().then_some(v)
}

/// Joint angles (rad) in degrees.
pub(crate) fn deg6(q: &[f64; 6]) -> Vec<f64> {
    q.iter().map(|v| v.to_degrees()).collect()
}

/// `place`'s `placement.json`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PlacementSummary {
    /// A placement was found.
    pub feasible: bool,
    /// Each placement variable: its bounds, the value given and the one found.
    pub variables: Vec<PlacementVariableSummary>,
    /// The keep-out box, robot base frame (mm).
    pub keep_out: Option<KeepOutSummary>,
    /// Worst-layer margins at the placement found.
    pub margins: crate::place::Margins,
    /// The same at the cell file's own placement.
    pub margins_before: crate::place::Margins,
    /// Candidates screened.
    pub candidates: usize,
    /// Candidates certified on the full path.
    pub certified: usize,
    /// Feedback rounds.
    pub rounds: usize,
    /// The constraint the search stopped on.
    pub stopped_on: Option<String>,
    /// Layers of the last subsample.
    pub subsample_layers: usize,
    /// Layers of the full path.
    pub subsample_layers_full: usize,
    /// Time of each phase (s).
    pub times: crate::place::PlaceTimes,
    /// Fraction of the screened candidates feasible on the subsample.
    pub feasible_fraction: f64,
    /// The binding constraint and the share of candidates it bound.
    pub binding: Option<BindingSummary>,
    /// The infeasible layers of the best plan and their status.
    pub infeasible_layers: Vec<InfeasibleLayerSummary>,
    /// The search's time (s).
    pub time_s: f64,
}

/// A placement variable in `placement.json`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PlacementVariableSummary {
    /// Its cell-file name.
    pub name: &'static str,
    /// `deg` or `mm`.
    pub unit: &'static str,
    /// Lower bound (unit).
    pub lower: f64,
    /// Upper bound (unit).
    pub upper: f64,
    /// The cell file's value (unit).
    pub given: f64,
    /// The value found (unit).
    pub found: f64,
}

/// An axis-aligned keep-out box, robot base frame (mm).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct KeepOutSummary {
    /// Lower corner (mm).
    pub min_mm: [f64; 3],
    /// Upper corner (mm).
    pub max_mm: [f64; 3],
}

/// Placement's binding constraint.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct BindingSummary {
    /// The constraint, as a sentence.
    pub constraint: String,
    /// Share of the candidates it bound (0–1).
    pub share: f64,
}

/// An infeasible layer and its status.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct InfeasibleLayerSummary {
    /// The layer.
    pub layer: usize,
    /// Its binding constraint.
    pub status: String,
}
