//! Phase 3, **certification**: every layer of a candidate at full
//! resolution, the failing layers met first, stopping at the first group
//! with an infeasible layer; a feasible plan then goes to the caller's
//! check.

use std::collections::BTreeSet;
use std::sync::Arc;
use std::time::Instant;

use rayon::prelude::*;

use super::bounds::{placed_cell, Coords};
use super::score::{margins, scaled};
use super::screen::radical_inverse;
use super::Search;
use crate::optimise::{
    optimise, transitions, LayerPlan, LayerPoints, OptimiseError, OptimiseOptions, Plan,
};
use crate::robot::CellLayout;

/// Layers certified together: certification stops after the first group
/// of this many (in certification order) with an infeasible layer, whatever
/// the number of threads (the chunks computed in parallel are whole
/// groups), so that the search's path does not depend on the machine.
const CERTIFY_GROUP: usize = 8;

/// How much better (in the search's score: 1 is comfortable margins, 10° from
/// a stop and 20 % speed headroom) another candidate must score on the
/// subsample for the cell as given, when feasible there, not to be
/// certified first: 0.05 is half a degree from a stop or 1 % of speed
/// headroom. A placed cell placed again thus stays where it is.
pub const KEEP_MARGIN: f64 = 0.05;

/// Layers planned at certification, with their indices in the path.
type Certified = Vec<(usize, LayerPlan)>;

/// How a round's certification ended.
pub(crate) enum RoundEnd {
    /// A candidate passed: the search is over.
    Chosen,
    /// Nothing feasible on the subsample was left to certify.
    NothingToCertify,
    /// The candidates certified failed (or were refused); the layers that
    /// failed or were named, and those that bind the margins, by index in
    /// the path (both empty: nothing to feed back).
    Failed {
        /// Layers infeasible, or named by the caller's refusal.
        failures: Vec<usize>,
        /// Layers binding the certified layers' margins.
        weakest: Vec<usize>,
    },
}

/// The order in which certification visits the layers: those that failed
/// before first, then the others by the base-2 radical inverse of their
/// index (so that the first few spread over the whole part).
fn certification_order(n: usize, hot: &[usize]) -> Vec<usize> {
    let mut seen = vec![false; n];
    let mut order = Vec::with_capacity(n);
    for &i in hot {
        if i < n && !seen[i] {
            seen[i] = true;
            order.push(i);
        }
    }
    let mut rest: Vec<usize> = (0..n).filter(|i| !seen[*i]).collect();
    rest.sort_by(|a, b| radical_inverse(*a, 2).total_cmp(&radical_inverse(*b, 2)));
    order.extend(rest);
    order
}

/// Every layer of `layers` in `cell`, in `order`, in parallel chunks of
/// about `chunk` (rounded up to whole [`CERTIFY_GROUP`]s), stopping after
/// the first group with an infeasible layer. Returns the layers planned (in
/// path order, with their indices in `layers`) and the infeasible ones'
/// indices.
fn certify(
    cell: &CellLayout,
    layers: &[LayerPoints],
    order: &[usize],
    serial: &OptimiseOptions,
    chunk: usize,
) -> Result<(Certified, Vec<usize>), OptimiseError> {
    let chunk = chunk.max(1).div_ceil(CERTIFY_GROUP) * CERTIFY_GROUP;
    let mut planned: Vec<(usize, LayerPlan)> = Vec::with_capacity(layers.len());
    let mut failing = Vec::new();
    for part in order.chunks(chunk) {
        let results: Vec<Result<(usize, LayerPlan), OptimiseError>> = part
            .par_iter()
            .map(|&i| {
                let mut plan = optimise(cell, std::slice::from_ref(&layers[i]), serial)?;
                Ok((i, plan.layers.remove(0)))
            })
            .collect();
        for (k, r) in results.into_iter().enumerate() {
            let (i, l) = r?;
            if !l.status.is_feasible() {
                failing.push(i);
            }
            planned.push((i, l));
            // the end of a group with a failure: the rest is not used
            if (k + 1) % CERTIFY_GROUP == 0 && !failing.is_empty() {
                break;
            }
        }
        if !failing.is_empty() {
            break;
        }
    }
    planned.sort_by_key(|(i, _)| *i);
    Ok((planned, failing))
}

/// The layers of a certified (possibly partial) plan that bind its margins
/// below the score's comfortable values (the smallest joint-stop distance,
/// speed headroom and reach margin, each over the layers planned), by their
/// index in the path, excluding those in `known`. The subsample's points
/// may miss a layer's worst point and its layers may miss the worst layer
/// (the S-bend at Delta 2 mm: 11° from a stop on the subsample, 0.5° on the
/// full path, in layers between the subsample's); these layers joining the
/// subsample make its score the full path's.
fn weakest_layers(
    planned: &[(usize, LayerPlan)],
    cell: &CellLayout,
    known: &BTreeSet<usize>,
) -> Vec<usize> {
    let mut worst: [(f64, Option<usize>); 3] = [(f64::INFINITY, None); 3];
    for (i, l) in planned {
        if known.contains(i) {
            continue;
        }
        let m = margins(
            &Plan {
                layers: vec![l.clone()],
                transitions: Vec::new(),
                time_s: 0.0,
            },
            cell,
        );
        for (w, v) in worst.iter_mut().zip(scaled(&m)) {
            if v < 1.0 && v < w.0 {
                *w = (v, Some(*i));
            }
        }
    }
    let mut out: Vec<usize> = worst.iter().filter_map(|w| w.1).collect();
    out.sort_unstable();
    out.dedup();
    out
}

