//! Tangent-discontinuity smoothing of constant-distance layers (SPEC §3.4;
//! thesis perspective §2.5). Offsetting a layer by a constant distance makes
//! corners where the layer below is concave in the surface (like offsets of a
//! plane curve), and they sharpen from layer to layer. Each layer's `t_i`
//! (its `v_i` kept) are moved by a small QP — solved with Clarabel — that
//! bounds the turning angle between consecutive segments while keeping every
//! local distance to the layer below within `tolerance × Delta`, with the
//! least displacement. The QP is re-linearised until the true angles and
//! distances meet the bounds (sequential QP).

use crate::geometry::Tube;
use crate::math::Vector3;
use crate::path::index::{SegmentId, SegmentIndex};
use clarabel::algebra::CscMatrix;
use clarabel::solver::{
    DefaultSettingsBuilder, DefaultSolver, IPSolver, SolverStatus, SupportedConeT,
};

/// Central-difference step of the distance's derivative in `t`, relative to
/// `1 + |t|` (parameter units).
const FD_STEP_REL: f64 = 1e-6;

/// Smoothing settings.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Smoothing {
    /// Largest turning angle allowed between consecutive segments (rad).
    pub max_turn_rad: f64,
    /// Allowed relative deviation of the local distance from `Delta` (e.g. 0.05).
    pub tolerance: f64,
}

/// Outcome of smoothing one layer.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LayerSmoothing {
    /// Largest turning angle before (rad).
    pub max_turn_before_rad: f64,
    /// Largest turning angle after (rad).
    pub max_turn_after_rad: f64,
    /// Largest |delta − Delta| / Delta after.
    pub max_deviation: f64,
    /// QP solves.
    pub iterations: usize,
    /// Whether both bounds hold.
    pub met: bool,
}

/// Turning angles (rad) at the points of a polyline (0 at open ends).
pub fn turning_angles(pts: &[crate::math::Point3], closed: bool) -> Vec<f64> {
    let n = pts.len();
    (0..n)
        .map(|i| {
            if !closed && (i == 0 || i + 1 == n) {
                return 0.0;
            }
            let a = pts[i] - pts[(i + n - 1) % n];
            let b = pts[(i + 1) % n] - pts[i];
            let c = a.dot(&b) / (a.norm() * b.norm());
            if c.is_finite() {
                c.clamp(-1.0, 1.0).acos()
            } else {
                0.0
            }
        })
        .collect()
}

