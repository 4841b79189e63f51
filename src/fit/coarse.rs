//! **Stage 0a — a tube from a mesh: what a coarse export needs** (mesh
//! frame, mm). A coarse export (rings of vertices far apart along the tube,
//! straights written as one strip of long triangles) leaves stations with
//! no ring of their own: how far apart its rings lie and how far its
//! facets' chords sag inside a curved guide between them (a warning naming
//! the knots to take), plane cuts for stations that hold no vertex, a
//! warning when a varying radius is held only at rings far apart, and the
//! bridge over sections that are not circles (a lug) when the guide is
//! refitted without them.

use super::cut;
use super::features::runs_of_false;
use super::outcome::Station;
use super::samples::Samples;
use super::section::station_frames;
use super::topology::Surfaces;
use super::TubeMesh;
use crate::geometry::guide::{CubicSpline, GuideCurve};
use crate::math::Point3;

/// Knots closer than this many times a coarse export's distance between
/// its rings of vertices (dimensionless) get a warning ([`Coarseness::warning`]): a
/// coil in rings 12 mm apart, fitted with knots 4 mm apart, lies 0.14 mm
/// RMS off its true surface (0.38 mm at most) with its vertices fitted
/// within hundredths; with knots 18 mm apart, 0.002 mm. A bend in a few
/// stretches needs its closer knots: the choice is the user's.
const KNOT_RING_GAPS: f64 = 1.5;

/// ... when the facets' chords between the rings lie more than this inside
/// the fitted guide's curve (mm): half the slices' RMS goal (a straight
/// written as one strip of long triangles gets none).
const WARN_SAG_MM: f64 = 0.05;

/// Gap between stations holding rings of their own past which a varying
/// radius law gets a warning ([`sparse_rings`]), in end radii.
const SPARSE_RING_GAP_RADII: f64 = 2.0;

/// What a fit learnt of a mesh's coarseness along the guide (mm): the
/// distance between its rings of vertices ([`rings_apart`]; 0 when every
/// station holds its own ring) and the knot spacing it used.
#[derive(Debug, Clone, Copy, Default)]
pub(super) struct Coarseness {
    pub ring_gap: f64,
    pub knot_h: f64,
    /// How far the facets' chords between rings lie inside the fitted
    /// guide's curve at most: its largest curvature times the rings'
    /// distance squared over 8 (mm).
    pub sag: f64,
}

impl Coarseness {
    /// The rings' distance ([`rings_apart`]) and the chords' sag of the
    /// final `stations` about the fitted guide `spline`.
    pub(super) fn measure(&mut self, stations: &[Station], spline: &CubicSpline) {
        self.ring_gap = rings_apart(stations);
        let curvature = |t: f64| {
            let (d1, d2) = (spline.d1(t), spline.d2(t));
            d1.cross(&d2).norm() / d1.norm().powi(3).max(1e-12)
        };
        let most = stations.iter().map(|s| curvature(s.t)).fold(0.0, f64::max);
        self.sag = most * self.ring_gap * self.ring_gap / 8.0;
    }

    /// The warning of a coarse export whose rings of vertices lie further
    /// apart than 1 / [`KNOT_RING_GAPS`] of its knot spacing, where the
    /// facets' chords between them lie over [`WARN_SAG_MM`] inside the
    /// guide's curve.
    pub(super) fn warning(&self) -> Option<String> {
        let wide = KNOT_RING_GAPS * self.ring_gap;
        (self.ring_gap > 0.0 && self.knot_h < wide && self.sag > WARN_SAG_MM).then(|| {
            format!(
                "a coarse export: its rings of vertices lie about {:.1} mm apart along the guide, its knots {:.1} mm apart: between the rings the guide follows the facets' chords, up to {:.2} mm inside the curved tube; on a gently curved tube (a coil) knots {wide:.0} mm apart or more (--knot-spacing, FitOptions::knot_spacing_mm) run it smooth between them",
                self.ring_gap, self.knot_h, self.sag
            )
        })
    }
}

