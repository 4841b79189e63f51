//! Placement of the part in the cell (`optimise::place`, `pipeline::place_part`):
//! a hemisphere refused where a ROBOWAM part-carried cell puts it plans after
//! placement, checked by the FANUC ArcMate forward kinematics written out in
//! SPEC §6.1 (independent of the library's model); the placed cell file reads
//! back and stays feasible when placed again; bad bounds name their field.

use crate::common::part_path;
use waam_slicer::math::{Matrix3, Vector3};
use waam_slicer::pipeline::{place_part, PlaceRequest};
use waam_slicer::{plan_part, Cell, Part, PlanOptions, SliceOverrides};

fn rx(a: f64) -> Matrix3 {
    let (s, c) = a.sin_cos();
    Matrix3::new(1.0, 0.0, 0.0, 0.0, c, -s, 0.0, s, c)
}
fn ry(a: f64) -> Matrix3 {
    let (s, c) = a.sin_cos();
    Matrix3::new(c, 0.0, s, 0.0, 1.0, 0.0, -s, 0.0, c)
}
fn rz(a: f64) -> Matrix3 {
    let (s, c) = a.sin_cos();
    Matrix3::new(c, -s, 0.0, s, c, 0.0, 0.0, 0.0, 1.0)
}

/// ArcMate 120iC flange pose from controller joints (rad), SPEC §6.1:
/// p = Rz(J1)[150,0,0] + Rz(J1)Ry(J2)[0,0,790] + Rz(J1)Ry(-J3)[835,0,250] + R6[100,0,0],
/// flange rotation R6·[[0,0,1],[0,-1,0],[1,0,0]].
fn spec_fk(q: &[f64; 6]) -> (Matrix3, Vector3) {
    let r1 = rz(q[0]);
    let r3 = r1 * ry(-q[2]);
    let r6 = r3 * rx(-q[3]) * ry(-q[4]) * rx(-q[5]);
    let p = r1 * Vector3::new(150.0, 0.0, 0.0)
        + r1 * ry(q[1]) * Vector3::new(0.0, 0.0, 790.0)
        + r3 * Vector3::new(835.0, 0.0, 250.0)
        + r6 * Vector3::new(100.0, 0.0, 0.0);
    let flange = r6 * Matrix3::new(0.0, 0.0, 1.0, 0.0, -1.0, 0.0, 1.0, 0.0, 0.0);
    (flange, p)
}

#[test]
fn spec_fk_reproduces_the_spec_check_values() {
    let (_, p) = spec_fk(&[0.0; 6]);
    assert!((p - Vector3::new(1085.0, 0.0, 1040.0)).norm() < 1e-9);
    let (_, p) = spec_fk(&[0.0, 10f64.to_radians(), 0.0, 0.0, 0.0, 0.0]);
    assert!(
        (p - Vector3::new(1222.18, 0.0, 1028.00)).norm() < 0.01,
        "{p}"
    );
    let (r, p) = spec_fk(&[0.0, 0.0, 0.0, 0.0, -90f64.to_radians(), 0.0]);
    assert!((p - Vector3::new(985.0, 0.0, 940.0)).norm() < 1e-9, "{p}");
    assert!((r.column(2) - Vector3::new(0.0, 0.0, -1.0)).norm() < 1e-9);
}

/// The ROBOWAM part-carried cell with its deposition point moved to
/// `[700, -300, 400]`, where the hemisphere is refused, and a search box.
fn misplaced_cell() -> Cell {
    let text = std::fs::read_to_string(part_path("cells/robowam_part_carried.toml")).unwrap();
    let text = text.replace(
        "deposition_point_mm = [1045.747, -630.155, 653.167]",
        "deposition_point_mm = [700.0, -300.0, 400.0]",
    ) + "\n[placement]\nmin_mm = [600, -900, 300]\nmax_mm = [1300, 300, 1200]\n";
    Cell::from_toml_str(&text, "misplaced.toml").unwrap()
}

fn small() -> SliceOverrides {
    SliceOverrides {
        discretisation: Some(waam_slicer::path::Discretisation::Points(48)),
        ..SliceOverrides::default()
    }
}

