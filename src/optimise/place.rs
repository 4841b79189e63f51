//! **Placement of the part in the cell** (beyond the thesis, which moved the
//! deposition point by hand, §3.3 "second position"). Takes a cell, the
//! layers of a path (part frame) and bounds on the cell's placement variables
//! and returns the placement that makes every layer feasible with the widest
//! worst-layer margin (joint-limit distance, speed headroom, dexterity).
//!
//! The variables (robot base frame; mm, rad), each searched only where its
//! bounds differ:
//!
//! | | part carried | torch carried |
//! |---|---|---|
//! | 0–2 | deposition point `D_R` x, y, z | positioner origin x, y, z |
//! | 3 | part mount about the flange axis | positioner about the vertical |
//! | 4, 5 | fixture tilt of the part on the flange about X, Y | fixture tilt of the part on the table about X, Y |
//! | 6 | part mount offset along the flange axis (mm) | torch in its clamp about the flange axis |
//!
//! The search:
//! 1. **Screening**: a coarse global sampling of the free variables (a
//!    Halton sequence; the cell as given is the first candidate), each
//!    candidate judged by the `R_Z` optimisation of SPEC §7 on a subsample
//!    of the layers and points, candidates in parallel.
//! 2. **Refinement**: a compass search from the best few, on the subsample
//!    (after a feedback, from the best one with half the evaluations).
//! 3. **Certification**, best first (the cell as given first unless beaten
//!    by [`KEEP_MARGIN`]), of the candidates feasible on the subsample: every layer at full resolution, in an order that meets the
//!    layers that failed before first and spreads the others over the part,
//!    in parallel chunks, stopping at the first chunk with an infeasible
//!    layer; a feasible plan is then offered to the caller's own check (the
//!    program stage's transit check, in [`crate::pipeline::place_part`]).
//! 4. **Feedback**: when certification fails, the failing layers join the
//!    subsample at full resolution (the subsample misses speed peaks at cusps
//!    between its points), and so do the layers of the certified plan that
//!    bind its joint-stop, speed or reach margin below the score's
//!    comfortable values (the subsample missed them); the best candidates
//!    are judged again on it, and when fewer than two of them stay feasible
//!    a fresh batch of the Halton sequence (half the screening's) is judged
//!    on it too; the search goes back to 2, for a bounded number of rounds.
//!
//! The score of a candidate feasible on the subsample is its worst margin:
//! joint stops, speed headroom and the wrist centre's distance inside the
//! arm's reach ([`REACH_COMFORT_MM`]), so that a candidate at the edge of
//! the reach ranks below one with room (points between the subsample's may
//! be out of reach). Certification still plans every point.

use std::collections::BTreeSet;
use std::f64::consts::PI;
use std::time::Instant;

use rayon::prelude::*;

use crate::math::{Isometry3, Point3, Translation3, UnitQuaternion, Vector3};
use crate::optimise::{
    optimise, transitions, LayerPlan, LayerPoints, LayerStatus, OptimiseError, OptimiseOptions,
    Plan,
};
use crate::robot::{Cell, Joints, RobotModel};

/// How much better (in the search's score: 1 is comfortable margins, 10° from
/// a stop and 20 % speed headroom) another candidate must score on the
/// subsample for the cell as given, when feasible there, not to be
/// certified first: 0.05 is half a degree from a stop or 1 % of speed
/// headroom. A placed cell placed again thus stays where it is.
pub const KEEP_MARGIN: f64 = 0.05;

/// The binding named for a candidate feasible on the subsample that the
/// caller's check refuses there.
const SCREEN_REFUSAL: &str = "program check on the subsample (transit or set-up)";

/// Number of placement variables (see the module doc's table).
pub const VARIABLES: usize = 7;

/// One placement variable: its name, its bounds and the cell's current value
/// (mm for positions and the offset, rad for rotations and tilts).
#[derive(Debug, Clone, PartialEq)]
pub struct PlacementVariable {
    /// Name, e.g. `deposition_point_mm.x`, `flange_rotation`, `positioner.x`,
    /// `fixture.tilt_x`, `fixture.offset`, `torch_rotation`.
    pub name: &'static str,
    /// `true` for an angle (rad), `false` for a length (mm).
    pub angle: bool,
    /// Lower bound (mm or rad).
    pub lower: f64,
    /// Upper bound (mm or rad); equal to `lower` for a fixed variable.
    pub upper: f64,
    /// The value in the cell as given (mm or rad).
    pub current: f64,
}

impl PlacementVariable {
    /// `true` when the bounds leave the variable free.
    pub fn is_free(&self) -> bool {
        self.upper > self.lower
    }
}

/// Bounds of the search and a keep-out box (robot base frame, mm): a
/// deposition point or positioner origin inside the box is refused (the
/// robot's base, a wall, the wire feeder).
#[derive(Debug, Clone, PartialEq)]
pub struct PlacementBounds {
    /// The [`VARIABLES`] variables, in the order of the module doc's table.
    pub variables: Vec<PlacementVariable>,
    /// Keep-out box `(min, max)`, robot base frame (mm).
    pub keep_out: Option<([f64; 3], [f64; 3])>,
}

