//! **Sections from the surface**: a station's plane (normal to the guide)
//! cuts the skin's triangles; the cut segments are chained into loops and
//! the closed loop around the guide point is kept: not another stretch of
//! the tube that a tight bend or the next turn of a coil brings into the
//! same plane. The loop is resampled evenly along its length, so that its
//! circle does not depend on where the exporter put its vertices. Mesh
//! frame, mm.
//!
//! The triangles a plane may cut are found by the guide parameter of their
//! vertices (each vertex's nearest guide point, which the driver has):
//! those spanning the station's parameter, with a margin. That index
//! already tells the stretches of the tube apart, which a spatial index of
//! the triangles (a BVH) would not.

use super::section::SectionPoint;
use crate::math::{Point3, Vector3};
use std::collections::HashMap;

/// Points per loop after resampling along its length, at least
/// (dimensionless): enough for a circle's RMS to reach the facets.
pub const MIN_LOOP_SAMPLES: usize = 64;

/// One station's plane: through `centre` (the guide point, mm), with unit
/// normal `normal` (the guide's tangent) and in-plane basis `e1`, `e2`.
#[derive(Debug, Clone, Copy)]
pub struct Plane {
    /// The guide point (mm).
    pub centre: Point3,
    /// Unit normal.
    pub normal: Vector3,
    /// First in-plane unit vector.
    pub e1: Vector3,
    /// Second in-plane unit vector.
    pub e2: Vector3,
}

/// The closed loop around the plane's centre cut from `tris` (triangles as
/// vertex indices into `pos`), resampled evenly: its points in the plane's
/// basis, and how many triangles it crosses; `None` when no closed loop
/// winds around the centre.
pub fn section_loop(
    plane: &Plane,
    pos: &[Point3],
    tris: &[[u32; 3]],
) -> Option<(Vec<SectionPoint>, usize)> {
    let d = |v: u32| (pos[v as usize] - plane.centre).dot(&plane.normal);
    // Segments between cut edges (an edge as its sorted vertex pair); a
    // vertex on the plane counts as above it.
    let mut ends: HashMap<(u32, u32), Vec<usize>> = HashMap::new();
    let mut segs: Vec<[(u32, u32); 2]> = Vec::new();
    for t in tris {
        let s = t.map(|v| d(v) >= 0.0);
        if s[0] == s[1] && s[1] == s[2] {
            continue;
        }
        let mut cut = [(0, 0); 2];
        let mut k = 0;
        for i in 0..3 {
            let (a, b) = (t[i], t[(i + 1) % 3]);
            if s[i] != s[(i + 1) % 3] && k < 2 {
                cut[k] = (a.min(b), a.max(b));
                k += 1;
            }
        }
        let id = segs.len();
        segs.push(cut);
        for e in cut {
            ends.entry(e).or_default().push(id);
        }
    }
    let point = |e: (u32, u32)| {
        let (da, db) = (d(e.0), d(e.1));
        let (pa, pb) = (pos[e.0 as usize], pos[e.1 as usize]);
        let f = da / (da - db);
        let p = pa + (pb - pa) * f;
        let o = p - plane.centre;
        [o.dot(&plane.e1), o.dot(&plane.e2)]
    };
    let mut used = vec![false; segs.len()];
    let mut best: Option<(Vec<[f64; 2]>, usize, f64)> = None;
    for start in 0..segs.len() {
        if used[start] {
            continue;
        }
        used[start] = true;
        let first = segs[start][0];
        let mut at = segs[start][1];
        let mut chain = vec![point(first), point(at)];
        let mut count = 1;
        let mut closed = false;
        while let Some(&next) = ends
            .get(&at)
            .and_then(|l| l.iter().find(|&&s| !used[s]))
        {
            used[next] = true;
            count += 1;
            at = if segs[next][0] == at {
                segs[next][1]
            } else {
                segs[next][0]
            };
            if at == first {
                closed = true;
                break;
            }
            chain.push(point(at));
        }
        if !closed || chain.len() < 3 || winding(&chain) == 0 {
            continue;
        }
        // Around the centre: keep the tightest loop (another stretch of the
        // tube around the same point would enclose this one).
        let size = chain.iter().map(|p| p[0].hypot(p[1])).sum::<f64>() / chain.len() as f64;
        if best.as_ref().is_none_or(|b| size < b.2) {
            best = Some((chain, count, size));
        }
    }
    let (chain, count, _) = best?;
    Some((resample(&chain, MIN_LOOP_SAMPLES.max(chain.len())), count))
}

