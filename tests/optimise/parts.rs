//! Parts of revolution in the ROBOWAM part-carried cell [thesis §4.1.3,
//! §4.1.4, appendix H; SPEC §7].

use crate::support::{cell, max_motion_within_layers, part_layers, plan_part, summed_acceleration};
use waam_slicer::optimise::{
    optimise, Abscissa, ConfigurationChoice, LayerStatus, OptimiseOptions, Parameterisation, Plan,
};

fn check_revolution_plan(plan: &Plan, what: &str) {
    assert!(
        plan.is_feasible(),
        "{what}: {:?}",
        plan.infeasible_layers()
            .map(|l| (l.layer, l.status.to_string()))
            .collect::<Vec<_>>()
    );
    assert_eq!(plan.violations().count(), 0, "{what}");
    for l in &plan.layers {
        for p in &l.points {
            let q = p.joints.unwrap();
            for (j, lim) in waam_slicer::robot::RobotModel::arcmate_120ic_nominal()
                .with_j5_travel_deg(135.0)
                .limits
                .iter()
                .enumerate()
            {
                assert!(lim.contains(q[j]), "{what}: layer {}, J{}", l.layer, j + 1);
            }
        }
        // J6 turns monotonically within the layer
        let j6: Vec<f64> = l.points.iter().map(|p| p.joints.unwrap()[5]).collect();
        let d: Vec<f64> = j6.windows(2).map(|w| w[1] - w[0]).collect();
        assert!(
            d.iter().all(|x| *x > 0.0) || d.iter().all(|x| *x < 0.0),
            "{what}: J6 not monotone on layer {}",
            l.layer
        );
    }
    for j in 0..5 {
        let (m, layer) = max_motion_within_layers(plan, j);
        assert!(
            m.to_degrees() < 0.1,
            "{what}: J{} moves {:.4}° on layer {layer}",
            j + 1,
            m.to_degrees()
        );
    }
}

#[test]
fn hemisphere_is_buildable_with_j1_to_j5_still_and_j6_turning() {
    for delta in [5.0, 1.0] {
        let plan = plan_part("hemisphere.toml", delta, &OptimiseOptions::default());
        check_revolution_plan(&plan, &format!("hemisphere, Delta = {delta}"));
        let layers = plan.layers.len();
        assert!(layers >= if delta == 5.0 { 14 } else { 68 }, "{layers}");
    }
}

#[test]
fn hemisphere_degrees_one_to_four_give_the_same_joints() {
    let run = |degree| {
        let opts = OptimiseOptions {
            parameterisation: Parameterisation::Polynomial {
                max_degree: degree,
                abscissa: Abscissa::CylindricalAngle,
                stop_relative_gain: -1.0,
            },
            configuration: ConfigurationChoice::Cell,
            ..OptimiseOptions::default()
        };
        plan_part("hemisphere.toml", 5.0, &opts)
    };
    let base = run(1);
    check_revolution_plan(&base, "degree 1");
    for degree in 2..=4 {
        let plan = run(degree);
        assert!(plan.is_feasible());
        let mut worst: f64 = 0.0;
        for (a, b) in base.layers.iter().zip(&plan.layers) {
            for (p, q) in a.points.iter().zip(&b.points) {
                let (p, q) = (p.joints.unwrap(), q.joints.unwrap());
                for j in 0..6 {
                    worst = worst.max((p[j] - q[j]).abs());
                }
            }
        }
        println!(
            "degree {degree}: largest joint difference {:.2e}°",
            worst.to_degrees()
        );
        assert!(
            worst.to_degrees() < 0.01,
            "degree {degree}: joints differ by {:.5}°",
            worst.to_degrees()
        );
    }
}

#[test]
fn nozzle_and_half_catenoid_need_the_optimisation() {
    for part in ["nozzle.toml", "half-catenoid.toml"] {
        let plan = plan_part(part, 1.0, &OptimiseOptions::default());
        assert!(
            plan.is_feasible(),
            "{part}: {:?}",
            plan.infeasible_layers()
                .map(|l| (l.layer, l.status.to_string()))
                .collect::<Vec<_>>()
        );
        assert_eq!(plan.violations().count(), 0, "{part}");
        let fixed = OptimiseOptions {
            parameterisation: Parameterisation::Fixed { r_z_rad: 0.0 },
            ..OptimiseOptions::default()
        };
        let plan = plan_part(part, 1.0, &fixed);
        assert!(
            !plan.is_feasible(),
            "{part}: unoptimised R_Z = 0 should not be buildable"
        );
        let l = plan.infeasible_layers().next().unwrap();
        assert!(matches!(l.status, LayerStatus::FixedViolates { .. }));
        assert!(plan
            .violations()
            .next()
            .unwrap()
            .to_string()
            .contains("layer"));
    }
}