impl PlacementBounds {
    /// Default bounds around `cell`'s placement: ±`half_box_mm` on each
    /// coordinate of the deposition point (positioner), the full turn on the
    /// rotation, the fixture and torch mount fixed as given, and the robot's
    /// base keep-out: a vertical cylinder's bounding box of half-width 250 mm
    /// about the base axis below the shoulder.
    pub fn around(cell: &Cell, half_box_mm: f64) -> Self {
        let names_pc = [
            "deposition_point_mm.x",
            "deposition_point_mm.y",
            "deposition_point_mm.z",
            "flange_rotation",
            "fixture.tilt_x",
            "fixture.tilt_y",
            "fixture.offset",
        ];
        let names_tc = [
            "positioner.x",
            "positioner.y",
            "positioner.z",
            "positioner.rotation",
            "fixture.tilt_x",
            "fixture.tilt_y",
            "torch_rotation",
        ];
        let (p, names): (Point3, [&'static str; VARIABLES]) = match cell {
            Cell::PartCarried(c) => (c.deposition_point_mm, names_pc),
            Cell::TorchCarried(c) => (
                Point3::from(c.base_from_positioner.translation.vector),
                names_tc,
            ),
        };
        let fixed = |name, angle| PlacementVariable {
            name,
            angle,
            lower: 0.0,
            upper: 0.0,
            current: 0.0,
        };
        let mut variables: Vec<PlacementVariable> = (0..3)
            .map(|k| PlacementVariable {
                name: names[k],
                angle: false,
                lower: p[k] - half_box_mm,
                upper: p[k] + half_box_mm,
                current: p[k],
            })
            .collect();
        variables.push(PlacementVariable {
            lower: -PI,
            upper: PI,
            ..fixed(names[3], true)
        });
        variables.push(fixed(names[4], true));
        variables.push(fixed(names[5], true));
        variables.push(fixed(names[6], matches!(cell, Cell::TorchCarried(_))));
        Self {
            variables,
            keep_out: Some(([-250.0, -250.0, -1e4], [250.0, 250.0, 400.0])),
        }
    }

    /// Checks every bound.
    ///
    /// # Errors
    /// [`OptimiseError::InvalidPlacement`] naming the variable.
    pub fn validate(&self) -> Result<(), OptimiseError> {
        if self.variables.len() != VARIABLES {
            return Err(OptimiseError::InvalidPlacement {
                field: "variables".into(),
                reason: format!(
                    "{VARIABLES} variables expected, got {}",
                    self.variables.len()
                ),
            });
        }
        for v in &self.variables {
            if !(v.lower.is_finite() && v.upper.is_finite() && v.lower <= v.upper) {
                return Err(OptimiseError::InvalidPlacement {
                    field: v.name.to_string(),
                    reason: format!(
                        "the range [{}, {}] must be finite and ordered",
                        v.lower, v.upper
                    ),
                });
            }
            if v.angle && (v.upper - v.lower) > 2.0 * PI + 1e-9 {
                return Err(OptimiseError::InvalidPlacement {
                    field: v.name.to_string(),
                    reason: "a rotation range wider than a turn".into(),
                });
            }
            if v.name.contains("tilt") && (v.lower < -PI / 2.0 - 1e-9 || v.upper > PI / 2.0 + 1e-9)
            {
                return Err(OptimiseError::InvalidPlacement {
                    field: v.name.to_string(),
                    reason: "a fixture tilt beyond ±90°".into(),
                });
            }
        }
        if let Some((lo, hi)) = self.keep_out {
            if !(0..3).all(|k| lo[k] <= hi[k] && lo[k].is_finite() && hi[k].is_finite()) {
                return Err(OptimiseError::InvalidPlacement {
                    field: "keep_out".into(),
                    reason: format!("min {lo:?} must be below max {hi:?}, finite"),
                });
            }
        }
        Ok(())
    }
}

/// Settings of [`place`]. Plain data.
#[derive(Debug, Clone, PartialEq)]
pub struct PlaceOptions {
    /// Coarse candidates sampled in the box (and half as many more, further
    /// along the Halton sequence, after a feedback that leaves fewer than two
    /// of the best feasible on the subsample).
    pub samples: usize,
    /// Layers of the subsample (evenly spread, first and last included).
    pub layers: usize,
    /// Points per layer of the subsample.
    pub points_per_layer: usize,
    /// Candidates refined by the compass search, and certified, per round.
    pub refined: usize,
    /// Evaluations of each compass search.
    pub refine_evaluations: usize,
    /// Rounds of refinement and certification (the failing layers of one
    /// round join the subsample of the next).
    pub rounds: usize,
    /// Failing layers added to the subsample after a failed certification
    /// (besides at most three that bind the certified layers' joint-stop,
    /// speed and reach margins).
    pub feedback_layers: usize,
    /// The optimiser's options (travel speed among them).
    pub optimise: OptimiseOptions,
}

impl Default for PlaceOptions {
    fn default() -> Self {
        Self {
            samples: 64,
            layers: 8,
            points_per_layer: 24,
            refined: 2,
            refine_evaluations: 24,
            rounds: 6,
            feedback_layers: 4,
            optimise: OptimiseOptions::default(),
        }
    }
}

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
    /// [`RobotError::Unreachable`](crate::robot::RobotError::Unreachable)).
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

/// What [`place`] found.
#[derive(Debug, Clone)]
pub struct Placement {
    /// The cell with the placement found (or the best tried when none is
    /// feasible).
    pub cell: Cell,
    /// The variables' values (mm, rad), in the order of the bounds.
    pub values: Vec<f64>,
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
    /// The binding constraint the rounds stopped on, when they stopped
    /// before [`PlaceOptions::rounds`] because every candidate judged again
    /// after a feedback was infeasible on the subsample, bound by it.
    pub stopped_on: Option<String>,
    /// Layers of the final subsample, and of them at full resolution.
    pub subsample_layers: (usize, usize),
    /// Why no placement was found: when no candidate was feasible on the
    /// subsample, the constraint that bound most of them (the first
    /// infeasible layer's) with the share of candidates it bound; when the
    /// best failed on the full path, that plan's first binding constraint
    /// (marked `(on the full path)`, followed by the caller's check's
    /// reason when it refused another candidate) with the share of the
    /// layers checked that are infeasible; when the caller's check refused every
    /// candidate feasible on the full path, its reason (suffix
    /// `(program check)`) and 1.
    pub binding: Option<(String, f64)>,
    /// The plan in the placed cell: every layer when feasible; otherwise
    /// the layers checked before certification stopped, or the subsample's
    /// plan when no candidate reached certification.
    pub plan: Plan,
    /// Phase times (s).
    pub times: PlaceTimes,
    /// Wall time (s).
    pub time_s: f64,
}

/// The cell with the placement `x` (see the module doc's table; missing
/// trailing values are 0).
pub fn placed_cell(cell: &Cell, x: &[f64]) -> Cell {
    let at = |k: usize| x.get(k).copied().unwrap_or(0.0);
    let rot = |axis: &crate::math::UnitVector3, a: f64| UnitQuaternion::from_axis_angle(axis, a);
    let tilt = rot(&Vector3::x_axis(), at(4)) * rot(&Vector3::y_axis(), at(5));
    let mut out = cell.clone();
    match &mut out {
        Cell::PartCarried(c) => {
            c.deposition_point_mm = Point3::new(at(0), at(1), at(2));
            let mount = Isometry3::from_parts(
                Translation3::new(0.0, 0.0, at(6)),
                rot(&Vector3::z_axis(), at(3)) * tilt,
            );
            c.flange_from_part = mount * c.flange_from_part;
        }
        Cell::TorchCarried(c) => {
            c.base_from_positioner = Isometry3::from_parts(
                Translation3::new(at(0), at(1), at(2)),
                rot(&Vector3::z_axis(), at(3)) * c.base_from_positioner.rotation,
            );
            c.table_from_part =
                Isometry3::from_parts(Translation3::identity(), tilt) * c.table_from_part;
            c.flange_from_tcp =
                Isometry3::from_parts(Translation3::identity(), rot(&Vector3::z_axis(), at(6)))
                    * c.flange_from_tcp;
        }
    }
    out
}

/// The layers picked for the subsample: `n_layers` evenly spread (first and
/// last included), or all when there are fewer.
fn coarse_picks(n: usize, n_layers: usize) -> BTreeSet<usize> {
    if n <= n_layers.max(2) {
        return (0..n).collect();
    }
    (0..n_layers)
        .map(|i| (i as f64 * (n - 1) as f64 / (n_layers - 1) as f64).round() as usize)
        .collect()
}

/// The subsample: the picked layers, every `k`-th point, and the layers of
/// `full` with all their points.
fn subsample(
    layers: &[LayerPoints],
    picks: &BTreeSet<usize>,
    full: &BTreeSet<usize>,
    n_points: usize,
) -> Vec<LayerPoints> {
    picks
        .union(full)
        .map(|&i| {
            let l = &layers[i];
            if full.contains(&i) {
                return l.clone();
            }
            let k = l.points.len().div_ceil(n_points.max(3)).max(1);
            let mut points: Vec<_> = l.points.iter().step_by(k).copied().collect();
            // The last point too: the arc-off moves start there.
            if (l.points.len() - 1) % k != 0 {
                points.extend(l.points.last().copied());
            }
            LayerPoints {
                layer: l.layer,
                points,
            }
        })
        .filter(|l| l.points.len() >= 3)
        .collect()
}

/// The worst layer's margins of `plan` in `cell`.
pub fn margins(plan: &Plan, cell: &Cell) -> Margins {
    let robot = cell.robot();
    let mut m = Margins {
        joint_limit_deg: f64::INFINITY,
        speed_headroom: f64::INFINITY,
        dexterity: f64::INFINITY,
        reach_mm: f64::INFINITY,
        infeasible_layers: 0,
    };
    for l in &plan.layers {
        if !l.status.is_feasible() {
            m.infeasible_layers += 1;
        }
        for q in l.points.iter().filter_map(|p| p.joints.as_ref()) {
            m.reach_mm = m.reach_mm.min(reach_margin_mm(robot, q));
        }
        let q = &l.quality;
        m.joint_limit_deg = m.joint_limit_deg.min(q.min_limit_distance_rad.to_degrees());
        m.dexterity = m.dexterity.min(q.min_dexterity);
        for j in 0..6 {
            let vmax = robot.max_speed_rad_s[j];
            if vmax.is_finite() && vmax > 0.0 {
                m.speed_headroom = m.speed_headroom.min(1.0 - q.peak_speed_rad_s[j] / vmax);
            }
        }
    }
    for v in [
        &mut m.joint_limit_deg,
        &mut m.speed_headroom,
        &mut m.dexterity,
        &mut m.reach_mm,
    ] {
        if !v.is_finite() {
            *v = 0.0;
        }
    }
    m
}

/// Distance (mm) of the wrist centre at joints `q` (rad) inside the arm's
/// reach annulus `[|c2 − k|, c2 + k]` about the J2 axis (`c2` the upper arm,
/// `k` the J3 → wrist-centre distance), as the inverse kinematics tests it;
/// negative outside.
fn reach_margin_mm(robot: &RobotModel, q: &Joints) -> f64 {
    let s = robot.chain_state(q);
    let d = (s.wrist_centre - s.axis_points[1]).norm();
    let g = &robot.geometry;
    let k = g.forearm_mm.hypot(g.elbow_offset_mm);
    (d - (g.upper_arm_mm - k).abs()).min(g.upper_arm_mm + k - d)
}

/// The reach margin (mm) the score calls comfortable. The full path's
/// layers and laws (each layer re-optimised on every point) take the wrist
/// centre further out than the subsample's: the S-bend at Delta 2 mm, 400
/// points a layer, had a candidate 51 mm inside the reach on the subsample
/// and 6.7 mm beyond it at layer 192 on the full path, between two layers
/// of the subsample.
pub const REACH_COMFORT_MM: f64 = 50.0;

/// One scalar to maximise: for a feasible plan the worst of the joint-limit,
/// speed and reach margins, each scaled to 1 at a comfortable value (10°
/// from a stop, 20 % speed headroom, [`REACH_COMFORT_MM`] inside the arm's
/// reach) and capped at 1, plus a small reward for
/// dexterity (the floor itself is a constraint of every layer; dexterity
/// mixes mm and rad, its values are ~1e-3 on our arms, so it only breaks
/// ties); for an infeasible plan minus the share of infeasible layers minus
/// a bounded measure of the violations.
fn score(plan: &Plan, cell: &Cell) -> f64 {
    let m = margins(plan, cell);
    if m.infeasible_layers == 0 {
        let a = (m.joint_limit_deg / 10.0).min(1.0);
        let b = (m.speed_headroom / 0.2).min(1.0);
        let r = (m.reach_mm / REACH_COMFORT_MM).min(1.0);
        let c = (m.dexterity / 2e-3).min(1.0);
        return a.min(b).min(r).max(0.0) + 0.01 * c.max(0.0);
    }
    let n = plan.layers.len().max(1) as f64;
    let violation: f64 = plan
        .layers
        .iter()
        .map(|l| match &l.status {
            LayerStatus::Infeasible { binding } | LayerStatus::FixedViolates { binding } => {
                binding.violation.abs().min(1.0)
            }
            LayerStatus::NoSolution { .. } => 1.0,
            _ => 0.0,
        })
        .sum::<f64>()
        / n;
    -(m.infeasible_layers as f64 / n) - 0.5 * violation
}

/// The first infeasible layer's binding constraint, as words.
fn binding_of(plan: &Plan) -> Option<String> {
    plan.layers.iter().find_map(|l| match &l.status {
        LayerStatus::Infeasible { binding } | LayerStatus::FixedViolates { binding } => {
            Some(binding.constraint.to_string())
        }
        LayerStatus::NoSolution { error, .. } => Some(format!("no joint solution ({error})")),
        _ => None,
    })
}

/// Radical inverse of `i` in `base` (Halton sequence), in `[0, 1)`.
fn radical_inverse(mut i: usize, base: usize) -> f64 {
    let (mut f, mut r) = (1.0, 0.0);
    while i > 0 {
        f /= base as f64;
        r += f * (i % base) as f64;
        i /= base;
    }
    r
}

/// The order in which certification visits the layers: those that failed
/// before first, then the others by the base-2 radical inverse of their
/// index (so that the first few spread over the whole part).
fn certification_order(n: usize, hot: &[usize]) -> Vec<usize> {
    let mut seen = vec![false; n];
    let mut order = Vec::with_capacity(n);
    for &i in hot {
        if i < n && !seen[i] {
            seen[i] = true;
            order.push(i);
        }
    }
    let mut rest: Vec<usize> = (0..n).filter(|i| !seen[*i]).collect();
    rest.sort_by(|a, b| radical_inverse(*a, 2).total_cmp(&radical_inverse(*b, 2)));
    order.extend(rest);
    order
}

/// Layers planned at certification, with their indices in the path.
type Certified = Vec<(usize, LayerPlan)>;

/// Layers certified together: certification stops after the first group
/// of this many (in certification order) with an infeasible layer, whatever
/// the number of threads (the chunks computed in parallel are whole
/// groups), so that the search's path does not depend on the machine.
const CERTIFY_GROUP: usize = 8;

/// Every layer of `layers` in `cell`, in `order`, in parallel chunks of
/// about `chunk` (rounded up to whole [`CERTIFY_GROUP`]s), stopping after
/// the first group with an infeasible layer. Returns the layers planned (in
/// path order, with their indices in `layers`) and the infeasible ones'
/// indices.
fn certify(
    cell: &Cell,
    layers: &[LayerPoints],
    order: &[usize],
    serial: &OptimiseOptions,
    chunk: usize,
) -> Result<(Certified, Vec<usize>), OptimiseError> {
    let chunk = chunk.max(1).div_ceil(CERTIFY_GROUP) * CERTIFY_GROUP;
    let mut planned: Vec<(usize, LayerPlan)> = Vec::with_capacity(layers.len());
    let mut failing = Vec::new();
    for part in order.chunks(chunk) {
        let results: Vec<Result<(usize, LayerPlan), OptimiseError>> = part
            .par_iter()
            .map(|&i| {
                let mut plan = optimise(cell, std::slice::from_ref(&layers[i]), serial)?;
                Ok((i, plan.layers.remove(0)))
            })
            .collect();
        for (k, r) in results.into_iter().enumerate() {
            let (i, l) = r?;
            if !l.status.is_feasible() {
                failing.push(i);
            }
            planned.push((i, l));
            // the end of a group with a failure: the rest is not used
            if (k + 1) % CERTIFY_GROUP == 0 && !failing.is_empty() {
                break;
            }
        }
        if !failing.is_empty() {
            break;
        }
    }
    planned.sort_by_key(|(i, _)| *i);
    Ok((planned, failing))
}

/// The layers of a certified (possibly partial) plan that bind its margins
/// below the score's comfortable values (the smallest joint-stop distance,
/// speed headroom and reach margin, each over the layers planned), by their
/// index in the path, excluding those in `known`. The subsample's points
/// may miss a layer's worst point and its layers may miss the worst layer
/// (the S-bend at Delta 2 mm: 11° from a stop on the subsample, 0.5° on the
/// full path, in layers between the subsample's); these layers joining the
/// subsample make its score the full path's.
fn weakest_layers(
    planned: &[(usize, LayerPlan)],
    cell: &Cell,
    known: &BTreeSet<usize>,
) -> Vec<usize> {
    let mut worst: [(f64, Option<usize>); 3] = [(f64::INFINITY, None); 3];
    for (i, l) in planned {
        if known.contains(i) {
            continue;
        }
        let m = margins(
            &Plan {
                layers: vec![l.clone()],
                transitions: Vec::new(),
                time_s: 0.0,
            },
            cell,
        );
        let scaled = [
            m.joint_limit_deg / 10.0,
            m.speed_headroom / 0.2,
            m.reach_mm / REACH_COMFORT_MM,
        ];
        for (w, v) in worst.iter_mut().zip(scaled) {
            if v < 1.0 && v < w.0 {
                *w = (v, Some(*i));
            }
        }
    }
    let mut out: Vec<usize> = worst.iter().filter_map(|w| w.1).collect();
    out.sort_unstable();
    out.dedup();
    out
}

#[derive(Clone)]
struct Judged {
    x: Vec<f64>,
    score: f64,
    binding: Option<String>,
}

/// The most frequent binding constraint among `judged`, with its share.
fn most_frequent_binding(judged: &[Judged]) -> Option<(String, f64)> {
    let mut counts: Vec<(String, usize)> = Vec::new();
    for j in judged {
        if let Some(b) = &j.binding {
            match counts.iter_mut().find(|(n, _)| n == b) {
                Some((_, c)) => *c += 1,
                None => counts.push((b.clone(), 1)),
            }
        }
    }
    counts.sort_by(|a, b| b.1.cmp(&a.1).then_with(|| a.0.cmp(&b.0)));
    counts
        .first()
        .map(|(n, c)| (n.clone(), *c as f64 / judged.len().max(1) as f64))
}

/// A caller's refusal of a candidate: why, and the layers it implicates
/// (their [`LayerPoints::layer`] numbers, e.g. the two ends of an arc-off
/// move), which join the subsample at full resolution.
#[derive(Debug, Clone, PartialEq)]
pub struct Refusal {
    /// Why (names the layer and point).
    pub reason: String,
    /// Layers implicated (may be empty).
    pub layers: Vec<usize>,
}

/// A caller's check of a plan feasible on every layer it has (e.g. the
/// program stage's), given the layers the plan is of (the subsample's while
/// screening, every layer at certification).
pub type Accept<'a> = &'a (dyn Fn(&Cell, &[LayerPoints], &Plan) -> Result<(), Refusal> + Sync);

/// Searches the placement of `layers` in `cell` within `bounds` [module doc].
///
/// # Errors
/// Bad input only: [`OptimiseError::InvalidPlacement`] naming the bound or
/// option, and the optimiser's errors for bad layers. A part that no
/// placement makes feasible is a [`Placement`] with `feasible == false` and
/// the binding constraint named.
pub fn place(
    cell: &Cell,
    layers: &[LayerPoints],
    bounds: &PlacementBounds,
    opts: &PlaceOptions,
) -> Result<Placement, OptimiseError> {
    place_with(cell, layers, bounds, opts, &|_, _, _| Ok(()))
}

/// [`place`] with the caller's check of each plan feasible on every layer:
/// a candidate it refuses is passed over for the next (its reason becomes
/// the binding constraint when every candidate is refused).
///
/// # Errors
/// As [`place`].
pub fn place_with(
    cell: &Cell,
    layers: &[LayerPoints],
    bounds: &PlacementBounds,
    opts: &PlaceOptions,
    accept: Accept<'_>,
) -> Result<Placement, OptimiseError> {
    let t0 = Instant::now();
    bounds.validate()?;
    if opts.samples == 0 || opts.layers < 2 || opts.points_per_layer < 3 || opts.rounds == 0 {
        return Err(OptimiseError::InvalidPlacement {
            field: "options".into(),
            reason: "samples >= 1, layers >= 2, points_per_layer >= 3 and rounds >= 1".into(),
        });
    }
    opts.optimise.validate()?;
    cell.validate()?;
    let mut times = PlaceTimes::default();
    let serial = OptimiseOptions {
        parallel: false,
        ..opts.optimise
    };
    let vars = &bounds.variables;
    let free: Vec<usize> = (0..vars.len()).filter(|k| vars[*k].is_free()).collect();
    let inside_keep_out = |x: &[f64]| {
        bounds
            .keep_out
            .is_some_and(|(lo, hi)| (0..3).all(|k| x[k] >= lo[k] && x[k] <= hi[k]))
    };
    let screen_refusal: std::sync::Mutex<Option<String>> = std::sync::Mutex::new(None);
    let judge = |x: Vec<f64>, sub: &[LayerPoints]| -> Judged {
        if inside_keep_out(&x) {
            return Judged {
                x,
                score: -2.0,
                binding: Some("keep-out box".into()),
            };
        }
        let c = placed_cell(cell, &x);
        match optimise(&c, sub, &serial) {
            Ok(plan) => {
                let s = score(&plan, &c);
                // Feasible on the subsample: the caller's check on it too (a
                // screen: the subsample's wall is sparse and its transits
                // join layers far apart).
                if s >= 0.0 {
                    if let Err(reason) = accept(&c, sub, &plan) {
                        if let Ok(mut first) = screen_refusal.lock() {
                            first.get_or_insert(reason.reason);
                        }
                        return Judged {
                            x,
                            score: -0.05,
                            binding: Some(SCREEN_REFUSAL.into()),
                        };
                    }
                }
                Judged {
                    score: s,
                    binding: binding_of(&plan),
                    x,
                }
            }
            Err(e) => Judged {
                x,
                score: -3.0,
                binding: Some(e.to_string()),
            },
        }
    };
    let clamp = |x: &mut Vec<f64>| {
        for (v, b) in x.iter_mut().zip(vars) {
            *v = v.clamp(b.lower, b.upper);
        }
    };
    let picks = coarse_picks(layers.len(), opts.layers);
    let mut full: BTreeSet<usize> = BTreeSet::new();
    let mut sub = subsample(layers, &picks, &full, opts.points_per_layer);

    // 1. Screening: the cell as given first, then a Halton set on the free
    // variables.
    let t = Instant::now();
    let current: Vec<f64> = vars
        .iter()
        .map(|v| v.current.clamp(v.lower, v.upper))
        .collect();
    const BASES: [usize; VARIABLES] = [2, 3, 5, 7, 11, 13, 17];
    let halton = |i: usize| {
        let mut x = current.clone();
        for (d, &k) in free.iter().enumerate() {
            let v = &vars[k];
            x[k] = v.lower + radical_inverse(i, BASES[d]) * (v.upper - v.lower);
        }
        x
    };
    let mut starts = vec![current.clone()];
    starts.extend((1..opts.samples).map(halton));
    let mut halton_next = opts.samples.max(1);
    let screened: Vec<Judged> = starts.into_par_iter().map(|x| judge(x, &sub)).collect();
    let mut candidates = screened.len();
    let feasible_fraction =
        screened.iter().filter(|j| j.score >= 0.0).count() as f64 / screened.len() as f64;
    let mut pool = screened.clone();
    pool.sort_by(|a, b| b.score.total_cmp(&a.score));
    times.screening_s += t.elapsed().as_secs_f64();

    let chunk = (4 * rayon::current_num_threads()).max(8);
    let mut hot: Vec<usize> = Vec::new();
    let mut refused: Vec<Vec<f64>> = Vec::new();
    let mut certified = 0;
    let mut rounds = 0;
    let mut chosen: Option<(Vec<f64>, Cell, Plan)> = None;
    // The best candidate that failed certification: x, cell, partial plan,
    // share of the checked layers infeasible.
    let mut failed: Option<(Vec<f64>, Cell, Plan, f64)> = None;
    let mut refusal: Option<String> = None;
    // The binding constraint every re-judged candidate shared, when the
    // rounds stopped on it.
    let mut stopped: Option<String> = None;
    'rounds: for round in 0..opts.rounds {
        rounds += 1;
        // 2. Compass search from the best few not refused; after a
        // feedback (a heavier subsample) from the best one only, with half
        // the evaluations.
        let t = Instant::now();
        let (n_starts, n_evaluations) = if round == 0 {
            (opts.refined.max(1), opts.refine_evaluations)
        } else {
            (1, opts.refine_evaluations / 2)
        };
        let starts: Vec<Judged> = pool
            .iter()
            .filter(|j| !refused.contains(&j.x))
            .take(n_starts)
            .cloned()
            .collect();
        for start in starts {
            let mut best = start;
            let mut step: Vec<f64> = vars.iter().map(|v| (v.upper - v.lower) / 8.0).collect();
            let mut evaluations = 0;
            while evaluations < n_evaluations && step.iter().any(|s| *s > 1e-3) {
                let trials: Vec<Vec<f64>> = free
                    .iter()
                    .filter(|k| step[**k] > 1e-3)
                    .flat_map(|&k| {
                        [-1.0, 1.0].into_iter().map({
                            let (best, step) = (&best, &step);
                            move |sign| {
                                let mut x = best.x.clone();
                                x[k] += sign * step[k];
                                x
                            }
                        })
                    })
                    .map(|mut x| {
                        clamp(&mut x);
                        x
                    })
                    .collect();
                if trials.is_empty() {
                    break;
                }
                evaluations += trials.len();
                candidates += trials.len();
                let results: Vec<Judged> = trials.into_par_iter().map(|x| judge(x, &sub)).collect();
                let top = results.into_iter().max_by(|a, b| {
                    a.score
                        .total_cmp(&b.score)
                        .then(std::cmp::Ordering::Greater)
                });
                match top {
                    Some(t) if t.score > best.score + 1e-9 && !refused.contains(&t.x) => best = t,
                    _ => step.iter_mut().for_each(|s| *s *= 0.5),
                }
            }
            if !pool.iter().any(|j| j.x == best.x) {
                pool.push(best);
            }
        }
        pool.sort_by(|a, b| b.score.total_cmp(&a.score));
        times.refinement_s += t.elapsed().as_secs_f64();

        // 3. Certification of the best feasible on the subsample, the cell
        // as given last among them (a part that plans where it stands keeps
        // a feasible placement).
        let t = Instant::now();
        let mut to_certify: Vec<Vec<f64>> = pool
            .iter()
            .filter(|j| j.score >= 0.0 && !refused.contains(&j.x))
            .take(opts.refined.max(1))
            .map(|j| j.x.clone())
            .collect();
        let current_score = pool
            .iter()
            .find(|j| j.x == current && !refused.contains(&j.x))
            .map(|j| j.score)
            .filter(|s| *s >= 0.0);
        if let Some(s) = current_score {
            to_certify.retain(|x| *x != current);
            // Kept unless clearly beaten: placing a placed cell again finds it.
            let best = pool
                .iter()
                .find(|j| !refused.contains(&j.x))
                .map_or(s, |j| j.score);
            if s >= best - KEEP_MARGIN {
                to_certify.insert(0, current.clone());
            } else {
                to_certify.push(current.clone());
            }
        }
        if to_certify.is_empty() {
            times.certification_s += t.elapsed().as_secs_f64();
            break;
        }
        let mut new_failures: Vec<usize> = Vec::new();
        let mut new_weakest: Vec<usize> = Vec::new();
        for x in to_certify {
            certified += 1;
            let c = placed_cell(cell, &x);
            let order = certification_order(layers.len(), &hot);
            let (planned, failing) = certify(&c, layers, &order, &serial, chunk)?;
            let checked = planned.len().max(1);
            let known: BTreeSet<usize> = picks.union(&full).copied().collect();
            let weakest = weakest_layers(&planned, &c, &known);
            let planned: Vec<LayerPlan> = planned.into_iter().map(|(_, l)| l).collect();
            let plan = Plan {
                transitions: transitions(&c, &planned),
                layers: planned,
                time_s: 0.0,
            };
            refused.push(x.clone());
            if failing.is_empty() {
                match accept(&c, layers, &plan) {
                    Ok(()) => {
                        chosen = Some((x, c, plan));
                        times.certification_s += t.elapsed().as_secs_f64();
                        break 'rounds;
                    }
                    Err(r) => {
                        refusal.get_or_insert(r.reason);
                        let named: Vec<usize> = r
                            .layers
                            .iter()
                            .filter_map(|n| layers.iter().position(|l| l.layer == *n))
                            .collect();
                        if named.is_empty() && weakest.is_empty() {
                            continue;
                        }
                        // Those layers join the subsample: its screen then
                        // sees the move refused; and the layers that bind
                        // the margins, which the subsample missed (a
                        // refused transit follows a law pressed against a
                        // stop).
                        new_failures = named;
                        new_weakest = weakest;
                        break;
                    }
                }
            }
            let share = failing.len() as f64 / checked as f64;
            if failed.is_none() {
                failed = Some((x, c, plan, share));
            }
            new_failures = failing;
            new_weakest = weakest;
            break;
        }
        times.certification_s += t.elapsed().as_secs_f64();
        if new_failures.is_empty() && new_weakest.is_empty() {
            continue;
        }
        // 4. Feedback: the failing layers (spread, at most
        // `feedback_layers`) join the subsample at full resolution; the
        // best candidates are judged again on it.
        let t = Instant::now();
        new_failures.sort_unstable();
        let step = new_failures
            .len()
            .div_ceil(opts.feedback_layers.max(1))
            .max(1);
        for &i in new_failures.iter().step_by(step).chain(&new_weakest) {
            full.insert(i);
        }
        for &i in new_failures.iter().chain(&new_weakest) {
            if !hot.contains(&i) {
                hot.push(i);
            }
        }
        sub = subsample(layers, &picks, &full, opts.points_per_layer);
        let keep = (4 * opts.refined).max(8);
        let mut again: Vec<Vec<f64>> = pool
            .iter()
            .filter(|j| !refused.contains(&j.x))
            .take(keep)
            .map(|j| j.x.clone())
            .collect();
        if !again.contains(&current) {
            again.push(current.clone());
        }
        candidates += again.len();
        pool = again.into_par_iter().map(|x| judge(x, &sub)).collect();
        // None of the best is feasible on the heavier subsample and one
        // constraint binds them all (e.g. a joint speed at the cusps of the
        // layers that joined it): the search stops there; more candidates
        // and refinement would meet the same wall.
        let first = pool.first().and_then(|j| j.binding.clone());
        if first.is_some()
            && pool
                .iter()
                .all(|j| j.score < 0.0 && j.binding == first && j.score > -2.0)
        {
            times.screening_s += t.elapsed().as_secs_f64();
            stopped = first;
            break;
        }
        // Few of the best left feasible on the heavier subsample: screen a
        // fresh batch of the Halton sequence on it (the subsample now holds
        // what made the certified ones fail, so the batch is judged on it).
        let feasible = pool.iter().filter(|j| j.score >= 0.0).count();
        if feasible < opts.refined.max(2) && !free.is_empty() {
            let batch = (opts.samples / 2).max(1);
            let fresh: Vec<Vec<f64>> = (halton_next..halton_next + batch).map(halton).collect();
            halton_next += batch;
            candidates += fresh.len();
            pool.extend(
                fresh
                    .into_par_iter()
                    .map(|x| judge(x, &sub))
                    .collect::<Vec<_>>(),
            );
        }
        pool.sort_by(|a, b| b.score.total_cmp(&a.score));
        times.screening_s += t.elapsed().as_secs_f64();
    }

