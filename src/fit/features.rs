//! **Features that are not tube**: collars, flanges, blocks and tabs on a
//! tubular mesh, found when its sections stop being circles (mesh frame,
//! mm). The stations whose sections are circles of the tube's radius make
//! tubular stretches; the stations between them make features, each named
//! by its shape: a round outline all around is a collar (longer than it is
//! high) or a flange (higher than long), an outline all around that is not
//! round a block; an outline on one side of an intact wall a lug; a separate
//! piece of the mesh that is not a skin is a tab. An outline on one side
//! that is the far side of a shifted wall is not named (a guide off the axis
//! of a coarse bend gives one): the sections' failure stands. A cut of the mesh by the guide's normal planes to one
//! tubular stretch (for [`FitOptions::trim`](super::FitOptions::trim)).

use super::outcome::{FeatureKind, FeatureReport, Station};
use super::section::{fit_circle, plane_basis, SectionPoint};
use super::{FitError, FitOptions, TubeMesh};
use crate::geometry::guide::{CubicSpline, GuideCurve};
use crate::math::{Point3, UnitVector3, Vector3};
use std::collections::HashMap;

/// A station's section is a circle: each skin's points (`bins`) within
/// the bounds of the driver's section check (RMS, angular gap) of a circle
/// of constant radius (a fitted radius law's slope next to a feature is the
/// feature's); its largest radius.
fn round(bins: &[Vec<SectionPoint>], opts: &FitOptions) -> Option<f64> {
    let mut r: Option<f64> = None;
    for pts in bins {
        let f = fit_circle(pts, 0.0)?;
        let allowed = opts.section_rms_allowed(f.radius);
        if f.rms > allowed || f.max_gap_rad > opts.max_section_gap_deg.to_radians() {
            return None;
        }
        r = Some(r.map_or(f.radius, |r: f64| r.max(f.radius)));
    }
    r
}

/// A tubular stretch's radius within this fraction of the longest
/// stretch's is the same tube (dimensionless); a round stretch of another
/// radius (a collar's sleeve) is part of a feature.
const SAME_TUBE_RADIUS_FRACTION: f64 = 0.15;

/// Two neighbouring round sections whose radii differ by more than this
/// fraction of the radius (dimensionless) are not one tubular stretch.
const RADIUS_JUMP_FRACTION: f64 = 0.05;

/// An outline covering under this share of the directions around the
/// guide (dimensionless, all but the largest gap between its points'
/// directions: [`share_around`]) is on one side: a lug, when its wall stays
/// a circle.
const ALL_AROUND_FRACTION: f64 = 0.75;

/// An outline whose distance from the guide varies by more than this
/// fraction of its largest (dimensionless) is not round: a block.
const ROUND_OUTLINE_FRACTION: f64 = 0.1;

/// A feature spans at most this share of the tube's length (dimensionless).
const MAX_FEATURE_SHARE: f64 = 0.5;

/// Directions around the guide in which the outline is measured.
const SECTORS: usize = 72;

