//! **The problem of one section**: a least-squares circle whose radius
//! varies along the guide at a given rate, fitted to points carried into the plane
//! normal to the guide at a station (station-plane coordinates, mm), and the
//! least-squares plane of a point set (for the open ends and flat faces).
//!
//! The circle is seeded by the algebraic (Kåsa) fit and refined by
//! Gauss–Newton on the geometric distances; both solve small normal
//! equations with nalgebra's Cholesky factorisation.

use crate::geometry::guide::{CubicSpline, GuideCurve};
use crate::math::{Point3, UnitVector3, Vector3};
use nalgebra::{Matrix3, SymmetricEigen};

/// One point of a section: `x`, `y` in the station plane (mm, any
/// orthonormal basis normal to the guide) and `dt`, its guide parameter
/// minus the station's (mm).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SectionPoint {
    /// Coordinate along the plane's first axis (mm).
    pub x: f64,
    /// Coordinate along the plane's second axis (mm).
    pub y: f64,
    /// Guide parameter of the point minus the station's (mm).
    pub dt: f64,
}

/// A fitted circle: `|p - centre| = radius + slope * dt` (station plane, mm),
/// `slope` given.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CircleFit {
    /// Centre in the station plane (mm).
    pub centre: [f64; 2],
    /// Radius at the station (mm).
    pub radius: f64,
    /// Change of the radius along the guide (mm per mm), as given.
    pub slope: f64,
    /// RMS of the points' distances to the circle (mm).
    pub rms: f64,
    /// Largest distance of a point to the circle (mm).
    pub max_dev: f64,
    /// Largest angle between consecutive points around the centre (rad).
    pub max_gap_rad: f64,
    /// Number of points.
    pub points: usize,
    /// Mean of the points' `dt` (mm along the guide from the station): the
    /// radius read without the slope is the radius at `dt` = this.
    pub mean_dt: f64,
}

/// Fewest points a section needs.
pub const MIN_SECTION_POINTS: usize = 6;

/// Fits a circle to `points`, whose radius changes by `slope` (mm per mm)
/// with their `dt`. The slope is given, not fitted: in a section cut
/// obliquely, `dt` varies with the angle around the circle and a fitted
/// slope would trade itself for a shift of the centre.
/// `None` with fewer than [`MIN_SECTION_POINTS`] points, collinear points,
/// or a non-finite result.
pub fn fit_circle(points: &[SectionPoint], slope: f64) -> Option<CircleFit> {
    if points.len() < MIN_SECTION_POINTS {
        return None;
    }
    let n = points.len() as f64;
    // Work about the mean for conditioning.
    let (mx, my) = points
        .iter()
        .fold((0.0, 0.0), |a, p| (a.0 + p.x / n, a.1 + p.y / n));
    // Kåsa: x² + y² + D x + E y + F = 0 in least squares.
    let mut a = Matrix3::zeros();
    let mut b = Vector3::zeros();
    for p in points {
        let (x, y) = (p.x - mx, p.y - my);
        let row = Vector3::new(x, y, 1.0);
        a += row * row.transpose();
        b -= row * (x * x + y * y);
    }
    let s = a.cholesky()?.solve(&b);
    let (mut cx, mut cy) = (-0.5 * s[0], -0.5 * s[1]);
    let r2 = cx * cx + cy * cy - s[2];
    if !(r2 > 0.0) {
        return None;
    }
    let mut p3 = Vector3::new(cx, cy, r2.sqrt());
    // Gauss–Newton on (cx, cy, r0): residual |p - c| - r0 - slope dt.
    for _ in 0..20 {
        let mut jtj = Matrix3::zeros();
        let mut jtr = Vector3::zeros();
        for p in points {
            let (dx, dy) = (p.x - mx - p3[0], p.y - my - p3[1]);
            let d = (dx * dx + dy * dy).sqrt().max(1e-12);
            let res = d - p3[2] - slope * p.dt;
            let j = Vector3::new(-dx / d, -dy / d, -1.0);
            jtj += j * j.transpose();
            jtr += j * res;
        }
        let step = jtj.cholesky()?.solve(&jtr);
        p3 -= step;
        if !p3.iter().all(|x| x.is_finite()) {
            return None;
        }
        if step.norm() < 1e-12 * (1.0 + p3[2].abs()) {
            break;
        }
    }
    (cx, cy) = (p3[0], p3[1]);
    let r0 = p3[2];
    if !(r0 > 0.0) {
        return None;
    }
    let (mut ss, mut max_dev) = (0.0, 0.0_f64);
    let mut angles = Vec::with_capacity(points.len());
    for p in points {
        let (dx, dy) = (p.x - mx - cx, p.y - my - cy);
        let res = (dx * dx + dy * dy).sqrt() - r0 - slope * p.dt;
        ss += res * res;
        max_dev = max_dev.max(res.abs());
        angles.push(dy.atan2(dx));
    }
    angles.sort_by(f64::total_cmp);
    let mut gap = angles[0] + std::f64::consts::TAU - angles[angles.len() - 1];
    for w in angles.windows(2) {
        gap = gap.max(w[1] - w[0]);
    }
    let fit = CircleFit {
        centre: [cx + mx, cy + my],
        radius: r0,
        slope,
        rms: (ss / n).sqrt(),
        mean_dt: points.iter().map(|p| p.dt).sum::<f64>() / n,
        max_dev,
        max_gap_rad: gap,
        points: points.len(),
    };
    (fit.radius > 0.0 && fit.rms.is_finite()).then_some(fit)
}

