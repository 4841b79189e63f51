//! **Report — the interactive 3-D page.** Takes what the stages produced for
//! one part — the sliced [`Path`] (part frame, mm), its tool frames, its
//! [`DistanceMap`], the bead width, the substrate, the process speeds and,
//! for a plan, the cell, the layers and the [`Plan`] — and writes one
//! self-contained HTML file (`report.html`): a small WebGL viewer written for
//! this project, with the data embedded as base64 of little-endian typed
//! arrays. The page loads nothing from the network (no CDN, no external
//! script, style or font) and opens by double-click.
//!
//! What the page shows: the path as polylines coloured by a chosen field
//! (interlayer distance deviation, lean of the tool axis, travel speed,
//! layer; with a plan also `R_Z` and the smallest joint-limit margin) with a
//! legend; tool axes; the substrate and the deposited wall (the bead section
//! swept along the layers) as translucent surfaces; a layer range; hover
//! picking. With a plan: the robot as simple solids between its joint frame
//! origins (computed here with [`RobotModel::chain_state`](crate::robot::model::RobotModel)
//! and [`RobotModel::flange_pose`](crate::robot::model::RobotModel), so the
//! script only draws), the torch and positioner, animated along the plan
//! with live joint values and limit margins, and the plan's violations
//! marked on the path. The whole-cell check's bodies
//! ([`crate::program::cell_check`]: the arm's link capsules, the
//! positioner's table and tilt body, the keep-out boxes) are drawn as the
//! check models them, translucent, moving with the animation; the layer's
//! closest pair is drawn in red (the part's wall when it is one of them)
//! and named with its distance; a collision refusal marks its layer and
//! names its bodies.
//!
//! A second page shows a tube fitted to a mesh ([`write_fit_report`],
//! [`FitReportInput`]): the mesh with its vertices coloured by their
//! distance to the fitted tube (mm, with a legend), the fitted tube as a
//! translucent surface, the substrate, and the fit's figures (RMS and
//! largest distance, radius error per station, wall thickness). Same
//! template, viewer and encodings; `waam fit` writes it.
//!
//! Above [`ReportOptions::max_points`] displayed points (and
//! [`ReportOptions::max_frames`] animation frames) the data is decimated
//! evenly along each layer, and the page says so.
//!
//! ```no_run
//! # fn main() -> Result<(), Box<dyn std::error::Error>> {
//! use waam_slicer::io::part_file::read_part_file;
//! use waam_slicer::path::{distance_map, slice};
//! use waam_slicer::report::{write_report, ReportInput};
//! use waam_slicer::toolaxis::tool_axes;
//!
//! let part = read_part_file("parts/quarter-torus.toml".as_ref())?;
//! let path = slice(&part.tube, &part.substrate, &part.slice_options())?;
//! let axes = tool_axes(&path, Some(&part.tube), Some(&part.substrate), &part.tool_axis)?;
//! let map = distance_map(&path);
//! let input = ReportInput {
//!     substrate: Some(&part.substrate),
//!     ..ReportInput::new(&part.name, &path, &axes.frames, &map, path.delta_mm)
//! };
//! write_report("out/report.html".as_ref(), &input)?;
//! # Ok(())
//! # }
//! ```

mod build;
pub mod cell_view;
mod encode;
mod fit_page;
mod page;
mod substrate;

use crate::geometry::Substrate;
use crate::optimise::{LayerPoints, Plan};
use crate::path::{DistanceMap, Path};
use crate::process::ProcessPlan;
use crate::robot::CellLayout;
use crate::toolaxis::LocalFrame;
use std::io::Write;

use build::report_data;
pub use fit_page::FitReportInput;

const TEMPLATE: &str = include_str!("template.html");
const VIEWER_JS: &str = include_str!("viewer.js");
const VIEWER_CSS: &str = include_str!("viewer.css");

/// Display bounds of a report.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ReportOptions {
    /// Most path points embedded and drawn; above it every layer keeps every
    /// `k`-th point (and its last), `k` the same for the whole path. The
    /// viewer thins tool axes and the wall further, and says by how much.
    pub max_points: usize,
    /// Most animation frames of a plan (planned points at which the cell is
    /// embedded); above it every `k`-th planned point (and the last).
    pub max_frames: usize,
    /// Most violation markers embedded (the rest are counted).
    pub max_marks: usize,
}

impl Default for ReportOptions {
    fn default() -> Self {
        Self {
            max_points: 200_000,
            max_frames: 2_000,
            max_marks: 2_000,
        }
    }
}

/// A corner of a layer marked on the path ([`crate::path::Layer::corners`]),
/// and whether the plan split the layer's bead there.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CornerMark {
    /// Layer index in the report's path.
    pub layer: usize,
    /// The layer's point where it turns most within the corner.
    pub point: usize,
    /// Turning angle of the polyline across the corner (deg).
    pub turning_deg: f64,
    /// The layer's seam lies on the corner.
    pub on_seam: bool,
    /// The plan split the layer's bead here: one bead ends on the point and
    /// the next starts on it ([`crate::optimise::split`]).
    pub split: bool,
}

