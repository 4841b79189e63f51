//! The measured layer: a scan file read into [`Measured`], and the height
//! error of layer `K`'s top per planned point estimated from it (part frame,
//! mm, along each point's build direction `b`, positive where the wall is
//! high), with the outliers named and a scan of another layer or part
//! refused.

use std::path::Path as FsPath;

use rayon::prelude::*;

use super::{ReplanError, ReplanOptions};
use crate::math::{Point3, Vector3};
use crate::path::index::SegmentIndex;
use crate::path::Path;
use crate::toolaxis::LocalFrame;

/// Most outliers listed by name in a report (the count is always exact).
pub const MAX_LISTED_OUTLIERS: usize = 1000;

/// A measured layer, as a scanner or a host program gives it.
#[derive(Debug, Clone, PartialEq)]
pub enum Measured {
    /// Points of the deposited top surface of the layer, part frame (mm),
    /// any density and order; noise, gaps and stray points allowed.
    Points(Vec<Point3>),
    /// A height error per planned point of the layer (mm along the point's
    /// build direction, positive where the wall is high); points not given
    /// are interpolated from their neighbours along the layer.
    HeightErrors(Vec<HeightError>),
}

/// The height error of one planned point (a `layer,point,dh_mm` row).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HeightError {
    /// Layer index (as in `joints.csv`).
    pub layer: usize,
    /// Point index within the layer (as in `joints.csv`).
    pub point: usize,
    /// Measured top minus planned top along the build direction (mm).
    pub dh_mm: f64,
}

impl Measured {
    /// Reads a scan file (CSV, see [`Measured::from_csv_str`]).
    ///
    /// # Errors
    /// [`ReplanError::ScanFile`] naming the file (and line) for an unreadable
    /// file or a bad row.
    pub fn read(path: impl AsRef<FsPath>) -> Result<Measured, ReplanError> {
        let path = path.as_ref();
        let shown = path.display().to_string();
        let text = std::fs::read_to_string(path).map_err(|e| ReplanError::ScanFile {
            file: shown.clone(),
            line: 0,
            reason: e.to_string(),
        })?;
        Self::from_csv_str(&text, &shown)
    }

    /// Parses scan text: a header `x,y,z` (points of the top surface, part
    /// frame, mm) or `layer,point,dh_mm` (height error per planned point,
    /// mm), then one row per value. Blank lines and lines starting with `#`
    /// are skipped; cells may be padded with spaces. `origin` names the
    /// text in errors.
    ///
    /// # Errors
    /// [`ReplanError::ScanFile`] naming `origin`, the line and the column: an
    /// unknown header, a wrong column count, a value that is not a finite
    /// number (or not an index), no rows.
    pub fn from_csv_str(text: &str, origin: &str) -> Result<Measured, ReplanError> {
        let err = |line: usize, reason: String| ReplanError::ScanFile {
            file: origin.to_string(),
            line,
            reason,
        };
        let mut rows = text
            .lines()
            .enumerate()
            .map(|(i, l)| (i + 1, l.trim()))
            .filter(|(_, l)| !l.is_empty() && !l.starts_with('#'));
        let Some((hline, header)) = rows.next() else {
            return Err(err(0, "empty scan: no header, no rows".into()));
        };
        let names: Vec<String> = header
            .split(',')
            .map(|c| c.trim().to_ascii_lowercase())
            .collect();
        let points = match names.iter().map(String::as_str).collect::<Vec<_>>()[..] {
            ["x", "y", "z"] => true,
            ["layer", "point", "dh_mm"] => false,
            _ => {
                return Err(err(
                    hline,
                    format!("header `{header}`: expected `x,y,z` (points of the top surface, part frame, mm) or `layer,point,dh_mm` (height error per planned point)"),
                ))
            }
        };
        let mut pts = Vec::new();
        let mut errs = Vec::new();
        for (n, line) in rows {
            let cells: Vec<&str> = line.split(',').map(str::trim).collect();
            if cells.len() != 3 {
                return Err(err(n, format!("{} columns, expected 3", cells.len())));
            }
            let num = |k: usize| -> Result<f64, ReplanError> {
                match cells[k].parse::<f64>() {
                    Ok(v) if v.is_finite() => Ok(v),
                    _ => Err(err(
                        n,
                        format!("`{}`: `{}` is not a finite number", names[k], cells[k]),
                    )),
                }
            };
            let index = |k: usize| -> Result<usize, ReplanError> {
                cells[k]
                    .parse::<usize>()
                    .map_err(|_| err(n, format!("`{}`: `{}` is not an index", names[k], cells[k])))
            };
            if points {
                pts.push(Point3::new(num(0)?, num(1)?, num(2)?));
            } else {
                errs.push(HeightError {
                    layer: index(0)?,
                    point: index(1)?,
                    dh_mm: num(2)?,
                });
            }
        }
        if pts.is_empty() && errs.is_empty() {
            return Err(err(hline, "no rows after the header".into()));
        }
        Ok(if points {
            Measured::Points(pts)
        } else {
            Measured::HeightErrors(errs)
        })
    }

