//! **Stage 6 — the elastic QP of the `R_Z` driver and the positioner's
//! laws.** Solves `min ½ δᵀPδ + gᵀδ + ρ t` over a step `δ` (the law's
//! coefficients: rad per unit basis value) subject to linearised rows
//! `a·δ − t ≤ b`, `t ≥ 0` and a box `|δ_i| ≤ bound`: in closed form when no
//! row binds, otherwise on a working set, with clarabel or a dense
//! primal–dual interior point ([`QpMethod::Dense`], for the positioner's
//! laws' few dozen coefficients where their options ask). A leaf: both SQPs (the
//! per-layer `R_Z` one and the positioner's) build on it, and it imports
//! nothing else of the optimisation.

use clarabel::algebra::CscMatrix;
use clarabel::solver::{
    DefaultSettingsBuilder, DefaultSolver, IPSolver, SolverStatus, SupportedConeT,
};

/// A row `a·x ≤ b` counts as violated when `a·x - t` exceeds `b` by more
/// than this fraction of `1 + |b|` (relative).
const ROW_SLACK_REL: f64 = 1e-10;

/// One linearised inequality `a · δc ≤ b`.
#[derive(Debug, Clone)]
pub(crate) struct Row {
    pub a: Vec<(usize, f64)>,
    pub b: f64,
}

/// How a QP that needs its rows is solved.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum QpMethod {
    /// clarabel (sparse, equilibrated; any size).
    Clarabel,
    /// [`solve_qp_dense`]: for few coefficients (the positioner's laws,
    /// 2 × 19, with [`PositionerQp::Dense`](crate::optimise::positioner::PositionerQp::Dense)),
    /// where clarabel's set-up per QP (ordering, symbolic factorisation,
    /// equilibration) costs more than the solve.
    Dense,
}

/// A QP's solution: the step `δ` and the elastic variable `t` (0 when every
/// row holds).
pub(crate) struct Qp {
    pub x: Vec<f64>,
    pub t: f64,
}

/// Solves `min ½ δᵀPδ + gᵀδ + ρ t` s.t. `a·δ − t ≤ b`, `t ≥ 0`, `|δ_i| ≤ box`.
///
/// Most QPs of a layer have few binding rows among many: the unconstrained
/// minimiser (a `k × k` Cholesky solve) is tried first and is the exact
/// optimum when it satisfies every row and the box; otherwise clarabel
/// solves the QP on a working set (the rows that minimiser violates, and
/// the currently violated ones), grown with the rows its solution violates
/// until none is (constraint generation: the same optimum as with all rows).
/// `method` solves the QPs on the working set.
pub(crate) fn solve_qp(
    k: usize,
    p_dense: &[f64],
    g: &[f64],
    rows: &[Row],
    rho: f64,
    bound: f64,
    method: QpMethod,
) -> Option<Qp> {
    let on_rows = |sub: &[&Row]| match method {
        QpMethod::Clarabel => solve_qp_clarabel(k, p_dense, g, sub, rho, bound),
        QpMethod::Dense => solve_qp_dense(k, p_dense, g, sub, rho, bound),
    };
    let violated_by = |x: &[f64], t: f64, r: &Row| {
        let ax: f64 = r.a.iter().map(|&(i, v)| v * x[i]).sum();
        ax - t > r.b + ROW_SLACK_REL * (1.0 + r.b.abs())
    };
    let mut work: Vec<usize> = Vec::new();
    if let Some(x) = unconstrained(k, p_dense, g) {
        if x.iter().all(|v| v.abs() < bound) {
            work = (0..rows.len())
                .filter(|&i| rows[i].b < 0.0 || violated_by(&x, 0.0, &rows[i]))
                .collect();
            if work.is_empty() {
                return Some(Qp { x, t: 0.0 });
            }
        }
    }
    if work.is_empty() {
        work = (0..rows.len()).filter(|&i| rows[i].b < 0.0).collect();
    }
    let mut in_work = vec![false; rows.len()];
    for &i in &work {
        in_work[i] = true;
    }
    for _ in 0..8 {
        let sub: Vec<&Row> = work.iter().map(|&i| &rows[i]).collect();
        let qp = on_rows(&sub)?;
        let mut added = false;
        for (i, r) in rows.iter().enumerate() {
            if !in_work[i] && violated_by(&qp.x, qp.t, r) {
                in_work[i] = true;
                work.push(i);
                added = true;
            }
        }
        if !added {
            return Some(qp);
        }
    }
    let all: Vec<&Row> = rows.iter().collect();
    on_rows(&all)
}

