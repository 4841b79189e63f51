//! **Stage 8 — placement of the part in the cell** (beyond the thesis,
//! which moved the deposition point by hand, §3.3 "second position"). An
//! outer search over stages 6 and 7: takes a [`CellLayout`], the layers of a path
//! (part frame, mm) and [`PlacementBounds`] on the cell's placement
//! variables (robot base frame; mm, rad), judges candidates with the `R_Z`
//! optimisation ([`optimise`]) as its oracle and
//! the caller's program check ([`Accept`]), and returns a [`Placement`]: the
//! placement ([`PlacementValues`]) that makes every layer feasible with the
//! widest worst-layer margin (joint-limit distance, speed headroom, reach,
//! dexterity), or the [`Binding`] constraint that stopped it, with the
//! phase it was found in.
//!
//! | piece | module |
//! |---|---|
//! | variables, bounds, typed values, the placed cell | [`bounds`] |
//! | 1. screening: subsample, Halton candidates, judging one | `screen` |
//! | 2. refinement: compass search | `refine` |
//! | 3. certification: every layer, then the caller's check | `certify` |
//! | 4. feedback: failing layers join the subsample | `feedback` |
//! | margins and score | [`score`] |
//! | what the search gives back | [`outcome`] |
//!
//! The variables (robot base frame unless said; mm, rad), each searched
//! only where its bounds differ:
//!
//! | | part carried | torch carried |
//! |---|---|---|
//! | 0–2 | deposition point `D_R` x, y, z | positioner origin x, y, z |
//! | 3 | part mount about the flange axis | positioner about the vertical |
//! | 4, 5 | fixture tilt of the part on the flange about X, Y | fixture tilt of the part on the table about X, Y |
//! | 6 | part mount offset along the flange axis (mm) | torch in its clamp about the flange axis |
//! | 7, 8 | part mount offset in the flange plane, flange x, y (mm) | part offset on the table, table x, y (mm) |
//! | 9 | — (fixed at 0: variable 3 turns the mount) | part rotation on the table about its normal |
//!
//! By default ([`PlacementBounds::around`]) variables 0–3 are searched, and
//! in a torch-carried cell also the part's offset on the table (7, 8: the
//! part origin within ±[`TABLE_OFFSET_MM`] of the turn axis): a layer far
//! from the turn axis orbits it as the table turns, and moving the part on
//! the table is what a cell operator does. The others are searched when
//! the bounds give them a range (the cell file's `[placement]` table).
//! [`PlacementValues::apply`] gives the order in which the mount variables
//! compose.
//!
//! The search:
//! 1. **Screening**: a coarse global sampling of the free variables (a
//!    Halton sequence; the cell as given is the first candidate), each
//!    candidate judged by the `R_Z` optimisation of SPEC §7 on a subsample
//!    of the layers and points, candidates in parallel.
//! 2. **Refinement**: a compass search from the best few, on the subsample
//!    (after a feedback, from the best one with half the evaluations).
//! 3. **Certification**, best first (the cell as given first unless beaten
//!    by [`KEEP_MARGIN`]), of the candidates feasible on the subsample:
//!    every layer at full resolution, in an order that meets the layers
//!    that failed before first and spreads the others over the part,
//!    in parallel chunks, stopping at the first chunk with an infeasible
//!    layer; a feasible plan is then offered to the caller's own check (the
//!    program stage's transit check, in [`place_part`](crate::place_part)).
//! 4. **Feedback**: when certification fails, the failing layers join the
//!    subsample at full resolution (the subsample misses speed peaks at cusps
//!    between its points), or the layers the caller's refusal names in typed
//!    fields ([`ProgramError::layers`]), and so do the layers of the certified plan that
//!    bind its joint-stop, speed or reach margin below the score's
//!    comfortable values (the subsample missed them); the best candidates
//!    are judged again on it, and when fewer than two of them stay feasible
//!    a fresh batch of the Halton sequence (half the screening's) is judged
//!    on it too; the search goes back to 2, for a bounded number of rounds.
//!
//! The score of a candidate feasible on the subsample is its worst margin:
//! joint stops, speed headroom and the wrist centre's distance inside the
//! arm's reach ([`REACH_COMFORT_MM`]), so that a candidate at the edge of
//! the reach ranks below one with room (points between the subsample's may
//! be out of reach). Certification still plans every point.

use std::collections::BTreeSet;
use std::sync::{Arc, Mutex};
use std::time::Instant;

pub mod bounds;
mod certify;
mod feedback;
pub mod outcome;
mod refine;
pub mod score;
mod screen;
#[cfg(test)]
mod tests;

pub use bounds::{PlacementBounds, PlacementValues, PlacementVariable, TABLE_OFFSET_MM, VARIABLES};
pub use certify::KEEP_MARGIN;
pub use outcome::{Binding, Limit, Margins, PlaceTimes, Placement};
pub use score::{margins, REACH_COMFORT_MM};

use bounds::{placed_cell, Coords};
use certify::RoundEnd;
use feedback::Next;
use screen::{coarse_picks, most_frequent_binding, subsample, Judged};

