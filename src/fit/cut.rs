//! **Sections from the surface** (stage 0a, inside the driver, the third
//! pass of the driver): a station's plane (normal to the
//! guide) cuts the skin's triangles; the cut segments are chained into loops
//! and the closed loop around the guide point is kept, not another stretch
//! of the tube that a tight bend or the next turn of a coil brings into the
//! same plane. The loop is resampled evenly along its length, so that its
//! circle does not depend on where the exporter put its vertices: a coarse
//! export's rings askew to the stations (a helix, an S-bend in a few
//! stretches) still give each station a closed ring. Mesh frame, mm.
//!
//! The triangles a plane may cut are found by the guide parameter of their
//! vertices (each vertex's nearest guide point, which the driver has):
//! those spanning the station's parameter, with a station's margin. That
//! index already tells the stretches of the tube apart, which a spatial
//! index of the triangles (a BVH) would not.

use super::outcome::{EndRing, Station};
use super::samples::Samples;
use super::section::{fit_circle, frame_at, Frame, SectionPoint};
use super::topology::Surfaces;
use super::TubeMesh;
use crate::geometry::guide::CubicSpline;
use crate::math::{Point3, Vector3};
use rayon::prelude::*;
use std::collections::HashMap;

/// Most (station, triangle) pairs [`cut_sections`] lists (dimensionless):
/// 50 M, 600 MB; a mesh of triangles that each span most of the tube (no
/// tube a CAD tool exports) gets no section from cuts instead.
const MAX_CUT_ENTRIES: usize = 50_000_000;

/// Most triangle tests of a [`march`] (dimensionless): 2·10⁸, a few
/// seconds; 2 000 steps on a 100 k-triangle skin.
const MAX_MARCH_TESTS: f64 = 2e8;

/// The stations at `frames` (`step` mm apart) from plane cuts of the skins:
/// per skin, the closed loop around the guide point, resampled, and its
/// circle. `samples`: the skins' vertices alone, in the skins' order
/// ([`Samples::vertices`]); `t`: each one's guide parameter (mm);
/// `margin`: how far past its vertices' parameters a triangle is tried (mm).
pub(super) fn cut_sections(
    mesh: &TubeMesh,
    surf: &Surfaces,
    samples: &Samples,
    t: &[f64],
    frames: &[Frame],
    step: f64,
    margin: f64,
) -> Vec<Station> {
    cut_loops(mesh, surf, samples, t, frames, step, margin)
        .into_iter()
        .zip(frames)
        .map(|(loops, frame)| {
            let points = loops.iter().flatten().map(Vec::len).sum();
            let fits = loops
                .iter()
                .map(|l| l.as_deref().and_then(|l| fit_circle(l, 0.0)))
                .collect();
            Station::from_fits(frame, fits, points, true)
        })
        .collect()
}

/// The points of the stations' plane cuts as samples: each loop's points
/// of [`cut_loops`] (mesh frame, mm) with its skin and its station's guide
/// parameter (mm), at the stations' `ts` (mm) on `spline`; `samples`, `t`
/// and `margin` as for [`cut_sections`]. A solid as a CAD tool writes it
/// has vertices only where its shape changes (a flange's edges); its tube's
/// sections are the cuts.
pub(super) fn cut_points(
    (mesh, surf, samples, t): (&TubeMesh, &Surfaces, &Samples, &[f64]),
    spline: &CubicSpline,
    ts: &[f64],
    margin: f64,
) -> (Vec<Point3>, Vec<u8>, Vec<f64>) {
    let frames: Vec<Frame> = ts.iter().map(|&ti| frame_at(spline, ti)).collect();
    let step = (ts[ts.len() - 1] - ts[0]) / (ts.len() - 1).max(1) as f64;
    let (mut pos, mut skin, mut at) = (Vec::new(), Vec::new(), Vec::new());
    let loops = cut_loops(mesh, surf, samples, t, &frames, step, margin);
    for (per_skin, (ti, c, _, e1, e2)) in loops.into_iter().zip(&frames) {
        for (k, pts) in per_skin.into_iter().enumerate() {
            for q in pts.into_iter().flatten() {
                pos.push(c + e1 * q.x + e2 * q.y);
                skin.push(k as u8);
                at.push(*ti);
            }
        }
    }
    (pos, skin, at)
}

