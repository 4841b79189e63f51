//! **Stage 0a — a tube from a mesh: what a coarse export needs** (mesh
//! frame, mm). A coarse export (rings of vertices far apart along the tube,
//! straights written as one strip of long triangles) leaves stations with
//! no ring of their own: its flat rings of vertices (the exporter's own
//! samples of the axis and the tangent) and the cubic that bridges the
//! guide between two of them (straight along a straight leg, leaving a
//! leg along it), plane cuts for stations that hold no vertex,
//! how far apart its rings lie and how far its facets' chords sag inside a
//! curved guide between them where no ring bridges them (a warning naming
//! the knots to take), a warning when a varying radius is held only at
//! rings far apart, and the bridge over sections that are not circles (a
//! lug) when the guide is refitted without them.

use super::cut;
use super::features::runs_of_false;
use super::outcome::Station;
use super::samples::Samples;
use super::section::{circle_in_plane, fit_plane, plane_rms, station_frames};
use super::smooth::{arc_tangent_length, hermite};
use super::topology::Surfaces;
use super::{FitOptions, TubeMesh};
use crate::geometry::guide::{CubicSpline, GuideCurve};
use crate::math::{Point3, Vector3};

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

/// Runs of vertices along the guide further apart than this many station
/// spacings are separate rings ([`vertex_rings`]); within a ring the
/// vertices lie a ring's tilt to the guide apart at most.
const RING_APART_STEPS: f64 = 0.5;

/// Fewest vertices of each skin in a ring of a coarse export
/// ([`vertex_rings`]): a hexagon.
const MIN_RING_POINTS: usize = 6;

/// One ring of vertices of a coarse export (mesh frame, mm): a flat closed
/// ring of vertices with none nearby along the guide, as a sweep exporter
/// writes one section of the tube. Its plane is the tube's normal plane
/// there, its centre on the tube's axis.
#[derive(Debug, Clone, Copy)]
pub(super) struct VertexRing {
    /// Mean guide parameter of its vertices (mm).
    pub t: f64,
    /// Centre of its circle (the skins' mean).
    pub centre: Point3,
    /// Unit normal of its plane, along the guide's direction.
    pub normal: Vector3,
    /// Its vertices.
    pub points: usize,
}

/// The runs of the skins' vertices (the first `samples.vertices`, at guide
/// parameters `t`, mm) along the guide, apart by more than
/// [`RING_APART_STEPS`] station `step`s (mm), in order; each a ring of a
/// coarse export when it is flat (RMS) within
/// [`FitOptions::section_rms_allowed`] of its radius and a closed circle (gaps under `max_gap_deg`) of at least
/// [`MIN_RING_POINTS`] per skin, `None` when not (a stretch of a fine mesh,
/// a cap, two rings that the guide's tilt runs together).
pub(super) fn vertex_rings(
    samples: &Samples,
    t: &[f64],
    spline: &CubicSpline,
    step: f64,
    max_gap_deg: f64,
    opts: &FitOptions,
) -> Vec<Option<VertexRing>> {
    let n = samples.vertices.min(t.len());
    let mut order: Vec<usize> = (0..n).filter(|&i| t[i].is_finite()).collect();
    order.sort_by(|&a, &b| t[a].total_cmp(&t[b]));
    let mut runs: Vec<&[usize]> = Vec::new();
    let mut start = 0;
    for k in 1..=order.len() {
        if k == order.len() || t[order[k]] - t[order[k - 1]] > RING_APART_STEPS * step {
            runs.push(&order[start..k]);
            start = k;
        }
    }
    runs.into_iter()
        .map(|run| ring_of(run, samples, t, spline, max_gap_deg, opts))
        .collect()
}

