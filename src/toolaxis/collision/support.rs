//! A faster support function for convex hulls (the torch's nozzle here, the
//! part's hulls in the whole-cell check), with the same answer as parry's:
//! GJK asks a hull for its vertex farthest along a direction some ten to
//! twenty times a distance query, and parry's [`ConvexPolyhedron`] scans
//! every vertex each time (a hull of a band of layers holds about a
//! hundred, the nozzle's frustum 64). Here the vertices are grouped into small
//! clusters, each with a bounding sphere; a cluster whose sphere cannot
//! reach the best dot product found (less a rounding slack far above the
//! dot product's rounding error) is skipped. The vertex returned is the one
//! parry's scan returns, to the bit: the largest computed dot product, the
//! lowest index among equals, so GJK takes the same steps and the distances
//! are the same numbers.

use parry3d_f64::bounding_volume::{Aabb, BoundingSphere};
use parry3d_f64::mass_properties::MassProperties;
use parry3d_f64::query::{PointProjection, PointQuery, Ray, RayCast, RayIntersection};
use parry3d_f64::shape::{
    ConvexPolyhedron, FeatureId, PolygonalFeatureMap, Shape, ShapeType, SupportMap, TypedShape,
};

use crate::math::{Isometry3, Point3, Vector3};

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
pub(crate) struct ClusteredHull {
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
    pub(crate) fn new(hull: &ConvexPolyhedron) -> Self {
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

/// A convex hull that answers parry's queries as its [`ConvexPolyhedron`]
/// does, every one delegated to it, except its support function, which is
/// the [`ClusteredHull`]'s (the same vertex, found faster). Distance and
/// closest-point queries against it take the same steps and give the same
/// numbers as against the polyhedron.
#[derive(Debug, Clone)]
pub(crate) struct SupportedHull {
    hull: ConvexPolyhedron,
    clusters: ClusteredHull,
}

impl SupportedHull {
    /// `hull` with its vertices clustered.
    pub(crate) fn new(hull: ConvexPolyhedron) -> Self {
        let clusters = ClusteredHull::new(&hull);
        Self { hull, clusters }
    }
}

impl SupportMap for SupportedHull {
    fn local_support_point(&self, dir: &Vector3) -> Point3 {
        self.clusters.local_support_point(dir)
    }
}

impl RayCast for SupportedHull {
    fn cast_local_ray(&self, ray: &Ray, max_time_of_impact: f64, solid: bool) -> Option<f64> {
        self.hull.cast_local_ray(ray, max_time_of_impact, solid)
    }

    fn cast_local_ray_and_get_normal(
        &self,
        ray: &Ray,
        max_time_of_impact: f64,
        solid: bool,
    ) -> Option<RayIntersection> {
        self.hull
            .cast_local_ray_and_get_normal(ray, max_time_of_impact, solid)
    }

    fn intersects_local_ray(&self, ray: &Ray, max_time_of_impact: f64) -> bool {
        self.hull.intersects_local_ray(ray, max_time_of_impact)
    }
}

impl PointQuery for SupportedHull {
    fn project_local_point(&self, pt: &Point3, solid: bool) -> PointProjection {
        self.hull.project_local_point(pt, solid)
    }

    fn project_local_point_and_get_feature(&self, pt: &Point3) -> (PointProjection, FeatureId) {
        self.hull.project_local_point_and_get_feature(pt)
    }

    fn distance_to_local_point(&self, pt: &Point3, solid: bool) -> f64 {
        self.hull.distance_to_local_point(pt, solid)
    }

    fn contains_local_point(&self, pt: &Point3) -> bool {
        self.hull.contains_local_point(pt)
    }
}

impl Shape for SupportedHull {
    fn compute_local_aabb(&self) -> Aabb {
        self.hull.compute_local_aabb()
    }

    fn compute_local_bounding_sphere(&self) -> BoundingSphere {
        self.hull.compute_local_bounding_sphere()
    }

    fn compute_aabb(&self, position: &Isometry3) -> Aabb {
        self.hull.compute_aabb(position)
    }

    fn compute_bounding_sphere(&self, position: &Isometry3) -> BoundingSphere {
        self.hull.compute_bounding_sphere(position)
    }

    fn clone_dyn(&self) -> Box<dyn Shape> {
        Box::new(self.clone())
    }

    fn scale_dyn(&self, scale: &Vector3, num_subdivisions: u32) -> Option<Box<dyn Shape>> {
        self.hull.scale_dyn(scale, num_subdivisions)
    }

    fn mass_properties(&self, density: f64) -> MassProperties {
        self.hull.mass_properties(density)
    }

    fn shape_type(&self) -> ShapeType {
        ShapeType::Custom
    }

    fn as_typed_shape(&self) -> TypedShape<'_> {
        TypedShape::Custom(self)
    }

    fn ccd_thickness(&self) -> f64 {
        self.hull.ccd_thickness()
    }

    fn ccd_angular_thickness(&self) -> f64 {
        self.hull.ccd_angular_thickness()
    }

    fn is_convex(&self) -> bool {
        self.hull.is_convex()
    }

    fn as_support_map(&self) -> Option<&dyn SupportMap> {
        Some(self as &dyn SupportMap)
    }

    fn as_polygonal_feature_map(&self) -> Option<(&dyn PolygonalFeatureMap, f64)> {
        self.hull.as_polygonal_feature_map()
    }

    fn feature_normal_at_point(
        &self,
        feature: FeatureId,
        point: &Point3,
    ) -> Option<parry3d_f64::na::Unit<Vector3>> {
        self.hull.feature_normal_at_point(feature, point)
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

    #[test]
    fn a_supported_hull_answers_parrys_queries_as_its_polyhedron_to_the_bit() {
        use parry3d_f64::query;
        use parry3d_f64::shape::{Capsule, Polyline, Segment};
        // a nozzle-like frustum and a few beads as a polyline
        let pts: Vec<Point3> = [(6.0, 8.0), (12.0, 60.0)]
            .iter()
            .flat_map(|&(r, z)| {
                (0..32).map(move |i| {
                    let a = i as f64 * std::f64::consts::TAU / 32.0;
                    Point3::new(r * a.cos(), r * a.sin(), z)
                })
            })
            .collect();
        let plain = ConvexPolyhedron::from_convex_hull(&pts).unwrap();
        let fast = SupportedHull::new(plain.clone());
        let bead: Vec<Point3> = (0..200)
            .map(|i| {
                let a = i as f64 * 0.05;
                Point3::new(40.0 * a.cos(), 40.0 * a.sin(), 2.0 * (i / 126) as f64)
            })
            .collect();
        let wall = Polyline::new(bead, None);
        let capsule = Capsule::new(
            Point3::new(-30.0, 5.0, 0.0),
            Point3::new(30.0, -5.0, 4.0),
            3.0,
        );
        let segment = Segment::new(Point3::new(-30.0, 5.0, 0.0), Point3::new(30.0, -5.0, 4.0));
        let id = Isometry3::identity();
        let mut s = 0.5_f64;
        for _ in 0..300 {
            let mut next = || {
                s = (s * 9301.0 + 49297.0) % 233280.0;
                s / 233280.0 * 2.0 - 1.0
            };
            let pose = Isometry3::new(
                Vector3::new(45.0 * next(), 45.0 * next(), 10.0 * next()),
                Vector3::new(next(), next(), next()) * 1.5,
            );
            for other in [&wall as &dyn Shape, &capsule, &segment] {
                assert_eq!(
                    query::distance(&pose, &fast, &id, other).unwrap(),
                    query::distance(&pose, &plain, &id, other).unwrap()
                );
                let a = query::closest_points(&pose, &fast, &id, other, 4.0).unwrap();
                let b = query::closest_points(&pose, &plain, &id, other, 4.0).unwrap();
                assert_eq!(format!("{a:?}"), format!("{b:?}"));
            }
            assert_eq!(fast.compute_aabb(&pose), plain.compute_aabb(&pose));
        }
    }
}
