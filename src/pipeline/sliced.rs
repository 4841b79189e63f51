//! Slicing a part in one call: path (SPEC §3), distance map (§3.2), tool axes
//! (§4) and process plan (§5) with the part file's settings and the caller's
//! overrides.

use std::time::Instant;

use serde::ser::{SerializeMap, SerializeStruct};
use serde::Serialize;

use super::summary::{
    CornerSummary, CornersSummary, DistanceSummary, PathSummary, ProcessSummary, SliceSummary,
    SlicerSummary, ToolAxesSummary,
};
use super::{Control, Part, SliceOverrides};
use crate::path::{distance_map, DistanceMap, Path, SliceOptions};
use crate::process::{plan_process, ProcessParameters, ProcessPlan};
use crate::toolaxis::{tool_axes, ToolAxes, ToolAxisOptions};
use crate::Error;

/// Wall-clock time of each slicing stage (s).
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize)]
pub struct SliceTimes {
    /// Slicing (s).
    pub slice: f64,
    /// Distance map (s).
    pub distance_map: f64,
    /// Tool axes (s).
    pub tool_axes: f64,
}

/// A sliced part: the deposition path (part frame, mm), its local
/// interlayer distances, one local frame per point and the process plan.
///
/// Serialises (serde) as `{ "summary": …, "layers": [{ "points", "tool_axis",
/// "delta" }] }`: the summary is [`SlicedPart::summary`], the layers give each
/// point's position (mm), tool axis (unit) and distance to the layer below
/// (mm, `null` on the first layer), part frame.
#[derive(Debug, Clone)]
pub struct SlicedPart {
    /// The part's name.
    pub part_name: String,
    /// The part file, as given.
    pub part_file: String,
    /// The slicing options used (the part's, with the overrides).
    pub options: SliceOptions,
    /// The deposition path, part frame (mm).
    pub path: Path,
    /// Local interlayer distances per layer and overall (mm).
    pub map: DistanceMap,
    /// The tool-axis settings used.
    pub tool_axis: ToolAxisOptions,
    /// One local frame per point (`axes.frames[layer][point]`), part frame.
    pub axes: ToolAxes,
    /// The process parameters used (validated; travel speed in mm/s).
    pub process: ProcessParameters,
    /// Per-point process values and the estimates (time, wire, mass).
    pub process_plan: ProcessPlan,
    /// Run times.
    pub times: SliceTimes,
}

/// Slices `part` with its own settings: [`slice_part_with`] and no overrides.
///
/// # Errors
/// As [`slice_part_with`].
pub fn slice_part(part: &Part) -> Result<SlicedPart, Error> {
    slice_part_with(part, &SliceOverrides::default(), &Control::default())
}

/// Slices `part` with its file's settings and `overrides`: path, distance
/// map, tool axes and process plan. `control` reports progress and may cancel.
///
/// # Errors
/// [`Error::InPart`] naming the part file around the stage's error (a bad
/// option names its field, a failed root find its layer and point);
/// [`Error::Cancelled`].
pub fn slice_part_with(
    part: &Part,
    overrides: &SliceOverrides,
    control: &Control,
) -> Result<SlicedPart, Error> {
    let in_part = |e: Error| Error::InPart {
        file: part.file.clone(),
        source: Box::new(e),
    };
    let options = overrides.apply(&part.slice_options());
    let process = overrides.apply_process(&part.process);
    process.validate().map_err(|e| in_part(e.into()))?;
    let tool_axis = overrides.tool_axis.apply(&part.tool_axis);
    tool_axis.validate().map_err(|e| in_part(e.into()))?;
    options.validate().map_err(|e| in_part(e.into()))?;
    let estimate = crate::path::estimate_work(&part.tube, &part.substrate, &options);
    let budget = overrides.max_points.unwrap_or(super::DEFAULT_MAX_POINTS);
    if estimate.points > budget || estimate.over_path_limit {
        return Err(Error::OverBudget {
            file: part.file.clone(),
            layers: estimate.layers,
            points_per_layer: estimate.points_per_layer,
            points: estimate.points,
            megabytes: estimate.bytes as f64 / 1e6,
            budget,
        });
    }
    control.check("slicing")?;
    control.report("slicing", 0.0);
    let t = Instant::now();
    let mut path = crate::path::slice_positions(&part.tube, &part.substrate, &options)
        .map_err(|e| in_part(e.into()))?;
    let t_slice = t.elapsed().as_secs_f64();
    control.check("slicing")?;
    // The distance map, once: it also gives every point its local distance.
    let t = Instant::now();
    let map = distance_map(&path);
    crate::path::distance_map::apply_deltas(&mut path, &map);
    let t_map = t.elapsed().as_secs_f64();
    control.report("tool axes", 0.5);
    let t = Instant::now();
    let axes = tool_axes(&path, Some(&part.tube), Some(&part.substrate), &tool_axis)
        .map_err(|e| in_part(e.into()))?;
    let t_axes = t.elapsed().as_secs_f64();
    let process_plan =
        plan_process(&path, &process, &Default::default()).map_err(|e| in_part(e.into()))?;
    control.report("tool axes", 1.0);
    Ok(SlicedPart {
        part_name: part.name.clone(),
        part_file: part.file.clone(),
        options,
        path,
        map,
        tool_axis,
        axes,
        process,
        process_plan,
        times: SliceTimes {
            slice: t_slice,
            distance_map: t_map,
            tool_axes: t_axes,
        },
    })
}

