//! Differential test: the plan does not depend on the thread count (STYLE
//! 18: layers in parallel, each layer single-threaded, order preserved).

use waam_slicer::optimise::{optimise, LayerPoints, OptimiseOptions, Plan};

use crate::support::{cell, part_layers};

/// `layers` optimised in a rayon pool of `threads` threads.
fn plan_with_threads(layers: &[LayerPoints], threads: usize) -> Plan {
    let cell = cell("robowam_part_carried.toml");
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap();
    pool.install(|| optimise(&cell, layers, &OptimiseOptions::default()).unwrap())
}

/// Asserts `a` and `b` are the same plan: `R_Z`, joints, positioner and
/// dexterity bit for bit, everything else equal but the run times.
fn assert_same_plan(a: &Plan, b: &Plan, what: &str) {
    assert_eq!(a.layers.len(), b.layers.len(), "{what}: layer count");
    let bits = |x: f64| x.to_bits();
    for (la, lb) in a.layers.iter().zip(&b.layers) {
        assert_eq!(
            la.points.len(),
            lb.points.len(),
            "{what}: layer {}",
            la.layer
        );
        for (m, (pa, pb)) in la.points.iter().zip(&lb.points).enumerate() {
            let at = format!("{what}: layer {}, point {m}", la.layer);
            assert_eq!(bits(pa.r_z), bits(pb.r_z), "{at}: R_Z");
            assert_eq!(
                pa.joints.map(|q| q.map(bits)),
                pb.joints.map(|q| q.map(bits)),
                "{at}: joints"
            );
            assert_eq!(
                pa.positioner.map(|q| q.map(bits)),
                pb.positioner.map(|q| q.map(bits)),
                "{at}: positioner"
            );
            assert_eq!(bits(pa.dexterity), bits(pb.dexterity), "{at}: dexterity");
        }
        let untimed = |l: &waam_slicer::optimise::LayerPlan| {
            let mut l = l.clone();
            l.solver.time_s = 0.0;
            l
        };
        assert_eq!(untimed(la), untimed(lb), "{what}: layer {}", la.layer);
    }
    assert_eq!(a.transitions, b.transitions, "{what}: transitions");
}

#[test]
fn one_thread_and_two_threads_give_the_same_plan() {
    // the hemisphere (every layer) and the elbow (branch choice on a bent
    // guide; every 15th layer to keep the run short)
    for (part, delta, every) in [("hemisphere.toml", 5.0, 1), ("elbow.toml", 2.0, 15)] {
        let layers = part_layers(part, delta, every);
        assert!(
            layers.len() >= 2,
            "{part}: need several layers to run in parallel"
        );
        let one = plan_with_threads(&layers, 1);
        let two = plan_with_threads(&layers, 2);
        assert_same_plan(&one, &two, part);
        // and the serial driver (no rayon at all) agrees too
        let serial = optimise(
            &cell("robowam_part_carried.toml"),
            &layers,
            &OptimiseOptions {
                parallel: false,
                ..OptimiseOptions::default()
            },
        )
        .unwrap();
        assert_same_plan(&one, &serial, part);
    }
}
