//! **Repair of what exporters leave**, before the fit (mesh frame, mm):
//! vertices closer than a tolerance scaled to the mesh are welded (duplicated
//! seam vertices), triangles of zero area or a repeated vertex are dropped,
//! and separate pieces holding under [`SMALL_PIECE_AREA_FRACTION`] of the
//! area are left out and named. Winding and normals are not read: the fit
//! uses positions and edges only, so an inconsistent winding or inward
//! normals need no repair.

use super::outcome::LeftOut;
use super::TubeMesh;
use crate::math::{Point3, Vector3};
use std::collections::HashMap;

/// Weld tolerance, as a fraction of the bounding box's diagonal
/// (dimensionless): far below any exporter's edge length (a 100 mm part:
/// 0.1 µm), far above the rounding of its coordinates to `f32`.
pub const WELD_FRACTION: f64 = 1e-6;

/// A separate piece holding under this fraction of the mesh's area is left
/// out of the fit and named (dimensionless): a printing tab, a stray
/// triangle, a label.
pub const SMALL_PIECE_AREA_FRACTION: f64 = 0.01;

/// The repaired mesh and how it maps to the one read.
#[derive(Debug, Clone)]
pub(super) struct Repaired {
    /// Welded, without zero-area triangles and small pieces.
    pub mesh: TubeMesh,
    /// For each vertex of the mesh read, its vertex in [`Repaired::mesh`];
    /// `None` when it is in no kept triangle.
    pub vertex_of: Vec<Option<u32>>,
    /// Vertices merged into another.
    pub welded: usize,
    /// The weld tolerance (mm).
    pub weld_tolerance_mm: f64,
    /// Triangles dropped for zero area or a repeated vertex (after welding).
    pub degenerate: usize,
    /// The small pieces left out.
    pub left_out: Vec<LeftOut>,
}

/// Welds, drops degenerate triangles and small pieces.
pub(super) fn repair(mesh: &TubeMesh) -> Repaired {
    let (lo, hi) = mesh.vertices.iter().fold(
        (Point3::from([f64::MAX; 3]), Point3::from([f64::MIN; 3])),
        |(lo, hi), p| (lo.inf(p), hi.sup(p)),
    );
    let tol = WELD_FRACTION * (hi - lo).norm();
    let (weld_to, welded) = weld(&mesh.vertices, tol);
    let mut degenerate = 0;
    let mut tris: Vec<[u32; 3]> = Vec::with_capacity(mesh.triangles.len());
    for t in &mesh.triangles {
        let t = t.map(|v| weld_to[v as usize]);
        let [a, b, c] = t.map(|v| mesh.vertices[v as usize]);
        if t[0] == t[1] || t[1] == t[2] || t[0] == t[2] || (b - a).cross(&(c - a)).norm() <= 0.0 {
            degenerate += 1;
        } else {
            tris.push(t);
        }
    }
    // Pieces joined by shared vertices.
    let mut root: Vec<u32> = (0..mesh.vertices.len() as u32).collect();
    let find = |root: &mut Vec<u32>, mut i: u32| {
        while root[i as usize] != i {
            let p = root[root[i as usize] as usize];
            root[i as usize] = p;
            i = p;
        }
        i
    };
    for t in &tris {
        let (a, b, c) = (
            find(&mut root, t[0]),
            find(&mut root, t[1]),
            find(&mut root, t[2]),
        );
        let m = a.min(b).min(c);
        for r in [a, b, c] {
            root[r as usize] = m;
        }
    }
    let area = |t: &[u32; 3]| {
        let [a, b, c] = t.map(|v| mesh.vertices[v as usize]);
        0.5 * (b - a).cross(&(c - a)).norm()
    };
    let mut pieces: HashMap<u32, (f64, usize, Vector3)> = HashMap::new();
    let piece_of: Vec<u32> = tris.iter().map(|t| find(&mut root, t[0])).collect();
    for (t, &p) in tris.iter().zip(&piece_of) {
        let e = pieces.entry(p).or_insert((0.0, 0, Vector3::zeros()));
        let a = area(t);
        e.0 += a;
        e.1 += 1;
        e.2 += t
            .iter()
            .map(|&v| mesh.vertices[v as usize].coords)
            .sum::<Vector3>()
            * (a / 3.0);
    }
    let total: f64 = pieces.values().map(|p| p.0).sum();
    let mut left_out: Vec<LeftOut> = pieces
        .values()
        .filter(|p| p.0 < SMALL_PIECE_AREA_FRACTION * total)
        .map(|p| LeftOut {
            triangles: p.1,
            area_mm2: p.0,
            area_fraction: p.0 / total,
            centroid_mm: (p.2 / p.0.max(f64::MIN_POSITIVE)).into(),
        })
        .collect();
    left_out.sort_by(|a, b| b.area_mm2.total_cmp(&a.area_mm2));
    let keep: Vec<bool> = piece_of
        .iter()
        .map(|p| pieces[p].0 >= SMALL_PIECE_AREA_FRACTION * total)
        .collect();
    // Renumber the kept vertices in their order (a clean mesh keeps its numbering).
    let mut new_index: Vec<Option<u32>> = vec![None; mesh.vertices.len()];
    for (t, _) in tris.iter().zip(&keep).filter(|(_, &k)| k) {
        for &v in t {
            new_index[v as usize] = Some(0);
        }
    }
    let mut vertices = Vec::new();
    for (i, slot) in new_index.iter_mut().enumerate() {
        if slot.is_some() {
            *slot = Some(vertices.len() as u32);
            vertices.push(mesh.vertices[i]);
        }
    }
    let triangles: Vec<[u32; 3]> = tris
        .iter()
        .zip(&keep)
        .filter(|(_, &k)| k)
        .map(|(t, _)| t.map(|v| new_index[v as usize].expect("kept")))
        .collect();
    let vertex_of = weld_to.iter().map(|&w| new_index[w as usize]).collect();
    Repaired {
        mesh: TubeMesh {
            file: mesh.file.clone(),
            vertices,
            triangles,
        },
        vertex_of,
        welded,
        weld_tolerance_mm: tol,
        degenerate,
        left_out,
    }
}

/// Each vertex's representative: the first vertex within `tol` of it (grid
/// hashing, cells of `tol`); and how many were merged.
fn weld(points: &[Point3], tol: f64) -> (Vec<u32>, usize) {
    if !(tol > 0.0) {
        return ((0..points.len() as u32).collect(), 0);
    }
    let cell = |p: &Point3| p.coords.map(|c| (c / tol).floor() as i64);
    let mut grid: HashMap<[i64; 3], Vec<u32>> = HashMap::new();
    let mut to = Vec::with_capacity(points.len());
    let mut merged = 0;
    for (i, p) in points.iter().enumerate() {
        let c = cell(p);
        let mut found = None;
        'search: for dx in -1..=1 {
            for dy in -1..=1 {
                for dz in -1..=1 {
                    if let Some(list) = grid.get(&[c.x + dx, c.y + dy, c.z + dz]) {
                        if let Some(&j) = list
                            .iter()
                            .find(|&&j| (points[j as usize] - p).norm() <= tol)
                        {
                            found = Some(j);
                            break 'search;
                        }
                    }
                }
            }
        }
        match found {
            Some(j) => {
                merged += 1;
                to.push(j);
            }
            None => {
                grid.entry([c.x, c.y, c.z]).or_default().push(i as u32);
                to.push(i as u32);
            }
        }
    }
    (to, merged)
}
