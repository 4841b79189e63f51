//! Circular moves in thinned beads (issue 32, item 2): where a stretch of a
//! bead is a circle arc within `path_tolerance_mm` and
//! `orientation_tolerance_deg`, it is written as one circular move (two
//! positions: via and end) and read back and checked by sampling the
//! circle as the controller interpolates it.
//!
//! Vendor syntax each test relies on:
//! * FANUC TP (`.ls`): "Circular motion" — `C P[v]` with the via point, the
//!   end point, speed and termination on the continuation line `:  P[n]
//!   100mm/sec CNT100 ;` (as a controller exports it, e.g. `769:C P[698]` /
//!   `:  P[699] WELD_SPEED FINE`).
//! * KUKA KRL: `CIRC aux, end` with Cartesian auxiliary and end points
//!   (KSS 8 system software manual, "CIRC"); orientation `$ORI_TYPE = #VAR`,
//!   `$CIRC_TYPE = #BASE`: the orientation changes from start to end, the
//!   auxiliary point's orientation is ignored.
//! * ABB RAPID: `MoveC CirPoint, ToPoint, speed, zone, tool \WObj` and
//!   `ArcC` with the same two targets (RAPID reference, MoveC: "the
//!   orientation of the circle point is not critical").

use waam_slicer::program::registry::{check_files, emit};
use waam_slicer::program::ProgramSettings;

use crate::fixture::{cell, hemisphere, law, trajectory, TS_MM_S};

/// The hemisphere's `layers` at 240 points a layer in `c`, thinned at the
/// default tolerances (circular moves on).
fn thinned_hemisphere(
    c: &waam_slicer::robot::CellLayout,
    layers: std::ops::Range<usize>,
) -> waam_slicer::program::Program {
    let path = hemisphere(layers, 240, law(c));
    let tr = trajectory(c, &path);
    waam_slicer::program::build_program(
        "HEMI",
        c,
        &path,
        &tr,
        &waam_slicer::program::PointFeed::constant(TS_MM_S, crate::fixture::WFS_MM_S, path.len()),
    )
    .unwrap_or_else(|e| panic!("{}: {e}", c.name()))
}

/// Every sample cell: the hemisphere's layers (near circles) are written
/// with circular moves, and the files read back clean with every circular
/// move sampled on its circle against the dense plan.
#[test]
fn circular_beads_round_trip_in_every_vendor() {
    for file in crate::fixture::FANUC_CELLS
        .iter()
        .chain(&crate::fixture::KUKA_CELLS)
        .chain(&crate::fixture::ABB_CELLS)
    {
        let c = cell(file);
        let prog = thinned_hemisphere(&c, 0..3);
        let vias = prog.points.iter().filter(|p| p.via).count();
        let kept = prog.bead_points().count();
        println!(
            "{file}: {} planned, {kept} positions, {vias} circular moves",
            prog.planned.len()
        );
        // the ROBOWAM part-carried cells move the flange in the robot
        // base frame (FANUC without remote TCP): the part turns on J6 under
        // the torch and the flange's path is no circle
        if !file.starts_with("robowam_part_carried") {
            assert!(vias > 0, "{file}: no circular move");
        }
        let settings = ProgramSettings::default();
        let files = emit(&prog, &settings).unwrap();
        let r = check_files(c.robot().vendor, &files, &c, &settings, Some(&prog.planned)).unwrap();
        assert!(r.is_ok(), "{file}:\n{r}");
    }
}

