//! **Stage 6a — the positioner's laws: the law's problem.** A layer's
//! points in the table frame (mm; tool axes and build directions), the
//! positioner's travels (rad), speeds (rad/s) and the arm's linearised rows
//! ([`ArmRow`]); the law's residuals, Jacobian and linearised constraints at
//! its spline coefficients, and the check of a law given per point against
//! every constraint (cone, travel, stroke, speeds).

use crate::math::{Matrix3, Vector3};
use crate::optimise::parameterisation::Basis;
use crate::optimise::qp::Row;
use crate::robot::cell::{CellPoint, TorchCarriedCell};
use crate::robot::positioner::{Positioner, PositionerJoints};

use super::options::PositionerOptions;
use super::outcome::PositionerBinding;

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

/// What a law is solved against: the layer in the table frame.
pub(super) struct LawProblem<'a> {
    pub(super) cell: &'a TorchCarriedCell,
    /// Deposition points, table frame (mm).
    pub(super) m: Vec<Vector3>,
    /// Tool axes, table frame.
    pub(super) t: Vec<Vector3>,
    /// Build directions, table frame.
    pub(super) b: Vec<Vector3>,
    /// `base_from_positioner` rotation.
    pub(super) r0: Matrix3,
    /// Time of the step into each point (s); 0 for point 0.
    pub(super) dt: Vec<f64>,
    pub(super) cos_cone: f64,
    pub(super) cone: f64,
    pub(super) gamma: [f64; 2],
    pub(super) gamma_arm: f64,
    pub(super) lower: [f64; 2],
    pub(super) upper: [f64; 2],
    /// `true` when `lower[1]..upper[1]` is the controller's stroke window
    /// ([`stroke_window`](super::stroke_window)), not the turn's travel.
    pub(super) stroke_window: bool,
    /// The arm's linearised constraints ([`positioner_law_for_arm`](super::positioner_law_for_arm)).
    pub(super) arm: Vec<ArmRow>,
    pub(super) max_speed: [f64; 2],
    pub(super) opts: PositionerOptions,
}

