//! A faster support function for the part's hulls in the whole-cell check,
//! with the same answer as parry's: GJK asks a hull for its vertex farthest
//! along a direction some ten to twenty times a distance query, and parry's
//! [`ConvexPolyhedron`] scans every vertex each time (a hull of a band of
//! layers holds about a hundred). Here the vertices are grouped into small
//! clusters, each with a bounding sphere; a cluster whose sphere cannot
//! reach the best dot product found (less a rounding slack far above the
//! dot product's rounding error) is skipped. The vertex returned is the one
//! parry's scan returns, to the bit: the largest computed dot product, the
//! lowest index among equals, so GJK takes the same steps and the distances
//! are the same numbers.

use parry3d_f64::shape::{ConvexPolyhedron, SupportMap};

use crate::math::{Point3, Vector3};

/// Fewest vertices a cluster may hold before it is split.
const CLUSTER_SIZE: usize = 8;

/// Most clusters of a hull: larger hulls get larger clusters.
const MAX_CLUSTERS: usize = 32;

/// Relative rounding slack of the culling (of `|p| |dir|`): a dot product of
/// three terms is computed within a few units of 1e-16 of it.
const SLACK: f64 = 1e-9;

/// One cluster: its bounding sphere (hull frame, mm) and its range in
/// [`ClusteredHull::members`].
#[derive(Debug, Clone)]
struct Cluster {
    centre: Vector3,
    radius: f64,
    members: std::ops::Range<usize>,
}

/// A convex hull's vertices in clusters (hull frame, mm).
#[derive(Debug, Clone)]
pub(super) struct ClusteredHull {
    points: Vec<Point3>,
    /// The vertices cluster by cluster, each with its index in `points`
    /// (ascending within a cluster).
    members: Vec<(Vector3, usize)>,
    clusters: Vec<Cluster>,
    /// The largest `|p|` over the vertices plus one (mm): the scale of the
    /// rounding slack.
    scale: f64,
}

impl ClusteredHull {
    /// The clusters of `hull`'s vertices: split at the median along the
    /// longest side of their box until small enough, at most
    /// [`MAX_CLUSTERS`] of them.
    pub(super) fn new(hull: &ConvexPolyhedron) -> Self {
        let points = hull.points().to_vec();
        let cap = CLUSTER_SIZE.max(points.len().div_ceil(MAX_CLUSTERS / 2));
        let mut clusters = Vec::new();
        let mut members = Vec::with_capacity(points.len());
        let mut stack = vec![(0..points.len()).collect::<Vec<usize>>()];
        while let Some(mut idx) = stack.pop() {
            if idx.is_empty() {
                continue;
            }
            if idx.len() <= cap {
                idx.sort_unstable();
                let n = idx.len() as f64;
                let centre = idx.iter().map(|&i| points[i].coords).sum::<Vector3>() / n;
                let radius = idx
                    .iter()
                    .map(|&i| (points[i].coords - centre).norm())
                    .fold(0.0, f64::max);
                let first = members.len();
                members.extend(idx.iter().map(|&i| (points[i].coords, i)));
                clusters.push(Cluster {
                    centre,
                    radius,
                    members: first..members.len(),
                });
                continue;
            }
            let (lo, hi) = idx.iter().fold(
                (
                    Vector3::repeat(f64::INFINITY),
                    Vector3::repeat(f64::NEG_INFINITY),
                ),
                |(lo, hi), &i| (lo.inf(&points[i].coords), hi.sup(&points[i].coords)),
            );
            let axis = (hi - lo).imax();
            idx.sort_by(|&a, &b| points[a][axis].total_cmp(&points[b][axis]));
            let upper = idx.split_off(idx.len() / 2);
            stack.push(idx);
            stack.push(upper);
        }
        let scale = 1.0 + points.iter().map(|p| p.coords.norm()).fold(0.0, f64::max);
        Self {
            points,
            members,
            clusters,
            scale,
        }
    }