/// `[program] circular_moves = false` in a cell file turns them off: the
/// same bead is then written with linear moves only, and needs more
/// positions.
#[test]
fn a_cell_file_can_turn_circular_moves_off() {
    let p = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("parts/cells/kuka_kr16_2_torch_carried.toml");
    let text = std::fs::read_to_string(&p).unwrap();
    let on = waam_slicer::io::cell_file::parse_cell_file(&text, "on").unwrap();
    assert!(on.program.common.circular_moves, "default on");
    let off_text = if text.contains("\n[program]\n") {
        text.replace("\n[program]\n", "\n[program]\ncircular_moves = false\n")
    } else {
        format!("{text}\n[program]\ncircular_moves = false\n")
    };
    let off = waam_slicer::io::cell_file::parse_cell_file(&off_text, "off").unwrap();
    assert!(!off.program.common.circular_moves);
    let c = cell("kuka_kr16_2_torch_carried.toml");
    let path = hemisphere(0..2, 240, law(&c));
    let tr = trajectory(&c, &path);
    let build = |common: &waam_slicer::program::ProgramOptions| {
        waam_slicer::program::build_program_with(
            "HEMI",
            &c,
            &path,
            &tr,
            &waam_slicer::program::PointFeed::constant(
                TS_MM_S,
                crate::fixture::WFS_MM_S,
                path.len(),
            ),
            common,
        )
        .unwrap()
    };
    let with = build(&on.program.common);
    let without = build(&off.program.common);
    assert!(with.points.iter().any(|p| p.via));
    assert!(!without.points.iter().any(|p| p.via));
    assert!(
        with.bead_points().count() < without.bead_points().count(),
        "{} positions with circles, {} without",
        with.bead_points().count(),
        without.bead_points().count()
    );
}

/// Closed form: points on an exact circle (radius 40 mm, 1° apart, tool
/// axis constant) compress to at most two circular moves per 180° of arc,
/// and every programmed circle, sampled with the controller model
/// (`interpolate`), stays within the path tolerance of the true circle:
/// `| |p - centre| - r |` and the height off its plane.
#[test]
fn points_on_a_circle_compress_to_few_circular_moves() {
    use waam_slicer::math::{Point3, UnitQuaternion, Vector3};
    use waam_slicer::program::compress::{
        compress, interpolate, tool_z_map, CompressOptions, ControllerPose, Move,
    };
    let (r, centre) = (40.0, Point3::new(100.0, -20.0, 5.0));
    for sweep_deg in [90usize, 180, 300, 360] {
        let poses: Vec<ControllerPose> = (0..=sweep_deg)
            .map(|k| {
                let a = (k as f64).to_radians();
                let p = centre + Vector3::new(r * a.cos(), r * a.sin(), 0.0);
                ControllerPose::new(p, UnitQuaternion::identity(), Vec::new())
            })
            .collect();
        let opts = CompressOptions::default();
        let c = compress(&poses, &[], &tool_z_map, &opts).unwrap();
        let halves = sweep_deg.div_ceil(180);
        assert!(
            c.moves.len() <= 2 * halves && c.moves.iter().all(|m| m.via().is_some()),
            "{sweep_deg}°: {:?}",
            c.moves
        );
        assert!(c.max_path_error_mm < opts.path_tolerance_mm, "{c:?}");
        let mut from = 0;
        for m in &c.moves {
            let Move::Circular { via, to } = *m else {
                unreachable!()
            };
            for k in 0..=100 {
                let x = interpolate(
                    &poses[from],
                    Some(&poses[via]),
                    &poses[to],
                    k as f64 / 100.0,
                )
                .p;
                let radial = ((x - centre).xy().norm() - r).abs();
                let height = (x.z - centre.z).abs();
                assert!(
                    radial.max(height) < opts.path_tolerance_mm,
                    "{radial} {height}"
                );
            }
            from = to;
        }
    }
}

/// The checker samples the circle the controller would run: a KUKA
/// program whose first `CIRC` auxiliary point is moved by 1 mm (its `X` in
/// the `.dat`) is refused, with a deviation between the moves on the
/// `CIRC` line (KRL: the circle runs through the auxiliary point, so moving
/// it moves the whole arc).
#[test]
fn a_via_moved_by_1_mm_is_refused() {
    let c = cell("kuka_kr16_2_torch_carried.toml");
    let prog = thinned_hemisphere(&c, 0..1);
    let settings = ProgramSettings::default();
    let mut files = emit(&prog, &settings).unwrap();
    let ok = check_files(c.robot().vendor, &files, &c, &settings, Some(&prog.planned)).unwrap();
    assert!(ok.is_ok(), "{ok}");
    let src = files.iter().find(|f| f.name.ends_with(".src")).unwrap();
    let (circ_line, circ) = src
        .text
        .lines()
        .enumerate()
        .find(|(_, l)| l.trim_start().starts_with("CIRC "))
        .expect("a CIRC");
    let aux = circ.trim()["CIRC ".len()..]
        .split(',')
        .next()
        .unwrap()
        .trim()
        .to_string();
    let dat = files.iter_mut().find(|f| f.name.ends_with(".dat")).unwrap();
    let decl = format!("DECL E6POS {aux}={{X ");
    let text: Vec<String> = dat
        .text
        .lines()
        .map(|l| match l.find(&decl) {
            Some(at) => {
                let start = at + decl.len();
                let end = start + l[start..].find(',').unwrap();
                let x: f64 = l[start..end].parse().unwrap();
                format!("{}{:.4}{}", &l[..start], x + 1.0, &l[end..])
            }
            None => l.to_string(),
        })
        .collect();
    assert_ne!(text.join("\n"), dat.text.trim_end(), "{aux} not found");
    dat.text = text.join("\n") + "\n";
    let r = check_files(c.robot().vendor, &files, &c, &settings, Some(&prog.planned)).unwrap();
    let between = r.problems.iter().find(|p| {
        p.kind == waam_slicer::program::validate::ProblemKind::Deviation
            && p.line == circ_line + 1
            && p.message.contains("between the moves")
    });
    assert!(between.is_some(), "line {}: {r}", circ_line + 1);
}