/// The tubular stretches (station ranges, inclusive) and the features
/// between them, from the stations of a guide whose sections failed:
/// `pos` the fitted points with `t` their guide parameters. Empty when
/// every station is round and of one tube (the failure is not a feature).
pub(super) fn detect(
    spline: &CubicSpline,
    stations: &[Station],
    pos: &[Point3],
    skin: &[u8],
    t: &[f64],
    opts: &FitOptions,
) -> (Vec<(usize, usize)>, Vec<FeatureReport>) {
    let n = stations.len();
    if n < 3 {
        return (Vec::new(), Vec::new());
    }
    let skins = stations[0].fits.len().max(1);
    let step = (stations[n - 1].t - stations[0].t) / (n - 1) as f64;
    let t0 = stations[0].t;
    let station_of = |tv: f64| (((tv - t0) / step).round().max(0.0) as usize).min(n - 1);
    let frames: Vec<(Point3, Vector3, Vector3)> = stations
        .iter()
        .map(|s| {
            let (e1, e2) = plane_basis(&UnitVector3::new_normalize(spline.d1(s.t)));
            (spline.point(s.t), e1, e2)
        })
        .collect();
    // Each fitted point in its station's plane (about the guide's point at
    // its own parameter), per skin.
    let mut bins: Vec<Vec<Vec<SectionPoint>>> = vec![vec![Vec::new(); skins]; n];
    let mut at: Vec<(usize, f64, f64, f64)> = Vec::with_capacity(pos.len());
    for ((p, &tv), &k) in pos.iter().zip(t).zip(skin) {
        let i = station_of(tv);
        let (_, e1, e2) = &frames[i];
        let o = p - spline.point(tv);
        let (x, y) = (o.dot(e1), o.dot(e2));
        bins[i][(k as usize).min(skins - 1)].push(SectionPoint {
            x,
            y,
            dt: tv - stations[i].t,
        });
        at.push((i, tv, x, y));
    }
    let radius: Vec<Option<f64>> = bins.iter().map(|b| round(b, opts)).collect();
    // Runs of round stations of a continuous radius. A station without
    // points (between the rings of a coarse export) carries the run on:
    // it says nothing against the tube.
    let empty: Vec<bool> = bins.iter().map(|b| b.iter().all(Vec::is_empty)).collect();
    let mut runs: Vec<(usize, usize)> = Vec::new();
    let mut last_r = f64::NAN;
    for i in 0..n {
        let Some(r) = radius[i] else {
            match runs.last_mut() {
                Some(run) if empty[i] && run.1 + 1 == i => run.1 = i,
                _ => {}
            }
            continue;
        };
        match runs.last_mut() {
            Some(run)
                if run.1 + 1 == i && (last_r - r).abs() <= RADIUS_JUMP_FRACTION * last_r.max(r) =>
            {
                run.1 = i
            }
            _ => runs.push((i, i)),
        }
        last_r = r;
    }
    // And back over the stations without points before it.
    for run in &mut runs {
        while run.0 > 0 && empty[run.0 - 1] {
            run.0 -= 1;
        }
    }
    let median = |run: &(usize, usize)| {
        let mut v: Vec<f64> = (run.0..=run.1).filter_map(|i| radius[i]).collect();
        let k = v.len() / 2;
        *v.select_nth_unstable_by(k, f64::total_cmp).1
    };
    let Some(main) = runs.iter().max_by_key(|r| r.1 - r.0).copied() else {
        return (Vec::new(), Vec::new());
    };
    let r_main = median(&main);
    let tube: Vec<(usize, usize)> = runs
        .into_iter()
        .filter(|r| (median(r) - r_main).abs() <= SAME_TUBE_RADIUS_FRACTION * r_main)
        .collect();
    let mut in_tube = vec![false; n];
    for r in &tube {
        in_tube[r.0..=r.1].iter_mut().for_each(|x| *x = true);
    }
    if in_tube.iter().all(|&x| x) {
        return (tube, Vec::new());
    }
    let mut features = Vec::new();
    for run in runs_of_false(&in_tube) {
        let (first, last) = (run.start, run.end - 1);
        // The tube's radius beside it: its neighbours', else the main run's.
        let beside: Vec<f64> = [first.checked_sub(1), Some(last + 1).filter(|&j| j < n)]
            .into_iter()
            .flatten()
            .filter_map(|j| radius[j])
            .collect();
        let r_tube = if beside.is_empty() {
            r_main
        } else {
            beside.iter().sum::<f64>() / beside.len() as f64
        };
        let margin = opts.max_rms_mm.max(0.1 * r_tube);
        // The outline: in each direction around the guide, the largest
        // distance of a point beyond the tube's wall; and the span of
        // those points along the guide.
        // Directions are measured from the first station's basis carried
        // along the feature (the stations' own plane bases turn about the
        // guide from one to the next along a bend, [`plane_basis`]): the
        // share they cover is the feature's, whichever station its points
        // project to (a flange's ring splits between two).
        let e1_first = frames[first].1;
        let turn: Vec<f64> = (first..=last)
            .map(|i| {
                let (_, e1, e2) = &frames[i];
                let tan = spline.d1(stations[i].t).normalize();
                let e = e1_first - tan * e1_first.dot(&tan);
                e.dot(e2).atan2(e.dot(e1))
            })
            .collect();
        let mut sector = vec![0.0_f64; SECTORS];
        let mut angles: Vec<f64> = Vec::new();
        let (mut t_lo, mut t_hi) = (f64::INFINITY, f64::NEG_INFINITY);
        for &(i, tv, x, y) in &at {
            let rho = x.hypot(y);
            if i < first || i > last || rho <= r_tube + margin {
                continue;
            }
            let a = (y.atan2(x) - turn[i - first]).rem_euclid(std::f64::consts::TAU);
            let k = ((a / std::f64::consts::TAU * SECTORS as f64) as usize).min(SECTORS - 1);
            sector[k] = sector[k].max(rho);
            angles.push(a);
            (t_lo, t_hi) = (t_lo.min(tv), t_hi.max(tv));
        }
        let out: Vec<f64> = sector.iter().copied().filter(|&o| o > 0.0).collect();
        let (lo, hi) = out
            .iter()
            .fold((f64::INFINITY, 0.0_f64), |a, &o| (a.0.min(o), a.1.max(o)));
        let cover = share_around(&mut angles);
        // Points past an end project beyond it along the guide.
        (t_lo, t_hi) = (t_lo.max(t0), t_hi.min(stations[n - 1].t).max(t_lo.max(t0)));
        let length = t_hi - t_lo;
        let height = (hi - r_tube).max(0.0);
        // Longer than the tube's longest tubular stretch, or over half the
        // tube, is not a feature on it: the tube itself fails (a coil whose
        // radius tapers by a third, its sections read against one radius),
        // and its failure stands.
        let longest = stations[main.1].t - stations[main.0].t;
        if out.is_empty()
            || length > longest
            || length > MAX_FEATURE_SHARE * (stations[n - 1].t - t0)
        {
            continue;
        }
        // An outline on one side only is what a guide off the tube's axis
        // gives as well (a coarse bend): a lug only when the wall beside it
        // is the tube's circle and the outline stands beyond that circle,
        // else not named a feature and the failure stands.
        let one_side = cover < ALL_AROUND_FRACTION;
        if one_side && !stands_off_the_wall(&at, (first, last), r_tube, margin, opts) {
            continue;
        }
        let kind = if one_side {
            FeatureKind::Lug
        } else if hi - lo > ROUND_OUTLINE_FRACTION * hi {
            FeatureKind::Block
        } else if length >= height {
            FeatureKind::Collar
        } else {
            FeatureKind::Flange
        };
        let mid = spline.point(0.5 * (t_lo + t_hi));
        features.push(FeatureReport {
            kind,
            first_station: first,
            last_station: last,
            t_from_mm: t_lo - t0,
            t_to_mm: t_hi - t0,
            length_mm: length,
            height_mm: height,
            across_mm: if out.is_empty() {
                [0.0; 2]
            } else {
                [2.0 * lo, 2.0 * hi]
            },
            around_deg: 360.0 * cover,
            centre_mm: mid.coords.into(),
            triangles: 0,
            box_mm: [0.0; 3],
        });
    }
    (tube, features)
}

