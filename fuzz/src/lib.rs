//! What each fuzz target checks, as plain functions so a crashing input can be
//! replayed from a test or a debugger. Every function must return normally for
//! any input: the library may refuse the input (an `Err`), but must not panic,
//! hang, or let a NaN or infinity reach an output. Each accepted input is also
//! pushed a few steps down the pipeline (tube, first layer, three layers of
//! twelve points) so that semantic panics are found too, not only parser ones.

use std::collections::BTreeMap;
use std::path::Path;
use std::sync::Arc;
use waam_slicer::geometry::guide::{ExprCurve, Expression, GuideCurve, Line};
use waam_slicer::geometry::{
    FrameMethod, MeshSubstrate, ProfileLaw, ProfilePiece, Substrate, Tube, TubeRange,
};
use waam_slicer::io::part_file::parse_part;
use waam_slicer::math::{Point3, UnitVector3, Vector3};
use waam_slicer::path::{self, Discretisation, SliceOptions, Strategy};

/// Folder the part-file target resolves relative STL paths against (the STL
/// seeds: `file = "plate-binary.stl"` names a real mesh).
pub fn stl_seed_dir() -> &'static Path {
    Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/seeds/stl"))
}

fn finite(p: &Point3) -> bool {
    p.coords.iter().all(|c| c.is_finite())
}

/// Slices at most three layers of twelve points and checks every number of
/// the result is finite.
fn slice_a_little(tube: &Tube, substrate: &Substrate, mut opts: SliceOptions) {
    opts.max_layers = Some(3);
    opts.discretisation = Discretisation::Points(12);
    if let Ok(path) = path::slice(tube, substrate, &opts) {
        for layer in &path.layers {
            for p in &layer.points {
                assert!(
                    p.t.is_finite() && p.v.is_finite() && finite(&p.position),
                    "non-finite path point {p:?} in slice {}",
                    layer.slice
                );
                assert!(
                    p.delta.is_none_or(f64::is_finite),
                    "non-finite local distance {p:?}"
                );
            }
        }
    }
}

/// Part-file target: text → part; if it reads, slice a little.
pub fn part_file(text: &str) {
    match parse_part(text, "fuzz.toml", stl_seed_dir()) {
        Ok(part) => slice_a_little(&part.tube, &part.substrate, part.slice_options()),
        Err(e) => assert!(
            e.to_string().starts_with("fuzz.toml"),
            "error does not name the file: {e}"
        ),
    }
}

fn expr(text: &str) -> Expression {
    Expression::parse(text, "t", &BTreeMap::new()).expect("fixed expression parses")
}

/// Expression target: `role` says where the text goes (0: the profile
/// radius `A(t)` of a cylinder; 1: `x(t)` of the guide; 2: `z(t)` of the
/// guide; 3: the second piece of a piecewise profile). The expression is
/// evaluated at a few `t`; if the tube validates, it is sliced a little.
pub fn expression(role: u8, text: &str) {
    let constants = BTreeMap::from([("R".to_string(), 30.0), ("r".to_string(), 5.0)]);
    let e = match Expression::parse(text, "t", &constants) {
        Ok(e) => e,
        Err(err) => {
            assert!(!err.to_string().is_empty());
            return;
        }
    };
    for t in [0.0, 0.5, 1.0, -1.0, 16.0, 1e6, -1e300] {
        for order in 0..=3 {
            // NaN is allowed here (undefined there); the tube must catch it.
            let _ = e.eval_derivative(order, t);
        }
    }
    let line: Arc<dyn GuideCurve> = Arc::new(Line {
        origin: Point3::origin(),
        direction: UnitVector3::new_normalize(Vector3::z()),
    });
    let (guide, profile): (Arc<dyn GuideCurve>, ProfileLaw) = match role % 4 {
        0 => (line, ProfileLaw::Expression(e)),
        1 => (
            Arc::new(ExprCurve {
                x: e,
                y: expr("0"),
                z: expr("t"),
            }),
            ProfileLaw::Constant(2.0),
        ),
        2 => (
            Arc::new(ExprCurve {
                x: expr("0"),
                y: expr("0"),
                z: e,
            }),
            ProfileLaw::Constant(2.0),
        ),
        _ => (
            line,
            ProfileLaw::Piecewise(vec![
                ProfilePiece {
                    until: 8.0,
                    radius: expr("5"),
                },
                ProfilePiece {
                    until: f64::INFINITY,
                    radius: e,
                },
            ]),
        ),
    };
    let Ok(tube) = Tube::new(
        guide,
        FrameMethod::default(),
        None,
        profile,
        TubeRange::new(0.0, 32.0),
    ) else {
        return;
    };
    let substrate = Substrate::Plane {
        point: Point3::origin(),
        normal: UnitVector3::new_normalize(Vector3::z()),
    };
    slice_a_little(
        &tube,
        &substrate,
        SliceOptions::new(Strategy::Constant, 4.0),
    );
}

