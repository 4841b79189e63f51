//! The fit page: the mesh a tube was fitted to ([`TubeMesh`], mesh frame =
//! part frame, mm), its vertices coloured by their distance to the fitted
//! surface, the fitted tube as a translucent surface around its guide, the
//! substrate, and the fit's figures ([`FitReport`]: RMS, largest distance,
//! radius error per station, wall thickness). Same template, viewer and
//! encodings as the path's page: the page data's path is the fitted guide
//! (one layer) and its `fit` object holds the mesh.

use super::encode::{f32s, i8s, u32s, unit_i8};
use super::page::{script_safe_json, stride, FieldData, FitData, PageData};
use super::substrate::substrate_triangles;
use super::ReportError;
use crate::fit::section::plane_basis;
use crate::fit::{TubeFit, TubeMesh};
use crate::geometry::guide::GuideCurve;
use crate::geometry::Substrate;
use crate::math::{Point3, UnitVector3, Vector3};

/// Points of the fitted guide drawn (and coloured by the radius law).
const GUIDE_POINTS: usize = 200;
/// Points around each ring of the drawn fitted surface.
const AROUND: usize = 48;

/// A fit to show in a page: the mesh, the tube fitted to it, and the
/// substrate. Geometry in the mesh frame (= part frame, mm).
#[derive(Debug, Clone, Copy)]
pub struct FitReportInput<'a> {
    /// Page title (the part's name, say).
    pub title: &'a str,
    /// The mesh the tube was fitted to.
    pub mesh: &'a TubeMesh,
    /// The fit of `mesh` ([`fit_tube`](crate::fit::fit_tube)): guide, laws,
    /// one distance per mesh vertex, report.
    pub fit: &'a TubeFit,
    /// The substrate the written part stands on (a plane as a square, a
    /// cylinder as a band, a mesh as its triangles); `None`: the fit's
    /// start plane ([`TubeFit::substrate_point`], [`TubeFit::substrate_normal`]).
    pub substrate: Option<&'a Substrate>,
    /// Most mesh triangles drawn; above it every `k`-th triangle is drawn
    /// (the page says so). Every vertex and its distance are embedded.
    pub max_triangles: usize,
}

impl<'a> FitReportInput<'a> {
    /// A fit page with the fit's own start plane as the substrate and up to
    /// 400 000 triangles drawn.
    pub fn new(title: &'a str, mesh: &'a TubeMesh, fit: &'a TubeFit) -> Self {
        Self {
            title,
            mesh,
            fit,
            substrate: None,
            max_triangles: 400_000,
        }
    }
}

/// Triangles (9 floats each, mm) of the fitted surface: rings along the
/// guide from `t_min` to `t_max`, the frames carried along by projection
/// (no twist); both skins for a fitted wall.
fn tube_triangles(fit: &TubeFit) -> Vec<f32> {
    let guide = fit.guide();
    let (t0, t1) = (fit.t_min, fit.t_max);
    let r_mean = 0.5 * (fit.report.radius_min_mm + fit.report.radius_max_mm);
    let rings = ((t1 - t0) / (0.5 * r_mean).max(0.5))
        .ceil()
        .clamp(16.0, 400.0) as usize;
    let mut frames: Vec<(f64, Point3, Vector3, Vector3)> = Vec::with_capacity(rings + 1);
    for i in 0..=rings {
        let t = t0 + (t1 - t0) * i as f64 / rings as f64;
        let tan = UnitVector3::new_normalize(guide.d1(t));
        let tv = tan.into_inner();
        let e1 = match frames.last() {
            Some((_, _, prev, _)) => (prev - tv * prev.dot(&tv))
                .try_normalize(1e-9)
                .unwrap_or_else(|| plane_basis(&tan).0),
            None => plane_basis(&tan).0,
        };
        frames.push((t, guide.point(t), e1, tv.cross(&e1)));
    }
    let offsets: Vec<f64> = match fit.thickness_mm {
        Some(_) => vec![-0.5, 0.5],
        None => vec![0.0],
    };
    let mut out = Vec::with_capacity(offsets.len() * rings * AROUND * 18);
    for side in offsets {
        let ring = |i: usize| -> Vec<Point3> {
            let (t, c, e1, e2) = &frames[i];
            let r = fit.radius(*t) + side * fit.wall_thickness(*t).unwrap_or(0.0);
            (0..AROUND)
                .map(|j| {
                    let a = std::f64::consts::TAU * j as f64 / AROUND as f64;
                    c + (e1 * a.cos() + e2 * a.sin()) * r
                })
                .collect()
        };
        let mut lower = ring(0);
        for i in 1..=rings {
            let upper = ring(i);
            for j in 0..AROUND {
                let k = (j + 1) % AROUND;
                for p in [lower[j], lower[k], upper[k], lower[j], upper[k], upper[j]] {
                    out.extend([p.x as f32, p.y as f32, p.z as f32]);
                }
            }
            lower = upper;
        }
    }
    out
}

/// Triangles (9 floats each, mm) of a mesh substrate, every `k`-th to stay
/// within `max` triangles.
fn mesh_substrate_triangles(sub: &Substrate, max: usize) -> Option<Vec<f32>> {
    let Substrate::Mesh(m) = sub else { return None };
    let tris = m.triangles();
    let k = stride(tris.len(), max);
    Some(
        tris.iter()
            .step_by(k)
            .flat_map(|t| t.iter().flat_map(|p| [p.x as f32, p.y as f32, p.z as f32]))
            .collect(),
    )
}

