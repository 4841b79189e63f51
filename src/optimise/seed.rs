//! Seeds of a layer [SPEC §7]: constant `R_Z` laws over a coarse grid,
//! and `c − theta` laws on layers turning about the part Z axis, scored in
//! every IK branch on a few sample points (violation of the travels, joint
//! displacement estimate, centring).

use std::f64::consts::{PI, TAU};

use super::setup::LayerSetup;
use crate::robot::ik::{unwrap_near, Configuration};
use crate::robot::model::Joints;

/// A seed: `R_Z` at every point and the polynomial degree that holds it.
#[derive(Debug, Clone)]
pub(super) struct Seed {
    pub(super) r: Vec<f64>,
    pub(super) degree: usize,
    pub(super) violation: f64,
    pub(super) estimate: f64,
    pub(super) centring: f64,
}

impl LayerSetup<'_> {
    /// The seed families on a layer.
    fn seed_laws(&self) -> Vec<(Vec<f64>, usize)> {
        let p = self.points.len();
        if let Some(a) = self.anchor {
            // continue the previous turn: R_Z held, then constant or `− theta`
            let mut out = vec![(vec![a.r_z; p], 1)];
            if self.turning {
                let r = self
                    .theta
                    .iter()
                    .map(|t| a.r_z - (t - self.theta[0]))
                    .collect();
                out.push((r, 1));
            }
            return out;
        }
        let n = self.opts.seeds;
        let mut out = Vec::new();
        for i in 0..n {
            let c = -PI + TAU * i as f64 / n as f64;
            out.push((vec![c; p], 0));
            if self.turning {
                let r = self.theta.iter().map(|t| c - (t - self.theta[0])).collect();
                out.push((r, 1));
            }
        }
        out
    }

    /// Scores every seed in each branch of `cfgs` on the sample points; per
    /// branch, its best seed. The cell poses of a seed's sample points do not
    /// depend on the branch: they are computed once and every branch's IK is
    /// solved from them ([`RobotModel::inverse_all`](crate::robot::RobotModel::inverse_all)).
    pub(super) fn best_seeds(&self, cfgs: &[Configuration]) -> Vec<Seed> {
        let p = self.points.len();
        let ns = self.opts.seed_points.min(p);
        let idx: Vec<usize> = (0..ns)
            .map(|i| ((i as f64) * (p - 1) as f64 / (ns - 1).max(1) as f64).round() as usize)
            .collect();
        let prob = self.problem(cfgs[0], vec![0.0; p]);
        let robot = self.cell.robot();
        let mut best: Vec<Option<Seed>> = vec![None; cfgs.len()];
        for (r, degree) in self.seed_laws() {
            // per branch: (violation, displacement estimate, centring, previous joints)
            let mut acc: Vec<(f64, f64, f64, Option<Joints>)> =
                vec![(0.0, 0.0, 0.0, prob.start_near); cfgs.len()];
            let mut q8 = 0.0;
            for &m in &idx {
                let pose = match prob.pose(m, r[m], q8) {
                    Ok(pose) => pose,
                    Err(_) => {
                        for a in &mut acc {
                            a.0 = f64::INFINITY;
                        }
                        break;
                    }
                };
                let all = robot.inverse_all(&pose.base_from_flange);
                let mut any = false;
                for (a, cfg) in acc.iter_mut().zip(cfgs) {
                    if a.0 == f64::INFINITY {
                        continue;
                    }
                    let q = match &all[cfg.index()] {
                        Ok(q) => match a.3 {
                            Some(n) => std::array::from_fn(|j| unwrap_near(q[j], n[j])),
                            None => *q,
                        },
                        Err(_) => {
                            a.0 = f64::INFINITY;
                            continue;
                        }
                    };
                    any = true;
                    let (viol, est, cen, prev) = a;
                    for j in 0..6 {
                        let (lo, hi) = prob.joint_bounds(j, &q);
                        *viol = viol.max(q[j] - hi).max(lo - q[j]);
                        if let Some(qq) = prev {
                            *est += prob.gamma[j] * (q[j] - qq[j]).powi(2);
                        }
                    }
                    *cen += prob.centring_of(&q);
                    if let Some(h) = prob.hose {
                        *viol = viol.max((q[3] + q[5]).abs() - h);
                    }
                    *prev = Some(q);
                }
                if !any {
                    break;
                }
                if let Some(qp) = pose.positioner {
                    q8 = qp[1];
                }
            }
            for (b, (viol, est, cen, _)) in best.iter_mut().zip(acc) {
                let cen = cen / ns as f64;
                // displacement between samples ≈ (ns−1)/(p−1) of the full sum
                let est = est * (ns - 1) as f64 / (p - 1) as f64;
                let seed = Seed {
                    r: r.clone(),
                    degree,
                    violation: viol.max(0.0),
                    estimate: est + self.opts.centring_weight * cen,
                    centring: cen,
                };
                // the first of equal seeds wins (a stable sort's order)
                let better = b.as_ref().is_none_or(|s| {
                    seed.violation
                        .total_cmp(&s.violation)
                        .then(seed.estimate.total_cmp(&s.estimate))
                        .is_lt()
                });
                if better {
                    *b = Some(seed);
                }
            }
        }
        best.into_iter()
            .map(|b| b.expect("at least one seed law"))
            .collect()
    }
}
