//! **The tube's ends**, once the guide is fitted: how each end is closed
//! (open, a flat cap, a flat ring joining two skins) and how it is cut
//! (square or oblique to the guide), or why it is none of these (a rim that
//! is not flat, not round seen along the guide, a flat face covering part
//! of it). Mesh frame, mm.

use super::outcome::{which, EndKind, EndRing, EndShape};
use super::section::{fit_circle, fit_plane, plane_basis, SectionPoint};
use super::topology::Surfaces;
use super::{FitError, FitOptions, TubeMesh};
use crate::math::{Point3, UnitVector3, Vector3};

/// An end plane tilted from the guide's normal plane by more than this
/// (degrees) is cut obliquely: below it, the tilt of a CAD tool's square
/// cut on a helix (the coil's 3.3 degree pitch) or the fit's noise.
pub const OBLIQUE_TILT_DEG: f64 = 5.0;

/// A flat face covering at least this share of an end's rim vertices
/// (dimensionless) closes that end; a face covering less is a partial cap,
/// none of the ends the fit knows.
pub const CAP_COVER_FRACTION: f64 = 0.9;

/// Points of a vertex set (mm).
fn points(mesh: &TubeMesh, vs: &[u32]) -> Vec<Point3> {
    vs.iter().map(|&v| mesh.vertices[v as usize]).collect()
}

/// Classifies `end` (its loops in `surf`'s skins) against the fitted
/// guide's unit `tangent` there; `station` and `t_mm` name it in errors.
///
/// # Errors
/// [`FitError::UnknownEnd`]: a flat face covering part of the rim only,
/// closing one skin of two, a rim not flat or not round seen along the guide.
#[allow(clippy::too_many_arguments)]
pub(super) fn classify(
    mesh: &TubeMesh,
    surf: &Surfaces,
    end: &EndRing,
    first: bool,
    tangent: &Vector3,
    station: usize,
    t_mm: f64,
    opts: &FitOptions,
) -> Result<EndShape, FitError> {
    let refuse = |found: String| FitError::UnknownEnd {
        file: mesh.file.clone(),
        end: which(first).into(),
        station,
        t_mm,
        found,
    };
    let loops: Vec<&Vec<u32>> = end
        .loops
        .iter()
        .enumerate()
        .map(|(k, &l)| &surf.skins[k].loops[l])
        .collect();
    // Each skin's rim: the share of its vertices on each flat face.
    let cover: Vec<Vec<f64>> = loops
        .iter()
        .map(|l| {
            surf.caps
                .iter()
                .map(|c| {
                    let on = l
                        .iter()
                        .filter(|v| c.vertices.binary_search(v).is_ok())
                        .count();
                    on as f64 / l.len().max(1) as f64
                })
                .collect()
        })
        .collect();
    let best = |k: usize| {
        cover[k]
            .iter()
            .copied()
            .enumerate()
            .fold(
                (usize::MAX, 0.0),
                |a, (i, c)| if c > a.1 { (i, c) } else { a },
            )
    };
    let skin_name = |k: usize| {
        if loops.len() == 2 {
            format!("skin {k}'s ")
        } else {
            String::new()
        }
    };
    let mut kind = EndKind::Open;
    let bests: Vec<(usize, f64)> = (0..loops.len()).map(best).collect();
    if bests.iter().any(|b| b.1 > 0.0) {
        for (k, &(_, c)) in bests.iter().enumerate() {
            if c < CAP_COVER_FRACTION {
                return Err(refuse(format!(
                    "a flat face covers {:.0} % of {}rim ({} vertices); a cap covers at least {:.0} %",
                    100.0 * c,
                    skin_name(k),
                    loops[k].len(),
                    100.0 * CAP_COVER_FRACTION
                )));
            }
        }
        kind = match bests.as_slice() {
            [_] => EndKind::FlatCapped,
            [a, b] if a.0 == b.0 => EndKind::RingCapped,
            _ => {
                return Err(refuse(
                    "each skin's rim is closed by its own flat face, not by one ring joining the two skins"
                        .into(),
                ))
            }
        };
    }
    let rims: Vec<Vec<Point3>> = loops.iter().map(|l| points(mesh, l)).collect();
    // The rim's own axis: the direction along which it looks most like a
    // circle, searched from the guide's tangent (the guide bends a little
    // at an oblique end, where the sections hold part rings).
    let axis = rim_axis(&rims[0], tangent);
    let (e1, e2) = plane_basis(&axis);
    let mut radii = Vec::with_capacity(loops.len());
    for (k, pts) in rims.iter().enumerate() {
        let Some((c, n, max_dev)) = fit_plane(pts) else {
            return Err(refuse(format!(
                "{}rim of {} vertices has no plane",
                skin_name(k),
                pts.len()
            )));
        };
        let Some(circle) = fit_circle(&seen_along(pts, &e1, &e2), 0.0) else {
            return Err(refuse(format!(
                "{}rim of {} vertices is not a ring seen along the guide",
                skin_name(k),
                pts.len()
            )));
        };
        let allowed = opts.section_rms_allowed(circle.radius);
        let plane_rms =
            (pts.iter().map(|p| (p - c).dot(&n).powi(2)).sum::<f64>() / pts.len() as f64).sqrt();
        if plane_rms > allowed {
            return Err(refuse(format!(
                "{}rim is not flat: its {} vertices are {plane_rms:.3} mm RMS ({max_dev:.3} mm at most) from their best plane; allowed {allowed:.3} mm",
                skin_name(k),
                pts.len()
            )));
        }
        if circle.rms > allowed {
            return Err(refuse(format!(
                "{}rim seen along the guide is not a circle: its {} vertices are {:.3} mm RMS ({:.3} mm at most) from their best circle of radius {:.3} mm; allowed {allowed:.3} mm",
                skin_name(k),
                pts.len(),
                circle.rms,
                circle.max_dev,
                circle.radius
            )));
        }
        radii.push(circle.radius);
    }
    let tangent = axis;
    let cos = end.normal.dot(&tangent).abs().min(1.0);
    Ok(EndShape {
        kind,
        tilt: cos.acos(),
        radius: radii.iter().sum::<f64>() / radii.len().max(1) as f64,
    })
}

