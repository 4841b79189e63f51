//! **Stage 0a — a tube from a mesh: its laws** (mesh frame, mm). The radius
//! and wall-thickness laws fitted to the stations' sections along the
//! guide (a smoothing cubic over the knots), the knot spacing that keeps
//! the guide's refit stable where the radius changes, and which of two
//! skins is the outer one.

use super::outcome::Station;
use super::{smooth, FitError, TubeMesh};
use nalgebra::DMatrix;

/// Fewest stations with rings of their own that a radius or thickness law
/// is fitted to alone, leaving out the widened ones ([`fit_law`]).
const MIN_OWN_LAW_STATIONS: usize = 3;

/// Shortest knot interval (mm) that keeps the refit stable on a tube whose
/// radius changes: a guide tilted by `alpha` moves a section's centre by
/// about `A' A alpha` (the points of one side come from a wider part), so a
/// wiggle of wavelength `2 h` grows unless `h > pi |A'| A`; 20 % margin.
pub(super) fn coupling_gap(law: Option<&(Vec<f64>, Vec<f64>)>) -> f64 {
    let Some((k, v)) = law else { return 0.0 };
    let m = smooth::natural_second_derivatives(k, v);
    let mut worst = 0.0_f64;
    for w in k.windows(2) {
        for f in [0.0, 0.5, 1.0] {
            let t = w[0] + f * (w[1] - w[0]);
            let h = 1e-3 * (w[1] - w[0]);
            let d = (smooth::eval(k, v, &m, t + h) - smooth::eval(k, v, &m, t - h)) / (2.0 * h);
            worst = worst.max(d.abs() * smooth::eval(k, v, &m, t));
        }
    }
    1.2 * std::f64::consts::PI * worst
}

/// A law over `knots` fitted to the stations' values. With `own_rings`
/// (the final laws), to those of the stations whose rings are their own
/// when at least [`MIN_OWN_LAW_STATIONS`] have a value: a widened station's
/// value (a coarse mesh) leans on the refits' slope across the points it
/// borrowed, tens of mm away, and swung the law by ±2 mm between the rings
/// of a coarse export (a bridged one holds none,
/// [`bridge_between_rings`](super::coarse::bridge_between_rings)). The refits' slope law takes every station
/// (its knot spacing, [`coupling_gap`], keeps the guide of a coarse bend
/// smooth). `pick`: a station's value (mm) and the guide parameter (mm)
/// where it is read. A law that is not positive, or any law when
/// `straight`, is fitted again straight between the sections where they
/// leave it free ([`straight_between`]).
pub(super) fn fit_law(
    mesh: &TubeMesh,
    stations: &[Station],
    knots: &[f64],
    pick: &dyn Fn(&Station) -> Option<(f64, f64)>,
    own_rings: bool,
    straight: bool,
) -> Result<Law, FitError> {
    let own = stations
        .iter()
        .filter(|s| !s.widened && pick(s).is_some())
        .count();
    let all = !own_rings || own < MIN_OWN_LAW_STATIONS;
    let mut held: Vec<(f64, f64, f64)> = stations
        .iter()
        .filter(|s| all || !s.widened)
        .filter_map(|s| pick(s).map(|(t, v)| (t, v, s.points as f64)))
        .collect();
    held.sort_by(|a, b| a.0.total_cmp(&b.0));
    let solve = |data: &[(f64, f64, f64)]| {
        let ts: Vec<f64> = data.iter().map(|x| x.0).collect();
        let w: Vec<f64> = data.iter().map(|x| x.2).collect();
        let ys = DMatrix::from_fn(data.len(), 1, |i, _| data[i].1);
        smooth::fit(knots, &ts, &ys, &w, 1e-6)
            .map(|sol| sol.column(0).iter().copied().collect::<Vec<f64>>())
            .ok_or_else(|| FitError::Degenerate {
                file: mesh.file.clone(),
                station: 0,
                reason: "the radius law's least-squares system is singular".into(),
            })
    };
    let mut v = solve(&held)?;
    let straight = straight || v.iter().any(|&r| !(r > 0.0));
    if straight {
        let at = stations.iter().map(|s| s.t).chain(knots.iter().copied());
        v = solve(&[held.clone(), straight_between(at, &held)].concat())?;
    }
    if let Some(j) = v.iter().position(|&r| !(r > 0.0)) {
        let at = knots[j];
        let station = stations
            .iter()
            .enumerate()
            .min_by(|a, b| (a.1.t - at).abs().total_cmp(&(b.1.t - at).abs()))
            .map_or(0, |(i, _)| i);
        let (lo, hi) = held
            .iter()
            .fold((f64::MAX, f64::MIN), |m, x| (m.0.min(x.1), m.1.max(x.1)));
        return Err(FitError::Degenerate {
            file: mesh.file.clone(),
            station,
            reason: format!(
                "the law fitted to {} sections' values ({lo:.3} to {hi:.3} mm) is not positive at t = {at:.2} mm: the value changes faster along the guide than the sections hold it (a cone or a cap, not a tube?)",
                held.len()
            ),
        });
    }
    let kinks = if straight { kinks(&held) } else { Vec::new() };
    Ok(Law { values: v, kinks })
}

