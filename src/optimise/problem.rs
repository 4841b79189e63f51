//! The per-layer problem [SPEC §7, eq. 4.3–4.8, 4.13]: given the layer's
//! points (part frame, mm), a cell and an IK branch, evaluate the joints for
//! `R_Z` values (rad) with their analytic derivative `dq/dR_Z`, the objective
//! as a sum of squared residuals and the constraints per point, and linearise
//! both through the basis `R = B c` for the SQP.

use std::cell::Cell;
use std::sync::Arc;

use nalgebra::{Matrix6, Vector6};

use crate::optimise::options::Objective;
use crate::optimise::outcome::{BindingConstraint, Constraint};
use crate::optimise::parameterisation::Basis;
use crate::optimise::qp::Row;
use crate::robot::cell::{CellLayout, CellPoint, CellPose, TorchPointFrame};
use crate::robot::ik::Configuration;
use crate::robot::indices::{
    dexterity, dexterity_warm, positioning_uncertainty, SvdWarmStart, UncertaintyFormula,
};
use crate::robot::model::{Joints, RobotModel, ARCMATE_120IC_ENCODER_SIGMA_DEG};
use crate::robot::positioner::PositionerJoints;
use crate::robot::RobotError;

/// Relative amount shaved off the dexterity lower bound so that rounding
/// keeps it below the true value (relative).
const ROUNDING_SHAVE_REL: f64 = 1e-12;

/// The joint resolutions of eq. 4.13 (rad): the robot model's encoder
/// resolutions, or the ArcMate 120iC's [table 4.2] when it has none.
pub(crate) fn encoder_sigma_rad(robot: &RobotModel) -> [f64; 6] {
    robot
        .encoder_sigma_rad
        .unwrap_or(ARCMATE_120IC_ENCODER_SIGMA_DEG.map(f64::to_radians))
}

/// Where the dexterity bound is at least this multiple of the floor, the
/// SVD is skipped (the constraint is inactive and its slope is not needed:
/// [`LayerProblem::constraints`] computes slopes below 1.5 floors).
const DEX_BOUND_FACTOR: f64 = 1.5;

/// How far inside every bound the SQP works (rad for joint travels, hose
/// torsion and a step's joint motion; relative for the dexterity floors).
/// Its last steps stop below the step tolerance (1e-7 rad of `R_Z`), which
/// can leave an active bound a few 1e-8 outside (the KUKA torch-carried
/// nozzle's top layer: hose torsion 1.8e-8 rad over); the layer's status
/// and the trajectory re-check test the bounds themselves, so aiming this
/// hair inside them makes an optimiser-feasible layer pass the re-check.
pub(crate) const SOLVER_MARGIN: f64 = 1e-6;

/// Finite-difference step on `R_Z` for the dexterity and uncertainty slopes (rad).
const FD_STEP_RAD: f64 = 1e-6;

/// Everything fixed about one layer in one branch.
#[derive(Debug, Clone)]
pub(crate) struct LayerProblem<'a> {
    pub cell: &'a CellLayout,
    pub configuration: Configuration,
    pub points: &'a [CellPoint],
    /// Time from point m−1 to m at the travel speed (s); `dt[0] = 0`.
    pub dt: Vec<f64>,
    /// Dexterity floor per point (0 = none).
    pub psi: Vec<f64>,
    /// Weights `gamma_j = 1/range_j` (0 for unlimited joints).
    pub gamma: [f64; 6],
    /// Travel with the margin (rad; infinite when unlimited).
    pub lower: [f64; 6],
    pub upper: [f64; 6],
    /// `|J5|` must stay above this on its branch's side (rad).
    pub wrist_margin: f64,
    /// The cell's hose-torsion bound on `|q4 + q6|` (rad; torch-carried cell).
    pub hose: Option<f64>,
    pub max_speed: [f64; 6],
    /// Centring weight per point (already divided by the number of points).
    pub centring: f64,
    pub objective: Objective,
    /// Joint resolutions (rad) for eq. 4.13, scaled to keep `I²` near 1.
    pub sigma: [f64; 6],
    /// Length scale of the dexterity (mm).
    pub dex_scale: f64,
    /// Joints the first point is unwrapped towards (a spiral turn continuing
    /// the one before); `None`: the representation inside the travel.
    pub start_near: Option<Joints>,
    /// Quadrature weights when `points` is a subsample of the layer
    /// (`None`: every point of the layer, each of weight 1).
    pub weights: Option<SampleWeights>,
    /// Per point, what its pose keeps whatever `R_Z` (torch-carried cell,
    /// positioner joints planned; [`point_frames`]); `None` where the cell
    /// computes the whole pose. Empty: `None` everywhere.
    pub frames: Arc<[Option<TorchPointFrame>]>,
}

