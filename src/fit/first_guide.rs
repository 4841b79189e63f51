//! **The first guide** (stage 0a, inside the driver): the guide the
//! refits start from, end to end through the tube, with one point past
//! each end. Through the centroids of the level sets of the geodesic
//! distance from the start end, or the cubic leaving each end along its
//! normal when the mesh is too coarse for level sets, or through a swept
//! export's rings where the level sets leave them; on the plane-cut pass,
//! marched through plane cuts of the skin ([`cut::march`]). Mesh frame, mm.

use super::cut;
use super::outcome::EndRing;
use super::smooth::{arc_tangent_length, hermite};
use super::topology::{self, Surfaces};
use super::{FitError, TubeMesh};
use crate::math::{Point3, UnitVector3};

/// The first guide of a pass (points, one past each end): marched through
/// plane cuts of the skin it follows ([`guide_skin`]) with `march`
/// ([`cut::march`]), else (or when the march is lost) through the level
/// sets ([`initial_guide`]). The sizes: the median edge, the knot spacing
/// and the RMS a flat ring may have (mm).
pub(super) fn first_guide(
    mesh: &TubeMesh,
    surf: &Surfaces,
    [start, finish]: [&EndRing; 2],
    (edge, knot_h, flat_mm): (f64, f64, f64),
    march: bool,
) -> Result<Vec<Point3>, FitError> {
    let k = guide_skin(mesh, surf);
    march
        .then(|| cut::march(mesh, &surf.skins[k].triangles, start, finish, 0.5 * knot_h))
        .flatten()
        .map_or_else(
            || initial_guide(mesh, surf, k, [start, finish], (edge, knot_h, flat_mm)),
            |g| Ok(with_ends_past(g, knot_h)),
        )
}

/// The skin the first guide follows: of a wall's two skins the one of
/// the smaller area, the bore (a flange, a collar or a block stands on the
/// outer skin, and on a bend the distance along it across the feature's
/// steps breaks the level sets apart); else the only one.
fn guide_skin(mesh: &TubeMesh, surf: &Surfaces) -> usize {
    let area = |tris: &[u32]| -> f64 {
        tris.iter()
            .map(|&t| {
                let [a, b, c] = mesh.triangles[t as usize].map(|i| mesh.vertices[i as usize]);
                (b - a).cross(&(c - a)).norm()
            })
            .sum()
    };
    match &surf.skins[..] {
        [outer, inner] if area(&inner.triangles) < area(&outer.triangles) => 1,
        _ => 0,
    }
}

/// First guide: the start end's centre, the centroids of the level sets of
/// the geodesic distance from the start end (those before the far end), the
/// far end's centre; thinned to points `knot_h / 2` apart. On skin `k`
/// ([`guide_skin`]); `edge` its median edge (mm). When the level sets are
/// wider than the tube, a swept export's rings (flat within `flat_mm` RMS,
/// [`topology::swept_rings`]) that lie over [`SWEPT_RINGS_OFF_RADII`] end
/// radii from that guide take their place.
fn initial_guide(
    mesh: &TubeMesh,
    surf: &Surfaces,
    k: usize,
    [start, finish]: [&EndRing; 2],
    (edge, knot_h, flat_mm): (f64, f64, f64),
) -> Result<Vec<Point3>, FitError> {
    let skin = &surf.skins[k];
    let width = (3.0 * edge).max(start.radius / 3.0);
    let sets = topology::level_sets(mesh, &skin.triangles, &skin.loops[start.loops[k]], width);
    let far = skin.loops[finish.loops[k]]
        .iter()
        .map(|&v| sets.distance[v as usize])
        .fold(f64::INFINITY, f64::min);
    if !far.is_finite() {
        return Err(FitError::NotATube {
            file: mesh.file.clone(),
            found: "the two open ends are not connected by the surface".into(),
        });
    }
    let complete = ((far / width).floor() as usize).saturating_sub(1);
    let mut raw = Vec::new();
    for band in sets.bands.iter().take(complete) {
        // A level set in several rings on a skin with two open ends is not
        // a branch (a branch ends in an open end of its own): the distance
        // reaches a feature on one side apart from the wall beside it (a
        // lug). Its centroid is pulled towards the feature: no point there,
        // and the sections decide (a feature is named by them).
        if band.vertices > 0 && band.pieces < 2 {
            raw.push(band.centroid);
        }
    }
    let mut pts = thinned(start, &raw, finish, knot_h);
    // A swept export whose rings the level sets leave (bands wider than
    // the tube shear across a coarse coil's turn): through its rings.
    let r0 = start.radius.min(finish.radius);
    let ends = [start, finish].map(|e| &skin.loops[e.loops[k]][..]);
    let swept = (width > 2.0 * r0)
        .then(|| topology::swept_rings(mesh, &skin.triangles, ends, flat_mm))
        .flatten();
    if let Some(rings) = swept {
        let off = rings
            .iter()
            .map(|c| distance_to_polyline(c, &pts))
            .fold(0.0, f64::max);
        if off > SWEPT_RINGS_OFF_RADII * r0 {
            let through = thinned(start, &rings[1..rings.len() - 1], finish, knot_h);
            return Ok(with_ends_past(through, knot_h));
        }
    }
    if pts.len() == 2 {
        // No level set between the ends (a coarse mesh, whose bands are
        // wide): the cubic leaving each end along its normal.
        let n = ((finish.centre - start.centre).norm() / (0.5 * knot_h))
            .ceil()
            .max(2.0) as usize;
        let inner = end_cubic(start, finish, n);
        pts.splice(1..1, inner);
    }
    if (pts[pts.len() - 1] - pts[0]).norm() < 1e-3 {
        return Err(FitError::NotATube {
            file: mesh.file.clone(),
            found: "the two open ends have the same centre".into(),
        });
    }
    Ok(with_ends_past(pts, knot_h))
}

