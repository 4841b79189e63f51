//! `waam plan`: part file + cell file → slice → tool axes → `R_Z`
//! optimisation → joints; writes `joints.csv` and `summary.json`.
//! Exit codes: 0 done, 1 bad input (the message names the file and field),
//! 2 plan infeasible (summary written, no program).

use crate::args::PlanArgs;
use serde_json::json;
use std::io::Write;
use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Instant;
use waam_slicer::io::atomic::write_atomic;
use waam_slicer::io::cell_file::read_cell_file;
use waam_slicer::io::part_file::read_part_file;
use waam_slicer::optimise::{
    layer_points, optimise, Abscissa, OptimiseOptions, Parameterisation, Plan,
};
use waam_slicer::path::{distance_map, slice};
use waam_slicer::robot::Cell;

/// Header of `joints.csv` (degrees, part frame mm); `e1,e2` appended with a positioner.
pub const JOINTS_HEADER: &str = "layer,point,x,y,z,tx,ty,tz,rz_deg,j1,j2,j3,j4,j5,j6";

fn parse_rz(s: &str) -> Result<Parameterisation, String> {
    let bad = || format!("--rz `{s}`: expected fixed:DEG, poly:N (0..=8), spline or point");
    match s.split_once(':') {
        Some(("fixed", d)) => {
            let deg: f64 = d.parse().map_err(|_| bad())?;
            if !deg.is_finite() {
                return Err(bad());
            }
            Ok(Parameterisation::Fixed {
                r_z_rad: deg.to_radians(),
            })
        }
        Some(("poly", n)) => {
            let n: usize = n.parse().map_err(|_| bad())?;
            if n > 8 {
                return Err(bad());
            }
            Ok(Parameterisation::Polynomial {
                max_degree: n,
                abscissa: Abscissa::Auto,
                stop_relative_gain: 1e-3,
            })
        }
        None if s == "spline" => Ok(Parameterisation::SmoothingSpline { smoothness: 1.0 }),
        None if s == "point" => Ok(Parameterisation::PointByPoint),
        _ => Err(bad()),
    }
}

/// Why `plan` stops before planning: bad input (exit 1) or a program format
/// the cell's robot cannot run (exit 2).
enum PlanError {
    Input(String),
    Format(String),
}

impl From<String> for PlanError {
    fn from(message: String) -> Self {
        PlanError::Input(message)
    }
}

/// The emitter for `asked` (`None`: the cell robot's vendor's); another
/// vendor's format is [`PlanError::Format`] with the library's message.
fn program_format(asked: Option<&str>, cell: &Cell) -> Result<&'static str, PlanError> {
    use waam_slicer::robot::Vendor;
    let (vendor, name, emitter) = match asked {
        Some("kuka") => (Vendor::Kuka, "kuka", waam_slicer::program::kuka::EMITTER),
        Some("abb") => (Vendor::Abb, "abb", waam_slicer::program::abb::EMITTER),
        Some(_) => (Vendor::Fanuc, "fanuc", waam_slicer::program::fanuc::EMITTER),
        None => {
            return Ok(match cell.robot().vendor {
                Vendor::Fanuc => "fanuc",
                Vendor::Kuka => "kuka",
                Vendor::Abb => "abb",
            })
        }
    };
    waam_slicer::program::check_vendor(cell, vendor, emitter)
        .map_err(|e| PlanError::Format(format!("--format {name}: {e}")))?;
    Ok(name)
}

/// Runs the command; prints errors itself and returns the exit code.
pub fn run(a: &PlanArgs, quiet: bool) -> ExitCode {
    match plan(a, quiet) {
        Ok(true) => ExitCode::SUCCESS,
        Ok(false) => ExitCode::from(2),
        Err(PlanError::Format(message)) => {
            eprintln!("error: {message}");
            ExitCode::from(2)
        }
        Err(PlanError::Input(message)) => {
            eprintln!("error: {message}");
            ExitCode::from(1)
        }
    }
}

