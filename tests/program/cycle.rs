//! The build's cycle time in `summary.json`: per layer and for the build,
//! consistent with each other and bounded below by the time under the arc
//! at the travel speed (an independent computation from the program's bead
//! points).

use crate::shared::part_path;
use waam_slicer::program::ArcFlag;
use waam_slicer::{plan_part, Cell, Part, PlanOptions, SliceOverrides};

#[test]
fn summary_gives_the_cycle_time_per_layer_and_for_the_build() {
    let part = Part::read(part_path("hemisphere.toml")).unwrap();
    let cell = Cell::read(part_path("cells/robowam_part_carried.toml")).unwrap();
    let opts = PlanOptions {
        slice: SliceOverrides {
            discretisation: Some(waam_slicer::path::Discretisation::Points(120)),
            ..SliceOverrides::default()
        },
        ..PlanOptions::default()
    };
    let planned = plan_part(&part, &cell, &opts).unwrap();
    assert!(planned.is_feasible(), "{:?}", planned.refusal());
    let s = serde_json::to_value(planned.summary()).unwrap();
    let total = s["cycle_time_s"].as_f64().expect("cycle_time_s");
    let layers = s["layer_plans"].as_array().unwrap();
    let per_layer: f64 = layers
        .iter()
        .map(|l| l["cycle_time_s"].as_f64().expect("layer cycle_time_s"))
        .sum();
    let home = s["cycle"]["home_return_s"].as_f64().unwrap();
    assert!((total - (per_layer + home)).abs() < 1e-9 * total);
    // each bead takes at least its length over its programmed speeds
    let program = planned.program.as_ref().unwrap();
    let mut lower = 0.0;
    for w in program.points.windows(2) {
        if w[1].arc.is_bead() && w[1].arc != ArcFlag::Start {
            lower += (w[1].position_mm - w[0].position_mm).norm() / w[1].speed_mm_s;
        }
    }
    let arc_on = s["cycle"]["arc_on_s"].as_f64().unwrap();
    assert!(arc_on >= lower * (1.0 - 1e-9), "{arc_on} < {lower}");
    // ... and the ramps at 2000 mm/s² add little at ~10 mm/s
    assert!(arc_on < lower * 1.05 + 1.0, "{arc_on} vs {lower}");
    assert!(total > arc_on);
}