/// A law of [`fit_law`]: its values at the knots (mm) and, when it runs
/// straight between sections far apart, the guide parameters (mm) of the
/// sections where its slope turns by over [`KINK_SLOPE_TURN`].
pub(super) struct Law {
    pub values: Vec<f64>,
    pub kinks: Vec<f64>,
}

/// Change of a straight law's slope (mm per mm) at a section past which it
/// is a kink of the profile ([`Law::kinks`]): a reducer's cone meeting its
/// pipe turns by its flare's tangent (1.7 at 60 degrees).
const KINK_SLOPE_TURN: f64 = 0.05;

/// The guide parameters of the `held` sections (guide parameter, value,
/// weight; sorted) where the straight line through them turns by over
/// [`KINK_SLOPE_TURN`].
fn kinks(held: &[(f64, f64, f64)]) -> Vec<f64> {
    let slope = |a: &(f64, f64, f64), b: &(f64, f64, f64)| (b.1 - a.1) / (b.0 - a.0).max(1e-9);
    held.windows(3)
        .filter(|w| (slope(&w[1], &w[2]) - slope(&w[0], &w[1])).abs() > KINK_SLOPE_TURN)
        .map(|w| w[1].0)
        .collect()
}

/// Weight of a station's straight-line value ([`straight_between`]) as a
/// fraction of the least weight of the sections' own values: enough to hold
/// a law the sections leave free (the curvature penalty is ~1e-6 of the
/// data), too little to move it where they hold it (a bias under 1e-3).
const STRAIGHT_WEIGHT_FRACTION: f64 = 1e-3;

/// Values at the guide parameters `at` (mm: the stations' and the knots')
/// between two `held` sections (guide parameter, value, weight; sorted
/// along the guide): on the straight line between those two, at
/// [`STRAIGHT_WEIGHT_FRACTION`] of their weight.
/// Taken when the law through the sections alone is not positive (on the
/// last refit's sections: the final law then follows, [`Law::kinks`]): a
/// coarse export written as rings only where its profile bends (a reducer:
/// pipe, cone, pipe) leaves tens of knots between two rings, where the
/// least-curvature law through a step of the radius bowed below zero. Its
/// facets between the rings are straight, and so is the law there then.
/// Elsewhere the smooth law stays: a swelling written as a few rings is
/// nearer its author's shape smooth than straight between them.
fn straight_between(
    at: impl Iterator<Item = f64>,
    held: &[(f64, f64, f64)],
) -> Vec<(f64, f64, f64)> {
    let least = held.iter().map(|x| x.2).fold(f64::INFINITY, f64::min);
    let weight = STRAIGHT_WEIGHT_FRACTION * least;
    at.filter_map(|t| {
        // The held sections either side of `t` (none past the first or the
        // last; none at `t` itself).
        let b = held.partition_point(|h| h.0 < t);
        let (a, b) = (held.get(b.checked_sub(1)?)?, held.get(b)?);
        (b.0 > t && b.0 > a.0).then(|| {
            let u = (t - a.0) / (b.0 - a.0);
            (t, a.1 + u * (b.1 - a.1), weight)
        })
    })
    .collect()
}

/// Index of the outer skin (larger mean radius), when two.
pub(super) fn outer_skin(stations: &[Station]) -> usize {
    let mean = |k: usize| {
        let v: Vec<f64> = stations
            .iter()
            .filter_map(|s| s.fits.get(k).copied().flatten().map(|f| f.radius))
            .collect();
        v.iter().sum::<f64>() / v.len().max(1) as f64
    };
    usize::from(stations.first().is_some_and(|s| s.fits.len() == 2) && mean(1) > mean(0))
}