/// Per station at `frames` (`step` mm apart) and per skin, the closed loop
/// of [`section_loop`] cut from the skin's triangles near the station;
/// `samples`, `t` and `margin` as for [`cut_sections`].
fn cut_loops(
    mesh: &TubeMesh,
    surf: &Surfaces,
    samples: &Samples,
    t: &[f64],
    frames: &[Frame],
    step: f64,
    margin: f64,
) -> Vec<Vec<Option<Vec<SectionPoint>>>> {
    let skins = surf.skins.len();
    let n = frames.len() - 1;
    let t0 = frames[0].0;
    let mut vt = vec![f64::NAN; mesh.vertices.len()];
    let mut at = 0;
    for skin in &surf.skins {
        for &v in &skin.vertices {
            if let Some(&tv) = t.get(at).filter(|_| at < samples.vertices) {
                vt[v as usize] = tv;
            }
            at += 1;
        }
    }
    // Each triangle in the stations its vertices' parameters span, and
    // `margin` mm either side (a plane tilted off a guide that is not yet
    // the tube's axis cuts triangles further along).
    let mut cand: Vec<Vec<[u32; 3]>> = vec![Vec::new(); (n + 1) * skins];
    let mut entries = 0;
    for (k, skin) in surf.skins.iter().enumerate() {
        for &tri in &skin.triangles {
            let tri = mesh.triangles[tri as usize];
            let ts = tri.map(|v| vt[v as usize]);
            if ts.iter().any(|x| !x.is_finite()) {
                continue;
            }
            let lo = ts.iter().copied().fold(f64::INFINITY, f64::min);
            let hi = ts.iter().copied().fold(f64::NEG_INFINITY, f64::max);
            let i0 = ((lo - margin - t0) / step).floor().max(0.0);
            let i1 = ((hi + margin - t0) / step).ceil().min(n as f64);
            if i0 > i1 {
                continue;
            }
            entries += (i1 - i0) as usize + 1;
            if entries > MAX_CUT_ENTRIES {
                // Triangles each spanning the tube: no section from cuts.
                return vec![vec![None; skins]; frames.len()];
            }
            for i in i0 as usize..=i1 as usize {
                cand[i * skins + k].push(tri);
            }
        }
    }
    frames
        .par_iter()
        .enumerate()
        .map(|(i, frame)| {
            let (_, centre, normal, e1, e2) = *frame;
            let plane = Plane {
                centre,
                normal,
                e1,
                e2,
            };
            (0..skins)
                .map(|k| section_loop(&plane, &mesh.vertices, &cand[i * skins + k]))
                .collect()
        })
        .collect()
}

/// The end stations' centre and radius from the open ends' rings where
/// their planes found no closed loop (a plane through an end's rim, or
/// tilted past it): else nothing holds the guide's ends and the refits
/// swing them by millimetres. Weighted as a typical station.
pub(super) fn hold_ends(stations: &mut [Station], ends: [&EndRing; 2]) {
    let mut counts: Vec<usize> = stations
        .iter()
        .map(|s| s.points)
        .filter(|&p| p > 0)
        .collect();
    if counts.is_empty() {
        return;
    }
    let k = counts.len() / 2;
    let typical = *counts.select_nth_unstable(k).1;
    let last = stations.len() - 1;
    for (i, ring) in [(0, ends[0]), (last, ends[1])] {
        let s = &mut stations[i];
        if s.centre.is_none() {
            s.centre = Some(ring.centre);
            s.radius = Some(ring.radius);
            s.points = typical;
        }
    }
}

