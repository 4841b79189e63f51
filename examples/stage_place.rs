//! Stage 8 alone (placement, [`waam_slicer::place`] through the front
//! door's [`place_part`](waam_slicer::place_part)): the hemisphere in the
//! KUKA part-carried sample cell is refused as the cell stands (at this
//! grid J6 leaves its travel on layer 9; at the part file's own grid an
//! arc-off move passes through the deposited wall); the search moves the
//! deposition point and the part's mount until every layer is feasible and
//! the program stage accepts it, and the placed cell then plans.
//!
//! The check is independent of the search's own verdict: the placed cell is
//! read back from the cell file the search wrote (as `waam place` writes
//! it), planned again from scratch, and its program read back clean.
//!
//! ```text
//! cargo run --example stage_place
//! ```

use waam_slicer::path::Discretisation;
use waam_slicer::{
    check_program, place_part, plan_part, Cell, Part, PlaceRequest, PlanOptions, SliceOverrides,
};

fn main() -> Result<(), waam_slicer::Error> {
    let root = env!("CARGO_MANIFEST_DIR");
    let part = Part::read(format!("{root}/parts/hemisphere.toml"))?;
    let cell = Cell::read(format!("{root}/parts/cells/kuka_kr16_2_part_carried.toml"))?;
    // a coarse grid: 48 points a layer, every layer
    let slice = SliceOverrides {
        discretisation: Some(Discretisation::Points(48)),
        ..SliceOverrides::default()
    };
    let opts = PlanOptions {
        slice: slice.clone(),
        ..PlanOptions::default()
    };
    let before = plan_part(&part, &cell, &opts)?;
    println!(
        "as the cell stands: {}",
        before
            .refusal()
            .map_or("feasible".to_string(), |e| e.to_string())
    );
    assert!(
        !before.is_feasible(),
        "the sample cell refuses the hemisphere"
    );

    let placed = place_part(
        &part,
        &cell,
        &PlaceRequest {
            slice,
            ..PlaceRequest::default()
        },
    )?;
    assert!(placed.placement.feasible, "{:?}", placed.placement.binding);
    // the written cell file, read back as a user would
    let again = Cell::from_toml_str(&placed.toml, &format!("{root}/parts/cells/placed.toml"))?;
    let after = plan_part(&part, &again, &opts)?;
    assert!(after.is_feasible(), "{:?}", after.refusal());
    let dir = std::env::temp_dir().join(format!("waam-stage-place-{}", std::process::id()));
    let files = after.write_programs(&dir)?;
    let report = check_program(&files[0], &again)?;
    let _ = std::fs::remove_dir_all(&dir);
    println!(
        "placed: {} candidates, {} motions checked, {} problem(s)",
        placed.placement.candidates,
        report.motions,
        report.problems.len()
    );
    assert!(report.is_ok(), "{report}");
    Ok(())
}
