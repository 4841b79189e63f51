//! `wall.stl`: the deposited wall as a triangle mesh (part frame, mm) — a
//! rectangular bead section swept along every layer, for a visual check of
//! the part in any STL viewer.
//!
//! At each path point the section spans `±width/2` along the surface normal
//! and reaches down along the build direction by the local distance to the
//! layer below (`Delta` on the first layer), so beads of consecutive layers
//! touch.

use crate::math::Point3;
use crate::path::Path;
use crate::toolaxis::LocalFrame;
use std::io::Write;

/// Triangles of the swept wall. `frames` are the local frames of `path`
/// (layer by layer); `width_mm` is the bead width.
pub fn wall_triangles(path: &Path, frames: &[Vec<LocalFrame>], width_mm: f64) -> Vec<[Point3; 3]> {
    let mut tris = Vec::new();
    let half = 0.5 * width_mm;
    for (layer, fr) in path.layers.iter().zip(frames) {
        let n = layer.points.len();
        if n < 2 {
            continue;
        }
        // Section corners: top outer, top inner, bottom inner, bottom outer.
        let sections: Vec<[Point3; 4]> = layer
            .points
            .iter()
            .zip(fr)
            .map(|(p, f)| {
                let h = p.delta.unwrap_or(path.delta_mm);
                let (o, b) = (f.normal * half, f.build * h);
                let q = p.position;
                [q + o, q - o, q - o - b, q + o - b]
            })
            .collect();
        let segments = if layer.closed { n } else { n - 1 };
        for i in 0..segments {
            let (a, c) = (&sections[i], &sections[(i + 1) % n]);
            for k in 0..4 {
                let k1 = (k + 1) % 4;
                tris.push([a[k], c[k], c[k1]]);
                tris.push([a[k], c[k1], a[k1]]);
            }
        }
        if !layer.closed {
            let (s, e) = (&sections[0], &sections[n - 1]);
            tris.push([s[0], s[2], s[1]]);
            tris.push([s[0], s[3], s[2]]);
            tris.push([e[0], e[1], e[2]]);
            tris.push([e[0], e[2], e[3]]);
        }
    }
    tris
}

/// Writes triangles as a binary STL (facet normals from the vertex order).
///
/// # Errors
/// I/O errors of `w`.
pub fn write_stl(w: &mut dyn Write, triangles: &[[Point3; 3]]) -> std::io::Result<()> {
    let to = |p: &Point3| stl_io::Vertex::new([p.x as f32, p.y as f32, p.z as f32]);
    let facets: Vec<stl_io::Triangle> = triangles
        .iter()
        .map(|t| {
            let n = (t[1] - t[0]).cross(&(t[2] - t[0]));
            let n = if n.norm() > 0.0 { n.normalize() } else { n };
            stl_io::Triangle {
                normal: stl_io::Normal::new([n.x as f32, n.y as f32, n.z as f32]),
                vertices: [to(&t[0]), to(&t[1]), to(&t[2])],
            }
        })
        .collect();
    let mut buf = Vec::new();
    stl_io::write_stl(&mut buf, facets.iter())?;
    w.write_all(&buf)
}
