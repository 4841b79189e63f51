//! `waam plan`: part file + cell file → the library's `plan_part` (slice →
//! tool axes → `R_Z` optimisation → joints → program model); writes
//! `joints.csv`, `summary.json`, `joints.svg`, `speeds.svg` and, if feasible,
//! the robot program. Exit codes: 0 done, 1 bad input (the message names the
//! file and field), 2 plan infeasible (summary written, no program) or a
//! program format the cell's robot cannot run.

use crate::args::PlanArgs;
use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Instant;
use waam_slicer::program::ProgramError;
use waam_slicer::robot::Vendor;
use waam_slicer::util::atomic::write_atomic;
use waam_slicer::{plan_part_with, Cell, Error, Part, PlanOptions, PlannedPart};

/// Runs the command; prints errors itself and returns the exit code.
pub fn run(a: &PlanArgs, quiet: bool) -> ExitCode {
    match plan(a, quiet) {
        Ok(true) => ExitCode::SUCCESS,
        Ok(false) => ExitCode::from(2),
        Err((code, message)) => {
            eprintln!("error: {message}");
            ExitCode::from(code)
        }
    }
}

/// `Ok(feasible)`; `Err((exit code, message))`: 1 bad input, 2 a format the
/// cell's robot cannot run.
fn plan(a: &PlanArgs, quiet: bool) -> Result<bool, (u8, String)> {
    let input = |e: String| (1u8, e);
    let t0 = Instant::now();
    let part = Part::read(&a.part).map_err(|e| input(e.to_string()))?;
    let cell = Cell::read(&a.cell).map_err(|e| input(e.to_string()))?;
    let format: Option<Vendor> = match a.format.as_deref() {
        Some(f) => Some(f.parse().map_err(|e| input(format!("--format {e}")))?),
        None => None,
    };
    let mut opts = PlanOptions {
        format,
        ..PlanOptions::default()
    }
    .with_rz(a.rz.parse().map_err(|e| input(format!("--rz {e}")))?);
    opts.slice.max_layers = a.max_layers;
    opts.slice.smoothing = a.smooth.map(|deg| waam_slicer::path::smooth::Smoothing {
        max_turn_rad: deg.to_radians(),
        tolerance: a.smooth_tol,
    });
    if a.positioner == "vertical" {
        opts.optimise.positioner.mode = waam_slicer::optimise::positioner::PositionerMode::Vertical;
    }
    a.grid.apply(&mut opts.slice);
    a.axes.apply(&mut opts.slice);
    let t_read = t0.elapsed().as_secs_f64();
    let spinner = crate::progress::Stage::start(quiet, "slicing");

    let planned = match plan_part_with(&part, &cell, &opts, &spinner.control()) {
        Ok(p) => p,
        Err(Error::Program(e @ ProgramError::VendorMismatch { .. })) => {
            let name = format.map(Vendor::key).unwrap_or_default();
            return Err((2, format!("--format {name}: {e}")));
        }
        Err(e) => return Err(input(e.to_string())),
    };
    drop(spinner);

    let dir: PathBuf = a
        .out
        .clone()
        .unwrap_or_else(|| PathBuf::from("out").join(&part.name));
    std::fs::create_dir_all(&dir).map_err(|e| input(format!("{}: {e}", dir.display())))?;
    let t = Instant::now();
    let csv = dir.join("joints.csv");
    write_atomic(&csv, |w| planned.write_joints_csv(w))
        .map_err(|e| input(format!("{}: {e}", csv.display())))?;
    let t_csv = t.elapsed().as_secs_f64();
    let t = Instant::now();
    draw_joint_plots(&dir, &part.name, &planned).map_err(input)?;
    let t_plots = t.elapsed().as_secs_f64();
    let t = Instant::now();
    planned
        .write_report(&dir.join("report.html"), Some(&part.substrate))
        .map_err(|e| input(e.to_string()))?;
    let t_report = t.elapsed().as_secs_f64();
    // The robot program, only for a feasible plan; the program stage checks
    // again and refuses (exit 2) if the trajectory it rebuilds breaks a limit.
    let t = Instant::now();
    let mut written: Vec<serde_json::Value> = Vec::new();
    let feasible = if planned.plan.is_feasible() {
        match planned.write_programs(&dir) {
            Ok(files) => {
                // the files in the order the cell loads them (the main
                // first; a build cut to the memory budget: its groups in turn)
                let names: Vec<String> = files
                    .iter()
                    .filter_map(|f| f.file_name().map(|n| n.to_string_lossy().into_owned()))
                    .collect();
                for (f, name) in files.iter().zip(&names) {
                    let bytes = std::fs::metadata(f).map_or(0, |m| m.len());
                    written.push(serde_json::json!({ "file": name, "bytes": bytes }));
                }
                if !quiet {
                    println!("  program: {}", names.join(", "));
                }
                true
            }
            Err(why) => {
                // the program stage's own refusal (typed, kept by the plan)
                eprintln!("no program written: {why}");
                false
            }
        }
    } else {
        false
    };
    let t_programs = t.elapsed().as_secs_f64();
    // Last, with every writer's time.
    let mut summary = serde_json::to_value(planned.summary()).map_err(|e| input(e.to_string()))?;
    let times = &mut summary["run_time_s"];
    times["read"] = t_read.into();
    times["joints_csv"] = t_csv.into();
    times["pictures"] = t_plots.into();
    times["report_html"] = t_report.into();
    times["program_files"] = t_programs.into();
    // the program files in the order the cell loads them, with their sizes
    summary["program_files"] = written.into();
    let sj = dir.join("summary.json");
    write_atomic(&sj, |w| {
        serde_json::to_writer_pretty(&mut *w, &summary).map_err(std::io::Error::other)?;
        writeln!(w)
    })
    .map_err(|e| input(format!("{}: {e}", sj.display())))?;
    if !quiet {
        let result = &planned.plan;
        println!(
            "{}: {} layers, {} points, {} in {:.3} s -> {}",
            part.name,
            result.layers.len(),
            planned.layers.iter().map(|l| l.points.len()).sum::<usize>(),
            if feasible { "feasible" } else { "INFEASIBLE" },
            result.time_s,
            dir.display()
        );
        for l in result.infeasible_layers() {
            println!("  layer {}: {}", l.layer, l.status);
        }
    }
    Ok(feasible)
}