/// A FANUC `C P[v]` line whose end line `:  P[n] …` is missing is refused
/// by the reader, naming the file and the `C` line (TP: a circular motion
/// is one program line written on two text lines).
#[test]
fn a_fanuc_circular_move_without_its_end_line_is_refused() {
    let c = cell("robowam_torch_carried.toml");
    let prog = thinned_hemisphere(&c, 0..1);
    let files = emit(&prog, &ProgramSettings::default()).unwrap();
    let ls = &files[0];
    let lines: Vec<&str> = ls.text.lines().collect();
    let at = lines
        .iter()
        .position(|l| l.contains(":C P["))
        .expect("a circular move");
    assert!(
        lines[at + 1].trim_start().starts_with(":  P["),
        "{}",
        lines[at + 1]
    );
    let cut: Vec<&str> = lines
        .iter()
        .enumerate()
        .filter(|(k, _)| *k != at + 1)
        .map(|(_, l)| *l)
        .collect();
    let err = waam_slicer::program::fanuc::parse_ls(&cut.join("\n"), &ls.name).unwrap_err();
    let msg = err.to_string();
    assert!(
        msg.contains(&ls.name) && msg.contains(&format!("{}", at + 1)),
        "{msg}"
    );
}

/// A KRL program with `CIRC` moves states the orientation control the
/// checker models (`$ORI_TYPE = #VAR`, `$CIRC_TYPE = #BASE`: orientation
/// from start to end relative to the base, the auxiliary point's
/// orientation ignored — KUKA system software, "Orientation control for
/// CIRC"); without it the first `CIRC` is a frame problem.
#[test]
fn krl_circ_needs_its_orientation_control_stated() {
    let c = cell("kuka_kr16_2_torch_carried.toml");
    let prog = thinned_hemisphere(&c, 0..1);
    let settings = ProgramSettings::default();
    let mut files = emit(&prog, &settings).unwrap();
    let src = files.iter_mut().find(|f| f.name.ends_with(".src")).unwrap();
    assert!(src
        .text
        .contains("\n  $ORI_TYPE = #VAR\n  $CIRC_TYPE = #BASE\n"));
    src.text = src.text.replace("  $ORI_TYPE = #VAR\n", "");
    let circ_line = src
        .text
        .lines()
        .position(|l| l.trim_start().starts_with("CIRC "))
        .unwrap()
        + 1;
    let r = check_files(c.robot().vendor, &files, &c, &settings, Some(&prog.planned)).unwrap();
    assert!(
        r.problems.iter().any(
            |p| p.kind == waam_slicer::program::validate::ProblemKind::Frame && p.line == circ_line
        ),
        "{r}"
    );
}