    /// Number of rows (points or height errors).
    pub fn len(&self) -> usize {
        match self {
            Measured::Points(p) => p.len(),
            Measured::HeightErrors(e) => e.len(),
        }
    }

    /// `true` without any row.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

/// A scan row that was not used: too far from layer `K`'s planned top.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Outlier {
    /// Row index in the scan (0-based, header and comments not counted).
    pub row: usize,
    /// The point (part frame, mm); for a height-error row, the planned
    /// point moved by its error.
    pub position_mm: Point3,
    /// Its distance to layer `K`'s planned top (mm).
    pub distance_mm: f64,
}

/// What was read from the scan: the error per planned point of layer `K`
/// and how it was obtained.
#[derive(Debug, Clone, PartialEq)]
pub struct ScanEstimate {
    /// Height error per point of layer `K` in the path's order (mm along the
    /// point's build direction, + high), averaged over the along-layer
    /// window and interpolated across gaps.
    pub error_mm: Vec<f64>,
    /// Points of layer `K` with scan data of their own (before
    /// interpolation).
    pub covered_points: usize,
    /// Scan rows used.
    pub inliers: usize,
    /// Scan rows not used (the first [`MAX_LISTED_OUTLIERS`] of them).
    pub outliers: Vec<Outlier>,
    /// Number of scan rows not used.
    pub outlier_count: usize,
    /// The outlier distance used (mm).
    pub outlier_distance_mm: f64,
    /// Median height error of the rows used (mm).
    pub median_error_mm: f64,
    /// Median offset across the wall (along the surface normal) of the
    /// points used (mm; 0 for height errors).
    pub median_wall_offset_mm: f64,
}

/// Per-row classification before the column accumulation.
struct Sample {
    column: usize,
    s: f64,
    error: f64,
    across: f64,
}

/// Estimates layer `after_layer`'s height error from `measured`. `path` is
/// the nominal path, `frames` its local frames (part frame): the rows
/// gathered onto the layer's points, the scan refused when it is not of
/// this layer, then smoothed along the layer and its gaps filled.
pub(super) fn estimate(
    path: &Path,
    frames: &[Vec<LocalFrame>],
    after_layer: usize,
    measured: &Measured,
    opts: &ReplanOptions,
) -> Result<ScanEstimate, ReplanError> {
    let layer = &path.layers[after_layer];
    let fr = &frames[after_layer];
    let delta = path.delta_mm;
    let limit = opts
        .outlier_distance_mm
        .unwrap_or_else(|| (3.0 * delta).max(3.0));
    let positions: Vec<Point3> = layer.points.iter().map(|p| p.position).collect();
    let smooth = matches!(measured, Measured::Points(_));
    let mut g = match measured {
        Measured::Points(points) => gather_points(points, &positions, fr, layer.closed, limit),
        Measured::HeightErrors(rows) => {
            gather_height_errors(rows, &positions, fr, after_layer, limit)?
        }
    };
    let checked = refuse_other_scans(path, after_layer, measured, &mut g, limit, opts)?;
    let error_mm = smoothed(&positions, layer.closed, &g, smooth, opts);
    Ok(ScanEstimate {
        error_mm,
        covered_points: checked.covered_points,
        inliers: checked.inliers,
        outliers: g.outliers,
        outlier_count: g.outlier_count,
        outlier_distance_mm: limit,
        median_error_mm: checked.median_error_mm,
        median_wall_offset_mm: checked.median_wall_offset_mm,
    })
}

/// The scan rows gathered onto the layer's points: per point the weighted
/// sum of the errors and the weights, the errors and offsets across the
/// wall used (mm), every row's distance to the layer (mm), the outliers.
struct Gathered {
    sum: Vec<f64>,
    weight: Vec<f64>,
    errors_used: Vec<f64>,
    across_used: Vec<f64>,
    distances: Vec<f64>,
    outliers: Vec<Outlier>,
    outlier_count: usize,
}