use crate::optimise::{optimise, LayerPoints, OptimiseError, OptimiseOptions, Plan};
use crate::program::ProgramError;
use crate::robot::CellLayout;

/// Settings of the search ([`place`]). Plain data; the optimiser's own
/// options are [`place`]'s argument.
#[derive(Debug, Clone, PartialEq)]
pub struct PlaceOptions {
    /// Coarse candidates sampled in the box (and half as many more, further
    /// along the Halton sequence, after a feedback that leaves fewer than two
    /// of the best feasible on the subsample).
    pub samples: usize,
    /// Layers of the subsample (evenly spread, first and last included).
    pub layers: usize,
    /// Points per layer of the subsample.
    pub points_per_layer: usize,
    /// Candidates refined by the compass search, and certified, per round.
    pub refined: usize,
    /// Evaluations of each compass search.
    pub refine_evaluations: usize,
    /// Rounds of refinement and certification (the failing layers of one
    /// round join the subsample of the next).
    pub rounds: usize,
    /// Failing layers added to the subsample after a failed certification
    /// (besides at most three that bind the certified layers' joint-stop,
    /// speed and reach margins).
    pub feedback_layers: usize,
}

impl Default for PlaceOptions {
    fn default() -> Self {
        Self {
            samples: 64,
            layers: 8,
            points_per_layer: 24,
            refined: 2,
            refine_evaluations: 24,
            rounds: 6,
            feedback_layers: 4,
        }
    }
}

impl PlaceOptions {
    /// Checks the settings.
    ///
    /// # Errors
    /// [`OptimiseError::InvalidPlacement`] naming the settings.
    pub fn validate(&self) -> Result<(), OptimiseError> {
        if self.samples == 0 || self.layers < 2 || self.points_per_layer < 3 || self.rounds == 0 {
            return Err(OptimiseError::InvalidPlacement {
                field: "options".into(),
                reason: "samples >= 1, layers >= 2, points_per_layer >= 3 and rounds >= 1".into(),
            });
        }
        Ok(())
    }
}

/// A caller's check of a plan feasible on every layer it has (e.g. the
/// program stage's), given the layers the plan is of (the subsample's while
/// screening, every layer at certification). A refusal naming layers
/// ([`ProgramError::layers`]) brings them into the subsample at full
/// resolution.
pub type Accept<'a> =
    &'a (dyn Fn(&CellLayout, &[LayerPoints], &Plan) -> Result<(), ProgramError> + Sync);

/// Searches the placement of `layers` in `cell` within `bounds` [module
/// doc], each candidate planned with `optimise` (run serially per layer;
/// the search runs candidates in parallel).
///
/// # Errors
/// Bad input only: [`OptimiseError::InvalidPlacement`] naming the bound or
/// option, and the optimiser's errors for bad layers. A part that no
/// placement makes feasible is a [`Placement`] with `feasible == false` and
/// the binding constraint named.
pub fn place(
    cell: &CellLayout,
    layers: &[LayerPoints],
    bounds: &PlacementBounds,
    opts: &PlaceOptions,
    optimise: &OptimiseOptions,
) -> Result<Placement, OptimiseError> {
    place_with(cell, layers, bounds, opts, optimise, &|_, _, _| Ok(()))
}

/// [`place`] with the caller's check of each plan feasible on every layer:
/// a candidate it refuses is passed over for the next (its refusal becomes
/// the binding constraint when every candidate is refused).
///
/// # Errors
/// As [`place`].
pub fn place_with(
    cell: &CellLayout,
    layers: &[LayerPoints],
    bounds: &PlacementBounds,
    opts: &PlaceOptions,
    optimise: &OptimiseOptions,
    accept: Accept<'_>,
) -> Result<Placement, OptimiseError> {
    let t0 = Instant::now();
    bounds.validate()?;
    opts.validate()?;
    optimise.validate()?;
    cell.validate()?;
    let mut s = Search::new(cell, layers, bounds, opts, optimise, accept);
    s.screen();
    for round in 0..opts.rounds {
        s.rounds += 1;
        s.refine(round);
        match s.certify_round()? {
            RoundEnd::Chosen | RoundEnd::NothingToCertify => break,
            RoundEnd::Failed { failures, weakest } => {
                if failures.is_empty() && weakest.is_empty() {
                    continue;
                }
                if s.feedback(failures, weakest) == Next::Stop {
                    break;
                }
            }
        }
    }
    s.certify_current()?;
    s.finish(t0)
}