/// The typical distance (mm) along the guide between the rings of vertices
/// of a coarse export: the median gap between the runs of stations holding
/// rings of their own, where some stations hold none (they took their
/// neighbours' points); 0 when every station holds its own ring.
pub(super) fn rings_apart(stations: &[Station]) -> f64 {
    if stations.iter().all(|s| !s.widened) {
        return 0.0;
    }
    let mut centres: Vec<f64> = Vec::new();
    let mut run: Vec<f64> = Vec::new();
    for s in stations {
        if !s.widened && s.centre.is_some() {
            run.push(s.t);
        } else if !run.is_empty() {
            centres.push(run.iter().sum::<f64>() / run.len() as f64);
            run.clear();
        }
    }
    if !run.is_empty() {
        centres.push(run.iter().sum::<f64>() / run.len() as f64);
    }
    // A ring whose vertices fall either side of a station is one ring.
    let step = stations.get(1).map_or(0.0, |s| s.t - stations[0].t);
    centres.dedup_by(|b, a| {
        let near = *b - *a <= 2.5 * step;
        if near {
            *a = 0.5 * (*a + *b);
        }
        near
    });
    let mut gaps: Vec<f64> = centres.windows(2).map(|w| w[1] - w[0]).collect();
    if gaps.is_empty() {
        return 0.0;
    }
    let k = gaps.len() / 2;
    *gaps.select_nth_unstable_by(k, f64::total_cmp).1
}

/// A warning when the stations holding rings of their own lie more than
/// [`SPARSE_RING_GAP_RADII`] end radii `r0` (mm) apart somewhere: a coarse
/// export of a tube whose radius varies, whose radius law is then
/// interpolated where the mesh does not hold it.
pub(super) fn sparse_rings(stations: &[Station], r0: f64) -> Option<String> {
    let own: Vec<f64> = stations
        .iter()
        .filter(|s| !s.widened && s.radius.is_some())
        .map(|s| s.t)
        .collect();
    let (a, b) = own
        .windows(2)
        .map(|w| (w[0], w[1]))
        .max_by(|x, y| (x.1 - x.0).total_cmp(&(y.1 - y.0)))?;
    (b - a > SPARSE_RING_GAP_RADII * r0).then(|| {
        format!(
            "the radius varies, and the mesh holds it only at rings up to {:.1} mm apart (t = {a:.1} to {b:.1} mm): the radius law is interpolated between them",
            b - a
        )
    })
}

/// When under half the stations' vertices give a circle (the guide's refit
/// needs half), those without take their section from plane cuts of the
/// skins at the same frames ([`cut::cut_sections`]), their own
/// (a cut of the surface at the station, not its neighbours' points; the
/// facets lie up to r (1 - cos(pi / n)) inside an n-gon's circle): a
/// straight written as one strip of long triangles has no vertex between
/// its end rings, further apart than the stations borrow. `data`: the mesh, its surfaces, the samples (the skins' vertices
/// first) and their guide parameters; `at`: the guide, its range, the
/// stations' spacing and the end radius (mm). Stations with circles are
/// left as they are.
pub(super) fn fill_from_cuts(
    (mesh, surf, samples, t): (&TubeMesh, &Surfaces, &Samples, &[f64]),
    (spline, range, spacing, r0): (&CubicSpline, (f64, f64), f64, f64),
    stations: &mut [Station],
) {
    let held = stations.iter().filter(|s| s.centre.is_some()).count();
    if held * 2 >= stations.len() {
        return;
    }
    let (step, frames) = station_frames(spline, range, spacing);
    let cuts = cut::cut_sections(mesh, surf, samples, t, &frames, step, 2.0 * r0);
    for (s, c) in stations.iter_mut().zip(cuts) {
        if s.centre.is_none() && c.centre.is_some() {
            *s = c;
        }
    }
}

/// Replaces the centres (mm, at guide parameters `ts`, mm) of each run of
/// stations that are not `round` by the cubic (Hermite) between the round
/// centres either side, leaving each along the direction of the two round
/// centres behind it with the run's length in `t`: within a bend, close to
/// its arc. A run at an end, or with fewer than two round stations on a side,
/// is left as it is.
pub(super) fn bridge_not_round(ts: &[f64], centres: &mut [Point3], round: &[bool]) {
    let n = ts.len();
    for run in runs_of_false(round) {
        let (first, i) = (run.start, run.end);
        // Round stations a - 1, a before the run and b, b + 1 after it.
        let (Some(a), b) = (first.checked_sub(1), i) else {
            continue;
        };
        if a == 0 || !round[a - 1] || b + 1 >= n || !round[b + 1] {
            continue;
        }
        let span = ts[b] - ts[a];
        let dir = |p: usize, q: usize| (centres[q] - centres[p]).normalize() * span;
        let (p0, p1, m0, m1) = (centres[a], centres[b], dir(a - 1, a), dir(b, b + 1));
        for k in first..b {
            let s = (ts[k] - ts[a]) / span;
            let (s2, s3) = (s * s, s * s * s);
            centres[k] = Point3::from(
                p0.coords * (2.0 * s3 - 3.0 * s2 + 1.0)
                    + m0 * (s3 - 2.0 * s2 + s)
                    + p1.coords * (-2.0 * s3 + 3.0 * s2)
                    + m1 * (s3 - s2),
            );
        }
    }
}