/// The ring of vertices `run` (indices into `samples`), when it is one
/// ([`vertex_rings`]).
fn ring_of(
    run: &[usize],
    samples: &Samples,
    t: &[f64],
    spline: &CubicSpline,
    max_gap_deg: f64,
    opts: &FitOptions,
) -> Option<VertexRing> {
    let pts: Vec<Point3> = run.iter().map(|&i| samples.pos[i]).collect();
    let (c, normal, _) = fit_plane(&pts)?;
    let flat = plane_rms(&pts, &c, &normal);
    let mut centre = Vector3::zeros();
    for skin in 0..samples.skins {
        let pts: Vec<Point3> = run
            .iter()
            .filter(|&&i| samples.skin[i] as usize == skin)
            .map(|&i| samples.pos[i])
            .collect();
        if pts.len() < MIN_RING_POINTS {
            return None;
        }
        let (at, f) = circle_in_plane(&pts, &c, &normal)?;
        let allowed = opts.section_rms_allowed(f.radius);
        if f.rms > allowed || flat > allowed || f.max_gap_rad > max_gap_deg.to_radians() {
            return None;
        }
        centre += at.coords;
    }
    let tm = run.iter().map(|&i| t[i]).sum::<f64>() / run.len() as f64;
    let along = spline.d1(tm);
    let normal = if normal.dot(&along) < 0.0 {
        -normal.into_inner()
    } else {
        normal.into_inner()
    };
    Some(VertexRing {
        t: tm,
        centre: Point3::from(centre / samples.skins as f64),
        normal,
        points: run.len(),
    })
}

/// Two consecutive stretches between rings whose chords turn by less than
/// this (degrees) are straight ([`straight_stretches`]): a bend's chords
/// turn by its stretches' angle; an arc in stretches of 0.5 degrees sags
/// under 0.0011 of a stretch inside its chord.
const STRAIGHT_TURN_DEG: f64 = 0.5;

/// A stretch between rings that holds plane cuts and is longer than this
/// many times each stretch beside it is straight ([`straight_stretches`]):
/// an exporter writes a straight leg as one strip of long triangles, and a
/// curve in stretches of a few lengths each (their chords sag alike, by the
/// exporter's tolerance).
const STRAIGHT_LENGTH_RATIO: f64 = 2.0;

/// Which stretches between consecutive `rings` (`rings.len() - 1` of them)
/// are straight, from the rings' centres: its chord and a neighbour's turn
/// by under [`STRAIGHT_TURN_DEG`], or it holds a station's plane cut
/// (`cut`, per stretch: too long for its stations to borrow its rings'
/// vertices) and is over [`STRAIGHT_LENGTH_RATIO`] times as long as each
/// neighbour. `None` for a stretch with a missing ring or no neighbour to
/// tell it by.
fn straight_stretches(rings: &[Option<VertexRing>], cut: &[bool]) -> Vec<Option<bool>> {
    let chords: Vec<Option<Vector3>> = rings
        .windows(2)
        .map(|w| match w {
            [Some(a), Some(b)] => Some(b.centre - a.centre),
            _ => None,
        })
        .collect();
    (0..chords.len())
        .map(|i| {
            let d = chords[i]?;
            let beside: Vec<Vector3> = [i.checked_sub(1), Some(i + 1)]
                .into_iter()
                .flatten()
                .filter_map(|j| chords.get(j).copied().flatten())
                .collect();
            (!beside.is_empty()).then(|| {
                beside
                    .iter()
                    .any(|e| d.angle(e) < STRAIGHT_TURN_DEG.to_radians())
                    || (cut[i]
                        && beside
                            .iter()
                            .all(|e| d.norm() > STRAIGHT_LENGTH_RATIO * e.norm()))
            })
        })
        .collect()
}

