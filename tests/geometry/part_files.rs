//! Part files: every sample parses; each kind of malformed file gives an
//! error naming the file and the field, never a panic.

use crate::common::{load_part, part_path, SAMPLE_PARTS};
use std::path::Path;
use waam_slicer::io::part_file::{
    parse_part, read_part_file, Discretisation, PartFileError, Strategy,
};

/// The smallest valid part file; each test breaks one field of it.
fn good() -> String {
    crate::common::cylinder_part_text("t", 10.0, 20.0, 2.0)
}

fn err(text: &str) -> PartFileError {
    match parse_part(text, "bad.toml", Path::new(".")) {
        Ok(_) => panic!("accepted:\n{text}"),
        Err(e) => e,
    }
}

fn assert_names(e: &PartFileError, needles: &[&str]) {
    let msg = e.to_string();
    assert!(msg.contains("bad.toml"), "no file name in: {msg}");
    for n in needles {
        assert!(msg.contains(n), "`{n}` missing in: {msg}");
    }
}

#[test]
fn every_sample_part_reads() {
    for name in SAMPLE_PARTS {
        let part = load_part(name);
        assert!(
            !part.name.is_empty() && !part.description.is_empty() && !part.source.is_empty(),
            "{name}"
        );
        assert!(part.slicing.delta_mm > 0.0);
    }
    let torus = load_part("quarter-torus.toml");
    assert_eq!(torus.slicing.strategy, Strategy::Constant);
    assert_eq!(torus.slicing.discretisation, Discretisation::Points(500));
    assert!(torus.end_plane.is_some());
    assert!((torus.tube.range().t_max - std::f64::consts::FRAC_PI_2).abs() < 1e-15);
}

#[test]
fn the_minimal_file_is_accepted() {
    let part = parse_part(&good(), "good.toml", Path::new(".")).unwrap();
    assert_eq!(part.slicing.discretisation, Discretisation::Points(500));
}

#[test]
fn syntax_error_names_file_and_line() {
    let e = err(&good().replace("t_max = 20", "t_max = = 20"));
    assert!(matches!(e, PartFileError::Syntax { .. }));
    assert_names(&e, &["line"]);
}

#[test]
fn truncated_file_is_an_error() {
    let e = err(&good()[..good().len() / 2]);
    assert_names(&e, &[]);
}

#[test]
fn unknown_field_is_named() {
    let e = err(&good().replace("radius = 10", "radius = 10\nradiuss = 3"));
    assert_names(&e, &["radiuss"]);
    let e = err(&good().replace("name = \"t\"", "name = \"t\"\ncolour = 1"));
    assert_names(&e, &["colour"]);
}

#[test]
fn missing_guide_is_named() {
    let text = good().replace(
        "[guide]\nkind = \"line\"\norigin = [0, 0, 0]\ndirection = [0, 0, 1]\n",
        "",
    );
    let e = err(&text);
    assert_names(&e, &["guide"]);
}

#[test]
fn negative_radius_is_named() {
    let e = err(&good().replace("radius = 10", "radius = -3"));
    assert_names(&e, &["profile.radius", "positive"]);
    let e = err(&good().replace(
        "kind = \"constant\"\nradius = 10",
        "kind = \"expr\"\nradius = \"5 - t\"",
    ));
    assert!(matches!(e, PartFileError::Geometry { .. }), "{e:?}");
    assert_names(&e, &["not positive", "t = 5"]);
}

#[test]
fn unparsable_expression_is_named() {
    let e = err(&good().replace(
        "kind = \"constant\"\nradius = 10",
        "kind = \"expr\"\nradius = \"5 + cos(t\"",
    ));
    assert_names(&e, &["profile.radius", "5 + cos(t"]);
    let e = err(&good().replace(
        "kind = \"constant\"\nradius = 10",
        "kind = \"expr\"\nradius = \"5 + k * t\"",
    ));
    assert_names(&e, &["profile.radius", "unknown variable `k`"]);
}

#[test]
fn empty_t_range_is_named() {
    let e = err(&good().replace("t_max = 20", "t_max = 0"));
    assert_names(&e, &["range", "empty t-range"]);
}

#[test]
fn wrong_type_and_non_finite_numbers_are_named() {
    let e = err(&good().replace("t_max = 20", "t_max = [1]"));
    assert_names(&e, &["t_max"]);
    let e = err(&good().replace("t_max = 20", "t_max = nan"));
    assert_names(&e, &["range.t_max", "finite"]);
    let e = err(&good().replace("delta_mm = 2", "delta_mm = inf"));
    assert_names(&e, &["slicing.delta_mm"]);
    let e = err(&good().replace("delta_mm = 2", "delta_mm = -1"));
    assert_names(&e, &["slicing.delta_mm"]);
}

#[test]
fn self_folding_tube_names_t() {
    let text = std::fs::read_to_string(part_path("quarter-torus.toml"))
        .unwrap()
        .replace("r = 15.0", "r = 55.0");
    let e = err(&text);
    match &e {
        PartFileError::Geometry { source, .. } => assert!(matches!(
            source,
            waam_slicer::geometry::GeometryError::Folds { .. }
        )),
        other => panic!("{other:?}"),
    }
    assert_names(&e, &["folds at t = 0.000000", "55.0000", "50.0000"]);
    // The elbow folds in its bend only: the error names a t inside the bend.
    let text = std::fs::read_to_string(part_path("elbow.toml"))
        .unwrap()
        .replace("radius = 20", "radius = 61");
    match err(&text) {
        PartFileError::Geometry {
            source: waam_slicer::geometry::GeometryError::Folds { t, .. },
            ..
        } => {
            assert!(
                (30.0..=30.0 + 60.0 * std::f64::consts::FRAC_PI_2).contains(&t),
                "t = {t}"
            )
        }
        other => panic!("{other:?}"),
    }
}

