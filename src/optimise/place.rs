//! **Placement of the part in the cell** (beyond the thesis, which moved the
//! deposition point by hand, §3.3 "second position"). Takes a cell, the
//! layers of a path (part frame) and bounds on the cell's placement variables
//! — part carried: the deposition point `D_R` (robot base frame, mm) and the
//! rotation of the part's mount about the flange axis (rad); torch carried:
//! the positioner's position (mm) and its rotation about the vertical (rad) —
//! and returns the placement that makes every layer feasible with the widest
//! worst-layer margin (joint-limit distance, speed headroom, dexterity).
//!
//! The search is a coarse global sampling of the box (a Halton sequence),
//! each candidate judged by the `R_Z` optimisation of SPEC §7 on a subsample
//! of the layers and points, in parallel; then a compass search refines the
//! best candidates on the same subsample; the winner is certified by the full
//! optimisation of every point of every layer.

use std::f64::consts::PI;
use std::time::Instant;

use rayon::prelude::*;

use crate::math::{Isometry3, Point3, Translation3, UnitQuaternion, Vector3};
use crate::optimise::{optimise, LayerPoints, LayerStatus, OptimiseError, OptimiseOptions, Plan};
use crate::robot::Cell;

/// One placement variable: its name (as in the cell file), its bounds and
/// the cell's current value (mm for positions, rad for rotations).
#[derive(Debug, Clone, PartialEq)]
pub struct PlacementVariable {
    /// Name, e.g. `deposition_point_mm.x`, `flange_rotation`, `positioner.x`.
    pub name: &'static str,
    /// Lower bound (mm or rad).
    pub lower: f64,
    /// Upper bound (mm or rad); equal to `lower` for a fixed variable.
    pub upper: f64,
    /// The value in the cell as given (mm or rad).
    pub current: f64,
}

/// Bounds of the search and a keep-out box (robot base frame, mm): a
/// deposition point or positioner origin inside the box is refused (the
/// robot's base, a wall, the wire feeder).
#[derive(Debug, Clone, PartialEq)]
pub struct PlacementBounds {
    /// The variables: part carried `[D_R x, y, z, flange rotation]`, torch
    /// carried `[positioner x, y, z, rotation about the vertical]`.
    pub variables: Vec<PlacementVariable>,
    /// Keep-out box `(min, max)`, robot base frame (mm).
    pub keep_out: Option<([f64; 3], [f64; 3])>,
}

