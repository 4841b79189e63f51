//! The hostile inputs of issue 10's "Done when" list, one test each: every
//! one gets an error that names the file and the field, point or problem,
//! never a panic. (Some repeat a case of `tests/geometry/part_files.rs` or
//! `tests/geometry/substrates.rs`; here they are the checklist in one place.)

use std::path::Path;
use waam_slicer::geometry::{GeometryError, MeshSubstrate};
use waam_slicer::io::cell_file::parse_cell_file;
use waam_slicer::io::part_file::{parse_part, read_part_file, PartFileError};
use waam_slicer::optimise::{layer_points, optimise, LayerStatus, OptimiseOptions};
use waam_slicer::path::slice;
use waam_slicer::robot::RobotError;
use waam_slicer::toolaxis::local_frames;

/// A valid cylinder part; each test breaks one thing in it.
fn good() -> String {
    crate::common::cylinder_part_text("hostile", 10.0, 20.0, 2.0)
}

/// Parses `text` as `hostile.toml`, expecting an error; returns its message.
fn refused(text: &str) -> (PartFileError, String) {
    match parse_part(text, "hostile.toml", Path::new(".")) {
        Ok(_) => panic!("accepted:\n{text}"),
        Err(e) => {
            let msg = e.to_string();
            assert!(msg.starts_with("hostile.toml"), "file not named: {msg}");
            (e, msg)
        }
    }
}

fn assert_mentions(msg: &str, needles: &[&str]) {
    for n in needles {
        assert!(msg.contains(n), "`{n}` missing in: {msg}");
    }
}

/// Binary STL of a 20 mm square plate at z = 0 (two facets).
fn plate_stl() -> Vec<u8> {
    let mut b = vec![b' '; 80];
    b.extend_from_slice(&2u32.to_le_bytes());
    let corners = [
        [
            [-10.0f32, -10.0, 0.0],
            [10.0, -10.0, 0.0],
            [10.0, 10.0, 0.0],
        ],
        [[-10.0, -10.0, 0.0], [10.0, 10.0, 0.0], [-10.0, 10.0, 0.0]],
    ];
    for tri in corners {
        for c in [0.0f32, 0.0, 1.0] {
            b.extend_from_slice(&c.to_le_bytes());
        }
        for v in tri {
            for c in v {
                b.extend_from_slice(&c.to_le_bytes());
            }
        }
        b.extend_from_slice(&[0, 0]);
    }
    b
}

/// A part on an STL substrate `bytes`, written next to it in a temporary folder;
/// returns the error of reading it.
fn read_with_stl(bytes: &[u8]) -> String {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("base.stl"), bytes).unwrap();
    let text = good().replace(
        "kind = \"plane\"\npoint = [0, 0, 0]\nnormal = [0, 0, 1]",
        "kind = \"mesh\"\nfile = \"base.stl\"",
    );
    let part = dir.path().join("hostile.toml");
    std::fs::write(&part, text).unwrap();
    match read_part_file(&part) {
        Ok(_) => panic!("accepted an STL of {} bytes", bytes.len()),
        Err(e) => e.to_string(),
    }
}

#[test]
fn truncated_toml_names_the_file_and_the_line() {
    let text = good();
    // Cut inside `[substrate]`'s table header: a syntax error with its line.
    let cut = text.find("[substrate]").unwrap() + 5;
    let (e, msg) = refused(&text[..cut]);
    assert!(matches!(e, PartFileError::Syntax { .. }), "{e:?}");
    assert_mentions(&msg, &["line"]);
    // Cut after a whole table: the first missing section is named.
    let cut = text.find("[substrate]").unwrap();
    let (_, msg) = refused(&text[..cut]);
    assert_mentions(&msg, &["missing field `substrate`"]);
}

#[test]
fn wrong_types_name_the_field() {
    let (_, msg) = refused(&good().replace("t_max = 20", "t_max = [1]"));
    assert_mentions(&msg, &["t_max"]);
    let (_, msg) = refused(&good().replace("delta_mm = 2", "delta_mm = \"two\""));
    assert_mentions(&msg, &["delta_mm", "string"]);
    // Inside a `kind`-tagged section (guide, profile, substrate) the TOML
    // reader points at the section's header, not at the key: the section and
    // the problem are named.
    let (_, msg) = refused(&good().replace("origin = [0, 0, 0]", "origin = [0, 0]"));
    assert_mentions(
        &msg,
        &["line 3", "[guide]", "expected an array of length 3"],
    );
    let (_, msg) = refused(&good().replace("name = \"hostile\"", "name = 7"));
    assert_mentions(&msg, &["name"]);
}