    // Last resort: the cell as given, when feasible on the subsample and not
    // yet certified (a part that plans where it stands keeps a placement).
    if chosen.is_none() && !refused.contains(&current) {
        let c = placed_cell(cell, &current);
        if optimise(&c, &sub, &serial).is_ok_and(|p| p.is_feasible()) {
            let t = Instant::now();
            certified += 1;
            let order = certification_order(layers.len(), &hot);
            let (planned, failing) = certify(&c, layers, &order, &serial, chunk)?;
            let planned: Vec<LayerPlan> = planned.into_iter().map(|(_, l)| l).collect();
            let plan = Plan {
                transitions: transitions(&c, &planned),
                layers: planned,
                time_s: 0.0,
            };
            if failing.is_empty() {
                match accept(&c, layers, &plan) {
                    Ok(()) => chosen = Some((current.clone(), c, plan)),
                    Err(r) => {
                        refusal.get_or_insert(r.reason);
                    }
                }
            }
            times.certification_s += t.elapsed().as_secs_f64();
        }
    }
    let before_cell = placed_cell(cell, &current);
    let margins_before = match optimise(&before_cell, &sub, &serial) {
        Ok(p) => margins(&p, &before_cell),
        Err(_) => Margins::default(),
    };
    let (values, placed, plan, feasible, binding) = match (chosen, failed) {
        (Some((x, c, plan)), _) => (x, c, plan, true, None),
        (None, Some((x, c, plan, share))) => {
            // The best candidate's failure on the full path; and, when
            // others were refused by the caller's check, that reason too
            // (it may be what bound the rest of the search).
            let b = binding_of(&plan).map(|b| {
                let also = refusal
                    .as_ref()
                    .map(|r| format!("; another candidate was refused by the program check: {r}"))
                    .unwrap_or_default();
                (format!("{b} (on the full path){also}"), share)
            });
            (x, c, plan, false, b)
        }
        (None, None) => {
            let best = pool
                .iter()
                .find(|j| !refused.contains(&j.x))
                .or(pool.first())
                .map(|j| j.x.clone())
                .unwrap_or(current);
            let c = placed_cell(cell, &best);
            let plan = optimise(&c, &sub, &serial)?;
            let b = match refusal {
                Some(r) => Some((format!("{r} (program check)"), 1.0)),
                None => most_frequent_binding(&screened).map(|(b, share)| {
                    let first = screen_refusal.lock().ok().and_then(|f| f.clone());
                    match first {
                        Some(r) if b == SCREEN_REFUSAL => (format!("{b}, e.g. {r}"), share),
                        _ => (b, share),
                    }
                }),
            };
            (best, c, plan, false, b)
        }
    };
    Ok(Placement {
        feasible,
        margins: margins(&plan, &placed),
        margins_before,
        values,
        cell: placed,
        candidates,
        feasible_fraction,
        certified,
        rounds,
        stopped_on: stopped,
        subsample_layers: (sub.len(), full.len()),
        binding,
        plan,
        times,
        time_s: t0.elapsed().as_secs_f64(),
    })
}

