//! Local frames `(t, n, b)` at the path points (part frame, unit vectors):
//! tangent by central difference (eq. 2.34), normal analytic from the tube
//! (eq. 2.33) or numeric from facets of the path alone (thesis §2.4.3), and
//! the build direction `b = ± t × n` (eq. 2.35) oriented away from the
//! substrate. [SPEC §4]

use super::{LocalFrame, ToolAxisError};
use crate::geometry::{Substrate, Tube};
use crate::math::{tol, Point3, Vector3};
use crate::path::index::SegmentIndex;
use crate::path::{Layer, Path};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

/// The sum of the adjacent facets' unit normals (at most two) shorter than
/// this has no direction: the facets face opposite ways (unitless).
const MIN_NORMAL_SUM: f64 = 1e-9;

/// Where surface normals come from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum NormalMethod {
    /// Analytic when a tube is given, numeric otherwise.
    #[default]
    Auto,
    /// From the tube's surface derivatives, `n = ∂M/∂t × ∂M/∂v` (eq. 2.33).
    Analytic,
    /// From the path alone: mean of the normals of the facet below
    /// (`M_{i-1}`, `M_{i+1}`, nearest point of the layer below) and the facet
    /// above; the first and last slices use one facet (thesis §2.4.3).
    Numeric,
}

/// Indices of the neighbours of point `i` used by the central difference
/// (eq. 2.34): wrapping on a closed layer whose bead wraps
/// ([`Layer::bead_wraps`]), one-sided at the ends of an open one.
pub(crate) fn neighbours(n: usize, i: usize, closed: bool) -> (usize, usize) {
    if closed {
        ((i + n - 1) % n, (i + 1) % n)
    } else {
        (i.saturating_sub(1), (i + 1).min(n - 1))
    }
}

/// Analytic frames; never fails (legacy behaviour of [`super::local_frames`]):
/// a zero chord falls back to `∂M/∂v`.
pub(crate) fn analytic_frames(path: &Path, tube: &Tube) -> Vec<Vec<LocalFrame>> {
    path.layers
        .iter()
        .map(|layer| analytic_layer(layer, tube, usize::MAX).unwrap_or_default())
        .collect()
}

/// Analytic frames, failing on a degenerate tangent.
pub(crate) fn analytic_frames_checked(
    path: &Path,
    tube: &Tube,
) -> Result<Vec<Vec<LocalFrame>>, ToolAxisError> {
    path.layers
        .par_iter()
        .enumerate()
        .map(|(li, layer)| analytic_layer(layer, tube, li))
        .collect()
}

/// Frames of one layer from the tube. `li == usize::MAX` selects the lenient
/// legacy mode (fall back to `∂M/∂v` for a zero chord).
fn analytic_layer(layer: &Layer, tube: &Tube, li: usize) -> Result<Vec<LocalFrame>, ToolAxisError> {
    let n = layer.points.len();
    let wraps = layer.bead_wraps();
    (0..n)
        .map(|i| {
            let p = &layer.points[i];
            let (prev, next) = neighbours(n, i, wraps);
            let sp = tube.surface(p.t, p.v);
            let normal = sp.normal.into_inner();
            let chord = layer.points[next].position - layer.points[prev].position;
            // Tangent in the surface's tangent plane.
            let c = chord - normal * chord.dot(&normal);
            let scale = chord.norm().max(1.0);
            let tangent = if c.norm() > tol::DEGENERATE * scale {
                c.normalize()
            } else if li == usize::MAX {
                sp.d_dv.normalize()
            } else {
                return Err(ToolAxisError::DegenerateTangent {
                    layer: li,
                    point: i,
                });
            };
            let mut build = tangent.cross(&normal).normalize();
            // Toward increasing guide parameter: the direction layers advance.
            if build.dot(&sp.d_dt) < 0.0 {
                build = -build;
            }
            Ok(LocalFrame {
                tangent,
                normal,
                build,
                tool: build,
            })
        })
        .collect()
}

/// Per slice number, the layer indices of that slice.
fn layers_by_slice(path: &Path) -> Vec<Vec<usize>> {
    let mut by: Vec<Vec<usize>> = vec![Vec::new(); path.num_slices()];
    for (li, l) in path.layers.iter().enumerate() {
        by[l.slice].push(li);
    }
    by
}

/// Nearest point to `p` on the polylines of `index` (`None` if empty).
fn nearest_point(index: &SegmentIndex, p: &Point3) -> Option<Point3> {
    let nearest = index.nearest(p)?;
    let (pts, _) = &index.polylines()[nearest.id.polyline];
    let a = pts[nearest.id.segment];
    let b = pts[(nearest.id.segment + 1) % pts.len()];
    Some(a + (b - a) * nearest.s)
}

/// Numeric frames from the path alone (thesis §2.4.3). `b` points toward
/// the next slice (away from the one below); `n` is flipped per layer to
/// point away from the layer's centroid (outward for a tube).
pub(crate) fn numeric_frames(path: &Path) -> Result<Vec<Vec<LocalFrame>>, ToolAxisError> {
    let by_slice = layers_by_slice(path);
    if by_slice.iter().filter(|s| !s.is_empty()).count() < 2 {
        return Err(ToolAxisError::TooFewSlices {
            slices: by_slice.len(),
        });
    }
    let indices: Vec<SegmentIndex> = by_slice
        .par_iter()
        .map(|ls| {
            SegmentIndex::new(
                ls.iter()
                    .map(|&li| {
                        let l = &path.layers[li];
                        (l.points.iter().map(|p| p.position).collect(), l.closed)
                    })
                    .collect(),
            )
        })
        .collect();
    path.layers
        .par_iter()
        .enumerate()
        .map(|(li, layer)| {
            let s = layer.slice;
            let below = s
                .checked_sub(1)
                .map(|b| &indices[b])
                .filter(|i| !i.is_empty());
            let above = indices.get(s + 1).filter(|i| !i.is_empty());
            numeric_layer(layer, li, below, above)
        })
        .collect()
}

