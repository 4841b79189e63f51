//! **The points the fit uses** (stage 0a, inside the driver): the skins'
//! vertices, with points along the edges of a coarse export's bend when the
//! vertices alone fail, and the guide parameter of each one's nearest guide
//! point (mesh frame, mm).

use super::topology::Surfaces;
use super::TubeMesh;
use crate::geometry::guide::{CubicSpline, GuideCurve};
use crate::math::Point3;
use parry3d_f64::query::PointQueryWithLocation;
use parry3d_f64::shape::Polyline;
use rayon::prelude::*;

/// The points the fit uses (mesh frame, mm): every skin vertex, and with a
/// coarse bend points along its edges, each with its skin.
pub(super) struct Samples {
    pub(super) pos: Vec<Point3>,
    pub(super) skin: Vec<u8>,
    pub(super) skins: usize,
    /// The first `vertices` samples are the skins' vertices; the others
    /// lie along the skins' long edges.
    pub(super) vertices: usize,
}

impl Samples {
    /// The skins' vertices, with their skins.
    pub(super) fn vertices(mesh: &TubeMesh, surf: &Surfaces) -> Samples {
        let mut pos = Vec::new();
        let mut skin = Vec::new();
        for (k, s) in surf.skins.iter().enumerate() {
            pos.extend(s.vertices.iter().map(|&v| mesh.vertices[v as usize]));
            skin.extend(std::iter::repeat_n(k as u8, s.vertices.len()));
        }
        let vertices = pos.len();
        Samples {
            pos,
            skin,
            skins: surf.skins.len(),
            vertices,
        }
    }

    /// Drops the points along the edges, and their `hints`; whether there
    /// were any.
    pub(super) fn drop_edges(&mut self, hints: &mut Option<Vec<f64>>) -> bool {
        if self.vertices == self.pos.len() {
            return false;
        }
        self.pos.truncate(self.vertices);
        self.skin.truncate(self.vertices);
        if let Some(h) = hints {
            h.truncate(self.vertices);
        }
        true
    }

    /// The skins' vertices only.
    pub(super) fn vertex_only(&self) -> Samples {
        Samples {
            pos: self.pos[..self.vertices].to_vec(),
            skin: self.skin[..self.vertices].to_vec(),
            skins: self.skins,
            vertices: self.vertices,
        }
    }
}

/// An edge spans a bend when the first guide turns by more than this
/// between its ends (degrees): a coarse export's bend in eight stretches
/// along 90 degrees turns by 11 degrees a stretch.
const BEND_EDGE_MIN_TURN_DEG: f64 = 3.0;
/// An edge runs along the tube when within this of the first guide's
/// tangent (degrees): the long thin triangles of a coarse export do, the
/// flat rings of a flange and the rings of vertices do not.
const BEND_EDGE_MAX_ANGLE_DEG: f64 = 45.0;

/// `vertices` with points along the skins' edges that span a bend: edges
/// longer than a station `spacing` (mm), running along the first `guide`
/// (within [`BEND_EDGE_MAX_ANGLE_DEG`] of its tangent) while the guide turns
/// by more than [`BEND_EDGE_MIN_TURN_DEG`] between their ends. A coarse
/// export's bend (a few long stretches) then gives each station a ring of
/// points of the surface, not only those near the exporter's vertex rings,
/// which lie askew to the stations there. Straight stretches and the faces
/// of features across the tube (a flange's flat rings) keep their vertices
/// alone: their chords' points lie inside the surface. The edges' points
/// come after the vertices (the report pairs the first samples with them).
/// `None` when no edge spans a bend. `past_end`: as [`project_all`]'s.
pub(super) fn with_bend_edges(
    mesh: &TubeMesh,
    surf: &Surfaces,
    vertices: Samples,
    guide: &CubicSpline,
    range: (f64, f64),
    spacing: f64,
    past_end: f64,
) -> Option<Samples> {
    let t = project_all(guide, range, &vertices, None, past_end);
    let mut t_of = vec![f64::NAN; mesh.vertices.len()];
    let skin_vertices = surf.skins.iter().flat_map(|s| s.vertices.iter());
    for (&v, &tv) in skin_vertices.zip(&t) {
        t_of[v as usize] = tv;
    }
    let (min_turn, max_angle) = (
        BEND_EDGE_MIN_TURN_DEG.to_radians(),
        BEND_EDGE_MAX_ANGLE_DEG.to_radians(),
    );
    let Samples {
        mut pos, mut skin, ..
    } = vertices;
    let (count, mut bend) = (pos.len(), false);
    for (k, s) in surf.skins.iter().enumerate() {
        let mut edges: Vec<(u32, u32)> = s
            .triangles
            .iter()
            .flat_map(|&t| {
                let v = mesh.triangles[t as usize];
                [(v[0], v[1]), (v[1], v[2]), (v[2], v[0])].map(|(a, b)| (a.min(b), a.max(b)))
            })
            .collect();
        edges.sort_unstable();
        edges.dedup();
        for (a, b) in edges {
            let (p, q) = (mesh.vertices[a as usize], mesh.vertices[b as usize]);
            let m = ((q - p).norm() / spacing).floor() as usize;
            if m < 2 {
                continue;
            }
            let (ta, tb) = (t_of[a as usize], t_of[b as usize]);
            let along = guide.d1(0.5 * (ta + tb));
            if (q - p).angle(&along).min((p - q).angle(&along)) >= max_angle {
                continue;
            }
            bend |= guide.d1(ta).angle(&guide.d1(tb)) > min_turn;
            for i in 1..m {
                pos.push(p + (q - p) * (i as f64 / m as f64));
                skin.push(k as u8);
            }
        }
    }
    bend.then_some(Samples {
        pos,
        skin,
        skins: surf.skins.len(),
        vertices: count,
    })
}

