//! The whole cell checked for collisions (`program::cell_check`): a cell
//! built so that the forearm passes through the positioner's table, a
//! part-carried cell whose part is put on the forearm, a keep-out box on
//! the wrist — each refused naming both bodies; the sample plans keep
//! their clearance; a bad `[[keep_out]]` names its table.

use crate::shared::part_path;
use waam_slicer::math::{Isometry3, Point3, Translation3, Vector3};
use waam_slicer::program::cell_check::{check_cell, CellScene, KeepOut};
use waam_slicer::program::ProgramError;
use waam_slicer::robot::chain::arm_chain;
use waam_slicer::robot::trajectory::{joint_trajectory, TrajectoryOptions};
use waam_slicer::robot::CellLayout;
use waam_slicer::{plan_part, Cell, Part, PlanOptions, PlannedPart, SliceOverrides};

fn planned(cell: &str) -> PlannedPart {
    let part = Part::read(part_path("hemisphere.toml")).unwrap();
    let cell = Cell::read(part_path(&format!("cells/{cell}.toml"))).unwrap();
    let opts = PlanOptions {
        slice: SliceOverrides {
            discretisation: Some(waam_slicer::path::Discretisation::Points(60)),
            max_layers: Some(3),
            ..SliceOverrides::default()
        },
        ..PlanOptions::default()
    };
    let p = plan_part(&part, &cell, &opts).unwrap();
    assert!(p.is_feasible(), "{:?}", p.refusal());
    p
}

/// The plan's joints at every bead point, as the check reads them.
fn trajectory(p: &PlannedPart) -> waam_slicer::robot::trajectory::JointTrajectory {
    let inputs = waam_slicer::optimise::trajectory_inputs(&p.layers, &p.plan);
    joint_trajectory(&p.cell.layout, &inputs, &TrajectoryOptions::default()).unwrap()
}

fn scene(keep_out: Vec<KeepOut>) -> CellScene {
    CellScene {
        keep_out,
        clearance_mm: 10.0,
        transits: true,
    }
}

fn collision(e: ProgramError) -> (usize, String, String, f64) {
    match e {
        ProgramError::Collision {
            layer,
            body_a,
            body_b,
            distance_mm,
            ..
        } => (layer, body_a, body_b, distance_mm),
        other => panic!("not a collision: {other}"),
    }
}

#[test]
fn sample_plans_keep_their_clearance() {
    for cell in ["robowam_part_carried", "robowam_torch_carried"] {
        let p = planned(cell);
        let c = p.clearance.as_ref().expect("checked");
        assert_eq!(c.layers.len(), p.plan.layers.len());
        assert!(c.samples > 0);
        let s = serde_json::to_value(p.summary()).unwrap();
        for l in s["layer_plans"].as_array().unwrap() {
            if let Some(d) = l["closest_approach_mm"].as_f64() {
                assert!(d >= 10.0, "{cell}: {l}");
            }
        }
        assert!(s["collision"].is_null());
    }
}

#[test]
fn forearm_through_the_positioner_table_is_refused_naming_both() {
    let p = planned("robowam_torch_carried");
    let traj = trajectory(&p);
    let mut program = p.program.clone().unwrap();
    let first = traj.points.iter().find(|j| j.joints.is_some()).unwrap();
    let (q, qp) = (first.joints.unwrap(), first.positioner.unwrap());
    let CellLayout::TorchCarried(c) = &mut program.cell else {
        panic!("torch-carried cell")
    };
    // the forearm's middle at the first bead point (base frame)
    let chain = arm_chain(&c.robot, &q);
    let mid = Point3::from((chain[4].coords + chain[5].coords) * 0.5);
    let along = (chain[5] - chain[4]).normalize();
    // 150 mm beside the forearm, across it and horizontal: the table's rim
    // (250 mm) reaches under the forearm, the part (r 45 mm) stays clear
    let mut side = along.cross(&Vector3::z());
    if side.norm() < 1e-6 {
        side = Vector3::x();
    }
    let target = mid + side.normalize() * 150.0;
    let table_now = c.base_from_positioner * c.positioner.positioner_from_table(&qp);
    let shift = target - Point3::from(table_now.translation.vector);
    c.base_from_positioner = Translation3::from(shift) * c.base_from_positioner;
    let e = check_cell(&program, &traj, &p.layers, &scene(vec![])).unwrap_err();
    let m = e.to_string();
    let (layer, a, b, d) = collision(e);
    assert_eq!(layer, p.layers[0].layer, "{m}");
    let mut bodies = [a, b];
    bodies.sort();
    assert_eq!(
        bodies,
        ["forearm".to_string(), "positioner table".to_string()],
        "{m}"
    );
    assert!(d < 0.0, "{m}");
    assert!(
        m.contains("forearm") && m.contains("positioner table"),
        "{m}"
    );
}