impl Gathered {
    fn new(n: usize) -> Self {
        Self {
            sum: vec![0.0; n],
            weight: vec![0.0; n],
            errors_used: Vec::new(),
            across_used: Vec::new(),
            distances: Vec::new(),
            outliers: Vec::new(),
            outlier_count: 0,
        }
    }
}

/// Scan points (part frame, mm) gathered onto the layer of `positions`
/// (frames `fr`): each point's foot on the layer, its error along the
/// blended build direction shared between the segment's two ends; points
/// farther than `limit` (mm) are outliers.
fn gather_points(
    points: &[Point3],
    positions: &[Point3],
    fr: &[LocalFrame],
    closed: bool,
    limit: f64,
) -> Gathered {
    let n = positions.len();
    let mut g = Gathered::new(n);
    let index = SegmentIndex::new(vec![(positions.to_vec(), closed)]);
    let samples: Vec<(Option<Sample>, f64)> = points
        .par_iter()
        .map(|q| {
            let Some(near) = index.nearest(q) else {
                return (None, f64::INFINITY);
            };
            let j = near.id.segment;
            let k = if j + 1 < n { j + 1 } else { 0 };
            let s = near.s.clamp(0.0, 1.0);
            let foot = positions[j] + (positions[k] - positions[j]) * s;
            let b = blend(&fr[j].build, &fr[k].build, s);
            let nrm = blend(&fr[j].normal, &fr[k].normal, s);
            let d = q - foot;
            let dist = d.norm();
            if !(dist <= limit) {
                return (None, dist);
            }
            let sample = Sample {
                column: j,
                s,
                error: d.dot(&b),
                across: d.dot(&nrm),
            };
            (Some(sample), dist)
        })
        .collect();
    for (row, ((sample, dist), q)) in samples.into_iter().zip(points).enumerate() {
        g.distances.push(dist);
        match sample {
            Some(smp) => {
                let k = if smp.column + 1 < n {
                    smp.column + 1
                } else {
                    0
                };
                g.sum[smp.column] += (1.0 - smp.s) * smp.error;
                g.weight[smp.column] += 1.0 - smp.s;
                g.sum[k] += smp.s * smp.error;
                g.weight[k] += smp.s;
                g.errors_used.push(smp.error);
                g.across_used.push(smp.across);
            }
            None => {
                g.outlier_count += 1;
                if g.outliers.len() < MAX_LISTED_OUTLIERS {
                    g.outliers.push(Outlier {
                        row,
                        position_mm: *q,
                        distance_mm: dist,
                    });
                }
            }
        }
    }
    g
}

/// Height-error rows gathered onto the layer's points; a row of another
/// layer or point is refused, a row whose error exceeds `limit` (mm) is an
/// outlier.
fn gather_height_errors(
    rows: &[HeightError],
    positions: &[Point3],
    fr: &[LocalFrame],
    after_layer: usize,
    limit: f64,
) -> Result<Gathered, ReplanError> {
    let n = positions.len();
    let mut g = Gathered::new(n);
    for (row, r) in rows.iter().enumerate() {
        if r.layer != after_layer {
            return Err(ReplanError::ScanOfAnotherLayer {
                row,
                scan_layer: r.layer,
                after_layer,
            });
        }
        if r.point >= n {
            return Err(ReplanError::ScanPoint {
                row,
                point: r.point,
                points: n,
                after_layer,
            });
        }
        let dist = r.dh_mm.abs();
        g.distances.push(dist);
        if dist > limit {
            g.outlier_count += 1;
            if g.outliers.len() < MAX_LISTED_OUTLIERS {
                g.outliers.push(Outlier {
                    row,
                    position_mm: positions[r.point] + fr[r.point].build * r.dh_mm,
                    distance_mm: dist,
                });
            }
            continue;
        }
        g.sum[r.point] += r.dh_mm;
        g.weight[r.point] += 1.0;
        g.errors_used.push(r.dh_mm);
        g.across_used.push(0.0);
    }
    Ok(g)
}

/// What the checks of a scan measured.
struct ScanChecks {
    inliers: usize,
    median_error_mm: f64,
    median_wall_offset_mm: f64,
    covered_points: usize,
}