#[test]
fn a_refused_hemisphere_plans_after_placement_checked_by_spec_kinematics() {
    let part = Part::read(part_path("hemisphere.toml")).unwrap();
    let cell = misplaced_cell();
    let opts = PlanOptions {
        slice: small(),
        ..PlanOptions::default()
    };
    let before = plan_part(&part, &cell, &opts).unwrap();
    assert!(
        !before.is_feasible(),
        "the misplaced cell must refuse the part"
    );

    let req = PlaceRequest {
        slice: small(),
        ..PlaceRequest::default()
    };
    let placed = place_part(&part, &cell, &req).unwrap();
    assert!(placed.placement.feasible, "{:?}", placed.summary());
    assert!(placed.placement.margins.joint_limit_deg > 0.0);
    assert!(placed.toml.starts_with("# Placed by waam place"));

    // The written cell file reads back and plans (as `plan` would take it).
    let again = Cell::from_toml_str(&placed.toml, "placed.toml").unwrap();
    let planned = plan_part(&part, &again, &opts).unwrap();
    assert!(planned.is_feasible(), "{:?}", planned.refusal);

    // Independent check: every planned point, carried by the SPEC's forward
    // kinematics of the planned joints, is at the placed D_R with its tool
    // axis vertical.
    let doc: toml::Table = placed.toml.parse().unwrap();
    let pc = doc["part_carried"].as_table().unwrap();
    let d: Vec<f64> = pc["deposition_point_mm"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_float().unwrap())
        .collect();
    let d_r = Vector3::new(d[0], d[1], d[2]);
    let (fp_rot, fp_t) = match pc.get("flange_from_part_xyzwpr") {
        Some(v) => {
            let v: Vec<f64> = v
                .as_array()
                .unwrap()
                .iter()
                .map(|x| x.as_float().unwrap())
                .collect();
            // FANUC W P R: Rz(R) Ry(P) Rx(W) (SPEC §6.3).
            let r = rz(v[5].to_radians()) * ry(v[4].to_radians()) * rx(v[3].to_radians());
            (r, Vector3::new(v[0], v[1], v[2]))
        }
        None => (Matrix3::identity(), Vector3::zeros()),
    };
    let mut checked = 0;
    for (lp, pl) in planned.layers.iter().zip(&planned.plan.layers) {
        for (cp, pp) in lp.points.iter().zip(&pl.points) {
            let (r, p) = spec_fk(&pp.joints.unwrap());
            let m = r * (fp_rot * cp.position_mm.coords + fp_t) + p;
            assert!(
                (m - d_r).norm() < 1e-3,
                "layer {}: {m} vs D_R {d_r}",
                lp.layer
            );
            let t = r * fp_rot * cp.tool_axis.into_inner();
            assert!((t - Vector3::z()).norm() < 1e-6, "tool axis {t}");
            checked += 1;
        }
    }
    assert!(checked > 300);

    // Placing again from the placed cell keeps it feasible with margins at
    // least as wide (the search starts from the cell as given).
    let replaced = place_part(&part, &again, &req).unwrap();
    assert!(replaced.placement.feasible);
    assert!(
        replaced.placement.margins.joint_limit_deg
            >= placed.placement.margins.joint_limit_deg.min(10.0) - 0.5,
        "{:?} vs {:?}",
        replaced.placement.margins,
        placed.placement.margins
    );
}

#[test]
fn bad_placement_bounds_name_their_field() {
    let text = std::fs::read_to_string(part_path("cells/robowam_part_carried.toml")).unwrap();
    let bad = text.clone() + "\n[placement]\nmin_mm = [900, 0, 0]\nmax_mm = [800, 10, 10]\n";
    let cell = Cell::from_toml_str(&bad, "bad.toml").unwrap();
    let part = Part::read(part_path("hemisphere.toml")).unwrap();
    let e = place_part(&part, &cell, &PlaceRequest::default()).unwrap_err();
    assert!(e.to_string().contains("deposition_point_mm.x"), "{e}");
    let bad = text.clone() + "\n[placement]\nfixed = [\"w\"]\n";
    let e = Cell::from_toml_str(&bad, "bad.toml").unwrap_err();
    assert!(e.to_string().contains("placement.fixed"), "{e}");
    let bad = text + "\n[placement]\nmin_mm = [900, 0, 0]\n";
    let e = Cell::from_toml_str(&bad, "bad.toml").unwrap_err();
    assert!(e.to_string().contains("placement.min_mm"), "{e}");
}