/// A first guide (mm, end to end) marched through the tube from `start` to
/// `finish` by plane cuts of `tris` (one skin's triangles, indices into the
/// mesh's): from each point a step of `step` mm along the direction so far,
/// the plane normal to it there cuts the skin, and the centre of the loop
/// around that point (or nearest it) is the next point. `None` when a plane
/// finds no loop before the finish, or the march runs past the mesh's size.
/// For a coarse export whose level sets shear along a bend (the first guide
/// of [`level_sets`](super::topology::level_sets) cut across a coarse
/// helix's turn 20 mm off its axis), whatever its vertices.
pub(super) fn march(
    mesh: &super::TubeMesh,
    tris: &[u32],
    start: &EndRing,
    finish: &EndRing,
    step: f64,
) -> Option<Vec<Point3>> {
    let tris: Vec<[u32; 3]> = tris.iter().map(|&t| mesh.triangles[t as usize]).collect();
    let pos = &mesh.vertices;
    let reach = 2.0 * start.radius.max(finish.radius) + step;
    // Into the tube: the side of the start plane the skin near it lies on.
    let n0 = start.normal.into_inner();
    let side: f64 = pos
        .iter()
        .filter(|p| (*p - start.centre).norm() < reach)
        .map(|p| (p - start.centre).dot(&n0))
        .sum();
    let mut dir = if side < 0.0 { -n0 } else { n0 };
    let mut pts = vec![start.centre];
    // The tube's length is its skin's area over its circumference: twice
    // that in steps at most, and at most MAX_MARCH_TESTS triangle tests.
    let area: f64 = tris
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|v| pos[v as usize]);
            0.5 * (b - a).cross(&(c - a)).norm()
        })
        .sum();
    let r_min = start.radius.min(finish.radius).max(1e-9);
    let most = (2.0 * area / (std::f64::consts::TAU * r_min) / step)
        .min(MAX_MARCH_TESTS / tris.len().max(1) as f64) as usize
        + 8;
    for _ in 0..most {
        let last = pts[pts.len() - 1];
        if (finish.centre - last).norm() < 1.5 * step {
            break;
        }
        let at = last + dir * step;
        let (e1, e2) = super::section::plane_basis(&crate::math::UnitVector3::new_normalize(dir));
        let plane = Plane {
            centre: at,
            normal: dir,
            e1,
            e2,
        };
        // The triangles the plane cuts near the point.
        let near: Vec<[u32; 3]> = tris
            .iter()
            .filter(|t| segment_near(t.map(|v| pos[v as usize]), &at, &dir, reach))
            .copied()
            .collect();
        let Some(ring) = section_loop(&plane, pos, &near) else {
            // Past the open finish, or lost.
            if (finish.centre - last).norm() < reach {
                break;
            }
            return None;
        };
        let m = ring.len() as f64;
        let (cx, cy) = (
            ring.iter().map(|p| p.x).sum::<f64>() / m,
            ring.iter().map(|p| p.y).sum::<f64>() / m,
        );
        let c = at + e1 * cx + e2 * cy;
        // Past the finish's plane: done.
        let nf = finish.normal.into_inner();
        if (c - finish.centre).dot(&nf).signum() != (last - finish.centre).dot(&nf).signum()
            && (c - finish.centre).norm() < reach
        {
            break;
        }
        let d = c - last;
        if d.norm() < 1e-9 {
            return None;
        }
        dir = d.normalize();
        pts.push(c);
    }
    let last = pts[pts.len() - 1];
    if (finish.centre - last).norm() >= reach {
        return None;
    }
    if (finish.centre - last).norm() < 0.5 * step && pts.len() > 1 {
        pts.pop();
    }
    pts.push(finish.centre);
    (pts.len() >= 2).then_some(pts)
}

