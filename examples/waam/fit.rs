//! `waam fit`: a part fitted to a tubular mesh.

use crate::args::FitArgs;
use waam_slicer::{FitOptions, Part};

pub fn run(a: &FitArgs, quiet: bool) -> Result<(), String> {
    let opts = FitOptions {
        units: a.units,
        start: a.start,
        max_rms_mm: a.max_rms,
        template: a.template.clone(),
        name: a.name.clone(),
        substrate: a.substrate.clone(),
        substrate_tolerance_mm: a.substrate_tolerance,
        trim: a.trim,
        knot_spacing_mm: a.knot_spacing,
        station_spacing_mm: a.station_spacing,
        ..FitOptions::default()
    };
    let fitted = Part::from_mesh(&a.mesh, &opts).map_err(|e| e.to_string())?;
    let mut files = fitted.write(&a.out).map_err(|e| e.to_string())?;
    files.push(fitted.write_report(&a.out).map_err(|e| e.to_string())?);
    let r = fitted.report();
    for w in &r.warnings {
        eprintln!("warning     {w}");
    }
    if !quiet {
        println!(
            "fitted      {} ({} triangles, {} skin{}): guide {:.2} mm through {} points, {} iterations{}",
            r.file,
            r.triangles,
            r.skins,
            if r.skins == 1 { "" } else { "s" },
            r.length_mm,
            r.guide_points,
            r.iterations,
            if r.converged { "" } else { " (not converged)" }
        );
        println!(
            "radius      {:.3} to {:.3} mm{}",
            r.radius_min_mm,
            r.radius_max_mm,
            r.wall
                .as_ref()
                .map(|w| format!(
                    "; wall {:.3} mm ({:.3} to {:.3})",
                    w.mean_mm, w.min_mm, w.max_mm
                ))
                .unwrap_or_default()
        );
        for (name, e) in [("start", &r.start), ("end", &r.end)] {
            println!(
                "{name:<11} {}, {} (tilt {:.1} deg), station {} (t = {:.2} mm), radius {:.3} mm",
                e.kind.name(),
                if e.oblique { "cut obliquely" } else { "square" },
                e.tilt_deg,
                e.station,
                e.t_mm,
                e.radius_mm
            );
        }
        for f in &r.features {
            println!(
                "left out    a {} from {:.2} to {:.2} mm along the guide (stations {} to {} before trimming): {}",
                f.kind.name(),
                f.t_from_mm,
                f.t_to_mm,
                f.first_station,
                f.last_station,
                f.size()
            );
        }
        println!(
            "residual    {:.4} mm RMS, {:.4} mm at most (vertices to the fitted surface)",
            r.rms_mm, r.max_mm
        );
        if let Some(d) = r.substrate_distance_mm {
            println!("substrate   the start end's rim within {d:.4} mm of the substrate mesh");
        }
        for f in files {
            println!("wrote       {}", f.display());
        }
    }
    Ok(())
}
