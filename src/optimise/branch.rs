//! One layer: its IK branch chosen from the seeds' ranking [SPEC §7], the
//! branch optimised with the layer's `R_Z` law, the next branches tried
//! while the layer stays infeasible, and the layer's plan made from the best.

use std::time::Instant;

use super::branch_types::{Anchor, BranchOutcome, Degrees};
use super::parameterisation::Basis;
use super::point_by_point::point_by_point;
use super::problem::{LayerProblem, PointFailure};
use super::report::finish;
use super::seed::Seed;
use super::setup::LayerSetup;
use super::{degree, sqp, subsample, LayerPoints};
use super::{
    ConfigurationChoice, ConfigurationChoiceReport, LayerPlan, LayerQuality, LayerStatus,
    ObjectiveReport, OptimiseOptions, Parameterisation, PlannedPoint, SolvedRzLaw, SolverReport,
};
use crate::math::tol;
use crate::robot::cell::CellLayout;
use crate::robot::ik::Configuration;

/// One layer (or spiral turn, `anchor` given); also returns the dexterity
/// floor at its last point (the next spiral turn starts from it).
pub(super) fn optimise_layer(
    cell: &CellLayout,
    lp: &LayerPoints,
    opts: &OptimiseOptions,
    anchor: Option<Anchor>,
) -> (LayerPlan, f64) {
    let t0 = Instant::now();
    let setup = LayerSetup::new(cell, &lp.points, opts, anchor);

    // 1. branches
    let fixed = matches!(opts.parameterisation, Parameterisation::Fixed { .. });
    let candidates: Vec<Configuration> = if let Some(a) = anchor {
        vec![a.configuration]
    } else if fixed || opts.configuration == ConfigurationChoice::Cell {
        vec![cell.configuration()]
    } else {
        Configuration::ALL.to_vec()
    };
    let mut ranked: Vec<(Configuration, Seed)> = candidates
        .iter()
        .copied()
        .zip(setup.best_seeds(&candidates))
        .collect();
    let own = cell.configuration();
    ranked.sort_by(|a, b| {
        let key = |x: &(Configuration, Seed)| {
            let bonus = if x.0 == own { 1.0 / 1.5 } else { 1.0 };
            (x.1.violation, x.1.centring * bonus)
        };
        let (va, ca) = key(a);
        let (vb, cb) = key(b);
        va.total_cmp(&vb).then(ca.total_cmp(&cb))
    });
    let ranking: Vec<(Configuration, f64, f64)> = ranked
        .iter()
        .map(|(c, s)| {
            (
                *c,
                s.violation,
                if s.violation.is_finite() {
                    s.centring
                } else {
                    f64::INFINITY
                },
            )
        })
        .collect();

    // 2. optimise the best branch, then the next ones while infeasible
    let mut outcomes: Vec<BranchOutcome> = Vec::new();
    for (cfg, seed) in &ranked {
        if !seed.violation.is_finite() && !outcomes.is_empty() {
            break;
        }
        let out = optimise_branch(&setup, *cfg, seed);
        let done = out.eval.is_ok() && out.violation <= 0.0;
        outcomes.push(out);
        if done || fixed {
            break;
        }
    }
    let branches_tried = outcomes.len();
    let (iterations, qp_solves, qp_failures) = outcomes.iter().fold((0, 0, 0), |a, o| {
        (a.0 + o.iterations, a.1 + o.qp_solves, a.2 + o.qp_failures)
    });
    // keep the first feasible, else the least violating with a solution
    let pick = outcomes
        .iter()
        .position(|o| o.eval.is_ok() && o.violation <= 0.0)
        .or_else(|| {
            outcomes
                .iter()
                .enumerate()
                .filter(|(_, o)| o.eval.is_ok())
                .min_by(|a, b| a.1.violation.total_cmp(&b.1.violation))
                .map(|(i, _)| i)
        })
        .unwrap_or(0);
    let out = outcomes.swap_remove(pick);
    let chosen = out.cfg;
    let samples = out.samples;
    let reason = match anchor {
        Some(_) => format!("{chosen}: the previous spiral turn's branch (the arc does not stop)"),
        None => choice_reason(&ranking, chosen, own, branches_tried, fixed, opts),
    };
    let configuration = ConfigurationChoiceReport {
        chosen,
        ranking,
        reason,
    };
    let solver = |time_s| SolverReport {
        iterations,
        qp_solves,
        qp_failures,
        branches_tried,
        samples,
        time_s,
    };
    let end_floor = out.problem_psi.last().copied().unwrap_or(0.0);
    let eval = match out.eval {
        Ok(e) => e,
        Err(f) => {
            let plan = LayerPlan {
                layer: lp.layer,
                status: LayerStatus::NoSolution {
                    point: f.point,
                    error: f.error,
                },
                configuration,
                law: out.law,
                // one point per input point, without joints, so that every
                // writer and the report see the layer's shape
                points: lp
                    .points
                    .iter()
                    .map(|cp| PlannedPoint {
                        r_z: 0.0,
                        joints: None,
                        positioner: cp.positioner,
                        dexterity: 0.0,
                    })
                    .collect(),
                positioner: None,
                objective: ObjectiveReport::default(),
                quality: LayerQuality::default(),
                solver: solver(t0.elapsed().as_secs_f64()),
                violations: Vec::new(),
                solved: None,
            };
            return (plan, end_floor);
        }
    };
    let problem = setup.problem(chosen, out.problem_psi);
    let plan = finish(
        &setup,
        lp.layer,
        &problem,
        eval,
        out.law,
        out.converged,
        out.iterations,
        fixed,
        configuration,
        solver,
        t0,
    );
    (plan, end_floor)
}