impl SlicedPart {
    /// What `slice` and `plan` report of the path (the shared part of
    /// `summary.json`): strategy, Delta, layers, slices, points, arc starts,
    /// bead length (mm), process estimates, tool-axis report, the local
    /// interlayer distances overall and per layer, and the layers' corners.
    pub fn path_summary(&self) -> PathSummary {
        let (path, map, params, axes) = (&self.path, &self.map, &self.process, &self.axes);
        let est = self.process_plan.estimates;
        PathSummary {
            strategy: path.strategy.name(),
            delta_mm: path.delta_mm,
            layers: path.layers.len(),
            slices: path.num_slices(),
            points: path.num_points(),
            arc_starts: est.arc_starts,
            length_mm: path.length_mm(),
            process: ProcessSummary {
                material: params.material.clone(),
                travel_speed_mm_s: params.travel_speed_mm_s,
                wire_feed_speed_mm_s: params.wire_feed_speed_mm_s,
                deposition_time_s: est.deposition_time_s,
                wire_length_mm: est.wire_length_mm,
                deposited_mass_g: est.deposited_mass_g,
                speed_window_violations: self.process_plan.violation_count,
            },
            tool_axes: ToolAxesSummary {
                normals: axes.report.normals,
                max_angle_from_z_deg: axes.report.max_angle_from_z_rad.to_degrees(),
                max_rate_deg_per_mm: axes.report.max_rate_rad_per_mm.to_degrees(),
                rule_active_points: axes.report.rule_active_points,
                rule_unreachable_points: axes.report.rule_unreachable_count,
                smoothed_points: axes.report.smoothed_points,
            },
            distance: DistanceSummary {
                overall: map.overall,
                per_layer: map.per_layer.clone(),
            },
            corners: self.corners_summary(),
        }
    }

    /// The layers' corners above the options' threshold, per layer, with
    /// the build direction's jump across each (`summary.json`'s `corners`).
    pub fn corners_summary(&self) -> CornersSummary {
        let threshold = self.options.corner_threshold_rad;
        let per_layer: Vec<Vec<CornerSummary>> = self
            .path
            .layers
            .iter()
            .zip(&self.axes.frames)
            .map(|(layer, frames)| {
                layer
                    .corners(threshold)
                    .iter()
                    .map(|c| CornerSummary::of(layer, frames, c))
                    .collect()
            })
            .collect();
        CornersSummary {
            threshold_deg: threshold.to_degrees(),
            seams_on_corners: self.options.seams_on_corners,
            layers_with_corners: per_layer.iter().filter(|c| !c.is_empty()).count(),
            count: per_layer.iter().map(Vec::len).sum(),
            per_layer,
        }
    }

    /// The content of `slice`'s `summary.json`: the part, what the slicer
    /// did, the run times (s) and [`SlicedPart::path_summary`]
    /// (`serde_json::to_value` gives the JSON).
    pub fn summary(&self) -> SliceSummary {
        let r = &self.path.report;
        SliceSummary {
            part: self.part_name.clone(),
            part_file: self.part_file.clone(),
            slicer: SlicerSummary {
                grid_points: r.grid_points,
                root_finds: r.root_finds,
                evaluations: r.evaluations,
                max_residual_mm: r.max_residual_mm,
                truncated_points: r.truncated_points,
                stop: r.stop,
                max_turn_before_deg: r.max_turn_before_rad.to_degrees(),
                max_turn_after_deg: r.max_turn_after_rad.to_degrees(),
            },
            run_time_s: self.times,
            path: self.path_summary(),
        }
    }

    /// Writes `path.csv` (one row per point, see [`crate::io::path_csv`]).
    ///
    /// # Errors
    /// I/O errors of `w`.
    pub fn write_path_csv(&self, w: &mut dyn std::io::Write) -> std::io::Result<()> {
        crate::io::path_csv::write_path_csv(w, &self.path.layers, &self.axes.frames)
    }