/// Points in the plane normal to a direction (basis `e1`, `e2`, mm).
fn seen_along(pts: &[Point3], e1: &Vector3, e2: &Vector3) -> Vec<SectionPoint> {
    pts.iter()
        .map(|p| SectionPoint {
            x: p.coords.dot(e1),
            y: p.coords.dot(e2),
            dt: 0.0,
        })
        .collect()
}

/// Largest tilt of the rim's axis from the guide's tangent searched (rad):
/// the guide's own error at an end, not a bend.
const RIM_AXIS_SEARCH_RAD: f64 = 0.3;

/// The direction near `tangent` along which the rim `pts` looks most like a
/// circle (least RMS of its circle fit): a pattern search over tilts about
/// two axes normal to the tangent, within [`RIM_AXIS_SEARCH_RAD`].
fn rim_axis(pts: &[Point3], tangent: &Vector3) -> UnitVector3 {
    let t0 = UnitVector3::new_normalize(*tangent);
    let (u1, u2) = plane_basis(&t0);
    let dir = |a: f64, b: f64| UnitVector3::new_normalize(t0.into_inner() + u1 * a + u2 * b);
    let cost = |a: f64, b: f64| {
        if a.hypot(b) > RIM_AXIS_SEARCH_RAD {
            return f64::INFINITY;
        }
        let (e1, e2) = plane_basis(&dir(a, b));
        fit_circle(&seen_along(pts, &e1, &e2), 0.0).map_or(f64::INFINITY, |c| c.rms)
    };
    let (mut a, mut b) = (0.0, 0.0);
    let mut best = cost(a, b);
    if !best.is_finite() {
        return t0;
    }
    let mut step = 0.05;
    while step > 1e-5 {
        let mut moved = false;
        for (da, db) in [(step, 0.0), (-step, 0.0), (0.0, step), (0.0, -step)] {
            let c = cost(a + da, b + db);
            if c < best {
                (a, b, best, moved) = (a + da, b + db, c, true);
            }
        }
        if !moved {
            step *= 0.5;
        }
    }
    dir(a, b)
}
