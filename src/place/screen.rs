//! Phase 1, **screening**: the subsample of layers and points every
//! candidate is judged on, the Halton sequence of candidates over the free
//! variables, and the judgement of one candidate (its score, its binding
//! constraint).

use std::collections::BTreeSet;
use std::time::Instant;

use rayon::prelude::*;

use super::bounds::{placed_cell, Coords, VARIABLES};
use super::outcome::Limit;
use super::score::{binding_of, score};
use super::Search;
use crate::optimise::{optimise, LayerPoints};

/// Score of a candidate in the keep-out box (below every planned one).
const SCORE_KEEP_OUT: f64 = -2.0;
/// Score of a candidate whose cell the optimiser refuses.
const SCORE_REFUSED_CELL: f64 = -3.0;
/// Score of a candidate feasible on the subsample that the caller's check
/// refuses there (below every feasible one, above most infeasible ones).
const SCORE_SCREEN_REFUSAL: f64 = -0.05;

/// Bases of the Halton sequence, one per variable.
const HALTON_BASES: [usize; VARIABLES] = [2, 3, 5, 7, 11, 13, 17, 19, 23, 29];

/// A candidate judged on the subsample.
#[derive(Clone)]
pub(crate) struct Judged {
    /// The candidate.
    pub x: Coords,
    /// Its score (≥ 0 feasible; see [`score`]).
    pub score: f64,
    /// What bound it when infeasible.
    pub binding: Option<Limit>,
}

/// The layers picked for the subsample: `n_layers` evenly spread (first and
/// last included), or all when there are fewer.
pub(crate) fn coarse_picks(n: usize, n_layers: usize) -> BTreeSet<usize> {
    if n <= n_layers.max(2) {
        return (0..n).collect();
    }
    (0..n_layers)
        .map(|i| (i as f64 * (n - 1) as f64 / (n_layers - 1) as f64).round() as usize)
        .collect()
}

/// The subsample: the picked layers, every `k`-th point, and the layers of
/// `full` with all their points.
pub(crate) fn subsample(
    layers: &[LayerPoints],
    picks: &BTreeSet<usize>,
    full: &BTreeSet<usize>,
    n_points: usize,
) -> Vec<LayerPoints> {
    picks
        .union(full)
        .map(|&i| {
            let l = &layers[i];
            if full.contains(&i) {
                return l.clone();
            }
            let k = l.points.len().div_ceil(n_points.max(3)).max(1);
            let mut points: Vec<_> = l.points.iter().step_by(k).copied().collect();
            // The last point too: the arc-off moves start there.
            if (l.points.len() - 1) % k != 0 {
                points.extend(l.points.last().copied());
            }
            LayerPoints {
                points,
                ..l.clone()
            }
        })
        .filter(|l| l.points.len() >= 3)
        .collect()
}

/// Radical inverse of `i` in `base` (Halton sequence), in `[0, 1)`.
pub(crate) fn radical_inverse(mut i: usize, base: usize) -> f64 {
    let (mut f, mut r) = (1.0, 0.0);
    while i > 0 {
        f /= base as f64;
        r += f * (i % base) as f64;
        i /= base;
    }
    r
}

/// The most frequent binding constraint among `judged`, with its share
/// (ties broken by the constraint's words, so that the result does not
/// depend on the order of the candidates).
pub(crate) fn most_frequent_binding(judged: &[Judged]) -> Option<(Limit, f64)> {
    let mut counts: Vec<(String, &Limit, usize)> = Vec::new();
    // Counted by their words: two limits that read the same are one.
    for b in judged.iter().filter_map(|j| j.binding.as_ref()) {
        let words = b.to_string();
        match counts.iter_mut().find(|(w, _, _)| *w == words) {
            Some((_, _, c)) => *c += 1,
            None => counts.push((words, b, 1)),
        }
    }
    counts.sort_by(|a, b| b.2.cmp(&a.2).then_with(|| a.0.cmp(&b.0)));
    counts
        .first()
        .map(|(_, l, c)| ((*l).clone(), *c as f64 / judged.len().max(1) as f64))
}

impl Search<'_> {
    /// The `i`-th point of the Halton sequence over the free variables (the
    /// fixed ones at the cell's values).
    pub(crate) fn halton(&self, i: usize) -> Coords {
        let mut x = self.current;
        for (d, &k) in self.free.iter().enumerate() {
            let v = &self.bounds.variables[k];
            x[k] = v.lower + radical_inverse(i, HALTON_BASES[d]) * (v.upper - v.lower);
        }
        x
    }

    /// Judges `x` on `sub`: its plan's score, and the caller's check on the
    /// subsample when the plan is feasible there (a screen: the subsample's
    /// wall is sparse and its transits join layers far apart).
    pub(crate) fn judge(&self, x: Coords, sub: &[LayerPoints]) -> Judged {
        if self.bounds.inside_keep_out(&x) {
            return Judged {
                x,
                score: SCORE_KEEP_OUT,
                binding: Some(Limit::KeepOut),
            };
        }
        let c = placed_cell(self.cell, &x);
        match optimise(&c, sub, &self.serial) {
            Ok(plan) => {
                let s = score(&plan, &c);
                if s >= 0.0 {
                    if let Err(e) = (self.accept)(&c, sub, &plan) {
                        if let Ok(mut first) = self.screen_refusal.lock() {
                            first.get_or_insert(std::sync::Arc::new(e));
                        }
                        return Judged {
                            x,
                            score: SCORE_SCREEN_REFUSAL,
                            binding: Some(Limit::ProgramCheck),
                        };
                    }
                }
                Judged {
                    score: s,
                    binding: binding_of(&plan),
                    x,
                }
            }
            Err(e) => Judged {
                x,
                score: SCORE_REFUSED_CELL,
                binding: Some(Limit::Optimiser(e)),
            },
        }
    }

    /// Judges every candidate of `xs` on the current subsample, in parallel
    /// (order kept).
    pub(crate) fn judge_all(&self, xs: Vec<Coords>) -> Vec<Judged> {
        xs.into_par_iter()
            .map(|x| self.judge(x, &self.sub))
            .collect()
    }

    /// Phase 1: the cell as given first, then the first
    /// [`samples`](super::PlaceOptions::samples) − 1 points of the Halton
    /// sequence, judged on the first subsample; the pool sorted best first.
    pub(crate) fn screen(&mut self) {
        let t = Instant::now();
        let mut starts = vec![self.current];
        starts.extend((1..self.opts.samples).map(|i| self.halton(i)));
        self.halton_next = self.opts.samples.max(1);
        let screened = self.judge_all(starts);
        self.candidates = screened.len();
        self.feasible_fraction =
            screened.iter().filter(|j| j.score >= 0.0).count() as f64 / screened.len() as f64;
        self.pool = screened.clone();
        self.screened = screened;
        self.sort_pool();
        self.times.screening_s += t.elapsed().as_secs_f64();
    }

    /// The pool, best score first (stable).
    pub(crate) fn sort_pool(&mut self) {
        self.pool.sort_by(|a, b| b.score.total_cmp(&a.score));
    }
}