/// The search's state across its phases.
pub(crate) struct Search<'a> {
    cell: &'a CellLayout,
    layers: &'a [LayerPoints],
    bounds: &'a PlacementBounds,
    opts: &'a PlaceOptions,
    /// The optimiser's options, serial per layer.
    serial: OptimiseOptions,
    accept: Accept<'a>,
    /// Indices of the free variables.
    free: Vec<usize>,
    /// The cell as given, clamped into the bounds.
    current: Coords,
    /// Layers of the first subsample, by index in the path.
    picks: BTreeSet<usize>,
    /// Layers that joined the subsample at full resolution.
    full: BTreeSet<usize>,
    /// The subsample candidates are judged on.
    sub: Vec<LayerPoints>,
    /// Layers certified in parallel at a time.
    chunk: usize,
    /// Layers certification meets first (those that failed before).
    hot: Vec<usize>,
    /// Candidates certified (passed over afterwards).
    refused: Vec<Coords>,
    /// Candidates judged on the current subsample, best first.
    pool: Vec<Judged>,
    /// The screening's candidates, as judged on the first subsample.
    screened: Vec<Judged>,
    /// The caller's first refusal on a subsample.
    screen_refusal: Mutex<Option<Arc<ProgramError>>>,
    /// The caller's first refusal at certification.
    refusal: Option<Arc<ProgramError>>,
    /// Next index of the Halton sequence.
    halton_next: usize,
    candidates: usize,
    certified: usize,
    rounds: usize,
    feasible_fraction: f64,
    /// The placement found: candidate, cell, full plan.
    chosen: Option<(Coords, CellLayout, Plan)>,
    /// The first candidate that failed certification: candidate, cell,
    /// partial plan, share of the checked layers infeasible.
    failed: Option<(Coords, CellLayout, Plan, f64)>,
    /// The constraint every re-judged candidate shared, when the rounds
    /// stopped on it.
    stopped: Option<Limit>,
    times: PlaceTimes,
}

impl<'a> Search<'a> {
    fn new(
        cell: &'a CellLayout,
        layers: &'a [LayerPoints],
        bounds: &'a PlacementBounds,
        opts: &'a PlaceOptions,
        optimise: &OptimiseOptions,
        accept: Accept<'a>,
    ) -> Self {
        let picks = coarse_picks(layers.len(), opts.layers);
        let full = BTreeSet::new();
        let sub = subsample(layers, &picks, &full, opts.points_per_layer);
        Self {
            cell,
            layers,
            bounds,
            opts,
            serial: OptimiseOptions {
                parallel: false,
                ..*optimise
            },
            accept,
            free: (0..VARIABLES)
                .filter(|k| bounds.variables[*k].is_free())
                .collect(),
            current: bounds.current(),
            picks,
            full,
            sub,
            chunk: (4 * rayon::current_num_threads()).max(8),
            hot: Vec::new(),
            refused: Vec::new(),
            pool: Vec::new(),
            screened: Vec::new(),
            screen_refusal: Mutex::new(None),
            refusal: None,
            halton_next: 0,
            candidates: 0,
            certified: 0,
            rounds: 0,
            feasible_fraction: 0.0,
            chosen: None,
            failed: None,
            stopped: None,
            times: PlaceTimes::default(),
        }
    }

    /// The outcome: the placement chosen; or the first candidate that
    /// failed certification with its binding constraint on the full path;
    /// or the best candidate on the subsample with the constraint that
    /// bound most of the screening (or the caller's refusal).
    fn finish(mut self, t0: Instant) -> Result<Placement, OptimiseError> {
        let before_cell = placed_cell(self.cell, &self.current);
        let margins_before = match optimise(&before_cell, &self.sub, &self.serial) {
            Ok(p) => margins(&p, &before_cell),
            Err(_) => Margins::default(),
        };
        let (x, placed, plan, feasible, binding) = match (self.chosen.take(), self.failed.take()) {
            (Some((x, c, plan)), _) => (x, c, plan, true, None),
            (None, Some((x, c, plan, share))) => {
                let b = score::binding_of(&plan).map(|limit| Binding::FullPath {
                    limit,
                    share,
                    refused: self.refusal.clone(),
                });
                (x, c, plan, false, b)
            }
            (None, None) => {
                let best = self
                    .pool
                    .iter()
                    .find(|j| !self.refused.contains(&j.x))
                    .or(self.pool.first())
                    .map_or(self.current, |j| j.x);
                let c = placed_cell(self.cell, &best);
                let plan = optimise(&c, &self.sub, &self.serial)?;
                (best, c, plan, false, self.subsample_binding())
            }
        };
        Ok(Placement {
            feasible,
            margins: margins(&plan, &placed),
            margins_before,
            values: PlacementValues::from_coords(self.cell, &x),
            cell: placed,
            candidates: self.candidates,
            feasible_fraction: self.feasible_fraction,
            certified: self.certified,
            rounds: self.rounds,
            stopped_on: self.stopped,
            subsample_layers: (self.sub.len(), self.full.len()),
            binding,
            plan,
            times: self.times,
            time_s: t0.elapsed().as_secs_f64(),
        })
    }

    /// Why no candidate reached a feasible full plan when none failed one:
    /// the caller's refusal at certification, or the constraint that bound
    /// most of the screening (with the first refusal on the subsample when
    /// that was the caller's check).
    fn subsample_binding(&self) -> Option<Binding> {
        if let Some(r) = &self.refusal {
            return Some(Binding::ProgramCheck { refusal: r.clone() });
        }
        most_frequent_binding(&self.screened).map(|(limit, share)| {
            let example = match limit {
                Limit::ProgramCheck => self.screen_refusal.lock().ok().and_then(|f| f.clone()),
                _ => None,
            };
            Binding::Subsample {
                limit,
                share,
                example,
            }
        })
    }
}