/// The refusal of a feature that is not tube: `f`, the first of `count`.
pub(super) fn refusal(mesh: &TubeMesh, f: &FeatureReport, count: usize) -> FitError {
    let c = f.centre_mm;
    FitError::Feature {
        file: mesh.file.clone(),
        kind: f.kind.name(),
        station: f.first_station,
        last_station: f.last_station,
        t_mm: f.t_from_mm,
        t_end_mm: f.t_to_mm,
        size: format!(
            "{}, near ({:.1}, {:.1}, {:.1}) mm{}; with --trim (FitOptions::trim) the longest tubular stretch is fitted and the rest named in fit.json",
            f.size(),
            c[0],
            c[1],
            c[2],
            match count {
                1 => String::new(),
                n => format!(" (and {} more)", n - 1),
            }
        ),
    }
}

/// The share of the directions around the guide (dimensionless, 0 to 1)
/// that the directions `angles` (rad, from a common basis) span: all but
/// their largest gap. A ring of 32 points spans 31/32; a lug over 40
/// degrees, a ninth. Sorts `angles`.
fn share_around(angles: &mut [f64]) -> f64 {
    use std::f64::consts::TAU;
    if angles.len() < 2 {
        return 0.0;
    }
    angles.sort_unstable_by(f64::total_cmp);
    let wrap = angles[0] + TAU - angles[angles.len() - 1];
    let gap = angles.windows(2).map(|w| w[1] - w[0]).fold(wrap, f64::max);
    (TAU - gap) / TAU
}

