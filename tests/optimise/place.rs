//! Placement of the part in the cell (`optimise::place`, `pipeline::place_part`):
//! a hemisphere refused where a ROBOWAM part-carried cell puts it plans after
//! placement, checked by the FANUC ArcMate forward kinematics written out in
//! SPEC §6.1 (independent of the library's model); the placed cell file reads
//! back and stays feasible when placed again; bad bounds name their field.

use crate::common::{part_path, rx, ry, rz, spec_fk};
use waam_slicer::math::{Matrix3, Vector3};
use waam_slicer::pipeline::{place_part, PlaceRequest};
use waam_slicer::{plan_part, Cell, Part, PlanOptions, SliceOverrides};

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

/// Checks every planned point of `planned` with the SPEC §6.1 forward
/// kinematics against the placed cell file `toml`: the part point carried by
/// the flange pose of its planned joints through the file's
/// `flange_from_part_xyzwpr` lands on the file's `deposition_point_mm`
/// (within 1 µm) with its tool axis vertical (within 1e-6). Returns the
/// number of points checked. Reads the file's numbers itself (not the
/// library's cell model).
fn fk_check(toml: &str, planned: &waam_slicer::pipeline::PlannedPart) -> usize {
    let doc: toml::Table = toml.parse().unwrap();
    let pc = doc["part_carried"].as_table().unwrap();
    let floats = |v: &toml::Value| -> Vec<f64> {
        v.as_array()
            .unwrap()
            .iter()
            .map(|x| x.as_float().or(x.as_integer().map(|i| i as f64)).unwrap())
            .collect()
    };
    let d = floats(&pc["deposition_point_mm"]);
    let d_r = Vector3::new(d[0], d[1], d[2]);
    let (fp_rot, fp_t) = match pc.get("flange_from_part_xyzwpr") {
        Some(v) => {
            let v = floats(v);
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
    checked
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
    // The user's file survives: every comment line of the original (the
    // cell file's notes on J5, J6 and the configuration) and every key
    // outside the placement, as written.
    let original = &cell.text;
    for line in original.lines().filter(|l| l.trim_start().starts_with('#')) {
        assert!(placed.toml.contains(line), "comment lost: {line}");
    }
    let before_placement = original.split("\n[placement]").next().unwrap();
    for line in before_placement.lines() {
        if !line.starts_with("deposition_point_mm") {
            assert!(placed.toml.contains(line), "line lost: {line:?}");
        }
    }

    // The written cell file reads back and plans (as `plan` would take it).
    let again = Cell::from_toml_str(&placed.toml, "placed.toml").unwrap();
    let planned = plan_part(&part, &again, &opts).unwrap();
    assert!(planned.is_feasible(), "{:?}", planned.refusal());

    // Independent check: every planned point, carried by the SPEC's forward
    // kinematics of the planned joints, is at the placed D_R with its tool
    // axis vertical.
    assert!(fk_check(&placed.toml, &planned) > 300);

    // Placing again from the placed cell keeps it feasible with margins at
    // least as wide (the search starts from the cell as given).
    let replaced = place_part(&part, &again, &req).unwrap();
    assert!(replaced.placement.feasible);
    // One header, the new one, on a file placed twice; the comments kept.
    assert_eq!(replaced.toml.matches("# Placed by waam place").count(), 1);
    for line in original.lines().filter(|l| l.trim_start().starts_with('#')) {
        assert!(replaced.toml.contains(line), "comment lost: {line}");
    }
    assert!(
        replaced.placement.margins.joint_limit_deg
            >= placed.placement.margins.joint_limit_deg.min(10.0) - 0.5,
        "{:?} vs {:?}",
        replaced.placement.margins,
        placed.placement.margins
    );
}

/// Issue 19's "done when": the S-bent tube of `parts/s-bend.toml` (a pipe
/// of straight legs and two opposite 90° bends, as a new user writes one)
/// is refused where `parts/cells/robowam_part_carried.toml` puts it, at
/// J5's ±135° travel, and plans after `place_part` in that cell with its
/// own `[placement]`-less default box; every planned point is checked by
/// the SPEC §6.1 forward kinematics with the placed file's `D_R`.
/// Coarse grid for test time: Delta 5 mm, 48 points a layer (86 layers;
/// refused at J5's travel on that grid too, as on the part file's own
/// Delta 2 / 400 points, checked with `waam plan` on 2026-12-02).
#[test]
fn the_s_bent_tube_refused_in_the_robowam_part_carried_cell_plans_after_placement() {
    let part = Part::read(part_path("s-bend.toml")).unwrap();
    let cell = Cell::read(part_path("cells/robowam_part_carried.toml")).unwrap();
    let coarse = SliceOverrides {
        delta_mm: Some(5.0),
        discretisation: Some(waam_slicer::path::Discretisation::Points(48)),
        ..SliceOverrides::default()
    };
    let opts = PlanOptions {
        slice: coarse.clone(),
        ..PlanOptions::default()
    };
    let before = plan_part(&part, &cell, &opts).unwrap();
    assert!(
        !before.is_feasible(),
        "the cell as given must refuse the S-bend"
    );
    let j5 = before
        .plan
        .infeasible_layers()
        .filter(|l| l.status.to_string().contains("J5 travel"))
        .count();
    assert!(j5 > 0, "refused at J5's travel: {:?}", before.refusal());

    let req = PlaceRequest {
        slice: coarse,
        ..PlaceRequest::default()
    };
    let placed = place_part(&part, &cell, &req).unwrap();
    assert!(placed.placement.feasible, "{:#?}", placed.summary());
    let again = Cell::from_toml_str(&placed.toml, "placed.toml").unwrap();
    let planned = plan_part(&part, &again, &opts).unwrap();
    assert!(planned.is_feasible(), "{:?}", planned.refusal());
    assert_eq!(fk_check(&placed.toml, &planned), 86 * 48);
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
    let bad = text.clone() + "\n[placement]\nmin_mm = [900, 0, 0]\n";
    let e = Cell::from_toml_str(&bad, "bad.toml").unwrap_err();
    assert!(e.to_string().contains("placement.min_mm"), "{e}");
    // The fixture and torch-mount ranges: beyond ±90°, unordered, not
    // finite, or a variable the cell kind does not have.
    let torch = std::fs::read_to_string(part_path("cells/kuka_kr16_2_torch_carried.toml")).unwrap();
    for (base, table, field) in [
        (&text, "tilt_x_deg = [-100, 0]", "placement.tilt_x_deg"),
        (&text, "tilt_y_deg = [10, -10]", "placement.tilt_y_deg"),
        (&text, "offset_mm = [0, inf]", "placement.offset_mm"),
        (
            &text,
            "torch_rotation_deg = [-90, 90]",
            "placement.torch_rotation_deg",
        ),
        (&torch, "offset_mm = [0, 50]", "placement.offset_mm"),
        (
            &torch,
            "torch_rotation_deg = [-200, 200]",
            "placement.torch_rotation_deg",
        ),
        (&torch, "tilt_x_deg = [nan, 10]", "placement.tilt_x_deg"),
    ] {
        let bad = format!("{base}\n[placement]\n{table}\n");
        let e = Cell::from_toml_str(&bad, "bad.toml").unwrap_err();
        assert!(e.to_string().contains(field), "{table}: {e}");
        assert!(e.to_string().contains("bad.toml"), "{table}: {e}");
    }
    // Good ranges read and become free variables of the search, in radians.
    let good =
        format!("{torch}\n[placement]\ntilt_x_deg = [-30, 30]\ntorch_rotation_deg = [-90, 90]\n");
    let cell = Cell::from_toml_str(&good, "good.toml").unwrap();
    let b = waam_slicer::pipeline::placement_bounds(&cell, 400.0).unwrap();
    let v = &b.variables;
    assert_eq!(
        (v[4].name, v[5].name, v[6].name),
        ("fixture.tilt_x", "fixture.tilt_y", "torch_rotation")
    );
    assert!((v[4].upper - 30f64.to_radians()).abs() < 1e-12 && v[4].is_free());
    assert!(!v[5].is_free());
    assert!((v[6].lower + 90f64.to_radians()).abs() < 1e-12);
}

/// Issue 19's "done when" at the S-bend's own grid (Delta 2 mm, 400 points a
/// layer, 213 layers, 85 200 points), the default search: placed, the
/// written cell plans, and every one of the 85 200 planned points is checked
/// by the SPEC §6.1 forward kinematics at the placed file's `D_R`.
/// Measured alone (2026-12-03, 2-core box, load average 3): 53 s in the
/// test profile, 33 s of CPU in release for the search itself.
#[test]
fn the_s_bent_tube_at_its_own_grid_plans_after_placement() {
    let part = Part::read(part_path("s-bend.toml")).unwrap();
    let cell = Cell::read(part_path("cells/robowam_part_carried.toml")).unwrap();
    let opts = PlanOptions::default();
    let before = plan_part(&part, &cell, &opts).unwrap();
    assert!(!before.is_feasible(), "the cell as given must refuse it");
    let placed = place_part(&part, &cell, &PlaceRequest::default()).unwrap();
    assert!(placed.placement.feasible, "{:#?}", placed.summary());
    let again = Cell::from_toml_str(&placed.toml, "placed.toml").unwrap();
    let planned = plan_part(&part, &again, &opts).unwrap();
    assert!(planned.is_feasible(), "{:?}", planned.refusal());
    assert_eq!(planned.plan.layers.len(), 213);
    assert_eq!(fk_check(&placed.toml, &planned), 213 * 400);
}

/// A refused placement names its binding constraint as data: the S-bend,
/// refused where `parts/cells/robowam_part_carried.toml` puts it at J5's
/// travel (the cell file restricts J5 to ±135°, "to avoid substrate/robot
/// collisions"), with every placement variable fixed so that the search can
/// only judge the cell as given: the binding is a joint limit named by its
/// joint (J5), the same constraint `plan_part` reports for the cell's
/// infeasible layers; a share in (0, 1]; and its words are those of
/// `placement.json`. Coarse grid (Delta 5 mm, 48 points) as in the S-bend
/// test above.
#[test]
fn a_refused_placement_names_the_joint_limit_as_a_typed_binding() {
    use waam_slicer::optimise::{Constraint, LayerStatus};
    use waam_slicer::place::{Binding, Limit, PlaceOptions};
    let part = Part::read(part_path("s-bend.toml")).unwrap();
    let text = std::fs::read_to_string(part_path("cells/robowam_part_carried.toml")).unwrap();
    let text = text + "\n[placement]\nfixed = [\"x\", \"y\", \"z\", \"rotation\"]\n";
    let cell = Cell::from_toml_str(&text, "fixed.toml").unwrap();
    let coarse = SliceOverrides {
        delta_mm: Some(5.0),
        discretisation: Some(waam_slicer::path::Discretisation::Points(48)),
        ..SliceOverrides::default()
    };
    // The cell's own verdict, layer by layer: J5's travel binds.
    let opts = PlanOptions {
        slice: coarse.clone(),
        ..PlanOptions::default()
    };
    let before = plan_part(&part, &cell, &opts).unwrap();
    let planned_limits: Vec<Constraint> = before
        .plan
        .infeasible_layers()
        .filter_map(|l| match &l.status {
            LayerStatus::Infeasible { binding } | LayerStatus::FixedViolates { binding } => {
                Some(binding.constraint)
            }
            _ => None,
        })
        .collect();
    let j5 = Constraint::JointLimit { joint: 5 };
    assert!(planned_limits.contains(&j5), "{planned_limits:?}");

    let req = waam_slicer::PlaceRequest {
        slice: coarse,
        search: PlaceOptions {
            samples: 2,
            rounds: 1,
            ..PlaceOptions::default()
        },
        ..waam_slicer::PlaceRequest::default()
    };
    let placed = waam_slicer::place_part(&part, &cell, &req).unwrap();
    let p = &placed.placement;
    assert!(!p.feasible, "{:#?}", placed.summary());
    let binding = p.binding.as_ref().expect("a refused placement names why");
    assert_eq!(binding.limit(), Some(&Limit::Layer(j5)), "{binding:?}");
    assert!(
        matches!(
            binding,
            Binding::Subsample { .. } | Binding::FullPath { .. }
        ),
        "{binding:?}"
    );
    assert!(binding.share() > 0.0 && binding.share() <= 1.0);
    assert_eq!(
        serde_json::to_value(placed.summary()).unwrap()["binding"]["constraint"],
        binding.to_string().as_str()
    );
    assert!(binding.to_string().starts_with("J5 travel"), "{binding}");
}

/// The request's half box is an `Option`: a value given must be positive
/// and finite, and the error names the field.
#[test]
fn a_bad_half_box_names_its_field() {
    let part = Part::read(part_path("hemisphere.toml")).unwrap();
    let cell = Cell::read(part_path("cells/robowam_part_carried.toml")).unwrap();
    for h in [0.0, -1.0, f64::NAN] {
        let req = waam_slicer::PlaceRequest {
            half_box_mm: Some(h),
            ..waam_slicer::PlaceRequest::default()
        };
        let e = waam_slicer::place_part(&part, &cell, &req).unwrap_err();
        assert!(e.to_string().contains("half_box_mm"), "{h}: {e}");
    }
}
