//! `waam place`: part file + cell file → the library's `place_part` →
//! `cell.toml` (a complete cell file with the placement found) and
//! `placement.json` (the search). Exit codes: 0 found, 1 bad input, 2 no
//! placement makes every layer feasible (the binding constraint is named).

use crate::args::PlaceArgs;
use std::path::PathBuf;
use std::process::ExitCode;
use waam_slicer::place::Binding;
use waam_slicer::{place_part, Cell, Part, PlaceRequest};

/// Runs the command; prints errors itself and returns the exit code.
pub fn run(a: &PlaceArgs, quiet: bool) -> ExitCode {
    match place(a, quiet) {
        Ok(true) => ExitCode::SUCCESS,
        Ok(false) => ExitCode::from(2),
        Err(message) => {
            eprintln!("error: {message}");
            ExitCode::from(1)
        }
    }
}

fn place(a: &PlaceArgs, quiet: bool) -> Result<bool, String> {
    let part = Part::read(&a.part).map_err(|e| e.to_string())?;
    let cell = Cell::read(&a.cell).map_err(|e| e.to_string())?;
    if !(a.half_box.is_finite() && a.half_box > 0.0) {
        return Err(format!(
            "--half-box {}: must be positive and finite",
            a.half_box
        ));
    }
    let mut req = PlaceRequest {
        half_box_mm: Some(a.half_box),
        ..PlaceRequest::default()
    };
    req.search.samples = a.samples;
    a.grid.apply(&mut req.slice);
    a.axes.apply(&mut req.slice);
    let spinner = crate::progress::Stage::start(quiet, "placing");
    let placed = place_part(&part, &cell, &req).map_err(|e| e.to_string())?;
    drop(spinner);
    let dir: PathBuf = a
        .out
        .clone()
        .unwrap_or_else(|| PathBuf::from("out").join(format!("{}-placed", part.name)));
    placed.write(&dir).map_err(|e| e.to_string())?;
    let p = &placed.placement;
    let toml = dir.join("cell.toml");
    if !quiet {
        let values: Vec<String> = placed
            .bounds
            .variables
            .iter()
            .zip(p.values.in_table_order(&p.cell))
            .filter(|(v, _)| v.is_free() || v.current != 0.0)
            .map(|(v, x)| {
                if v.angle {
                    format!("{} = {:.2} deg", v.name, x.to_degrees())
                } else {
                    format!("{} = {:.3} mm", v.name, x)
                }
            })
            .collect();
        println!(
            "{}: {} candidates ({:.0} % feasible on the subsample), {} certified on the full path, in {:.2} s (screening {:.2} s, refinement {:.2} s, certification {:.2} s)",
            part.name,
            p.candidates,
            100.0 * p.feasible_fraction,
            p.certified,
            p.time_s,
            p.times.screening_s,
            p.times.refinement_s,
            p.times.certification_s,
        );
        println!("  {}", values.join(", "));
        if p.feasible {
            println!(
                "  feasible: worst layer {:.2} deg from a joint stop, speed headroom {:.1} %, {:.1} mm inside the arm's reach, dexterity {:.4} -> {}",
                p.margins.joint_limit_deg,
                100.0 * p.margins.speed_headroom,
                p.margins.reach_mm,
                p.margins.dexterity,
                toml.display()
            );
        }
    }
    if !p.feasible {
        let why = match &p.binding {
            Some(b @ Binding::FullPath { limit, refused, .. }) => {
                let also = refused
                    .as_ref()
                    .map(|r| format!("; another candidate was refused by the program check: {r}"))
                    .unwrap_or_default();
                format!(
                    "{limit} (on the full path): feasible on the subsample, it binds {:.0} % of the layers checked of the best candidate{also}",
                    100.0 * b.share()
                )
            }
            Some(b @ Binding::ProgramCheck { .. }) => {
                format!("every candidate feasible on the full path was refused: {b}")
            }
            Some(b) => format!("{b} bound {:.0} % of the candidates", 100.0 * b.share()),
            None => "no candidate was feasible".into(),
        };
        eprintln!(
            "no placement found: {why}; {} layer(s) infeasible in the best one (placement.json)",
            p.margins.infeasible_layers
        );
    }
    Ok(p.feasible)
}
