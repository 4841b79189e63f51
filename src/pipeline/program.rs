//! **Stage 7 from a plan — the program of planned layers.** Takes the
//! layers a plan was made for (part frame, mm, each point at its own travel
//! speed), their [`Plan`] (joints, rad), each point's wire feed (mm/s), the
//! cell and its `[program]` options, and returns the program model
//! ([`build_program_with`]) with its payloads set and the whole cell checked
//! along every motion ([`check_cell`]). `plan` and `replan` both build their
//! programs here; they differ only in the feed they pass and the payload the
//! build starts with. SPEC §8.

use std::collections::HashMap;
use std::time::Instant;

use super::Cell;
use crate::optimise::{trajectory_inputs, LayerPoints, Plan};
use crate::program::cell_check::{check_cell, CellClearance, CellScene};
use crate::program::{
    build_program_with, LayerRefusal, PointFeed, Program, ProgramError, ProgramOptions,
};
use crate::robot::trajectory::{
    joint_trajectory_without_measures, JointTrajectory, PathPointInput, ReusedBead, SolvedBead,
    TrajectoryOptions,
};
use crate::robot::{CellLayout, RobotError};

/// What a plan's program is built from.
#[derive(Debug, Clone, Copy)]
pub(crate) struct ProgramBuild<'a> {
    /// Program name (controller-safe).
    pub name: &'a str,
    /// The cell (robot base frame).
    pub cell: &'a Cell,
    /// The layers planned, in order (part frame, mm): a layer split at its
    /// corners is one entry a bead.
    pub layers: &'a [LayerPoints],
    /// Their plan, one layer plan per entry of `layers`.
    pub plan: &'a Plan,
    /// Wire feed of every point of `layers` in order (mm/s); each point's
    /// travel speed is its own ([`crate::robot::CellPoint::travel_speed_mm_s`]).
    pub wire_feed_mm_s: &'a [f64],
    /// The cell's `[program]` options, the payload the build starts with
    /// among them (kg, mm).
    pub common: &'a ProgramOptions,
    /// Mass deposited in each layer of the path (kg), indexed by layer:
    /// the payload updates' (a split layer's beads share it by their
    /// lengths).
    pub layer_masses_kg: &'a [f64],
    /// `layers` are the whole build; `false` for a subsample (a
    /// placement's screening), whose transits between beads the cell check
    /// leaves out ([`CellScene::transits`]).
    pub every_layer: bool,
}

