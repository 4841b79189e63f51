//! `waam replan`: part file + cell file + the scan of layer K → the
//! library's `replan_part` (speed correction, then geometry, optimisation of
//! the remaining layers, the program that resumes the build); writes
//! `joints.csv`, `summary.json`, `report.html` (layer K as measured, the
//! replanned layers) and, if feasible, the program. Exit codes: 0
//! done, 1 bad input or a refused scan (the message names the distance that
//! gave it away), 2 plan infeasible (summary written, no program).

use crate::args::ReplanArgs;
use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Instant;
use waam_slicer::program::ProgramError;
use waam_slicer::replan::ReplanOptions;
use waam_slicer::robot::Vendor;
use waam_slicer::util::atomic::write_atomic;
use waam_slicer::{replan_part_with, Cell, Error, Measured, Part, PlanOptions};

/// Runs the command; prints errors itself and returns the exit code.
pub fn run(a: &ReplanArgs, quiet: bool) -> ExitCode {
    match replan(a, quiet) {
        Ok(true) => ExitCode::SUCCESS,
        Ok(false) => ExitCode::from(2),
        Err((code, message)) => {
            eprintln!("error: {message}");
            ExitCode::from(code)
        }
    }
}

fn replan(a: &ReplanArgs, quiet: bool) -> Result<bool, (u8, String)> {
    let input = |e: String| (1u8, e);
    let t0 = Instant::now();
    let part = Part::read(&a.part).map_err(|e| input(e.to_string()))?;
    let cell = Cell::read(&a.cell).map_err(|e| input(e.to_string()))?;
    let measured = Measured::read(&a.measured).map_err(|e| input(e.to_string()))?;
    let format: Option<Vendor> = match a.format.as_deref() {
        Some(f) => Some(f.parse().map_err(|e| input(format!("--format {e}")))?),
        None => None,
    };
    let mut opts = PlanOptions {
        format,
        ..PlanOptions::default()
    }
    .with_rz(a.rz.parse().map_err(|e| input(format!("--rz {e}")))?);
    a.grid.apply(&mut opts.slice);
    opts.slice.max_layers = a.max_layers;
    let ropts = ReplanOptions {
        outlier_distance_mm: a.outlier_distance,
        ..ReplanOptions::default()
    };
    let t_read = t0.elapsed().as_secs_f64();
    let replanned = match replan_part_with(&part, &cell, &measured, a.after_layer, &opts, &ropts) {
        Ok(r) => r,
        Err(Error::Program(e @ ProgramError::VendorMismatch { .. })) => {
            return Err((2, format!("--format: {e}")));
        }
        Err(e) => return Err(input(e.to_string())),
    };
    let dir: PathBuf = a.out.clone().unwrap_or_else(|| {
        PathBuf::from("out").join(format!("{}-replan-{}", part.name, a.after_layer))
    });
    std::fs::create_dir_all(&dir).map_err(|e| input(format!("{}: {e}", dir.display())))?;
    let t = Instant::now();
    let csv = dir.join("joints.csv");
    write_atomic(&csv, |w| replanned.write_joints_csv(w))
        .map_err(|e| input(format!("{}: {e}", csv.display())))?;
    let t_csv = t.elapsed().as_secs_f64();
    let t = Instant::now();
    replanned
        .write_report(&dir.join("report.html"), Some(&part.substrate))
        .map_err(|e| input(e.to_string()))?;
    let t_report = t.elapsed().as_secs_f64();
    let t = Instant::now();
    let mut written: Vec<serde_json::Value> = Vec::new();
    let feasible = if replanned.planned.plan.is_feasible() {
        match replanned.write_programs(&dir) {
            Ok(files) => {
                for f in &files {
                    let name = f
                        .file_name()
                        .map(|n| n.to_string_lossy().into_owned())
                        .unwrap_or_default();
                    let bytes = std::fs::metadata(f).map_or(0, |m| m.len());
                    written.push(serde_json::json!({ "file": name, "bytes": bytes }));
                }
                true
            }
            Err(why) => {
                eprintln!("no program written: {why}");
                false
            }
        }
    } else {
        false
    };
    let t_programs = t.elapsed().as_secs_f64();
    let mut summary =
        serde_json::to_value(replanned.summary()).map_err(|e| input(e.to_string()))?;
    let times = &mut summary["run_time_s"];
    times["read"] = t_read.into();
    times["joints_csv"] = t_csv.into();
    times["report_html"] = t_report.into();
    times["program_files"] = t_programs.into();
    summary["program_files"] = written.into();
    let sj = dir.join("summary.json");
    write_atomic(&sj, |w| {
        serde_json::to_writer_pretty(&mut *w, &summary).map_err(std::io::Error::other)?;
        writeln!(w)
    })
    .map_err(|e| input(format!("{}: {e}", sj.display())))?;
    if !quiet {
        let corrected = replanned.corrections.iter().filter(|c| c.corrected).count();
        println!(
            "{}: layers {}..{} replanned from the scan of layer {} ({} rows used, {} outliers); {} corrected, {}; {} in {:.3} s -> {}",
            part.name,
            replanned.after_layer + 1,
            replanned.after_layer + replanned.corrections.len(),
            replanned.after_layer,
            replanned.scan.inliers,
            replanned.scan.outlier_count,
            corrected,
            match (replanned.rejoined_at, replanned.skipped.as_slice()) {
                (Some(l), []) => format!("nominal again from layer {l}"),
                (Some(l), skipped) => format!(
                    "nominal again from layer {l} (nominal layer {}; nominal layers {}..={} skipped, the rest renumbered)",
                    l + skipped.len(),
                    skipped[0],
                    skipped[skipped.len() - 1]
                ),
                (None, _) => "the nominal layers are not rejoined".into(),
            },
            if feasible { "feasible" } else { "INFEASIBLE" },
            replanned.times.total,
            dir.display()
        );
    }
    Ok(feasible)
}
