//! `waam slice`: part file → the library's `slice_part_with` → path.csv,
//! wall.stl, path.svg, distance.svg and summary.json.

use crate::args::{SliceArgs, StrategyArg};
use std::path::{Path as FsPath, PathBuf};
use std::time::Instant;
use waam_slicer::util::atomic::write_atomic;

/// `write_atomic` for a writer that returns a value.
fn write_atomic_with<T>(
    dest: &FsPath,
    f: impl FnOnce(&mut dyn std::io::Write) -> std::io::Result<T>,
) -> std::io::Result<T> {
    let mut out = None;
    write_atomic(dest, |w| {
        out = Some(f(w)?);
        Ok(())
    })?;
    out.ok_or_else(|| std::io::Error::other("nothing written"))
}
use waam_slicer::path::smooth::Smoothing;
use waam_slicer::path::Strategy;
use waam_slicer::{slice_part_with, Part, SliceOverrides};

pub fn run(args: &SliceArgs, quiet: bool) -> Result<(), String> {
    let part_file = args.part.as_path();
    let more = &args.more;
    let t0 = Instant::now();
    let part = Part::read(part_file).map_err(|e| e.to_string())?;
    let t_read = t0.elapsed().as_secs_f64();
    let mut o = SliceOverrides {
        strategy: args.strategy.map(|s| match s {
            StrategyArg::Constant => Strategy::Constant,
            StrategyArg::Iso => Strategy::Iso,
            StrategyArg::Perpendicular => Strategy::Perpendicular,
            StrategyArg::Planar => Strategy::Planar,
            StrategyArg::Spiral => Strategy::Spiral,
        }),
        smoothing: more.smooth.map(|deg| Smoothing {
            max_turn_rad: deg.to_radians(),
            tolerance: more.smooth_tol,
        }),
        stagger_rad: more.stagger.map(f64::to_radians),
        spiral_start_rad: more.spiral_start.map(f64::to_radians),
        spiral_reverse: more.reverse,
        max_layers: more.max_layers,
        ..SliceOverrides::default()
    };
    args.grid.apply(&mut o);
    args.axes.apply(&mut o);
    let spinner = crate::progress::Stage::start(quiet, "slicing");
    let sliced = slice_part_with(&part, &o, &spinner.control()).map_err(|e| e.to_string())?;
    drop(spinner);
    let (path, map) = (&sliced.path, &sliced.map);

    let dir: PathBuf = args
        .out
        .clone()
        .unwrap_or_else(|| PathBuf::from("out").join(&part.name));
    std::fs::create_dir_all(&dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    let t_csv = Instant::now();
    let csv = dir.join("path.csv");
    write_atomic(&csv, |w| sliced.write_path_csv(w))
        .map_err(|e| format!("{}: {e}", csv.display()))?;
    let t_csv = t_csv.elapsed().as_secs_f64();
    let t_wall = Instant::now();
    let stl = dir.join("wall.stl");
    let width = more.bead_width.unwrap_or(path.delta_mm);
    if !more.no_wall {
        let wall = write_atomic_with(&stl, |w| sliced.write_wall_stl(w, width))
            .map_err(|e| format!("{}: {e}", stl.display()))?;
        if wall.every > 1 && !quiet {
            println!(
                "  wall.stl: {} triangles, a section at every {}th point (triangle budget)",
                wall.triangles, wall.every
            );
        }
    }
    let t_wall = t_wall.elapsed().as_secs_f64();
    let t_report = Instant::now();
    sliced
        .write_report(&dir.join("report.html"), Some(&part.substrate), width)
        .map_err(|e| e.to_string())?;
    let t_report = t_report.elapsed().as_secs_f64();
    // Pictures: written to temporary names, then renamed (no half-written file).
    let t4 = Instant::now();
    for (name, draw) in [
        (
            "path.svg",
            Box::new(|f: &FsPath| {
                crate::plots::path_view(
                    path,
                    &format!(
                        "{}: {} path, Delta = {} mm",
                        part.name,
                        path.strategy.name(),
                        path.delta_mm
                    ),
                    f,
                )
            }) as Box<dyn Fn(&FsPath) -> Result<(), String>>,
        ),
        (
            "distance.svg",
            Box::new(|f: &FsPath| {
                crate::plots::distance_plot(
                    path,
                    map,
                    &format!("{}: local interlayer distance per layer", part.name),
                    f,
                )
            }),
        ),
    ] {
        let tmp = dir.join(format!(".{name}.tmp"));
        draw(&tmp)?;
        std::fs::rename(&tmp, dir.join(name))
            .map_err(|e| format!("{}: {e}", dir.join(name).display()))?;
    }
    let t_plots = t4.elapsed().as_secs_f64();
    let mut summary = serde_json::to_value(sliced.summary()).map_err(|e| e.to_string())?;
    summary["run_time_s"]["read"] = t_read.into();
    summary["run_time_s"]["path_csv"] = t_csv.into();
    summary["run_time_s"]["wall_stl"] = t_wall.into();
    summary["run_time_s"]["report_html"] = t_report.into();
    summary["run_time_s"]["pictures"] = t_plots.into();
    let summary_file = dir.join("summary.json");
    write_atomic(&summary_file, |w| {
        serde_json::to_writer_pretty(&mut *w, &summary).map_err(std::io::Error::other)?;
        writeln!(w)
    })
    .map_err(|e| format!("{}: {e}", summary_file.display()))?;
    if !quiet {
        let o = map.overall;
        println!(
            "{}: {} strategy, Delta = {} mm: {} layers, {} points, {:.1} mm of bead in {:.3} s",
            part.name,
            path.strategy.name(),
            path.delta_mm,
            path.layers.len(),
            path.num_points(),
            path.length_mm(),
            sliced.times.slice
        );
        if let Some(o) = o {
            println!(
                "  interlayer distance {:.4} .. {:.4} mm (mean {:.4}), variation {:.3} % of Delta",
                o.min_mm,
                o.max_mm,
                o.mean_mm,
                100.0 * o.variation
            );
        }
        println!(
            "  wrote path.csv, summary.json, path.svg, distance.svg, {}report.html in {}",
            if more.no_wall { "" } else { "wall.stl, " },
            dir.display()
        );
    }
    Ok(())
}