/// Winding number of a closed polygon around the origin.
fn winding(poly: &[[f64; 2]]) -> i32 {
    let mut w = 0;
    for i in 0..poly.len() {
        let (a, b) = (poly[i], poly[(i + 1) % poly.len()]);
        if a[1] <= 0.0 {
            if b[1] > 0.0 && cross(a, b) > 0.0 {
                w += 1;
            }
        } else if b[1] <= 0.0 && cross(a, b) < 0.0 {
            w -= 1;
        }
    }
    w
}

fn cross(a: [f64; 2], b: [f64; 2]) -> f64 {
    a[0] * b[1] - a[1] * b[0]
}

/// `n` points evenly spaced along the closed polygon's length.
fn resample(poly: &[[f64; 2]], n: usize) -> Vec<SectionPoint> {
    let m = poly.len();
    let len: Vec<f64> = (0..m)
        .map(|i| {
            let (a, b) = (poly[i], poly[(i + 1) % m]);
            (b[0] - a[0]).hypot(b[1] - a[1])
        })
        .collect();
    let total: f64 = len.iter().sum();
    let mut out = Vec::with_capacity(n);
    let (mut i, mut start) = (0, 0.0);
    for k in 0..n {
        let s = total * k as f64 / n as f64;
        while i + 1 < m && start + len[i] < s {
            start += len[i];
            i += 1;
        }
        let f = if len[i] > 0.0 {
            ((s - start) / len[i]).clamp(0.0, 1.0)
        } else {
            0.0
        };
        let (a, b) = (poly[i], poly[(i + 1) % m]);
        out.push(SectionPoint {
            x: a[0] + (b[0] - a[0]) * f,
            y: a[1] + (b[1] - a[1]) * f,
            dt: 0.0,
        });
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_cut_cylinder_gives_one_loop_around_its_axis() {
        // A cylinder of radius 5 along z, 40 around, rings at z = 0, 2.
        let n = 40;
        let mut pos = Vec::new();
        for z in [0.0, 2.0] {
            for j in 0..n {
                let a = std::f64::consts::TAU * j as f64 / n as f64;
                pos.push(Point3::new(5.0 * a.cos(), 5.0 * a.sin(), z));
            }
        }
        let mut tris = Vec::new();
        for j in 0..n as u32 {
            let k = (j + 1) % n as u32;
            tris.push([j, k, j + n as u32]);
            tris.push([k, k + n as u32, j + n as u32]);
        }
        let plane = Plane {
            centre: Point3::new(0.0, 0.0, 0.7),
            normal: Vector3::z(),
            e1: Vector3::x(),
            e2: Vector3::y(),
        };
        let (pts, crossed) = section_loop(&plane, &pos, &tris).expect("a loop");
        assert_eq!(crossed, 2 * n);
        assert_eq!(pts.len(), MIN_LOOP_SAMPLES.max(2 * n));
        for p in &pts {
            let r = p.x.hypot(p.y);
            assert!(r <= 5.0 + 1e-9 && r > 5.0 * (std::f64::consts::PI / n as f64).cos() - 1e-9);
        }
        // Off to the side, the loop does not wind around the point.
        let aside = Plane {
            centre: Point3::new(20.0, 0.0, 0.7),
            ..plane
        };
        assert!(section_loop(&aside, &pos, &tris).is_none());
    }
}
