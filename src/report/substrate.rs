//! The substrate as a page draws it: a plane as a square and a cylinder as
//! a band around the drawn points (part frame, mm), shared by the path's
//! page and the fit page.

use crate::geometry::Substrate;
use crate::math::{Point3, Vector3};

/// Triangles (part frame, mm, 9 floats each) of the substrate around the
/// drawn points `pos` (xyz triples), and a note when it is not drawn.
pub(super) fn substrate_triangles(
    substrate: Option<&Substrate>,
    pos: &[f32],
) -> (Option<Vec<f32>>, Option<&'static str>) {
    let Some(substrate) = substrate else {
        return (None, None);
    };
    let pts: Vec<Point3> = pos
        .chunks_exact(3)
        .map(|c| Point3::new(f64::from(c[0]), f64::from(c[1]), f64::from(c[2])))
        .collect();
    let mut lo = Vector3::repeat(f64::INFINITY);
    let mut hi = Vector3::repeat(f64::NEG_INFINITY);
    for p in &pts {
        lo = lo.inf(&p.coords);
        hi = hi.sup(&p.coords);
    }
    let centre = Point3::from((lo + hi) * 0.5);
    let size = (hi - lo).max().max(1.0);
    let mut tris: Vec<f32> = vec![];
    let mut push = |a: Point3, b: Point3, c: Point3| {
        for p in [a, b, c] {
            tris.extend([p.x as f32, p.y as f32, p.z as f32]);
        }
    };
    match substrate {
        Substrate::Plane { point, normal } => {
            let n = normal.into_inner();
            let c = centre - n * (centre - point).dot(&n);
            let u = n.cross(&if n.x.abs() < 0.9 {
                Vector3::x()
            } else {
                Vector3::y()
            });
            let u = u.normalize() * (0.75 * size);
            let v = n.cross(&u);
            let q = [c - u - v, c + u - v, c + u + v, c - u + v];
            push(q[0], q[1], q[2]);
            push(q[0], q[2], q[3]);
        }
        Substrate::Cylinder {
            axis_point,
            axis,
            radius,
        } => {
            let a = axis.into_inner();
            let (mut s0, mut s1) = (f64::INFINITY, f64::NEG_INFINITY);
            for p in &pts {
                let s = (p - axis_point).dot(&a);
                s0 = s0.min(s);
                s1 = s1.max(s);
            }
            let margin = 0.25 * size;
            let (s0, s1) = (s0 - margin, s1 + margin);
            let u = a
                .cross(&if a.x.abs() < 0.9 {
                    Vector3::x()
                } else {
                    Vector3::y()
                })
                .normalize();
            let v = a.cross(&u);
            let n = 48;
            let ring = |k: usize, s: f64| {
                let th = std::f64::consts::TAU * k as f64 / n as f64;
                axis_point + a * s + (u * th.cos() + v * th.sin()) * *radius
            };
            for k in 0..n {
                let (p0, p1) = (ring(k, s0), ring(k + 1, s0));
                let (p2, p3) = (ring(k + 1, s1), ring(k, s1));
                push(p0, p1, p2);
                push(p0, p2, p3);
            }
        }
        Substrate::Mesh(_) => return (None, Some("The mesh substrate is not drawn.")),
    }
    (Some(tris), None)
}