fn choice_reason(
    ranking: &[(Configuration, f64, f64)],
    chosen: Configuration,
    own: Configuration,
    tried: usize,
    fixed: bool,
    opts: &OptimiseOptions,
) -> String {
    if fixed {
        return format!("R_Z fixed (no optimisation): the cell's branch {own}");
    }
    if opts.configuration == ConfigurationChoice::Cell {
        return format!("the cell's branch {own}, as asked");
    }
    let r = ranking.iter().find(|r| r.0 == chosen);
    let mut s = match r {
        Some((_, v, c)) if *v <= 0.0 => format!(
            "{chosen}: a seed keeps every joint inside its travel and it is the most centred \
             of those (mean Σ((q − mid)/range)² = {c:.4})"
        ),
        Some((_, v, _)) if v.is_finite() => format!(
            "{chosen}: no branch has a feasible seed; this one violates least ({:.3}°)",
            v.to_degrees()
        ),
        _ => format!("{chosen}"),
    };
    if chosen == own {
        s.push_str("; it is the cell's branch");
    } else if let Some((_, v, c)) = ranking.iter().find(|r| r.0 == own) {
        if v.is_finite() {
            s.push_str(&format!(
                "; the cell's branch {own} scores violation {:.3}°, centring {c:.4}",
                v.to_degrees()
            ));
        } else {
            s.push_str(&format!("; the cell's branch {own} has no solution here"));
        }
    }
    if tried > 1 {
        s.push_str(&format!(
            "; {tried} branches optimised (the better-ranked ones ended infeasible)"
        ));
    }
    s
}