/// Guide parameter of the nearest guide point of every sample: Newton from
/// the hint, or from the nearest point of a polyline of the guide (parry3d
/// BVH query) when there is no hint or Newton does not settle.
pub(super) fn project_all(
    spline: &CubicSpline,
    range: (f64, f64),
    s: &Samples,
    hints: Option<&[f64]>,
    ext: f64,
) -> Vec<f64> {
    let (lo, hi) = (range.0 - ext, range.1 + ext);
    let n = ((hi - lo) / 0.5).ceil().clamp(16.0, 20_000.0) as usize;
    let ts: Vec<f64> = (0..=n)
        .map(|i| lo + (hi - lo) * i as f64 / n as f64)
        .collect();
    let line = Polyline::new(ts.iter().map(|&t| spline.point(t)).collect(), None);
    let global = |p: &Point3| {
        let (_, (seg, loc)) = line.project_local_point_and_get_location(p, false);
        let [u, v] = loc.barycentric_coordinates();
        ts[seg as usize] * u + ts[seg as usize + 1] * v
    };
    s.pos
        .par_iter()
        .enumerate()
        .map(|(i, p)| {
            let hint = hints.and_then(|h| h.get(i).copied());
            match hint.and_then(|t0| newton(spline, p, t0, lo, hi)) {
                Some(t) => t,
                None => {
                    let t0 = global(p);
                    newton(spline, p, t0, lo, hi).unwrap_or(t0)
                }
            }
        })
        .collect()
}

/// The guide parameters `t` (mm) of the samples on the guide that the
/// refit replaced, carried onto the new guide: the refit's point `j` lies at
/// `from[j]` on the old guide and at `to[j]` on the new one (its chord
/// lengths), linear between and past the ends. Newton's search from an
/// uncarried parameter lands on the wrong stretch when the refit
/// lengthens the guide (a coil's first guide, 13 % short, put the vertices
/// of its far turns at its start).
pub(super) fn carry_hints(mut t: Vec<f64>, from: &[f64], to: &[f64]) -> Vec<f64> {
    let n = from.len().min(to.len());
    if n < 2 {
        return t;
    }
    for x in &mut t {
        let j = from[..n].partition_point(|&k| k <= *x).clamp(1, n - 1);
        let (a, b) = (j - 1, j);
        let span = from[b] - from[a];
        if span > 0.0 {
            *x = to[a] + (*x - from[a]) * (to[b] - to[a]) / span;
        }
    }
    t
}

/// Nearest-point parameter by Newton on `(C(t) - p) · C'(t) = 0` in `[lo, hi]`.
fn newton(spline: &CubicSpline, p: &Point3, mut t: f64, lo: f64, hi: f64) -> Option<f64> {
    for _ in 0..12 {
        let d = spline.point(t) - p;
        let d1 = spline.d1(t);
        let f = d.dot(&d1);
        let fp = d1.norm_squared() + d.dot(&spline.d2(t));
        let step = if fp > 0.1 * d1.norm_squared() {
            f / fp
        } else {
            f / d1.norm_squared()
        };
        let next = (t - step).clamp(lo, hi);
        if (next - t).abs() < 1e-10 {
            return Some(next);
        }
        t = next;
    }
    None
}