impl ProgramBuild<'_> {
    /// The program model, refused when a layer is infeasible or lost or a
    /// motion collides in the cell; with the closest approach per layer and
    /// the collision check's run time (s).
    ///
    /// # Errors
    /// [`ProgramError::InfeasibleLayer`] naming the first layer without a
    /// plan, a joint solution or its point count; the builder's and the
    /// cell check's errors.
    pub fn build(&self) -> Result<(Program, CellClearance, f64), ProgramError> {
        let (cell, layers, common) = (self.cell, self.layers, self.common);
        check_every_layer(layers, self.plan)?;
        let inputs = trajectory_inputs(layers, self.plan);
        // the optimiser's re-check of each layer, by where its points start
        let mut solved = HashMap::new();
        let mut start = 0;
        for (lp, pl) in layers.iter().zip(&self.plan.layers) {
            if let Some(s) = &pl.solved {
                solved.insert(start, s.as_ref());
            }
            start += lp.points.len();
        }
        // the program reads the joints, speeds and violations only: no
        // dexterity (an SVD a point) nor dq/dR_Z
        let traj = trajectory_by_bead(&cell.layout, &inputs, &solved)
            .map_err(|source| ProgramError::Trajectory { source })?;
        if self.wire_feed_mm_s.len() != inputs.len() {
            return Err(ProgramError::InvalidOptions {
                field: "wire_feed_mm_s",
                value: format!("{} values", self.wire_feed_mm_s.len()),
                reason: "one wire feed per planned point",
            });
        }
        let feed: Vec<PointFeed> = inputs
            .iter()
            .zip(self.wire_feed_mm_s)
            .map(|(p, &w)| PointFeed {
                travel_speed_mm_s: p.travel_speed_mm_s,
                wire_feed_mm_s: w,
            })
            .collect();
        let mut program =
            build_program_with(self.name, &cell.layout, &inputs, &traj, &feed, common)?;
        if common.payload_every_layers > 0 {
            program.set_payloads(common, &self.bead_masses_kg())?;
        }
        let t = Instant::now();
        let scene = CellScene {
            keep_out: cell.keep_out.clone(),
            clearance_mm: common.collision_clearance_mm,
            transits: self.every_layer,
        };
        let clearance = check_cell(&program, &traj, layers, &scene)?;
        Ok((program, clearance, t.elapsed().as_secs_f64()))
    }

    /// The mass of each bead (kg): its layer's, shared among a split
    /// layer's beads by their lengths.
    fn bead_masses_kg(&self) -> Vec<f64> {
        let length = |l: &LayerPoints| -> f64 {
            l.points
                .windows(2)
                .map(|w| (w[1].position_mm - w[0].position_mm).norm())
                .sum()
        };
        let mut layer_length = HashMap::new();
        for l in self.layers {
            *layer_length.entry(l.layer).or_insert(0.0) += length(l);
        }
        self.layers
            .iter()
            .map(|l| {
                let mass = self.layer_masses_kg.get(l.layer).copied().unwrap_or(0.0);
                let whole = layer_length.get(&l.layer).copied().unwrap_or(0.0);
                // (a whole layer's length over itself: exactly 1)
                if whole > 0.0 {
                    mass * length(l) / whole
                } else {
                    0.0
                }
            })
            .collect()
    }
}

/// The program's joint trajectory of `inputs` (default options: no
/// measures), its beads solved in parallel: the same joints, speeds and
/// violations as one walk along `inputs`. Each bead starts afresh in that
/// walk (the options rewind between layers: no joints to stay near, no
/// speed from the previous bead), and the positioner's turn hint it
/// carries from bead to bead is read only for a point without planned
/// positioner joints: where one has none in a torch-carried cell, the
/// walk is one. A bead starting at input `i` whose points `solved[&i]`
/// solved already ([`SolvedBead::reuse`]: the same points in the same
/// cell) takes its joints from there instead of solving them again.
///
/// # Errors
/// As [`joint_trajectory_without_measures`]: the first bad input point in
/// order.
fn trajectory_by_bead(
    cell: &CellLayout,
    inputs: &[PathPointInput],
    solved: &HashMap<usize, &SolvedBead>,
) -> Result<JointTrajectory, RobotError> {
    use rayon::prelude::*;
    let opts = TrajectoryOptions::default();
    let independent = opts.rewind_between_layers
        && (matches!(cell, CellLayout::PartCarried(_))
            || inputs.iter().all(|p| p.positioner.is_some()));
    if !independent {
        return joint_trajectory_without_measures(cell, inputs, &opts);
    }
    let mut beads: Vec<std::ops::Range<usize>> = Vec::new();
    for (i, p) in inputs.iter().enumerate() {
        match beads.last_mut() {
            Some(r) if inputs[r.start].same_bead(p) => r.end = i + 1,
            _ => beads.push(i..i + 1),
        }
    }
    // each bead taken from its solved points, or solved
    let parts: Vec<Result<Result<ReusedBead, JointTrajectory>, RobotError>> = beads
        .par_iter()
        .map(|r| {
            let bead = &inputs[r.clone()];
            match solved
                .get(&r.start)
                .and_then(|s| s.reuse(cell, bead, &opts))
            {
                Some(t) => Ok(Ok(t)),
                None => joint_trajectory_without_measures(cell, bead, &opts).map(Err),
            }
        })
        .collect();
    let mut whole = JointTrajectory {
        configuration: cell.configuration(),
        points: Vec::with_capacity(inputs.len()),
        report: Default::default(),
    };
    for (part, r) in parts.into_iter().zip(&beads) {
        match part? {
            Ok(taken) => taken.append_to(&inputs[r.clone()], &mut whole),
            Err(part) => {
                whole.points.extend(part.points);
                whole.report.violations.extend(part.report.violations);
            }
        }
    }
    Ok(whole)
}