/// STL target: bytes → mesh substrate; if it reads, find the first layer of
/// a cylinder of radius 5 along Z (t from -20 to 20) on it.
pub fn stl(bytes: &[u8]) {
    let mesh = match MeshSubstrate::from_stl_bytes(bytes, "fuzz.stl") {
        Ok(m) => m,
        Err(e) => {
            assert!(
                e.to_string().contains("fuzz.stl"),
                "error does not name the file: {e}"
            );
            return;
        }
    };
    let tube = Tube::new(
        Arc::new(Line {
            origin: Point3::origin(),
            direction: UnitVector3::new_normalize(Vector3::z()),
        }),
        FrameMethod::default(),
        None,
        ProfileLaw::Constant(5.0),
        TubeRange::new(-20.0, 20.0),
    )
    .expect("fixed cylinder is valid");
    let substrate = Substrate::Mesh(Box::new(mesh));
    if let Ok(layer) = substrate.first_layer(&tube, 8) {
        for p in &layer {
            assert!(
                p.t.is_finite() && finite(&p.position),
                "non-finite first-layer point {p:?}"
            );
        }
    }
}

// ---------------------------------------------------------------------------
// Cell files and the program readers behind `waam check`.

use std::sync::OnceLock;
use waam_slicer::io::cell_file::parse_cell_file;
use waam_slicer::program::{abb::parse_mod, fanuc::parse_ls, kuka::parse_krl};
use waam_slicer::program::abb::validate_abb;
use waam_slicer::program::fanuc::validate_fanuc;
use waam_slicer::program::kuka::validate_kuka;
use waam_slicer::robot::{CellLayout, CellPoint};

/// Cell-file target: text → `parse_cell_file`; errors must name the file.
/// An accepted cell is asked for the joints of a few points near the part
/// origin (tool axis vertical and tilted, several `R_Z`): each answer is a
/// typed error or finite joints and a finite flange pose.
pub fn cell_file(text: &str) {
    let cell = match parse_cell_file(text, "fuzz.toml") {
        Ok(f) => {
            for q in f.robot.limits {
                assert!(!q.lower_rad.is_nan() && !q.upper_rad.is_nan());
            }
            match f.cell {
                Some(c) => c,
                None => return,
            }
        }
        Err(e) => {
            assert!(
                e.to_string().starts_with("fuzz.toml"),
                "error does not name the file: {e}"
            );
            return;
        }
    };
    let _ = format!("{cell:?}");
    let axes = [
        Vector3::z(),
        Vector3::new(0.3, -0.2, 1.0),
        Vector3::new(1.0, 0.0, 0.2),
    ];
    let mut near = None;
    for (i, a) in axes.iter().enumerate() {
        let p = CellPoint {
            position_mm: Point3::new(10.0 * i as f64, -5.0, 2.0),
            tool_axis: UnitVector3::new_normalize(*a),
            build_direction: None,
            positioner: None,
            travel_speed_mm_s: 6.0,
        };
        for r_z in [0.0, 1.0, -2.5] {
            if let Ok((q, pose)) = cell.joints(&p, r_z, near.as_ref(), 0.0) {
                assert!(
                    q.iter().all(|v| v.is_finite()),
                    "non-finite joints {q:?} at point {i}, R_Z {r_z}"
                );
                let t = pose.base_from_flange.translation.vector;
                assert!(t.iter().all(|v| v.is_finite()), "non-finite flange {t:?}");
                if let Ok(d) = cell.dq_drz(&pose, &q) {
                    assert!(d.iter().all(|v| v.is_finite()), "non-finite dq/dR_Z");
                }
                near = Some(q);
            }
        }
    }
}

/// The sample cells programs are checked against: FANUC (ROBOWAM part and
/// torch carried), KUKA KR 16-2 and ABB IRB 2600 (part and torch carried).
fn sample_cells() -> &'static [CellLayout; 6] {
    static CELLS: OnceLock<[CellLayout; 6]> = OnceLock::new();
    CELLS.get_or_init(|| {
        let read = |text: &str, name: &str| {
            parse_cell_file(text, name)
                .expect("sample cell reads")
                .cell
                .expect("sample file is a cell")
        };
        macro_rules! cell {
            ($f:literal) => {
                read(include_str!(concat!("../../parts/cells/", $f)), $f)
            };
        }
        [
            cell!("robowam_part_carried.toml"),
            cell!("robowam_torch_carried.toml"),
            cell!("kuka_kr16_2_part_carried.toml"),
            cell!("kuka_kr16_2_torch_carried.toml"),
            cell!("abb_irb2600_part_carried.toml"),
            cell!("abb_irb2600_torch_carried.toml"),
        ]
    })
}