/// A plan to show in the report: the cell it was made in, the layers it was
/// made from (`optimise::layer_points` of the report's path and frames) and
/// the plan.
#[derive(Debug, Clone, Copy)]
pub struct PlanView<'a> {
    /// The cell (robot base frame, mm).
    pub cell: &'a CellLayout,
    /// The layers of the plan, one per path layer, same points (part frame).
    pub layers: &'a [LayerPoints],
    /// The plan made from `layers` in `cell`.
    pub plan: &'a Plan,
    /// Programmed travel speed (mm/s), for the animation's clock where the
    /// report has no per-point process speeds.
    pub travel_speed_mm_s: f64,
    /// The program's cycle time (s, per layer and for the build), shown
    /// beside the animation's clock; `None` without a program.
    pub cycle: Option<&'a crate::program::cycle::CycleTime>,
    /// The cell's `[[keep_out]]` boxes (robot base frame, mm), drawn with
    /// the check's other bodies ([`crate::program::cell_check`]).
    pub keep_out: &'a [crate::program::cell_check::KeepOut],
    /// The whole-cell check's closest approach per layer, shown per layer
    /// with its two bodies highlighted; `None` when the check did not run
    /// or refused the program.
    pub clearance: Option<&'a crate::program::cell_check::CellClearance>,
    /// The program stage's refusal, if any: a
    /// [`ProgramError::Collision`](crate::program::ProgramError::Collision)
    /// marks its layer and highlights its two bodies.
    pub refusal: Option<&'a crate::program::ProgramError>,
}

/// Everything a report shows. Geometry is in the part frame (mm) except the
/// cell, which is in the robot base frame (mm).
#[derive(Debug, Clone, Copy)]
pub struct ReportInput<'a> {
    /// Page title (the part's name, say).
    pub title: &'a str,
    /// The sliced path (part frame, mm).
    pub path: &'a Path,
    /// Tool frames, one per path point, layer by layer (`ToolAxes::frames`).
    pub frames: &'a [Vec<LocalFrame>],
    /// Local interlayer distances of `path` (`path::distance_map`).
    pub map: &'a DistanceMap,
    /// Bead width (mm) for the drawn wall: the section spans ±width/2 along
    /// the surface normal and reaches down by the local distance to the layer
    /// below (`Delta` on the first layer), as `io::wall_stl`.
    pub bead_width_mm: f64,
    /// The substrate, drawn as a translucent surface around the part (a plane
    /// as a square, a cylinder as a band; a mesh substrate is not drawn).
    pub substrate: Option<&'a Substrate>,
    /// Per-point process (travel speeds, mm/s), from `process::plan_process`.
    pub process: Option<&'a ProcessPlan>,
    /// A plan to animate.
    pub plan: Option<PlanView<'a>>,
    /// The layers' corners (and the plan's bead splits), marked on the
    /// path; empty: none marked.
    pub corners: &'a [CornerMark],
    /// Display bounds.
    pub options: ReportOptions,
}

impl<'a> ReportInput<'a> {
    /// A slice report: no substrate, process or plan, default bounds.
    pub fn new(
        title: &'a str,
        path: &'a Path,
        frames: &'a [Vec<LocalFrame>],
        map: &'a DistanceMap,
        bead_width_mm: f64,
    ) -> Self {
        Self {
            title,
            path,
            frames,
            map,
            bead_width_mm,
            substrate: None,
            process: None,
            plan: None,
            corners: &[],
            options: ReportOptions::default(),
        }
    }
}

/// Why a report could not be built or written.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ReportError {
    /// An input does not match the path's layers or points.
    #[error("report: {what} has {got} {unit} where the path has {expected}{}", layer_suffix(*.layer))]
    Shape {
        /// Which input (`frames`, `distance map`, `process`, `plan layers`, `plan`).
        what: &'static str,
        /// The layer, for a per-layer point count.
        layer: Option<usize>,
        /// What the path has.
        expected: usize,
        /// What the input has.
        got: usize,
        /// `layers` or `points`.
        unit: &'static str,
    },
    /// A coordinate or vector that is not finite.
    #[error("report: layer {layer}, point {point}: {what} is not finite")]
    NonFinite {
        /// Which value (`position`, `tool axis`, ...).
        what: &'static str,
        /// Layer index.
        layer: usize,
        /// Point index within the layer.
        point: usize,
    },
    /// An option or size out of its range.
    #[error("report: {field} = {value} {reason}")]
    InvalidOption {
        /// Field name.
        field: &'static str,
        /// Its value.
        value: f64,
        /// What is wrong.
        reason: &'static str,
    },
    /// The path has no point.
    #[error("report: the path has no point")]
    EmptyPath,
    /// A fit's distances do not match its mesh's vertices.
    #[error("report: {file}: the fit has {distances} vertex distances where the mesh has {vertices} vertices")]
    FitMismatch {
        /// The mesh file.
        file: String,
        /// Vertices of the mesh.
        vertices: usize,
        /// Distances of the fit.
        distances: usize,
    },
    /// A mesh vertex that is not finite.
    #[error("report: {file}: vertex {vertex} is not finite")]
    NonFiniteVertex {
        /// The mesh file.
        file: String,
        /// Index of the vertex.
        vertex: usize,
    },
    /// The page data could not be encoded as JSON.
    #[error("report: encoding the page data: {0}")]
    Encode(#[source] std::sync::Arc<serde_json::Error>),
    /// Writing the page failed.
    #[error("report: writing {file}: {source}")]
    Io {
        /// The file (or `<writer>`).
        file: String,
        /// The I/O error.
        source: std::io::Error,
    },
}