/// No layer may vanish between the plan and the program: each layer of the
/// path has its plan, with a joint solution at each of its points, and is
/// feasible.
pub(super) fn check_every_layer(layers: &[LayerPoints], plan: &Plan) -> Result<(), ProgramError> {
    let infeasible: Vec<_> = plan.infeasible_layers().collect();
    if let Some(first) = infeasible.first() {
        return Err(ProgramError::InfeasibleLayer {
            layer: first.layer,
            count: infeasible.len(),
            status: LayerRefusal::Infeasible(first.status.clone()),
        });
    }
    for (i, lp) in layers.iter().enumerate() {
        let Some(pl) = plan.layers.get(i) else {
            return Err(ProgramError::InfeasibleLayer {
                layer: lp.layer,
                count: layers.len() - i,
                status: LayerRefusal::NoPlan,
            });
        };
        if pl.layer != lp.layer || pl.points.len() != lp.points.len() {
            return Err(ProgramError::InfeasibleLayer {
                layer: lp.layer,
                count: 1,
                status: LayerRefusal::PointCount {
                    planned: pl.points.len(),
                    path: lp.points.len(),
                    plan_layer: pl.layer,
                },
            });
        }
        if let Some(m) = pl.points.iter().position(|p| p.joints.is_none()) {
            return Err(ProgramError::InfeasibleLayer {
                layer: lp.layer,
                count: 1,
                status: LayerRefusal::NoJointSolution { point: m },
            });
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::optimise::layer_points;
    use crate::robot::ik::Wrist;

    /// The beads solved in parallel give the trajectory of one walk, to the
    /// bit: the hemisphere's layers (R_Z 0 and 0.3 rad on alternate layers)
    /// in the ROBOWAM part-carried cell, and in its torch-carried cell both
    /// without positioner joints (one walk: the turn hint carries over) and
    /// with the ones that walk solved (beads in parallel).
    #[test]
    fn trajectory_by_bead_is_one_walk() {
        let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("parts");
        let part = crate::Part::read(root.join("hemisphere.toml")).unwrap();
        let sliced = crate::pipeline::slice_part(&part).unwrap();
        let layers = layer_points(
            &sliced.path,
            &sliced.axes.frames,
            sliced.process.travel_speed_mm_s,
        );
        let inputs: Vec<PathPointInput> = layers
            .iter()
            .flat_map(|l| {
                l.points
                    .iter()
                    .enumerate()
                    .map(move |(m, p)| PathPointInput {
                        layer: l.layer,
                        bead: l.bead,
                        point: l.first_point + m,
                        position_mm: p.position_mm,
                        tool_axis: p.tool_axis,
                        build_direction: p.build_direction,
                        r_z: if l.layer % 2 == 0 { 0.0 } else { 0.3 },
                        positioner: p.positioner,
                        travel_speed_mm_s: p.travel_speed_mm_s,
                    })
            })
            .collect();
        assert!(layers.len() > 2);
        let opts = TrajectoryOptions::default();
        for cell in ["robowam_part_carried", "robowam_torch_carried"] {
            let cell = crate::Cell::read(root.join(format!("cells/{cell}.toml"))).unwrap();
            let one = joint_trajectory_without_measures(&cell.layout, &inputs, &opts).unwrap();
            assert_eq!(
                trajectory_by_bead(&cell.layout, &inputs, &HashMap::new()).unwrap(),
                one
            );
            if matches!(cell.layout, CellLayout::TorchCarried(_)) {
                let planned: Vec<PathPointInput> = inputs
                    .iter()
                    .zip(&one.points)
                    .map(|(p, jp)| PathPointInput {
                        positioner: jp.positioner.or(Some([0.0, 0.0])),
                        ..*p
                    })
                    .collect();
                let one = joint_trajectory_without_measures(&cell.layout, &planned, &opts).unwrap();
                assert_eq!(
                    trajectory_by_bead(&cell.layout, &planned, &HashMap::new()).unwrap(),
                    one
                );
            }
        }
    }

    /// The optimiser's re-check of each layer is the program's trajectory
    /// of its bead, to the bit: the hemisphere planned in the ROBOWAM
    /// part-carried and torch-carried cells (at a coarser grid), its
    /// trajectory with the solved beads taken is the one solved afresh,
    /// and in the part-carried cell every bead is taken; a bead one of
    /// whose points moved (`R_Z` by one ulp) or in another cell (the other
    /// branch) is solved again.
    #[test]
    fn solved_beads_are_the_program_trajectory() {
        let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("parts");
        let mut part = crate::Part::read(root.join("hemisphere.toml")).unwrap();
        part.slicing.delta_mm *= 2.0;
        let sliced = crate::pipeline::slice_part(&part).unwrap();
        let layers = layer_points(
            &sliced.path,
            &sliced.axes.frames,
            sliced.process.travel_speed_mm_s,
        );
        let opts = crate::PlanOptions::default().optimise;
        for name in ["robowam_part_carried", "robowam_torch_carried"] {
            let cell = crate::Cell::read(root.join(format!("cells/{name}.toml"))).unwrap();
            let plan = crate::optimise::optimise(&cell.layout, &layers, &opts).unwrap();
            let inputs = trajectory_inputs(&layers, &plan);
            let mut solved = HashMap::new();
            let mut start = 0;
            for (lp, pl) in layers.iter().zip(&plan.layers) {
                if let Some(s) = &pl.solved {
                    solved.insert(start, s.as_ref());
                }
                start += lp.points.len();
            }
            let fresh = trajectory_by_bead(&cell.layout, &inputs, &HashMap::new()).unwrap();
            assert_eq!(
                trajectory_by_bead(&cell.layout, &inputs, &solved).unwrap(),
                fresh,
                "{name}"
            );
            let opts = TrajectoryOptions::default();
            let (mut start, mut taken) = (0, 0);
            for lp in &layers {
                let bead = &inputs[start..start + lp.points.len()];
                if let Some(s) = solved.get(&start) {
                    let t = s.reuse(&cell.layout, bead, &opts);
                    taken += usize::from(t.is_some());
                    if let Some(t) = t {
                        let mut whole = JointTrajectory {
                            configuration: cell.layout.configuration(),
                            points: Vec::new(),
                            report: Default::default(),
                        };
                        t.append_to(bead, &mut whole);
                        let one = joint_trajectory_without_measures(&cell.layout, bead, &opts);
                        assert_eq!(whole, one.unwrap(), "{name}, layer {}", lp.layer);
                    }
                    let mut moved = bead.to_vec();
                    moved[bead.len() / 2].r_z =
                        f64::from_bits(moved[bead.len() / 2].r_z.to_bits() + 1);
                    assert!(s.reuse(&cell.layout, &moved, &opts).is_none());
                    let mut other = cell.layout.clone();
                    let flip = |w| match w {
                        Wrist::NoFlip => Wrist::Flip,
                        Wrist::Flip => Wrist::NoFlip,
                    };
                    match &mut other {
                        CellLayout::PartCarried(c) => {
                            c.configuration.wrist = flip(c.configuration.wrist)
                        }
                        CellLayout::TorchCarried(c) => {
                            c.configuration.wrist = flip(c.configuration.wrist)
                        }
                    }
                    assert!(s.reuse(&other, bead, &opts).is_none());
                }
                start += lp.points.len();
            }
            if name == "robowam_part_carried" {
                assert_eq!(taken, layers.len(), "{name}");
            }
            assert!(taken > 0, "{name}");
        }
    }
}
