//! Unit tests of the per-layer problem: the analytic derivatives the SQP
//! linearises with (`dq/dR_Z`, the constraint slopes, the objective's
//! gradient through the basis) against central finite differences of the
//! problem's own values, on a layer of the hemisphere sample part
//! (`parts/hemisphere.toml`: `R_s` = 45 mm on a plate, `Delta` = 5 mm,
//! 500 points a layer) in the ROBOWAM part-carried cell
//! (`parts/cells/robowam_part_carried.toml`), at the `R_Z` the optimiser
//! chose for it.

use std::collections::BTreeMap;
use std::sync::Arc;

use super::parameterisation::Basis;
use super::problem::{Evaluation, LayerProblem};
use super::setup::LayerSetup;
use super::*;
use crate::geometry::guide::{Expression, Line};
use crate::geometry::{FrameMethod, ProfileLaw, Substrate, Tube, TubeRange};
use crate::math::{Isometry3, Point3, Vector3};
use crate::path::{slice, SliceOptions, Strategy};
use crate::robot::{Configuration, PartCarriedCell, RobotModel};
use crate::toolaxis::local_frames;

/// Central-difference step on `R_Z` and on the coefficients.
const H: f64 = 1e-6;

/// The hemisphere of `parts/hemisphere.toml`, sliced as that file asks.
fn hemisphere_layers() -> Vec<LayerPoints> {
    let radius = Expression::parse("sqrt(45^2 - t^2)", "t", &BTreeMap::new()).unwrap();
    let guide = Line {
        origin: Point3::origin(),
        direction: Vector3::z_axis(),
    };
    let tube = Tube::new(
        Arc::new(guide),
        FrameMethod::default(),
        None,
        ProfileLaw::Expression(radius),
        TubeRange::new(0.0, 45.0 - 0.1),
    )
    .unwrap();
    let plate = Substrate::Plane {
        point: Point3::origin(),
        normal: Vector3::z_axis(),
    };
    let path = slice(&tube, &plate, &SliceOptions::new(Strategy::Constant, 5.0)).unwrap();
    layer_points(&path, &local_frames(&path, &tube), 6.0)
}

/// The cell of `parts/cells/robowam_part_carried.toml`.
fn robowam() -> CellLayout {
    CellLayout::PartCarried(PartCarriedCell {
        name: "ROBOWAM".into(),
        robot: RobotModel::arcmate_120ic_nominal().with_j5_travel_deg(135.0),
        deposition_point_mm: Point3::new(1045.747, -630.155, 653.167),
        configuration: Configuration::from_fanuc("F U T").unwrap(),
        flange_from_part: Isometry3::identity(),
    })
}

/// A mid-height layer of the hemisphere, the optimiser's `R_Z` for it (rad)
/// and its branch.
fn layer_at_its_optimum(
    cell: &CellLayout,
    opts: &OptimiseOptions,
) -> (LayerPoints, Vec<f64>, Configuration) {
    let layers = hemisphere_layers();
    assert!(layers.len() >= 6, "{} layers", layers.len());
    let layer = layers[4].clone();
    let plan = optimise(cell, std::slice::from_ref(&layer), opts).unwrap();
    let lp = &plan.layers[0];
    let r = lp.points.iter().map(|p| p.r_z).collect();
    (layer, r, lp.configuration.chosen)
}

/// `|a − b| <= tol · max(1, |a|, |b|)`.
fn close(a: f64, b: f64, tol: f64) -> bool {
    (a - b).abs() <= tol * 1f64.max(a.abs()).max(b.abs())
}

/// Every constraint row at `e` (bounds themselves): point, value, slope at
/// the point, slope at the point before, `true` for a dexterity row.
fn rows(problem: &LayerProblem, e: &Evaluation) -> Vec<(usize, f64, f64, f64, bool)> {
    let mut out = Vec::new();
    problem.constraints(e, true, false, &mut |m, c, v, d, dp| {
        out.push((m, v, d, dp, c == Constraint::Dexterity));
    });
    out
}

/// `r` with `r[k]` moved by `dr`.
fn moved(r: &[f64], k: usize, dr: f64) -> Vec<f64> {
    let mut r = r.to_vec();
    r[k] += dr;
    r
}

