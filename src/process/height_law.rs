//! The bead height against travel speed law of the closed loop
//! [SPEC §9 "Closed loop"; RPI Scan-n-Print]: `ln h = a ln v + b`, at the
//! process's wire feed speed. Heights in mm, speeds in mm/s.
//!
//! # Fitting `a` and `b` from measured beads
//! Lay straight beads on a flat plate at the cell's wire feed speed and at
//! five or more travel speeds `v_k` (mm/s) spread over the process window,
//! measure each bead's height `h_k` (mm) away from its ends, and fit the line
//! `ln h_k = a ln v_k + b` by least squares:
//! `a = cov(ln v, ln h) / var(ln v)`, `b = mean(ln h) − a mean(ln v)`.
//! Write them as `bead_height_law_a` and `bead_height_law_b` in the part's
//! `[process]` table. `b` depends on the units: mm for `h`, mm/s for `v`.

use serde::{Deserialize, Serialize};

/// The default exponent `a` (dimensionless): −0.5, the value RPI's
/// Scan-n-Print identified for ER4043 at 140 ipm wire feed (SPEC §9). A bead of
/// constant width and section `∝ 1/v` would give −1.
pub const DEFAULT_HEIGHT_LAW_A: f64 = -0.5;

/// `ln h = a ln v + b`: bead height `h` (mm) against travel speed `v`
/// (mm/s) at the process's wire feed speed. Plain data with serde (the
/// `bead_height_law_a` / `bead_height_law_b` keys of a part's `[process]`
/// table).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct BeadHeightLaw {
    /// Exponent `a` (dimensionless, < 0: a faster torch lays a lower bead).
    pub a: f64,
    /// Intercept `b` (`ln mm`, with `v` in mm/s). `None`: anchored so that
    /// the nominal travel speed lays a bead of the path's `Delta` (the
    /// height the plan assumes), see [`BeadHeightLaw::anchored`].
    pub b: Option<f64>,
}

impl Default for BeadHeightLaw {
    fn default() -> Self {
        Self {
            a: DEFAULT_HEIGHT_LAW_A,
            b: None,
        }
    }
}

impl BeadHeightLaw {
    /// Checks the coefficients.
    ///
    /// # Errors
    /// A message naming the coefficient: `a` must be finite and < 0, `b`
    /// finite.
    pub fn validate(&self) -> Result<(), (&'static str, String)> {
        if !(self.a.is_finite() && self.a < 0.0) {
            return Err((
                "bead_height_law_a",
                format!(
                    "must be finite and < 0 (a faster torch lays a lower bead), got {}",
                    self.a
                ),
            ));
        }
        if let Some(b) = self.b {
            if !b.is_finite() {
                return Err(("bead_height_law_b", format!("must be finite, got {b}")));
            }
        }
        Ok(())
    }

    /// The law with its intercept resolved: `b` as given, or
    /// `ln(height_mm) − a ln(speed_mm_s)` so that `speed_mm_s` lays
    /// `height_mm` (both > 0).
    pub fn anchored(&self, speed_mm_s: f64, height_mm: f64) -> ResolvedHeightLaw {
        let b = self
            .b
            .unwrap_or_else(|| height_mm.ln() - self.a * speed_mm_s.ln());
        ResolvedHeightLaw { a: self.a, b }
    }
}

/// A [`BeadHeightLaw`] with both coefficients known.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct ResolvedHeightLaw {
    /// Exponent (dimensionless, < 0).
    pub a: f64,
    /// Intercept (`ln mm`, `v` in mm/s).
    pub b: f64,
}

impl ResolvedHeightLaw {
    /// Bead height (mm) at travel speed `speed_mm_s` (> 0).
    pub fn height_mm(&self, speed_mm_s: f64) -> f64 {
        (self.a * speed_mm_s.ln() + self.b).exp()
    }

    /// Travel speed (mm/s) that lays a bead `height_mm` high (> 0).
    pub fn speed_mm_s(&self, height_mm: f64) -> f64 {
        ((height_mm.ln() - self.b) / self.a).exp()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn anchored_law_lays_delta_at_the_nominal_speed_and_inverts() {
        let law = BeadHeightLaw::default().anchored(8.0, 2.0);
        assert!((law.height_mm(8.0) - 2.0).abs() < 1e-12);
        // a = -0.5: four times the speed, half the height
        assert!((law.height_mm(32.0) - 1.0).abs() < 1e-12);
        for h in [0.5, 1.0, 2.5, 4.0] {
            assert!((law.height_mm(law.speed_mm_s(h)) - h).abs() < 1e-12);
        }
        let given = BeadHeightLaw {
            a: -1.0,
            b: Some(3.0),
        }
        .anchored(8.0, 2.0);
        assert_eq!(given.b, 3.0);
        assert!(BeadHeightLaw { a: 0.2, b: None }.validate().is_err());
        assert!(BeadHeightLaw {
            a: -0.5,
            b: Some(f64::NAN)
        }
        .validate()
        .is_err());
    }
}
