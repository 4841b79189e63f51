//! The hemisphere of SPEC §7 in the ROBOWAM part-carried cell (thesis fig.
//! 3.21–3.22, 4.2–4.4), built from its closed form.

use std::f64::consts::{FRAC_PI_2, TAU};

use waam_slicer::math::Point3;
use waam_slicer::robot::trajectory::{
    joint_trajectory, PathPointInput, TrajectoryOptions, ViolationKind,
};
use waam_slicer::robot::{CellLayout, Configuration, PartCarriedCell, RobotModel};

/// Radius R_s (mm), meridian arc spacing Delta (mm), points per layer.
pub const R_S: f64 = 45.0;
pub const DELTA: f64 = 5.0;
pub const POINTS: usize = 100;

/// Layers at constant meridian arc spacing from Z = 0, stopping below the pole.
/// `r_z(layer, v)` gives R_Z at layer angle v.
pub fn hemisphere(r_z: impl Fn(usize, f64) -> f64) -> Vec<PathPointInput> {
    // Every layer whose latitude l Delta / R_s stays below pi/2.
    let layers = ((FRAC_PI_2 - 1e-9) * R_S / DELTA).floor() as usize + 1;
    crate::shared::hemisphere_cell_points(0..layers, POINTS, r_z)
}

/// ROBOWAM part-carried cell at D_R of §3.3, J5 ±135° (table A.1 note 1).
pub fn robowam_part_carried(config: Configuration) -> CellLayout {
    CellLayout::PartCarried(PartCarriedCell {
        name: "ROBOWAM part carried".into(),
        robot: RobotModel::arcmate_120ic_nominal().with_j5_travel_deg(135.0),
        deposition_point_mm: Point3::new(1045.747, -630.155, 653.167),
        configuration: config,
        flange_from_part: waam_slicer::math::Isometry3::identity(),
    })
}

/// The thesis's configuration: shoulder up, elbow up, wrist down (§3.3). With
/// FANUC's letters that is `F U T` here: the wrist branch with J4 near 0,
/// where only J5 leaves its travel as the thesis reports (`N U T` has the
/// same |J5| with J4 near 180°, over its ±200° from layer 3 on).
pub fn thesis_configuration() -> Configuration {
    Configuration::from_fanuc("F U T").unwrap()
}

#[test]
fn constant_rz_zero_makes_j5_leave_its_travel_and_the_report_says_so() {
    let cell = robowam_part_carried(thesis_configuration());
    let path = hemisphere(|_, _| 0.0);
    assert_eq!(path.len(), 15 * POINTS);
    // TS 36 cm/min = 6 mm/s [table 3.1]
    let tr = joint_trajectory(&cell, &path, &TrajectoryOptions::default()).unwrap();
    assert!(tr.points.iter().all(|p| p.joints.is_some()));
    let j5_max = tr
        .points
        .iter()
        .map(|p| p.joints.unwrap()[4].to_degrees().abs())
        .fold(0.0, f64::max);
    // an independent check reached ~167°; the nominal model here peaks at 177°
    assert!(j5_max > 160.0 && j5_max < 180.0, "max |J5| = {j5_max}°");
    let j5: Vec<_> = tr.report.limit_violations_of(5).collect();
    assert!(!j5.is_empty());
    // every point with |J5| > 135° is reported, and only those (J5 travel, J4 stays inside)
    let over = tr
        .points
        .iter()
        .filter(|p| p.joints.unwrap()[4].abs() > 135f64.to_radians())
        .count();
    assert_eq!(j5.len(), over);
    // J4 stays inside its ±200° up to layer 10; above, |J5| passes near 180°
    // (the other wrist pole) and J4 must make a full turn within the layer
    assert!(tr.report.limit_violations_of(4).all(|v| v.layer >= 11));
    assert!(tr.report.limit_violations_of(4).count() > 0);
    assert!(!tr.report.is_clean());
    let text = tr.report.to_string();
    assert!(
        text.contains("J5 = ") && text.contains("outside [-135.0°, 135.0°]"),
        "{text}"
    );
    assert!(text.contains("layer 10, point"), "{text}");
    // the other constant values of fig. 3.22 fail too
    for c in [90.0f64, 180.0, 270.0] {
        let path = hemisphere(|_, _| c.to_radians());
        let tr = joint_trajectory(&cell, &path, &TrajectoryOptions::default()).unwrap();
        assert!(tr.report.limit_violations_of(5).count() > 0, "R_Z = {c}");
    }
}

