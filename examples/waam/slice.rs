//! `waam slice`: part file → path.csv + summary.json.

use crate::args::{SliceArgs, StrategyArg};
use serde_json::json;
use std::path::{Path as FsPath, PathBuf};
use std::time::Instant;
use waam_slicer::io::atomic::write_atomic;
use waam_slicer::io::part_file::read_part_file;
use waam_slicer::io::path_csv::write_path_csv;
use waam_slicer::path::smooth::Smoothing;
use waam_slicer::path::{distance_map, slice, Strategy};

pub fn run(args: &SliceArgs, quiet: bool) -> Result<(), String> {
    let part_file = args.part.as_path();
    let strategy = args.strategy;
    let (out, more) = (args.out.as_deref(), &args.more);
    let t0 = Instant::now();
    let part = read_part_file(part_file).map_err(|e| e.to_string())?;
    let t_read = t0.elapsed().as_secs_f64();
    let mut opts = part.slice_options();
    if let Some(s) = strategy {
        opts.strategy = match s {
            StrategyArg::Constant => Strategy::Constant,
            StrategyArg::Iso => Strategy::Iso,
            StrategyArg::Perpendicular => Strategy::Perpendicular,
            StrategyArg::Planar => Strategy::Planar,
            StrategyArg::Spiral => Strategy::Spiral,
        };
    }
    args.grid.apply(&mut opts);
    if let Some(deg) = more.smooth {
        opts.smoothing = Some(Smoothing {
            max_turn_rad: deg.to_radians(),
            tolerance: more.smooth_tol,
        });
    }
    if let Some(deg) = more.stagger {
        opts.stagger_rad = deg.to_radians();
        opts.align_seams = false;
    }
    if let Some(deg) = more.spiral_start {
        opts.spiral_start_rad = deg.to_radians();
    }
    opts.spiral_reverse = more.reverse;
    opts.max_layers = more.max_layers.or(opts.max_layers);
    let t1 = Instant::now();
    let spinner = crate::progress::Stage::start(quiet, "slicing");
    let path = slice(&part.tube, &part.substrate, &opts)
        .map_err(|e| format!("{}: {e}", part_file.display()))?;
    drop(spinner);
    let t_slice = t1.elapsed().as_secs_f64();
    let t2 = Instant::now();
    let map = distance_map(&path);
    let t_map = t2.elapsed().as_secs_f64();
    let t3 = Instant::now();
    let axes = crate::stages::axes_of(&part, &path, &args.axes, part_file)?;
    let frames = &axes.frames;
    let t_axes = t3.elapsed().as_secs_f64();

    let dir: PathBuf = out
        .map(FsPath::to_path_buf)
        .unwrap_or_else(|| PathBuf::from("out").join(&part.name));
    std::fs::create_dir_all(&dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    let csv = dir.join("path.csv");
    write_atomic(&csv, |w| write_path_csv(w, &path.layers, frames))
        .map_err(|e| format!("{}: {e}", csv.display()))?;
    let params = crate::stages::process_parameters(&part, &args.axes)?;
    let shared = crate::stages::path_summary(&path, &map, &params, &axes)?;
    let stl = dir.join("wall.stl");
    let width = more.bead_width.unwrap_or(path.delta_mm);
    let triangles = waam_slicer::io::wall_stl::wall_triangles(&path, frames, width);
    write_atomic(&stl, |w| {
        waam_slicer::io::wall_stl::write_stl(w, &triangles)
    })
    .map_err(|e| format!("{}: {e}", stl.display()))?;
    // Pictures: written to temporary names, then renamed (no half-written file).
    let t4 = Instant::now();
    for (name, draw) in [
        (
            "path.svg",
            Box::new(|f: &FsPath| {
                crate::plots::path_view(
                    &path,
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
                    &path,
                    &map,
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
    let mut summary = json!({
        "part": part.name,
        "part_file": part_file.display().to_string(),
        "slicer": {
            "grid_points": path.report.grid_points,
            "root_finds": path.report.root_finds,
            "evaluations": path.report.evaluations,
            "max_residual_mm": path.report.max_residual_mm,
            "truncated_points": path.report.truncated_points,
            "stop": format!("{:?}", path.report.stop),
            "max_turn_before_deg": path.report.max_turn_before_rad.to_degrees(),
            "max_turn_after_deg": path.report.max_turn_after_rad.to_degrees(),
        },
        "run_time_s": { "read": t_read, "slice": t_slice, "distance_map": t_map, "tool_axes": t_axes, "pictures": t_plots },
    });
    crate::stages::merge(&mut summary, shared);
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
            t_slice
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
            "  wrote path.csv, summary.json, path.svg, distance.svg, wall.stl in {}",
            dir.display()
        );
    }
    Ok(())
}