fn layer_suffix(layer: Option<usize>) -> String {
    layer.map(|l| format!(" (layer {l})")).unwrap_or_default()
}

/// Writes the report page to `w`.
///
/// # Errors
/// [`ReportError::Shape`], [`ReportError::NonFinite`],
/// [`ReportError::InvalidOption`], [`ReportError::EmptyPath`] for bad input
/// (nothing is written then); [`ReportError::Io`] if `w` fails.
pub fn write_report_html(w: &mut dyn Write, input: &ReportInput) -> Result<(), ReportError> {
    let data = report_data(input)?;
    write_page(w, input.title, &data).map_err(|source| ReportError::Io {
        file: "<writer>".into(),
        source,
    })
}

/// The report page as a string (see [`write_report_html`]).
///
/// # Errors
/// As [`write_report_html`].
pub fn report_html(input: &ReportInput) -> Result<String, ReportError> {
    let mut out = Vec::new();
    write_report_html(&mut out, input)?;
    // Every piece written is UTF-8 (template, escaped strings, base64).
    String::from_utf8(out).map_err(|e| ReportError::Io {
        file: "<string>".into(),
        source: std::io::Error::other(e),
    })
}

/// Writes the report to `dest` atomically (temporary file, then rename):
/// bad input leaves no file and an old report untouched.
///
/// # Errors
/// As [`write_report_html`]; [`ReportError::Io`] names `dest`.
pub fn write_report(dest: &std::path::Path, input: &ReportInput) -> Result<(), ReportError> {
    let data = report_data(input)?;
    crate::util::atomic::write_atomic(dest, |w| write_page(w, input.title, &data)).map_err(
        |source| ReportError::Io {
            file: dest.display().to_string(),
            source,
        },
    )
}

/// Writes the page of a mesh fit to `w`: the mesh coloured by the distance
/// of its vertices to the fitted tube, the fitted tube, the substrate and
/// the fit's figures (see [`FitReportInput`]).
///
/// # Errors
/// [`ReportError::FitMismatch`], [`ReportError::NonFiniteVertex`],
/// [`ReportError::InvalidOption`] for bad input (nothing is written then);
/// [`ReportError::Io`] if `w` fails.
pub fn write_fit_report_html(w: &mut dyn Write, input: &FitReportInput) -> Result<(), ReportError> {
    let data = fit_page::fit_data(input)?;
    write_page(w, input.title, &data).map_err(|source| ReportError::Io {
        file: "<writer>".into(),
        source,
    })
}

/// Writes the page of a mesh fit to `dest` atomically (temporary file, then
/// rename): bad input leaves no file and an old page untouched.
///
/// # Errors
/// As [`write_fit_report_html`]; [`ReportError::Io`] names `dest`.
pub fn write_fit_report(dest: &std::path::Path, input: &FitReportInput) -> Result<(), ReportError> {
    let data = fit_page::fit_data(input)?;
    crate::util::atomic::write_atomic(dest, |w| write_page(w, input.title, &data)).map_err(
        |source| ReportError::Io {
            file: dest.display().to_string(),
            source,
        },
    )
}

/// Fills the template: `{{TITLE}}` (HTML-escaped), `{{CSS}}`, `{{DATA}}`
/// (JSON, `<` escaped) and `{{JS}}`.
fn write_page(w: &mut dyn Write, title: &str, data: &str) -> std::io::Result<()> {
    let mut rest = TEMPLATE;
    while let Some(start) = rest.find("{{") {
        let end = start
            + rest[start..]
                .find("}}")
                .ok_or_else(|| std::io::Error::other("report template: unclosed {{"))?;
        w.write_all(&rest.as_bytes()[..start])?;
        match &rest[start + 2..end] {
            "TITLE" => w.write_all(encode::html_escape(title).as_bytes())?,
            "CSS" => w.write_all(VIEWER_CSS.as_bytes())?,
            "JS" => w.write_all(VIEWER_JS.as_bytes())?,
            "DATA" => w.write_all(data.as_bytes())?,
            other => {
                return Err(std::io::Error::other(format!(
                    "report template: unknown slot {{{{{other}}}}}"
                )))
            }
        }
        rest = &rest[end + 2..];
    }
    w.write_all(rest.as_bytes())
}

#[cfg(test)]
mod tests;