#[test]
fn zero_derivative_guide_names_t() {
    let text = good().replace(
        "kind = \"line\"\norigin = [0, 0, 0]\ndirection = [0, 0, 1]",
        "kind = \"expr\"\nx = \"0\"\ny = \"0\"\nz = \"(t - 10)^3 + 10\"",
    );
    let e = err(&text);
    assert_names(&e, &["zero derivative", "t = 10.000000"]);
}

#[test]
fn unicode_garbage_and_missing_file_are_errors() {
    let e = err("名前 = ☃\u{0}\u{fffd}");
    assert!(matches!(e, PartFileError::Syntax { .. }));
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("garbage.toml");
    std::fs::write(&p, [0xff, 0xfe, 0x00, 0x41]).unwrap();
    let e = read_part_file(&p).unwrap_err();
    assert!(
        e.to_string().contains("garbage.toml") && e.to_string().contains("UTF-8"),
        "{e}"
    );
    let e = read_part_file(&dir.path().join("none.toml")).unwrap_err();
    assert!(matches!(e, PartFileError::Io { .. }) && e.to_string().contains("none.toml"));
}

#[test]
fn conflicting_discretisations_are_named() {
    let e = err(&good().replace("delta_mm = 2", "delta_mm = 2\npoints = 100\nchord_mm = 0.1"));
    assert_names(&e, &["slicing", "only one"]);
    let e = err(&good().replace("delta_mm = 2", "delta_mm = 2\npoints = 2"));
    assert_names(&e, &["slicing.points"]);
}

#[test]
fn missing_stl_substrate_names_the_field() {
    let e = err(&good().replace(
        "kind = \"plane\"\npoint = [0, 0, 0]\nnormal = [0, 0, 1]",
        "kind = \"mesh\"\nfile = \"nope.stl\"",
    ));
    assert_names(&e, &["substrate.file", "nope.stl"]);
}

/// `[tool_axis]` and `[process]`: read into the library's options (degrees
/// to radians, preset plus overrides), and each bad value names its field.
#[test]
fn tool_axis_and_process_tables() {
    let text = format!(
        "{}\n[tool_axis]\nlead_deg = 5\ntilt_deg = -3\nmax_lean_deg = 50\nproject_build = [1, 0, 0]\nproject_build_full_deg = 45\nmax_axis_rate_deg_per_mm = 10\n\n[process]\npreset = \"pla\"\ntravel_speed_mm_s = 5\n",
        good()
    );
    let part = parse_part(&text, "good.toml", Path::new(".")).unwrap();
    let o = &part.tool_axis;
    assert!((o.lead_rad - 5f64.to_radians()).abs() < 1e-15);
    assert!((o.tilt_rad + 3f64.to_radians()).abs() < 1e-15);
    assert_eq!(o.rule, waam_slicer::toolaxis::AxisRule::thesis_50_deg());
    assert_eq!(o.project_build, Some([1.0, 0.0, 0.0]));
    assert!((o.project_build_full_rad.unwrap() - 45f64.to_radians()).abs() < 1e-15);
    assert!((o.max_axis_rate_rad_per_mm.unwrap() - 10f64.to_radians()).abs() < 1e-15);
    assert_eq!(part.process.material, "PLA");
    assert_eq!(part.process.travel_speed_mm_s, 5.0);
    // Absent tables: T = b, CMT steel.
    let plain = parse_part(&good(), "good.toml", Path::new(".")).unwrap();
    assert_eq!(
        plain.tool_axis,
        waam_slicer::toolaxis::ToolAxisOptions::default()
    );
    assert_eq!(
        plain.process,
        waam_slicer::process::ProcessParameters::cmt_steel_er70s6()
    );
    for (table, bad, field) in [
        ("tool_axis", "max_lean_deg = 95", "tool_axis.max_lean_deg"),
        ("tool_axis", "lead_deg = 90", "tool_axis.lead_deg"),
        ("tool_axis", "lean_axis = [0, 0, 1]", "tool_axis.lean_axis"),
        (
            "tool_axis",
            "project_build_full_deg = 45",
            "tool_axis.project_build_full_deg",
        ),
        (
            "tool_axis",
            "project_build = [1, 0, 0]\nproject_build_full_deg = 90",
            "tool_axis.project_build_full_deg",
        ),
        (
            "tool_axis",
            "project_build = [0, 0, 0]",
            "tool_axis.project_build",
        ),
        (
            "tool_axis",
            "max_axis_rate_deg_per_mm = -1",
            "tool_axis.max_axis_rate_deg_per_mm",
        ),
        ("tool_axis", "normals = \"magic\"", "normals"),
        ("process", "preset = \"gold\"", "preset"),
        (
            "process",
            "travel_speed_mm_s = 0",
            "process.travel_speed_mm_s",
        ),
        (
            "process",
            "travel_speed_mm_s = 100",
            "process.travel_speed_mm_s",
        ),
        ("process", "voltage = 3", "voltage"),
    ] {
        let e = err(&format!("{}\n[{table}]\n{bad}\n", good()));
        assert_names(&e, &[field]);
    }
}