/// The [`TorchPointFrame`] of every point of `points` whose positioner
/// joints are planned, in a torch-carried cell (`None` elsewhere): those do
/// not depend on `R_Z` or on the points before, so [`LayerProblem::pose`]
/// computes each once instead of in every evaluation. Empty in the
/// part-carried cell.
pub(crate) fn point_frames(
    cell: &CellLayout,
    points: &[CellPoint],
) -> Arc<[Option<TorchPointFrame>]> {
    match cell {
        CellLayout::TorchCarried(c) => points
            .iter()
            .map(|p| p.positioner.and_then(|_| c.point_frame(p, 0.0).ok()))
            .collect(),
        CellLayout::PartCarried(_) => Arc::from([]),
    }
}

/// How a subsample of a layer stands for the whole layer in the objective:
/// the displacement between two successive samples `L` points apart counts
/// as `L` equal steps (`(Δq)² / L`, exact where the joints move linearly
/// between them), and each sample's own terms (centring, uncertainty) count
/// for the points around it (half the index gap on either side).
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct SampleWeights {
    /// Per sample `m ≥ 1`: `1 / L`, `L` the index gap from sample `m − 1`;
    /// entry 0 unused.
    pub step: Vec<f64>,
    /// Per sample: the number of layer points it stands for (they sum to
    /// the layer's points).
    pub point: Vec<f64>,
}

/// Joints and derivatives at every point for given `R_Z`.
#[derive(Debug, Clone)]
pub(crate) struct Evaluation {
    pub r: Vec<f64>,
    pub q: Vec<Joints>,
    pub g: Vec<Joints>,
    pub positioner: Vec<Option<PositionerJoints>>,
    /// Dexterity per point, or a lower bound of it at least
    /// `DEX_BOUND_FACTOR` times the floor where `dex_exact` is `false`.
    pub dex: Vec<f64>,
    pub dex_exact: Vec<bool>,
    /// `I_m` (scaled units) when the objective needs it.
    pub unc: Vec<f64>,
    /// Per point, the dexterity's slope along `R_Z` (per rad) once
    /// [`LayerProblem::constraints`] has needed it (NaN before): the SQP
    /// linearises the constraints at one evaluation several times (a refused
    /// step, the polish, the next degree's start), each time the same slope.
    dex_slope: Vec<Cell<f64>>,
}

impl Evaluation {
    /// Replaces the dexterity at point `m` by its exact value `dex` (a
    /// lower bound of it before).
    pub fn set_exact_dexterity(&mut self, m: usize, dex: f64) {
        self.dex[m] = dex;
        self.dex_exact[m] = true;
        self.dex_slope[m].set(f64::NAN);
    }
}

/// A point failed.
#[derive(Debug, Clone)]
pub(crate) struct PointFailure {
    pub point: usize,
    pub error: RobotError,
}

/// Receives one residual and its row over the coefficients.
pub(crate) type ResidualSink<'s> = dyn FnMut(f64, &[(usize, f64)]) + 's;