/// ABB circular moves reorient the tool as the checker models them (start
/// to end slerp in the work object's frame) only under `CirPathMode
/// \ObjectFrame`: RobotWare's default `\PathFrame` reorients relative to the
/// circular path (RAPID reference, MoveC: "The reorientation is performed
/// relative to the circular path"). Measured on the thinned hemisphere in
/// both ABB cells: mid-arc, the path-frame reorientation (the orientation
/// relative to the circle's tangent, radial and normal directions carried
/// from start to end by slerp) and the object-frame slerp part by up to
/// 0.49° in the part-carried cell, 0.000° in the coordinated torch-carried
/// one, whose arcs turn about the layer's axis (printed). The module writes the switch before its first circular
/// move; without it, or with `\PathFrame`, each `ArcC` is a frame problem
/// on its line.
#[test]
fn rapid_arcc_runs_under_cir_path_mode_object_frame() {
    use waam_slicer::math::{Matrix3, Rotation3, UnitQuaternion};
    use waam_slicer::program::pose::controller_pose_at;
    use waam_slicer::program::validate::ProblemKind;
    let mut overall: f64 = 0.0;
    for file in crate::fixture::ABB_CELLS {
        let c = cell(file);
        let prog = thinned_hemisphere(&c, 0..2);
        // the controller poses of each circular move, part frame (both ABB
        // cells move in the part frame: stationary tool, coordinated)
        let pose = |i: usize| {
            let p = &prog.points[i];
            controller_pose_at(&c, &p.joints, p.positioner, true)
        };
        let mut largest: f64 = 0.0;
        for i in (1..prog.points.len() - 1).filter(|&i| prog.points[i].via) {
            let (a, v, b) = (pose(i - 1), pose(i), pose(i + 1));
            // the circle through the three positions
            let (ab, av) = (b.p - a.p, v.p - a.p);
            let n = av.cross(&ab);
            let centre = a.p
                + (av.norm_squared() * ab - ab.norm_squared() * av).cross(&n)
                    / (2.0 * n.norm_squared());
            let normal = n.normalize();
            // the path frame at a point of the circle: tangent, towards the
            // centre, circle normal
            let frame = |p: &waam_slicer::math::Point3| {
                let inward = (centre - p).normalize();
                let t = inward.cross(&normal);
                UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(
                    Matrix3::from_columns(&[t, inward, normal]),
                ))
            };
            // the arc's midpoint: a turned by half the sweep about the
            // normal, a -> via -> b counterclockwise about it (arcs of at
            // most 120°, MAX_ARC_SWEEP_DEG)
            let sweep = (a.p - centre).angle(&(b.p - centre));
            let half = Rotation3::from_axis_angle(
                &waam_slicer::math::UnitVector3::new_normalize(normal),
                sweep / 2.0,
            );
            let m = centre + half * (a.p - centre);
            let rel_a = frame(&a.p).inverse() * a.q;
            let rel_b = frame(&b.p).inverse() * b.q;
            let path_frame = frame(&m) * rel_a.slerp(&rel_b, 0.5);
            let object_frame = a.q.slerp(&b.q, 0.5);
            largest = largest.max(path_frame.angle_to(&object_frame).to_degrees());
        }
        println!("{file}: path frame vs object frame mid-arc, largest {largest:.3}°");
        overall = overall.max(largest);
        let settings = ProgramSettings::default();
        let files = emit(&prog, &settings).unwrap();
        let text = &files[0].text;
        let mode = text
            .find("    CirPathMode \\ObjectFrame;\n")
            .expect("the switch");
        let first_arcc = text.find("    ArcC ").expect("a circular move");
        assert!(mode < first_arcc);
        let arcc_line = text
            .lines()
            .position(|l| l.trim_start().starts_with("ArcC "))
            .unwrap()
            + 1;
        for edited in [
            text.replace("    CirPathMode \\ObjectFrame;\n", ""),
            text.replace("CirPathMode \\ObjectFrame;", "CirPathMode \\PathFrame;"),
        ] {
            let mut bad = files.clone();
            bad[0].text = edited;
            // the line numbers move up by one without the switch
            let r =
                check_files(c.robot().vendor, &bad, &c, &settings, Some(&prog.planned)).unwrap();
            assert!(
                r.problems.iter().any(|p| p.kind == ProblemKind::Frame
                    && p.message.contains("CirPathMode")
                    && (p.line == arcc_line || p.line + 1 == arcc_line)),
                "{file}:\n{r}"
            );
        }
    }
    // the part-carried cell's arcs (0.49°, as issue 45 measured); the
    // coordinated torch-carried cell's turn about the layer's axis, where
    // both modes agree (0.000°)
    assert!(overall > 0.3, "{overall}°");
}
