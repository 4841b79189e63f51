//! Stage 4 — robot kinematics: IK throughput (target ≥ 2 million per second
//! on one core), FK, Jacobian, and the hemisphere joint trajectory in the
//! ROBOWAM part-carried cell.

use std::hint::black_box;

use criterion::{Criterion, Throughput};
use waam_slicer::math::{Isometry3, Point3, UnitVector3, Vector3};
use waam_slicer::robot::trajectory::{joint_trajectory, PathPointInput, TrajectoryOptions};
use waam_slicer::robot::{CellLayout, Configuration, Joints, PartCarriedCell, RobotModel};

/// 1024 reachable flange poses of the ArcMate 120iC (deterministic).
fn poses(robot: &RobotModel) -> Vec<(Isometry3, Configuration, Joints)> {
    let mut s = 0x1234_5678_u64;
    let mut next = move || {
        s ^= s << 13;
        s ^= s >> 7;
        s ^= s << 17;
        (s >> 11) as f64 / (1u64 << 53) as f64
    };
    (0..1024)
        .map(|_| {
            let q: Joints = std::array::from_fn(|j| {
                let l = robot.limits[j];
                let lo = l.lower_rad.max(-3.0);
                let hi = l.upper_rad.min(3.0);
                lo + (hi - lo) * next()
            });
            (robot.flange_pose(&q), robot.configuration_of(&q), q)
        })
        .collect()
}

/// IK in one configuration, FK, IK in all eight, Jacobian.
pub fn kinematics(c: &mut Criterion) {
    let robot = RobotModel::arcmate_120ic_nominal();
    let set = poses(&robot);
    let mut g = c.benchmark_group("robot");
    g.throughput(Throughput::Elements(set.len() as u64));
    g.bench_function("ik_one_configuration_x1024", |b| {
        b.iter(|| {
            for (pose, cfg, _) in &set {
                let _ = black_box(robot.inverse(black_box(pose), *cfg));
            }
        })
    });
    g.bench_function("ik_all_eight_x1024", |b| {
        b.iter(|| {
            for (pose, _, _) in &set {
                let _ = black_box(robot.inverse_all(black_box(pose)));
            }
        })
    });
    g.bench_function("fk_x1024", |b| {
        b.iter(|| {
            for (_, _, q) in &set {
                black_box(robot.flange_pose(black_box(q)));
            }
        })
    });
    g.bench_function("jacobian_x1024", |b| {
        b.iter(|| {
            for (_, _, q) in &set {
                black_box(robot.jacobian(black_box(q)));
            }
        })
    });
    g.finish();
}

/// The hemisphere R_s = 45, Delta = 5 (15 layers × 100 points) in the ROBOWAM
/// part-carried cell, R_Z = -v: IK, unwrap, speeds, dexterity, dq/dR_Z, report.
pub fn hemisphere_trajectory(c: &mut Criterion) {
    let cell = CellLayout::PartCarried(PartCarriedCell {
        name: "ROBOWAM part carried".into(),
        robot: RobotModel::arcmate_120ic_nominal().with_j5_travel_deg(135.0),
        deposition_point_mm: Point3::new(1045.747, -630.155, 653.167),
        configuration: Configuration::from_fanuc("F U T").unwrap(),
        flange_from_part: Isometry3::identity(),
    });
    let mut pts = Vec::new();
    for layer in 0..15 {
        let phi = layer as f64 * 5.0 / 45.0;
        for k in 0..100 {
            let v = std::f64::consts::TAU * k as f64 / 100.0;
            pts.push(PathPointInput {
                layer,
                point: k,
                position_mm: Point3::new(
                    45.0 * phi.cos() * v.cos(),
                    45.0 * phi.cos() * v.sin(),
                    45.0 * phi.sin(),
                ),
                tool_axis: UnitVector3::new_normalize(Vector3::new(
                    -phi.sin() * v.cos(),
                    -phi.sin() * v.sin(),
                    phi.cos(),
                )),
                build_direction: None,
                positioner: None,
                r_z: -v,
                bead: 0,
                travel_speed_mm_s: 6.0,
            });
        }
    }
    let opts = TrajectoryOptions::default();
    let mut g = c.benchmark_group("robot");
    g.throughput(Throughput::Elements(pts.len() as u64));
    g.bench_function("hemisphere_joint_trajectory_1500_points", |b| {
        b.iter(|| black_box(joint_trajectory(&cell, black_box(&pts), &opts).unwrap()))
    });
    g.finish();
}
