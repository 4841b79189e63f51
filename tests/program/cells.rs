//! Every sample cell plans a part and writes a program with its `[program]`
//! table's set-up (issue 18): home as first and last motion, an interlayer
//! dwell before every layer after the first, arc-off transits checked
//! against the wall, payload updates where the arm carries the part — and
//! the program read back from the files checks clean against the same cell
//! file (the validator's set-up checks are exercised on hand-made steps in
//! `setup`). The nozzle plans in all seven cells (README feasibility table);
//! its first four layers at 40 points a layer keep this quick.

use waam_slicer::program::validate::ProblemKind;
use waam_slicer::{check_program, plan_part, Cell, Part, PlanOptions};

use crate::shared::SAMPLE_CELLS;

fn root() -> std::path::PathBuf {
    std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

#[test]
fn every_sample_cell_writes_programs_with_home_dwell_transit_and_payload_that_check_clean() {
    let part = Part::read(root().join("parts/nozzle.toml")).unwrap();
    let mut opts = PlanOptions::default();
    opts.slice.max_layers = Some(4);
    opts.slice.discretisation = Some(waam_slicer::path::Discretisation::Points(40));
    let tmp = std::env::temp_dir().join(format!("waam-cells-{}", std::process::id()));
    for file in SAMPLE_CELLS {
        let cell = Cell::read(root().join("parts/cells").join(file)).unwrap();
        let common = cell.program.common;
        assert!(
            common.home_deg.is_some(),
            "{file}: the sample cells state home"
        );
        assert!(common.dwell_s > 0.0, "{file}: and a dwell");
        let planned = plan_part(&part, &cell, &opts).unwrap_or_else(|e| panic!("{file}: {e}"));
        assert!(planned.is_feasible(), "{file}: {:?}", planned.refusal());
        let program = planned.program.as_ref().unwrap();
        assert!(program.home.is_some(), "{file}");
        assert_eq!(program.bead_setup.len(), 4, "{file}");
        for (k, s) in program.bead_setup.iter().enumerate() {
            assert_eq!(
                s.dwell_s,
                if k == 0 { 0.0 } else { common.dwell_s },
                "{file}"
            );
        }
        let part_carried = matches!(cell.layout, waam_slicer::robot::CellLayout::PartCarried(_));
        let first = program.bead_setup[0].payload;
        assert_eq!(
            first.is_some(),
            part_carried,
            "{file}: payload before bead 0"
        );
        if let Some(p) = first {
            assert!((p.mass_kg - common.payload_base_kg).abs() < 1e-12, "{file}");
        }
        let dir = tmp.join(file.trim_end_matches(".toml"));
        let files = planned
            .write_programs(&dir)
            .unwrap_or_else(|e| panic!("{file}: {e}"));
        let report = check_program(&files[0], &cell).unwrap();
        assert!(report.is_ok(), "{file}:\n{report}");
        // the check is not vacuous: the same files against the cell without
        // its dwell find the dwell missing (a dwell the cell did not ask for
        // is not a problem), and with a longer dwell they fall short
        let mut longer = cell.clone();
        longer.program.common.dwell_s = common.dwell_s + 10.0;
        let report = check_program(&files[0], &longer).unwrap();
        assert!(
            report.problems.len() == 3
                && report.problems.iter().all(|p| p.kind == ProblemKind::Setup),
            "{file}: a 40 s dwell must be missed before beads 2-4:\n{report}"
        );
    }
    let _ = std::fs::remove_dir_all(&tmp);
}
