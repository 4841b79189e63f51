//! Issue 33, deliverable 5: `place` in a torch-carried cell searches the
//! part's offset on the positioner's table (table frame x, y) with the
//! positioner's pose. A quarter torus (a bent tube) mounted off the turn
//! axis in the ROBOWAM torch-carried cell is refused as given (the wrist
//! runs into the table); `place_part` with the default bounds moves the part
//! towards the turn axis, and the written `cell.toml` plans, read back as
//! `waam plan --cell` reads it. Every planned point is checked by hand: the
//! SPEC §6.1 forward kinematics of its planned joints, the torch of the
//! file's `tool_xyzwpr`, the positioner's tilt and turn and the mount
//! composed from the placement values (not the library's cell model). Bad
//! offset ranges name their field.
//!
//! Coarse grid for test time, as `place_cells.rs`: Delta 8 mm, 16 points a
//! layer, 8 coarse candidates on a 4-layer × 8-point subsample.

use crate::common::{part_path, rx, ry, rz, spec_fk};
use waam_slicer::math::{Matrix3, Vector3};
use waam_slicer::pipeline::{place_part, PlaceRequest};
use waam_slicer::place::PlaceOptions;
use waam_slicer::robot::CellLayout;
use waam_slicer::{plan_part, Cell, Part, PlanOptions, SliceOverrides};

fn coarse() -> SliceOverrides {
    SliceOverrides {
        delta_mm: Some(8.0),
        discretisation: Some(waam_slicer::path::Discretisation::Points(16)),
        ..SliceOverrides::default()
    }
}

/// The ROBOWAM torch-carried cell file's text with the part mounted at
/// `mount` on the table (FANUC `[X, Y, Z, W, P, R]`, table frame; mm, deg).
fn mounted_text(mount: [f64; 6]) -> String {
    let text = std::fs::read_to_string(part_path("cells/robowam_torch_carried.toml")).unwrap();
    let key = "max_hose_torsion_deg = 120.0\n";
    assert!(text.contains(key));
    text.replacen(
        key,
        &format!("{key}table_from_part_xyzwpr = {mount:?}\n"),
        1,
    )
}

/// A FANUC `[X, Y, Z, W, P, R]` (mm, deg) as rotation and translation:
/// `Rz(R) Ry(P) Rx(W)` (SPEC §6.3).
fn xyzwpr(v: &[f64]) -> (Matrix3, Vector3) {
    let r = rz(v[5].to_radians()) * ry(v[4].to_radians()) * rx(v[3].to_radians());
    (r, Vector3::new(v[0], v[1], v[2]))
}

/// The numbers of `key` in table `table` of the cell file `toml`.
fn floats(toml: &toml::Table, table: &str, key: &str) -> Vec<f64> {
    let t = toml[table].as_table().unwrap();
    let t = match key.split_once('.') {
        Some((sub, _)) => t[sub].as_table().unwrap(),
        None => t,
    };
    let v = &t[key.rsplit('.').next().unwrap()];
    match v.as_array() {
        Some(a) => a
            .iter()
            .map(|x| x.as_float().or(x.as_integer().map(|i| i as f64)).unwrap())
            .collect(),
        None => vec![v.as_float().unwrap()],
    }
}

/// The part at 250 mm along table x and 100 mm along y (269 mm from the turn
/// axis, at the Ø500 mm table's edge).
const MOUNT: [f64; 6] = [250.0, 100.0, 0.0, 0.0, 0.0, 0.0];

