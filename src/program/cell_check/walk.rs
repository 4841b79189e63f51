//! The walk of [`check_cell`] along a program's motions: the motions listed
//! in program order (the beads' sampled stretches, then the approach,
//! retract, transit and home moves), cut into runs of one layer, and the
//! layers walked in parallel. Each run starts with the culling's memory
//! empty and each layer carries its closest approach from run to run, as a
//! walk in program order does (the memory forgets everything when the
//! layer changes), so the answer is the same as walking them in turn: the
//! same samples, the same exact distances, the same closest approach per
//! layer, and the refusal of the first run in program order that collides.

use std::collections::HashMap;
use std::ops::Range;

use rayon::prelude::*;

use super::{CellClearance, CellScene, Checker, Closest, LayerCellClearance, Memory, PartModel};
use super::{Place, Sample, SAMPLE_STEP_MM};
use crate::optimise::LayerPoints;
use crate::program::{ArcFlag, Program, ProgramError};
use crate::robot::trajectory::JointTrajectory;
use crate::robot::Joints;

/// Checks every motion of `program` against the whole cell (module doc).
///
/// `trajectory` holds the planned joints of every bead point (the program's
/// beads may be thinned); `layers` the layers in the same order, part frame.
///
/// # Errors
/// [`ProgramError::Collision`] at the first sample (in program order) where
/// a pair comes closer than `scene.clearance_mm`, naming its layer, point
/// or move, the two bodies and the distance (negative: the depth).
pub fn check_cell(
    program: &Program,
    trajectory: &JointTrajectory,
    layers: &[LayerPoints],
    scene: &CellScene,
) -> Result<CellClearance, ProgramError> {
    let checker = Checker::new(&program.cell, scene, layers);
    let index: HashMap<usize, usize> = layers
        .iter()
        .enumerate()
        .map(|(i, l)| (l.layer, i))
        .collect();
    let mut motions = bead_motions(&checker, trajectory);
    other_motions(&mut motions, program, scene);
    let runs = runs_of_one_layer(&motions);
    // the runs of each layer, layers in the order met
    let mut order: Vec<(usize, Vec<usize>)> = Vec::new();
    let mut slot: HashMap<usize, usize> = HashMap::new();
    for (r, range) in runs.iter().enumerate() {
        let layer = motions[range.start].place.layer;
        let k = *slot.entry(layer).or_insert_with(|| {
            order.push((layer, Vec::new()));
            order.len() - 1
        });
        order[k].1.push(r);
    }
    let walked: Vec<LayerWalk> = order
        .par_iter()
        .map(|(layer, rs)| {
            let hull = hull_of(&checker, &index, *layer);
            let mut walk = LayerWalk {
                layer: *layer,
                closest: Closest {
                    distance_mm: f64::INFINITY,
                    pair: None,
                },
                stats: CellClearance::default(),
                refusal: None,
            };
            for &r in rs {
                let mut memory = Memory::default();
                for m in &motions[runs[r].clone()] {
                    if let Err(e) = walk.run(&checker, &hull, m, &mut memory) {
                        walk.refusal = Some((r, e));
                        return walk;
                    }
                }
            }
            walk
        })
        .collect();
    let mut walked = walked;
    let first = walked
        .iter()
        .enumerate()
        .filter_map(|(i, w)| w.refusal.as_ref().map(|(r, _)| (*r, i)))
        .min();
    if let Some((_, i)) = first {
        if let Some((_, e)) = walked.swap_remove(i).refusal {
            return Err(e);
        }
    }
    let mut stats = CellClearance::default();
    for w in walked {
        stats.samples += w.stats.samples;
        stats.exact_queries += w.stats.exact_queries;
        stats.culled += w.stats.culled;
        stats.layers.push(LayerCellClearance {
            layer: w.layer,
            closest_approach_mm: w.closest.distance_mm,
            closest_pair: w.closest.pair,
        });
    }
    stats.layers.sort_by_key(|l| l.layer);
    Ok(stats)
}

/// One motion of the program, sampled by swept distance from `from` to
/// `to` (both included; the first left out with `skip_first`).
struct Motion<'p> {
    from: Sample<'p>,
    to: Sample<'p>,
    skip_first: bool,
    place: Place,
}

/// The motions cut where the layer changes (index ranges into `motions`).
fn runs_of_one_layer(motions: &[Motion]) -> Vec<Range<usize>> {
    let mut runs: Vec<Range<usize>> = Vec::new();
    for (i, m) in motions.iter().enumerate() {
        match runs.last_mut() {
            Some(r) if motions[r.start].place.layer == m.place.layer => r.end = i + 1,
            _ => runs.push(i..i + 1),
        }
    }
    runs
}

/// The part's hulls a motion of `layer` is checked against: the complete
/// bands before it and its own partial band (none for a layer not in the
/// path).
fn hull_of<'c>(checker: &'c Checker, index: &HashMap<usize, usize>, layer: usize) -> PartModel<'c> {
    PartModel::new(
        index
            .get(&layer)
            .map_or_else(Vec::new, |&i| checker.wall.hulls_of(i)),
    )
}