#[cfg(test)]
mod tests {
    use super::reach_margin_mm;
    use crate::math::{Isometry3, Translation3, Vector3};
    use crate::robot::ik::Configuration;
    use crate::robot::RobotModel;

    /// At zero joints the SPEC §6.1 chain puts the flange at (1085, 0, 1040)
    /// mm with the approach along +X, so the wrist centre at (985, 0, 1040),
    /// 1333.7 mm from the J2 axis at (150, 0, 0); the arm spans
    /// |790 − 871.6| .. 790 + 871.6 mm (871.6 = hypot(835, 250)).
    #[test]
    fn the_reach_margin_at_zero_joints_is_the_specs_closed_form() {
        let robot = RobotModel::arcmate_120ic_nominal();
        let k = 835f64.hypot(250.0);
        let d = 835f64.hypot(1040.0);
        let expected = (d - (790.0 - k).abs()).min(790.0 + k - d);
        let got = reach_margin_mm(&robot, &[0.0; 6]);
        assert!((got - expected).abs() < 1e-9, "{got} vs {expected}");
        assert!((expected - 327.9).abs() < 0.1);
    }

    /// A wrist centre placed `m` mm inside the stretched arm's reach (the
    /// flange pose of zero joints moved along X) comes back from the inverse
    /// kinematics with a margin of `m`; 1 mm beyond, the inverse refuses it.
    #[test]
    fn the_reach_margin_agrees_with_the_inverse_kinematics_reach() {
        let robot = RobotModel::arcmate_120ic_nominal();
        let home = robot.flange_pose(&[0.0; 6]);
        let arm_max = 790.0 + 835f64.hypot(250.0);
        for m in [100.0, 10.0, 1.0] {
            // the wrist centre at (150 + x, 0, 1040): distance hypot(x, 1040)
            let x = ((arm_max - m).powi(2) - 1040f64.powi(2)).sqrt();
            let shift = Vector3::new(x - 835.0, 0.0, 0.0);
            let pose = Isometry3::from_parts(
                Translation3::from(home.translation.vector + shift),
                home.rotation,
            );
            let q = robot.inverse(&pose, Configuration::NUT).unwrap();
            let got = reach_margin_mm(&robot, &q);
            assert!((got - m).abs() < 1e-6, "{got} vs {m}");
        }
        let x = ((arm_max + 1.0).powi(2) - 1040f64.powi(2)).sqrt();
        let pose = Isometry3::from_parts(
            Translation3::from(home.translation.vector + Vector3::new(x - 835.0, 0.0, 0.0)),
            home.rotation,
        );
        assert!(robot.inverse(&pose, Configuration::NUT).is_err());
    }
}
