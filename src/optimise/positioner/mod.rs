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
//! [`Positioner::positioner_from_table_derivatives`](crate::robot::positioner::Positioner::positioner_from_table_derivatives)); the QPs are the
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

mod grid;
mod options;
mod outcome;
mod problem;
mod rate;
mod sqp;
mod starts;
#[cfg(test)]
mod tests;

pub use grid::unreachable_point;
pub use options::{PositionerMode, PositionerOptions, PositionerQp};
pub use outcome::{PositionerBinding, PositionerLaw, PositionerSeed};
pub use problem::ArmRow;
pub use rate::required_rotation_rate;
pub use starts::vertical_joints;

use crate::math::Point3;
use crate::optimise::parameterisation::{cylindrical_angles, turns_about_z};
use crate::robot::cell::{CellPoint, TorchCarriedCell};
use crate::robot::positioner::PositionerJoints;

use grid::GRID_CELLS_DEG;
use problem::{check, LawProblem};
use starts::solve_bases;

/// Positioner laws of one layer [module doc], each point reached at its
/// own travel speed ([`CellPoint::travel_speed_mm_s`]); `margin_rad`: how far
/// inside its travel each axis stays (rad); `q8_hint`: the turn the layer
/// should start near (rad; the previous layer's last).
pub fn positioner_law(
    cell: &TorchCarriedCell,
    points: &[CellPoint],
    margin_rad: f64,
    q8_hint: f64,
    opts: &PositionerOptions,
) -> PositionerLaw {
    solve_law(cell, points, margin_rad, q8_hint, opts, &[], None)
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
    margin_rad: f64,
    opts: &PositionerOptions,
    arm: &[ArmRow],
    start: &[PositionerJoints],
) -> PositionerLaw {
    let hint = start.first().map_or(0.0, |q| q[1]);
    solve_law(
        cell,
        points,
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
    margin_rad: f64,
    q8_hint: f64,
    opts: &PositionerOptions,
    arm: &[ArmRow],
    start: Option<&[PositionerJoints]>,
) -> PositionerLaw {
    let mut pb = LawProblem::new(cell, points, margin_rad, opts, arm);
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