/// Every problem of a report has a line and a message.
fn check_report(report: &waam_slicer::program::validate::ValidationReport) {
    let _ = report.to_string();
    for p in &report.problems {
        assert!(p.line >= 1, "problem without a line: {p}");
        assert!(!p.message.is_empty(), "problem without a message: {p}");
    }
}

/// FANUC target: first byte picks the cell (part or torch carried), the rest
/// is one `.ls` file (its `CALL`s are not followed). Errors name the file; a
/// program that reads is validated against the cell.
pub fn fanuc_ls(selector: u8, text: &str) {
    match parse_ls(text, "FUZZ.LS") {
        Ok(tp) => {
            let cell = &sample_cells()[usize::from(selector % 2)];
            let report = validate_fanuc(std::slice::from_ref(&tp), cell, &Default::default(), None);
            check_report(&report);
        }
        Err(e) => assert!(
            e.to_string().starts_with("FUZZ.LS"),
            "error does not name the file: {e}"
        ),
    }
}

/// KUKA target: the bytes up to the first NUL are the `.src`, the rest the
/// `.dat`; the first byte picks the cell. Errors name one of the two files.
pub fn kuka_krl(selector: u8, src: &str, dat: &str) {
    match parse_krl(src, "fuzz.src", dat, "fuzz.dat") {
        Ok(program) => {
            let cell = &sample_cells()[2 + usize::from(selector % 2)];
            let report = validate_kuka(&program, cell, &Default::default(), None);
            check_report(&report);
        }
        Err(e) => {
            let s = e.to_string();
            assert!(
                s.starts_with("fuzz.src") || s.starts_with("fuzz.dat"),
                "error does not name the file: {s}"
            );
        }
    }
}

/// ABB target: first byte picks the cell, the rest is one `.mod` module.
pub fn abb_mod(selector: u8, text: &str) {
    match parse_mod(text, "fuzz.mod") {
        Ok(module) => {
            let cell = &sample_cells()[4 + usize::from(selector % 2)];
            let report = validate_abb(&module, cell, &Default::default(), None);
            check_report(&report);
        }
        Err(e) => assert!(
            e.to_string().starts_with("fuzz.mod"),
            "error does not name the file: {e}"
        ),
    }
}

// ---------------------------------------------------------------------------
// The mesh fit (`waam fit`) and the replan's scan reader.

use waam_slicer::fit::{fit_tube, FitOptions, TubeMesh, Units};
use waam_slicer::Measured;

/// Fit target: first byte: the mesh's unit (mm, cm, in, m); rest: STL
/// bytes → `TubeMesh::from_stl_bytes` → `fit_tube` (a bounded fit: at most
/// 4 refits). Errors must name the file; an accepted fit has finite guide
/// points, radii, residuals and per-vertex distances, one per vertex read.
pub fn fit_stl(units: u8, bytes: &[u8]) {
    let mesh = match TubeMesh::from_stl_bytes(bytes, "fuzz.stl") {
        Ok(m) => m,
        Err(e) => {
            assert!(e.to_string().contains("fuzz.stl"), "error does not name the file: {e}");
            return;
        }
    };
    let opts = FitOptions {
        units: Units::ALL[units as usize % Units::ALL.len()],
        max_iterations: 4,
        check_surface: false,
        ..FitOptions::default()
    };
    match fit_tube(&mesh, &opts) {
        Ok(fit) => {
            assert!(fit.guide_points.iter().all(finite), "non-finite guide point");
            assert!(fit.radius_mm.iter().all(|r| r.is_finite() && *r > 0.0));
            assert!(fit.report.rms_mm.is_finite() && fit.report.max_mm.is_finite());
            assert_eq!(fit.vertex_distance_mm.len(), mesh.vertices.len());
            assert!(fit.vertex_distance_mm.iter().flatten().all(|d| d.is_finite()));
        }
        Err(e) => assert!(e.to_string().contains("fuzz.stl"), "error does not name the file: {e}"),
    }
}

/// Scan target: text → `Measured::from_csv_str`; errors must name the
/// origin; accepted points and height errors are finite and not empty.
pub fn scan(text: &str) {
    match Measured::from_csv_str(text, "fuzz-scan.csv") {
        Ok(Measured::Points(p)) => assert!(!p.is_empty() && p.iter().all(finite)),
        Ok(Measured::HeightErrors(h)) => {
            assert!(!h.is_empty() && h.iter().all(|e| e.dh_mm.is_finite()))
        }
        Err(e) => assert!(e.to_string().contains("fuzz-scan.csv"), "error does not name the scan: {e}"),
    }
}
