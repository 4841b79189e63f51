//! Bead splits at corners (issue 45, deliverable 3): the quarter torus at
//! its own grid (Delta 5 mm, 17 layers) in each torch-carried sample cell.
//! Its open layers 11–16 each turn one corner inside the bead (77–112°),
//! across which no positioner keeps the build direction within the cone:
//! planned as one bead each layer is refused. Split there, each layer is
//! two beads, the first ending on the corner and the second starting on
//! it after an arc-off move (checked against the wall and the cell with
//! the other transits), and every layer plans. The splits are named in
//! `summary.json` and counted in its arc starts, `joints.csv` numbers the
//! beads, and the program of the cell's vendor has one bead more per split
//! and reads back clean (`waam check`).

use waam_slicer::io::joints_csv::read_joints_csv;
use waam_slicer::{check_program, plan_part, Cell, Part, PlanOptions};

use crate::shared::part_path;

const TORCH_CELLS: [&str; 3] = [
    "robowam_torch_carried.toml",
    "kuka_kr16_2_torch_carried.toml",
    "abb_irb2600_torch_carried.toml",
];

#[test]
fn the_quarter_torus_splits_each_corner_layer_once_and_plans_in_every_torch_carried_cell() {
    let part = Part::read(part_path("quarter-torus.toml")).unwrap();
    for cell_file in TORCH_CELLS {
        let cell = Cell::read(part_path(&format!("cells/{cell_file}"))).unwrap();
        let p = plan_part(&part, &cell, &PlanOptions::default()).unwrap();
        let what = cell_file;
        assert!(
            p.is_feasible(),
            "{what}: {:?} {:?}",
            p.plan
                .infeasible_layers()
                .map(|l| l.layer)
                .collect::<Vec<_>>(),
            p.refusal().map(|e| e.to_string())
        );
        let path = &p.sliced.path;
        assert_eq!(path.layers.len(), 17);
        let threshold = p.sliced.options.corner_threshold_rad;
        // one split a corner layer, on its corner
        let want: Vec<(usize, usize)> = (11..=16)
            .map(|li| {
                let inside = path.layers[li].inside_corners(threshold);
                assert_eq!(inside.len(), 1, "{what} layer {li}");
                (li, inside[0].point)
            })
            .collect();
        let got: Vec<(usize, usize)> = p.splits.iter().map(|s| (s.layer, s.point)).collect();
        assert_eq!(got, want, "{what}");
        assert!(p.splits.iter().all(|s| s.bead == 1 && !s.why.is_empty()));
        // the plan's entries are the beads: the first ends on the corner,
        // the second starts there
        assert_eq!(p.layers.len(), 17 + 6);
        for (lp, pl) in p.layers.iter().zip(&p.plan.layers) {
            assert_eq!((lp.layer, lp.points.len()), (pl.layer, pl.points.len()));
            assert!(pl.status.is_feasible(), "{what} layer {}", pl.layer);
        }
        for w in p.layers.windows(2) {
            if w[1].bead == 1 {
                let (a, b) = (&w[0], &w[1]);
                assert_eq!((a.layer, a.bead), (b.layer, 0));
                let n = path.layers[a.layer].points.len();
                assert_eq!(a.points.len() + b.points.len(), n + 1);
                assert_eq!(
                    a.points.last().unwrap().position_mm,
                    b.points[0].position_mm
                );
            }
        }
        // summary.json: the splits named, one arc start more each
        let json = serde_json::to_value(p.summary()).unwrap();
        let splits = json["splits"].as_array().unwrap();
        assert_eq!(splits.len(), 6, "{what}");
        for (s, (li, point)) in splits.iter().zip(&want) {
            assert_eq!(
                (s["layer"].as_u64(), s["point"].as_u64()),
                (Some(*li as u64), Some(*point as u64))
            );
            let turn = s["turning_deg"].as_f64().unwrap();
            assert!((75.0..115.0).contains(&turn), "{what}: {turn}");
            assert!(!s["why"].as_str().unwrap().is_empty());
        }
        let sliced_starts = serde_json::to_value(p.sliced.summary()).unwrap()["arc_starts"]
            .as_u64()
            .unwrap();
        assert_eq!(json["arc_starts"].as_u64().unwrap(), sliced_starts + 6);
        // each bead's cycle time is its own: the cycle's entries, a bead
        // each in program order, taken in turn within their layer
        let cycle = json["cycle"]["layers"].as_array().unwrap();
        let mut seen = std::collections::HashMap::<u64, usize>::new();
        for lp in json["layer_plans"].as_array().unwrap() {
            let layer = lp["layer"].as_u64().unwrap();
            let bead = lp["bead"].as_u64().unwrap_or(0) as usize;
            let k = seen.entry(layer).or_insert(0);
            assert_eq!(bead, *k, "{what}: layer {layer}'s beads in order");
            *k += 1;
            let own = cycle
                .iter()
                .filter(|c| c["layer"].as_u64() == Some(layer))
                .nth(bead)
                .unwrap()["total_s"]
                .as_f64();
            assert_eq!(
                lp["cycle_time_s"].as_f64(),
                own,
                "{what}: layer {layer} bead {bead}"
            );
        }
        for &(li, _) in &want {
            let beads: Vec<f64> = json["layer_plans"]
                .as_array()
                .unwrap()
                .iter()
                .filter(|lp| lp["layer"].as_u64() == Some(li as u64))
                .map(|lp| lp["cycle_time_s"].as_f64().unwrap())
                .collect();
            assert_eq!(beads.len(), 2, "{what} layer {li}");
            assert_ne!(
                beads[0], beads[1],
                "{what} layer {li}: two beads, two cycle times"
            );
        }
        // the program: one bead a layer and one more a split
        let program = p.program.as_ref().unwrap();
        assert_eq!(program.num_beads(), 17 + 6, "{what}");
        // joints.csv: the bead column, the split point in both beads
        let mut csv = Vec::new();
        p.write_joints_csv(&mut csv).unwrap();
        let rows = read_joints_csv(&String::from_utf8(csv).unwrap(), "joints.csv").unwrap();
        for &(li, point) in &want {
            let layer: Vec<_> = rows.iter().filter(|r| r.layer == li).collect();
            assert_eq!(layer.len(), path.layers[li].points.len() + 1);
            let at: Vec<usize> = layer
                .iter()
                .filter(|r| r.point == point)
                .map(|r| r.bead)
                .collect();
            assert_eq!(at, [0, 1], "{what} layer {li}");
            assert!(layer
                .iter()
                .all(|r| r.bead == usize::from(r.point > point) || r.point == point));
        }
        assert!(rows
            .iter()
            .all(|r| r.bead == 0 || (11..=16).contains(&r.layer)));
        // the cell's vendor's program reads back clean, with every bead
        let dir = tempfile::tempdir().unwrap();
        p.write_programs(dir.path()).unwrap();
        let report = check_program(dir.path(), &cell).unwrap();
        assert!(report.is_ok(), "{what}:\n{report}");
        assert_eq!(report.beads, 17 + 6, "{what}");
    }
}
