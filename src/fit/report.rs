//! The fit report's builder: how far the mesh is from the fitted tube, per
//! station and overall (mm), the radius errors, the wall thickness, as a
//! [`FitReport`] (the `fit.json` that `waam fit` writes; every number is
//! finite).

use super::ends::OBLIQUE_TILT_DEG;
use super::outcome::EndKind;
use super::outcome::{EndReport, EndRing, FitReport, Station, StationReport, TubeFit, WallReport};
use super::section::plane_basis;
use super::smooth;
use super::topology::Surfaces;
use super::TubeMesh;
use crate::geometry::guide::GuideCurve;
use crate::math::{Point3, UnitVector3};
use parry3d_f64::query::PointQuery;
use parry3d_f64::shape::TriMesh;
use rayon::prelude::*;

/// What the report is built from.
pub(super) struct Context<'a> {
    pub mesh: &'a TubeMesh,
    pub surfaces: &'a Surfaces,
    pub samples_pos: &'a [Point3],
    pub samples_skin: &'a [u8],
    pub outer: usize,
    pub t: &'a [f64],
    pub stations: &'a [Station],
    pub start: &'a EndRing,
    pub finish: &'a EndRing,
    pub iterations: usize,
    pub converged: bool,
    pub last_move_mm: f64,
    pub check_surface: bool,
}

fn end(e: &EndRing) -> EndReport {
    let (shape, station, t_mm) = e.shape.map_or((None, 0, 0.0), |(s, i, t)| (Some(s), i, t));
    let tilt_deg = shape.map_or(0.0, |s| s.tilt.to_degrees());
    EndReport {
        centre_mm: e.centre.coords.into(),
        normal: e.normal.into_inner().into(),
        radius_mm: shape.map_or(e.radius, |s| s.radius),
        capped: e.capped,
        kind: shape.map_or(EndKind::Open, |s| s.kind),
        oblique: tilt_deg > OBLIQUE_TILT_DEG,
        tilt_deg,
        station,
        t_mm,
    }
}