impl<'a> LawProblem<'a> {
    /// The layer `points` (part frame) in `cell`'s table frame, each at its
    /// travel speed, each travel narrowed by `margin_rad`, with the
    /// arm's rows `arm`.
    pub(super) fn new(
        cell: &'a TorchCarriedCell,
        points: &[CellPoint],
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
                    points.windows(2).map(|w| {
                        (w[1].position_mm - w[0].position_mm).norm() / w[1].travel_speed_mm_s
                    }),
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
pub(super) struct WorldPoint {
    pub(super) p: [Vector3; 3],
    pub(super) t: [Vector3; 3],
    pub(super) b: [Vector3; 3],
}

impl LawProblem<'_> {
    /// The largest violation of the arm's rows by `joints` (rad; 0 without
    /// rows).
    pub(super) fn arm_violation(&self, joints: &[PositionerJoints]) -> f64 {
        self.arm
            .iter()
            .filter_map(|a| joints.get(a.point).map(|q| a.violation(q)))
            .fold(0.0, f64::max)
    }

    /// Bounds the turn to the controller's stroke window `w` (rad,
    /// [`stroke_window`](super::stroke_window)).
    pub(super) fn within_stroke(&mut self, w: (f64, f64)) {
        self.lower[1] = w.0;
        self.upper[1] = w.1;
        self.stroke_window = true;
    }

    pub(super) fn world(&self, m: usize, q: &PositionerJoints) -> WorldPoint {
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

    pub(super) fn tilt(&self, m: usize, q: &PositionerJoints) -> f64 {
        let b = self.world(m, q).b[0];
        b.xy().norm().atan2(b.z)
    }
}

/// Share of the cone (unitless) from which the SQP's merit counts a
/// violation of a cone row (aimed at 99 %, [`LawProblem::cos_cone`]).
const CONE_MERIT_SHARE: f64 = 0.995;

/// The laws' value and the linear model at `x = [c7; c8]` on samples `idx`.
pub(super) struct Model {
    /// Residuals (the objective is `½|r|²`).
    pub(super) r: Vec<f64>,
    /// Jacobian rows, one per residual, their non-zero entries only.
    pub(super) jac: SparseRows,
    pub(super) rows: Vec<Row>,
    /// Per row, how far past it the merit counts no violation (its own
    /// units): the cone's rows aim at 99 % of the cone, and the merit
    /// counts from 99.5 % (the rest is a margin the check keeps), so that
    /// a step along the cone's curved edge, which its linearisation leaves
    /// a hair outside, is not refused (the Maratos effect); 0 for the
    /// linear rows (travel, stroke, speeds, the arm's), which a step keeps
    /// exactly.
    pub(super) merit_slack: Vec<f64>,
    /// Largest violation of a row at `δ = 0` past its merit slack (its own
    /// units).
    pub(super) violation: f64,
}

/// Rows of a matrix over the coefficients `[c7; c8]`, each its non-zero
/// `(coefficient, value)` entries in coefficient order.
#[derive(Default)]
pub(super) struct SparseRows {
    /// Row `i`'s entries are `entries[start[i]..start[i + 1]]`.
    start: Vec<usize>,
    entries: Vec<(usize, f64)>,
}

impl SparseRows {
    /// Row `i`'s non-zero entries.
    pub(super) fn row(&self, i: usize) -> &[(usize, f64)] {
        &self.entries[self.start[i]..self.start[i + 1]]
    }
}

/// A gradient in the coefficients `[c7; c8]` of a quantity with
/// derivatives `a7`, `a8` in `q7`, `q8` at one point, built densely (the
/// basis rows of two points may share coefficients) and read out as its
/// non-zero entries; the buffer is reused from row to row.
struct Gradient {
    g: Vec<f64>,
    k: usize,
    /// The coefficients touched since the last drain lie in `lo..hi` of
    /// each block.
    lo: usize,
    hi: usize,
}

impl Gradient {
    fn new(k: usize) -> Self {
        Gradient {
            g: vec![0.0; 2 * k],
            k,
            lo: k,
            hi: 0,
        }
    }

    /// Adds the point's basis row `row` times `a7` (the `c7` block) and
    /// `a8` (the `c8` block).
    fn add(&mut self, row: &[(usize, f64)], a7: f64, a8: f64) {
        for &(i, v) in row {
            self.g[i] += a7 * v;
            self.g[self.k + i] += a8 * v;
            self.lo = self.lo.min(i);
            self.hi = self.hi.max(i + 1);
        }
    }

    /// Subtracts the basis row `row` times `b7` and `b8`.
    fn sub(&mut self, row: &[(usize, f64)], b7: f64, b8: f64) {
        for &(i, v) in row {
            self.g[i] -= b7 * v;
            self.g[self.k + i] -= b8 * v;
            self.lo = self.lo.min(i);
            self.hi = self.hi.max(i + 1);
        }
    }

    /// The non-zero entries times `sign`, in coefficient order, pushed
    /// onto `out`; the gradient is zero again.
    fn drain_into(&mut self, sign: f64, out: &mut Vec<(usize, f64)>) {
        for block in [0, self.k] {
            for i in block + self.lo..block + self.hi {
                let v = &mut self.g[i];
                if *v != 0.0 {
                    out.push((i, sign * *v));
                }
                *v = 0.0;
            }
        }
        (self.lo, self.hi) = (self.k, 0);
    }

    /// The non-zero entries times `sign` as a row's coefficients.
    fn drain(&mut self, sign: f64) -> Vec<(usize, f64)> {
        let mut out = Vec::with_capacity(2 * self.hi.saturating_sub(self.lo));
        self.drain_into(sign, &mut out);
        out
    }
}

/// The law's residuals, Jacobian (where `jacobian`; else the Jacobian and
/// the rows' gradients are left empty) and linearised rows at coefficients
/// `x` on `basis`, over the samples `idx`.
// the axes' loops index several per-axis arrays together
#[allow(clippy::needless_range_loop)]
pub(super) fn build_model(
    pb: &LawProblem,
    basis: &Basis,
    idx: &[usize],
    x: &[f64],
    jacobian: bool,
) -> Model {
    let k = basis.len();
    let (c7, c8) = x.split_at(k);
    let q7 = basis.eval(c7);
    let q8 = basis.eval(c8);
    // per sample: at most 10 residuals (2 tilt, 2 axes, 6 arm) of at most
    // 16 entries (two points' basis rows, both axes) and 9 rows
    let mut r = Vec::with_capacity(10 * idx.len());
    let mut jac = SparseRows::default();
    if jacobian {
        jac.start.reserve(10 * idx.len() + 1);
        jac.entries.reserve(160 * idx.len());
    }
    jac.start.push(0);
    let mut rows = Vec::with_capacity(9 * idx.len() + pb.arm.len());
    let mut violation: f64 = 0.0;
    let n_all = basis.points().max(1) as f64;
    let cone_target = pb.cos_cone;
    let cone_slack = cone_target - (CONE_MERIT_SHARE * pb.cone).cos();
    let mut merit_slack = Vec::with_capacity(9 * idx.len() + pb.arm.len());
    let mut push_row = |rows: &mut Vec<Row>, a: Vec<(usize, f64)>, b: f64, slack: f64| {
        violation = violation.max(-b - slack);
        rows.push(Row { a, b });
        merit_slack.push(slack);
    };
    let mut g = Gradient::new(if jacobian { k } else { 0 });
    // a residual's value and its Jacobian row `g` (emptied)
    let mut push_residual = |g: &mut Gradient, v: f64| {
        r.push(v);
        if jacobian {
            g.drain_into(1.0, &mut jac.entries);
            jac.start.push(jac.entries.len());
        }
    };
    // this sample's basis row, and the previous sample's
    let (mut brow, mut rowp) = (Vec::new(), Vec::new());
    let mut prev: Option<(usize, WorldPoint)> = None;
    for (si, &m) in idx.iter().enumerate() {
        let q = [q7[m], q8[m]];
        let w = pb.world(m, &q);
        basis.row(m, &mut brow);
        // d/dx of a quantity with d/dq7 = a7, d/dq8 = a8, into `g`
        let grad = |g: &mut Gradient, a7: f64, a8: f64| {
            if jacobian {
                g.add(&brow, a7, a8);
            }
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
            grad(&mut g, wt * w.b[1][c], wt * w.b[2][c]);
            push_residual(&mut g, wt * w.b[0][c]);
        }
        // cone: b_z >= cos(cone)
        grad(&mut g, w.b[1].z, w.b[2].z);
        push_row(&mut rows, g.drain(-1.0), w.b[0].z - cone_target, cone_slack);
        // travel
        for a in 0..2 {
            let (a7, a8) = if a == 0 { (1.0, 0.0) } else { (0.0, 1.0) };
            if pb.upper[a].is_finite() {
                grad(&mut g, a7, a8);
                push_row(&mut rows, g.drain(1.0), pb.upper[a] - q[a], 0.0);
            }
            if pb.lower[a].is_finite() {
                grad(&mut g, a7, a8);
                push_row(&mut rows, g.drain(-1.0), q[a] - pb.lower[a], 0.0);
            }
        }
        // the arm's rows at this point: grad·(q + δ − q0) ≤ slack
        for a in pb.arm.iter().filter(|a| a.point == m) {
            grad(&mut g, a.grad[0], a.grad[1]);
            let at = a.grad[0] * (q[0] - a.q0[0]) + a.grad[1] * (q[1] - a.q0[1]);
            push_row(&mut rows, g.drain(1.0), a.slack_rad - at, 0.0);
        }
        if let Some((mp, wp)) = &prev {
            let gap = (m - mp) as f64;
            let dq = [q7[m] - q7[*mp], q8[m] - q8[*mp]];
            // d(Δ)/dx = row_m − row_prev
            let diff = |g: &mut Gradient, a7: f64, a8: f64, b7: f64, b8: f64| {
                if jacobian {
                    g.add(&brow, a7, a8);
                    g.sub(&rowp, b7, b8);
                }
            };
            let s = 1.0 / gap.sqrt();
            for a in 0..2 {
                let wa = pb.gamma[a].sqrt() * s;
                if wa > 0.0 {
                    let (a7, a8) = if a == 0 { (1.0, 0.0) } else { (0.0, 1.0) };
                    diff(&mut g, wa * a7, wa * a8, wa * a7, wa * a8);
                    push_residual(&mut g, wa * dq[a]);
                }
            }
            let wp_ = pb.gamma_arm.sqrt() * s / pb.opts.arm_length_mm;
            let wtv = pb.gamma_arm.sqrt() * s;
            for c in 0..3 {
                diff(
                    &mut g,
                    wp_ * w.p[1][c],
                    wp_ * w.p[2][c],
                    wp_ * wp.p[1][c],
                    wp_ * wp.p[2][c],
                );
                push_residual(&mut g, wp_ * (w.p[0][c] - wp.p[0][c]));
                diff(
                    &mut g,
                    wtv * w.t[1][c],
                    wtv * w.t[2][c],
                    wtv * wp.t[1][c],
                    wtv * wp.t[2][c],
                );
                push_residual(&mut g, wtv * (w.t[0][c] - wp.t[0][c]));
            }
            // speeds over the samples' time
            let time: f64 = pb.dt[mp + 1..=m].iter().sum();
            for a in 0..2 {
                if pb.max_speed[a].is_finite() && time > 0.0 {
                    let cap = 0.98 * pb.max_speed[a] * time;
                    let (a7, a8) = if a == 0 { (1.0, 0.0) } else { (0.0, 1.0) };
                    diff(&mut g, a7, a8, a7, a8);
                    push_row(&mut rows, g.drain(1.0), cap - dq[a], 0.0);
                    diff(&mut g, a7, a8, a7, a8);
                    push_row(&mut rows, g.drain(-1.0), cap + dq[a], 0.0);
                }
            }
        }
        prev = Some((m, w));
        std::mem::swap(&mut brow, &mut rowp);
    }
    Model {
        r,
        jac,
        rows,
        merit_slack,
        violation,
    }
}

/// `½|r|²` of a law given per point (rad), over every point: the
/// objective the SQP minimises, without its derivatives.
pub(super) fn objective(pb: &LawProblem, joints: &[PositionerJoints]) -> f64 {
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

/// Every point's positioner joints, checked: the worst violation (in its
/// own units scaled to radians) and its binding, the max tilt and where.
pub(super) struct Check {
    pub(super) binding: Option<(f64, PositionerBinding)>,
    pub(super) max_tilt: (f64, usize),
    /// Points whose constraints are violated, worst first.
    pub(super) worst: Vec<usize>,
}

pub(super) fn check(pb: &LawProblem, q: &[PositionerJoints]) -> Check {
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

#[cfg(test)]
mod tests {
    use super::*;

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
}
