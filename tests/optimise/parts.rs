//! Parts of revolution in the ROBOWAM part-carried cell [thesis §4.1.3,
//! §4.1.4, appendix H; SPEC §7].

use crate::support::{max_motion_within_layers, plan_part};
use waam_slicer::optimise::{
    Abscissa, ConfigurationChoice, LayerStatus, OptimiseOptions, Parameterisation, Plan,
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
/// With an exact per-point solver it is feasible, and on a part of
/// revolution as smooth as layer by layer: every point's best `R_Z` is
/// `c − theta` by symmetry, so J1–J5 stay still either way (both sums below
/// are rounding-level). The thesis's jerks come from its solver, not from the
/// method; this test pins what we observe instead of the thesis's claim.
#[test]
fn point_by_point_is_feasible_and_on_a_part_of_revolution_as_smooth() {
    let layer = plan_part("hemisphere.toml", 5.0, &OptimiseOptions::default());
    let pbp = plan_part(
        "hemisphere.toml",
        5.0,
        &OptimiseOptions {
            parameterisation: Parameterisation::PointByPoint,
            ..OptimiseOptions::default()
        },
    );
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
    println!(
        "summed J1-J5 accelerations: layer by layer {a:.3e} rad/s, point by point {b:.3e} rad/s"
    );
    assert!(
        a < 1e-5 && b < 1e-5,
        "layer by layer {a}, point by point {b}"
    );
}