    /// Writes the deposited wall as binary STL, streamed: a bead section
    /// `width_mm` × the local distance swept along the path (part frame,
    /// mm), at most [`DEFAULT_MAX_WALL_TRIANGLES`](crate::io::wall_stl::DEFAULT_MAX_WALL_TRIANGLES)
    /// triangles (sections at every k-th point above; the result says k).
    ///
    /// # Errors
    /// I/O errors of `w`.
    pub fn write_wall_stl(
        &self,
        w: &mut dyn std::io::Write,
        width_mm: f64,
    ) -> std::io::Result<crate::io::wall_stl::WallStl> {
        crate::io::wall_stl::write_wall_stl(
            w,
            &self.path,
            &self.axes.frames,
            width_mm,
            crate::io::wall_stl::DEFAULT_MAX_WALL_TRIANGLES,
        )
    }
}

impl SlicedPart {
    /// The report's input for this part: the path with its frames, distances
    /// and process speeds, the substrate if given, bead width `width_mm`.
    pub fn report_input<'a>(
        &'a self,
        title: &'a str,
        substrate: Option<&'a crate::geometry::Substrate>,
        width_mm: f64,
    ) -> crate::report::ReportInput<'a> {
        let mut input = crate::report::ReportInput::new(
            title,
            &self.path,
            &self.axes.frames,
            &self.map,
            width_mm,
        );
        input.substrate = substrate;
        input.process = Some(&self.process_plan);
        input
    }

    /// Writes the interactive 3-D report (`report.html`, see
    /// [`crate::report`]) atomically to `dest`.
    ///
    /// # Errors
    /// [`Error::Report`] naming the input or the file.
    pub fn write_report(
        &self,
        dest: &std::path::Path,
        substrate: Option<&crate::geometry::Substrate>,
        width_mm: f64,
    ) -> Result<(), Error> {
        let title = format!(
            "{}: {} path, Delta = {} mm",
            self.part_name,
            self.path.strategy.name(),
            self.path.delta_mm
        );
        let corners = self.corner_marks(&[]);
        let mut input = self.report_input(&title, substrate, width_mm);
        input.corners = &corners;
        crate::report::write_report(dest, &input)?;
        Ok(())
    }

    /// The layers' corners above the options' threshold as the report
    /// marks them, each flagged where `splits` split the layer's bead on it.
    pub fn corner_marks(
        &self,
        splits: &[crate::optimise::BeadSplit],
    ) -> Vec<crate::report::CornerMark> {
        let threshold = self.options.corner_threshold_rad;
        self.path
            .layers
            .iter()
            .enumerate()
            .flat_map(|(li, layer)| {
                let n = layer.points.len();
                layer
                    .corners(threshold)
                    .into_iter()
                    .map(move |c| crate::report::CornerMark {
                        layer: li,
                        point: c.point,
                        turning_deg: c.turn_rad.to_degrees(),
                        on_seam: layer.closed && c.on_seam(n),
                        split: splits.iter().any(|s| s.layer == li && s.point == c.point),
                    })
            })
            .collect()
    }
}

/// The points of one layer, serialised as three parallel arrays.
struct LayerView<'a> {
    part: &'a SlicedPart,
    layer: usize,
}

impl Serialize for LayerView<'_> {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        let layer = &self.part.path.layers[self.layer];
        let frames = &self.part.axes.frames[self.layer];
        let points: Vec<[f64; 3]> = layer
            .points
            .iter()
            .map(|p| [p.position.x, p.position.y, p.position.z])
            .collect();
        let axes: Vec<[f64; 3]> = frames
            .iter()
            .map(|f| [f.tool.x, f.tool.y, f.tool.z])
            .collect();
        let delta: Vec<Option<f64>> = layer.points.iter().map(|p| p.delta).collect();
        let mut st = s.serialize_struct("Layer", 4)?;
        st.serialize_field("slice", &layer.slice)?;
        st.serialize_field("points", &points)?;
        st.serialize_field("tool_axis", &axes)?;
        st.serialize_field("delta", &delta)?;
        st.end()
    }
}

impl Serialize for SlicedPart {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        let layers: Vec<LayerView<'_>> = (0..self.path.layers.len())
            .map(|layer| LayerView { part: self, layer })
            .collect();
        let mut m = s.serialize_map(Some(2))?;
        m.serialize_entry("summary", &self.summary())?;
        m.serialize_entry("layers", &layers)?;
        m.end()
    }
}
