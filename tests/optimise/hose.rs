//! The hose torsion `|J4 + J6| ≤ 120°` of the torch-carried cells (eq. 4.8;
//! SPEC §7): a layer the optimiser holds on that bound must pass the
//! trajectory stage's re-check of the same bound; what only the re-check
//! finds (the positioner's speed) is named with its amount.

use crate::common::load_part;
use crate::support::cell;
use waam_slicer::optimise::{
    layer_points, optimise, trajectory_inputs, ConfigurationChoice, LayerPoints, LayerStatus,
    OptimiseOptions,
};
use waam_slicer::path::slice;
use waam_slicer::robot::trajectory::{joint_trajectory, TrajectoryOptions, ViolationKind};
use waam_slicer::robot::CellLayout;
use waam_slicer::toolaxis::tool_axes;

/// Layer `layer` of `part` (its own settings, `delta_mm` if given) with its
/// tool axes, and the options `plan` uses in the KUKA torch-carried cell
/// (the part's travel speed, the cell's branch).
fn kuka_torch_layer(
    part: &str,
    delta_mm: Option<f64>,
    layer: usize,
) -> (Vec<LayerPoints>, CellLayout, OptimiseOptions) {
    let part = load_part(part);
    let mut so = part.slice_options();
    if let Some(d) = delta_mm {
        so.delta_mm = d;
    }
    let path = slice(&part.tube, &part.substrate, &so).unwrap();
    let axes = tool_axes(
        &path,
        Some(&part.tube),
        Some(&part.substrate),
        &part.tool_axis,
    )
    .unwrap();
    let all = layer_points(&path, &axes.frames, part.process.travel_speed_mm_s);
    let opts = OptimiseOptions {
        configuration: ConfigurationChoice::Cell,
        ..OptimiseOptions::default()
    };
    (
        vec![all[layer].clone()],
        cell("kuka_kr16_2_torch_carried.toml"),
        opts,
    )
}

/// The nozzle at Delta = 1 mm, its own tool-axis and process settings, in
/// the KUKA KR16-2 torch-carried cell with the cell's branch (as `plan`
/// does): on its top layer the arm stands still while the positioner turns
/// the part, and the hose torsion is held on its 120° bound at every point.
/// The SQP stops once its steps are below its step tolerance, which left the
/// torsion 1e-6° over the bound: the trajectory re-check refused the layer
/// although the optimiser had found it feasible. The optimiser now aims a
/// hair inside the bound, so the plan is feasible and its trajectory has no
/// hose violation.
#[test]
fn a_layer_held_on_the_hose_bound_passes_the_trajectory_recheck() {
    let (layers, cell, opts) = kuka_torch_layer("nozzle.toml", Some(1.0), 99);
    let plan = optimise(&cell, &layers, &opts).unwrap();
    let l = &plan.layers[0];
    let max = match &cell {
        CellLayout::TorchCarried(c) => c.max_hose_torsion_rad,
        _ => unreachable!(),
    };
    // the bound is active on this layer
    assert!(
        l.quality.max_hose_torsion_rad > max - 1e-3,
        "{}",
        l.quality.max_hose_torsion_rad.to_degrees()
    );
    assert!(
        matches!(
            l.status,
            LayerStatus::Optimal | LayerStatus::NotConverged { .. }
        ),
        "{}: {:?}",
        l.status,
        l.violations.first()
    );
    assert!(l.quality.max_hose_torsion_rad <= max);
    let tr = joint_trajectory(
        &cell,
        &trajectory_inputs(&layers, &plan),
        &TrajectoryOptions::default(),
    )
    .unwrap();
    let hose: Vec<_> = tr
        .report
        .violations
        .iter()
        .filter(|v| matches!(v.kind, ViolationKind::HoseTorsion { .. }))
        .collect();
    assert!(hose.is_empty(), "{:?}", hose.first());
}

/// The positioner's turn `q8` does not depend on `R_Z`: a layer of the torus
/// on a cylinder in the KUKA torch-carried example cell asks it to turn
/// faster than its 180°/s at the part's travel speed, which no `R_Z` law
/// can fix. The optimiser does not model the positioner's speed; the
/// trajectory re-check finds it, and the layer's binding constraint says so
/// with the amount (rad over one step), not "over by 0°".
#[test]
fn a_positioner_speed_found_by_the_recheck_is_named_with_its_amount() {
    // the thesis's positioner (b exactly vertical): the table's turn spins
    // past its speed on this layer (the optimised laws build it)
    let (layers, cell, mut opts) = kuka_torch_layer("torus-on-cylinder.toml", None, 0);
    opts.positioner.mode = waam_slicer::optimise::positioner::PositionerMode::Vertical;
    let plan = optimise(&cell, &layers, &opts).unwrap();
    let LayerStatus::Infeasible { binding } = &plan.layers[0].status else {
        panic!("{}", plan.layers[0].status);
    };
    assert_eq!(
        binding.constraint,
        waam_slicer::optimise::Constraint::JointSpeed { joint: 8 },
        "{binding}"
    );
    assert!(binding.violation > 1e-3, "{binding}");
    assert!(!binding.to_string().contains("over by 0.0000"), "{binding}");
}