/// The start end's centre, the points `between` (mm, in order) at least
/// `knot_h / 2` from the point kept before them and from the far end's
/// centre, and the far end's centre.
fn thinned(start: &EndRing, between: &[Point3], finish: &EndRing, knot_h: f64) -> Vec<Point3> {
    let mut pts = vec![start.centre];
    for p in between {
        if (p - pts[pts.len() - 1]).norm() >= 0.5 * knot_h
            && (finish.centre - p).norm() >= 0.5 * knot_h
        {
            pts.push(*p);
        }
    }
    pts.push(finish.centre);
    pts
}

/// A swept export's ring further than this many end radii from the guide
/// through the level sets takes the guide through its rings
/// ([`topology::swept_rings`]).
const SWEPT_RINGS_OFF_RADII: f64 = 0.5;

/// Distance (mm) from `p` to the polyline through `pts` (at least one).
fn distance_to_polyline(p: &Point3, pts: &[Point3]) -> f64 {
    pts.windows(2)
        .map(|w| {
            let d = w[1] - w[0];
            let u = ((p - w[0]).dot(&d) / d.norm_squared().max(1e-300)).clamp(0.0, 1.0);
            (p - (w[0] + d * u)).norm()
        })
        .fold((p - pts[0]).norm(), f64::min)
}

/// `pts` (end to end, at least two) with one point past each end, along
/// the end chord, a quarter of `knot_h` (mm) out.
fn with_ends_past(mut pts: Vec<Point3>, knot_h: f64) -> Vec<Point3> {
    let n = pts.len();
    let before = pts[0] + (pts[0] - pts[1]).normalize() * (0.25 * knot_h);
    let after = pts[n - 1] + (pts[n - 1] - pts[n - 2]).normalize() * (0.25 * knot_h);
    pts.insert(0, before);
    pts.push(after);
    pts
}

/// `n - 1` points evenly spaced in the parameter of the cubic (Hermite)
/// from `start`'s centre to `finish`'s, leaving each along its end's normal
/// with the length that makes it a circular arc when the normals allow one;
/// the chord's midpoint when the normals are nearly opposed to the chord.
fn end_cubic(start: &EndRing, finish: &EndRing, n: usize) -> Vec<Point3> {
    let (p0, p1) = (start.centre, finish.centre);
    let chord = p1 - p0;
    let c = chord.norm();
    let along = |n: &UnitVector3| {
        let n = n.into_inner();
        if n.dot(&chord) < 0.0 {
            -n
        } else {
            n
        }
    };
    let (d0, d1) = (along(&start.normal), along(&finish.normal));
    let turn = d0.angle(&d1);
    if d0.dot(&chord) < 0.3 * c || d1.dot(&chord) < 0.3 * c || turn > 0.75 * std::f64::consts::PI {
        return vec![Point3::from((p0.coords + p1.coords) / 2.0)];
    }
    let m = arc_tangent_length(c, turn);
    let (m0, m1) = (d0 * m, d1 * m);
    (1..n)
        .map(|i| hermite(&p0, &m0, &p1, &m1, i as f64 / n as f64))
        .collect()
}
