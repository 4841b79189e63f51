//! The vendor-independent set-up of a program (issue 18): home moves,
//! interlayer dwell and interpass wait, payload updates from the deposited
//! mass, and arc-off transit moves checked against the deposited wall — as
//! built by `build_program_with` and as checked by the validator's common
//! checker (`check_steps`) on decoded steps.
//!
//! Independent checks: the torch pose seen from the part at a program's
//! joints is compared with the planned deposition point and tool axis
//! (forward kinematics against the path, in every sample cell); the payload
//! against the closed-form sums of the bead masses and mass-weighted
//! centres; a transit into the wall against plain geometry (the next layers
//! lie inside the torch's nozzle column).

use waam_slicer::math::{Point3, Vector3};
use waam_slicer::program::transit::{joint_move_clearance, torch_in_part, wall_of};
use waam_slicer::program::validate::{
    check_steps, DecodedStep, Motion, MotionSpeed, ProblemKind, ValidationReport,
};
use waam_slicer::program::MoveKind;
use waam_slicer::program::{build_program_with, ArcFlag, PointFeed, ProgramError, ProgramOptions};
use waam_slicer::robot::CellLayout;
use waam_slicer::toolaxis::collision::Torch;

use crate::fixture::{
    bead_positions, cell, hemisphere, law, part_carried, program, trajectory, ABB_CELLS,
    FANUC_CELLS, KUKA_CELLS, TS_MM_S,
};

#[test]
fn the_torch_seen_from_the_part_is_the_planned_point_and_axis_in_every_cell() {
    for file in FANUC_CELLS.iter().chain(&KUKA_CELLS).chain(&ABB_CELLS) {
        let cell = cell(file);
        let path = hemisphere(0..3, 12, law(&cell));
        let tr = trajectory(&cell, &path);
        let opts = ProgramOptions {
            transit_check: false,
            ..options()
        };
        let prog = build_program_with(
            "HEMI",
            &cell,
            &path,
            &tr,
            &PointFeed::constant(TS_MM_S, crate::fixture::WFS_MM_S, path.len()),
            &opts,
        )
        .unwrap_or_else(|e| panic!("{file}: {e}"));
        for p in prog.bead_points() {
            let (tip, axis) = torch_in_part(&cell, &p.joints, p.positioner).expect("a torch pose");
            assert!(
                (tip - p.position_mm).norm() < 1e-6,
                "{file}: layer {} point {}: tip {tip:?} vs planned {:?}",
                p.layer,
                p.point,
                p.position_mm
            );
            assert!(
                (axis - p.tool_axis.into_inner()).norm() < 1e-9,
                "{file}: layer {} point {}: axis {axis:?} vs planned {:?}",
                p.layer,
                p.point,
                p.tool_axis
            );
        }
    }
}

fn options() -> ProgramOptions {
    ProgramOptions::default()
}

#[test]
fn home_dwell_and_interpass_wait_are_set_before_every_bead_but_the_first() {
    let cell = part_carried();
    let path = hemisphere(0..4, 12, law(&cell));
    let tr = trajectory(&cell, &path);
    let first = tr.points[0].joints.expect("joints");
    let mut home = first.map(f64::to_degrees);
    home[1] -= 10.0; // upper arm back, away from the part
    let opts = ProgramOptions {
        home_deg: Some(home),
        dwell_s: 30.0,
        interpass_input: Some(7),
        ..options()
    };
    let prog = build_program_with(
        "HEMI",
        &cell,
        &path,
        &tr,
        &PointFeed::constant(TS_MM_S, crate::fixture::WFS_MM_S, path.len()),
        &opts,
    )
    .unwrap_or_else(|e| panic!("{e}"));
    let h = prog.home.expect("a home position");
    for (a, b) in h.joints.iter().zip(home) {
        assert!((a.to_degrees() - b).abs() < 1e-9);
    }
    assert_eq!(prog.bead_setup.len(), 4);
    assert_eq!(prog.bead_setup[0].dwell_s, 0.0);
    assert_eq!(prog.bead_setup[0].wait_input, None);
    for (k, s) in prog.bead_setup.iter().enumerate().skip(1) {
        assert_eq!(s.layer, k);
        assert_eq!(s.dwell_s, 30.0);
        assert_eq!(s.wait_input, Some(7));
        assert!(s.payload.is_none());
    }
}

