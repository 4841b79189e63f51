//! The validator accepts our programs and rejects corrupted files, naming
//! the line; the program stage refuses infeasible plans.

use waam_slicer::program::fanuc::parse_ls;
use waam_slicer::program::fanuc::validate_fanuc;
use waam_slicer::program::fanuc::{
    fanuc_files, write_ls, FanucOptions, MotionTiming, Op, TpProgram,
};
use waam_slicer::program::validate::{ProblemKind, ValidationReport};
use waam_slicer::program::PositionMode;
use waam_slicer::program::{build_program, PointFeed, ProgramError};
use waam_slicer::robot::CellLayout;

use crate::fixture::{cell, hemisphere, part_carried, program, trajectory, TS_MM_S};

const CELLS: [&str; 3] = [
    "robowam_part_carried.toml",
    "robowam_part_carried_second_position.toml",
    "robowam_torch_carried.toml",
];

fn emitted(
    cell: &CellLayout,
    opts: &FanucOptions,
) -> (String, Vec<waam_slicer::program::PlannedPoint>) {
    let (prog, path) = program(cell, 0..4, 24);
    let files = fanuc_files(&prog, opts).unwrap();
    assert_eq!(files.len(), 1);
    (files[0].text.clone(), crate::fixture::planned_of(&path))
}

fn check(
    text: &str,
    cell: &CellLayout,
    opts: &FanucOptions,
    planned: &[waam_slicer::program::PlannedPoint],
) -> ValidationReport {
    let tp = parse_ls(text, "HEMI.ls").unwrap_or_else(|e| panic!("{e}"));
    validate_fanuc(&[tp], cell, opts, Some(planned))
}

fn line_of(text: &str, needle: &str, after: usize) -> usize {
    text.lines()
        .enumerate()
        .skip(after)
        .find(|(_, l)| l.contains(needle))
        .map(|(i, _)| i + 1)
        .unwrap_or_else(|| panic!("`{needle}` not found"))
}

#[test]
fn validator_accepts_our_programs_in_every_feasible_cell() {
    for file in CELLS {
        let cell = cell(file);
        for positions in [PositionMode::Joint, PositionMode::Cartesian] {
            let opts = FanucOptions {
                positions,
                ..Default::default()
            };
            let (text, planned) = emitted(&cell, &opts);
            let r = check(&text, &cell, &opts, &planned);
            assert!(r.is_ok(), "{file} {positions:?}:\n{r}");
            // 96 bead points, an approach and a retract point per bead
            assert_eq!(r.motions, 96 + 2 * 4);
            assert_eq!(r.beads, 4);
        }
    }
}

#[test]
fn a_joint_pushed_out_of_range_is_named_by_its_line() {
    let cell = part_carried();
    let opts = FanucOptions::default();
    let (text, planned) = emitted(&cell, &opts);
    let p3 = line_of(&text, "P[3]{", 0);
    let j5_line = line_of(&text, "J5=", p3);
    let mut lines: Vec<String> = text.lines().map(String::from).collect();
    let l = &lines[j5_line - 1];
    let start = l.find("J5=").unwrap();
    let end = start + l[start..].find("deg").unwrap();
    lines[j5_line - 1] = format!("{}J5=  170.0000 {}", &l[..start], &l[end..]);
    let bad = lines.join("\n") + "\n";
    let r = check(&bad, &cell, &opts, &planned);
    assert!(!r.is_ok());
    let p = r
        .problems
        .iter()
        .find(|p| p.message.contains("J5 = 170.0000°"))
        .unwrap_or_else(|| panic!("{r}"));
    assert_eq!(p.line, j5_line, "{r}");
    assert_eq!(p.kind, ProblemKind::JointLimit, "{r}");
    assert!(
        p.to_string()
            .starts_with(&format!("HEMI:{j5_line}: P[3]: J5")),
        "{p}"
    );
}