#[test]
fn unicode_garbage_is_a_syntax_error_or_a_utf8_error() {
    let (e, _) = refused("名前 = ☃\u{0}\u{fffd}\u{202e}[[[");
    assert!(matches!(e, PartFileError::Syntax { .. }), "{e:?}");
    // Valid UTF-8 garbage inside a string field reaches the expression parser.
    let (_, msg) = refused(&good().replace(
        "kind = \"constant\"\nradius = 10",
        "kind = \"expr\"\nradius = \"☃ + t\u{202e}\"",
    ));
    assert_mentions(&msg, &["profile.radius"]);
    // Bytes that are not UTF-8 at all, from disk: the byte offset is named.
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("hostile.toml");
    let mut bytes = good().into_bytes();
    bytes.splice(10..10, [0xff, 0xfe, 0xc0]);
    std::fs::write(&p, bytes).unwrap();
    let msg = read_part_file(&p).unwrap_err().to_string();
    assert_mentions(&msg, &["hostile.toml", "not valid UTF-8", "byte 10"]);
}

#[test]
fn nan_and_inf_numbers_name_the_field() {
    for (from, to, field) in [
        ("t_max = 20", "t_max = nan", "range.t_max"),
        ("t_min = 0", "t_min = -inf", "range.t_min"),
        ("radius = 10", "radius = inf", "profile.radius"),
        ("delta_mm = 2", "delta_mm = nan", "slicing.delta_mm"),
        (
            "origin = [0, 0, 0]",
            "origin = [0, +inf, 0]",
            "guide.origin[1]",
        ),
        (
            "normal = [0, 0, 1]",
            "normal = [0, 0, nan]",
            "substrate.normal[2]",
        ),
        (
            "delta_mm = 2",
            "delta_mm = 2\nchord_mm = inf",
            "slicing.chord_mm",
        ),
    ] {
        let (_, msg) = refused(&good().replace(from, to));
        assert_mentions(&msg, &[field]);
    }
    // An expression that overflows to infinity is caught as well.
    let (_, msg) = refused(&good().replace("t_max = 20", "t_max = \"exp(1000)\""));
    assert_mentions(&msg, &["range.t_max", "finite"]);
    // A constant that is not finite.
    let (_, msg) = refused(&good().replace("[guide]", "[constants]\nk = nan\n[guide]"));
    assert_mentions(&msg, &["constants.k", "finite"]);
}

#[test]
fn guide_curve_with_zero_derivative_names_t() {
    let (e, msg) = refused(&good().replace(
        "kind = \"line\"\norigin = [0, 0, 0]\ndirection = [0, 0, 1]",
        "kind = \"expr\"\nx = \"0\"\ny = \"0\"\nz = \"(t - 10)^3 + 10\"",
    ));
    assert!(
        matches!(
            e,
            PartFileError::Geometry {
                source: GeometryError::ZeroDerivative { .. },
                ..
            }
        ),
        "{e:?}"
    );
    assert_mentions(&msg, &["zero derivative", "t = 10.000000"]);
    // A guide that does not move at all.
    let (_, msg) = refused(&good().replace(
        "kind = \"line\"\norigin = [0, 0, 0]\ndirection = [0, 0, 1]",
        "kind = \"expr\"\nx = \"1\"\ny = \"2\"\nz = \"3\"",
    ));
    assert_mentions(&msg, &["zero derivative", "t = 0.000000"]);
    // A line without a direction.
    let (_, msg) = refused(&good().replace("direction = [0, 0, 1]", "direction = [0, 0, 0]"));
    assert_mentions(&msg, &["guide.direction", "non-zero"]);
}

#[test]
fn self_folding_tube_names_t_and_both_radii() {
    // A 30 mm bend under a 40 mm profile radius: the inner side folds.
    let text = good()
        .replace(
            "kind = \"line\"\norigin = [0, 0, 0]\ndirection = [0, 0, 1]",
            "kind = \"arc\"\ncentre = [-30, 0, 0]\nradius = 30\nradial0 = [1, 0, 0]\ntangent0 = [0, 0, 1]",
        )
        .replace("radius = 10\n", "radius = 40\n")
        .replace("t_max = 20", "t_max = 1");
    let (e, msg) = refused(&text);
    assert!(
        matches!(
            e,
            PartFileError::Geometry {
                source: GeometryError::Folds { .. },
                ..
            }
        ),
        "{e:?}"
    );
    assert_mentions(&msg, &["folds at t = 0.000000", "40.0000", "30.0000"]);
}