#[test]
fn a_home_outside_the_travel_is_refused_naming_the_field_and_joint() {
    let cell = part_carried();
    let path = hemisphere(0..2, 12, law(&cell));
    let tr = trajectory(&cell, &path);
    let opts = ProgramOptions {
        home_deg: Some([0.0, 0.0, 0.0, 0.0, 400.0, 0.0]),
        ..options()
    };
    let e = build_program_with(
        "HEMI",
        &cell,
        &path,
        &tr,
        &PointFeed::constant(TS_MM_S, crate::fixture::WFS_MM_S, path.len()),
        &opts,
    )
    .expect_err("J5 at 400 degrees is outside every arm's travel");
    let msg = e.to_string();
    assert!(
        matches!(
            e,
            ProgramError::InvalidOptions {
                field: "home_deg",
                ..
            }
        ),
        "{msg}"
    );
    assert!(msg.contains("J5"), "{msg}");
}

#[test]
fn payloads_are_the_substrate_plus_the_beads_before_in_the_flange_frame() {
    let cell = part_carried();
    let CellLayout::PartCarried(pc) = &cell else {
        unreachable!()
    };
    let (mut prog, _) = program(&cell, 0..5, 12);
    let masses = [0.10, 0.09, 0.08, 0.07, 0.06];
    let opts = ProgramOptions {
        payload_every_layers: 2,
        payload_base_kg: 5.0,
        payload_base_cog_mm: [0.0, 0.0, 40.0],
        ..options()
    };
    prog.set_payloads(&opts, &masses).unwrap();
    // closed form: the hemisphere's layer k is a circle of radius
    // 45 cos(k·5/45) at height 45 sin(k·5/45), centred on the part's axis;
    // its 12 equally spaced points average to the centre
    let centre = |k: usize| {
        let phi = k as f64 * 5.0 / 45.0;
        pc.flange_from_part * Point3::new(0.0, 0.0, 45.0 * phi.sin())
    };
    let expect = |upto: usize| {
        let m: f64 = 5.0 + masses[..upto].iter().sum::<f64>();
        let moment = Vector3::new(0.0, 0.0, 40.0) * 5.0
            + (0..upto)
                .map(|k| centre(k).coords * masses[k])
                .sum::<Vector3>();
        (m, Point3::from(moment / m))
    };
    for (k, s) in prog.bead_setup.iter().enumerate() {
        match s.payload {
            Some(p) => {
                assert_eq!(k % 2, 0, "bead {k}: no update expected");
                let (m, cog) = expect(k);
                assert!(
                    (p.mass_kg - m).abs() < 1e-12,
                    "bead {k}: {} kg vs {m}",
                    p.mass_kg
                );
                assert!(
                    (p.cog_mm - cog).norm() < 1e-9,
                    "bead {k}: {:?} vs {cog:?}",
                    p.cog_mm
                );
            }
            None => assert_ne!(k % 2, 0, "bead {k}: update expected"),
        }
    }
    // one mass per bead, finite
    assert!(prog.set_payloads(&opts, &masses[..4]).is_err());
    assert!(prog
        .set_payloads(&opts, &[0.1, f64::NAN, 0.1, 0.1, 0.1])
        .is_err());
}