/// `Ok(feasible)`, `Err` for bad input or a mismatching format.
fn plan(a: &PlanArgs, quiet: bool) -> Result<bool, PlanError> {
    let t0 = Instant::now();
    let part = read_part_file(&a.part).map_err(|e| e.to_string())?;
    let cell_file = read_cell_file(&a.cell).map_err(|e| e.to_string())?;
    let cell: Cell = cell_file.cell.ok_or_else(|| {
        format!(
            "{}: no [part_carried] or [torch_carried] section: not a cell",
            a.cell.display()
        )
    })?;
    // The program format: the cell robot's vendor's unless asked; another
    // vendor's is refused before any planning (exit 2, as the emitter would).
    let format = program_format(a.format.as_deref(), &cell)?;
    // One IK branch for the whole part (the cell's): a program must not
    // reconfigure the arm between layers.
    let process = crate::stages::process_parameters(&part, &a.axes)?;
    let opts = OptimiseOptions {
        parameterisation: parse_rz(&a.rz)?,
        travel_speed_mm_s: process.travel_speed_mm_s,
        configuration: waam_slicer::optimise::ConfigurationChoice::Cell,
        ..OptimiseOptions::default()
    };
    opts.validate().map_err(|e| e.to_string())?;
    let mut so = part.slice_options();
    a.grid.apply(&mut so);
    let t_read = t0.elapsed().as_secs_f64();
    let t1 = Instant::now();
    let spinner = crate::progress::Stage::start(quiet, "slicing");
    let path = slice(&part.tube, &part.substrate, &so)
        .map_err(|e| format!("{}: {e}", a.part.display()))?;
    drop(spinner);
    let t_slice = t1.elapsed().as_secs_f64();
    let t2 = Instant::now();
    let axes = crate::stages::axes_of(&part, &path, &a.axes, &a.part)?;
    let layers = layer_points(&path, &axes.frames);
    let shared = crate::stages::path_summary(&path, &distance_map(&path), &process, &axes)?;
    let t_axes = t2.elapsed().as_secs_f64();
    let result = {
        let _spinner = crate::progress::Stage::start(
            quiet,
            &format!("optimising R_Z on {} layers", layers.len()),
        );
        optimise(&cell, &layers, &opts).map_err(|e| e.to_string())?
    };

    let dir: PathBuf = a
        .out
        .clone()
        .unwrap_or_else(|| PathBuf::from("out").join(&part.name));
    std::fs::create_dir_all(&dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    let feasible = result.is_feasible();
    let csv = dir.join("joints.csv");
    write_atomic(&csv, |w| write_joints_csv(w, &layers, &result, &cell))
        .map_err(|e| format!("{}: {e}", csv.display()))?;
    draw_joint_plots(
        &dir,
        &part.name,
        &cell,
        &layers,
        &result,
        opts.travel_speed_mm_s,
    )?;
    let mut summary = summary_json(&part.name, a, &result, &opts, [t_read, t_slice, t_axes]);
    crate::stages::merge(&mut summary, shared);
    let sj = dir.join("summary.json");
    write_atomic(&sj, |w| {
        serde_json::to_writer_pretty(&mut *w, &summary).map_err(std::io::Error::other)?;
        writeln!(w)
    })
    .map_err(|e| format!("{}: {e}", sj.display()))?;
    // The robot program, only for a feasible plan; the program stage checks
    // again and refuses (exit 2) if the trajectory it rebuilds breaks a limit.
    let feasible = if feasible {
        match emit_program(
            &part.name,
            format,
            &cell,
            &layers,
            &result,
            opts.travel_speed_mm_s,
            &dir,
        ) {
            Ok(files) => {
                if !quiet {
                    println!("  program: {}", files.join(", "));
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
    if !quiet {
        println!(
            "{}: {} layers, {} points, {} in {:.3} s -> {}",
            part.name,
            result.layers.len(),
            layers.iter().map(|l| l.points.len()).sum::<usize>(),
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

fn write_joints_csv(
    w: &mut dyn Write,
    layers: &[waam_slicer::optimise::LayerPoints],
    plan: &Plan,
    cell: &Cell,
) -> std::io::Result<()> {
    let positioner = matches!(cell, Cell::TorchCarried(_));
    write!(w, "{JOINTS_HEADER}")?;
    writeln!(w, "{}", if positioner { ",e1,e2" } else { "" })?;
    for (lp, l) in layers.iter().zip(&plan.layers) {
        for (m, (cp, pp)) in lp.points.iter().zip(&l.points).enumerate() {
            let p = cp.position_mm;
            let t = cp.tool_axis;
            write!(
                w,
                "{},{m},{:.6},{:.6},{:.6},{:.6},{:.6},{:.6},{:.6}",
                lp.layer,
                p.x,
                p.y,
                p.z,
                t.x,
                t.y,
                t.z,
                pp.r_z.to_degrees()
            )?;
            match pp.joints {
                Some(q) => {
                    for v in q {
                        write!(w, ",{:.6}", v.to_degrees())?;
                    }
                }
                None => write!(w, ",,,,,,")?,
            }
            if positioner {
                match pp.positioner {
                    Some(e) => write!(w, ",{:.6},{:.6}", e[0].to_degrees(), e[1].to_degrees())?,
                    None => write!(w, ",,")?,
                }
            }
            writeln!(w)?;
        }
    }
    Ok(())
}

fn deg6(q: &[f64; 6]) -> Vec<f64> {
    q.iter().map(|v| v.to_degrees()).collect()
}

fn summary_json(
    name: &str,
    a: &PlanArgs,
    plan: &Plan,
    opts: &OptimiseOptions,
    times: [f64; 3],
) -> serde_json::Value {
    let layers: Vec<_> = plan
        .layers
        .iter()
        .map(|l| {
            let q = &l.quality;
            json!({
                "layer": l.layer,
                "status": l.status.to_string(),
                "feasible": l.status.is_feasible(),
                "configuration": l.configuration.chosen.to_string(),
                "configuration_reason": l.configuration.reason,
                "law": format!("{:?}", l.law),
                "points": l.points.len(),
                "objective": {
                    "joint_displacement": l.objective.joint_displacement,
                    "uncertainty_sum_sq_mm2": l.objective.uncertainty_sum_sq_mm2,
                    "mean_uncertainty_mm": l.objective.mean_uncertainty_mm,
                    "centring": l.objective.centring,
                },
                "quality": {
                    "joint_travel_deg": deg6(&q.joint_travel_rad),
                    "peak_speed_deg_s": deg6(&q.peak_speed_rad_s),
                    "peak_acceleration_deg_s2": deg6(&q.peak_acceleration_rad_s2),
                    "summed_acceleration_j1_j5_deg_s": q.summed_acceleration_rad_s.to_degrees(),
                    "direction_reversals": q.direction_reversals,
                    "min_dexterity": q.min_dexterity,
                    "min_limit_distance_deg": q.min_limit_distance_rad.to_degrees(),
                    "min_limit_distance_joint": q.min_limit_distance_joint,
                    "max_hose_torsion_deg": q.max_hose_torsion_rad.to_degrees(),
                },
                "solver": {
                    "iterations": l.solver.iterations,
                    "qp_solves": l.solver.qp_solves,
                    "qp_failures": l.solver.qp_failures,
                    "branches_tried": l.solver.branches_tried,
                    "time_s": l.solver.time_s,
                },
            })
        })
        .collect();
    let violations: Vec<String> = plan.violations().map(|v| v.to_string()).collect();
    json!({
        "part": name,
        "part_file": a.part.display().to_string(),
        "cell_file": a.cell.display().to_string(),
        "rz": a.rz,
        "travel_speed_mm_s": opts.travel_speed_mm_s,
        "feasible": plan.is_feasible(),
        "infeasible_layers": plan.infeasible_layers().map(|l| l.layer).collect::<Vec<_>>(),
        "violations": violations,
        "layer_plans": layers,
        "transitions": plan.transitions.iter().map(|t| json!({
            "from_layer": t.from_layer,
            "to_layer": t.to_layer,
            "joint_change_deg": deg6(&t.joint_change_rad),
            "branch_change": t.branch_change,
            "start_limit_distance_deg": t.start_limit_distance_rad.to_degrees(),
        })).collect::<Vec<_>>(),
        "program": serde_json::Value::Null,
        "run_time_s": {
            "read": times[0],
            "slice": times[1],
            "tool_axes": times[2],
            "optimise": plan.time_s,
        },
    })
}

/// Builds the joint trajectory of the optimised `R_Z`, the program, and
/// writes its files; returns their names.
fn emit_program(
    part: &str,
    format: &str,
    cell: &Cell,
    layers: &[waam_slicer::optimise::LayerPoints],
    plan: &waam_slicer::optimise::Plan,
    speed_mm_s: f64,
    dir: &std::path::Path,
) -> Result<Vec<String>, String> {
    use waam_slicer::program::{build_program, write_files, TravelSpeed};
    use waam_slicer::robot::trajectory::{joint_trajectory, TrajectoryOptions};
    let inputs = waam_slicer::optimise::trajectory_inputs(layers, plan);
    let traj = joint_trajectory(cell, &inputs, speed_mm_s, &TrajectoryOptions::default())
        .map_err(|e| e.to_string())?;
    let name: String = {
        let mut n: String = part
            .chars()
            .map(|c| {
                if c.is_ascii_alphanumeric() {
                    c.to_ascii_uppercase()
                } else {
                    '_'
                }
            })
            .collect();
        if !n.starts_with(|c: char| c.is_ascii_alphabetic()) {
            n.insert(0, 'P');
        }
        n.truncate(24);
        n
    };
    let program = build_program(
        &name,
        cell,
        &inputs,
        &traj,
        &TravelSpeed::Constant(speed_mm_s),
    )
    .map_err(|e| e.to_string())?;
    let files = match format {
        "kuka" => waam_slicer::program::kuka::kuka_files(&program, &Default::default()),
        "abb" => waam_slicer::program::abb::abb_files(&program, &Default::default()),
        _ => waam_slicer::program::fanuc::fanuc_files(&program, &Default::default()),
    }
    .map_err(|e| e.to_string())?;
    write_files(dir, &files).map_err(|e| e.to_string())?;
    Ok(files.iter().map(|f| f.name.clone()).collect())
}

/// `waam check`: reads a FANUC program and the sub-programs it calls, a KUKA
/// `.src` + `.dat` pair or an ABB module, and validates it against the cell.
pub fn check(a: &crate::args::CheckArgs, quiet: bool) -> ExitCode {
    use waam_slicer::program::fanuc::FanucOptions;
    use waam_slicer::program::readback::parse_ls;
    use waam_slicer::program::validate::validate_fanuc;
    let run = || -> Result<bool, String> {
        let cell_file = read_cell_file(&a.cell).map_err(|e| e.to_string())?;
        let cell = cell_file
            .cell
            .ok_or_else(|| format!("{}: not a cell", a.cell.display()))?;
        let dir = a
            .program
            .parent()
            .map(std::path::Path::to_path_buf)
            .unwrap_or_default();
        let read = |p: &std::path::Path| -> Result<waam_slicer::program::fanuc::TpProgram, String> {
            let text = std::fs::read_to_string(p).map_err(|e| format!("{}: {e}", p.display()))?;
            parse_ls(&text, &p.display().to_string()).map_err(|e| e.to_string())
        };
        let ext = a
            .program
            .extension()
            .and_then(|e| e.to_str())
            .unwrap_or("")
            .to_ascii_lowercase();
        let text_of = |p: &std::path::Path| {
            std::fs::read_to_string(p).map_err(|e| format!("{}: {e}", p.display()))
        };
        let report = match ext.as_str() {
            "src" | "dat" => {
                let src = a.program.with_extension("src");
                let dat = a.program.with_extension("dat");
                let program = waam_slicer::program::readback::kuka::parse_krl(
                    &text_of(&src)?,
                    &src.display().to_string(),
                    &text_of(&dat)?,
                    &dat.display().to_string(),
                )
                .map_err(|e| e.to_string())?;
                waam_slicer::program::validate::validate_kuka(
                    &program,
                    &cell,
                    &Default::default(),
                    None,
                )
            }
            "mod" => {
                let module = waam_slicer::program::readback::abb::parse_mod(
                    &text_of(&a.program)?,
                    &a.program.display().to_string(),
                )
                .map_err(|e| e.to_string())?;
                waam_slicer::program::validate::validate_abb(
                    &module,
                    &cell,
                    &Default::default(),
                    None,
                )
            }
            "ls" => {
                let main = read(&a.program)?;
        let mut programs = vec![main];
        let mut k = 0;
        while k < programs.len() {
            let calls: Vec<String> = programs[k]
                .instructions
                .iter()
                .filter_map(|i| match &i.op {
                    waam_slicer::program::fanuc::Op::Call(n) => Some(n.clone()),
                    _ => None,
                })
                .collect();
            for called in calls {
                if !programs.iter().any(|p| p.name == called) {
                    programs.push(read(&dir.join(format!("{called}.ls")))?);
                }
            }
            k += 1;
        }
        validate_fanuc(&programs, &cell, &FanucOptions::default(), None)
            }
            other => {
                return Err(format!(
                    "{}: unknown program type `.{other}`; expected .ls (FANUC), .src/.dat (KUKA) or .mod (ABB)",
                    a.program.display()
                ))
            }
        };
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
    cell: &Cell,
    layers: &[waam_slicer::optimise::LayerPoints],
    plan: &waam_slicer::optimise::Plan,
    speed_mm_s: f64,
) -> Result<(), String> {
    let robot = cell.robot();
    let mut angles: [Vec<(f64, f64)>; 6] = Default::default();
    let mut speeds: [Vec<(f64, f64)>; 6] = Default::default();
    let mut k = 0usize;
    for (lp, pl) in layers.iter().zip(&plan.layers) {
        let mut prev: Option<(waam_slicer::math::Point3, [f64; 6])> = None;
        for (cp, pp) in lp.points.iter().zip(&pl.points) {
            if let Some(q) = pp.joints {
                for j in 0..6 {
                    angles[j].push((k as f64, q[j].to_degrees()));
                }
                if let Some((p0, q0)) = prev {
                    let dt = (cp.position_mm - p0).norm() / speed_mm_s;
                    if dt > 0.0 {
                        for j in 0..6 {
                            speeds[j].push((k as f64, ((q[j] - q0[j]) / dt).abs().to_degrees()));
                        }
                    }
                }
                prev = Some((cp.position_mm, q));
            }
            k += 1;
        }
    }
    let limits = robot
        .limits
        .map(|l| (l.lower_rad.to_degrees(), l.upper_rad.to_degrees()));
    let max_speed = robot
        .max_speed_rad_s
        .map(|v| (f64::NEG_INFINITY, v.to_degrees()));
    for (file, title, unit, series, bounds) in [
        (
            "joints.svg",
            format!("{name}: joint angles (limits in red)"),
            "deg",
            &angles,
            limits,
        ),
        (
            "speeds.svg",
            format!("{name}: joint speeds at the travel speed (maxima in red)"),
            "deg/s",
            &speeds,
            max_speed,
        ),
    ] {
        let tmp = dir.join(format!(".{file}.tmp"));
        crate::plots::joint_panels(&title, unit, series, bounds, &tmp)?;
        std::fs::rename(&tmp, dir.join(file))
            .map_err(|e| format!("{}: {e}", dir.join(file).display()))?;
    }
    Ok(())
}