fn optimise_branch(setup: &LayerSetup, cfg: Configuration, seed: &Seed) -> BranchOutcome {
    let opts = setup.opts;
    let p = setup.points.len();
    let mut psi = setup.floors(cfg);
    if let Some(a) = setup.anchor {
        // A continuous floor along the spiral: from the previous turn's at
        // the shared point to this turn's own at its last point. A step at
        // the junction would leave the shared point, held where the
        // previous turn put it (on its floor, when that was active), below
        // the new floor, and the turn would have to bend R_Z steeply away
        // from it.
        let n = (p - 1).max(1) as f64;
        for (m, x) in psi.iter_mut().enumerate() {
            *x = a.floor + (*x - a.floor) * m as f64 / n;
        }
    }
    if setup.anchor.is_some() {
        // the shared point of a spiral turn was checked against the
        // previous turn's floor, and cannot move
        psi[0] = 0.0;
    }
    let problem = setup.problem(cfg, psi.clone());
    let mut outcome = BranchOutcome {
        cfg,
        eval: Err(PointFailure {
            point: 0,
            error: crate::robot::RobotError::NonFinite { what: "not solved" },
        }),
        law: SolvedRzLaw::PointByPoint,
        violation: f64::INFINITY,
        converged: true,
        iterations: 0,
        qp_solves: 0,
        qp_failures: 0,
        problem_psi: psi,
        samples: None,
    };
    match opts.parameterisation {
        Parameterisation::Fixed { r_z_rad } => {
            outcome.law = SolvedRzLaw::Fixed { r_z_rad };
            outcome.eval = problem.evaluate(&vec![r_z_rad; p]);
        }
        Parameterisation::PointByPoint => {
            outcome.law = SolvedRzLaw::PointByPoint;
            outcome.eval = point_by_point(&problem, seed.r[0], setup.anchor.map(|a| a.r_z));
        }
        Parameterisation::SmoothingSpline { smoothness } => {
            outcome.law = SolvedRzLaw::SmoothingSpline;
            let basis = Basis::PerPoint { points: p };
            let scale = scale_of(&problem, &seed.r, smoothness);
            match sqp::solve(
                &problem,
                &basis,
                seed.r.clone(),
                None,
                smoothness,
                scale,
                &opts.sqp,
            ) {
                Ok(res) => {
                    outcome.iterations = res.iterations;
                    outcome.qp_solves = res.qp_solves;
                    outcome.qp_failures = res.qp_failures;
                    outcome.converged = res.converged;
                    outcome.eval = Ok(res.eval);
                }
                Err(f) => outcome.eval = Err(f),
            }
        }
        Parameterisation::Polynomial {
            max_degree,
            stop_relative_gain,
            ..
        } => raise_degrees(
            setup,
            &problem,
            seed,
            max_degree,
            stop_relative_gain,
            &mut outcome,
        ),
    }
    if let Ok(e) = &outcome.eval {
        outcome.violation = problem.max_violation_of_bounds(e);
    }
    outcome
}

/// Objective scale of a layer: its value at the seed (bounded below).
fn scale_of(problem: &LayerProblem, r: &[f64], smoothness: f64) -> f64 {
    match problem.evaluate(r) {
        Ok(e) => problem
            .objective(&e, smoothness)
            .max(tol::OBJECTIVE_SCALE_FLOOR),
        Err(_) => 1.0,
    }
}

/// Raises the degree of the polynomial `R_Z` law of `setup`'s layer from
/// `seed`'s up to `max_degree` while the relative objective gain is at least
/// `stop_relative_gain`, and records the best degree's law and evaluation
/// (and the SQP's counts) in `outcome`. Spiral turns hold `R_Z` on their
/// shared point (degree at least 1).
pub(super) fn raise_degrees(
    setup: &LayerSetup,
    problem: &LayerProblem,
    seed: &Seed,
    max_degree: usize,
    stop_relative_gain: f64,
    outcome: &mut BranchOutcome,
) {
    let p = setup.points.len();
    let x: Vec<f64> = if setup.cylindrical {
        setup.theta.clone()
    } else {
        (0..p).map(|m| m as f64).collect()
    };
    let (start, basis) = match setup.anchor {
        // continuity: R_Z held on the shared point, degree ≥ 1
        Some(a) => {
            let d = seed.degree.min(max_degree).max(1);
            (d, Basis::anchored_polynomial(&x, d, a.r_z))
        }
        None => {
            let d = seed.degree.min(max_degree);
            (d, Basis::polynomial(&x, d + 1))
        }
    };
    let c = basis.fit(&seed.r);
    let degrees = Degrees {
        start,
        max: max_degree,
        stop_relative_gain,
    };
    if subsample::solve(setup, problem, &basis, &c, &degrees, outcome) {
        return;
    }
    match degree::degree_loop(problem, basis, c, &degrees, &setup.opts.sqp, outcome) {
        Ok((best, history)) => degree::record(setup, best, history, outcome),
        Err(f) => outcome.eval = Err(f),
    }
}