#[test]
fn joint_and_constraint_slopes_match_central_differences() {
    let cell = robowam();
    let opts = OptimiseOptions::default();
    let (layer, r, cfg) = layer_at_its_optimum(&cell, &opts);
    let setup = LayerSetup::new(&cell, &layer.points, &opts, None);
    let p = layer.points.len();
    let mut problem = setup.problem(cfg, vec![0.0; p]);
    // a dexterity floor at 0.8 of every point's dexterity: every point's
    // dexterity is then computed exactly, with its slope (below 1.5 floors)
    let e = problem.evaluate(&r).unwrap();
    let mut exact = e.clone();
    problem.exact_dexterity(&mut exact);
    problem.psi = exact.dex.iter().map(|d| 0.8 * d).collect();
    let e = problem.evaluate(&r).unwrap();
    let analytic = rows(&problem, &e);
    assert!(analytic.iter().filter(|x| x.4).count() == p);

    let (mut worst_q, mut worst_c, mut worst_dex) = (0.0f64, 0.0f64, 0.0f64);
    for k in (0..p).step_by(p / 20) {
        let plus = problem.evaluate(&moved(&r, k, H)).unwrap();
        let minus = problem.evaluate(&moved(&r, k, -H)).unwrap();
        // dq/dR_Z at point k
        for j in 0..6 {
            let fd = (plus.q[k][j] - minus.q[k][j]) / (2.0 * H);
            let g = e.g[k][j];
            worst_q = worst_q.max((fd - g).abs() / 1f64.max(g.abs()));
            assert!(
                close(fd, g, 1e-6),
                "point {k}, J{}: dq/dR_Z {g} vs central difference {fd}",
                j + 1
            );
        }
        // every constraint's slope along R_Z at point k
        let (rp, rm) = (rows(&problem, &plus), rows(&problem, &minus));
        assert_eq!(rp.len(), analytic.len());
        assert_eq!(rm.len(), analytic.len());
        for (i, &(m, _, d, dp, dex)) in analytic.iter().enumerate() {
            let fd = (rp[i].1 - rm[i].1) / (2.0 * H);
            let slope = if m == k {
                d
            } else if m == k + 1 {
                dp
            } else {
                0.0
            };
            // the dexterity slope is a forward difference along the joint
            // tangent (first order): looser (measured 2e-7)
            let tol = if dex { 1e-5 } else { 1e-6 };
            let err = (fd - slope).abs() / 1f64.max(slope.abs());
            if dex {
                worst_dex = worst_dex.max(err);
            } else {
                worst_c = worst_c.max(err);
            }
            assert!(
                close(fd, slope, tol),
                "row {i} (point {m}, dexterity {dex}) along R_Z at point {k}: slope {slope} vs central difference {fd}"
            );
        }
    }
    eprintln!("worst relative error: dq/dR_Z {worst_q:.2e}, constraints {worst_c:.2e}, dexterity {worst_dex:.2e}");
}

/// Gradient of the objective with respect to the coefficients: `2 Σ r_i a_i`
/// over the residuals `r_i` and their rows `a_i`.
fn gradient(problem: &LayerProblem, e: &Evaluation, basis: &Basis, smoothness: f64) -> Vec<f64> {
    let mut g = vec![0.0; basis.len()];
    problem.residuals(e, smoothness, Some(basis), &mut |r, a| {
        for &(i, x) in a {
            g[i] += 2.0 * r * x;
        }
    });
    g
}

/// Checks the objective's gradient in `basis` (coefficients `c`) against
/// central differences on the coefficients `ks`; returns the worst
/// relative error.
fn check_objective_gradient(
    problem: &LayerProblem,
    basis: &Basis,
    c: &[f64],
    smoothness: f64,
    ks: impl Iterator<Item = usize>,
    tol: f64,
    what: &str,
) -> f64 {
    let e = problem.evaluate(&basis.eval(c)).unwrap();
    let g = gradient(problem, &e, basis, smoothness);
    let f = |c: &[f64]| problem.objective(&problem.evaluate(&basis.eval(c)).unwrap(), smoothness);
    let scale = problem.objective(&e, smoothness);
    let mut worst = 0.0f64;
    for k in ks {
        let fd = (f(&moved(c, k, H)) - f(&moved(c, k, -H))) / (2.0 * H);
        // relative to the objective's own size: a coefficient the objective
        // hardly depends on has a gradient near 0
        let err = (fd - g[k]).abs() / scale.max(g[k].abs());
        worst = worst.max(err);
        assert!(
            err <= tol,
            "{what}: d/dc_{k} {} vs central difference {fd} (objective {scale})",
            g[k]
        );
    }
    worst
}

#[test]
fn objective_gradients_match_central_differences() {
    let cell = robowam();
    let opts = OptimiseOptions::default();
    let (layer, r, cfg) = layer_at_its_optimum(&cell, &opts);
    let setup = LayerSetup::new(&cell, &layer.points, &opts, None);
    let p = layer.points.len();
    let mut problem = setup.problem(cfg, vec![0.0; p]);
    assert!(
        problem.centring > 0.0,
        "the centring term is part of the check"
    );
    // a cubic in the cylindrical angle (the optimiser's law on this layer)
    let poly = Basis::polynomial(&setup.theta, 4);
    let c = poly.fit(&r);
    let displacement =
        check_objective_gradient(&problem, &poly, &c, 0.0, 0..4, 1e-6, "displacement, cubic");
    // one coefficient per point with the smoothing penalty
    let per_point = Basis::PerPoint { points: p };
    let spline = check_objective_gradient(
        &problem,
        &per_point,
        &r,
        10.0,
        (1..p).step_by(p / 10),
        1e-6,
        "displacement, per point, smoothing",
    );
    // the uncertainty objective (its slope is a forward difference along
    // the joint tangent)
    problem.objective = Objective::PositioningUncertainty;
    let uncertainty =
        check_objective_gradient(&problem, &poly, &c, 0.0, 0..4, 1e-6, "uncertainty, cubic");
    eprintln!("worst relative error: displacement {displacement:.2e}, spline {spline:.2e}, uncertainty {uncertainty:.2e}");
}