/// The thesis (§4.1.4, fig. 4.5) finds point by point feasible but jerky.
/// On a part of revolution we find it feasible and, to the 1-D search's
/// tolerance, as smooth as layer by layer, J6 included: every point's best
/// `R_Z` is `c − theta` by symmetry (J1–J5 still, J6 free since
/// `gamma_6 = 0`), which point by point finds as well as the polynomial
/// does. Measured on the hemisphere at Delta = 5 (14 layers, 500 points
/// each, 6 mm/s), summed |acceleration| × time: J1–J5 2.1e-7 rad/s layer by
/// layer, 3.6e-5 rad/s point by point (its search stops at 1e-7 rad of
/// `R_Z`, each constraint penalised from 1e-6 inside its bound); J1–J6
/// 3.5e-7 and 8.0e-5 — six orders of magnitude below the elbow's 80 and 141
/// rad/s (next test). So this test pins what we observe instead of the
/// thesis's claim, which holds on the free-form part.
#[test]
fn point_by_point_is_feasible_and_on_a_part_of_revolution_as_smooth() {
    let layers = part_layers("hemisphere.toml", 5.0, 1);
    let cell = cell("robowam_part_carried.toml");
    let layer = optimise(&cell, &layers, &OptimiseOptions::default()).unwrap();
    let pbp = optimise(
        &cell,
        &layers,
        &OptimiseOptions {
            parameterisation: Parameterisation::PointByPoint,
            ..OptimiseOptions::default()
        },
    )
    .unwrap();
    assert!(
        pbp.is_feasible(),
        "{:?}",
        pbp.infeasible_layers()
            .map(|l| (l.layer, l.status.to_string()))
            .collect::<Vec<_>>()
    );
    let rough = |p: &Plan| -> f64 {
        p.layers
            .iter()
            .map(|l| l.quality.summed_acceleration_rad_s)
            .sum()
    };
    let (a, b) = (rough(&layer), rough(&pbp));
    let (a6, b6) = (
        summed_acceleration(&layer, &layers, 6.0, 0..6),
        summed_acceleration(&pbp, &layers, 6.0, 0..6),
    );
    println!(
        "summed J1-J5 accelerations: layer by layer {a:.3e} rad/s, point by point {b:.3e} rad/s; \
         J1-J6: {a6:.3e}, {b6:.3e}"
    );
    assert!(
        a < 1e-5 && b < 1e-3,
        "layer by layer {a}, point by point {b}"
    );
    assert!(a6 < 1e-5 && b6 < 1e-3, "J1-J6: {a6}, {b6}");
}

/// Thesis §4.1.4 on a part that is not of revolution: the 90° elbow (Delta
/// = 2, every 6th layer: 11 layers), where `R_Z` must trade the joints
/// against each other. Point by point, with no look-ahead, is feasible but
/// rougher. Measured: summed |acceleration| × time over J1–J5 79.8 rad/s
/// layer by layer, 141 rad/s point by point (+77 %); J1–J6 121 vs 283;
/// J1–J5 direction reversals 202 vs 233. (Its per-step displacement sum,
/// eq. 4.3, is slightly lower, 0.214 vs 0.226: it is greedy on exactly that.)
#[test]
fn point_by_point_is_feasible_but_rougher_on_the_elbow() {
    let layers = part_layers("elbow.toml", 2.0, 6);
    let cell = cell("robowam_part_carried.toml");
    let layer = optimise(&cell, &layers, &OptimiseOptions::default()).unwrap();
    let pbp = optimise(
        &cell,
        &layers,
        &OptimiseOptions {
            parameterisation: Parameterisation::PointByPoint,
            ..OptimiseOptions::default()
        },
    )
    .unwrap();
    for (what, p) in [("layer by layer", &layer), ("point by point", &pbp)] {
        assert!(
            p.is_feasible(),
            "{what}: {:?}",
            p.infeasible_layers()
                .map(|l| (l.layer, l.status.to_string()))
                .collect::<Vec<_>>()
        );
    }
    let a5 = summed_acceleration(&layer, &layers, 6.0, 0..5);
    let b5 = summed_acceleration(&pbp, &layers, 6.0, 0..5);
    let a6 = summed_acceleration(&layer, &layers, 6.0, 0..6);
    let b6 = summed_acceleration(&pbp, &layers, 6.0, 0..6);
    let q: f64 = layer
        .layers
        .iter()
        .map(|l| l.quality.summed_acceleration_rad_s)
        .sum();
    println!(
        "elbow: summed |acc| J1-J5 layer by layer {a5:.4} rad/s (quality report {q:.4}), \
         point by point {b5:.4}; J1-J6 {a6:.4} vs {b6:.4}"
    );
    assert!((a5 - q).abs() <= 1e-6 * q, "{a5} vs the report's {q}");
    assert!(
        b5 > 1.3 * a5,
        "J1-J5: point by point {b5}, layer by layer {a5}"
    );
    assert!(
        b6 > 1.3 * a6,
        "J1-J6: point by point {b6}, layer by layer {a6}"
    );
}