#[test]
fn a_dropped_arc_end_is_named_by_its_line() {
    let cell = part_carried();
    let opts = FanucOptions::default();
    let (text, planned) = emitted(&cell, &opts);
    // raw edit: the numbering no longer follows, the reader names the line
    let end_line = line_of(&text, "Arc End[1]", 0);
    let mut lines: Vec<&str> = text.lines().collect();
    lines.remove(end_line - 1);
    let raw = lines.join("\n") + "\n";
    let e = parse_ls(&raw, "HEMI.ls").unwrap_err();
    assert!(
        matches!(e, ProgramError::Read { line, .. } if line == end_line),
        "{e}"
    );
    // consistent edit (renumbered): the validator names the next bead's start
    let mut tp: TpProgram = parse_ls(&text, "HEMI.ls").unwrap();
    let k = tp
        .instructions
        .iter()
        .position(|i| i.op == Op::ArcEnd(1))
        .unwrap();
    tp.instructions.remove(k);
    let mut buf = Vec::new();
    write_ls(&mut buf, &tp).unwrap();
    let edited = String::from_utf8(buf).unwrap();
    let r = check(&edited, &cell, &opts, &planned);
    let second_start = {
        let first = line_of(&edited, "Arc Start[1]", 0);
        line_of(&edited, "Arc Start[1]", first)
    };
    let p = r
        .problems
        .iter()
        .find(|p| p.message.contains("missing Arc End"))
        .unwrap_or_else(|| panic!("{r}"));
    assert_eq!(p.line, second_start, "{r}");
    assert_eq!(p.kind, ProblemKind::Bead, "{r}");
    // and the last bead: dropping the final Arc End is reported at its start
    let mut tp2: TpProgram = parse_ls(&text, "HEMI.ls").unwrap();
    let k = tp2
        .instructions
        .iter()
        .rposition(|i| i.op == Op::ArcEnd(1))
        .unwrap();
    tp2.instructions.remove(k);
    let r = validate_fanuc(&[tp2.clone()], &cell, &opts, Some(&planned));
    let last_start = tp2
        .instructions
        .iter()
        .rev()
        .find(|i| i.op == Op::ArcStart(1))
        .unwrap()
        .line;
    assert!(
        r.problems
            .iter()
            .any(|p| p.line == last_start && p.message.contains("never stops")),
        "{r}"
    );
}

#[test]
fn a_truncated_file_is_named_by_its_last_line() {
    let cell = part_carried();
    let opts = FanucOptions::default();
    let (text, _) = emitted(&cell, &opts);
    let lines: Vec<&str> = text.lines().collect();
    for keep in [lines.len() / 3, lines.len() / 2, lines.len() - 1] {
        let cut = lines[..keep].join("\n") + "\n";
        let e = parse_ls(&cut, "HEMI.ls").unwrap_err();
        let msg = e.to_string();
        assert!(
            msg.starts_with(&format!("HEMI.ls:{keep}: ")) && msg.contains("without /END"),
            "{msg}"
        );
    }
    let _ = cell;
}

/// In the part-carried cell the flange is the controller's TCP: with the
/// fixture's law (J1–J5 still, J6 turning the part under the torch) it does
/// not move, so a TCP speed (`cm/min`) would let the controller turn the
/// part at its orientation speed limit. Our default writes segment times;
/// the same program with TCP speeds is refused, naming the first such move.
#[test]
fn tcp_speeds_with_a_still_tcp_are_refused() {
    let cell = part_carried();
    let mut opts = FanucOptions {
        timing: MotionTiming::TcpSpeed,
        ..Default::default()
    };
    // without remote TCP (with it, RTCP speeds are relative to the torch)
    opts.common.remote_tcp = false;
    let (text, planned) = emitted(&cell, &opts);
    let r = check(&text, &cell, &opts, &planned);
    let p = r
        .problems
        .iter()
        .find(|p| p.message.contains("TCP still"))
        .unwrap_or_else(|| panic!("{r}"));
    let first_bead_move = line_of(&text, ":L P[", line_of(&text, "Arc Start[1]", 0));
    assert_eq!(p.line, first_bead_move, "{r}");
    let mut no_rtcp = FanucOptions::default();
    no_rtcp.common.remote_tcp = false;
    let timed = emitted(&cell, &no_rtcp);
    assert!(check(&timed.0, &cell, &no_rtcp, &timed.1).is_ok());
}

#[test]
fn an_overspeed_is_named_by_its_motion_line() {
    let cell = part_carried();
    // time-based moves: the part-carried cell without remote TCP
    let mut opts = FanucOptions::default();
    opts.common.remote_tcp = false;
    let (text, planned) = emitted(&cell, &opts);
    // a linear move of the top layer's bead in 1 ms: J6 needs 15° / 1 ms
    let mut lines: Vec<String> = text.lines().map(String::from).collect();
    let first_l = line_of(
        &text,
        ":L P[",
        line_of(
            &text,
            "Arc Start[1]",
            line_of(&text, "Arc End[1]", line_of(&text, "Arc End[1]", 0)),
        ),
    );
    // the first L after Arc Start is the bead's second point: +4 is its 6th
    let target = first_l + 4;
    let l = &lines[target - 1];
    let speed = l.split_whitespace().nth(2).unwrap().to_string();
    assert!(
        speed.ends_with("msec"),
        "time-based in the part-carried cell: {l}"
    );
    lines[target - 1] = l.replace(&speed, "1msec");
    let bad = lines.join("\n") + "\n";
    let r = check(&bad, &cell, &opts, &planned);
    let p = r
        .problems
        .iter()
        .find(|p| p.message.contains("J6 needs"))
        .unwrap_or_else(|| panic!("{r}"));
    assert_eq!(p.line, target, "{r}");
}