/// Smooths the layer given by `ts` (guide parameters of the columns `vs`,
/// all present, `closed` if a loop) against the layer below `below`.
/// `ts` is updated in place only if the bounds are met.
#[allow(clippy::too_many_arguments)]
pub fn smooth_layer(
    tube: &Tube,
    vs: &[f64],
    ts: &mut [f64],
    closed: bool,
    below: &SegmentIndex,
    hints: &[SegmentId],
    delta_mm: f64,
    s: &Smoothing,
) -> LayerSmoothing {
    let n = ts.len();
    let dist = |i: usize, t: f64| below.nearest_from(&tube.point(t, vs[i]), hints[i]).distance;
    let exact = |i: usize, t: f64| {
        below
            .nearest(&tube.point(t, vs[i]))
            .map_or(f64::INFINITY, |nr| nr.distance)
    };
    let positions = |ts: &[f64]| (0..n).map(|i| tube.point(ts[i], vs[i])).collect::<Vec<_>>();
    let before = turning_angles(&positions(ts), closed)
        .into_iter()
        .fold(0.0, f64::max);
    let mut out = LayerSmoothing {
        max_turn_before_rad: before,
        max_turn_after_rad: before,
        max_deviation: 0.0,
        iterations: 0,
        met: before <= s.max_turn_rad,
    };
    if out.met || n < 4 {
        return out;
    }
    let mut cur: Vec<f64> = ts.to_vec();
    let tol = s.tolerance * delta_mm;
    for iter in 0..8 {
        out.iterations = iter + 1;
        let p = positions(&cur);
        let d: Vec<Vector3> = (0..n).map(|i| tube.surface(cur[i], vs[i]).d_dt).collect();
        let delta0: Vec<f64> = (0..n).map(|i| dist(i, cur[i])).collect();
        let g: Vec<f64> = (0..n)
            .map(|i| {
                let h = FD_STEP_REL * (1.0 + cur[i].abs());
                (dist(i, cur[i] + h) - dist(i, cur[i] - h)) / (2.0 * h)
            })
            .collect();
        // Rows: distance (2 per point), turning (2 per interior point), trust region (2 per point).
        let (mut ri, mut ci, mut vals, mut b) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
        let mut row = 0;
        let mut push = |entries: &[(usize, f64)], rhs: f64, row: &mut usize| {
            for &(c, v) in entries {
                ri.push(*row);
                ci.push(c);
                vals.push(v);
            }
            b.push(rhs);
            *row += 1;
        };
        for i in 0..n {
            // |delta0 + g x − Delta| <= tol
            push(&[(i, g[i])], tol - (delta0[i] - delta_mm), &mut row);
            push(&[(i, -g[i])], tol + (delta0[i] - delta_mm), &mut row);
            // Trust region: move at most a quarter of Delta.
            let trust = 0.25 * delta_mm / d[i].norm();
            push(&[(i, 1.0)], trust, &mut row);
            push(&[(i, -1.0)], trust, &mut row);
        }
        for i in 0..n {
            if !closed && (i == 0 || i + 1 == n) {
                continue;
            }
            let (im, ip) = ((i + n - 1) % n, (i + 1) % n);
            let e0 = p[i] - p[im];
            let e1 = p[ip] - p[i];
            let h = 0.5 * (e0.norm() + e1.norm());
            // Across-layer direction in the surface at i.
            let tan = (e0 + e1).normalize();
            let across = d[i] - tan * d[i].dot(&tan);
            let bdir = if across.norm() > 0.0 {
                across.normalize()
            } else {
                continue;
            };
            let r = bdir.dot(&(e1 - e0));
            let c = 0.9 * 2.0 * (0.5 * s.max_turn_rad).sin() * h;
            let a = [
                (im, bdir.dot(&d[im])),
                (i, -2.0 * bdir.dot(&d[i])),
                (ip, bdir.dot(&d[ip])),
            ];
            let neg = a.map(|(k, v)| (k, -v));
            push(&a, c - r, &mut row);
            push(&neg, c + r, &mut row);
        }
        let a_mat = CscMatrix::new_from_triplets(row, n, ri, ci, vals);
        let weights: Vec<f64> = d.iter().map(|v| 2.0 * v.norm_squared()).collect();
        let p_mat = CscMatrix::new_from_triplets(n, n, (0..n).collect(), (0..n).collect(), weights);
        let q = vec![0.0; n];
        let cones = [SupportedConeT::NonnegativeConeT(row)];
        let settings = DefaultSettingsBuilder::default()
            .verbose(false)
            .build()
            .expect("static settings are valid");
        let Ok(mut solver) = DefaultSolver::new(&p_mat, &q, &a_mat, &b, &cones, settings) else {
            return out;
        };
        solver.solve();
        match solver.solution.status {
            SolverStatus::Solved | SolverStatus::AlmostSolved => {}
            _ => return out,
        }
        for (t, x) in cur.iter_mut().zip(&solver.solution.x) {
            *t += x;
        }
        let after = turning_angles(&positions(&cur), closed)
            .into_iter()
            .fold(0.0, f64::max);
        let dev = (0..n)
            .map(|i| (exact(i, cur[i]) - delta_mm).abs() / delta_mm)
            .fold(0.0, f64::max);
        out.max_turn_after_rad = after;
        out.max_deviation = dev;
        if after <= s.max_turn_rad && dev <= s.tolerance {
            out.met = true;
            ts.copy_from_slice(&cur);
            return out;
        }
    }
    out
}