/// The maximal runs of `false` in `flags` (index ranges, in order).
pub(super) fn runs_of_false(flags: &[bool]) -> Vec<std::ops::Range<usize>> {
    let mut runs = Vec::new();
    let mut i = 0;
    while i < flags.len() {
        if flags[i] {
            i += 1;
            continue;
        }
        let first = i;
        while i < flags.len() && !flags[i] {
            i += 1;
        }
        runs.push(first..i);
    }
    runs
}

/// The points of stations `first..=last` (`at`: station, guide parameter,
/// x and y in the station's plane, mm) within `margin` of the tube's wall
/// (radius `r_tube` about the guide, mm) lie on one circle of about the
/// tube's radius, and most of the points beyond the wall lie beyond that
/// circle too: something stands on one side of an intact wall. A guide off
/// the axis of a coarse bend fails this: the points beyond its wall are the
/// far side of the same, shifted, circle.
fn stands_off_the_wall(
    at: &[(usize, f64, f64, f64)],
    (first, last): (usize, usize),
    r_tube: f64,
    margin: f64,
    opts: &FitOptions,
) -> bool {
    let (mut wall, mut beyond) = (Vec::new(), Vec::new());
    for &(i, _, x, y) in at {
        if i < first || i > last {
            continue;
        }
        if x.hypot(y) <= r_tube + margin {
            wall.push(SectionPoint { x, y, dt: 0.0 });
        } else {
            beyond.push((x, y));
        }
    }
    let Some(c) = fit_circle(&wall, 0.0) else {
        return false;
    };
    let allowed = opts.section_rms_allowed(c.radius);
    if c.rms > allowed || (c.radius - r_tube).abs() > SAME_TUBE_RADIUS_FRACTION * r_tube {
        return false;
    }
    let outside = beyond
        .iter()
        .filter(|&&(x, y)| (x - c.centre[0]).hypot(y - c.centre[1]) > c.radius + margin)
        .count();
    2 * outside > beyond.len()
}

/// A separate piece of the mesh (`tris`) as a tab, at the stations its
/// vertices are nearest (`stations`' guide points).
pub(super) fn piece(
    mesh: &TubeMesh,
    tris: &[u32],
    stations: &[Station],
    spline: &CubicSpline,
) -> FeatureReport {
    let mut vs: Vec<u32> = tris
        .iter()
        .flat_map(|&t| mesh.triangles[t as usize])
        .collect();
    vs.sort_unstable();
    vs.dedup();
    let (lo, hi) = vs.iter().fold(
        (Point3::from([f64::MAX; 3]), Point3::from([f64::MIN; 3])),
        |(lo, hi), &v| {
            (
                lo.inf(&mesh.vertices[v as usize]),
                hi.sup(&mesh.vertices[v as usize]),
            )
        },
    );
    let centres: Vec<Point3> = stations.iter().map(|s| spline.point(s.t)).collect();
    let nearest = |p: &Point3| {
        centres
            .iter()
            .enumerate()
            .min_by(|a, b| (a.1 - p).norm().total_cmp(&(b.1 - p).norm()))
            .map_or(0, |(i, _)| i)
    };
    let (first, last) = vs.iter().fold((usize::MAX, 0), |a, &v| {
        let i = nearest(&mesh.vertices[v as usize]);
        (a.0.min(i), a.1.max(i))
    });
    let first = first.min(last);
    let c = Point3::from((lo.coords + hi.coords) / 2.0);
    FeatureReport {
        kind: FeatureKind::Tab,
        first_station: first,
        last_station: last,
        t_from_mm: stations.get(first).map_or(0.0, |s| s.t - stations[0].t),
        t_to_mm: stations.get(last).map_or(0.0, |s| s.t - stations[0].t),
        length_mm: 0.0,
        height_mm: 0.0,
        across_mm: [0.0; 2],
        around_deg: 0.0,
        centre_mm: c.coords.into(),
        triangles: tris.len(),
        box_mm: (hi - lo).into(),
    }
}