/// Refuses a scan of another part (too few rows near the layer, or beside
/// the wall), of another layer (median error beyond the limit; the hint
/// names the layer it fits) or covering too little of the layer.
fn refuse_other_scans(
    path: &Path,
    after_layer: usize,
    measured: &Measured,
    g: &mut Gathered,
    limit: f64,
    opts: &ReplanOptions,
) -> Result<ScanChecks, ReplanError> {
    let delta = path.delta_mm;
    let n = path.layers[after_layer].points.len();
    let total = measured.len();
    let inliers = total - g.outlier_count;
    if (inliers as f64) < opts.min_inlier_fraction * total as f64 || inliers == 0 {
        return Err(ReplanError::WrongPart {
            after_layer,
            outside: g.outlier_count,
            total,
            limit_mm: limit,
            median_distance_mm: median(&mut g.distances),
        });
    }
    let median_error_mm = median(&mut g.errors_used);
    let median_wall_offset_mm = median(&mut g.across_used);
    let wall_limit = opts.max_wall_offset_mm.unwrap_or(delta);
    if median_wall_offset_mm.abs() > wall_limit {
        return Err(ReplanError::WallOffset {
            after_layer,
            median_mm: median_wall_offset_mm,
            limit_mm: wall_limit,
        });
    }
    let error_limit = opts.max_median_error_rel * delta;
    if median_error_mm.abs() > error_limit {
        let hint = match measured {
            Measured::Points(points) => nearest_layer(path, points, after_layer),
            Measured::HeightErrors(_) => None,
        };
        return Err(ReplanError::WrongLayer {
            after_layer,
            median_error_mm,
            limit_mm: error_limit,
            hint: match hint {
                Some((l, d)) => format!(
                    "; planned layer {l} lies {d:.3} mm from the scan on median: a scan of layer {l}?"
                ),
                None => String::new(),
            },
        });
    }
    let covered_points = g.weight.iter().filter(|w| **w > 0.0).count();
    if (covered_points as f64) < opts.min_coverage * n as f64 {
        return Err(ReplanError::TooLittleCoverage {
            after_layer,
            covered: covered_points,
            points: n,
            min_fraction: opts.min_coverage,
        });
    }
    Ok(ScanChecks {
        inliers,
        median_error_mm,
        median_wall_offset_mm,
        covered_points,
    })
}

/// Each point's error (mm): a weighted local line through the points'
/// means over the along-layer window (a scan; `smooth`), then the gaps
/// filled, zero where nothing is known.
fn smoothed(
    positions: &[Point3],
    closed: bool,
    g: &Gathered,
    smooth: bool,
    opts: &ReplanOptions,
) -> Vec<f64> {
    let n = positions.len();
    let (sum, weight) = (&g.sum, &g.weight);
    // Average over the along-layer window (a scan), then fill the gaps.
    let spacing = if n > 1 {
        let len: f64 = positions.windows(2).map(|w| (w[1] - w[0]).norm()).sum();
        len / (n - 1) as f64
    } else {
        1.0
    };
    let w = if smooth && spacing > 0.0 {
        ((opts.smoothing_mm / spacing).round() as usize).min(n / 4)
    } else {
        0
    };
    // A weighted local line through the points' means (by index along the
    // layer): unbiased on a ramp of the error, where a plain mean is not.
    let mean: Vec<Option<f64>> = (0..n)
        .map(|j| (weight[j] > 0.0).then(|| sum[j] / weight[j]))
        .collect();
    let mut value: Vec<Option<f64>> = (0..n)
        .map(|i| {
            let (mut s0, mut s1, mut s2, mut t0, mut t1) = (0.0, 0.0, 0.0, 0.0, 0.0);
            for k in -(w as isize)..=(w as isize) {
                let j = i as isize + k;
                let j = if closed {
                    j.rem_euclid(n as isize) as usize
                } else if j < 0 || j >= n as isize {
                    continue;
                } else {
                    j as usize
                };
                let Some(y) = mean[j] else { continue };
                let (wt, x) = (weight[j], k as f64);
                s0 += wt;
                s1 += wt * x;
                s2 += wt * x * x;
                t0 += wt * y;
                t1 += wt * x * y;
            }
            if !(s0 > 0.0) {
                return None;
            }
            let det = s0 * s2 - s1 * s1;
            let line = (s2 * t0 - s1 * t1) / det;
            // one column of data (or a degenerate spread): its mean
            Some(if det > 1e-9 * s0 * s0 && line.is_finite() {
                line
            } else {
                t0 / s0
            })
        })
        .collect();
    fill_gaps(&mut value, closed);
    value.into_iter().map(|v| v.unwrap_or(0.0)).collect()
}

/// `(1 − s) a + s b`, normalised.
fn blend(a: &Vector3, b: &Vector3, s: f64) -> Vector3 {
    let v = a * (1.0 - s) + b * s;
    let n = v.norm();
    if n > 0.0 {
        v / n
    } else {
        *a
    }
}