/// Builds the report of `fit` (whose `report` is not read), and the
/// distance (mm) of every mesh vertex to the fitted surface (`None` for a
/// vertex of no skin: a cap, a stray piece).
pub(super) fn build(cx: &Context<'_>, fit: &TubeFit) -> (FitReport, Vec<Option<f64>>) {
    let guide = fit.guide();
    let len = fit.length();
    let m_r = smooth::natural_second_derivatives(&fit.knots, &fit.radius_mm);
    let radius = |t: f64| smooth::eval(&fit.knots, &fit.radius_mm, &m_r, t);
    let thick = fit.thickness_mm.as_ref().map(|e| {
        let m = smooth::natural_second_derivatives(&fit.knots, e);
        move |t: f64| smooth::eval(&fit.knots, e, &m, t)
    });
    let skin_radius = |skin: u8, t: f64| match &thick {
        Some(e) if skin as usize == cx.outer => radius(t) + 0.5 * e(t),
        Some(e) => radius(t) - 0.5 * e(t),
        None => radius(t),
    };
    // Distance of each vertex to the fitted surface: past an end, to the
    // surface as the part extends it (the substrate, not the end's normal
    // plane, cuts the built tube).
    let dist: Vec<f64> = cx
        .samples_pos
        .par_iter()
        .zip(cx.t.par_iter())
        .zip(cx.samples_skin.par_iter())
        .map(|((p, &t), &skin)| ((p - guide.point(t)).norm() - skin_radius(skin, t)).abs())
        .collect();
    // The samples are the skins' vertices, skin after skin (`driver::samples`).
    let mut per_vertex = vec![None; cx.mesh.vertices.len()];
    let skin_vertices = cx.surfaces.skins.iter().flat_map(|s| s.vertices.iter());
    for (&v, &d) in skin_vertices.zip(&dist) {
        if let Some(slot) = per_vertex.get_mut(v as usize) {
            *slot = Some(d);
        }
    }
    let n = cx.stations.len();
    let step = len / (n - 1).max(1) as f64;
    let mut sums = vec![(0.0, 0usize); n];
    for (&t, &d) in cx.t.iter().zip(&dist) {
        let i = (((t - fit.t_min) / step).round().max(0.0) as usize).min(n - 1);
        sums[i].0 += d * d;
        sums[i].1 += 1;
    }
    let (imax, max) = dist
        .iter()
        .copied()
        .enumerate()
        .fold((0, 0.0), |a, (i, d)| if d > a.1 { (i, d) } else { a });
    let rms = (dist.iter().map(|d| d * d).sum::<f64>() / dist.len().max(1) as f64).sqrt();
    let stations: Vec<StationReport> = cx
        .stations
        .iter()
        .enumerate()
        .map(|(i, s)| {
            let law = radius(s.t);
            let worst = s
                .fits
                .iter()
                .flatten()
                .map(|f| f.rms)
                .fold(None, |a: Option<f64>, r| Some(a.map_or(r, |a| a.max(r))));
            StationReport {
                index: i,
                t_mm: s.t,
                points: s.points,
                centre_mm: s.centre.map(|c| c.coords.into()),
                section_radius_mm: s.radius,
                law_radius_mm: law,
                radius_error_mm: s.radius.map(|r| law - r),
                section_rms_mm: worst,
                vertex_rms_mm: (sums[i].0 / sums[i].1.max(1) as f64).sqrt(),
                wall_thickness_mm: s.thickness,
                law_thickness_mm: thick.as_ref().map(|e| e(s.t)),
            }
        })
        .collect();
    let wall = thick.as_ref().map(|e| {
        let v: Vec<f64> = stations.iter().map(|s| e(s.t_mm)).collect();
        WallReport {
            mean_mm: v.iter().sum::<f64>() / v.len().max(1) as f64,
            min_mm: v.iter().copied().fold(f64::INFINITY, f64::min),
            max_mm: v.iter().copied().fold(f64::NEG_INFINITY, f64::max),
        }
    });
    let surface = cx
        .check_surface
        .then(|| surface_to_mesh(cx, &guide, &stations, &skin_radius))
        .flatten();
    let report = FitReport {
        file: cx.mesh.file.clone(),
        triangles: cx.mesh.triangles.len(),
        vertices: cx.samples_pos.len(),
        skins: cx.surfaces.skins.len(),
        caps: cx.surfaces.caps.len(),
        ignored_triangles: cx.surfaces.ignored_triangles,
        start: end(cx.start),
        end: end(cx.finish),
        iterations: cx.iterations,
        converged: cx.converged,
        last_move_mm: if cx.last_move_mm.is_finite() {
            cx.last_move_mm
        } else {
            0.0
        },
        length_mm: len,
        guide_points: fit.guide_points.len(),
        radius_min_mm: fit.radius_mm.iter().copied().fold(f64::INFINITY, f64::min),
        radius_max_mm: fit
            .radius_mm
            .iter()
            .copied()
            .fold(f64::NEG_INFINITY, f64::max),
        rms_mm: rms,
        max_mm: max,
        max_at_mm: cx
            .samples_pos
            .get(imax)
            .map_or([0.0; 3], |p| p.coords.into()),
        surface_to_mesh_max_mm: surface,
        substrate_distance_mm: None,
        wall,
        stations,
        repair: Default::default(),
        units: Default::default(),
        warnings: Vec::new(),
        features: Vec::new(),
    };
    (report, per_vertex)
}

/// Largest distance (parry3d) from samples of the fitted surface (every
/// station, 36 profile angles, each skin) to the mesh.
fn surface_to_mesh(
    cx: &Context<'_>,
    guide: &crate::geometry::guide::CubicSpline,
    stations: &[StationReport],
    skin_radius: &(dyn Fn(u8, f64) -> f64 + Sync),
) -> Option<f64> {
    let trimesh = TriMesh::new(cx.mesh.vertices.clone(), cx.mesh.triangles.clone()).ok()?;
    let skins = cx.surfaces.skins.len() as u8;
    let samples: Vec<Point3> = stations
        .iter()
        .flat_map(|s| {
            let tan = UnitVector3::new_normalize(guide.d1(s.t_mm));
            let (e1, e2) = plane_basis(&tan);
            let c = guide.point(s.t_mm);
            (0..skins).flat_map(move |k| {
                (0..36).map(move |j| {
                    let v = std::f64::consts::TAU * j as f64 / 36.0;
                    c + (e1 * v.cos() + e2 * v.sin()) * skin_radius(k, s.t_mm)
                })
            })
        })
        .collect();
    let d = samples
        .par_iter()
        .map(|p| trimesh.distance_to_local_point(p, false))
        .reduce(|| 0.0, f64::max);
    d.is_finite().then_some(d)
}