/// One layer's walk: its closest approach, its counts, and its refusal
/// (the run it happened in).
struct LayerWalk {
    layer: usize,
    closest: Closest,
    stats: CellClearance,
    refusal: Option<(usize, ProgramError)>,
}

impl LayerWalk {
    /// A motion sampled by swept distance; refused at the first sample
    /// closer than the clearance.
    fn run(
        &mut self,
        checker: &Checker,
        hull: &PartModel,
        m: &Motion,
        memory: &mut Memory,
    ) -> Result<(), ProgramError> {
        let (from, to) = (&m.from, &m.to);
        let n = ((checker.swept_mm(from, to) / SAMPLE_STEP_MM).ceil() as usize).clamp(1, 100_000);
        for i in usize::from(m.skip_first)..=n {
            let s = i as f64 / n as f64;
            let q: Joints = std::array::from_fn(|j| from.q[j] + s * (to.q[j] - from.q[j]));
            let qp = match (from.qp, to.qp) {
                (Some(a), Some(b)) => Some([a[0] + s * (b[0] - a[0]), a[1] + s * (b[1] - a[1])]),
                (a, b) => a.or(b),
            };
            let sample = Sample { q: &q, qp };
            if let Some(hit) = checker.check(
                &sample,
                (m.place.layer, hull),
                &mut self.closest,
                memory,
                &mut self.stats,
            ) {
                return Err(super::refusal(&m.place, hit, checker.clearance));
            }
        }
        Ok(())
    }
}

/// The beads: every planned point, sampled by swept distance between
/// consecutive points of a layer: the first point of a layer, then
/// whenever the swept distance since the last sample reaches the step (the
/// motion between the two sampled points sampled in turn), and the layer's
/// last point.
fn bead_motions<'p>(checker: &Checker, trajectory: &'p JointTrajectory) -> Vec<Motion<'p>> {
    let tp = &trajectory.points;
    let mut motions = Vec::new();
    let mut prev: Option<((usize, usize), Sample)> = None;
    let mut last_sampled: Option<Sample> = None;
    let mut swept = 0.0;
    for (i, jp) in tp.iter().enumerate() {
        let Some(q) = jp.joints.as_ref() else {
            continue;
        };
        let s = Sample {
            q,
            qp: jp.positioner,
        };
        let new_layer = prev.as_ref().is_none_or(|(l, _)| *l != (jp.layer, jp.bead));
        if new_layer {
            swept = 0.0;
            last_sampled = None;
        } else if let Some((_, p)) = &prev {
            swept += checker.swept_mm(p, &s);
        }
        let is_last = tp
            .get(i + 1)
            .is_none_or(|n| (n.layer, n.bead) != (jp.layer, jp.bead));
        if last_sampled.is_none() || swept >= SAMPLE_STEP_MM || is_last {
            motions.push(Motion {
                from: last_sampled.unwrap_or(s),
                to: s,
                skip_first: last_sampled.is_some(),
                place: Place {
                    layer: jp.layer,
                    point: Some(jp.point),
                    motion: "bead",
                },
            });
            last_sampled = Some(s);
            swept = 0.0;
        }
        prev = Some(((jp.layer, jp.bead), s));
    }
    motions
}

/// Every other motion of the program, added to `motions`: home → first
/// point, approach → first point, last point → retract, the transits, last
/// → home (the home moves and transits only with `scene.transits`).
fn other_motions<'p>(motions: &mut Vec<Motion<'p>>, program: &'p Program, scene: &CellScene) {
    let pts = &program.points;
    let home = program.home.as_ref();
    if let (Some(h), Some(first)) = (home.filter(|_| scene.transits), pts.first()) {
        motions.push(Motion {
            from: Sample {
                q: &h.joints,
                qp: h.positioner,
            },
            to: Sample {
                q: &first.joints,
                qp: first.positioner,
            },
            skip_first: false,
            place: Place {
                layer: first.layer,
                point: None,
                motion: "home move",
            },
        });
    }
    for w in pts.windows(2) {
        let (a, b) = (&w[0], &w[1]);
        let same_bead = a.arc.is_bead() && b.arc.is_bead() && a.same_bead(b);
        if same_bead {
            continue;
        }
        let motion = match (a.arc, b.arc) {
            (ArcFlag::Approach, ArcFlag::Start) => "approach",
            (ArcFlag::End, ArcFlag::Retract) => "retract",
            _ if !scene.transits => continue,
            _ => "arc-off transit",
        };
        motions.push(Motion {
            from: Sample {
                q: &a.joints,
                qp: a.positioner,
            },
            to: Sample {
                q: &b.joints,
                qp: b.positioner,
            },
            skip_first: false,
            place: Place {
                layer: b.layer,
                point: Some(b.point),
                motion,
            },
        });
    }
    if let (Some(h), Some(last)) = (home.filter(|_| scene.transits), pts.last()) {
        motions.push(Motion {
            from: Sample {
                q: &last.joints,
                qp: last.positioner,
            },
            to: Sample {
                q: &h.joints,
                qp: h.positioner,
            },
            skip_first: false,
            place: Place {
                layer: last.layer,
                point: None,
                motion: "home move",
            },
        });
    }
}