    /// The index of the vertex parry's scan returns along `dir`.
    fn support_id(&self, dir: &Vector3) -> usize {
        let count = self.clusters.len();
        if !dir.iter().all(|v| v.is_finite()) || count == 0 || count > MAX_CLUSTERS {
            // parry's scan: no dot product beats the first vertex's with a
            // direction not finite
            return crate_scan(&self.points, dir);
        }
        let len = dir.norm();
        let slack = SLACK * self.scale * len;
        let mut bounds = [0.0; MAX_CLUSTERS];
        let mut first = 0;
        for (k, c) in self.clusters.iter().enumerate() {
            bounds[k] = c.centre.dot(dir) + c.radius * len;
            if bounds[k] > bounds[first] {
                first = k;
            }
        }
        let mut best = (f64::NEG_INFINITY, usize::MAX);
        self.scan(&self.clusters[first], dir, &mut best);
        for (k, c) in self.clusters.iter().enumerate() {
            if k != first && bounds[k] + slack >= best.0 {
                self.scan(c, dir, &mut best);
            }
        }
        best.1
    }

    /// Raises `best` (dot product, index) to the cluster's best vertex, the
    /// lower index among equals.
    fn scan(&self, c: &Cluster, dir: &Vector3, best: &mut (f64, usize)) {
        for (p, i) in &self.members[c.members.clone()] {
            let d = p.dot(dir);
            if d > best.0 || (d == best.0 && *i < best.1) {
                *best = (d, *i);
            }
        }
    }
}

/// parry's scan (`point_cloud_support_point_id`): the first vertex of the
/// largest dot product.
fn crate_scan(points: &[Point3], dir: &Vector3) -> usize {
    let mut best = 0;
    let mut best_dot = points.first().map_or(0.0, |p| p.coords.dot(dir));
    for (i, p) in points.iter().enumerate().skip(1) {
        let d = p.coords.dot(dir);
        if d > best_dot {
            best_dot = d;
            best = i;
        }
    }
    best
}

impl SupportMap for ClusteredHull {
    fn local_support_point(&self, dir: &Vector3) -> Point3 {
        self.points[self.support_id(dir)]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// parry's own scan (`point_cloud_support_point_id`), written out.
    fn scan(points: &[Point3], dir: &Vector3) -> usize {
        let mut best = 0;
        let mut best_dot = points[0].coords.dot(dir);
        for (i, p) in points.iter().enumerate().skip(1) {
            let d = p.coords.dot(dir);
            if d > best_dot {
                best_dot = d;
                best = i;
            }
        }
        best
    }

    #[test]
    fn the_clusters_answer_as_parrys_scan_on_a_band_of_tube_layers() {
        // five rings of 24 points, as a band of the part's wall (with flat
        // layers: ties along directions in a layer's plane)
        let pts: Vec<Point3> = (0..5)
            .flat_map(|k| {
                (0..24).map(move |i| {
                    let a = i as f64 * std::f64::consts::TAU / 24.0;
                    let r = 40.0 + 2.0 * k as f64;
                    Point3::new(r * a.cos() + 300.0, r * a.sin(), 2.5 * k as f64)
                })
            })
            .collect();
        let hull = ConvexPolyhedron::from_convex_hull(&pts).unwrap();
        let fast = ClusteredHull::new(&hull);
        assert!(fast.clusters.len() > 4, "{} clusters", fast.clusters.len());
        let mut dirs: Vec<Vector3> = vec![
            Vector3::z(),
            -Vector3::z(),
            Vector3::x(),
            Vector3::y(),
            Vector3::zeros(),
            Vector3::new(f64::NAN, 0.0, 1.0),
        ];
        let mut s = 0.123_f64;
        for _ in 0..5000 {
            let mut next = || {
                s = (s * 9301.0 + 49297.0) % 233280.0;
                s / 233280.0 * 2.0 - 1.0
            };
            dirs.push(Vector3::new(next(), next(), next()) * 10f64.powf(3.0 * next()));
        }
        for d in &dirs {
            assert_eq!(
                fast.support_id(d),
                scan(hull.points(), d),
                "direction {d:?}"
            );
            assert_eq!(
                fast.local_support_point(d),
                hull.local_support_point(d),
                "direction {d:?}"
            );
        }
    }
}
