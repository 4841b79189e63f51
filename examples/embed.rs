//! Plans a sample part through the library's front door, as a host program
//! would: read a part and a cell, plan, write the robot program, read it back
//! and check it.
//!
//! ```text
//! cargo run --release --example embed [PART.toml] [CELL.toml] [OUT_DIR]
//! ```

use waam_slicer::{Cell, Part, PlanOptions};

fn main() -> Result<(), waam_slicer::Error> {
    let mut args = std::env::args().skip(1);
    let part_file = args.next().unwrap_or("parts/hemisphere.toml".into());
    let cell_file = args
        .next()
        .unwrap_or("parts/cells/robowam_part_carried.toml".into());
    let out = args.next().unwrap_or("out/embed".into());

    let part = Part::read(&part_file)?;
    let cell = Cell::read(&cell_file)?;
    let planned = waam_slicer::plan_part(&part, &cell, &PlanOptions::default())?;
    println!(
        "{}: {} layers, feasible: {}",
        part.name,
        planned.plan.layers.len(),
        planned.is_feasible()
    );
    if !planned.is_feasible() {
        for layer in planned.plan.infeasible_layers() {
            println!("  layer {}: {}", layer.layer, layer.status);
        }
        std::process::exit(2);
    }
    let files = planned.write_programs(&out)?;
    let report = waam_slicer::check_program(&files[0], &cell)?;
    println!(
        "{}: {} motions, {} problem(s)",
        files[0].display(),
        report.motions,
        report.problems.len()
    );
    assert!(
        report.problems.is_empty(),
        "the program we wrote must read back clean"
    );
    Ok(())
}
