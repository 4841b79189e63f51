//! The stages `slice` and `plan` share: the part file's tool-axis and process
//! settings with the command line's overrides applied, and the tool axes of a
//! sliced path.

use crate::args::AxisArgs;
use serde_json::json;
use waam_slicer::io::part_file::Part;
use waam_slicer::path::{DistanceMap, Path};
use waam_slicer::process::{plan_process, ProcessParameters};
use waam_slicer::toolaxis::{tool_axes, AxisRule, ToolAxes, ToolAxisOptions};

/// The part's `[tool_axis]` settings with `--lead`, `--tilt`, `--max-lean`
/// and `--plain-axes` applied.
pub fn tool_axis_options(part: &Part, a: &AxisArgs) -> ToolAxisOptions {
    let mut o = part.tool_axis.clone();
    if a.plain_axes {
        o.lead_rad = 0.0;
        o.tilt_rad = 0.0;
        o.rule = AxisRule::None;
        o.max_rate_rad_per_mm = None;
        o.max_axis_rate_rad_per_mm = None;
    }
    if let Some(r) = a.max_axis_rate {
        o.max_axis_rate_rad_per_mm = Some(r.to_radians());
    }
    if let Some(d) = a.lead {
        o.lead_rad = d.to_radians();
    }
    if let Some(d) = a.tilt {
        o.tilt_rad = d.to_radians();
    }
    if let Some(d) = a.max_lean {
        o.rule = AxisRule::MaxAngleFromAxis {
            axis: [0.0, 0.0, 1.0],
            max_angle_rad: d.to_radians(),
        };
    }
    o
}

/// The part's `[process]` parameters with `--process` and `--travel-speed`
/// applied (a preset replaces the part's whole table), checked.
pub fn process_parameters(part: &Part, a: &AxisArgs) -> Result<ProcessParameters, String> {
    let mut p = match a.process {
        Some(preset) => preset.parameters(),
        None => part.process.clone(),
    };
    if let Some(v) = a.travel_speed {
        p.travel_speed_mm_s = v;
    }
    p.validate()
        .map_err(|e| format!("--travel-speed / --process: {e}"))?;
    Ok(p)
}

/// Tool axes of `path` with the part's settings and the command line's
/// overrides; errors name the part file.
pub fn axes_of(
    part: &Part,
    path: &Path,
    a: &AxisArgs,
    file: &std::path::Path,
) -> Result<ToolAxes, String> {
    let opts = tool_axis_options(part, a);
    tool_axes(path, Some(&part.tube), Some(&part.substrate), &opts)
        .map_err(|e| format!("{}: tool axes: {e}", file.display()))
}

/// The part of `summary.json` that `slice` and `plan` share: layers, points,
/// length, arc starts, the process estimates (time, wire, mass), the tool-axis
/// report and the local interlayer distances.
pub fn path_summary(
    path: &Path,
    map: &DistanceMap,
    params: &ProcessParameters,
    axes: &ToolAxes,
) -> Result<serde_json::Value, String> {
    let process = plan_process(path, params, &Default::default()).map_err(|e| e.to_string())?;
    let est = process.estimates;
    Ok(json!({
        "strategy": path.strategy.name(),
        "delta_mm": path.delta_mm,
        "layers": path.layers.len(),
        "slices": path.num_slices(),
        "points": path.num_points(),
        "arc_starts": est.arc_starts,
        "length_mm": path.length_mm(),
        "process": {
            "material": params.material,
            "travel_speed_mm_s": params.travel_speed_mm_s,
            "wire_feed_speed_mm_s": params.wire_feed_speed_mm_s,
            "deposition_time_s": est.deposition_time_s,
            "wire_length_mm": est.wire_length_mm,
            "deposited_mass_g": est.deposited_mass_g,
            "speed_window_violations": process.violation_count,
        },
        "tool_axes": {
            "normals": format!("{:?}", axes.report.normals),
            "max_angle_from_z_deg": axes.report.max_angle_from_z_rad.to_degrees(),
            "max_rate_deg_per_mm": axes.report.max_rate_rad_per_mm.to_degrees(),
            "rule_active_points": axes.report.rule_active_points,
            "rule_unreachable_points": axes.report.rule_unreachable_count,
            "smoothed_points": axes.report.smoothed_points,
        },
        "distance": {
            "overall": map.overall,
            "per_layer": map.per_layer,
        },
    }))
}

/// Adds the keys of `extra` (an object) to `into` (an object).
pub fn merge(into: &mut serde_json::Value, extra: serde_json::Value) {
    if let (Some(into), serde_json::Value::Object(extra)) = (into.as_object_mut(), extra) {
        into.extend(extra);
    }
}
