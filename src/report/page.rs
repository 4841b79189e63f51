//! The page contract: the data object every page of the report embeds
//! (`report.html`'s JSON, read by `viewer.js`) and its parts, how much of
//! the data a page shows (decimation), and how the object is written into
//! the page. The path's page (`build`) and the fit page (`fit_page`) fill
//! it; it imports neither.

use serde::Serialize;

use super::ReportError;
use crate::fit::FitReport;
use crate::program::cell_check::OutlineKind;

/// Indices kept of a run of `n` points with stride `k`: `0, k, 2k, ...` and `n − 1`.
pub(crate) fn kept(n: usize, k: usize) -> impl Iterator<Item = usize> {
    let k = k.max(1);
    let last = n.saturating_sub(1);
    (0..n)
        .step_by(k)
        .chain((n > 0 && last % k != 0).then_some(last))
}

/// The stride that keeps at most about `bound` of `total` points.
pub(crate) fn stride(total: usize, bound: usize) -> usize {
    total.div_ceil(bound.max(1)).max(1)
}

/// The page's data object (`report.html`'s embedded JSON): the path drawn
/// (part frame, mm; base64 typed arrays), its colour fields, marks, notes
/// and the plan's animation data.
/// A fit page (`fit_page`) fills the same object: its path is the fitted
/// guide (one layer) and `fit` holds the mesh.
#[derive(Serialize)]
pub(super) struct PageData<'a> {
    pub version: u32,
    pub title: &'a str,
    pub strategy: &'static str,
    pub delta_mm: f64,
    pub bead_width_mm: f64,
    pub points_total: usize,
    pub points_shown: usize,
    pub stride: usize,
    pub length_mm: f64,
    pub layer_slice: Vec<usize>,
    pub layer_closed: Vec<u8>,
    pub layer_points: Vec<usize>,
    /// Base64 `Uint32Array`: each layer's first drawn point, then the total.
    pub layer_start: String,
    /// Base64 `Float32Array`: drawn points, xyz (mm).
    pub pos: String,
    /// Base64 `Int8Array`s: unit vectors × 127.
    pub tool: String,
    pub normal: String,
    pub build: String,
    pub fields: Vec<FieldData>,
    /// Base64 `Float32Array` of the substrate's triangles, `null` if none.
    pub substrate: Option<String>,
    pub marks: Vec<MarkData<'a>>,
    pub marks_total: usize,
    /// The layers' corners and the plan's bead splits.
    pub corners: Vec<CornerData>,
    pub plan: Option<PlanData<'a>>,
    pub notes: Vec<String>,
    /// The mesh of a fit page (absent from a path's page).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub fit: Option<FitData<'a>>,
}

/// A colour field: one value per drawn point (base64 `Float32Array`), or
/// with `mesh` one per vertex of a fit page's mesh.
#[derive(Serialize)]
pub(super) struct FieldData {
    pub key: &'static str,
    pub name: &'static str,
    pub unit: &'static str,
    pub diverging: bool,
    pub min_half_range: f64,
    pub data: String,
    /// The values colour the fit page's mesh vertices, not the path.
    #[serde(skip_serializing_if = "std::ops::Not::not")]
    pub mesh: bool,
}

/// A marked point (a violation).
#[derive(Serialize)]
pub(super) struct MarkData<'a> {
    pub layer: usize,
    pub point: usize,
    pub text: &'a str,
    /// Part frame (mm).
    pub at: [f64; 3],
}

/// A layer's corner (or a bead split on it), marked on the path.
#[derive(Serialize)]
pub(super) struct CornerData {
    pub layer: usize,
    pub point: usize,
    pub split: bool,
    pub text: String,
    /// Part frame (mm).
    pub at: [f64; 3],
}

