//! One bad-input test per remaining error variant: the message names the place.

use waam_slicer::math::{Point3, UnitVector3, Vector3};
use waam_slicer::robot::trajectory::{joint_trajectory, PathPointInput, TrajectoryOptions};
use waam_slicer::robot::{CellLayout, CellPoint, Positioner, RobotError};

use crate::hemisphere::{robowam_part_carried, thesis_configuration};

fn point(layer: usize, point: usize, x: f64) -> PathPointInput {
    PathPointInput {
        layer,
        point,
        position_mm: Point3::new(x, 0.0, 0.0),
        tool_axis: Vector3::z_axis(),
        build_direction: None,
        positioner: None,
        r_z: 0.0,
        bead: 0,
        travel_speed_mm_s: 6.0,
    }
}

#[test]
fn bad_path_point_names_layer_and_point() {
    let cell = robowam_part_carried(thesis_configuration());
    let pts = [point(0, 0, 0.0), point(3, 7, f64::NAN)];
    let e = joint_trajectory(&cell, &pts, &TrajectoryOptions::default()).unwrap_err();
    assert!(matches!(
        e,
        RobotError::BadPathPoint {
            layer: 3,
            point: 7,
            ..
        }
    ));
    assert!(e.to_string().contains("layer 3, point 7"), "{e}");
}

#[test]
fn invalid_options_name_the_field() {
    let cell = robowam_part_carried(thesis_configuration());
    let pts = [point(0, 0, 0.0)];
    let stopped = [PathPointInput {
        travel_speed_mm_s: 0.0,
        ..point(2, 5, 0.0)
    }];
    let e = joint_trajectory(&cell, &stopped, &TrajectoryOptions::default()).unwrap_err();
    assert!(e.to_string().contains("travel_speed_mm_s"), "{e}");
    assert!(e.to_string().contains("layer 2, point 5"), "{e}");
    let opts = TrajectoryOptions {
        dexterity_length_scale_mm: -1.0,
        ..Default::default()
    };
    let e = joint_trajectory(&cell, &pts, &opts).unwrap_err();
    assert!(e.to_string().contains("dexterity_length_scale_mm"), "{e}");
}

#[test]
fn degenerate_tool_axis_is_reported() {
    let cell = robowam_part_carried(thesis_configuration());
    // T along part Y at R_Z = 0: R_X = 90°
    let p = CellPoint {
        position_mm: Point3::origin(),
        tool_axis: Vector3::y_axis(),
        build_direction: None,
        positioner: None,
        travel_speed_mm_s: 6.0,
    };
    let e = cell.pose(&p, 0.0, 0.0).unwrap_err();
    assert!(matches!(e, RobotError::DegenerateToolAxis { .. }), "{e}");
    assert!(e.to_string().contains("R_Z"), "{e}");
    // and a trajectory through it reports the point instead of failing
    let pts = [PathPointInput {
        tool_axis: Vector3::y_axis(),
        ..point(2, 5, 0.0)
    }];
    let tr = joint_trajectory(&cell, &pts, &TrajectoryOptions::default()).unwrap();
    assert!(tr.points[0].joints.is_none());
    assert!(
        tr.report
            .to_string()
            .contains("layer 2, point 5: no joint solution"),
        "{}",
        tr.report
    );
}

#[test]
fn singular_jacobian_is_reported_by_dq_drz() {
    let cell = robowam_part_carried(thesis_configuration());
    let CellLayout::PartCarried(pc) = &cell else {
        unreachable!()
    };
    let q = [0.2, 0.1, -0.3, 0.4, 0.0, 0.5]; // J5 = 0
    let p = CellPoint {
        position_mm: Point3::origin(),
        tool_axis: Vector3::z_axis(),
        build_direction: None,
        positioner: None,
        travel_speed_mm_s: 6.0,
    };
    let pose = pc.pose(&p, 0.0).unwrap();
    let e = cell.dq_drz(&pose, &q).unwrap_err();
    assert!(matches!(e, RobotError::SingularJacobian { .. }), "{e}");
    assert!(e.to_string().contains("singular Jacobian"));
}

#[test]
fn positioner_unreachable_names_the_direction() {
    let p = Positioner::robowam_nominal();
    let up = UnitVector3::new_normalize(Vector3::new(0.0, 0.6, 0.8));
    let e = p
        .angles_for_vertical(&Vector3::z_axis(), &up, 0.0, 0.0)
        .unwrap_err();
    assert!(matches!(e, RobotError::PositionerUnreachable { .. }), "{e}");
    assert!(e.to_string().contains("(0.0000, 0.0000, 1.0000)"), "{e}");
}