#[test]
fn part_carried_part_on_the_arm_is_refused_naming_both() {
    let p = planned("robowam_part_carried");
    let traj = trajectory(&p);
    let mut program = p.program.clone().unwrap();
    let q = traj.points[0].joints.unwrap();
    let CellLayout::PartCarried(c) = &mut program.cell else {
        panic!("part-carried cell")
    };
    // mount the part so that its origin sits on the forearm's axis at the
    // first bead point: flange · flange_from_part = that point
    let chain = arm_chain(&c.robot, &q);
    let mid = Point3::from((chain[4].coords + chain[5].coords) * 0.5);
    let flange = c.robot.flange_pose(&q);
    let base_from_part = Isometry3::from_parts(
        Translation3::from(mid.coords),
        (flange * c.flange_from_part).rotation,
    );
    c.flange_from_part = flange.inverse() * base_from_part;
    let e = check_cell(&program, &traj, &p.layers, &scene(vec![])).unwrap_err();
    let m = e.to_string();
    let (_, a, b, d) = collision(e);
    let mut bodies = [a, b];
    bodies.sort();
    assert_eq!(bodies, ["forearm".to_string(), "part".to_string()], "{m}");
    assert!(d < 0.0, "{m}");
}

#[test]
fn keep_out_box_on_the_wrist_is_refused_by_its_name() {
    let p = planned("robowam_part_carried");
    let traj = trajectory(&p);
    let program = p.program.clone().unwrap();
    // a box around the wrist centre at the plan's last bead point: the
    // program reaches it at the end of the last bead, not before
    let last = traj
        .points
        .iter()
        .rev()
        .find(|j| j.joints.is_some())
        .unwrap();
    let w = arm_chain(program.cell.robot(), &last.joints.unwrap())[5];
    let keep = KeepOut {
        name: "fixture clamp".into(),
        min_mm: [w.x - 5.0, w.y - 5.0, w.z - 5.0],
        max_mm: [w.x + 5.0, w.y + 5.0, w.z + 5.0],
    };
    let e = check_cell(&program, &traj, &p.layers, &scene(vec![keep])).unwrap_err();
    let m = e.to_string();
    let (_, a, b, _) = collision(e);
    assert!([&a, &b].contains(&&"fixture clamp".to_string()), "{m}");
    // far away, the same box is accepted and the approach is measured
    let far = KeepOut {
        name: "fence".into(),
        min_mm: [-5000.0, -5000.0, -500.0],
        max_mm: [-4000.0, 5000.0, 2000.0],
    };
    let ok = check_cell(&program, &traj, &p.layers, &scene(vec![far])).unwrap();
    assert!(ok.layers.iter().all(|l| l.closest_approach_mm >= 10.0));
}

#[test]
fn bad_keep_out_names_its_table() {
    let text = std::fs::read_to_string(part_path("cells/robowam_part_carried.toml")).unwrap();
    let bad = format!(
        "{text}\n[[keep_out]]\nname = \"fence\"\nmin_mm = [0.0, 0.0, 0.0]\nmax_mm = [100.0, -5.0, 100.0]\n"
    );
    let e = Cell::from_toml_str(&bad, "bad.toml")
        .unwrap_err()
        .to_string();
    assert!(e.contains("keep_out[0]") && e.contains("fence"), "{e}");
    let good = format!(
        "{text}\n[[keep_out]]\nname = \"fence\"\nmin_mm = [-5000.0, -5000.0, -500.0]\nmax_mm = [-4000.0, 5000.0, 2000.0]\n"
    );
    let cell = Cell::from_toml_str(&good, "good.toml").unwrap();
    assert_eq!(cell.keep_out.len(), 1);
}
