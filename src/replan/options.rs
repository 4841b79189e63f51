//! **Stage 9 — the closed loop's options**: how a scan is read and when it
//! is refused ([`ReplanOptions`]), plain data checked by
//! [`ReplanOptions::validate`].

use serde::Serialize;

use super::ReplanError;

/// Options of the closed loop: how a scan is read and when it is refused.
/// Plain data; [`ReplanOptions::validate`] names the field.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct ReplanOptions {
    /// A scan row farther than this from layer `K`'s planned top is an
    /// outlier: named in the summary, not used (mm). `None`: `max(3 Delta, 3 mm)`.
    pub outlier_distance_mm: Option<f64>,
    /// Half-width of the window along the layer over which the scan is
    /// fitted (a weighted local line) into a point's error (mm; 0: each
    /// point's own neighbours). A wider window averages more noise away but
    /// blurs an error that changes over a few mm.
    pub smoothing_mm: f64,
    /// A scan whose median height error is more than this fraction of
    /// `Delta` is refused as a scan of another layer (relative).
    pub max_median_error_rel: f64,
    /// A scan whose median offset across the wall (along the surface
    /// normal) is more than this is refused as a scan of another part (mm).
    /// `None`: `Delta`.
    pub max_wall_offset_mm: Option<f64>,
    /// Fewest scan rows that must lie within the outlier distance, as a
    /// fraction of the rows (relative); fewer: a scan of another part.
    pub min_inlier_fraction: f64,
    /// Fewest points of layer `K` with scan data of their own, as a fraction
    /// (relative); fewer: refused, too little of the layer was seen.
    pub min_coverage: f64,
    /// Whether the rebuilt layers may rejoin a later nominal layer than
    /// `K+1` (skipping nominal layers) when that rejoins in fewer layers.
    /// At most as many nominal layers are skipped as the highest point of
    /// the measured top stands above its nominal, in layers, rounded (none
    /// while the wall is nowhere half a layer high, so that the speed
    /// correction of layer `K+1` stays as it is). `false`: always aim at
    /// `K+1, K+2, ..`.
    pub skip_nominal_layers: bool,
}

impl Default for ReplanOptions {
    fn default() -> Self {
        Self {
            outlier_distance_mm: None,
            smoothing_mm: 0.5,
            max_median_error_rel: 0.5,
            max_wall_offset_mm: None,
            min_inlier_fraction: 0.5,
            min_coverage: 0.5,
            skip_nominal_layers: true,
        }
    }
}

impl ReplanOptions {
    /// Checks every field.
    ///
    /// # Errors
    /// [`ReplanError::InvalidOption`] naming the field.
    pub fn validate(&self) -> Result<(), ReplanError> {
        let bad = |field: &'static str, value: f64| {
            Err(ReplanError::InvalidOption {
                field,
                reason: format!("got {value}"),
            })
        };
        if let Some(d) = self.outlier_distance_mm {
            if !(d.is_finite() && d > 0.0) {
                return bad("outlier_distance_mm (must be > 0)", d);
            }
        }
        if let Some(d) = self.max_wall_offset_mm {
            if !(d.is_finite() && d > 0.0) {
                return bad("max_wall_offset_mm (must be > 0)", d);
            }
        }
        if !(self.smoothing_mm.is_finite() && self.smoothing_mm >= 0.0) {
            return bad("smoothing_mm (must be >= 0)", self.smoothing_mm);
        }
        if !(self.max_median_error_rel.is_finite() && self.max_median_error_rel > 0.0) {
            return bad(
                "max_median_error_rel (must be > 0)",
                self.max_median_error_rel,
            );
        }
        for (field, v) in [
            (
                "min_inlier_fraction (must be in [0, 1])",
                self.min_inlier_fraction,
            ),
            ("min_coverage (must be in [0, 1])", self.min_coverage),
        ] {
            if !(0.0..=1.0).contains(&v) {
                return bad(field, v);
            }
        }
        Ok(())
    }
}