#[test]
fn a_bent_tube_off_the_turn_axis_plans_after_place_moves_it_on_the_table() {
    let dir = tempfile::tempdir().unwrap();
    let given = dir.path().join("off-centre.toml");
    std::fs::write(&given, mounted_text(MOUNT)).unwrap();
    let cell = Cell::read(&given).unwrap();
    let part = Part::read(part_path("quarter-torus.toml")).unwrap();
    let opts = PlanOptions {
        slice: coarse(),
        ..PlanOptions::default()
    };
    let before = plan_part(&part, &cell, &opts).unwrap();
    assert!(
        !before.is_feasible(),
        "the off-centre mount must be refused as given"
    );
    eprintln!(
        "as given: {} of {} layers feasible; {:?}",
        before.plan.layers.len() - before.plan.infeasible_layers().count(),
        before.plan.layers.len(),
        before.refusal().map(ToString::to_string)
    );

    let req = PlaceRequest {
        slice: coarse(),
        search: PlaceOptions {
            samples: 8,
            layers: 4,
            points_per_layer: 8,
            refined: 1,
            refine_evaluations: 6,
            rounds: 2,
            ..PlaceOptions::default()
        },
        ..PlaceRequest::default()
    };
    let placed = place_part(&part, &cell, &req).unwrap();
    let p = &placed.placement;
    assert!(p.feasible, "{:#?}", placed.summary());
    // The default bounds searched the offset: the part origin within
    // ±150 mm of the turn axis or where the file put it.
    let b = &placed.bounds.variables;
    assert_eq!(
        (b[7].name, b[8].name),
        ("fixture.offset_x", "fixture.offset_y")
    );
    assert_eq!((b[7].lower, b[7].upper), (-400.0, 0.0));
    assert_eq!((b[8].lower, b[8].upper), (-250.0, 50.0));
    // Moved towards the turn axis (rotation and tilts stay as given, so the
    // origin's distance in the table plane is that of mount + offset).
    let v = &p.values;
    assert_eq!((v.tilt_x, v.tilt_y, v.fixture_rotation), (0.0, 0.0, 0.0));
    let from_axis = (MOUNT[0] + v.offset_x_mm).hypot(MOUNT[1] + v.offset_y_mm);
    let was = MOUNT[0].hypot(MOUNT[1]);
    assert!(
        from_axis < was - 20.0,
        "the part origin is {from_axis:.1} mm from the turn axis (was {was:.1}): {v:?}"
    );
    eprintln!(
        "off-centre quarter torus: offset ({:.1}, {:.1}) mm, {:.1} -> {:.1} mm from the turn axis; positioner at {:?}, rotation {:.1} deg; {} candidates, {:.1} s",
        v.offset_x_mm,
        v.offset_y_mm,
        was,
        from_axis,
        v.position_mm,
        v.rotation.to_degrees(),
        p.candidates,
        p.time_s
    );

    // `placement.json` reports the offset in mm; `cell.toml` holds the
    // moved mount and plans as `waam plan --cell placed/cell.toml` would.
    let out = dir.path().join("placed");
    placed.write(&out).unwrap();
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("placement.json")).unwrap())
            .unwrap();
    let offset_x = json["variables"]
        .as_array()
        .unwrap()
        .iter()
        .find(|x| x["name"] == "fixture.offset_x")
        .unwrap();
    assert_eq!(offset_x["unit"], "mm");
    assert!((offset_x["found"].as_f64().unwrap() - v.offset_x_mm).abs() < 1e-9);
    let again = Cell::read(out.join("cell.toml")).unwrap();
    let planned = plan_part(&part, &again, &opts).unwrap();
    assert!(planned.is_feasible(), "{:?}", planned.refusal());

    // Independent check, from the file's numbers and the placement values
    // only: the mount composed by hand, T(offset) · Rz · Rx · Ry · mount₀
    // (table frame), is the file's `table_from_part_xyzwpr`; and every
    // planned point, carried by the SPEC §6.1 forward kinematics of its
    // planned joints and the file's torch, lies on the part point carried by
    // the positioner's tilt and turn and that mount, its torch axis along
    // the point's tool axis.
    let (m0_rot, m0_t) = xyzwpr(&MOUNT);
    let mount_rot = rz(v.fixture_rotation) * rx(v.tilt_x) * ry(v.tilt_y) * m0_rot;
    let mount_t = rz(v.fixture_rotation) * rx(v.tilt_x) * ry(v.tilt_y) * m0_t
        + Vector3::new(v.offset_x_mm, v.offset_y_mm, 0.0);
    let file: toml::Table = std::fs::read_to_string(out.join("cell.toml"))
        .unwrap()
        .parse()
        .unwrap();
    let (file_rot, file_t) = xyzwpr(&floats(&file, "torch_carried", "table_from_part_xyzwpr"));
    assert!((file_t - mount_t).norm() < 1e-5, "{file_t} vs {mount_t}");
    assert!((file_rot - mount_rot).norm() < 1e-6);
    let (pos_rot, pos_t) = xyzwpr(&floats(&file, "torch_carried", "positioner_pose_xyzwpr"));
    assert!((pos_t - v.position_mm.coords).norm() < 1e-5);
    let (tool_rot, tool_t) = xyzwpr(&floats(&file, "torch_carried", "tool_xyzwpr"));
    let l = floats(&file, "torch_carried", "positioner.tilt_to_table_mm")[0];
    // base_from_part at positioner joints [q7 tilt about y, q8 turn about z]
    // (the table centre C8 `l` above the tilt centre C7 along the tilted z).
    let base_from_part = |q: [f64; 2], m: &Vector3| {
        let r = pos_rot * ry(q[0]) * rz(q[1]);
        let c8 = pos_t + pos_rot * (ry(q[0]) * Vector3::new(0.0, 0.0, l));
        (r * mount_rot, r * (mount_rot * m + mount_t) + c8)
    };
    let CellLayout::TorchCarried(lib) = &again.layout else {
        panic!("torch carried")
    };
    let mut checked = 0;
    for (lp, pl) in planned.layers.iter().zip(&planned.plan.layers) {
        for (cp, pp) in lp.points.iter().zip(&pl.points) {
            let q = pp.positioner.unwrap();
            let (r_part, m) = base_from_part(q, &cp.position_mm.coords);
            // the library's cell puts the part point at the same place
            let lib_m = lib.base_from_part(&q) * cp.position_mm;
            assert!((lib_m.coords - m).norm() < 1e-6, "{lib_m} vs {m}");
            let (r, f) = spec_fk(&pp.joints.unwrap());
            let tcp = r * tool_t + f;
            assert!(
                (tcp - m).norm() < 1e-3,
                "layer {}: TCP {tcp} vs {m}",
                lp.layer
            );
            let axis = (r * tool_rot).column(2).into_owned();
            let t = r_part * cp.tool_axis.into_inner();
            assert!((axis - t).norm() < 1e-6, "torch axis {axis} vs {t}");
            checked += 1;
        }
    }
    assert!(checked >= 100, "{checked} points checked");
}

