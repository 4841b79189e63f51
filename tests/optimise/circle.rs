//! The Ø600 circle of the torch-carried cell [thesis §4.2.1; SPEC §7].

use crate::support::cell;
use std::f64::consts::TAU;
use waam_slicer::math::{Point3, UnitVector3, Vector3};
use waam_slicer::optimise::{optimise, Abscissa, LayerPoints, OptimiseOptions, Parameterisation};
use waam_slicer::robot::trajectory::{joint_trajectory, PathPointInput, TrajectoryOptions};
use waam_slicer::robot::CellPoint;

const POINTS: usize = 385;

fn circle() -> Vec<CellPoint> {
    (0..POINTS)
        .map(|k| {
            let v = TAU * k as f64 / POINTS as f64;
            CellPoint {
                position_mm: Point3::new(300.0 * v.cos(), 300.0 * v.sin(), 0.0),
                tool_axis: UnitVector3::new_normalize(Vector3::z()),
                build_direction: Some(UnitVector3::new_normalize(Vector3::z())),
                positioner: None,
                travel_speed_mm_s: 6.0,
            }
        })
        .collect()
}

#[test]
fn circle_is_feasible_within_the_hose_limit_and_beats_the_thesis_cubic() {
    let cell = cell("robowam_torch_carried.toml");
    let plan = optimise(
        &cell,
        &[LayerPoints::whole(0, circle())],
        &OptimiseOptions {
            // as in the thesis: point index, degree 4, each degree warm-started
            parameterisation: Parameterisation::Polynomial {
                max_degree: 4,
                abscissa: Abscissa::PointIndex,
                stop_relative_gain: -1.0,
            },
            ..OptimiseOptions::default()
        },
    )
    .unwrap();
    let l = &plan.layers[0];
    assert!(plan.is_feasible(), "{}: {:?}", l.status, l.violations);
    assert!(l.quality.max_hose_torsion_rad.to_degrees() <= 120.0);
    // the thesis's cubic (deg, point index m = 1..385), with our kinematics
    // thesis §4.2.1 (0.4343 is a fitted coefficient, not log10(e))
    #[allow(clippy::approx_constant)]
    let b = [5.7938e-6, -0.0033, 0.4343, -31.7134];
    let inputs: Vec<PathPointInput> = circle()
        .iter()
        .enumerate()
        .map(|(k, p)| {
            let m = (k + 1) as f64;
            let rz = b.iter().fold(0.0, |acc, c| acc * m + c);
            PathPointInput {
                layer: 0,
                point: k,
                position_mm: p.position_mm,
                tool_axis: p.tool_axis,
                build_direction: p.build_direction,
                positioner: None,
                r_z: rz.to_radians(),
                bead: 0,
                travel_speed_mm_s: 6.0,
            }
        })
        .collect();
    let tr = joint_trajectory(&cell, &inputs, &TrajectoryOptions::default()).unwrap();
    let robot = cell.robot();
    let mut phi = 0.0;
    for w in tr.points.windows(2) {
        let (a, c) = (w[0].joints.unwrap(), w[1].joints.unwrap());
        for j in 0..6 {
            let lim = robot.limits[j];
            if !lim.is_unlimited() {
                phi += (c[j] - a[j]).powi(2) / lim.range_rad();
            }
        }
    }
    println!(
        "circle: ours {:.6e} ({}, {:?}), thesis cubic {:.6e} (violations {})",
        l.objective.joint_displacement,
        l.configuration.chosen,
        l.law,
        phi,
        tr.report.violations.len()
    );
    assert!(l.objective.joint_displacement <= phi * (1.0 + 1e-9));
}