/// Sets the centres (mm) of the stations between two consecutive runs of
/// vertices that are both rings of a coarse export ([`vertex_rings`]) and
/// hold no ring of their own to the cubic (Hermite) from one ring's centre
/// to the next: the facets between the rings are chords, inside a curved
/// tube, and the stations there hold only their neighbours' points (a
/// widened ring), none, or a plane cut of those chords. The rings' centres
/// are the exporter's own samples of the tube's axis. The cubic leaves a
/// ring along the tube's tangent there: along a straight stretch
/// ([`straight_stretches`]) its chord, from a straight stretch into a
/// curved one the straight's chord (a straight meets a bend at a tangent),
/// else the ring's normal. An exporter that takes a ring's normal from its
/// neighbours' centres leans the ring where a straight meets a bend (a
/// cubic along it left a pipe network's straight by 0.36 mm 19 mm before
/// its bend at 10 times scale); on a bend's arc that normal is its tangent.
/// The tangents' length makes the cubic an arc's when the rings are a
/// circular arc's (two tangents at `theta`: chord x 2 tan(theta / 4) /
/// sin(theta / 2)); parallel tangents give a straight. The bridged stations
/// weigh as their rings' mean. A station whose section is a plane cut
/// ([`fill_from_cuts`]) keeps its centre where its stretch is not told
/// curved (a straight's facets lie on it); on a curved stretch it is
/// bridged too. None of them holds a radius (nor wall thickness) then: the
/// radius law interpolates the rings' own (the facets lie up to
/// r (1 - cos(pi / n)) inside an n-gon's circle). Returns how many stations
/// it bridged.
pub(super) fn bridge_between_rings(
    stations: &mut [Station],
    rings: &[Option<VertexRing>],
) -> usize {
    let cut: Vec<bool> = rings
        .windows(2)
        .map(|w| match w {
            [Some(a), Some(b)] => stations.iter().any(|s| s.cut && s.t > a.t && s.t < b.t),
            _ => false,
        })
        .collect();
    let straight = straight_stretches(rings, &cut);
    // The unit chord of stretch `j` when it is straight.
    let straight_chord = |j: usize| match (straight.get(j), rings.get(j), rings.get(j + 1)) {
        (Some(Some(true)), Some(Some(p)), Some(Some(q))) => Some((q.centre - p.centre).normalize()),
        _ => None,
    };
    let mut set = 0;
    for (i, w) in rings.windows(2).enumerate() {
        let [Some(a), Some(b)] = w else { continue };
        let chord = b.centre - a.centre;
        let ta = straight_chord(i)
            .or_else(|| i.checked_sub(1).and_then(straight_chord))
            .unwrap_or(a.normal);
        let tb = straight_chord(i)
            .or_else(|| straight_chord(i + 1))
            .unwrap_or(b.normal);
        let curved = straight[i] == Some(false);
        let m = arc_tangent_length(chord.norm(), ta.angle(&tb));
        let (m0, m1) = (ta * m, tb * m);
        let weight = (a.points + b.points) / 2;
        for s in stations.iter_mut() {
            let own = !s.widened && s.centre.is_some();
            if (own && !s.cut) || s.t <= a.t || s.t >= b.t {
                continue;
            }
            // Its borrowed radius leans on the radius law's slope across
            // the rings, its cut one reads the facets: the law interpolates
            // the rings' own instead.
            (s.radius, s.thickness) = (None, None);
            if s.cut && !curved {
                continue;
            }
            let u = (s.t - a.t) / (b.t - a.t);
            s.centre = Some(hermite(&a.centre, &m0, &b.centre, &m1, u));
            s.points = weight;
            s.bridged = true;
            s.cut = false;
            set += 1;
        }
    }
    set
}

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
    /// Stations bridged between rings of vertices
    /// ([`bridge_between_rings`]): the guide there follows the rings, not
    /// the chords, and no warning is due.
    pub bridged: usize,
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
        let chords = self.ring_gap > 0.0 && self.bridged == 0;
        (chords && self.knot_h < wide && self.sag > WARN_SAG_MM).then(|| {
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
            s.cut = true;
        }
    }
}

/// An end of the tube for [`bridge_not_round`]: its guide parameter (mm),
/// its ring's centre (mesh frame, mm) and unit normal (either sense).
pub(super) type EndAnchor = (f64, Point3, Vector3);