/// The offset and rotation-on-the-table ranges of `[placement]`: out of
/// ±1000 mm, unordered, not finite, wider than a turn, or a variable the
/// cell kind has not, refused naming the key; good ones become the search's
/// bounds (relative to the file's mount; mm, rad), `[0, 0]` keeps the offset.
#[test]
fn bad_table_offset_ranges_name_their_field() {
    let torch = mounted_text(MOUNT);
    let part = std::fs::read_to_string(part_path("cells/robowam_part_carried.toml")).unwrap();
    for (base, table, field) in [
        (&torch, "offset_x_mm = [0, inf]", "placement.offset_x_mm"),
        (&torch, "offset_x_mm = [-1500, 0]", "placement.offset_x_mm"),
        (&torch, "offset_y_mm = [10, -10]", "placement.offset_y_mm"),
        (&part, "offset_y_mm = [nan, 0]", "placement.offset_y_mm"),
        (
            &torch,
            "fixture_rotation_deg = [-200, 200]",
            "placement.fixture_rotation_deg",
        ),
        (
            &part,
            "fixture_rotation_deg = [-90, 90]",
            "placement.fixture_rotation_deg",
        ),
    ] {
        let bad = format!("{base}\n[placement]\n{table}\n");
        let e = Cell::from_toml_str(&bad, "bad.toml").unwrap_err();
        assert!(e.to_string().contains(field), "{table}: {e}");
        assert!(e.to_string().contains("bad.toml"), "{table}: {e}");
    }
    let good = format!(
        "{torch}\n[placement]\noffset_x_mm = [-300, 20]\noffset_y_mm = [0, 0]\nfixture_rotation_deg = [-90, 90]\n"
    );
    let cell = Cell::from_toml_str(&good, "good.toml").unwrap();
    let b = waam_slicer::pipeline::placement_bounds(&cell, 400.0).unwrap();
    let v = &b.variables;
    assert_eq!((v[7].lower, v[7].upper), (-300.0, 20.0));
    assert!(!v[8].is_free());
    assert_eq!(v[9].name, "fixture.rotation");
    assert!((v[9].upper - 90f64.to_radians()).abs() < 1e-12 && v[9].is_free());
    // Part carried: the flange-plane offset is searched when given only.
    let cell = Cell::from_toml_str(&part, "pc.toml").unwrap();
    let b = waam_slicer::pipeline::placement_bounds(&cell, 400.0).unwrap();
    assert!(b.variables[7..].iter().all(|v| !v.is_free()));
    let cell = Cell::from_toml_str(
        &format!("{part}\n[placement]\noffset_x_mm = [-50, 50]\n"),
        "pc.toml",
    )
    .unwrap();
    let b = waam_slicer::pipeline::placement_bounds(&cell, 400.0).unwrap();
    assert_eq!((b.variables[7].lower, b.variables[7].upper), (-50.0, 50.0));
}