/// Median of `v` (0 for an empty slice); reorders `v`.
pub(super) fn median(v: &mut [f64]) -> f64 {
    if v.is_empty() {
        return 0.0;
    }
    v.sort_by(f64::total_cmp);
    let m = v.len() / 2;
    if v.len() % 2 == 1 {
        v[m]
    } else {
        0.5 * (v[m - 1] + v[m])
    }
}

/// Linear interpolation (by index, cyclic on a closed layer) across the
/// points without a value; ends of an open layer take the nearest value.
fn fill_gaps(value: &mut [Option<f64>], closed: bool) {
    let n = value.len();
    let known: Vec<usize> = (0..n).filter(|&i| value[i].is_some()).collect();
    let (Some(&first), Some(&last)) = (known.first(), known.last()) else {
        return;
    };
    for pair in known.windows(2) {
        let (a, b) = (pair[0], pair[1]);
        let (va, vb) = (value[a].unwrap_or(0.0), value[b].unwrap_or(0.0));
        for (i, slot) in value.iter_mut().enumerate().take(b).skip(a + 1) {
            let s = (i - a) as f64 / (b - a) as f64;
            *slot = Some(va + s * (vb - va));
        }
    }
    let (vf, vl) = (value[first].unwrap_or(0.0), value[last].unwrap_or(0.0));
    if closed {
        let span = first + n - last;
        for k in 1..span {
            let s = k as f64 / span as f64;
            value[(last + k) % n] = Some(vl + s * (vf - vl));
        }
    } else {
        for slot in &mut value[..first] {
            *slot = Some(vf);
        }
        for slot in &mut value[last + 1..] {
            *slot = Some(vl);
        }
    }
}

/// The planned layer nearest to the scan on median (layer, distance in
/// mm), over the layers within 5 of `after_layer`, from at most 500 of the
/// scan's points.
fn nearest_layer(path: &Path, points: &[Point3], after_layer: usize) -> Option<(usize, f64)> {
    let step = (points.len() / 500).max(1);
    let sample: Vec<Point3> = points.iter().step_by(step).copied().collect();
    let lo = after_layer.saturating_sub(5);
    let hi = (after_layer + 5).min(path.layers.len() - 1);
    (lo..=hi)
        .map(|l| {
            let layer = &path.layers[l];
            let index = SegmentIndex::new(vec![(
                layer.points.iter().map(|p| p.position).collect(),
                layer.closed,
            )]);
            let mut d: Vec<f64> = sample
                .iter()
                .filter_map(|q| index.nearest(q).map(|n| n.distance))
                .collect();
            (l, median(&mut d))
        })
        .min_by(|a, b| a.1.total_cmp(&b.1))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn csv_headers_rows_and_errors_are_named() {
        let m = Measured::from_csv_str("# scan\nx, y, z\n1,2,3\n\n4,5,6\n", "s.csv").unwrap();
        assert_eq!(m.len(), 2);
        let m = Measured::from_csv_str("layer,point,dh_mm\n10,3,0.25\n", "s.csv").unwrap();
        assert_eq!(
            m,
            Measured::HeightErrors(vec![HeightError {
                layer: 10,
                point: 3,
                dh_mm: 0.25
            }])
        );
        let e = Measured::from_csv_str("a,b\n", "s.csv")
            .unwrap_err()
            .to_string();
        assert!(e.contains("s.csv") && e.contains("line 1"), "{e}");
        let e = Measured::from_csv_str("x,y,z\n1,2,nan\n", "s.csv")
            .unwrap_err()
            .to_string();
        assert!(e.contains("line 2") && e.contains("`z`"), "{e}");
        let e = Measured::from_csv_str("x,y,z\n", "s.csv")
            .unwrap_err()
            .to_string();
        assert!(e.contains("no rows"), "{e}");
    }

    #[test]
    fn gaps_fill_linearly_and_cyclically() {
        let mut v = vec![None, Some(1.0), None, Some(3.0), None, None];
        fill_gaps(&mut v, true);
        let v: Vec<f64> = v.into_iter().map(Option::unwrap).collect();
        assert_eq!(v[2], 2.0);
        // 3 -> 1 over indices 3, 4, 5, 0, 1
        assert!(
            (v[4] - 2.5).abs() < 1e-12 && (v[0] - 1.5).abs() < 1e-12,
            "{v:?}"
        );
        assert_eq!(median(&mut [3.0, 1.0, 2.0, 10.0]), 2.5);
    }
}