#[test]
fn rz_turning_opposite_to_the_layer_angle_keeps_j1_to_j5_still() {
    let cell = robowam_part_carried(thesis_configuration());
    for c in [0.0f64, 1.0, 3.0] {
        let path = hemisphere(|_, v| c - v);
        let tr = joint_trajectory(&cell, &path, &TrajectoryOptions::default()).unwrap();
        for layer in 0..15 {
            let pts: Vec<_> = tr.layer(layer).map(|p| p.joints.unwrap()).collect();
            assert_eq!(pts.len(), POINTS);
            for q in &pts {
                for j in 0..5 {
                    assert!(
                        (q[j] - pts[0][j]).abs() < 1e-9,
                        "c {c}, layer {layer}, J{}: {} vs {}",
                        j + 1,
                        q[j],
                        pts[0][j]
                    );
                }
            }
            // J6 turns once per layer, at constant speed, without jumps
            let turn = pts[POINTS - 1][5] - pts[0][5];
            assert!(
                (turn.abs() - TAU * (POINTS - 1) as f64 / POINTS as f64).abs() < 1e-6,
                "{turn}"
            );
            let speeds: Vec<f64> = tr
                .layer(layer)
                .skip(1)
                .map(|p| p.joint_speed_rad_s[5])
                .collect();
            let s0 = speeds[0];
            assert!(speeds.iter().all(|s| (s - s0).abs() < 1e-6 * s0.abs()));
        }
    }
}

#[test]
fn joint_speeds_follow_the_travel_speed() {
    let cell = robowam_part_carried(thesis_configuration());
    let path = hemisphere(|_, v| -v);
    let slow = joint_trajectory(&cell, &path, &TrajectoryOptions::default()).unwrap();
    let fast = joint_trajectory(
        &cell,
        &at_speed(&path, 600.0),
        &TrajectoryOptions::default(),
    )
    .unwrap();
    for (a, b) in slow.points.iter().zip(&fast.points) {
        assert!((b.joint_speed_rad_s[5] - 100.0 * a.joint_speed_rad_s[5]).abs() < 1e-9);
    }
    // at 6 mm/s J6 needs 6/A rad/s on a layer of radius A: far below 550°/s ...
    assert_eq!(
        slow.report
            .violations
            .iter()
            .filter(|v| matches!(v.kind, ViolationKind::JointSpeed { .. }))
            .count(),
        0
    );
    // ... at 6000 mm/s the small top layers are too fast for J6, and reported
    let crazy = joint_trajectory(
        &cell,
        &at_speed(&path, 6000.0),
        &TrajectoryOptions::default(),
    )
    .unwrap();
    let text = crazy.report.to_string();
    assert!(text.contains("J6 needs"), "{text}");
}

/// `path` with every point reached at `v` (mm/s).
fn at_speed(path: &[PathPointInput], v: f64) -> Vec<PathPointInput> {
    path.iter()
        .map(|p| PathPointInput {
            travel_speed_mm_s: v,
            ..*p
        })
        .collect()
}

#[test]
fn each_point_is_reached_at_its_own_speed() {
    // layer 3's odd points at a third of the speed: their joint speeds are a
    // third and their times three times the uniform run's; every other
    // point's are unchanged (dt_m = |M_m - M_{m-1}| / TS_m)
    let cell = robowam_part_carried(thesis_configuration());
    let path = hemisphere(|_, v| -v);
    let uniform = joint_trajectory(&cell, &path, &TrajectoryOptions::default()).unwrap();
    let slowed: Vec<PathPointInput> = path
        .iter()
        .map(|p| PathPointInput {
            travel_speed_mm_s: if p.layer == 3 && p.point % 2 == 1 {
                p.travel_speed_mm_s / 3.0
            } else {
                p.travel_speed_mm_s
            },
            ..*p
        })
        .collect();
    let tr = joint_trajectory(&cell, &slowed, &TrajectoryOptions::default()).unwrap();
    let mut seen = 0;
    for ((a, b), p) in uniform.points.iter().zip(&tr.points).zip(&slowed) {
        assert_eq!(a.joints, b.joints);
        let k = if p.layer == 3 && p.point % 2 == 1 {
            3.0
        } else {
            1.0
        };
        assert!((b.dt_s - k * a.dt_s).abs() <= 1e-12 * a.dt_s.max(1.0));
        for j in 0..6 {
            let want = a.joint_speed_rad_s[j] / k;
            assert!((b.joint_speed_rad_s[j] - want).abs() <= 1e-9 * want.abs().max(1.0));
        }
        seen += usize::from(k > 1.0 && a.dt_s > 0.0);
    }
    assert!(seen > 10, "{seen} slowed points");
}