/// Whether triangle `p` crosses the plane through `at` normal to `dir`
/// within `reach` of `at` (a long thin triangle of a coarse export is cut
/// near a point its vertices are all far from).
fn segment_near(p: [Point3; 3], at: &Point3, dir: &Vector3, reach: f64) -> bool {
    let d = p.map(|q| (q - at).dot(dir));
    let mut cut = Vec::with_capacity(2);
    for i in 0..3 {
        let j = (i + 1) % 3;
        if (d[i] < 0.0) != (d[j] < 0.0) {
            let f = d[i] / (d[i] - d[j]);
            cut.push(p[i] + (p[j] - p[i]) * f);
        }
    }
    let [a, b] = cut[..] else { return false };
    let ab = b - a;
    let u = if ab.norm_squared() > 0.0 {
        ((at - a).dot(&ab) / ab.norm_squared()).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (a + ab * u - at).norm() < reach
}

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
/// basis (mm, `dt` 0). The tightest loop that winds around the centre, else
/// the closed loop whose centroid is nearest it within the loop's own mean
/// radius; `None` when there is neither.
pub fn section_loop(plane: &Plane, pos: &[Point3], tris: &[[u32; 3]]) -> Option<Vec<SectionPoint>> {
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
    // The best loop so far and its rank: (0, its mean radius) around the
    // centre, (1, its centroid's distance) beside it.
    let mut best: Option<(Polygon, (u8, f64))> = None;
    for start in 0..segs.len() {
        if used[start] {
            continue;
        }
        used[start] = true;
        let first = segs[start][0];
        let mut at = segs[start][1];
        let mut chain = vec![point(first), point(at)];
        let mut closed = false;
        while let Some(&next) = ends.get(&at).and_then(|l| l.iter().find(|&&s| !used[s])) {
            used[next] = true;
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
        if !closed || chain.len() < 3 {
            continue;
        }
        // Around the centre: the tightest loop (another stretch of the tube
        // around the same point would enclose this one). Else, a guide not
        // yet on the tube's axis: the loop whose centroid is nearest,
        // within its own size (the next refit moves the guide to it).
        let m = chain.len() as f64;
        let (cx, cy) = (
            chain.iter().map(|p| p[0]).sum::<f64>() / m,
            chain.iter().map(|p| p[1]).sum::<f64>() / m,
        );
        let rank = if winding(&chain) != 0 {
            (0, chain.iter().map(|p| p[0].hypot(p[1])).sum::<f64>() / m)
        } else {
            let size = chain
                .iter()
                .map(|p| (p[0] - cx).hypot(p[1] - cy))
                .sum::<f64>()
                / m;
            let off = cx.hypot(cy);
            if off > size {
                continue;
            }
            (1, off)
        };
        if best.as_ref().is_none_or(|b| rank < b.1) {
            best = Some((chain, rank));
        }
    }
    let (chain, _) = best?;
    Some(resample(&chain, MIN_LOOP_SAMPLES.max(chain.len())))
}

/// A closed polygon in a plane (mm, the plane's basis).
type Polygon = Vec<[f64; 2]>;

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

    /// A cylinder of radius 5 along z, `n` around, two rings at `zs`, in
    /// one stretch of two triangles a quad.
    fn cylinder(n: usize, zs: [f64; 2]) -> (Vec<Point3>, Vec<[u32; 3]>) {
        let mut pos = Vec::new();
        for z in zs {
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
        (pos, tris)
    }

    #[test]
    fn a_cut_cylinder_gives_one_loop_around_its_axis() {
        // A cylinder of radius 5 along z, 40 around, rings at z = 0, 2.
        let n = 40;
        let (pos, tris) = cylinder(n, [0.0, 2.0]);
        let plane = Plane {
            centre: Point3::new(0.0, 0.0, 0.7),
            normal: Vector3::z(),
            e1: Vector3::x(),
            e2: Vector3::y(),
        };
        let pts = section_loop(&plane, &pos, &tris).expect("a loop");
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

    #[test]
    fn a_loop_beside_the_point_is_taken_when_its_centroid_is_near() {
        // A cylinder of radius 5 along z in one stretch of long triangles
        // (z from -20 to 20, 40 around), cut by a plane tilted 60 degrees
        // about x: an ellipse of half-axes 5 (along x) and 10.
        let n = 40;
        let (pos, tris) = cylinder(n, [-20.0, 20.0]);
        let a = 60f64.to_radians();
        let normal = Vector3::new(0.0, a.sin(), a.cos());
        let e2 = Vector3::new(0.0, a.cos(), -a.sin());
        let at = |x: f64| Plane {
            centre: Point3::new(x, 0.0, 0.0),
            normal,
            e1: Vector3::x(),
            e2,
        };
        // Inside: around it. Just outside the ellipse across its short
        // axis, 6 mm from its centroid (its mean radius is about 7.7 mm):
        // the same loop, whose centre the refit moves to.
        for x in [0.0, 6.0] {
            let pts = section_loop(&at(x), &pos, &tris).expect("a loop");
            let m = pts.len() as f64;
            let cx = pts.iter().map(|p| p.x).sum::<f64>() / m;
            let cy = pts.iter().map(|p| p.y).sum::<f64>() / m;
            assert!((cx + x).abs() < 0.05 && cy.abs() < 0.05, "x {x}: {cx} {cy}");
            let long = pts.iter().map(|p| p.y.abs()).fold(0.0, f64::max);
            assert!((long - 10.0).abs() < 0.05, "x {x}: {long}");
        }
        // Further than its mean radius: none.
        assert!(section_loop(&at(9.0), &pos, &tris).is_none());
    }
}