#[test]
fn a_configuration_flip_in_a_cartesian_file_is_named() {
    let cell = part_carried();
    let opts = FanucOptions {
        positions: PositionMode::Cartesian,
        ..Default::default()
    };
    let (text, planned) = emitted(&cell, &opts);
    let p5 = line_of(&text, "P[5]{", 0);
    let cfg = line_of(&text, "CONFIG", p5);
    let bad = text
        .lines()
        .enumerate()
        .map(|(i, l)| {
            if i + 1 == cfg {
                l.replace("'F U T", "'N U T")
            } else {
                l.to_string()
            }
        })
        .collect::<Vec<_>>()
        .join("\n")
        + "\n";
    let r = check(&bad, &cell, &opts, &planned);
    assert!(
        r.problems
            .iter()
            .any(|p| p.line == cfg && p.message.contains("configuration flip")),
        "{r}"
    );
}

#[test]
fn no_program_for_an_infeasible_plan() {
    // constant R_Z = 0: J5 leaves its ±135° travel (SPEC §7)
    let cell = part_carried();
    let path = hemisphere(0..12, 24, |_| 0.0);
    let tr = trajectory(&cell, &path);
    assert!(!tr.report.is_clean());
    let e = build_program(
        "HEMI",
        &cell,
        &path,
        &tr,
        &PointFeed::constant(TS_MM_S, crate::fixture::WFS_MM_S, path.len()),
    )
    .unwrap_err();
    let msg = e.to_string();
    assert!(
        matches!(e, ProgramError::Infeasible { .. })
            && msg.contains("refusing")
            && msg.contains("layer"),
        "{msg}"
    );
    // a speed the joints cannot follow is refused too, naming the joint
    let path = hemisphere(8..9, 24, |v| -v);
    let tr = trajectory(&cell, &path);
    let e = build_program(
        "HEMI",
        &cell,
        &path,
        &tr,
        &PointFeed::constant(5000.0, crate::fixture::WFS_MM_S, path.len()),
    )
    .unwrap_err();
    assert!(e.to_string().contains("J6 needs"), "{e}");
    // and bad names
    let e = build_program(
        "9LIVES",
        &cell,
        &path,
        &tr,
        &PointFeed::constant(6.0, crate::fixture::WFS_MM_S, path.len()),
    )
    .unwrap_err();
    assert!(e.to_string().contains("`name`"), "{e}");
}

/// A Cartesian position whose J6 sits on a turn-number edge (180°) is
/// written in joint representation: from the rounded `W P R` the
/// controller could land on either side, a full turn apart. The rest stay
/// Cartesian, and the mixed file validates.
#[test]
fn a_cartesian_position_on_a_turn_edge_is_written_in_joints() {
    use std::f64::consts::{PI, TAU};
    let cell = part_carried();
    let opts = FanucOptions {
        positions: PositionMode::Cartesian,
        ..Default::default()
    };
    // the fixture's law R_Z = c - v with c turning J6 of the first layer's
    // fourth point onto the nearest odd multiple of 180° (J6 follows R_Z
    // one for one, in one sense or the other)
    let plan = |c: f64| {
        let path = hemisphere(0..4, 24, move |v| c - v);
        let tr = trajectory(&cell, &path);
        let prog = build_program(
            "HEMI",
            &cell,
            &path,
            &tr,
            &PointFeed::constant(TS_MM_S, crate::fixture::WFS_MM_S, path.len()),
        )
        .unwrap_or_else(|e| panic!("{e}"));
        (prog, path)
    };
    let j6_at = |prog: &waam_slicer::program::Program| {
        let p = prog
            .points
            .iter()
            .find(|p| p.layer == 0 && p.point == 3 && p.arc.is_bead())
            .unwrap();
        p.joints
    };
    let j6 = j6_at(&plan(0.0).0)[5];
    let edge = PI * (2.0 * ((j6 - PI) / TAU).round() + 1.0) + 1e-7;
    // secant iterations on c: J6 - edge = 0
    let f = |c: f64| j6_at(&plan(c).0)[5] - edge;
    let (mut c0, mut c1) = (0.0, 0.01);
    let (mut f0, mut f1) = (f(c0), f(c1));
    for _ in 0..20 {
        if f1.abs() < 1e-9 {
            break;
        }
        let c2 = c1 - f1 * (c1 - c0) / (f1 - f0);
        (c0, f0) = (c1, f1);
        c1 = c2;
        f1 = f(c1);
    }
    assert!(f1.abs() < 1e-9, "J6 off its edge by {f1} rad");
    let (prog, path) = plan(c1);
    assert!(waam_slicer::program::fanuc::near_turn_edge(&j6_at(&prog)));
    let text = fanuc_files(&prog, &opts).unwrap()[0].text.clone();
    let tp = parse_ls(&text, "HEMI.ls").unwrap();
    let joint_records: Vec<usize> = tp
        .positions
        .iter()
        .filter(|p| matches!(p.arm, waam_slicer::program::fanuc::ArmPosition::Joint(_)))
        .map(|p| p.index)
        .collect();
    let k = prog
        .points
        .iter()
        .position(|p| p.layer == 0 && p.point == 3 && p.arc.is_bead())
        .unwrap();
    assert_eq!(joint_records, vec![k + 1], "{text}");
    let planned = crate::fixture::planned_of(&path);
    let r = validate_fanuc(&[tp], &cell, &opts, Some(&planned));
    assert!(r.is_ok(), "{r}");
}