/// Least-squares plane of a point set (mm): its centroid, its unit normal
/// (the direction of least spread) and the largest distance of a point to it.
/// `None` for fewer than three points or no definite normal.
pub fn fit_plane(points: &[Point3]) -> Option<(Point3, UnitVector3, f64)> {
    if points.len() < 3 {
        return None;
    }
    let n = points.len() as f64;
    let c = points.iter().fold(Vector3::zeros(), |a, p| a + p.coords) / n;
    let mut cov = Matrix3::zeros();
    for p in points {
        let d = p.coords - c;
        cov += d * d.transpose();
    }
    let eig = SymmetricEigen::new(cov);
    let k = eig.eigenvalues.imin();
    let normal = UnitVector3::try_new(eig.eigenvectors.column(k).into_owned(), 1e-12)?;
    let max = points
        .iter()
        .map(|p| (p.coords - c).dot(&normal).abs())
        .fold(0.0, f64::max);
    max.is_finite().then_some((Point3::from(c), normal, max))
}

/// RMS distance (mm) of `points` from the plane through `centre` with unit
/// `normal` (mesh frame, mm).
pub fn plane_rms(points: &[Point3], centre: &Point3, normal: &Vector3) -> f64 {
    let sum: f64 = points
        .iter()
        .map(|p| (p - centre).dot(normal).powi(2))
        .sum();
    (sum / points.len().max(1) as f64).sqrt()
}

/// The least-squares circle of `pts` seen in the plane through `origin`
/// with unit `normal` (mm, slope 0): its centre (mesh frame, mm) and the
/// fit. `None` as [`fit_circle`].
pub fn circle_in_plane(
    pts: &[Point3],
    origin: &Point3,
    normal: &UnitVector3,
) -> Option<(Point3, CircleFit)> {
    let (e1, e2) = plane_basis(normal);
    let sp: Vec<SectionPoint> = pts
        .iter()
        .map(|p| SectionPoint {
            x: (p - origin).dot(&e1),
            y: (p - origin).dot(&e2),
            dt: 0.0,
        })
        .collect();
    let f = fit_circle(&sp, 0.0)?;
    Some((origin + e1 * f.centre[0] + e2 * f.centre[1], f))
}

/// Two unit vectors completing `normal` to a right-handed orthonormal basis.
pub fn plane_basis(normal: &UnitVector3) -> (Vector3, Vector3) {
    let pick = if normal.x.abs() < 0.6 {
        Vector3::x()
    } else {
        Vector3::y()
    };
    let e1 = normal.cross(&pick).normalize();
    let e2 = normal.cross(&e1);
    (e1, e2)
}

/// A station's frame: its guide parameter (mm), guide point (mm), unit
/// tangent and the unit basis of its plane.
pub type Frame = (f64, Point3, Vector3, Vector3, Vector3);

/// The stations' frames every `spacing` mm or a little less over `range`
/// (both ends included), and their step (mm).
pub fn station_frames(spline: &CubicSpline, range: (f64, f64), spacing: f64) -> (f64, Vec<Frame>) {
    let len = range.1 - range.0;
    let n = ((len / spacing).ceil() as usize).max(2);
    let step = len / n as f64;
    let frames = (0..=n)
        .map(|i| frame_at(spline, range.0 + i as f64 * step))
        .collect();
    (step, frames)
}

/// The station frame at guide parameter `ti` (mm): the guide's point, its
/// unit tangent and the plane's basis ([`plane_basis`]).
pub fn frame_at(spline: &CubicSpline, ti: f64) -> Frame {
    let tan = UnitVector3::new_normalize(spline.d1(ti));
    let (e1, e2) = plane_basis(&tan);
    (ti, spline.point(ti), tan.into_inner(), e1, e2)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn circle_with_varying_radius() {
        let pts: Vec<SectionPoint> = (0..60)
            .map(|k| {
                let v = k as f64 * 0.37;
                let dt = (k % 5) as f64 * 0.2 - 0.4;
                let r = 10.0 + 0.1 * dt;
                SectionPoint {
                    x: 3.0 + r * v.cos(),
                    y: -2.0 + r * v.sin(),
                    dt,
                }
            })
            .collect();
        let f = fit_circle(&pts, 0.1).unwrap();
        assert!((f.centre[0] - 3.0).abs() < 1e-9 && (f.centre[1] + 2.0).abs() < 1e-9);
        assert!((f.radius - 10.0).abs() < 1e-9);
        assert!(f.rms < 1e-9);
    }

    #[test]
    fn half_circle_has_a_half_turn_gap() {
        let pts: Vec<SectionPoint> = (0..=20)
            .map(|k| {
                let v = std::f64::consts::PI * k as f64 / 20.0;
                SectionPoint {
                    x: v.cos(),
                    y: v.sin(),
                    dt: 0.0,
                }
            })
            .collect();
        let f = fit_circle(&pts, 0.0).unwrap();
        assert!((f.max_gap_rad - std::f64::consts::PI).abs() < 1e-6);
    }
}
