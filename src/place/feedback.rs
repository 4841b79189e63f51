//! Phase 4, **feedback**: after a failed certification, the failing layers
//! (and those binding the certified plan's margins) join the subsample at
//! full resolution, the best candidates are judged again on it, and a fresh
//! batch of the Halton sequence when few of them stay feasible.

use std::time::Instant;

use super::bounds::Coords;
use super::screen::subsample;
use super::Search;

/// Score above which a candidate infeasible on the subsample still counts
/// as planned (below it: the keep-out box, a refused cell).
const SCORE_PLANNED: f64 = -2.0;

/// What the feedback decided.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Next {
    /// Go on with the next round.
    Continue,
    /// Every candidate judged again is infeasible, bound by one constraint
    /// ([`Search::stopped`] names it): more rounds would meet the same wall.
    Stop,
}

impl Search<'_> {
    /// Phase 4: `failures` (spread, at most
    /// [`feedback_layers`](super::PlaceOptions::feedback_layers)) and
    /// `weakest` join the subsample at full resolution and certification's
    /// first layers; the best candidates not refused (and the cell as
    /// given) are judged again on it.
    pub(crate) fn feedback(&mut self, mut failures: Vec<usize>, weakest: Vec<usize>) -> Next {
        let t = Instant::now();
        failures.sort_unstable();
        let step = failures
            .len()
            .div_ceil(self.opts.feedback_layers.max(1))
            .max(1);
        for &i in failures.iter().step_by(step).chain(&weakest) {
            self.full.insert(i);
        }
        for &i in failures.iter().chain(&weakest) {
            if !self.hot.contains(&i) {
                self.hot.push(i);
            }
        }
        self.sub = subsample(
            self.layers,
            &self.picks,
            &self.full,
            self.opts.points_per_layer,
        );
        let next = self.judge_again();
        self.times.screening_s += t.elapsed().as_secs_f64();
        next
    }

    /// The best candidates not refused, and the cell as given, judged on
    /// the new subsample; then either the stop (one constraint binds them
    /// all) or, when fewer than two stay feasible, a fresh batch of the
    /// Halton sequence (half the screening's) judged on it too (the
    /// subsample now holds what made the certified ones fail).
    fn judge_again(&mut self) -> Next {
        let keep = (4 * self.opts.refined).max(8);
        let mut again: Vec<Coords> = self
            .pool
            .iter()
            .filter(|j| !self.refused.contains(&j.x))
            .take(keep)
            .map(|j| j.x)
            .collect();
        if !again.contains(&self.current) {
            again.push(self.current);
        }
        self.candidates += again.len();
        self.pool = self.judge_all(again);
        // None of the best is feasible on the heavier subsample and one
        // constraint binds them all (e.g. a joint speed at the cusps of the
        // layers that joined it): the search stops there.
        let first = self.pool.first().and_then(|j| j.binding.clone());
        if first.is_some()
            && self
                .pool
                .iter()
                .all(|j| j.score < 0.0 && j.binding == first && j.score > SCORE_PLANNED)
        {
            self.stopped = first;
            return Next::Stop;
        }
        let feasible = self.pool.iter().filter(|j| j.score >= 0.0).count();
        if feasible < self.opts.refined.max(2) && !self.free.is_empty() {
            let batch = (self.opts.samples / 2).max(1);
            let fresh: Vec<Coords> = (self.halton_next..self.halton_next + batch)
                .map(|i| self.halton(i))
                .collect();
            self.halton_next += batch;
            self.candidates += fresh.len();
            let judged = self.judge_all(fresh);
            self.pool.extend(judged);
        }
        self.sort_pool();
        Next::Continue
    }
}