fn numeric_layer(
    layer: &Layer,
    li: usize,
    below: Option<&SegmentIndex>,
    above: Option<&SegmentIndex>,
) -> Result<Vec<LocalFrame>, ToolAxisError> {
    let n = layer.points.len();
    let wraps = layer.bead_wraps();
    let pos = |i: usize| layer.points[i].position;
    let mut frames = Vec::with_capacity(n);
    for i in 0..n {
        let (prev, next) = neighbours(n, i, wraps);
        let m = pos(i);
        let c = pos(next) - pos(prev);
        let c_len = c.norm();
        if !(c_len > tol::ZERO_LENGTH_MM) {
            return Err(ToolAxisError::DegenerateTangent {
                layer: li,
                point: i,
            });
        }
        let tangent = c / c_len;
        let mut sum = Vector3::zeros();
        for (index, sign) in [(below, -1.0), (above, 1.0)] {
            let Some(index) = index else { continue };
            let Some(q) = nearest_point(index, &m) else {
                continue;
            };
            // Direction toward the next layer, as seen from this facet.
            let up = (q - m) * sign;
            let facet = c.cross(&(q - pos(prev)));
            let f_len = facet.norm();
            if !(f_len > tol::DEGENERATE * c_len * (q - pos(prev)).norm().max(tol::DIV_FLOOR)) {
                continue;
            }
            let mut f = facet / f_len;
            // Orient as n = b × t with b along `up` (direct frame).
            if f.dot(&up.cross(&c)) < 0.0 {
                f = -f;
            }
            sum += f;
        }
        let s_len = sum.norm();
        if !(s_len > MIN_NORMAL_SUM) {
            return Err(ToolAxisError::DegenerateNormal {
                layer: li,
                point: i,
            });
        }
        let normal = sum / s_len;
        let build = tangent.cross(&normal).normalize();
        frames.push(LocalFrame {
            tangent,
            normal,
            build,
            tool: build,
        });
    }
    // Outward: away from the layer's centroid.
    let centroid = layer
        .points
        .iter()
        .fold(Vector3::zeros(), |a, p| a + p.position.coords)
        / n as f64;
    let outward: f64 = layer
        .points
        .iter()
        .zip(&frames)
        .map(|(p, f)| (p.position.coords - centroid).dot(&f.normal))
        .sum();
    if outward < 0.0 {
        for f in &mut frames {
            f.normal = -f.normal;
        }
    }
    Ok(frames)
}

/// Flips every build direction (and tool axis) if those of the first slice
/// point into the substrate on average (thesis §2.4.2: `b_0 · n_substrate > 0`);
/// optionally replaces the first slice's `b` by the substrate's outward
/// normal made perpendicular to `t`. Meshes (no outward normal) are left alone.
pub(crate) fn orient_away_from_substrate(
    path: &Path,
    frames: &mut [Vec<LocalFrame>],
    substrate: &Substrate,
    first_along_substrate: bool,
) {
    let mut score = 0.0;
    for (l, fl) in path.layers.iter().zip(frames.iter()) {
        if l.slice != 0 {
            continue;
        }
        for (p, f) in l.points.iter().zip(fl) {
            if let Some(o) = substrate.outward(&p.position) {
                score += f.build.dot(&o);
            }
        }
    }
    if score < 0.0 {
        for f in frames.iter_mut().flatten() {
            f.build = -f.build;
            f.tool = -f.tool;
        }
    }
    if first_along_substrate {
        for (l, fl) in path.layers.iter().zip(frames.iter_mut()) {
            if l.slice != 0 {
                continue;
            }
            for (p, f) in l.points.iter().zip(fl.iter_mut()) {
                if let Some(o) = substrate.outward(&p.position) {
                    let b = o - f.tangent * o.dot(&f.tangent);
                    if b.norm() > tol::ANGLE_RAD {
                        f.build = b.normalize();
                        f.tool = f.build;
                    }
                }
            }
        }
    }
}

/// Mean difference of eq. 2.36 layer by layer: `mu_n = (1/p_n) Σ_i |n_a − n_b|`
/// over the `p_n` points of layer `n` (unitless).
pub fn mean_normal_difference_per_layer(a: &[Vec<LocalFrame>], b: &[Vec<LocalFrame>]) -> Vec<f64> {
    a.iter()
        .zip(b)
        .map(|(la, lb)| mean_normal_difference(std::slice::from_ref(la), std::slice::from_ref(lb)))
        .collect()
}

/// Mean difference of eq. 2.36, `mu = (1/p) Σ |n_a − n_b|`, over every point
/// of two frame sets of the same shape (unitless; 0.04 reads "4 %").
/// Pairs beyond the shorter set are ignored.
pub fn mean_normal_difference(a: &[Vec<LocalFrame>], b: &[Vec<LocalFrame>]) -> f64 {
    let (sum, count) = a
        .iter()
        .zip(b)
        .flat_map(|(la, lb)| la.iter().zip(lb))
        .fold((0.0, 0usize), |(s, c), (fa, fb)| {
            (s + (fa.normal - fb.normal).norm(), c + 1)
        });
    if count == 0 {
        0.0
    } else {
        sum / count as f64
    }
}