/// Two consecutive points at the same place while the joints turn (here a
/// repeated point with another `R_Z`): no travel speed times such a
/// segment, and an emitter would have to write an infinite speed or a 1 ms
/// move. `build_program` refuses it, naming the layer and point.
#[test]
fn a_zero_length_segment_that_turns_the_joints_is_refused() {
    let cell = part_carried();
    let mut path = hemisphere(0..2, 24, |v| -v);
    path[5].position_mm = path[4].position_mm;
    path[5].tool_axis = path[4].tool_axis;
    path[5].build_direction = path[4].build_direction;
    let tr = trajectory(&cell, &path);
    match build_program(
        "HEMI",
        &cell,
        &path,
        &tr,
        &PointFeed::constant(TS_MM_S, crate::fixture::WFS_MM_S, path.len()),
    ) {
        Err(ProgramError::Infeasible { first, .. }) => {
            assert!(first.contains("layer 0, point 5"), "{first}");
            assert!(first.contains("zero-length"), "{first}");
        }
        other => panic!("{other:?}"),
    }
}

/// A hand-built program with a NaN joint or a non-finite speed gets no
/// file: every emitter refuses it, naming the point and the field.
#[test]
fn emitters_refuse_non_finite_values() {
    let cell = part_carried();
    let (mut prog, _) = program(&cell, 0..2, 24);
    prog.points[7].joints[2] = f64::NAN;
    match fanuc_files(&prog, &FanucOptions::default()) {
        Err(ProgramError::Mismatch { index, reason }) => {
            assert_eq!(index, 7);
            assert!(reason.contains("`joints`"), "{reason}");
        }
        other => panic!("{other:?}"),
    }
    let (mut prog, _) = program(&cell, 0..2, 24);
    prog.points[3].speed_mm_s = f64::INFINITY;
    let e = fanuc_files(&prog, &FanucOptions::default()).unwrap_err();
    assert!(e.to_string().contains("speed_mm_s"), "{e}");
}

/// A travel speed below the unit's step (0.1 mm/s < 1 cm/min) is written
/// as the segment's time, not raised to `1cm/min` (never faster than
/// planned).
#[test]
fn a_speed_below_the_units_step_is_written_as_a_time() {
    let cell = cell("robowam_torch_carried.toml");
    let path = hemisphere(0..1, 24, |_| 0.0);
    let tr = trajectory(&cell, &path);
    let prog = build_program(
        "HEMI",
        &cell,
        &path,
        &tr,
        &PointFeed::constant(0.1, crate::fixture::WFS_MM_S, path.len()),
    )
    .unwrap_or_else(|e| panic!("{e}"));
    let opts = FanucOptions {
        timing: MotionTiming::TcpSpeed,
        ..Default::default()
    };
    let text = fanuc_files(&prog, &opts).unwrap()[0].text.clone();
    let bead: Vec<&str> = text
        .lines()
        .skip_while(|l| !l.contains("Arc Start"))
        .take_while(|l| !l.contains("Arc End"))
        .filter(|l| l.contains(":L P["))
        .collect();
    assert!(!bead.is_empty(), "{text}");
    for l in bead {
        assert!(l.contains("msec"), "{l}");
    }
}
