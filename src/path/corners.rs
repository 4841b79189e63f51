//! Corners of a layer (SPEC §3.4, §9), part of stage 2: where a layer's
//! polyline (part frame, mm) turns sharply, and the seam that a closed layer
//! with corners takes on its sharpest one. Constant-distance layers grow
//! such corners where two fronts meet (20–111° between two points on the
//! bent sample tubes); across one the build direction `b` jumps by about
//! half the turning from one point to the next, which no positioner follows.
//! A bead that starts and ends at the corner does not turn it: the torch
//! ends on one side, and the positioner and the wrist reorient during the
//! arc-off move to the other. A corner inside the bead (a closed layer's
//! other corners, any corner of an open layer) is where a bead may be split
//! ([`Layer::inside_corners`]): one bead ends on it, the next starts there.

use super::{smooth, Layer, SEAM_CORNER_OVER_MEDIAN};
use crate::math::Point3;

/// One corner of a layer: a run of consecutive vertices (one or more) each
/// turning more than the layer's corner bar ([`corner_bar_rad`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Corner {
    /// The layer's point where the polyline turns most within the corner.
    pub point: usize,
    /// The corner's first vertex, in deposition order (a point index; on a
    /// closed layer the run may wrap, `first > last`).
    pub first: usize,
    /// The corner's last vertex (a point index).
    pub last: usize,
    /// Turning angle of the polyline across the corner (rad): between the
    /// segment entering its first vertex and the one leaving its last (the
    /// turning angle at `point` for a one-vertex corner).
    pub turn_rad: f64,
}

impl Corner {
    /// Number of vertices the corner spans (≥ 1) on a layer of `n` points.
    pub fn span(&self, n: usize) -> usize {
        (self.last + n - self.first) % n + 1
    }

    /// Whether the seam of a closed layer of `n` points lies on this corner:
    /// its last point (`n − 1`) or its first (`0`) is one of the corner's
    /// vertices, so the bead, from the first point to the last, does not
    /// turn there.
    pub fn on_seam(&self, n: usize) -> bool {
        let holds = |i: usize| (i + n - self.first) % n < self.span(n);
        holds(0) || holds(n - 1)
    }
}

/// The turning angle above which a vertex of a layer is a corner (rad):
/// `threshold_rad`, or [`SEAM_CORNER_OVER_MEDIAN`] times the median of the
/// layer's turning angles `turns` where more (on a coarse layer every smooth
/// step turns a lot).
pub fn corner_bar_rad(turns: &[f64], threshold_rad: f64) -> f64 {
    let mut sorted = turns.to_vec();
    sorted.sort_by(f64::total_cmp);
    let median = sorted.get(sorted.len() / 2).copied().unwrap_or(0.0);
    threshold_rad.max(SEAM_CORNER_OVER_MEDIAN * median)
}

/// The corners of the polyline `positions` (part frame, mm; `closed` if its
/// last point joins its first), in order of their first vertex: maximal
/// runs of consecutive vertices turning more than [`corner_bar_rad`] of
/// `threshold_rad` (rad, > 0). The ends of an open polyline turn nothing.
pub fn polyline_corners(positions: &[Point3], closed: bool, threshold_rad: f64) -> Vec<Corner> {
    let n = positions.len();
    if n < 3 {
        return Vec::new();
    }
    let turns = smooth::turning_angles(positions, closed);
    let bar = corner_bar_rad(&turns, threshold_rad);
    let sharp = |i: usize| turns[i] > bar;
    // Start the scan after a vertex that is no corner, so that a run
    // wrapping round a closed layer's seam is seen whole.
    let Some(calm) = (0..n).find(|&i| !sharp(i)) else {
        return Vec::new();
    };
    let mut corners = Vec::new();
    let mut k = 1;
    while k <= n {
        let first = (calm + k) % n;
        if !sharp(first) {
            k += 1;
            continue;
        }
        let mut len = 1;
        while sharp((first + len) % n) {
            len += 1;
        }
        let last = (first + len - 1) % n;
        // the first of equals in deposition order
        let point = (1..len).map(|j| (first + j) % n).fold(first, |best, i| {
            if turns[i] > turns[best] {
                i
            } else {
                best
            }
        });
        let into = positions[first] - positions[(first + n - 1) % n];
        let out = positions[(last + 1) % n] - positions[last];
        let c = into.dot(&out) / (into.norm() * out.norm());
        let turn_rad = if c.is_finite() {
            c.clamp(-1.0, 1.0).acos()
        } else {
            turns[point]
        };
        corners.push(Corner {
            point,
            first,
            last,
            turn_rad,
        });
        k += len;
    }
    corners.sort_by_key(|c| c.first);
    corners
}

impl Layer {
    /// This layer's corners above `threshold_rad` (rad, > 0), in order of
    /// their first vertex ([`polyline_corners`]).
    pub fn corners(&self, threshold_rad: f64) -> Vec<Corner> {
        let positions: Vec<Point3> = self.points.iter().map(|p| p.position).collect();
        polyline_corners(&positions, self.closed, threshold_rad)
    }
}

impl Layer {
    /// This layer's corners above `threshold_rad` (rad, > 0) that its bead
    /// turns: every corner of an open layer (its ends turn nothing), the
    /// corners of a closed layer that do not lie on its seam
    /// ([`Corner::on_seam`]). Where one of them cannot be crossed, the bead
    /// is split there: it ends on the corner's [`Corner::point`] and the
    /// next one starts on it.
    pub fn inside_corners(&self, threshold_rad: f64) -> Vec<Corner> {
        let n = self.points.len();
        let mut corners = self.corners(threshold_rad);
        corners.retain(|c| {
            // a split needs a bead on either side: not on an end point
            let interior = c.point > 0 && c.point + 1 < n;
            interior && !(self.closed && c.on_seam(n))
        });
        corners
    }
}

/// The start (a point index) that puts the seam of a closed layer of
/// `positions` on its sharpest corner above `threshold_rad` (the largest
/// [`Corner::turn_rad`], the first of equals), `None` on a layer without
/// corners. The seam's two vertices (the last point and the first) are the
/// two consecutive vertices of that corner that turn most together, so that
/// the bead turns as little of the corner as it can; a one-vertex corner at
/// `c` starts at `c` or `c + 1`, whichever leaves the lesser neighbour
/// inside the bead.
pub fn corner_seam_start(positions: &[Point3], threshold_rad: f64) -> Option<usize> {
    let n = positions.len();
    let corners = polyline_corners(positions, true, threshold_rad);
    let sharpest = corners
        .iter()
        .reduce(|a, b| if b.turn_rad > a.turn_rad { b } else { a })?;
    let turns = smooth::turning_angles(positions, true);
    // Starts whose seam vertices (s − 1, s) touch the corner: s from its
    // first vertex to one past its last.
    let seam_turn = |s: usize| turns[(s + n - 1) % n] + turns[s];
    let mut best = sharpest.first;
    for j in 1..=sharpest.span(n) {
        let s = (sharpest.first + j) % n;
        if seam_turn(s) > seam_turn(best) {
            best = s;
        }
    }
    Some(best)
}

#[cfg(test)]
mod tests;