#[test]
fn unreachable_cell_names_the_layer_point_and_reach() {
    // The part-carried ROBOWAM cell with the torch 6 m from the robot.
    let cell_text =
        std::fs::read_to_string(crate::common::part_path("cells/robowam_part_carried.toml"))
            .unwrap()
            .replace(
                "deposition_point_mm = [1045.747, -630.155, 653.167]",
                "deposition_point_mm = [6000.0, 0.0, 653.167]",
            );
    assert!(cell_text.contains("6000.0"));
    // The reader refuses it up front (issue 22)...
    let e = parse_cell_file(&cell_text, "far.toml").unwrap_err();
    assert_mentions(
        &e.to_string(),
        &[
            "far.toml",
            "`deposition_point_mm`",
            "out of the arm's reach",
        ],
    );
    // ...and a cell built through the API, with no reach check, gets a plan
    // whose every layer names the point and the reach.
    let mut cell = parse_cell_file(
        &std::fs::read_to_string(crate::common::part_path("cells/robowam_part_carried.toml"))
            .unwrap(),
        "near.toml",
    )
    .unwrap()
    .cell
    .unwrap();
    if let waam_slicer::robot::CellLayout::PartCarried(c) = &mut cell {
        c.deposition_point_mm = waam_slicer::math::Point3::new(6000.0, 0.0, 653.167);
    }
    let part = parse_part(
        &crate::common::cylinder_part_text("far", 10.0, 6.0, 2.0),
        "far.toml",
        Path::new("."),
    )
    .unwrap();
    let mut so = part.slice_options();
    so.discretisation = waam_slicer::path::Discretisation::Points(24);
    let path = slice(&part.tube, &part.substrate, &so).unwrap();
    let frames = local_frames(&path, &part.tube);
    let layers = layer_points(&path, &frames, 6.0);
    let plan = optimise(&cell, &layers, &OptimiseOptions::default()).unwrap();
    assert!(!plan.layers.is_empty());
    for l in &plan.layers {
        match &l.status {
            LayerStatus::NoSolution {
                point,
                error: RobotError::Unreachable { max_reach_mm, .. },
            } => {
                assert!(*point < 24 && *max_reach_mm < 6000.0);
                let msg = l.status.to_string();
                assert_mentions(&msg, &["no joint solution at point", "out of reach"]);
            }
            other => panic!("layer {}: expected unreachable, got {other}", l.layer),
        }
    }
    assert_eq!(plan.infeasible_layers().count(), plan.layers.len());
}

#[test]
fn empty_stl_names_the_file_and_says_empty() {
    let msg = read_with_stl(&[]);
    assert_mentions(
        &msg,
        &[
            "hostile.toml",
            "substrate.file",
            "base.stl",
            "empty (0 bytes)",
        ],
    );
    let e = MeshSubstrate::from_stl_bytes(&[], "empty.stl").unwrap_err();
    assert_mentions(&e.to_string(), &["empty.stl", "empty"]);
}

#[test]
fn binary_stl_with_wrong_triangle_count_names_both_counts() {
    let good_stl = plate_stl();
    assert!(MeshSubstrate::from_stl_bytes(&good_stl, "plate.stl").is_ok());
    // Announces 3 triangles, holds 2.
    let mut bytes = good_stl.clone();
    bytes[80] = 3;
    let msg = read_with_stl(&bytes);
    assert_mentions(
        &msg,
        &[
            "substrate.file",
            "base.stl",
            "announces 3 triangles",
            "184 bytes",
        ],
    );
    // Announces 4 billion triangles: refused from the header, before allocating.
    let mut bytes = good_stl.clone();
    bytes[80..84].copy_from_slice(&u32::MAX.to_le_bytes());
    let e = MeshSubstrate::from_stl_bytes(&bytes, "huge.stl").unwrap_err();
    assert_mentions(
        &e.to_string(),
        &["huge.stl", "announces 4294967295 triangles"],
    );
    // One byte short of its count.
    let e =
        MeshSubstrate::from_stl_bytes(&good_stl[..good_stl.len() - 1], "short.stl").unwrap_err();
    assert_mentions(&e.to_string(), &["short.stl", "announces 2 triangles"]);
}

#[cfg(unix)]
#[test]
fn endless_device_files_are_refused_at_the_size_limit() {
    // `/dev/zero` reports a length of 0 and never ends: reading must stop at
    // the limit instead of filling the memory.
    let e = MeshSubstrate::from_stl_file(Path::new("/dev/zero")).unwrap_err();
    assert_mentions(&e.to_string(), &["/dev/zero", "more than 268435456 bytes"]);
    let e = read_part_file(Path::new("/dev/zero")).unwrap_err();
    assert_mentions(&e.to_string(), &["/dev/zero", "more than 4194304 bytes"]);
}
