use super::{corner_seam_start, polyline_corners, Corner};
use crate::math::Point3;
use crate::path::{Layer, PathPoint};

/// A closed polygon through `vertices` (mm, z = 0), each side cut into `m`
/// equal steps (its first vertex kept, the next one starts the next side).
fn polygon(vertices: &[(f64, f64)], m: usize) -> Vec<Point3> {
    let k = vertices.len();
    (0..k)
        .flat_map(|i| {
            let (a, b) = (vertices[i], vertices[(i + 1) % k]);
            (0..m).map(move |j| {
                let s = j as f64 / m as f64;
                Point3::new(a.0 + s * (b.0 - a.0), a.1 + s * (b.1 - a.1), 0.0)
            })
        })
        .collect()
}

/// A closed layer through `pts`.
fn layer(pts: &[Point3]) -> Layer {
    Layer {
        slice: 1,
        points: pts
            .iter()
            .map(|&position| PathPoint {
                t: 0.0,
                v: 0.0,
                position,
                delta: None,
            })
            .collect(),
        closed: true,
    }
}

/// A right triangle whose angles are 90° at (0, 0), 60° at (10, 0) and
/// 30° at (0, 10·tan 60°), run counter-clockwise with 20 steps a side: its
/// polyline turns by the exterior angles, 90°, 120° and 150°, at points 0,
/// 20 and 40, and nowhere else.
fn triangle() -> Vec<Point3> {
    polygon(&[(0.0, 0.0), (10.0, 0.0), (0.0, 10.0 * 3f64.sqrt())], 20)
}

fn deg(d: f64) -> f64 {
    d.to_radians()
}

#[test]
fn a_triangles_corners_are_its_vertices_turning_by_their_exterior_angles() {
    let pts = triangle();
    let corners = polyline_corners(&pts, true, deg(10.0));
    assert_eq!(corners.len(), 3, "{corners:?}");
    for (c, (at, exterior)) in corners.iter().zip([(0, 90.0), (20, 120.0), (40, 150.0)]) {
        assert_eq!((c.point, c.first, c.last, c.span(60)), (at, at, at, 1));
        assert!((c.turn_rad - deg(exterior)).abs() < 1e-12, "{c:?}");
    }
    // the threshold keeps the sharper ones only
    let sharp: Vec<usize> = polyline_corners(&pts, true, deg(125.0))
        .iter()
        .map(|c| c.point)
        .collect();
    assert_eq!(sharp, vec![40]);
    assert!(polyline_corners(&pts, true, deg(155.0)).is_empty());
    // open, the same polyline has no corner at its ends (point 0)
    let open: Vec<usize> = polyline_corners(&pts, false, deg(10.0))
        .iter()
        .map(|c| c.point)
        .collect();
    assert_eq!(open, vec![20, 40]);
}

#[test]
fn a_regular_polygons_even_turning_is_no_corner() {
    // 12 sides, no point between vertices: every vertex turns 30°, the
    // median too, so the bar is 4 × 30° = 120°
    let vertices: Vec<(f64, f64)> = (0..12)
        .map(|i| {
            let a = std::f64::consts::TAU * i as f64 / 12.0;
            (10.0 * a.cos(), 10.0 * a.sin())
        })
        .collect();
    let pts = polygon(&vertices, 1);
    assert!(polyline_corners(&pts, true, deg(10.0)).is_empty());
    assert!(layer(&pts).corners(deg(10.0)).is_empty());
    assert_eq!(corner_seam_start(&pts, deg(10.0)), None);
}

#[test]
fn the_seam_goes_on_the_sharpest_corner() {
    let mut pts = triangle();
    // start mid-side: every corner inside the bead
    pts.rotate_left(7);
    assert!(layer(&pts).bead_wraps());
    let start = corner_seam_start(&pts, deg(10.0)).unwrap();
    // the 150° corner, now at point 33; its neighbours turn nothing (to
    // rounding), so either start puts it on the seam
    assert!(start == 33 || start == 34, "{start}");
    pts.rotate_left(start);
    let l = layer(&pts);
    assert!(!l.bead_wraps());
    let corners = l.corners(deg(10.0));
    let on: Vec<&Corner> = corners.iter().filter(|c| c.on_seam(60)).collect();
    assert_eq!(on.len(), 1);
    assert!((on[0].turn_rad - deg(150.0)).abs() < 1e-12);
}

#[test]
fn a_corner_over_two_vertices_is_one_corner_and_the_seam_takes_both() {
    // the triangle's 150° corner cut by a chamfer 0.5 mm either side of
    // it: two vertices turning 75° each, 150° across the corner
    let mut pts = triangle();
    let (b, c, a) = (pts[20], pts[40], pts[0]);
    let (into, out) = ((c - b).normalize(), (a - c).normalize());
    pts.splice(40..41, [c - into * 0.5, c + out * 0.5]);
    let n = pts.len();
    let corners = polyline_corners(&pts, true, deg(10.0));
    let points: Vec<usize> = corners.iter().map(|c| c.point).collect();
    assert_eq!(points[..2], [0, 20]);
    let chamfer = corners[2];
    assert_eq!((chamfer.first, chamfer.last, chamfer.span(n)), (40, 41, 2));
    // its two vertices turn alike (to rounding): either is its point
    assert!(chamfer.point == 40 || chamfer.point == 41, "{chamfer:?}");
    assert!((chamfer.turn_rad - deg(150.0)).abs() < 1e-12, "{chamfer:?}");
    // the seam between the two: the last point 40, the first 41
    assert_eq!(corner_seam_start(&pts, deg(10.0)), Some(41));
    pts.rotate_left(41);
    let l = layer(&pts);
    assert!(!l.bead_wraps());
    let corners = l.corners(deg(10.0));
    let seam = corners.iter().find(|c| c.on_seam(n)).unwrap();
    // wrapping round the seam: from the last point to the first
    assert_eq!((seam.first, seam.last, seam.span(n)), (n - 1, 0, 2));
    assert!((seam.turn_rad - deg(150.0)).abs() < 1e-12);
}