/// Replaces the centres (mm, at guide parameters `ts`, mm) of each run of
/// stations that are not `round` by the cubic (Hermite) between the round
/// centres either side, leaving each along the direction of the two round
/// centres behind it with the run's length in `t`: within a bend, close to
/// its arc. A run at an end (a flange or a block holding it) runs to that
/// end's centre, arriving along its normal: `ends`, the start's and the
/// finish's guide parameter (mm), centre (mesh frame, mm) and unit normal
/// (either sense). A run with fewer than two round stations on a side
/// within the tube is left as it is.
pub(super) fn bridge_not_round(
    ts: &[f64],
    centres: &mut [Point3],
    round: &[bool],
    ends: [EndAnchor; 2],
) {
    let n = ts.len();
    for run in runs_of_false(round) {
        let unit = |p: usize, q: usize| (centres[q] - centres[p]).normalize();
        // Each side: (guide parameter, point, unit direction along the guide).
        let from = match run.start.checked_sub(1) {
            Some(a) if a > 0 && round[a - 1] => (ts[a], centres[a], unit(a - 1, a)),
            None if run.end < n => {
                let (t, c, normal) = ends[0];
                (t, c, normal * normal.dot(&(centres[run.end] - c)).signum())
            }
            _ => continue,
        };
        let b = run.end;
        let to = if b + 1 < n && round[b + 1] {
            (ts[b], centres[b], unit(b, b + 1))
        } else if b == n && run.start > 0 {
            let (t, c, normal) = ends[1];
            (t, c, normal * normal.dot(&(c - from.1)).signum())
        } else {
            continue;
        };
        let span = to.0 - from.0;
        if span <= 0.0 {
            continue;
        }
        let (m0, m1) = (from.2 * span, to.2 * span);
        for k in run {
            centres[k] = hermite(&from.1, &m0, &to.1, &m1, (ts[k] - from.0) / span);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::{FRAC_PI_2, FRAC_PI_4};

    /// A station at `t` (mm) holding no ring of its own.
    fn borrowed(t: f64) -> Station {
        let frame = (
            t,
            Point3::origin(),
            Vector3::z(),
            Vector3::x(),
            Vector3::y(),
        );
        let mut s = Station::from_fits(&frame, vec![None], 0, false);
        s.widened = true;
        s
    }

    fn ring(t: f64, centre: Point3, normal: Vector3) -> Option<VertexRing> {
        Some(VertexRing {
            t,
            centre,
            normal,
            points: 16,
        })
    }

    /// Rings 12 mm apart, knots 4 mm apart and chords 0.2 mm inside the
    /// curve: the warning names the rings' and the knots' spacing, the sag
    /// and the knots to take (18 mm); no warning once bridged, with chords
    /// under 0.05 mm inside, or with knots as wide as 1.5 ring gaps.
    #[test]
    fn the_chords_warning_names_the_rings_and_the_knots() {
        let coarse = Coarseness {
            ring_gap: 12.0,
            knot_h: 4.0,
            sag: 0.2,
            bridged: 0,
        };
        let w = coarse.warning().expect("a warning");
        for part in [
            "12.0 mm apart",
            "knots 4.0 mm apart",
            "up to 0.20 mm inside",
            "knots 18 mm apart or more",
        ] {
            assert!(w.contains(part), "{part}: {w}");
        }
        for quiet in [
            Coarseness {
                bridged: 3,
                ..coarse
            },
            Coarseness {
                sag: 0.04,
                ..coarse
            },
            Coarseness {
                knot_h: 18.5,
                ..coarse
            },
            Coarseness {
                ring_gap: 0.0,
                ..coarse
            },
        ] {
            assert_eq!(quiet.warning(), None, "{quiet:?}");
        }
    }

    /// Two rings 40 degrees apart on an arc of radius 50 mm: the bridge
    /// between them lies on the arc (the cubic's closed-form error there is
    /// about 2e-6 of the radius); a ring between them of its own is kept.
    #[test]
    fn the_bridge_between_two_rings_of_an_arc_lies_on_the_arc() {
        let (radius, theta) = (50.0, 40f64.to_radians());
        let at = |a: f64| Point3::new(radius * a.cos(), radius * a.sin(), 0.0);
        let along = |a: f64| Vector3::new(-a.sin(), a.cos(), 0.0);
        let rings = [
            ring(0.0, at(0.0), along(0.0)),
            ring(radius * theta, at(theta), along(theta)),
        ];
        let mut stations: Vec<Station> = (1..20)
            .map(|i| borrowed(radius * theta * i as f64 / 20.0))
            .collect();
        stations[9].widened = false;
        stations[9].centre = Some(Point3::new(1.0, 2.0, 3.0));
        assert_eq!(bridge_between_rings(&mut stations, &rings), 18);
        for s in &stations {
            let c = s.centre.expect("a centre");
            if s.bridged {
                let off = (c.coords.norm() - radius).abs();
                assert!(off < 2e-4, "t {}: {off} mm off the arc", s.t);
                assert_eq!(s.points, 16);
            } else {
                assert_eq!(c, Point3::new(1.0, 2.0, 3.0));
            }
        }
    }

    /// Two parallel rings on one axis: the bridge is the straight between
    /// them; a run of vertices that is no ring (`None`) stops the bridge.
    #[test]
    fn the_bridge_between_two_parallel_rings_is_straight() {
        let z = Vector3::z();
        let rings = [
            ring(0.0, Point3::new(1.0, 2.0, 0.0), z),
            ring(30.0, Point3::new(1.0, 2.0, 30.0), z),
            None,
            ring(60.0, Point3::new(1.0, 2.0, 60.0), z),
        ];
        let mut stations: Vec<Station> = (1..60).map(|i| borrowed(i as f64)).collect();
        assert_eq!(bridge_between_rings(&mut stations, &rings), 29);
        for s in stations.iter().filter(|s| s.bridged) {
            let c = s.centre.expect("a centre");
            assert!((c - Point3::new(1.0, 2.0, s.t)).norm() < 1e-9, "{c:?}");
        }
        assert!(stations.iter().filter(|s| s.t > 30.0).all(|s| !s.bridged));
    }

    /// A leg 200 mm long meets an arc of radius 40 mm in two stretches of
    /// 45 degrees, then a second leg; each ring's normal is taken from its
    /// neighbours' centres, so the rings at the joins lean 2.94 degrees
    /// toward the arc. The legs (their stations hold plane cuts) are
    /// straight, the arc's stretches not, though one holds a cut of its
    /// chords. The bridge stays on each leg's axis up to its ring, and runs
    /// on the arc between the joins, the cut on the arc bridged too.
    #[test]
    fn a_leaning_ring_where_a_leg_meets_an_arc_bridges_both_true() {
        let radius = 40.0;
        let arc = |a: f64| Point3::new(radius * (1.0 - a.cos()), 0.0, 200.0 + radius * a.sin());
        let c = [
            Point3::origin(),
            arc(0.0),
            arc(FRAC_PI_4),
            arc(FRAC_PI_2),
            arc(FRAC_PI_2) + Vector3::x() * 200.0,
        ];
        let ts = [
            0.0,
            200.0,
            200.0 + radius * FRAC_PI_4,
            200.0 + radius * FRAC_PI_2,
            400.0 + radius * FRAC_PI_2,
        ];
        let rings: Vec<Option<VertexRing>> = (0..5_usize)
            .map(|i| {
                let (p, q) = (c[i.saturating_sub(1)], c[(i + 1).min(4)]);
                ring(ts[i], c[i], (q - p).normalize())
            })
            .collect();
        let lean = rings[1].expect("a ring").normal.angle(&Vector3::z());
        assert!((lean.to_degrees() - 2.94).abs() < 0.01, "{lean}");
        let on_leg = |t: f64| t < ts[1] || t > ts[3];
        let mut stations: Vec<Station> = (0..231).map(|i| borrowed(2.0 * i as f64 + 1.0)).collect();
        for s in stations.iter_mut() {
            let leg_cut = (s.t > 20.0 && s.t < 180.0) || (s.t > 282.0 && s.t < 442.0);
            if leg_cut || (s.t - 215.0).abs() < 1.0 {
                (s.widened, s.cut) = (false, true);
                // A leg's cut lies on its axis, the arc's on its chord.
                s.centre = Some(if s.t < ts[1] {
                    Point3::new(0.0, 0.0, s.t)
                } else if s.t > ts[3] {
                    c[3] + Vector3::x() * (s.t - ts[3])
                } else {
                    c[1] + (c[2] - c[1]) * ((s.t - ts[1]) / (ts[2] - ts[1]))
                });
            }
        }
        let cut: Vec<bool> = vec![true, true, false, true];
        assert_eq!(
            straight_stretches(&rings, &cut),
            vec![Some(true), Some(false), Some(false), Some(true)]
        );
        bridge_between_rings(&mut stations, &rings);
        for s in &stations {
            let p = s.centre.expect("a centre");
            let off = if on_leg(s.t) {
                let axis = if s.t < ts[1] {
                    p.coords.xy().norm()
                } else {
                    (p.z - 240.0).abs() + p.y.abs()
                };
                assert!(
                    !s.bridged || axis < 1e-9,
                    "t {}: {axis} mm off the leg",
                    s.t
                );
                axis
            } else {
                assert!(s.bridged, "t {}", s.t);
                ((p - Point3::new(radius, 0.0, 200.0)).norm() - radius).abs()
            };
            assert!(off < 2e-4 * radius, "t {}: {off} mm off", s.t);
        }
    }

    /// A station between two rings whose section is a plane cut of the
    /// facets keeps its centre (a straight's facets lie on it) but not its
    /// radius (the facets read inside the circle): the law takes the rings'.
    #[test]
    fn a_cut_between_two_rings_keeps_its_centre_not_its_radius() {
        let z = Vector3::z();
        let rings = [
            ring(0.0, Point3::origin(), z),
            ring(30.0, Point3::new(0.0, 0.0, 30.0), z),
        ];
        let mut cut = borrowed(15.0);
        (cut.widened, cut.cut) = (false, true);
        cut.centre = Some(Point3::new(0.0, 0.0, 15.0));
        cut.radius = Some(9.95);
        let mut stations = vec![cut];
        assert_eq!(bridge_between_rings(&mut stations, &rings), 0);
        let s = &stations[0];
        assert_eq!(s.centre, Some(Point3::new(0.0, 0.0, 15.0)));
        assert_eq!(s.radius, None);
        assert!(!s.bridged);
    }

    /// Runs not round at both ends (a flange on each) run to the ends'
    /// centres, here on the line of the round centres; a run between them
    /// takes the cubic, on the same line; a run with one round centre
    /// beside it stays.
    #[test]
    fn runs_not_round_at_the_ends_run_to_the_end_rings() {
        let line = |t: f64| Point3::new(1.0 + 0.6 * t, -2.0, 0.8 * t);
        let ts: Vec<f64> = (0..10).map(f64::from).collect();
        let round = [
            false, false, true, true, false, true, true, true, false, false,
        ];
        let pulled = Vector3::new(4.0, 0.0, 0.0);
        let mut centres: Vec<Point3> = ts
            .iter()
            .zip(&round)
            .map(|(&t, &r)| if r { line(t) } else { line(t) + pulled })
            .collect();
        let u = Vector3::new(0.6, 0.0, 0.8);
        let ends = [(-1.0, line(-1.0), -u), (10.0, line(10.0), u)];
        bridge_not_round(&ts, &mut centres, &round, ends);
        for (c, &t) in centres.iter().zip(&ts) {
            assert!(
                (c - line(t)).norm() < 1e-12,
                "t {t}: {c} against {}",
                line(t)
            );
        }
        let round = [true, false, true, true, true];
        let mut centres: Vec<Point3> = (0..5).map(|i| line(f64::from(i)) + pulled).collect();
        let before = centres.clone();
        bridge_not_round(&ts[..5], &mut centres, &round, ends);
        assert_eq!(centres, before);
    }
}
