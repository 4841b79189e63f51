//! Phase 2, **refinement**: a compass search on the subsample from the
//! best candidates not yet refused.

use std::time::Instant;

use super::bounds::{Coords, VARIABLES};
use super::screen::Judged;
use super::Search;

/// Steps (mm or rad) below which a variable is no longer moved.
const STEP_FLOOR: f64 = 1e-3;

/// Improvement of the score a compass move must make to be taken.
const SCORE_GAIN: f64 = 1e-9;

/// First compass step of a variable, as a fraction of its range.
const FIRST_STEP: f64 = 1.0 / 8.0;

impl Search<'_> {
    /// Phase 2 of round `round`: a compass search from the best few not
    /// refused ([`refined`](super::PlaceOptions::refined) of them, each
    /// [`refine_evaluations`](super::PlaceOptions::refine_evaluations)
    /// long); after a feedback (a heavier subsample) from the best one
    /// only, with half the evaluations. The results join the pool, sorted.
    pub(crate) fn refine(&mut self, round: usize) {
        let t = Instant::now();
        let (n_starts, n_evaluations) = if round == 0 {
            (self.opts.refined.max(1), self.opts.refine_evaluations)
        } else {
            (1, self.opts.refine_evaluations / 2)
        };
        let starts: Vec<Judged> = self
            .pool
            .iter()
            .filter(|j| !self.refused.contains(&j.x))
            .take(n_starts)
            .cloned()
            .collect();
        for start in starts {
            let best = self.compass(start, n_evaluations);
            if !self.pool.iter().any(|j| j.x == best.x) {
                self.pool.push(best);
            }
        }
        self.sort_pool();
        self.times.refinement_s += t.elapsed().as_secs_f64();
    }

    /// One compass search from `start` of at most `n_evaluations`
    /// candidates: each step tries ± the step on every free variable, takes
    /// the best trial when it improves, halves the steps otherwise.
    fn compass(&mut self, start: Judged, n_evaluations: usize) -> Judged {
        let mut best = start;
        let mut step: Coords = self
            .bounds
            .variables
            .each_ref()
            .map(|v| (v.upper - v.lower) * FIRST_STEP);
        let mut evaluations = 0;
        while evaluations < n_evaluations && step.iter().any(|s| *s > STEP_FLOOR) {
            let trials = self.compass_trials(&best.x, &step);
            if trials.is_empty() {
                break;
            }
            evaluations += trials.len();
            self.candidates += trials.len();
            let top = self.judge_all(trials).into_iter().max_by(|a, b| {
                a.score
                    .total_cmp(&b.score)
                    .then(std::cmp::Ordering::Greater)
            });
            match top {
                Some(t) if t.score > best.score + SCORE_GAIN && !self.refused.contains(&t.x) => {
                    best = t
                }
                _ => step.iter_mut().for_each(|s| *s *= 0.5),
            }
        }
        best
    }

    /// The trials around `x`: ± `step` on each free variable whose step is
    /// still above the floor, clamped into the bounds.
    fn compass_trials(&self, x: &Coords, step: &[f64; VARIABLES]) -> Vec<Coords> {
        self.free
            .iter()
            .filter(|k| step[**k] > STEP_FLOOR)
            .flat_map(|&k| {
                [-1.0, 1.0].map(|sign| {
                    let mut trial = *x;
                    trial[k] += sign * step[k];
                    self.bounds.clamp(&mut trial);
                    trial
                })
            })
            .collect()
    }
}
