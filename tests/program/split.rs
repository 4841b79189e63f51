//! Splitting at N points: sub-programs of whole beads (at most N points
//! each, filled greedily, so ceil(points / N) of them only when N is a
//! multiple of the bead size), called in order by a main program, whose
//! concatenated motions are the unsplit program's; a bead longer than N is
//! refused.

use waam_slicer::program::fanuc::parse_ls;
use waam_slicer::program::fanuc::validate_fanuc;
use waam_slicer::program::fanuc::{fanuc_files, ArmPosition, FanucOptions, Op, TpProgram};
use waam_slicer::program::MoveKind;

use crate::fixture::{part_carried, program};

/// Motions and process instructions in execution order, positions resolved.
fn flatten(files: &[TpProgram]) -> Vec<String> {
    let mut out = Vec::new();
    fn walk(tp: &TpProgram, all: &[TpProgram], out: &mut Vec<String>) {
        for ins in &tp.instructions {
            match &ins.op {
                Op::Call(n) => walk(all.iter().find(|p| &p.name == n).unwrap(), all, out),
                Op::UFrame(_) | Op::UTool(_) | Op::Remark(_) => {}
                Op::Move {
                    kind,
                    position,
                    speed,
                    term,
                    ..
                } => {
                    let p = tp.positions.iter().find(|p| p.index == *position).unwrap();
                    let arm = match &p.arm {
                        ArmPosition::Joint(j) => format!("{j:?}"),
                        ArmPosition::Cartesian { xyzwpr, config } => format!("{xyzwpr:?} {config}"),
                    };
                    out.push(format!("{kind:?} {speed} {term} {arm} {:?}", p.group2));
                }
                op => out.push(op.to_string()),
            }
        }
    }
    walk(&files[0], files, &mut out);
    out
}

#[test]
fn split_at_n_points_concatenates_to_the_unsplit_program() {
    let cell = part_carried();
    let (prog, path) = program(&cell, 0..3, 10);
    let planned: Vec<_> = path.iter().map(|p| p.position_mm).collect();
    let read = |opts: &FanucOptions| -> Vec<TpProgram> {
        fanuc_files(&prog, opts)
            .unwrap()
            .iter()
            .map(|f| parse_ls(&f.text, &f.name).unwrap_or_else(|e| panic!("{e}")))
            .collect()
    };
    let whole = read(&FanucOptions::default());
    assert_eq!(whole.len(), 1);
    // 30 bead points and an approach and a retract point per bead: three
    // beads of 12 points
    assert_eq!(prog.points.len(), 36);
    // Sub-programs hold whole beads, filled greedily: ceil(points / N) only
    // when N is a multiple of the bead size; a bead is never cut
    for (n, subs) in [
        (12usize, 3usize),
        (13, 3),
        (23, 3),
        (24, 2),
        (35, 2),
        (36, 1),
        (37, 1),
    ] {
        let opts = FanucOptions {
            point_limit: n,
            ..Default::default()
        };
        let parts = read(&opts);
        if subs == 1 {
            assert_eq!(parts.len(), 1);
        } else {
            assert_eq!(parts.len(), subs + 1, "N = {n}");
            let calls: Vec<_> = parts[0].instructions.iter().map(|i| i.op.clone()).collect();
            let want: Vec<_> = (1..=subs)
                .map(|k| Op::Call(format!("HEMI_{k:03}")))
                .collect();
            assert_eq!(calls, want);
            for (k, sub) in parts[1..].iter().enumerate() {
                assert_eq!(sub.name, format!("HEMI_{:03}", k + 1));
                assert!(sub.positions.len() <= n);
                // whole beads: as many arc starts as ends, the first motion
                // a joint move to an approach point
                let count =
                    |f: fn(&Op) -> bool| sub.instructions.iter().filter(|i| f(&i.op)).count();
                let starts = count(|o| matches!(o, Op::ArcStart(_)));
                assert!(
                    starts >= 1 && starts == count(|o| matches!(o, Op::ArcEnd(_))),
                    "N = {n}"
                );
                let first_move = sub
                    .instructions
                    .iter()
                    .find_map(|i| match &i.op {
                        Op::Move { kind, .. } => Some(*kind),
                        _ => None,
                    })
                    .unwrap();
                assert_eq!(first_move, MoveKind::Joint, "N = {n}");
            }
        }
        assert_eq!(flatten(&parts), flatten(&whole), "N = {n}");
        // `/ATTR COMMENT` takes at most 16 characters
        for tp in &parts {
            assert!(tp.comment.chars().count() <= 16, "{:?}", tp.comment);
        }
        let report = validate_fanuc(&parts, &cell, &opts, Some(&planned));
        assert!(report.is_ok(), "N = {n}: {report}");
        assert_eq!(report.beads, 3);
    }
}

/// A bead longer than the limit is refused, naming `point_limit` and the
/// layer, rather than split with the arc on across two programs.
#[test]
fn a_bead_longer_than_the_limit_is_refused() {
    let (prog, _) = program(&part_carried(), 0..3, 10);
    let opts = FanucOptions {
        point_limit: 11,
        ..Default::default()
    };
    let e = fanuc_files(&prog, &opts).unwrap_err().to_string();
    assert!(
        e.contains("`point_limit`") && e.contains("layer 0 has 12 points"),
        "{e}"
    );
}