/// Builds the fit page's data object (JSON text).
pub(super) fn fit_data(input: &FitReportInput) -> Result<String, ReportError> {
    let (mesh, fit) = (input.mesh, input.fit);
    if input.max_triangles < 2 {
        return Err(ReportError::InvalidOption {
            field: "max_triangles",
            value: input.max_triangles as f64,
            reason: "must be at least 2",
        });
    }
    if fit.vertex_distance_mm.len() != mesh.vertices.len() {
        return Err(ReportError::FitMismatch {
            file: mesh.file.clone(),
            vertices: mesh.vertices.len(),
            distances: fit.vertex_distance_mm.len(),
        });
    }
    if let Some(v) = mesh
        .vertices
        .iter()
        .position(|p| !p.coords.iter().all(|c| c.is_finite()))
    {
        return Err(ReportError::NonFiniteVertex {
            file: mesh.file.clone(),
            vertex: v,
        });
    }
    let guide = fit.guide();
    let n = GUIDE_POINTS;
    let (mut pos, mut tool, mut normal) = (vec![], vec![], vec![]);
    let (mut radius, mut wall) = (vec![], vec![]);
    for i in 0..n {
        let t = fit.t_min + (fit.t_max - fit.t_min) * i as f64 / (n - 1) as f64;
        let p = guide.point(t);
        let tan = UnitVector3::new_normalize(guide.d1(t));
        let (e1, _) = plane_basis(&tan);
        pos.extend([p.x as f32, p.y as f32, p.z as f32]);
        tool.extend([unit_i8(tan.x), unit_i8(tan.y), unit_i8(tan.z)]);
        normal.extend([unit_i8(e1.x), unit_i8(e1.y), unit_i8(e1.z)]);
        radius.push(fit.radius(t) as f32);
        if let Some(e) = fit.wall_thickness(t) {
            wall.push(e as f32);
        }
    }
    let distance: Vec<f32> = fit
        .vertex_distance_mm
        .iter()
        .map(|d| d.map_or(f32::NAN, |d| d as f32))
        .collect();
    let mut fields = vec![
        FieldData {
            key: "distance",
            name: "distance of the mesh to the fitted tube",
            unit: "mm",
            diverging: false,
            min_half_range: 0.0,
            data: f32s(&distance),
            mesh: true,
        },
        FieldData {
            key: "radius",
            name: "fitted radius A(t) along the guide",
            unit: "mm",
            diverging: false,
            min_half_range: 0.0,
            data: f32s(&radius),
            mesh: false,
        },
    ];
    if !wall.is_empty() {
        fields.push(FieldData {
            key: "wall",
            name: "fitted wall thickness along the guide",
            unit: "mm",
            diverging: false,
            min_half_range: 0.0,
            data: f32s(&wall),
            mesh: false,
        });
    }
    let total = mesh.triangles.len();
    let k = stride(total, input.max_triangles);
    let drawn: Vec<u32> = mesh
        .triangles
        .iter()
        .step_by(k)
        .flatten()
        .copied()
        .collect();
    let mut notes = vec![];
    if k > 1 {
        notes.push(format!(
            "{total} triangles: every {k}th is drawn ({}); every vertex keeps its distance.",
            drawn.len() / 3
        ));
    }
    if fit.vertex_distance_mm.iter().any(Option::is_none) {
        notes.push(
            "Grey vertices were left out of the fit (flat caps, stray pieces): no distance.".into(),
        );
    }
    let own_plane = Substrate::Plane {
        point: fit.substrate_point,
        normal: fit.substrate_normal,
    };
    let substrate = input.substrate.unwrap_or(&own_plane);
    let substrate_tris = match mesh_substrate_triangles(substrate, input.max_triangles) {
        Some(t) => Some(t),
        None => substrate_triangles(Some(substrate), &pos).0,
    };
    let vertices: Vec<f32> = mesh
        .vertices
        .iter()
        .flat_map(|p| [p.x as f32, p.y as f32, p.z as f32])
        .collect();
    let data = PageData {
        version: 1,
        title: input.title,
        strategy: "fitted guide",
        delta_mm: 1.0,
        bead_width_mm: 1.0,
        points_total: n,
        points_shown: n,
        stride: 1,
        length_mm: fit.report.length_mm,
        layer_slice: vec![0],
        layer_closed: vec![0],
        layer_points: vec![n],
        layer_start: u32s(&[0, n as u32]),
        pos: f32s(&pos),
        build: i8s(&tool),
        tool: i8s(&tool),
        normal: i8s(&normal),
        fields,
        substrate: substrate_tris.map(|t| f32s(&t)),
        marks: vec![],
        marks_total: 0,
        corners: Vec::new(),
        plan: None,
        notes,
        fit: Some(FitData {
            file: &mesh.file,
            vertices_total: mesh.vertices.len(),
            triangles_total: total,
            triangles_shown: drawn.len() / 3,
            triangle_stride: k,
            vertices: f32s(&vertices),
            triangles: u32s(&drawn),
            tube: f32s(&tube_triangles(fit)),
            report: &fit.report,
        }),
    };
    script_safe_json(&data)
}