impl<'a> LayerProblem<'a> {
    /// This whole-layer problem on the samples `idx` (increasing point
    /// indices) of its layer, `points` being those points: the time of a
    /// step between samples is the layer's time between them (so the joint
    /// speed bound there is on the mean speed over the gap, which every
    /// step obeying its own bound implies), the floors are the samples' own,
    /// and [`SampleWeights`] make the objective the layer's estimate.
    pub fn restricted<'b>(&self, idx: &[usize], points: &'b [CellPoint]) -> LayerProblem<'b>
    where
        'a: 'b,
    {
        debug_assert_eq!(idx.len(), points.len());
        let n = idx.len();
        let mut dt = vec![0.0; n];
        let mut step = vec![0.0; n];
        let mut point = vec![0.0; n];
        for k in 1..n {
            dt[k] = self.dt[idx[k - 1] + 1..=idx[k]].iter().sum();
            let gap = (idx[k] - idx[k - 1]) as f64;
            step[k] = 1.0 / gap;
            point[k - 1] += 0.5 * gap;
            point[k] += 0.5 * gap;
        }
        if n > 0 {
            point[0] += 0.5;
            point[n - 1] += 0.5;
        }
        LayerProblem {
            cell: self.cell,
            configuration: self.configuration,
            points,
            dt,
            psi: idx.iter().map(|&m| self.psi[m]).collect(),
            gamma: self.gamma,
            lower: self.lower,
            upper: self.upper,
            wrist_margin: self.wrist_margin,
            hose: self.hose,
            max_speed: self.max_speed,
            centring: self.centring,
            objective: self.objective,
            sigma: self.sigma,
            dex_scale: self.dex_scale,
            start_near: self.start_near,
            weights: Some(SampleWeights { step, point }),
            frames: if self.frames.is_empty() {
                Arc::from([])
            } else {
                idx.iter().map(|&m| self.frames[m]).collect()
            },
        }
    }

    /// The cell pose of point `m` at `r_z` (rad), as [`CellLayout::pose`]
    /// gives it (from the point's frame when it has one).
    ///
    /// # Errors
    /// As [`CellLayout::pose`].
    pub fn pose(&self, m: usize, r_z: f64, q8_hint: f64) -> Result<CellPose, RobotError> {
        match (self.cell, self.frames.get(m)) {
            (CellLayout::TorchCarried(c), Some(Some(f))) => Ok(c.pose_in(f, r_z)),
            _ => self.cell.pose(&self.points[m], r_z, q8_hint),
        }
    }

    /// Joints at one point for `r_z`, unwrapped towards `near`.
    pub fn joints_at(
        &self,
        m: usize,
        r_z: f64,
        near: Option<&Joints>,
        q8_hint: f64,
    ) -> Result<(Joints, CellPose), RobotError> {
        let pose = self.pose(m, r_z, q8_hint)?;
        let robot = self.cell.robot();
        let q = match near {
            Some(n) => robot.inverse_near(&pose.base_from_flange, self.configuration, n)?,
            None => robot.inverse(&pose.base_from_flange, self.configuration)?,
        };
        Ok((q, pose))
    }

    /// `1 / (‖J_s‖_F ‖J_s⁻¹‖_F) ≤ xi_min / xi_max` (`J_s`: linear rows
    /// divided by the dexterity length scale), from the LU of `J`; 0 if singular.
    fn dexterity_lower_bound(
        &self,
        jac: &Matrix6<f64>,
        lu: &nalgebra::LU<f64, nalgebra::U6, nalgebra::U6>,
    ) -> f64 {
        let Some(inv) = lu.try_inverse() else {
            return 0.0;
        };
        let s = self.dex_scale;
        let mut nj = 0.0;
        let mut ni = 0.0;
        for r in 0..6 {
            for c in 0..6 {
                let (fj, fi) = if r < 3 { (1.0 / s, 1.0) } else { (1.0, 1.0) };
                let fi = if c < 3 { fi * s } else { fi };
                nj += (jac[(r, c)] * fj).powi(2);
                ni += (inv[(r, c)] * fi).powi(2);
            }
        }
        let b = 1.0 / (nj * ni).sqrt();
        if b.is_finite() {
            // shave rounding so that the bound stays below the true value
            b * (1.0 - ROUNDING_SHAVE_REL)
        } else {
            0.0
        }
    }

    /// Exact dexterity at every point of `e` (replacing the bounds).
    pub fn exact_dexterity(&self, e: &mut Evaluation) {
        let robot = self.cell.robot();
        let mut warm = SvdWarmStart::default();
        for m in 0..e.q.len() {
            if !e.dex_exact[m] {
                let dex = dexterity_warm(&robot.jacobian(&e.q[m]), self.dex_scale, &mut warm);
                e.set_exact_dexterity(m, dex);
            }
        }
    }

    fn dex_of(&self, q: &Joints) -> f64 {
        dexterity(&self.cell.robot().jacobian(q), self.dex_scale)
    }

    fn unc_of(&self, q: &Joints) -> f64 {
        positioning_uncertainty(
            &self.cell.robot().jacobian(q),
            &self.sigma,
            UncertaintyFormula::RootTrace,
        )
    }

    /// Evaluates the layer at `r` (one `R_Z` per point, rad). Joints are
    /// unwrapped along the layer; the first point takes the representation
    /// inside the travel.
    #[allow(clippy::needless_range_loop)]
    pub fn evaluate(&self, r: &[f64]) -> Result<Evaluation, PointFailure> {
        let p = self.points.len();
        let robot = self.cell.robot();
        let mut q = Vec::with_capacity(p);
        let mut g = Vec::with_capacity(p);
        let mut pos = Vec::with_capacity(p);
        let mut dex = Vec::with_capacity(p);
        let mut dex_exact = Vec::with_capacity(p);
        let mut unc = Vec::new();
        let mut q8 = 0.0;
        let mut prev: Option<Joints> = self.start_near;
        let mut warm = SvdWarmStart::default();
        for m in 0..p {
            let fail = |error| PointFailure { point: m, error };
            let (qm, pose) = self.joints_at(m, r[m], prev.as_ref(), q8).map_err(fail)?;
            if let Some(qp) = pose.positioner {
                q8 = qp[1];
            }
            let jac: Matrix6<f64> = robot.jacobian(&qm);
            let tw: Vector6<f64> = pose.flange_twist_per_rz;
            let lu = jac.lu();
            let sol = lu.solve(&tw).filter(|x| x.iter().all(|v| v.is_finite()));
            let Some(sol) = sol else {
                return Err(fail(RobotError::SingularJacobian {
                    manipulability: crate::robot::indices::manipulability(&jac),
                }));
            };
            g.push([sol[0], sol[1], sol[2], sol[3], sol[4], sol[5]]);
            // The SVD only where the floor could matter: elsewhere a cheap
            // lower bound proves the point is well above it (it decides the
            // constraint and its slope exactly as the value would; the
            // reported dexterity is recomputed at the end).
            let bound = self.dexterity_lower_bound(&jac, &lu);
            let exact = !(bound >= DEX_BOUND_FACTOR * self.psi[m] && self.psi[m] > 0.0);
            dex.push(if exact {
                dexterity_warm(&jac, self.dex_scale, &mut warm)
            } else {
                bound
            });
            dex_exact.push(exact);
            if self.objective == Objective::PositioningUncertainty {
                unc.push(positioning_uncertainty(
                    &jac,
                    &self.sigma,
                    UncertaintyFormula::RootTrace,
                ));
            }
            q.push(qm);
            pos.push(pose.positioner);
            prev = Some(qm);
        }
        Ok(Evaluation {
            r: r.to_vec(),
            q,
            g,
            positioner: pos,
            dex,
            dex_exact,
            unc,
            dex_slope: vec![Cell::new(f64::NAN); p],
        })
    }

    /// Slope of a scalar function of the joints at point `m` along `R_Z`
    /// (per rad), `f0` its value at `e.q[m]`: a forward difference along
    /// the analytic tangent `dq/dR_Z` (`q + h·g`; no IK: the second-order
    /// term of the joints changes the slope by `O(h)`, as the difference does).
    fn slope(&self, e: &Evaluation, m: usize, f0: f64, f: impl Fn(&Self, &Joints) -> f64) -> f64 {
        let q = &e.q[m];
        let g = &e.g[m];
        let q1: Joints = std::array::from_fn(|j| q[j] + FD_STEP_RAD * g[j]);
        let d = (f(self, &q1) - f0) / FD_STEP_RAD;
        if d.is_finite() {
            d
        } else {
            0.0
        }
    }

    /// [`LayerProblem::slope`] of the dexterity at point `m` of `e`,
    /// computed once per evaluation and point.
    fn dex_slope(&self, e: &Evaluation, m: usize) -> f64 {
        let cached = &e.dex_slope[m];
        if cached.get().is_nan() {
            cached.set(self.slope(e, m, e.dex[m], Self::dex_of));
        }
        cached.get()
    }

    /// The objective: sum of squared residuals (displacement or uncertainty)
    /// plus the centring term; `smoothness` adds the spline penalty.
    pub fn objective(&self, e: &Evaluation, smoothness: f64) -> f64 {
        let mut f = 0.0;
        self.residuals(e, smoothness, None, &mut |r, _| f += r * r);
        f
    }

    /// Weighted joint displacement of eq. 4.3 (rad; over a subsample, its
    /// estimate with the sample weights).
    pub fn displacement(&self, e: &Evaluation) -> f64 {
        let mut f = 0.0;
        for m in 1..e.q.len() {
            for j in 0..6 {
                f += self.gamma[j] * self.step_weight(m) * (e.q[m][j] - e.q[m - 1][j]).powi(2);
            }
        }
        f
    }

    /// `1 / L` for the step into point `m` (1 on a whole layer).
    fn step_weight(&self, m: usize) -> f64 {
        self.weights.as_ref().map_or(1.0, |w| w.step[m])
    }

    /// The number of layer points that point `m` stands for (1 on a whole layer).
    fn point_weight(&self, m: usize) -> f64 {
        self.weights.as_ref().map_or(1.0, |w| w.point[m])
    }

    /// Calls `sink(value, row)` for every residual; rows (through `basis`)
    /// only when a basis is given.
    pub fn residuals(
        &self,
        e: &Evaluation,
        smoothness: f64,
        basis: Option<&Basis>,
        sink: &mut ResidualSink,
    ) {
        let p = e.q.len();
        let mut row_m = Vec::new();
        let mut row_p = Vec::new();
        let mut a: Vec<(usize, f64)> = Vec::new();
        let rows = |m: usize, out: &mut Vec<(usize, f64)>| {
            if let Some(b) = basis {
                b.row(m, out);
            }
        };
        // sparse combination x·row_m + y·row_p into `a`
        fn combine(
            a: &mut Vec<(usize, f64)>,
            x: f64,
            rm: &[(usize, f64)],
            y: f64,
            rp: &[(usize, f64)],
        ) {
            a.clear();
            // the polynomial bases: both rows over the same coefficients
            if rm.len() == rp.len() && rm.iter().zip(rp).all(|(u, v)| u.0 == v.0) {
                a.extend(
                    rm.iter()
                        .zip(rp)
                        .map(|(&(i, u), &(_, v))| (i, x * u + y * v)),
                );
                return;
            }
            for &(i, v) in rm {
                a.push((i, x * v));
            }
            for &(i, v) in rp {
                if let Some(e) = a.iter_mut().find(|e| e.0 == i) {
                    e.1 += y * v;
                } else {
                    a.push((i, y * v));
                }
            }
        }
        match self.objective {
            Objective::JointDisplacement => {
                rows(0, &mut row_m);
                for m in 1..p {
                    std::mem::swap(&mut row_m, &mut row_p);
                    rows(m, &mut row_m);
                    for j in 0..6 {
                        if self.gamma[j] == 0.0 {
                            continue;
                        }
                        let w = (self.gamma[j] * self.step_weight(m)).sqrt();
                        let r = w * (e.q[m][j] - e.q[m - 1][j]);
                        combine(&mut a, w * e.g[m][j], &row_m, -w * e.g[m - 1][j], &row_p);
                        sink(r, &a);
                    }
                }
            }
            Objective::PositioningUncertainty => {
                for m in 0..p {
                    rows(m, &mut row_m);
                    let d = if basis.is_some() {
                        self.slope(e, m, e.unc[m], Self::unc_of)
                    } else {
                        0.0
                    };
                    let w = self.point_weight(m).sqrt();
                    combine(&mut a, w * d, &row_m, 0.0, &[]);
                    sink(w * e.unc[m], &a);
                }
            }
        }
        if self.centring > 0.0 {
            for m in 0..p {
                let w = (self.centring * self.point_weight(m)).sqrt();
                rows(m, &mut row_m);
                for j in 0..6 {
                    if self.gamma[j] == 0.0 {
                        continue;
                    }
                    let l = &self.cell.robot().limits[j];
                    let s = w / l.range_rad();
                    combine(&mut a, s * e.g[m][j], &row_m, 0.0, &[]);
                    sink(s * (e.q[m][j] - l.mid_rad()), &a);
                }
            }
        }
        if smoothness > 0.0 && p >= 3 {
            let w = smoothness.sqrt();
            for m in 1..p - 1 {
                let r = w * (e.r[m + 1] - 2.0 * e.r[m] + e.r[m - 1]);
                a.clear();
                if basis.is_some() {
                    a.extend([(m - 1, w), (m, -2.0 * w), (m + 1, w)]);
                }
                sink(r, &a);
            }
        }
    }

    /// Wrist bounds of J5 on the current side (rad): `[lo, hi]`.
    pub(crate) fn j5_bounds(&self, q5: f64) -> (f64, f64) {
        if q5 >= 0.0 {
            (self.lower[4].max(self.wrist_margin), self.upper[4])
        } else {
            (self.lower[4], self.upper[4].min(-self.wrist_margin))
        }
    }

    /// Bounds `[lo, hi]` of joint `j` (0-based) at joints `q` (rad): the
    /// travel with the margin, and for J5 the wrist bounds on `q`'s side
    /// ([`LayerProblem::j5_bounds`]).
    pub(crate) fn joint_bounds(&self, j: usize, q: &Joints) -> (f64, f64) {
        if j == 4 {
            self.j5_bounds(q[4])
        } else {
            (self.lower[j], self.upper[j])
        }
    }

    /// Centring of joints `q`: `sum_j ((q_j − mid_j) / range_j)²` over the
    /// limited joints (dimensionless; the centring term of
    /// [`OptimiseOptions::centring_weight`](super::OptimiseOptions::centring_weight)
    /// at one point, before its weight).
    pub(crate) fn centring_of(&self, q: &Joints) -> f64 {
        let robot = self.cell.robot();
        let mut c = 0.0;
        for (j, qj) in q.iter().enumerate() {
            if self.gamma[j] > 0.0 {
                let l = &robot.limits[j];
                c += ((qj - l.mid_rad()) / l.range_rad()).powi(2);
            }
        }
        c
    }

    /// Every constraint value `c ≤ 0` at `e` (rad, or relative for the
    /// dexterity), calling `sink(point, constraint, value, gradient along R_Z
    /// at point m and at m−1)`. Gradients of the dexterity are computed only
    /// when `with_dex_slope` and the point is within a factor 1.5 of its floor.
    /// `solver`: the bounds the SQP works to, every one [`SOLVER_MARGIN`]
    /// tighter; otherwise the bounds themselves.
    pub fn constraints(
        &self,
        e: &Evaluation,
        with_dex_slope: bool,
        solver: bool,
        sink: &mut impl FnMut(usize, Constraint, f64, f64, f64),
    ) {
        let margin = if solver { SOLVER_MARGIN } else { 0.0 };
        let mut sink = |m, c, v: f64, d, dp| sink(m, c, v + margin, d, dp);
        let p = e.q.len();
        for m in 0..p {
            let q = &e.q[m];
            let g = &e.g[m];
            for j in 0..6 {
                let (lo, hi) = self.joint_bounds(j, q);
                let c = Constraint::JointLimit { joint: j + 1 };
                if hi.is_finite() {
                    sink(m, c, q[j] - hi, g[j], 0.0);
                }
                if lo.is_finite() {
                    sink(m, c, lo - q[j], -g[j], 0.0);
                }
            }
            if let Some(h) = self.hose {
                let t = q[3] + q[5];
                let d = g[3] + g[5];
                sink(m, Constraint::HoseTorsion, t - h, d, 0.0);
                sink(m, Constraint::HoseTorsion, -t - h, -d, 0.0);
            }
            let psi = self.psi[m];
            if psi > 0.0 {
                let d = if with_dex_slope && e.dex[m] < 1.5 * psi {
                    self.dex_slope(e, m)
                } else {
                    0.0
                };
                sink(
                    m,
                    Constraint::Dexterity,
                    (psi - e.dex[m]) / psi,
                    -d / psi,
                    0.0,
                );
            }
            if m > 0 && self.dt[m] > 0.0 {
                let qp = &e.q[m - 1];
                let gp = &e.g[m - 1];
                for j in 0..6 {
                    let lim = self.max_speed[j] * self.dt[m];
                    let c = Constraint::JointSpeed { joint: j + 1 };
                    let dq = q[j] - qp[j];
                    sink(m, c, dq - lim, g[j], -gp[j]);
                    sink(m, c, -dq - lim, -g[j], gp[j]);
                }
            }
        }
    }

    /// The most violated constraint at `e` (the bounds themselves), if any
    /// is violated by more than `tol`.
    pub fn binding(&self, e: &Evaluation, tol: f64) -> Option<BindingConstraint> {
        let mut worst: Option<BindingConstraint> = None;
        self.constraints(e, false, false, &mut |m, c, v, _, _| {
            if v > tol && worst.is_none_or(|w| v > w.violation) {
                worst = Some(BindingConstraint {
                    point: m,
                    constraint: c,
                    violation: v,
                });
            }
        });
        worst
    }

    /// Largest violation of the SQP's bounds (0 when feasible).
    pub fn max_violation(&self, e: &Evaluation) -> f64 {
        let mut worst: f64 = 0.0;
        self.constraints(e, false, true, &mut |_, _, v, _, _| worst = worst.max(v));
        worst
    }

    /// Largest violation of the bounds themselves (0 when feasible).
    pub fn max_violation_of_bounds(&self, e: &Evaluation) -> f64 {
        let mut worst: f64 = 0.0;
        self.constraints(e, false, false, &mut |_, _, v, _, _| worst = worst.max(v));
        worst
    }

    /// Linearised constraint rows `a·δc ≤ b` that a step with `|δR| ≤ trust`
    /// could violate (the others cannot, under the linear model).
    pub fn constraint_rows(&self, e: &Evaluation, basis: &Basis, trust: f64) -> Vec<Row> {
        let mut out = Vec::new();
        let mut rm = Vec::new();
        let mut rp = Vec::new();
        self.constraints(e, true, true, &mut |m, _, v, d, dp| {
            let reach = (d.abs() + dp.abs()) * trust;
            if v + reach <= 0.0 || (d == 0.0 && dp == 0.0) {
                return;
            }
            basis.row(m, &mut rm);
            let mut a: Vec<(usize, f64)> = rm.iter().map(|&(i, x)| (i, d * x)).collect();
            if dp != 0.0 {
                basis.row(m - 1, &mut rp);
                for &(i, x) in &rp {
                    if let Some(e) = a.iter_mut().find(|e| e.0 == i) {
                        e.1 += dp * x;
                    } else {
                        a.push((i, dp * x));
                    }
                }
            }
            out.push(Row { a, b: -v });
        });
        out
    }
}
