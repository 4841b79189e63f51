//! Splitting at N points: ceil(points / N) sub-programs, called in order by
//! a main program, whose concatenated motions are the unsplit program's.

use waam_slicer::program::fanuc::{fanuc_files, ArmPosition, FanucOptions, Op, TpProgram};
use waam_slicer::program::readback::parse_ls;
use waam_slicer::program::validate::validate_fanuc;

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
    for n in [1usize, 7, 10, 35, 36, 37] {
        let opts = FanucOptions {
            point_limit: n,
            ..Default::default()
        };
        let parts = read(&opts);
        // 30 bead points and an approach and a retract point per bead
        assert_eq!(prog.points.len(), 36);
        let subs = 36usize.div_ceil(n);
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
