//! Interlayer distance map [SPEC §3.2; thesis fig. 2.2, 2.6–2.8, eq. 2.20]:
//! for every point of layer `n`, the distance to the nearest segment of
//! layer `n − 1` (clamped projection), with statistics per layer and overall.
//! Works on any path, including one read from a file.

use super::index::SegmentIndex;
use super::{Layer, Path};
use rayon::prelude::*;
use serde::Serialize;

/// Statistics of local distances (mm) against the target `Delta`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct DistanceStats {
    /// Points counted.
    pub count: usize,
    /// Smallest distance (mm).
    pub min_mm: f64,
    /// Largest distance (mm).
    pub max_mm: f64,
    /// Mean distance (mm).
    pub mean_mm: f64,
    /// `(max − min) / Delta`.
    pub variation: f64,
    /// `(min − Delta) / Delta`.
    pub min_rel: f64,
    /// `(max − Delta) / Delta`.
    pub max_rel: f64,
    /// Points left out because their nearest point below is the cut end of an
    /// open layer (not an interlayer distance).
    pub boundary_points: usize,
}

impl DistanceStats {
    fn from(values: &[f64], delta: f64, boundary_points: usize) -> Option<Self> {
        if values.is_empty() {
            return None;
        }
        let min = values.iter().copied().fold(f64::INFINITY, f64::min);
        let max = values.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        let mean = values.iter().sum::<f64>() / values.len() as f64;
        Some(Self {
            count: values.len(),
            min_mm: min,
            max_mm: max,
            mean_mm: mean,
            variation: (max - min) / delta,
            min_rel: (min - delta) / delta,
            max_rel: (max - delta) / delta,
            boundary_points,
        })
    }
}

/// The distance map of a path.
#[derive(Debug, Clone, PartialEq)]
pub struct DistanceMap {
    /// Per layer (same order as the path's layers): `None` on the first slice.
    pub per_layer: Vec<Option<DistanceStats>>,
    /// Over the whole path.
    pub overall: Option<DistanceStats>,
    /// Per point: the distance (mm) and whether it is a boundary point.
    pub points: Vec<Vec<Option<(f64, bool)>>>,
}

/// Computes the distance map of `layers` against the target `delta_mm`.
/// Layers of slice `s` are measured against every layer of slice `s − 1`.
pub fn distance_map_of(layers: &[Layer], delta_mm: f64) -> DistanceMap {
    let max_slice = layers.iter().map(|l| l.slice).max().unwrap_or(0);
    let indexes: Vec<SegmentIndex> = (0..max_slice)
        .into_par_iter()
        .map(|s| {
            SegmentIndex::new(
                layers
                    .iter()
                    .filter(|l| l.slice == s)
                    .map(|l| (l.points.iter().map(|p| p.position).collect(), l.closed))
                    .collect(),
            )
        })
        .collect();
    let points: Vec<Vec<Option<(f64, bool)>>> = layers
        .par_iter()
        .map(|l| {
            if l.slice == 0 || indexes[l.slice - 1].is_empty() {
                return vec![None; l.points.len()];
            }
            let idx = &indexes[l.slice - 1];
            // Consecutive points have nearby feet: each query starts where the last ended.
            let mut hint = None;
            l.points
                .iter()
                .map(|p| {
                    let n = idx.nearest_hinted(&p.position, hint)?;
                    hint = Some(n.id);
                    Some((n.distance, n.at_open_end))
                })
                .collect()
        })
        .collect();
    let mut all = Vec::new();
    let mut all_boundary = 0;
    let per_layer = points
        .iter()
        .map(|pts| {
            let vals: Vec<f64> = pts
                .iter()
                .flatten()
                .filter(|(_, b)| !b)
                .map(|(d, _)| *d)
                .collect();
            let boundary = pts.iter().flatten().filter(|(_, b)| *b).count();
            all.extend_from_slice(&vals);
            all_boundary += boundary;
            DistanceStats::from(&vals, delta_mm, boundary)
        })
        .collect();
    DistanceMap {
        per_layer,
        overall: DistanceStats::from(&all, delta_mm, all_boundary),
        points,
    }
}

/// Computes the distance map of a path (for a spiral, the distance of each
/// point to the turn below; the ramp turns are left out of the statistics).
pub fn distance_map(path: &Path) -> DistanceMap {
    match (path.spiral, path.layers.as_slice()) {
        (Some(info), [layer]) => spiral_distance_map(layer, info, path.delta_mm),
        _ => distance_map_of(&path.layers, path.delta_mm),
    }
}

/// Distance of every spiral point of turn >= 1 to the turn below: the stretch
/// of the spiral from 1.5 to 0.5 turns earlier. The first turn (ramp up from
/// the substrate) and the ramp-down turn get no statistics; their points keep
/// `None` in the map.
pub fn spiral_distance_map(layer: &Layer, info: super::SpiralInfo, delta_mm: f64) -> DistanceMap {
    let n = info.per_turn;
    let half = n / 2;
    let pts: Vec<crate::math::Point3> = layer.points.iter().map(|p| p.position).collect();
    let index = SegmentIndex::new(vec![(pts.clone(), false)]);
    let end = info.ramp_down_from.unwrap_or(pts.len());
    let points: Vec<Option<(f64, bool)>> = (0..pts.len())
        .into_par_iter()
        .map(|m| {
            if m < n || m >= end {
                return None;
            }
            let below = m - n;
            let lo = below.saturating_sub(half);
            let hi = (below + half).min(pts.len() - 1);
            // Within half a turn of the spiral's start, the stretch below is cut
            // short by the start itself: a boundary point, not an interlayer distance.
            let boundary = below < half;
            index
                .nearest_in_range(&pts[m], 0, lo, hi)
                .map(|nr| (nr.distance, boundary))
        })
        .collect();
    let vals: Vec<f64> = points
        .iter()
        .flatten()
        .filter(|(_, b)| !b)
        .map(|(d, _)| *d)
        .collect();
    let boundary = points.iter().flatten().filter(|(_, b)| *b).count();
    let stats = DistanceStats::from(&vals, delta_mm, boundary);
    DistanceMap {
        per_layer: vec![stats],
        overall: stats,
        points: vec![points],
    }
}

/// Writes each point's distance to the layer below into `PathPoint::delta`.
/// Spiral points keep the distance their root find reached on the ramp turns.
pub(crate) fn fill_deltas(path: &mut Path) {
    let map = distance_map(path);
    apply_deltas(path, &map);
}

/// Writes the distances of `map` (the distance map of `path`) into
/// `PathPoint::delta`, as [`fill_deltas`] does.
pub(crate) fn apply_deltas(path: &mut Path, map: &DistanceMap) {
    let spiral = path.spiral.is_some();
    for (layer, pts) in path.layers.iter_mut().zip(&map.points) {
        for (p, d) in layer.points.iter_mut().zip(pts) {
            match d {
                Some((d, _)) => p.delta = Some(*d),
                None if spiral => {}
                None => p.delta = None,
            }
        }
    }
}