/// The plan's part of the page data: the cell, limits (deg) and the cell at
/// every animation frame (base64 typed arrays).
#[derive(Serialize)]
pub(super) struct PlanData<'a> {
    pub cell_kind: &'static str,
    pub cell: &'a str,
    pub robot: &'a str,
    pub reach_mm: f64,
    /// `[lower, upper]` per axis (J1–J6, then J7–J8 with a positioner), deg.
    pub limits_deg: Vec<[f64; 2]>,
    /// `null` in a part-carried cell.
    pub max_hose_deg: Option<f64>,
    pub feasible: bool,
    pub infeasible_layers: Vec<usize>,
    pub frames: usize,
    pub points_total: usize,
    pub frame_stride: usize,
    pub duration_s: f64,
    /// The program's cycle time (s; `null` without a program).
    pub cycle_time_s: Option<f64>,
    /// Each bead's layer number and its share of the cycle time (s).
    pub cycle_layers: Vec<usize>,
    pub cycle_layer_s: Vec<f64>,
    pub f_layer: String,
    pub f_point: String,
    pub f_time: String,
    pub f_rz: String,
    pub f_joints: String,
    pub f_chain: String,
    pub f_torch: String,
    pub f_table: String,
    pub f_part: String,
    /// The whole-cell check's bodies (robot base frame, mm), as
    /// [`crate::program::cell_check`] models them: the moving ones first
    /// (their ends per frame in `f_bodies`), then the fixed ones.
    pub bodies: Vec<BodyData>,
    /// Base64 `Float32Array`: per frame, the ends `a`, `b` of every moving
    /// body of `bodies` (6 floats a body; NaN without joints), base frame (mm).
    pub f_bodies: String,
    /// Per plan layer (the index of `f_layer`): the whole-cell check's
    /// closest approach and pair; empty when the check did not run.
    pub closest: Vec<ClosestData>,
    /// The program's collision refusal, `null` without one.
    pub collision: Option<CollisionData>,
    /// The name the check gives the part (its wall so far).
    pub part_body: &'static str,
}

/// One body of the whole-cell check (robot base frame, mm).
#[derive(Serialize)]
pub(super) struct BodyData {
    pub name: String,
    pub kind: OutlineKind,
    pub radius_mm: f64,
    /// `true`: its ends are per frame in `f_bodies`; else in `a`, `b`.
    pub moving: bool,
    /// Segment end or lower corner of a fixed body (mm).
    pub a: Option<[f64; 3]>,
    /// Segment end or upper corner of a fixed body (mm).
    pub b: Option<[f64; 3]>,
}

/// A layer's closest approach (`CellClearance`'s `LayerCellClearance`).
#[derive(Serialize, Debug, Clone, PartialEq)]
pub(crate) struct ClosestData {
    /// The layer's number (`LayerPoints::layer`).
    pub layer: usize,
    /// Closest approach (mm; `null` when no pair was measured).
    pub distance_mm: Option<f64>,
    /// The two bodies, as the check names them.
    pub pair: Option<[String; 2]>,
}

/// A collision refusal (`ProgramError::Collision`).
#[derive(Serialize)]
pub(super) struct CollisionData {
    /// Index of the layer in the plan (`f_layer`'s numbering), `null` if
    /// the refused layer is not one of the plan's.
    pub layer_index: Option<usize>,
    pub layer: usize,
    pub point: Option<usize>,
    pub motion: &'static str,
    pub body_a: String,
    pub body_b: String,
    pub distance_mm: f64,
    pub clearance_mm: f64,
    /// The refusal's message.
    pub text: String,
}

/// `value` as JSON text that can sit inside a `<script>` element: `<`, `>`,
/// `&` and the line separators U+2028/U+2029 (only ever inside strings) are
/// written as `\u00XX` escapes. Non-finite numbers are `null`.
pub(crate) fn script_safe_json(value: &impl Serialize) -> Result<String, ReportError> {
    let text =
        serde_json::to_string(value).map_err(|e| ReportError::Encode(std::sync::Arc::new(e)))?;
    let mut out = String::with_capacity(text.len());
    for c in text.chars() {
        match c {
            '<' | '>' | '&' | '\u{2028}' | '\u{2029}' => {
                out.push_str(&format!("\\u{:04x}", c as u32));
            }
            c => out.push(c),
        }
    }
    Ok(out)
}

/// The `fit` object of the page data: the mesh (base64 typed arrays, mesh
/// frame, mm), the fitted surface's triangles and the fit report.
#[derive(Serialize)]
pub(super) struct FitData<'a> {
    pub file: &'a str,
    pub vertices_total: usize,
    pub triangles_total: usize,
    pub triangles_shown: usize,
    pub triangle_stride: usize,
    /// Base64 `Float32Array`: every vertex, xyz (mm).
    pub vertices: String,
    /// Base64 `Uint32Array`: the drawn triangles' vertex indices.
    pub triangles: String,
    /// Base64 `Float32Array`: triangles of the fitted surface (9 floats each).
    pub tube: String,
    pub report: &'a FitReport,
}
