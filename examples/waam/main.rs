//! `waam` — the command-line front end of waam-slicer.
//!
//! ```text
//! cargo run --release --example waam -- parts
//! cargo run --release --example waam -- geometry parts/quarter-torus.toml
//! cargo run --release --example waam -- slice parts/quarter-torus.toml
//! cargo run --release --example waam -- fit scan.stl --out out/scan
//! ```
//! Exit codes: 0 done, 1 bad input (the message names the file and field).

mod args;
mod fit;
mod place;
mod plan;
mod plots;
mod progress;
mod replan;
mod slice;

use args::{Args, Command};
use clap::Parser;
use std::process::ExitCode;
use waam_slicer::io::part_file::{read_part_file, Part};

fn main() -> ExitCode {
    // Usage errors are bad input (exit 1); exit 2 is kept for infeasible plans.
    let args = match Args::try_parse() {
        Ok(a) => a,
        Err(e) => {
            let code = if e.use_stderr() { 1 } else { 0 };
            let _ = e.print();
            return ExitCode::from(code);
        }
    };
    let result = match &args.command {
        Command::Plan(a) => return plan::run(a, args.quiet),
        Command::Check(a) => return plan::check(a, args.quiet),
        Command::Place(a) => return place::run(a, args.quiet),
        Command::Replan(a) => return replan::run(a, args.quiet),
        Command::Parts { dir } => list_parts(dir),
        Command::Geometry { part, points } => geometry(part, *points, args.quiet),
        Command::Slice(cmd) => slice::run(cmd, args.quiet),
        Command::Fit(a) => fit::run(a, args.quiet),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(message) => {
            eprintln!("error: {message}");
            ExitCode::from(1)
        }
    }
}

fn list_parts(dir: &std::path::Path) -> Result<(), String> {
    let mut files: Vec<_> = std::fs::read_dir(dir)
        .map_err(|e| format!("{}: {e}", dir.display()))?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "toml"))
        .collect();
    files.sort();
    for f in files {
        match read_part_file(&f) {
            Ok(p) => println!("{:<40} {}", f.display(), p.description),
            Err(e) => println!("{:<40} INVALID: {e}", f.display()),
        }
    }
    let cells_dir = dir.join("cells");
    let mut cells: Vec<_> = std::fs::read_dir(&cells_dir)
        .map(|d| {
            d.filter_map(|e| e.ok().map(|e| e.path()))
                .filter(|p| p.extension().is_some_and(|x| x == "toml"))
                .collect()
        })
        .unwrap_or_default();
    cells.sort();
    for f in cells {
        match waam_slicer::io::cell_file::read_cell_file(&f) {
            Ok(c) => {
                let kind = if c.cell.is_some() {
                    "cell"
                } else {
                    "robot only"
                };
                println!(
                    "{:<40} {} ({kind}, robot {})",
                    f.display(),
                    c.name,
                    c.robot.name
                )
            }
            Err(e) => println!("{:<40} INVALID: {e}", f.display()),
        }
    }
    Ok(())
}

fn geometry(path: &std::path::Path, points: usize, quiet: bool) -> Result<(), String> {
    let part = read_part_file(path).map_err(|e| e.to_string())?;
    let layer = part
        .substrate
        .first_layer(&part.tube, points)
        .map_err(|e| format!("{}: {e}", path.display()))?;
    if quiet {
        return Ok(());
    }
    print_geometry(&part, &layer);
    Ok(())
}

fn print_geometry(part: &Part, layer: &[waam_slicer::geometry::CurvePoint]) {
    let tube = &part.tube;
    let r = tube.range();
    println!("part        {} — {}", part.name, part.description);
    println!("source      {}", part.source);
    println!(
        "guide       {}, frame {:?}",
        guide_kind(part),
        tube.frame_method()
    );
    println!(
        "range       t in [{:.6}, {:.6}] (evaluable [{:.6}, {:.6}]), guide length {:.3} mm",
        r.t_min,
        r.t_max,
        r.eval_min(),
        r.eval_max(),
        tube.arc_length(r.t_max)
    );
    let n = 400;
    let (mut a_min, mut a_max, mut fold) = (f64::MAX, f64::MIN, 0.0_f64);
    for i in 0..=n {
        let t = r.t_min + (r.t_max - r.t_min) * i as f64 / n as f64;
        let a = tube.radius(t);
        a_min = a_min.min(a);
        a_max = a_max.max(a);
        fold = fold.max(a * tube.guide().curvature(t));
    }
    println!(
        "profile     A(t) from {a_min:.3} to {a_max:.3} mm; max A·kappa = {fold:.4} (folds at 1)"
    );
    let (t_lo, t_hi) = layer
        .iter()
        .fold((f64::MAX, f64::MIN), |(a, b), p| (a.min(p.t), b.max(p.t)));
    let perimeter: f64 = layer
        .iter()
        .zip(layer.iter().cycle().skip(1))
        .map(|(a, b)| (b.position - a.position).norm())
        .sum();
    println!(
        "first layer {} points on the {} substrate, t in [{t_lo:.6}, {t_hi:.6}], perimeter {perimeter:.3} mm",
        layer.len(),
        substrate_kind(part)
    );
    let (mut lo, mut hi) = ([f64::MAX; 3], [f64::MIN; 3]);
    for i in 0..=100 {
        let t = r.t_min + (r.t_max - r.t_min) * i as f64 / 100.0;
        for p in tube.iso_t(t, 72) {
            for k in 0..3 {
                lo[k] = lo[k].min(p[k]);
                hi[k] = hi[k].max(p[k]);
            }
        }
    }
    println!(
        "bounding box x [{:.2}, {:.2}]  y [{:.2}, {:.2}]  z [{:.2}, {:.2}] mm (part frame)",
        lo[0], hi[0], lo[1], hi[1], lo[2], hi[2]
    );
    println!(
        "slicing     {:?}, Delta = {} mm, {:?}",
        part.slicing.strategy, part.slicing.delta_mm, part.slicing.discretisation
    );
    let mid = 0.5 * (r.t_min + r.t_max);
    let sp = tube.surface(mid, 0.0);
    println!(
        "M(t_mid, 0) = ({:.4}, {:.4}, {:.4}) mm, normal ({:.4}, {:.4}, {:.4})",
        sp.position.x, sp.position.y, sp.position.z, sp.normal.x, sp.normal.y, sp.normal.z
    );
}

fn guide_kind(part: &Part) -> &'static str {
    use waam_slicer::io::part_file::GuideSpec;
    match part.spec.guide {
        GuideSpec::Line { .. } => "line",
        GuideSpec::Arc { .. } => "arc",
        GuideSpec::Helix { .. } => "helix",
        GuideSpec::Expr { .. } => "expression",
        GuideSpec::Spline { .. } => "spline",
        GuideSpec::Pipe { .. } => "pipe run",
    }
}

fn substrate_kind(part: &Part) -> &'static str {
    use waam_slicer::geometry::Substrate;
    match part.substrate {
        Substrate::Plane { .. } => "plane",
        Substrate::Cylinder { .. } => "cylinder",
        Substrate::Mesh(_) => "mesh",
    }
}
