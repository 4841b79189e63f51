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

/// Most triangles [`write_wall_stl`] writes by default (2 M: a 100 MB
/// file); above, the sections are taken at every k-th point of each layer.
pub const DEFAULT_MAX_WALL_TRIANGLES: u64 = 2_000_000;

/// What [`write_wall_stl`] wrote.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct WallStl {
    /// Triangles written.
    pub triangles: u64,
    /// Sections taken at every `every`-th point of each layer (1: all).
    pub every: usize,
}

/// The indices of the sections of a layer of `n` points at every `every`-th
/// point (an open layer keeps its last point).
fn section_indices(n: usize, every: usize, closed: bool) -> Vec<usize> {
    let mut idx: Vec<usize> = (0..n).step_by(every.max(1)).collect();
    if !closed && idx.last() != Some(&(n - 1)) {
        idx.push(n - 1);
    }
    idx
}

/// Triangles of a layer of `m` sections.
fn layer_triangles(m: usize, closed: bool) -> u64 {
    if m < 2 {
        return 0;
    }
    let segments = if closed { m } else { m - 1 } as u64;
    8 * segments + if closed { 0 } else { 4 }
}

/// Calls `f` with each triangle of the swept wall, sections at every
/// `every`-th point; stops at the first error of `f`.
fn each_triangle(
    path: &Path,
    frames: &[Vec<LocalFrame>],
    width_mm: f64,
    every: usize,
    f: &mut dyn FnMut([Point3; 3]) -> std::io::Result<()>,
) -> std::io::Result<()> {
    let half = 0.5 * width_mm;
    for (layer, fr) in path.layers.iter().zip(frames) {
        let n = layer.points.len();
        if n < 2 {
            continue;
        }
        let idx = section_indices(n, every, layer.closed);
        let m = idx.len();
        if m < 2 {
            continue;
        }
        // Section corners: top outer, top inner, bottom inner, bottom outer.
        let section = |i: usize| -> [Point3; 4] {
            let (p, fr) = (&layer.points[i], &fr[i]);
            let h = p.delta.unwrap_or(path.delta_mm);
            let (o, b) = (fr.normal * half, fr.build * h);
            let q = p.position;
            [q + o, q - o, q - o - b, q + o - b]
        };
        let segments = if layer.closed { m } else { m - 1 };
        let mut a = section(idx[0]);
        let first = a;
        for s in 0..segments {
            let c = if s + 1 < m {
                section(idx[s + 1])
            } else {
                first
            };
            for k in 0..4 {
                let k1 = (k + 1) % 4;
                f([a[k], c[k], c[k1]])?;
                f([a[k], c[k1], a[k1]])?;
            }
            a = c;
        }
        if !layer.closed {
            let (s, e) = (first, section(idx[m - 1]));
            f([s[0], s[2], s[1]])?;
            f([s[0], s[3], s[2]])?;
            f([e[0], e[1], e[2]])?;
            f([e[0], e[2], e[3]])?;
        }
    }
    Ok(())
}

/// Triangles of the swept wall. `frames` are the local frames of `path`
/// (layer by layer); `width_mm` is the bead width. Holds every triangle in
/// memory: for files, [`write_wall_stl`] streams them.
pub fn wall_triangles(path: &Path, frames: &[Vec<LocalFrame>], width_mm: f64) -> Vec<[Point3; 3]> {
    let mut tris = Vec::new();
    let _ = each_triangle(path, frames, width_mm, 1, &mut |t| {
        tris.push(t);
        Ok(())
    });
    tris
}

