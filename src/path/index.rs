//! Nearest-segment queries on polylines (part frame, mm): an R-tree (`rstar`)
//! over the segments of one or more layers, with an exact clamped
//! point-to-segment distance [SPEC §3.2, eq. 2.20].

use crate::math::Point3;
use rstar::primitives::{GeomWithData, Line};
use rstar::RTree;

/// Distance from `p` to the segment `[a, b]` with the projection clamped to the
/// segment; returns `(distance, parameter in [0, 1])`.
pub fn point_segment_distance(p: &Point3, a: &Point3, b: &Point3) -> (f64, f64) {
    let ab = b - a;
    let l2 = ab.norm_squared();
    let s = if l2 > 0.0 {
        ((p - a).dot(&ab) / l2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    ((a + ab * s - p).norm(), s)
}

/// Identifies a segment: polyline index, and index of its first vertex.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SegmentId {
    /// Which polyline of the index.
    pub polyline: usize,
    /// The segment joins vertex `segment` to the next one (wrapping if closed).
    pub segment: usize,
}

/// Result of a nearest-segment query.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Nearest {
    /// Distance (mm).
    pub distance: f64,
    /// The segment.
    pub id: SegmentId,
    /// Clamped projection parameter on the segment, in `[0, 1]`.
    pub s: f64,
    /// Whether the projection is clamped at an open end of its polyline
    /// (the foot is the polyline's first or last vertex).
    pub at_open_end: bool,
}

type Seg = GeomWithData<Line<[f64; 3]>, SegmentId>;

/// A spatial index over the segments of some polylines.
#[derive(Debug, Clone)]
pub struct SegmentIndex {
    tree: RTree<Seg>,
    polylines: Vec<(Vec<Point3>, bool)>,
}

impl SegmentIndex {
    /// Indexes the given polylines: `(vertices, closed)`. A closed polyline
    /// includes the segment from its last vertex back to the first; a polyline
    /// of one vertex is a point.
    pub fn new(polylines: Vec<(Vec<Point3>, bool)>) -> Self {
        let mut segs = Vec::new();
        for (k, (pts, closed)) in polylines.iter().enumerate() {
            let n = pts.len();
            let count = match (n, closed) {
                (0, _) => 0,
                (1, _) => 1,
                (_, true) => n,
                (_, false) => n - 1,
            };
            for i in 0..count {
                let a = pts[i];
                let b = pts[(i + 1) % n];
                segs.push(GeomWithData::new(
                    Line::new(a.coords.into(), b.coords.into()),
                    SegmentId {
                        polyline: k,
                        segment: i,
                    },
                ));
            }
        }
        Self {
            tree: RTree::bulk_load(segs),
            polylines,
        }
    }

    /// Whether the index holds no segment.
    pub fn is_empty(&self) -> bool {
        self.tree.size() == 0
    }

    /// The indexed polylines.
    pub fn polylines(&self) -> &[(Vec<Point3>, bool)] {
        &self.polylines
    }

    fn segment_points(&self, id: SegmentId) -> (Point3, Point3) {
        let (pts, _) = &self.polylines[id.polyline];
        (pts[id.segment], pts[(id.segment + 1) % pts.len()])
    }

    fn make(&self, p: &Point3, id: SegmentId) -> Nearest {
        let (a, b) = self.segment_points(id);
        let (distance, s) = point_segment_distance(p, &a, &b);
        let (pts, closed) = &self.polylines[id.polyline];
        let n = pts.len();
        let at_open_end = !closed
            && ((id.segment == 0 && s == 0.0) || (id.segment + 2 >= n && s == 1.0) || n == 1);
        Nearest {
            distance,
            id,
            s,
            at_open_end,
        }
    }

    /// The nearest segment to `p`, `None` if the index is empty.
    pub fn nearest(&self, p: &Point3) -> Option<Nearest> {
        let q = [p.x, p.y, p.z];
        let seg = self
            .tree
            .nearest_neighbor(&q)
            .or_else(|| self.tree.nearest_neighbor_iter(&q).next())?;
        Some(self.make(p, seg.data))
    }

    /// Nearest segment by local descent from `hint` along its polyline: walks
    /// to neighbouring segments while the distance decreases. Exact only when
    /// the distance along the polyline is unimodal around the hint; callers
    /// confirm with [`SegmentIndex::nearest`].
    pub fn nearest_from(&self, p: &Point3, hint: SegmentId) -> Nearest {
        let (pts, closed) = &self.polylines[hint.polyline];
        let n = pts.len();
        let count = if n <= 1 {
            1
        } else if *closed {
            n
        } else {
            n - 1
        };
        let step = |i: usize, forward: bool| -> Option<usize> {
            match (forward, closed) {
                (true, true) => Some((i + 1) % count),
                (false, true) => Some((i + count - 1) % count),
                (true, false) => (i + 1 < count).then_some(i + 1),
                (false, false) => i.checked_sub(1),
            }
        };
        let mut best = self.make(p, hint);
        for forward in [true, false] {
            let mut i = hint.segment;
            let mut walked = 0;
            while let Some(j) = step(i, forward) {
                let cand = self.make(
                    p,
                    SegmentId {
                        polyline: hint.polyline,
                        segment: j,
                    },
                );
                if cand.distance < best.distance {
                    best = cand;
                    i = j;
                    walked += 1;
                    if walked > count {
                        break;
                    }
                } else {
                    break;
                }
            }
        }
        best
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn segment_distance_clamps() {
        let a = Point3::new(0.0, 0.0, 0.0);
        let b = Point3::new(10.0, 0.0, 0.0);
        assert_eq!(
            point_segment_distance(&Point3::new(5.0, 3.0, 0.0), &a, &b),
            (3.0, 0.5)
        );
        assert_eq!(
            point_segment_distance(&Point3::new(-4.0, 3.0, 0.0), &a, &b),
            (5.0, 0.0)
        );
    }

    #[test]
    fn rtree_agrees_with_brute_force() {
        let circle: Vec<Point3> = (0..100)
            .map(|k| {
                Point3::new(
                    20.0 * (k as f64 * 0.0628).cos(),
                    20.0 * (k as f64 * 0.0628).sin(),
                    0.0,
                )
            })
            .collect();
        let idx = SegmentIndex::new(vec![(circle.clone(), true)]);
        for q in [
            Point3::new(3.0, 25.0, 4.0),
            Point3::new(-30.0, 1.0, -2.0),
            Point3::new(0.0, 0.0, 5.0),
        ] {
            let brute = (0..100)
                .map(|i| point_segment_distance(&q, &circle[i], &circle[(i + 1) % 100]).0)
                .fold(f64::MAX, f64::min);
            let got = idx.nearest(&q).unwrap();
            assert!((got.distance - brute).abs() < 1e-12);
            let local = idx.nearest_from(
                &q,
                SegmentId {
                    polyline: 0,
                    segment: (got.id.segment + 7) % 100,
                },
            );
            assert!((local.distance - brute).abs() < 1e-12);
        }
        let open = SegmentIndex::new(vec![(circle[..10].to_vec(), false)]);
        let n = open.nearest(&Point3::new(40.0, -10.0, 0.0)).unwrap();
        assert!(n.at_open_end);
    }
}