/// `waam check`: reads a FANUC program and the sub-programs it calls, a KUKA
/// `.src` + `.dat` pair or an ABB module, and validates it against the cell.
pub fn check(a: &crate::args::CheckArgs, quiet: bool) -> ExitCode {
    let run = || -> Result<bool, String> {
        let cell = Cell::read(&a.cell).map_err(|e| e.to_string())?;
        let report = waam_slicer::check_program(&a.program, &cell).map_err(|e| e.to_string())?;
        for p in &report.problems {
            eprintln!("{p}");
        }
        if !quiet {
            println!(
                "{}: {} motions checked, {} problem(s)",
                a.program.display(),
                report.motions,
                report.problems.len()
            );
        }
        Ok(report.problems.is_empty())
    };
    match run() {
        Ok(true) => ExitCode::SUCCESS,
        Ok(false) => ExitCode::from(2),
        Err(message) => {
            eprintln!("error: {message}");
            ExitCode::from(1)
        }
    }
}

/// joints.svg (joint angles against the point index, limits in red) and
/// speeds.svg (joint speeds at the travel speed against their maxima).
fn draw_joint_plots(
    dir: &std::path::Path,
    name: &str,
    planned: &PlannedPart,
) -> Result<(), String> {
    let (layers, plan) = (&planned.layers, &planned.plan);
    let speed_mm_s = planned.travel_speed_mm_s();
    let robot = planned.cell.robot();
    // J1-J6, then the positioner's J7 (tilt) and J8 (turn) when there is one
    let positioner = match &planned.cell.layout {
        waam_slicer::robot::CellLayout::TorchCarried(c) => Some(&c.positioner),
        _ => None,
    };
    let axes = if positioner.is_some() { 8 } else { 6 };
    let mut angles: Vec<Vec<(f64, f64)>> = vec![Vec::new(); axes];
    let mut speeds: Vec<Vec<(f64, f64)>> = vec![Vec::new(); axes];
    let mut k = 0usize;
    for (lp, pl) in layers.iter().zip(&plan.layers) {
        let mut prev: Option<(waam_slicer::math::Point3, [f64; 8])> = None;
        for (cp, pp) in lp.points.iter().zip(&pl.points) {
            if let Some(q6) = pp.joints {
                let e = pp.positioner.unwrap_or([0.0; 2]);
                let q = [q6[0], q6[1], q6[2], q6[3], q6[4], q6[5], e[0], e[1]];
                for j in 0..axes {
                    angles[j].push((k as f64, q[j].to_degrees()));
                }
                if let Some((p0, q0)) = prev {
                    let dt = (cp.position_mm - p0).norm() / speed_mm_s;
                    if dt > 0.0 {
                        for j in 0..axes {
                            speeds[j].push((k as f64, ((q[j] - q0[j]) / dt).abs().to_degrees()));
                        }
                    }
                }
                prev = Some((cp.position_mm, q));
            }
            k += 1;
        }
    }
    let mut limits: Vec<(f64, f64)> = robot
        .limits
        .iter()
        .map(|l| (l.lower_rad.to_degrees(), l.upper_rad.to_degrees()))
        .collect();
    let mut max_speed: Vec<(f64, f64)> = robot
        .max_speed_rad_s
        .iter()
        .map(|v| (f64::NEG_INFINITY, v.to_degrees()))
        .collect();
    if let Some(p) = positioner {
        limits.extend(
            p.limits
                .iter()
                .map(|l| (l.lower_rad.to_degrees(), l.upper_rad.to_degrees())),
        );
        max_speed.extend(
            p.max_speed_rad_s
                .iter()
                .map(|v| (f64::NEG_INFINITY, v.to_degrees())),
        );
    }
    for (file, title, unit, series, bounds) in [
        (
            "joints.svg",
            format!("{name}: joint angles (limits in red)"),
            "deg",
            &angles,
            &limits,
        ),
        (
            "speeds.svg",
            format!("{name}: joint speeds at the travel speed (maxima in red)"),
            "deg/s",
            &speeds,
            &max_speed,
        ),
    ] {
        let tmp = dir.join(format!(".{file}.tmp"));
        crate::plots::joint_panels(&title, unit, series, bounds, &tmp)?;
        std::fs::rename(&tmp, dir.join(file))
            .map_err(|e| format!("{}: {e}", dir.join(file).display()))?;
    }
    Ok(())
}