/// `−P⁻¹ g` when `P` (dense, `k × k`) is positive definite.
pub(crate) fn unconstrained(k: usize, p_dense: &[f64], g: &[f64]) -> Option<Vec<f64>> {
    let pm = nalgebra::DMatrix::from_row_slice(k, k, p_dense);
    let ch = pm.cholesky()?;
    let x = ch.solve(&(-nalgebra::DVector::from_column_slice(g)));
    x.iter()
        .all(|v| v.is_finite())
        .then(|| x.iter().copied().collect())
}

/// The QP of [`solve_qp`] on the given rows, by clarabel.
pub(crate) fn solve_qp_clarabel(
    k: usize,
    p_dense: &[f64],
    g: &[f64],
    rows: &[&Row],
    rho: f64,
    bound: f64,
) -> Option<Qp> {
    let n = k + 1;
    // P: upper triangle, column-major
    let mut colptr = vec![0usize; n + 1];
    let mut rowval = Vec::new();
    let mut nzval = Vec::new();
    for j in 0..k {
        for i in 0..=j {
            let v = p_dense[i * k + j];
            if v != 0.0 {
                rowval.push(i);
                nzval.push(v);
            }
        }
        colptr[j + 1] = rowval.len();
    }
    colptr[n] = rowval.len();
    let p = CscMatrix::new(n, n, colptr, rowval, nzval);
    let mut q = g.to_vec();
    q.push(rho);
    let m = rows.len() + 1 + 2 * k;
    let (mut ii, mut jj, mut vv) = (Vec::new(), Vec::new(), Vec::new());
    let mut b = Vec::with_capacity(m);
    for (r, row) in rows.iter().enumerate() {
        for &(c, v) in &row.a {
            if v != 0.0 {
                ii.push(r);
                jj.push(c);
                vv.push(v);
            }
        }
        ii.push(r);
        jj.push(k);
        vv.push(-1.0);
        b.push(row.b);
    }
    let r0 = rows.len();
    ii.push(r0);
    jj.push(k);
    vv.push(-1.0);
    b.push(0.0);
    for i in 0..k {
        ii.extend([r0 + 1 + 2 * i, r0 + 2 + 2 * i]);
        jj.extend([i, i]);
        vv.extend([1.0, -1.0]);
        b.extend([bound, bound]);
    }
    let a = CscMatrix::new_from_triplets(m, n, ii, jj, vv);
    let cones = [SupportedConeT::NonnegativeConeT(m)];
    let settings = DefaultSettingsBuilder::default()
        .verbose(false)
        .presolve_enable(false)
        .build()
        .ok()?;
    let mut solver = DefaultSolver::new(&p, &q, &a, &b, &cones, settings).ok()?;
    solver.solve();
    match solver.solution.status {
        SolverStatus::Solved | SolverStatus::AlmostSolved => {
            let x = &solver.solution.x;
            if x.iter().all(|v| v.is_finite()) {
                Some(Qp {
                    x: x[..k].to_vec(),
                    t: x[k].max(0.0),
                })
            } else {
                None
            }
        }
        _ => None,
    }
}

/// Convergence tolerance of [`solve_qp_dense`] on the primal and dual
/// residuals and the duality gap (relative to the data's size; clarabel's
/// defaults are 1e-8).
const DENSE_TOL: f64 = 1e-9;
/// Looser tolerance [`solve_qp_dense`] accepts when its iterations run out
/// (clarabel's "almost solved" is 5e-5 on the gap, 1e-4 on feasibility).
const DENSE_TOL_REDUCED: f64 = 1e-6;
/// Interior-point iterations of [`solve_qp_dense`] (clarabel's default 200;
/// the positioner's QPs take about 10).
const DENSE_MAX_ITER: usize = 60;
/// Fraction of the way to the boundary an interior-point step goes.
const DENSE_STEP_FRACTION: f64 = 0.99;

