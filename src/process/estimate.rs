//! Estimates of a deposition: time, wire length, deposited volume and mass,
//! arc starts [SPEC §5]. mm, s, g.

use crate::path::Path;

/// Unit conversion: a volume in mm³ times a density in kg/m³ gives
/// `× G_PER_MM3_PER_KG_M3` grams (1 mm³ = 1e-9 m³, 1 kg = 1e3 g).
const G_PER_MM3_PER_KG_M3: f64 = 1e-6;

/// What a deposition costs.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Estimates {
    /// Number of layers (beads) deposited.
    pub layers: usize,
    /// Arc starts (one per bead: layers, open pieces counted separately).
    pub arc_starts: usize,
    /// Length of the path under the arc (mm), closing segments included.
    pub path_length_mm: f64,
    /// Time under the arc (s): path length over the travel speed.
    pub deposition_time_s: f64,
    /// Wire fed (mm): WFS × time.
    pub wire_length_mm: f64,
    /// Wire volume (mm³): wire length × π d_f² / 4.
    pub wire_volume_mm3: f64,
    /// Deposited mass (g): wire volume × density (all the wire is deposited).
    pub deposited_mass_g: f64,
}

/// Estimates for `path` given the travel speed at every point
/// (`speeds[layer][point]`, mm/s): each segment is travelled at the mean of
/// the inverse speeds of its ends; closing segments of closed layers count.
pub(crate) fn estimate(
    path: &Path,
    speeds: &[Vec<f64>],
    wire_diameter_mm: f64,
    wire_feed_speed_mm_s: f64,
    density_kg_m3: f64,
) -> Estimates {
    let (length, time) = layer_lengths_and_times(path, speeds)
        .into_iter()
        .fold((0.0, 0.0), |(a, b), (l, t)| (a + l, b + t));
    let wire_length_mm = wire_feed_speed_mm_s * time;
    let wire_volume_mm3 = wire_length_mm * std::f64::consts::PI * wire_diameter_mm.powi(2) / 4.0;
    Estimates {
        layers: path.layers.len(),
        arc_starts: path.layers.iter().filter(|l| !l.points.is_empty()).count(),
        path_length_mm: length,
        deposition_time_s: time,
        wire_length_mm,
        wire_volume_mm3,
        // 1 mm³ = 1e-9 m³; kg -> g: × 1e3.
        deposited_mass_g: wire_volume_mm3 * density_kg_m3 * G_PER_MM3_PER_KG_M3,
    }
}

/// Length under the arc (mm) and time (s) of each layer of `path` at the
/// travel speeds `speeds[layer][point]` (mm/s), as [`estimate`] counts them:
/// each segment at the mean of the inverse speeds of its ends, closing
/// segments of closed layers included.
pub(crate) fn layer_lengths_and_times(path: &Path, speeds: &[Vec<f64>]) -> Vec<(f64, f64)> {
    path.layers
        .iter()
        .zip(speeds)
        .map(|(l, v)| {
            let n = l.points.len();
            let segs = if l.closed && n > 2 {
                n
            } else {
                n.saturating_sub(1)
            };
            (0..segs).fold((0.0, 0.0), |(length, time), i| {
                let j = (i + 1) % n;
                let d = (l.points[j].position - l.points[i].position).norm();
                (length + d, time + d * 0.5 * (1.0 / v[i] + 1.0 / v[j]))
            })
        })
        .collect()
}
