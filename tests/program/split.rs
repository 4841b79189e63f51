//! Cutting a FANUC build to the memory budget (`[program.fanuc]
//! max_positions`, issue 32 item 3): groups of whole beads, each a complete
//! program the cell loads in turn (`HEMI_P01`, `HEMI_P02`, …, no main
//! program calling them: FANUC sub-programs called from a main are resident
//! together, so a main would not save memory), filled greedily, so
//! `ceil(positions / N)` groups only when N is a multiple of the bead size;
//! their motions in order are the uncut program's; a bead longer than N is
//! refused with the numbers.

use waam_slicer::program::fanuc::parse_ls;
use waam_slicer::program::fanuc::{fanuc_files, ArmPosition, FanucOptions, Op, TpProgram};
use waam_slicer::program::registry::check_files;
use waam_slicer::program::{MoveKind, ProgramError, ProgramSettings};
use waam_slicer::robot::Vendor;

use crate::fixture::{part_carried, program};

/// Motions and process instructions of the programs run one after the
/// other, positions resolved.
fn flatten(files: &[TpProgram]) -> Vec<String> {
    let mut out = Vec::new();
    for tp in files {
        for ins in &tp.instructions {
            match &ins.op {
                Op::UFrame(_) | Op::UTool(_) | Op::Remark(_) => {}
                Op::Call(n) => panic!("a group calls `{n}`: groups are complete programs"),
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
    out
}

#[test]
fn groups_at_n_positions_concatenate_to_the_uncut_program() {
    let cell = part_carried();
    let (prog, path) = program(&cell, 0..3, 10);
    let planned: Vec<_> = path
        .iter()
        .map(|p| waam_slicer::program::PlannedPoint {
            position_mm: p.position_mm,
            feed: waam_slicer::program::PointFeed {
                travel_speed_mm_s: crate::fixture::TS_MM_S,
                wire_feed_mm_s: crate::fixture::WFS_MM_S,
            },
        })
        .collect();
    let read = |opts: &FanucOptions| -> (Vec<TpProgram>, Vec<_>) {
        let files = fanuc_files(&prog, opts).unwrap();
        let tps = files
            .iter()
            .map(|f| parse_ls(&f.text, &f.name).unwrap_or_else(|e| panic!("{e}")))
            .collect();
        (tps, files)
    };
    let (whole, _) = read(&FanucOptions::default());
    assert_eq!(whole.len(), 1);
    assert_eq!(whole[0].name, "HEMI");
    // 30 bead points and an approach and a retract point per bead: three
    // beads of 12 positions (no home in this program)
    assert_eq!(prog.points.len(), 36);
    for (n, groups) in [
        (12usize, 3usize),
        (13, 3),
        (23, 3),
        (24, 2),
        (35, 2),
        (36, 1),
        (37, 1),
    ] {
        let opts = FanucOptions {
            max_positions: n,
            ..Default::default()
        };
        let (parts, files) = read(&opts);
        assert_eq!(parts.len(), groups, "N = {n}");
        if groups > 1 {
            for (k, g) in parts.iter().enumerate() {
                assert_eq!(g.name, format!("HEMI_P{:02}", k + 1));
                // each group alone is within the budget: it is all the
                // controller holds while it runs
                assert!(g.positions.len() <= n, "N = {n}");
                let count = |f: fn(&Op) -> bool| g.instructions.iter().filter(|i| f(&i.op)).count();
                let starts = count(|o| matches!(o, Op::ArcStart(_)));
                assert!(
                    starts >= 1 && starts == count(|o| matches!(o, Op::ArcEnd(_))),
                    "N = {n}"
                );
                let first_move = g
                    .instructions
                    .iter()
                    .find_map(|i| match &i.op {
                        Op::Move { kind, .. } => Some(*kind),
                        _ => None,
                    })
                    .unwrap();
                assert_eq!(first_move, MoveKind::Joint, "N = {n}");
                assert_eq!(g.comment, format!("waam: {} of {groups}", k + 1));
            }
        }
        assert_eq!(flatten(&parts), flatten(&whole), "N = {n}");
        // the whole build read back as one: every planned point in order
        let settings = ProgramSettings {
            fanuc: opts.clone(),
            ..Default::default()
        };
        let report = check_files(Vendor::Fanuc, &files, &cell, &settings, Some(&planned)).unwrap();
        assert!(report.is_ok(), "N = {n}: {report}");
        assert_eq!(report.beads, 3);
    }
}

/// A bead longer than the budget is refused, naming `max_positions`, the
/// layer and the numbers, rather than cut with the arc on across two
/// programs.
#[test]
fn a_bead_longer_than_the_budget_is_refused() {
    let (prog, _) = program(&part_carried(), 0..3, 10);
    let opts = FanucOptions {
        max_positions: 11,
        ..Default::default()
    };
    let e = fanuc_files(&prog, &opts).unwrap_err();
    assert!(
        matches!(
            e,
            ProgramError::OverBudget {
                layer: 0,
                size: 12,
                limit: 11,
                ..
            }
        ),
        "{e}"
    );
    let e = e.to_string();
    assert!(
        e.contains("`[program.fanuc] max_positions` = 11")
            && e.contains("layer 0 alone needs 12 positions"),
        "{e}"
    );
}