/// The QP of [`solve_qp`] on the given rows by a dense primal–dual interior
/// point (Mehrotra's predictor–corrector) on `x = [δ; t]`: `min ½ xᵀPx +
/// qᵀx` s.t. `Gx + s = h`, `s ≥ 0`, each Newton step by a Cholesky
/// factorisation of the `(k+1) × (k+1)` normal matrix `P + Gᵀ(Z/S)G`. For a
/// few dozen coefficients it costs a fraction of clarabel's set-up and
/// sparse factorisations; `None` where it does not converge.
pub(crate) fn solve_qp_dense(
    k: usize,
    p_dense: &[f64],
    g: &[f64],
    rows: &[&Row],
    rho: f64,
    bound: f64,
) -> Option<Qp> {
    let n = k + 1;
    // G's rows, sparse: the rows `a·δ − t ≤ b`, `−t ≤ 0`, `±δ_i ≤ bound`
    let mut start = vec![0usize];
    let mut entries: Vec<(usize, f64)> = Vec::new();
    let mut h = Vec::with_capacity(rows.len() + 1 + 2 * k);
    for row in rows {
        entries.extend(row.a.iter().copied().filter(|e| e.1 != 0.0));
        entries.push((k, -1.0));
        start.push(entries.len());
        h.push(row.b);
    }
    entries.push((k, -1.0));
    start.push(entries.len());
    h.push(0.0);
    for i in 0..k {
        for sign in [1.0, -1.0] {
            entries.push((i, sign));
            start.push(entries.len());
            h.push(bound);
        }
    }
    let m = h.len();
    let row = |i: usize| &entries[start[i]..start[i + 1]];
    let dot = |i: usize, x: &[f64]| row(i).iter().map(|&(j, v)| v * x[j]).sum::<f64>();
    let mut p = vec![0.0; n * n];
    for i in 0..k {
        p[i * n..i * n + k].copy_from_slice(&p_dense[i * k..i * k + k]);
    }
    let mut q = g.to_vec();
    q.push(rho);
    // the normal matrix P + Gᵀ diag(w) G, factorised in place
    let normal = |w: &[f64], mat: &mut Vec<f64>| -> bool {
        mat.copy_from_slice(&p);
        for (i, &wi) in w.iter().enumerate() {
            for &(a, va) in row(i) {
                for &(b, vb) in row(i) {
                    mat[a * n + b] += wi * va * vb;
                }
            }
        }
        cholesky(n, mat)
    };
    let norm_inf = |v: &[f64]| v.iter().fold(0.0f64, |a, x| a.max(x.abs()));
    let h_size = 1.0 + norm_inf(&h);
    let q_size = 1.0 + norm_inf(&q);
    let mut mat = vec![0.0; n * n];
    // start: the least-squares point of P x + q + Gᵀz = 0, Gx − h = z
    // (CVXOPT's), s and z shifted into the interior
    let mut x = vec![0.0; n];
    if !normal(&vec![1.0; m], &mut mat) {
        return None;
    }
    let mut rhs: Vec<f64> = q.iter().map(|v| -v).collect();
    for (i, &hi) in h.iter().enumerate() {
        for &(j, v) in row(i) {
            rhs[j] += v * hi;
        }
    }
    cholesky_solve(n, &mat, &mut rhs);
    x.copy_from_slice(&rhs);
    let mut s: Vec<f64> = (0..m).map(|i| h[i] - dot(i, &x)).collect();
    let mut z: Vec<f64> = s.iter().map(|v| -v).collect();
    for v in [&mut s, &mut z] {
        let lowest = v.iter().fold(f64::INFINITY, |a, &b| a.min(b));
        let shift = if lowest < 0.0 { 1.0 - lowest } else { 0.0 };
        let floor = 1e-8 * h_size;
        for e in v.iter_mut() {
            *e = (*e + shift).max(floor);
        }
    }
    let (mut dx, mut ds, mut dz) = (vec![0.0; n], vec![0.0; m], vec![0.0; m]);
    let mut w = vec![0.0; m];
    let mut rc = vec![0.0; m];
    for iter in 0..=DENSE_MAX_ITER {
        // residuals: r_d = Px + q + Gᵀz, r_p = Gx + s − h
        let px: Vec<f64> = (0..n)
            .map(|i| (0..n).map(|j| p[i * n + j] * x[j]).sum::<f64>())
            .collect();
        let mut rd: Vec<f64> = (0..n).map(|i| q[i] + px[i]).collect();
        for (i, &zi) in z.iter().enumerate() {
            for &(j, v) in row(i) {
                rd[j] += v * zi;
            }
        }
        let rp: Vec<f64> = (0..m).map(|i| dot(i, &x) + s[i] - h[i]).collect();
        let gap: f64 = s.iter().zip(&z).map(|(a, b)| a * b).sum();
        let objective: f64 = (0..n).map(|i| x[i] * (q[i] + 0.5 * px[i])).sum();
        let within = |tol: f64| {
            norm_inf(&rp) <= tol * h_size
                && norm_inf(&rd) <= tol * q_size
                && gap <= tol * (1.0 + objective.abs())
        };
        if within(DENSE_TOL) || (iter == DENSE_MAX_ITER && within(DENSE_TOL_REDUCED)) {
            return x.iter().all(|v| v.is_finite()).then(|| Qp {
                x: x[..k].to_vec(),
                t: x[k].max(0.0),
            });
        }
        if iter == DENSE_MAX_ITER {
            return None;
        }
        for i in 0..m {
            w[i] = z[i] / s[i];
        }
        if !normal(&w, &mut mat) {
            return None;
        }
        let mu = gap / m as f64;
        // Newton step for the complementarity target r_c (s∘z − r_c → 0):
        // (P + GᵀWG) Δx = −r_d − Gᵀ(W r_p − r_c/s), Δs = −r_p − GΔx,
        // Δz = W(GΔx + r_p) − r_c/s
        let step = |rc: &[f64], dx: &mut Vec<f64>, ds: &mut Vec<f64>, dz: &mut Vec<f64>| {
            for (d, r) in dx.iter_mut().zip(&rd) {
                *d = -r;
            }
            for i in 0..m {
                let c = w[i] * rp[i] - rc[i] / s[i];
                for &(j, v) in row(i) {
                    dx[j] -= v * c;
                }
            }
            cholesky_solve(n, &mat, dx);
            for i in 0..m {
                let gdx = dot(i, dx);
                ds[i] = -rp[i] - gdx;
                dz[i] = w[i] * (gdx + rp[i]) - rc[i] / s[i];
            }
        };
        let longest = |v: &[f64], dv: &[f64]| {
            v.iter()
                .zip(dv)
                .filter(|(_, d)| **d < 0.0)
                .fold(1.0f64, |a, (x, d)| a.min(-x / d))
        };
        // predictor (affine scaling), then Mehrotra's centring and corrector
        for i in 0..m {
            rc[i] = s[i] * z[i];
        }
        step(&rc, &mut dx, &mut ds, &mut dz);
        let alpha = longest(&s, &ds).min(longest(&z, &dz));
        let gap_aff: f64 = (0..m)
            .map(|i| (s[i] + alpha * ds[i]) * (z[i] + alpha * dz[i]))
            .sum();
        let sigma = (gap_aff / gap).clamp(0.0, 1.0).powi(3);
        for i in 0..m {
            rc[i] = s[i] * z[i] + ds[i] * dz[i] - sigma * mu;
        }
        step(&rc, &mut dx, &mut ds, &mut dz);
        let alpha = (DENSE_STEP_FRACTION * longest(&s, &ds).min(longest(&z, &dz))).min(1.0);
        for i in 0..n {
            x[i] += alpha * dx[i];
        }
        for i in 0..m {
            s[i] += alpha * ds[i];
            z[i] += alpha * dz[i];
        }
    }
    None
}

/// In-place Cholesky factor `L` (lower triangle, row-major `n × n`) of a
/// symmetric matrix; `false` where it is not positive definite.
fn cholesky(n: usize, a: &mut [f64]) -> bool {
    for j in 0..n {
        let mut d = a[j * n + j];
        for l in 0..j {
            d -= a[j * n + l] * a[j * n + l];
        }
        if !(d > 0.0) {
            return false;
        }
        let d = d.sqrt();
        a[j * n + j] = d;
        for i in j + 1..n {
            let mut v = a[i * n + j];
            for l in 0..j {
                v -= a[i * n + l] * a[j * n + l];
            }
            a[i * n + j] = v / d;
        }
    }
    true
}

/// Solves `L Lᵀ x = b` in place with [`cholesky`]'s factor.
fn cholesky_solve(n: usize, l: &[f64], b: &mut [f64]) {
    for i in 0..n {
        let mut v = b[i];
        for j in 0..i {
            v -= l[i * n + j] * b[j];
        }
        b[i] = v / l[i * n + i];
    }
    for i in (0..n).rev() {
        let mut v = b[i];
        for j in i + 1..n {
            v -= l[j * n + i] * b[j];
        }
        b[i] = v / l[i * n + i];
    }
}