/// `mesh` cut to the stretch of the guide between the normal planes at
/// `t_lo` and `t_hi` (mm; `None`: that end of the mesh is kept): triangles
/// across a plane are cut along it (new vertices appended, one per cut
/// edge), those outside dropped; a vertex's side is its distance to the
/// plane within `reach` mm of the plane's guide parameter, else its own
/// guide parameter (`t_of`, `None` for a vertex fitted by no skin: the plane
/// decides).
pub(super) fn clip(
    mesh: &TubeMesh,
    spline: &CubicSpline,
    t_of: &[Option<f64>],
    t_lo: Option<f64>,
    t_hi: Option<f64>,
    reach: f64,
) -> TubeMesh {
    let mut out = mesh.clone();
    for (t_cut, sense) in [(t_lo, 1.0), (t_hi, -1.0)] {
        let Some(tc) = t_cut else { continue };
        let c = spline.point(tc);
        let n = spline.d1(tc).normalize() * sense;
        let side: Vec<f64> = out
            .vertices
            .iter()
            .enumerate()
            .map(|(v, p)| match t_of.get(v).copied().flatten() {
                Some(tv) if (tv - tc).abs() > reach => (tv - tc) * sense,
                _ => (p - c).dot(&n),
            })
            .collect();
        let mut cut: HashMap<(u32, u32), u32> = HashMap::new();
        let old = std::mem::take(&mut out.triangles);
        let mut tris = Vec::with_capacity(old.len());
        for tri in &old {
            let inside = tri.map(|v| side[v as usize] >= 0.0);
            if inside.iter().all(|&x| x) {
                tris.push(*tri);
                continue;
            }
            if !inside.iter().any(|&x| x) {
                continue;
            }
            let mut poly: Vec<u32> = Vec::with_capacity(4);
            for k in 0..3 {
                let (a, b) = (tri[k], tri[(k + 1) % 3]);
                let (da, db) = (side[a as usize], side[b as usize]);
                if da >= 0.0 {
                    poly.push(a);
                }
                if (da > 0.0 && db < 0.0) || (da < 0.0 && db > 0.0) {
                    let key = (a.min(b), a.max(b));
                    let id = *cut.entry(key).or_insert_with(|| {
                        let (p, q) = (key.0 as usize, key.1 as usize);
                        let s = side[p] / (side[p] - side[q]);
                        let x = out.vertices[p] + (out.vertices[q] - out.vertices[p]) * s;
                        out.vertices.push(x);
                        (out.vertices.len() - 1) as u32
                    });
                    poly.push(id);
                }
            }
            for k in 1..poly.len().saturating_sub(1) {
                tris.push([poly[0], poly[k], poly[k + 1]]);
            }
        }
        out.triangles = tris;
    }
    out
}

#[cfg(test)]
mod tests {
    use super::share_around;
    use std::f64::consts::TAU;

    /// A ring of n points spans all but one n-th; points from -20 to +20
    /// degrees (wrapping through zero) span 40 degrees; one point, none.
    #[test]
    fn the_share_around_is_all_but_the_largest_gap() {
        for n in [8, 32, 64] {
            let mut a: Vec<f64> = (0..n).map(|k| TAU * k as f64 / n as f64).collect();
            let want = (n - 1) as f64 / n as f64;
            assert!((share_around(&mut a) - want).abs() < 1e-12, "{n}");
        }
        let mut lug: Vec<f64> = (-20..=20)
            .map(|d| f64::from(d).to_radians().rem_euclid(TAU))
            .collect();
        assert!((share_around(&mut lug) - 40.0 / 360.0).abs() < 1e-12);
        assert_eq!(share_around(&mut [1.0]), 0.0);
    }
}