/// The offset alone does it: with the positioner's pose fixed in
/// `[placement]`, the search still places the off-centre quarter torus,
/// by moving it on the table towards the turn axis.
#[test]
fn with_the_positioner_fixed_the_offset_alone_places_the_bent_tube() {
    let text = mounted_text(MOUNT) + "\n[placement]\nfixed = [\"x\", \"y\", \"z\", \"rotation\"]\n";
    let cell = Cell::from_toml_str(&text, "fixed.toml").unwrap();
    let part = Part::read(part_path("quarter-torus.toml")).unwrap();
    let req = PlaceRequest {
        slice: coarse(),
        search: PlaceOptions {
            samples: 8,
            layers: 4,
            points_per_layer: 8,
            refined: 1,
            refine_evaluations: 6,
            rounds: 2,
            ..PlaceOptions::default()
        },
        ..PlaceRequest::default()
    };
    let placed = place_part(&part, &cell, &req).unwrap();
    let p = &placed.placement;
    assert!(p.feasible, "{:#?}", placed.summary());
    let v = &p.values;
    let from_axis = (MOUNT[0] + v.offset_x_mm).hypot(MOUNT[1] + v.offset_y_mm);
    assert!(from_axis < MOUNT[0].hypot(MOUNT[1]) - 20.0, "{v:?}");
    let (CellLayout::TorchCarried(a), CellLayout::TorchCarried(b)) =
        (&cell.layout, &placed.cell.layout)
    else {
        panic!("torch carried")
    };
    assert_eq!(a.base_from_positioner, b.base_from_positioner);
    // The placed file's [placement] keeps the same box of the part origin
    // on the table, relative to the mount written.
    let spec = placed.cell.placement.as_ref().unwrap();
    let x = spec.offset_x_mm.unwrap();
    assert!((x[0] - (-400.0 - v.offset_x_mm)).abs() < 1e-6, "{x:?}");
    assert!((x[1] - (0.0 - v.offset_x_mm)).abs() < 1e-6, "{x:?}");

    // An offset kept at [0, 0] stays kept in the placed file.
    let text = mounted_text(MOUNT)
        + "\n[placement]\nfixed = [\"x\", \"y\", \"z\", \"rotation\"]\n\
           offset_x_mm = [0, 0]\noffset_y_mm = [0, 0]\n";
    let kept = place_part(
        &part,
        &Cell::from_toml_str(&text, "kept.toml").unwrap(),
        &req,
    )
    .unwrap();
    let spec = kept.cell.placement.as_ref().unwrap();
    assert_eq!(
        (spec.offset_x_mm, spec.offset_y_mm),
        (Some([0.0, 0.0]), Some([0.0, 0.0]))
    );
    let again = Cell::from_toml_str(&placed.toml, "placed.toml").unwrap();
    let opts = PlanOptions {
        slice: coarse(),
        ..PlanOptions::default()
    };
    let planned = plan_part(&part, &again, &opts).unwrap();
    assert!(planned.is_feasible(), "{:?}", planned.refusal());
    eprintln!(
        "positioner fixed: offset ({:.1}, {:.1}) mm, {from_axis:.1} mm from the turn axis, {:.1} s",
        v.offset_x_mm, v.offset_y_mm, p.time_s
    );
}