/// Writes the swept wall as a binary STL (80-byte zero header, triangle
/// count, one 50-byte record per triangle, facet normals from the vertex
/// order), streaming: nothing but one layer's sections is held. Above
/// `max_triangles` the sections are taken at every k-th point (the
/// smallest k under the budget); the result says which k.
///
/// # Errors
/// I/O errors of `w`.
pub fn write_wall_stl(
    w: &mut dyn Write,
    path: &Path,
    frames: &[Vec<LocalFrame>],
    width_mm: f64,
    max_triangles: u64,
) -> std::io::Result<WallStl> {
    let count = |every: usize| -> u64 {
        path.layers
            .iter()
            .filter(|l| l.points.len() >= 2)
            .map(|l| {
                layer_triangles(
                    section_indices(l.points.len(), every, l.closed).len(),
                    l.closed,
                )
            })
            .sum()
    };
    let mut every = 1;
    let mut triangles = count(1);
    while triangles > max_triangles.max(1) && every < 1 << 20 {
        every *= 2;
        triangles = count(every);
    }
    if triangles > u64::from(u32::MAX) {
        return Err(std::io::Error::other(format!(
            "{triangles} triangles: more than a binary STL holds"
        )));
    }
    let mut w = std::io::BufWriter::with_capacity(1 << 16, w);
    w.write_all(&[0u8; 80])?;
    w.write_all(&(triangles as u32).to_le_bytes())?;
    let mut record = [0u8; 50];
    each_triangle(path, frames, width_mm, every, &mut |t| {
        let n = (t[1] - t[0]).cross(&(t[2] - t[0]));
        let n = if n.norm() > 0.0 { n.normalize() } else { n };
        let values = [
            n.x, n.y, n.z, t[0].x, t[0].y, t[0].z, t[1].x, t[1].y, t[1].z, t[2].x, t[2].y, t[2].z,
        ];
        for (k, v) in values.iter().enumerate() {
            record[4 * k..4 * k + 4].copy_from_slice(&(*v as f32).to_le_bytes());
        }
        w.write_all(&record)
    })?;
    w.flush()?;
    Ok(WallStl { triangles, every })
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::Vector3;
    use crate::path::{Layer, PathPoint, SliceReport, Strategy};

    fn ring(n: usize, z: f64, closed: bool) -> (Layer, Vec<LocalFrame>) {
        let points = (0..n)
            .map(|i| {
                let a = i as f64 / n as f64 * std::f64::consts::TAU;
                PathPoint {
                    t: z,
                    v: a,
                    position: Point3::new(20.0 * a.cos(), 20.0 * a.sin(), z),
                    delta: (z > 0.0).then_some(1.0),
                }
            })
            .collect();
        let frames = (0..n)
            .map(|i| {
                let a = i as f64 / n as f64 * std::f64::consts::TAU;
                let normal = Vector3::new(a.cos(), a.sin(), 0.0);
                LocalFrame {
                    tangent: Vector3::new(-a.sin(), a.cos(), 0.0),
                    normal,
                    build: Vector3::z(),
                    tool: Vector3::z(),
                }
            })
            .collect();
        (
            Layer {
                slice: 0,
                points,
                closed,
            },
            frames,
        )
    }

    fn path_of(layers: Vec<(Layer, Vec<LocalFrame>)>) -> (Path, Vec<Vec<LocalFrame>>) {
        let (layers, frames): (Vec<_>, Vec<_>) = layers.into_iter().unzip();
        (
            Path {
                strategy: Strategy::Constant,
                delta_mm: 1.0,
                layers,
                report: SliceReport::default(),
                spiral: None,
            },
            frames,
        )
    }

    #[test]
    fn streamed_file_is_the_in_memory_one_and_the_budget_thins_it() {
        let (path, frames) = path_of(vec![ring(100, 0.0, true), ring(101, 1.0, false)]);
        let mut streamed = Vec::new();
        let r = write_wall_stl(&mut streamed, &path, &frames, 2.0, u64::MAX).unwrap();
        let mut whole = Vec::new();
        write_stl(&mut whole, &wall_triangles(&path, &frames, 2.0)).unwrap();
        assert_eq!(streamed, whole);
        assert_eq!(
            r,
            WallStl {
                triangles: 800 + 804,
                every: 1
            }
        );
        let mut thin = Vec::new();
        let r = write_wall_stl(&mut thin, &path, &frames, 2.0, 500).unwrap();
        assert!(r.triangles <= 500 && r.every == 4, "{r:?}");
        assert_eq!(thin.len() as u64, 84 + 50 * r.triangles);
        // a reader takes it back with that many facets
        let mesh = stl_io::read_stl(&mut std::io::Cursor::new(thin)).unwrap();
        assert_eq!(mesh.faces.len() as u64, r.triangles);
    }
}
