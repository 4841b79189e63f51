//! **Stage 6 — the elastic QP of the `R_Z` driver and the positioner's
//! laws.** Solves `min ½ δᵀPδ + gᵀδ + ρ t` over a step `δ` (the law's
//! coefficients: rad per unit basis value) subject to linearised rows
//! `a·δ − t ≤ b`, `t ≥ 0` and a box `|δ_i| ≤ bound`: in closed form when no
//! row binds, otherwise with clarabel on a working set. A leaf: both SQPs
//! (the per-layer `R_Z` one and the positioner's) build on it, and it
//! imports nothing else of the optimisation.

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
pub(crate) fn solve_qp(
    k: usize,
    p_dense: &[f64],
    g: &[f64],
    rows: &[Row],
    rho: f64,
    bound: f64,
) -> Option<Qp> {
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
        let qp = solve_qp_clarabel(k, p_dense, g, &sub, rho, bound)?;
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
    solve_qp_clarabel(k, p_dense, g, &all, rho, bound)
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
fn solve_qp_clarabel(
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
