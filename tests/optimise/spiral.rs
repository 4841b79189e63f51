//! A spiral path optimised turn by turn, each turn continuing the one before
//! (SPEC §7; issue 7).

use crate::common::load_part;
use crate::support::cell;
use waam_slicer::optimise::{
    layer_points, optimise, optimise_spiral, LayerStatus, OptimiseOptions,
};
use waam_slicer::path::{slice, Strategy};
use waam_slicer::toolaxis::local_frames;

/// Hemisphere spiral at Delta = 5 (one layer of ~6,800 points, 500 a
/// turn): turn by turn it is feasible in the ROBOWAM part-carried cell, one
/// IK branch throughout, and continuous where the turns meet — `R_Z` and the
/// joints (J6 unwrapped, no rewind) change there no more than between
/// neighbouring points inside a turn. Every turn converges.
#[test]
fn hemisphere_spiral_is_optimised_turn_by_turn_continuously() {
    let part = load_part("hemisphere.toml");
    let mut so = part.slice_options();
    so.delta_mm = 5.0;
    so.strategy = Strategy::Spiral;
    let path = slice(&part.tube, &part.substrate, &so).unwrap();
    let per_turn = path.spiral.unwrap().per_turn;
    let frames = local_frames(&path, &part.tube);
    let layers = layer_points(&path, &frames, 6.0);
    assert_eq!(layers.len(), 1);
    let cell = cell("robowam_part_carried.toml");
    let plan = optimise_spiral(&cell, &layers[0], per_turn, &OptimiseOptions::default()).unwrap();
    assert!(
        plan.is_feasible(),
        "{:?}",
        plan.infeasible_layers()
            .map(|l| (l.layer, l.status.to_string()))
            .collect::<Vec<_>>()
    );
    // every turn converges: the dexterity floor is continuous along the
    // spiral (a step at a junction left turn 4 starting below its floor,
    // and its SQP hit the iteration limit bending R_Z away from it)
    for l in &plan.layers {
        assert!(
            matches!(l.status, LayerStatus::Optimal),
            "turn {}: {}",
            l.layer,
            l.status
        );
    }
    assert_eq!(
        plan.layers.iter().map(|l| l.points.len()).sum::<usize>(),
        layers[0].points.len()
    );
    let turns = plan.layers.len();
    assert!(turns >= 13, "{turns}");
    let branch = plan.layers[0].configuration.chosen;
    assert!(plan.layers.iter().all(|l| l.configuration.chosen == branch));
    // steps inside the turns vs at the junctions
    let step = |a: &waam_slicer::optimise::PlannedPoint,
                b: &waam_slicer::optimise::PlannedPoint| {
        let (qa, qb) = (a.joints.unwrap(), b.joints.unwrap());
        let dq = (0..6).map(|j| (qa[j] - qb[j]).abs()).fold(0.0, f64::max);
        (dq, (a.r_z - b.r_z).abs())
    };
    let (mut inner_q, mut inner_r) = (0.0f64, 0.0f64);
    for l in &plan.layers {
        for w in l.points.windows(2) {
            let (q, r) = step(&w[0], &w[1]);
            inner_q = inner_q.max(q);
            inner_r = inner_r.max(r);
        }
    }
    let (mut joint_q, mut joint_r) = (0.0f64, 0.0f64);
    for w in plan.layers.windows(2) {
        let (q, r) = step(w[0].points.last().unwrap(), &w[1].points[0]);
        joint_q = joint_q.max(q);
        joint_r = joint_r.max(r);
    }
    println!(
        "{turns} turns of {per_turn}: largest step inside turns {:.3}° (R_Z {:.3}°), at junctions {:.3}° (R_Z {:.3}°)",
        inner_q.to_degrees(),
        inner_r.to_degrees(),
        joint_q.to_degrees(),
        joint_r.to_degrees()
    );
    assert!(joint_r <= 1.5 * inner_r, "R_Z jumps at a junction");
    assert!(joint_q <= 1.5 * inner_q, "the joints jump at a junction");
    // the whole spiral as one layer (a global polynomial) is feasible too
    let one = optimise(&cell, &layers, &OptimiseOptions::default()).unwrap();
    assert!(one.is_feasible());
}