#[test]
fn a_move_into_the_wall_is_found_and_the_program_refused() {
    // home = the joints of layer 0's first point: the torch's nozzle column
    // then holds the next layers' first points (5, 10, …, 30 mm above along
    // the build direction, the nozzle starting 15 mm above the tip)
    let cell = part_carried();
    let path = hemisphere(0..7, 12, law(&cell));
    let tr = trajectory(&cell, &path);
    let q0 = tr.points[0].joints.expect("joints");
    // plain geometry: at those joints layer 4's first point is within the
    // nozzle's radius (13 mm) plus a bead of the torch axis, above its tip
    let (tip, axis) = torch_in_part(&cell, &q0, None).unwrap();
    let p4 = path.iter().find(|p| p.layer == 4).unwrap().position_mm;
    let along = (p4 - tip).dot(&axis);
    let off_axis = ((p4 - tip) - axis * along).norm();
    assert!(
        along > 15.0 && along < 60.0 && off_axis < 13.0,
        "{along} {off_axis}"
    );
    let opts = ProgramOptions {
        home_deg: Some(q0.map(f64::to_degrees)),
        ..options()
    };
    let e = build_program_with(
        "HEMI",
        &cell,
        &path,
        &tr,
        &PointFeed::constant(TS_MM_S, crate::fixture::WFS_MM_S, path.len()),
        &opts,
    )
    .expect_err("the last move ends inside the wall");
    let msg = e.to_string();
    assert!(
        msg.contains("layer 6") && msg.contains("home") && msg.contains("wall"),
        "{msg}"
    );
    // and the move itself, checked alone
    let (prog, _) = program(&cell, 0..7, 12);
    let last = prog.points.last().unwrap();
    let beads = bead_positions(&prog, 7);
    let wall = wall_of(beads.iter().map(Vec::as_slice), 2.0);
    let torch = Torch::new(&Default::default()).unwrap();
    let c = joint_move_clearance(&cell, &wall, &torch, (&last.joints, None), (&q0, None)).unwrap();
    assert!(c.min_clearance_mm < 0.0, "{c:?}");
    assert!(c.at_fraction > 0.5, "{c:?}");
}

#[test]
fn the_transits_of_the_sample_programs_clear_the_wall() {
    // every arc-off joint move of the fixture programs clears the wall by
    // more than the nozzle's set-back: none needed raising
    for file in FANUC_CELLS.iter().chain(&KUKA_CELLS).chain(&ABB_CELLS) {
        let cell = cell(file);
        let (prog, _) = program(&cell, 0..4, 12);
        for (i, w) in prog.points.windows(2).enumerate() {
            if w[0].arc == ArcFlag::Retract {
                assert_eq!(w[1].arc, ArcFlag::Approach, "{file}: point {i}");
                assert!(
                    ((w[0].position_mm - prog.points[i - 1].position_mm).norm() - 20.0).abs()
                        < 1e-6,
                    "{file}: retract at the default 20 mm"
                );
            }
        }
    }
}

fn motion(line: usize, q: [f64; 6], kind: MoveKind) -> DecodedStep {
    DecodedStep::Motion(Box::new(Motion {
        file: "T".into(),
        line,
        label: format!("P[{line}]"),
        record_file: "T".into(),
        record_line: line,
        value_lines: [line; 6],
        joints: Some(q),
        from_cartesian: false,
        wire_feed: None,
        positioner: None,
        kind,
        speed: if kind == MoveKind::Joint {
            MotionSpeed::Joint
        } else {
            MotionSpeed::Linear(TS_MM_S)
        },
    }))
}

/// The steps of a two-bead program in the part-carried cell as a reader
/// would decode them, with `before_second` between the beads.
fn two_beads(
    home: Option<[f64; 6]>,
    before_second: Vec<DecodedStep>,
) -> (Vec<DecodedStep>, CellLayout) {
    let cell = part_carried();
    let (prog, _) = program(&cell, 0..2, 12);
    let mut steps = Vec::new();
    let mut line = 1;
    let mut next = || {
        line += 1;
        line
    };
    if let Some(h) = home {
        steps.push(motion(next(), h, MoveKind::Joint));
    }
    let mut before = Some(before_second);
    for (i, p) in prog.points.iter().enumerate() {
        if p.arc == ArcFlag::Approach && p.layer == 1 {
            steps.extend(before.take().unwrap_or_default());
        }
        let kind = if waam_slicer::program::joint_move_target(&prog, i) {
            MoveKind::Joint
        } else {
            MoveKind::Linear
        };
        steps.push(motion(next(), p.joints, kind));
        match p.arc {
            ArcFlag::Start => steps.push(DecodedStep::ProcessOn {
                file: "T".into(),
                line: next(),
            }),
            ArcFlag::End => steps.push(DecodedStep::ProcessOff {
                file: "T".into(),
                line: next(),
            }),
            _ => {}
        }
    }
    if let Some(h) = home {
        steps.push(motion(next(), h, MoveKind::Joint));
    }
    (steps, cell)
}

fn kinds(r: &ValidationReport) -> Vec<ProblemKind> {
    r.problems.iter().map(|p| p.kind).collect()
}