/// A candidate's full plan: every layer it planned at certification, with
/// the arc-off transitions between them.
struct FullPlan {
    cell: CellLayout,
    plan: Plan,
    /// Infeasible layers, by index in the path.
    failing: Vec<usize>,
    /// Share of the layers checked that are infeasible.
    share: f64,
    /// Layers binding the margins (see [`weakest_layers`]).
    weakest: Vec<usize>,
}

impl Search<'_> {
    /// The candidates to certify this round: the best feasible on the
    /// subsample not refused, the cell as given first among them unless
    /// beaten by [`KEEP_MARGIN`] (then last).
    fn to_certify(&self) -> Vec<Coords> {
        let open = |j: &&super::screen::Judged| !self.refused.contains(&j.x);
        let mut out: Vec<Coords> = self
            .pool
            .iter()
            .filter(|j| j.score >= 0.0)
            .filter(open)
            .take(self.opts.refined.max(1))
            .map(|j| j.x)
            .collect();
        let current_score = self
            .pool
            .iter()
            .filter(open)
            .find(|j| j.x == self.current)
            .map(|j| j.score)
            .filter(|s| *s >= 0.0);
        if let Some(s) = current_score {
            out.retain(|x| *x != self.current);
            // Kept unless clearly beaten: placing a placed cell again finds it.
            let best = self.pool.iter().find(open).map_or(s, |j| j.score);
            if s >= best - KEEP_MARGIN {
                out.insert(0, self.current);
            } else {
                out.push(self.current);
            }
        }
        out
    }

    /// Plans every layer of `x`'s cell (see [`certify`]).
    fn full_plan(&self, x: &Coords) -> Result<FullPlan, OptimiseError> {
        let cell = placed_cell(self.cell, x);
        let order = certification_order(self.layers.len(), &self.hot);
        let (planned, failing) = certify(&cell, self.layers, &order, &self.serial, self.chunk)?;
        let checked = planned.len().max(1);
        let known: BTreeSet<usize> = self.picks.union(&self.full).copied().collect();
        let weakest = weakest_layers(&planned, &cell, &known);
        let planned: Vec<LayerPlan> = planned.into_iter().map(|(_, l)| l).collect();
        let plan = Plan {
            transitions: transitions(&cell, &planned),
            layers: planned,
            time_s: 0.0,
        };
        Ok(FullPlan {
            share: failing.len() as f64 / checked as f64,
            cell,
            plan,
            failing,
            weakest,
        })
    }

    /// Phase 3: certifies the candidates of [`Search::to_certify`] in turn
    /// until one passes, one fails on the full path, or the caller's check
    /// refuses one and names layers (or margins bind) to feed back.
    pub(crate) fn certify_round(&mut self) -> Result<RoundEnd, OptimiseError> {
        let t = Instant::now();
        let end = self.certify_candidates();
        self.times.certification_s += t.elapsed().as_secs_f64();
        end
    }

    fn certify_candidates(&mut self) -> Result<RoundEnd, OptimiseError> {
        let to_certify = self.to_certify();
        if to_certify.is_empty() {
            return Ok(RoundEnd::NothingToCertify);
        }
        for x in to_certify {
            self.certified += 1;
            let f = self.full_plan(&x)?;
            self.refused.push(x);
            if !f.failing.is_empty() {
                if self.failed.is_none() {
                    self.failed = Some((x, f.cell, f.plan, f.share));
                }
                return Ok(RoundEnd::Failed {
                    failures: f.failing,
                    weakest: f.weakest,
                });
            }
            match (self.accept)(&f.cell, self.layers, &f.plan) {
                Ok(()) => {
                    self.chosen = Some((x, f.cell, f.plan));
                    return Ok(RoundEnd::Chosen);
                }
                Err(e) => {
                    // The layers the refusal names join the subsample: its
                    // screen then sees the move refused; and the layers
                    // that bind the margins, which the subsample missed (a
                    // refused transit follows a law pressed against a stop).
                    // A refusal naming its layers in words only (the
                    // transit check's and the turn stroke's
                    // `ProgramError::Infeasible`) brings none: only the
                    // margin-binding layers follow it.
                    let named: Vec<usize> = e
                        .layers()
                        .iter()
                        .filter_map(|n| self.layers.iter().position(|l| l.layer == *n))
                        .collect();
                    self.refusal.get_or_insert(Arc::new(e));
                    if named.is_empty() && f.weakest.is_empty() {
                        continue;
                    }
                    return Ok(RoundEnd::Failed {
                        failures: named,
                        weakest: f.weakest,
                    });
                }
            }
        }
        Ok(RoundEnd::Failed {
            failures: Vec::new(),
            weakest: Vec::new(),
        })
    }

    /// Last resort: the cell as given, when feasible on the subsample and
    /// not yet certified (a part that plans where it stands keeps a
    /// placement).
    pub(crate) fn certify_current(&mut self) -> Result<(), OptimiseError> {
        if self.chosen.is_some() || self.refused.contains(&self.current) {
            return Ok(());
        }
        let c = placed_cell(self.cell, &self.current);
        if !optimise(&c, &self.sub, &self.serial).is_ok_and(|p| p.is_feasible()) {
            return Ok(());
        }
        let t = Instant::now();
        self.certified += 1;
        let f = self.full_plan(&self.current)?;
        if f.failing.is_empty() {
            match (self.accept)(&f.cell, self.layers, &f.plan) {
                Ok(()) => self.chosen = Some((self.current, f.cell, f.plan)),
                Err(e) => {
                    self.refusal.get_or_insert(Arc::new(e));
                }
            }
        }
        self.times.certification_s += t.elapsed().as_secs_f64();
        Ok(())
    }
}