impl PlacementBounds {
    /// Default bounds around `cell`'s placement: ±`half_box_mm` on each
    /// coordinate of the deposition point (positioner), the full turn on the
    /// rotation, and the robot's base keep-out: a vertical cylinder's bounding
    /// box of half-width 250 mm about the base axis below the shoulder.
    pub fn around(cell: &Cell, half_box_mm: f64) -> Self {
        let names_pc = [
            "deposition_point_mm.x",
            "deposition_point_mm.y",
            "deposition_point_mm.z",
        ];
        let names_tc = ["positioner.x", "positioner.y", "positioner.z"];
        let (p, names, rot_name): (Point3, [&'static str; 3], &'static str) = match cell {
            Cell::PartCarried(c) => (c.deposition_point_mm, names_pc, "flange_rotation"),
            Cell::TorchCarried(c) => (
                Point3::from(c.base_from_positioner.translation.vector),
                names_tc,
                "positioner.rotation",
            ),
        };
        let mut variables: Vec<PlacementVariable> = (0..3)
            .map(|k| PlacementVariable {
                name: names[k],
                lower: p[k] - half_box_mm,
                upper: p[k] + half_box_mm,
                current: p[k],
            })
            .collect();
        variables.push(PlacementVariable {
            name: rot_name,
            lower: -PI,
            upper: PI,
            current: 0.0,
        });
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
            if v.name.ends_with("rotation") && (v.upper - v.lower) > 2.0 * PI + 1e-9 {
                return Err(OptimiseError::InvalidPlacement {
                    field: v.name.to_string(),
                    reason: "a rotation range wider than a turn".into(),
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
    /// Coarse candidates sampled in the box.
    pub samples: usize,
    /// Layers of the subsample (evenly spread, first and last included).
    pub layers: usize,
    /// Points per layer of the subsample.
    pub points_per_layer: usize,
    /// Candidates refined by the compass search.
    pub refined: usize,
    /// Evaluations of each compass search.
    pub refine_evaluations: usize,
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
    /// Layers infeasible.
    pub infeasible_layers: usize,
}

/// What [`place`] found.
#[derive(Debug, Clone)]
pub struct Placement {
    /// The cell with the placement found (or the best tried when none is
    /// feasible).
    pub cell: Cell,
    /// The variables' values (mm, rad), in the order of the bounds.
    pub values: Vec<f64>,
    /// `true` when the full plan in the placed cell is feasible.
    pub feasible: bool,
    /// Margins of the full plan in the placed cell.
    pub margins: Margins,
    /// Margins of the full plan in the cell as given.
    pub margins_before: Margins,
    /// Candidates evaluated on the subsample.
    pub candidates: usize,
    /// Fraction of them feasible on the subsample.
    pub feasible_fraction: f64,
    /// Why no placement was found: when no candidate was feasible on the
    /// subsample, the constraint that bound most of them (the first
    /// infeasible layer's) with the share of candidates it bound; when the
    /// best failed on the full path, the full plan's first binding
    /// constraint with the share of its layers that are infeasible.
    pub binding: Option<(String, f64)>,
    /// The full plan in the placed cell.
    pub plan: Plan,
    /// Wall time (s).
    pub time_s: f64,
}

/// The cell with the placement `x` (see [`PlacementBounds::variables`]).
pub fn placed_cell(cell: &Cell, x: &[f64]) -> Cell {
    let mut out = cell.clone();
    match &mut out {
        Cell::PartCarried(c) => {
            c.deposition_point_mm = Point3::new(x[0], x[1], x[2]);
            let turn = Isometry3::from_parts(
                Translation3::identity(),
                UnitQuaternion::from_axis_angle(&Vector3::z_axis(), x[3]),
            );
            c.flange_from_part = turn * c.flange_from_part;
        }
        Cell::TorchCarried(c) => {
            let turn = UnitQuaternion::from_axis_angle(&Vector3::z_axis(), x[3]);
            c.base_from_positioner = Isometry3::from_parts(
                Translation3::new(x[0], x[1], x[2]),
                turn * c.base_from_positioner.rotation,
            );
        }
    }
    out
}

/// Every `stride`-th layer (first and last kept), each with every `k`-th point.
fn subsample(layers: &[LayerPoints], n_layers: usize, n_points: usize) -> Vec<LayerPoints> {
    let n = layers.len();
    let picks: Vec<usize> = if n <= n_layers.max(2) {
        (0..n).collect()
    } else {
        let mut v: Vec<usize> = (0..n_layers)
            .map(|i| (i as f64 * (n - 1) as f64 / (n_layers - 1) as f64).round() as usize)
            .collect();
        v.dedup();
        v
    };
    picks
        .into_iter()
        .map(|i| {
            let l = &layers[i];
            let k = l.points.len().div_ceil(n_points.max(3)).max(1);
            LayerPoints {
                layer: l.layer,
                points: l.points.iter().step_by(k).copied().collect(),
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
        infeasible_layers: 0,
    };
    for l in &plan.layers {
        if !l.status.is_feasible() {
            m.infeasible_layers += 1;
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
    ] {
        if !v.is_finite() {
            *v = 0.0;
        }
    }
    m
}

/// One scalar to maximise: for a feasible plan the worse of the joint-limit
/// and speed margins, each scaled to 1 at a comfortable value (10° from a
/// stop, 20 % speed headroom) and capped at 1, plus a small reward for
/// dexterity (the floor itself is a constraint of every layer; dexterity
/// mixes mm and rad, its values are ~1e-3 on our arms, so it only breaks
/// ties); for an infeasible plan minus the share of infeasible layers minus
/// a bounded measure of the violations.
fn score(plan: &Plan, cell: &Cell) -> f64 {
    let m = margins(plan, cell);
    if m.infeasible_layers == 0 {
        let a = (m.joint_limit_deg / 10.0).min(1.0);
        let b = (m.speed_headroom / 0.2).min(1.0);
        let c = (m.dexterity / 2e-3).min(1.0);
        return a.min(b).max(0.0) + 0.01 * c.max(0.0);
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

struct Judged {
    x: Vec<f64>,
    score: f64,
    binding: Option<String>,
}

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
    let t0 = Instant::now();
    bounds.validate()?;
    if bounds.variables.len() != 4 {
        return Err(OptimiseError::InvalidPlacement {
            field: "variables".into(),
            reason: format!("4 variables expected, got {}", bounds.variables.len()),
        });
    }
    if opts.samples == 0 || opts.layers < 2 || opts.points_per_layer < 3 {
        return Err(OptimiseError::InvalidPlacement {
            field: "options".into(),
            reason: "samples >= 1, layers >= 2 and points_per_layer >= 3".into(),
        });
    }
    opts.optimise.validate()?;
    let sub = subsample(layers, opts.layers, opts.points_per_layer);
    let serial = OptimiseOptions {
        parallel: false,
        ..opts.optimise
    };
    let vars = &bounds.variables;
    let inside_keep_out = |x: &[f64]| {
        bounds
            .keep_out
            .is_some_and(|(lo, hi)| (0..3).all(|k| x[k] >= lo[k] && x[k] <= hi[k]))
    };
    let judge = |x: Vec<f64>| -> Judged {
        if inside_keep_out(&x) {
            return Judged {
                x,
                score: -2.0,
                binding: Some("keep-out box".into()),
            };
        }
        let c = placed_cell(cell, &x);
        match optimise(&c, &sub, &serial) {
            Ok(plan) => Judged {
                score: score(&plan, &c),
                binding: binding_of(&plan),
                x,
            },
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
    // Coarse global sampling: the cell as given first, then a Halton set.
    let current: Vec<f64> = vars
        .iter()
        .map(|v| v.current.clamp(v.lower, v.upper))
        .collect();
    let mut starts = vec![current];
    for i in 1..opts.samples {
        starts.push(
            vars.iter()
                .zip([2, 3, 5, 7])
                .map(|(v, base)| v.lower + radical_inverse(i, base) * (v.upper - v.lower))
                .collect(),
        );
    }
    let mut judged: Vec<Judged> = starts.into_par_iter().map(judge).collect();
    let mut candidates = judged.len();
    let feasible_count = judged.iter().filter(|j| j.score >= 0.0).count();
    judged.sort_by(|a, b| b.score.total_cmp(&a.score));
    // Binding constraint over the candidates (most frequent).
    let binding = if feasible_count == 0 {
        let mut counts: Vec<(String, usize)> = Vec::new();
        for j in &judged {
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
            .map(|(n, c)| (n.clone(), *c as f64 / judged.len() as f64))
    } else {
        None
    };
    // Compass search from the best few.
    let mut refined: Vec<Judged> = Vec::new();
    for start in judged.into_iter().take(opts.refined.max(1)) {
        let mut best = start;
        let mut step: Vec<f64> = vars.iter().map(|v| (v.upper - v.lower) / 8.0).collect();
        let mut evaluations = 0;
        while evaluations < opts.refine_evaluations && step.iter().any(|s| *s > 1e-3) {
            let trials: Vec<Vec<f64>> = (0..vars.len())
                .filter(|k| step[*k] > 0.0)
                .flat_map(|k| {
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
            evaluations += trials.len();
            candidates += trials.len();
            let results: Vec<Judged> = trials.into_par_iter().map(judge).collect();
            let top = results.into_iter().max_by(|a, b| {
                a.score
                    .total_cmp(&b.score)
                    .then(std::cmp::Ordering::Greater)
            });
            match top {
                Some(t) if t.score > best.score + 1e-9 => best = t,
                _ => step.iter_mut().for_each(|s| *s *= 0.5),
            }
        }
        refined.push(best);
    }
    refined.sort_by(|a, b| b.score.total_cmp(&a.score));
    // Certify on every point; fall back to the next candidate.
    let before_plan = optimise(cell, layers, &opts.optimise)?;
    let margins_before = margins(&before_plan, cell);
    let mut chosen: Option<(Vec<f64>, Cell, Plan)> = None;
    for r in &refined {
        let c = placed_cell(cell, &r.x);
        let plan = optimise(&c, layers, &opts.optimise)?;
        let ok = plan.is_feasible();
        if chosen.is_none() || ok {
            chosen = Some((r.x.clone(), c, plan));
        }
        if ok {
            break;
        }
    }
    let (values, placed, plan) = chosen.unwrap_or_else(|| {
        let x: Vec<f64> = vars.iter().map(|v| v.current).collect();
        (x, cell.clone(), before_plan.clone())
    });
    let m = margins(&plan, &placed);
    // Not feasible on every point: name what binds the full plan.
    let binding = match (plan.is_feasible(), binding) {
        (false, None) => binding_of(&plan).map(|b| {
            let share = plan.infeasible_layers().count() as f64 / plan.layers.len().max(1) as f64;
            (format!("{b} (on the full path)"), share)
        }),
        (_, b) => b,
    };
    Ok(Placement {
        feasible: plan.is_feasible(),
        margins: m,
        margins_before,
        values,
        cell: placed,
        candidates,
        feasible_fraction: feasible_count as f64 / opts.samples as f64,
        binding,
        plan,
        time_s: t0.elapsed().as_secs_f64(),
    })
}