#[test]
fn the_checker_wants_home_first_and_last_and_the_dwell_and_wait_between_beads() {
    let cell = part_carried();
    let (prog, _) = program(&cell, 0..2, 12);
    let mut home = prog.points[0].joints.map(f64::to_degrees);
    home[1] -= 10.0;
    let home_rad = home.map(f64::to_radians);
    let common = ProgramOptions {
        home_deg: Some(home),
        dwell_s: 20.0,
        interpass_input: Some(3),
        ..options()
    };
    let wait = |s: Option<f64>, i: Option<u32>| DecodedStep::Wait {
        file: "T".into(),
        line: 1000,
        seconds: s,
        input: i,
    };
    // all there: clean
    let (steps, cell) = two_beads(
        Some(home_rad),
        vec![wait(Some(20.0), None), wait(None, Some(3))],
    );
    let mut r = ValidationReport::default();
    check_steps(&steps, &cell, None, &common, &mut r);
    assert!(r.is_ok(), "{r}");
    // no home, a short dwell, no wait: three problems, each named
    let (steps, cell) = two_beads(None, vec![wait(Some(5.0), None)]);
    let mut r = ValidationReport::default();
    check_steps(&steps, &cell, None, &common, &mut r);
    assert_eq!(kinds(&r), vec![ProblemKind::Setup; 3], "{r}");
    let text = r.to_string();
    assert!(
        text.contains("first motion") && text.contains("last motion"),
        "{text}"
    );
    assert!(
        text.contains("dwell of 20 s") && text.contains("input 3"),
        "{text}"
    );
}

#[test]
fn the_checker_refuses_a_wait_or_payload_with_the_arc_on_and_a_shrinking_payload() {
    let common = ProgramOptions {
        payload_every_layers: 1,
        payload_base_kg: 2.0,
        ..options()
    };
    let payload = |m: f64| DecodedStep::Payload {
        file: "T".into(),
        line: 500,
        mass_kg: m,
        cog_mm: Point3::origin(),
    };
    let (mut steps, cell) = two_beads(None, vec![payload(1.9)]);
    // payload before bead 1 (at the start), and a wait inside bead 1
    steps.insert(0, payload(2.0));
    let on = steps
        .iter()
        .position(|s| matches!(s, DecodedStep::ProcessOn { .. }))
        .unwrap();
    steps.insert(
        on + 2,
        DecodedStep::Wait {
            file: "T".into(),
            line: 600,
            seconds: Some(1.0),
            input: None,
        },
    );
    let mut r = ValidationReport::default();
    check_steps(&steps, &cell, None, &common, &mut r);
    let text = r.to_string();
    assert_eq!(kinds(&r), vec![ProblemKind::Setup; 2], "{text}");
    assert!(text.contains("with the arc on"), "{text}");
    assert!(text.contains("less than the previous"), "{text}");
}

#[test]
fn the_checker_finds_a_joint_move_through_the_wall() {
    let cell = part_carried();
    let (prog, _) = program(&cell, 0..7, 12);
    let q0 = prog.bead_points().next().unwrap().joints;
    let mut steps: Vec<DecodedStep> = Vec::new();
    let mut line = 0;
    for (i, p) in prog.points.iter().enumerate() {
        line += 1;
        let kind = if waam_slicer::program::joint_move_target(&prog, i) {
            MoveKind::Joint
        } else {
            MoveKind::Linear
        };
        steps.push(motion(line, p.joints, kind));
        match p.arc {
            ArcFlag::Start => steps.push(DecodedStep::ProcessOn {
                file: "T".into(),
                line,
            }),
            ArcFlag::End => steps.push(DecodedStep::ProcessOff {
                file: "T".into(),
                line,
            }),
            _ => {}
        }
    }
    let mut r = ValidationReport::default();
    check_steps(&steps, &cell, None, &options(), &mut r);
    assert!(r.is_ok(), "{r}");
    steps.push(motion(9999, q0, MoveKind::Joint));
    let mut r = ValidationReport::default();
    check_steps(&steps, &cell, None, &options(), &mut r);
    assert_eq!(kinds(&r), vec![ProblemKind::Collision], "{r}");
    assert_eq!(r.problems[0].line, 9999);
}
