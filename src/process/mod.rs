//! **Stage 4 — process.** Takes a [`Path`] (part frame, mm) and
//! [`ProcessParameters`] (wire, speeds, voltage, stick-out, material) and
//! returns a [`ProcessPlan`]: the travel speed and bead cross-section at every
//! point, the points whose needed speed leaves the admissible window, and
//! estimates of time, wire, mass and arc starts [SPEC §5; thesis §1.2,
//! eq. 1.1–1.3, table 1.1–1.2, 3.1].
//!
//! Units: mm, s, mm/s, V, kg/m³ in the API; the regressions of Xiong are
//! evaluated in their own units (m/min, cm/min) by conversion inside
//! [`bead`].

pub mod bead;
pub mod estimate;
pub mod height_law;
pub mod speed;

#[cfg(test)]
mod tests;

pub use bead::{bead_area_mm2, xiong_height_mm, xiong_width_mm, Bead, BeadModel};
pub use estimate::Estimates;
pub use height_law::{BeadHeightLaw, ResolvedHeightLaw};
pub use speed::{SpeedLaw, SpeedViolation, WindowSide};

use crate::path::Path;
use bead::{MM_S_PER_CM_MIN, MM_S_PER_M_MIN};
use serde::{Deserialize, Serialize};

/// Humping limit of CMT steel (ER70S-6, 0.8 and 1.2 mm wire): 60 cm/min
/// (thesis §1.2.3, Adebayo et al. \[61\]), in mm/s.
pub const HUMPING_LIMIT_CMT_STEEL_MM_S: f64 = 60.0 * MM_S_PER_CM_MIN;

/// The named parameter sets: the `preset` of a part file's `[process]` table
/// and the CLI's `--process`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum ProcessPreset {
    /// [`ProcessParameters::pla_table_3_1`]: the thesis's polymer tests, 6 mm/s.
    Pla,
    /// [`ProcessParameters::cmt_steel_er70s6`]: CMT ER70S-6, 8.33 mm/s (the default).
    #[default]
    CmtSteel,
    /// [`ProcessParameters::mag_steel_xiong`]: MAG ER70S, 5 mm/s.
    MagSteel,
}

impl ProcessPreset {
    /// Every preset, in the order the CLI lists them.
    pub const ALL: [ProcessPreset; 3] = [Self::CmtSteel, Self::Pla, Self::MagSteel];

    /// The name used in files and on the command line.
    pub fn name(self) -> &'static str {
        match self {
            Self::Pla => "pla",
            Self::CmtSteel => "cmt-steel",
            Self::MagSteel => "mag-steel",
        }
    }

    /// The preset's parameters.
    pub fn parameters(self) -> ProcessParameters {
        match self {
            Self::Pla => ProcessParameters::pla_table_3_1(),
            Self::CmtSteel => ProcessParameters::cmt_steel_er70s6(),
            Self::MagSteel => ProcessParameters::mag_steel_xiong(),
        }
    }
}

impl std::str::FromStr for ProcessPreset {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        Self::ALL
            .into_iter()
            .find(|p| p.name() == s)
            .ok_or_else(|| {
                let names: Vec<_> = Self::ALL.iter().map(|p| p.name()).collect();
                format!(
                    "unknown process preset `{s}`; expected one of {}",
                    names.join(", ")
                )
            })
    }
}

/// Deposition parameters. Plain data with serde (a `[process]` table of a
/// part file can hold it); [`ProcessParameters::validate`] names the field.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ProcessParameters {
    /// Material label for reports (e.g. "ER70S-6", "PLA").
    pub material: String,
    /// Wire diameter `d_f` (mm).
    pub wire_diameter_mm: f64,
    /// Wire feed speed WFS (mm/s).
    pub wire_feed_speed_mm_s: f64,
    /// Nominal travel speed TS (mm/s).
    pub travel_speed_mm_s: f64,
    /// Arc voltage `V_a` (V; 0 for a polymer nozzle).
    pub voltage_v: f64,
    /// Stick-out `SO` (mm).
    pub stick_out_mm: f64,
    /// Density of the deposited material (kg/m³).
    pub density_kg_m3: f64,
    /// Slowest admissible travel speed (mm/s).
    pub travel_speed_min_mm_s: f64,
    /// Fastest admissible travel speed (mm/s): the humping limit for metals.
    pub travel_speed_max_mm_s: f64,
    /// Bead height/width model.
    pub bead_model: BeadModel,
    /// Bead height against travel speed, `ln h = a ln v + b` (mm, mm/s): the
    /// law the closed loop ([`crate::replan`]) inverts to correct a measured
    /// layer's height error with the next layer's travel speed.
    pub bead_height_law: BeadHeightLaw,
}

impl Default for ProcessParameters {
    fn default() -> Self {
        Self::cmt_steel_er70s6()
    }
}

impl ProcessParameters {
    /// The thesis's polymer set, table 3.1: PLA, TS 36 cm/min (6 mm/s), WFS
    /// 10 mm/s, extruded strand Ø 1 mm (taken as `d_f`), layers 1 mm high
    /// (§3.3.1: Delta = 1 mm, "the extruded diameter"), hence a
    /// constant-width bead of `A_c / 1 mm` = 1.309 mm. Density 1240 kg/m³.
    /// Window 3–12 mm/s (half to twice nominal: our assumption, the thesis
    /// gives none for the polymer).
    pub fn pla_table_3_1() -> Self {
        let (d, wfs, ts) = (1.0, 10.0, 36.0 * MM_S_PER_CM_MIN);
        Self {
            material: "PLA".into(),
            wire_diameter_mm: d,
            wire_feed_speed_mm_s: wfs,
            travel_speed_mm_s: ts,
            voltage_v: 0.0,
            stick_out_mm: 0.0,
            density_kg_m3: 1240.0,
            travel_speed_min_mm_s: 0.5 * ts,
            travel_speed_max_mm_s: 2.0 * ts,
            bead_model: BeadModel::ConstantWidth {
                width_mm: bead_area_mm2(d, wfs, ts) / 1.0,
            },
            bead_height_law: BeadHeightLaw::default(),
        }
    }

    /// A CMT steel set from table 1.2 (row \[61\]): ER70S-6, Ø 1.2 mm, WFS
    /// 4.8 m/min (80 mm/s), TS 50 cm/min (8.33 mm/s); the table gives no
    /// voltage or stick-out for that row: 18 V (middle of Xiong's range) and
    /// 11 mm (the CMT rows of \[73\]). Window 15 cm/min (lower end of Xiong's
    /// fit) to 60 cm/min (humping, §1.2.3). Xiong's bead model; density
    /// 7850 kg/m³.
    pub fn cmt_steel_er70s6() -> Self {
        Self {
            material: "ER70S-6".into(),
            wire_diameter_mm: 1.2,
            wire_feed_speed_mm_s: 4.8 * MM_S_PER_M_MIN,
            travel_speed_mm_s: 50.0 * MM_S_PER_CM_MIN,
            voltage_v: 18.0,
            stick_out_mm: 11.0,
            density_kg_m3: 7850.0,
            travel_speed_min_mm_s: 15.0 * MM_S_PER_CM_MIN,
            travel_speed_max_mm_s: HUMPING_LIMIT_CMT_STEEL_MM_S,
            bead_model: BeadModel::Xiong,
            bead_height_law: BeadHeightLaw::default(),
        }
    }

    /// Xiong's own MAG set, middle of its ranges (table 1.1, row \[72\]):
    /// ER70S Ø 1.2 mm, WFS 4.4 m/min, TS 30 cm/min, 19 V, stick-out 12 mm;
    /// window 15–45 cm/min (the fitted range).
    pub fn mag_steel_xiong() -> Self {
        Self {
            material: "ER70S".into(),
            wire_diameter_mm: 1.2,
            wire_feed_speed_mm_s: 4.4 * MM_S_PER_M_MIN,
            travel_speed_mm_s: 30.0 * MM_S_PER_CM_MIN,
            voltage_v: 19.0,
            stick_out_mm: 12.0,
            density_kg_m3: 7850.0,
            travel_speed_min_mm_s: 15.0 * MM_S_PER_CM_MIN,
            travel_speed_max_mm_s: 45.0 * MM_S_PER_CM_MIN,
            bead_model: BeadModel::Xiong,
            bead_height_law: BeadHeightLaw::default(),
        }
    }

    /// Checks every field.
    ///
    /// # Errors
    /// [`ProcessError::InvalidParameter`] naming the field.
    pub fn validate(&self) -> Result<(), ProcessError> {
        let bad = |field: &'static str, reason: String| {
            Err(ProcessError::InvalidParameter { field, reason })
        };
        for (field, v) in [
            ("wire_diameter_mm", self.wire_diameter_mm),
            ("wire_feed_speed_mm_s", self.wire_feed_speed_mm_s),
            ("travel_speed_mm_s", self.travel_speed_mm_s),
            ("density_kg_m3", self.density_kg_m3),
            ("travel_speed_min_mm_s", self.travel_speed_min_mm_s),
            ("travel_speed_max_mm_s", self.travel_speed_max_mm_s),
        ] {
            if !(v.is_finite() && v > 0.0) {
                return bad(field, format!("must be positive and finite, got {v}"));
            }
        }
        for (field, v) in [
            ("voltage_v", self.voltage_v),
            ("stick_out_mm", self.stick_out_mm),
        ] {
            if !(v.is_finite() && v >= 0.0) {
                return bad(field, format!("must be finite and >= 0, got {v}"));
            }
        }
        if !(self.travel_speed_min_mm_s < self.travel_speed_max_mm_s) {
            return bad(
                "travel_speed_min_mm_s",
                format!(
                    "must be below travel_speed_max_mm_s ({} >= {})",
                    self.travel_speed_min_mm_s, self.travel_speed_max_mm_s
                ),
            );
        }
        if !(self.travel_speed_min_mm_s..=self.travel_speed_max_mm_s)
            .contains(&self.travel_speed_mm_s)
        {
            return bad(
                "travel_speed_mm_s",
                format!(
                    "nominal {} mm/s is outside the admissible window [{}, {}] mm/s",
                    self.travel_speed_mm_s, self.travel_speed_min_mm_s, self.travel_speed_max_mm_s
                ),
            );
        }
        if let Err((field, reason)) = self.bead_height_law.validate() {
            return bad(field, reason);
        }
        if let BeadModel::ConstantWidth { width_mm } = self.bead_model {
            if !(width_mm.is_finite() && width_mm > 0.0) {
                return bad(
                    "bead_model.width_mm",
                    format!("must be positive and finite, got {width_mm}"),
                );
            }
        }
        Ok(())
    }

    /// `eta = WFS / TS` at a travel speed (mm/s).
    pub fn eta(&self, travel_speed_mm_s: f64) -> f64 {
        self.wire_feed_speed_mm_s / travel_speed_mm_s
    }

    /// The bead at a travel speed (mm/s): area from eq. 1.1, height and width
    /// from the bead model.
    pub fn bead_at(&self, travel_speed_mm_s: f64) -> Bead {
        let area_mm2 = bead_area_mm2(
            self.wire_diameter_mm,
            self.wire_feed_speed_mm_s,
            travel_speed_mm_s,
        );
        match self.bead_model {
            BeadModel::Xiong => {
                let (w, t) = (
                    self.wire_feed_speed_mm_s / MM_S_PER_M_MIN,
                    travel_speed_mm_s / MM_S_PER_CM_MIN,
                );
                Bead {
                    area_mm2,
                    height_mm: xiong_height_mm(w, t, self.voltage_v, self.stick_out_mm),
                    width_mm: xiong_width_mm(w, t, self.voltage_v, self.stick_out_mm),
                }
            }
            BeadModel::ConstantWidth { width_mm } => Bead {
                area_mm2,
                height_mm: area_mm2 / width_mm,
                width_mm,
            },
        }
    }

    /// The travel speed (mm/s) at which the model's bead height is
    /// `height_mm`; `None` if no positive speed gives it.
    pub fn travel_speed_for_height(&self, height_mm: f64) -> Option<f64> {
        if !(height_mm > 0.0) {
            return None;
        }
        let ts = match self.bead_model {
            BeadModel::Xiong => {
                bead::xiong_travel_speed_cm_min(
                    self.wire_feed_speed_mm_s / MM_S_PER_M_MIN,
                    self.voltage_v,
                    self.stick_out_mm,
                    height_mm,
                )? * MM_S_PER_CM_MIN
            }
            BeadModel::ConstantWidth { width_mm } => {
                std::f64::consts::PI * self.wire_feed_speed_mm_s * self.wire_diameter_mm.powi(2)
                    / (4.0 * width_mm * height_mm)
            }
        };
        (ts.is_finite() && ts > 0.0).then_some(ts)
    }

    /// Whether the bead model is used inside the range it was fitted on at
    /// this travel speed (always true for [`BeadModel::ConstantWidth`]).
    pub fn model_in_range(&self, travel_speed_mm_s: f64) -> bool {
        match self.bead_model {
            BeadModel::Xiong => bead::XIONG_RANGE.contains(
                self.wire_feed_speed_mm_s / MM_S_PER_M_MIN,
                travel_speed_mm_s / MM_S_PER_CM_MIN,
                self.voltage_v,
                self.stick_out_mm,
            ),
            BeadModel::ConstantWidth { .. } => true,
        }
    }
}

/// Options of [`plan_process`]. Plain data.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ProcessOptions {
    /// How the travel speed follows the local distance.
    pub speed_law: SpeedLaw,
    /// Bead height at the nominal speed for [`SpeedLaw::Proportional`] (mm);
    /// `None`: the path's `Delta`.
    pub reference_height_mm: Option<f64>,
}

impl Default for ProcessOptions {
    fn default() -> Self {
        Self {
            speed_law: SpeedLaw::Proportional,
            reference_height_mm: None,
        }
    }
}

impl ProcessOptions {
    /// Checks every field.
    ///
    /// # Errors
    /// [`ProcessError::InvalidOption`] naming the field.
    pub fn validate(&self) -> Result<(), ProcessError> {
        if let Some(h) = self.reference_height_mm {
            if !(h.is_finite() && h > 0.0) {
                return Err(ProcessError::InvalidOption {
                    field: "reference_height_mm",
                    reason: format!("must be positive and finite, got {h}"),
                });
            }
        }
        Ok(())
    }
}

/// Process data at one path point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PointProcess {
    /// Travel speed to program (mm/s), inside the admissible window.
    pub travel_speed_mm_s: f64,
    /// Bead at that speed.
    pub bead: Bead,
}

/// The process stage's result.
#[derive(Debug, Clone, PartialEq)]
pub struct ProcessPlan {
    /// Per point, `points[layer][point]` (same shape as `path.layers`).
    pub points: Vec<Vec<PointProcess>>,
    /// Points whose needed speed left the window (clamped), first 1000.
    pub violations: Vec<SpeedViolation>,
    /// Number of such points.
    pub violation_count: usize,
    /// Points where the bead model is used outside its fitted range.
    pub model_extrapolated_points: usize,
    /// Bead at the nominal speed.
    pub nominal_bead: Bead,
    /// Time, wire, mass, arc starts.
    pub estimates: Estimates,
}

impl ProcessPlan {
    /// Mass deposited in each layer of `path` (kg): the wire fed while the
    /// layer is laid (its time at the planned travel speeds, as in
    /// [`Estimates`]) times the wire's section and the density of
    /// `params`; the layers sum to [`Estimates::deposited_mass_g`]. `path`
    /// is the path this plan was made for.
    pub fn layer_masses_kg(&self, path: &Path, params: &ProcessParameters) -> Vec<f64> {
        let speeds: Vec<Vec<f64>> = self
            .points
            .iter()
            .map(|l| l.iter().map(|p| p.travel_speed_mm_s).collect())
            .collect();
        let section_mm2 = std::f64::consts::PI * params.wire_diameter_mm.powi(2) / 4.0;
        estimate::layer_lengths_and_times(path, &speeds)
            .into_iter()
            // mm³ × kg/m³ × 1e-9 m³/mm³ = kg
            .map(|(_, t)| {
                params.wire_feed_speed_mm_s * t * section_mm2 * params.density_kg_m3 * 1e-9
            })
            .collect()
    }
}

/// Errors of the process stage; each names the field, layer or point.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum ProcessError {
    /// A process parameter is invalid.
    #[error("process parameter `{field}`: {reason}")]
    InvalidParameter {
        /// The parameter.
        field: &'static str,
        /// What is wrong.
        reason: String,
    },
    /// An option is invalid.
    #[error("process option `{field}`: {reason}")]
    InvalidOption {
        /// The option.
        field: &'static str,
        /// What is wrong.
        reason: String,
    },
    /// A path point's distance to the layer below is not a finite number.
    #[error("layer {layer}, point {point}: local distance delta = {delta_mm} is not finite")]
    NonFiniteDelta {
        /// Layer.
        layer: usize,
        /// Point.
        point: usize,
        /// The value.
        delta_mm: f64,
    },
}

/// **Stage 4 entry point.** Travel speed and bead at every point of `path`,
/// window violations, and estimates [SPEC §5].
///
/// Points of the first layer (no `delta`) get the nominal speed. Elsewhere the
/// speed law gives the needed speed from `delta`; it is clamped to the
/// admissible window and every point where it had to be is reported.
///
/// # Errors
/// [`ProcessError`] for invalid parameters or options, or a non-finite
/// `delta` (naming layer and point).
///
/// # Example
/// ```
/// use waam_slicer::process::ProcessParameters;
/// let pla = ProcessParameters::pla_table_3_1();
/// let bead = pla.bead_at(pla.travel_speed_mm_s);
/// assert!((bead.area_mm2 - std::f64::consts::PI * (10.0 / 6.0) / 4.0).abs() < 1e-12);
/// ```
pub fn plan_process(
    path: &Path,
    params: &ProcessParameters,
    opts: &ProcessOptions,
) -> Result<ProcessPlan, ProcessError> {
    params.validate()?;
    opts.validate()?;
    let h_ref = opts.reference_height_mm.unwrap_or(path.delta_mm);
    let (lo, hi) = (params.travel_speed_min_mm_s, params.travel_speed_max_mm_s);
    let mut violations = Vec::new();
    let mut violation_count = 0;
    let mut model_extrapolated_points = 0;
    let mut points = Vec::with_capacity(path.layers.len());
    let mut speeds = Vec::with_capacity(path.layers.len());
    for (li, layer) in path.layers.iter().enumerate() {
        let mut lp = Vec::with_capacity(layer.points.len());
        let mut ls = Vec::with_capacity(layer.points.len());
        for (pi, p) in layer.points.iter().enumerate() {
            let ts = match p.delta {
                None => params.travel_speed_mm_s,
                Some(d) if !d.is_finite() => {
                    return Err(ProcessError::NonFiniteDelta {
                        layer: li,
                        point: pi,
                        delta_mm: d,
                    })
                }
                Some(d) => {
                    let needed = speed::needed_speed(params, opts.speed_law, d, h_ref);
                    let side = match needed {
                        None => Some(WindowSide::Unreachable),
                        Some(v) if v < lo => Some(WindowSide::BelowMin),
                        Some(v) if v > hi => Some(WindowSide::AboveMax),
                        Some(_) => None,
                    };
                    if let Some(side) = side {
                        violation_count += 1;
                        if violations.len() < 1000 {
                            violations.push(SpeedViolation {
                                layer: li,
                                point: pi,
                                delta_mm: d,
                                needed_mm_s: needed,
                                side,
                            });
                        }
                    }
                    match (needed, side) {
                        (Some(v), _) => v.clamp(lo, hi),
                        // Unreachable: the nearest end of the window — a
                        // too-low height (or delta <= 0) needs speed.
                        (None, _) => hi,
                    }
                }
            };
            if !params.model_in_range(ts) {
                model_extrapolated_points += 1;
            }
            lp.push(PointProcess {
                travel_speed_mm_s: ts,
                bead: params.bead_at(ts),
            });
            ls.push(ts);
        }
        points.push(lp);
        speeds.push(ls);
    }
    let estimates = estimate::estimate(
        path,
        &speeds,
        params.wire_diameter_mm,
        params.wire_feed_speed_mm_s,
        params.density_kg_m3,
    );
    Ok(ProcessPlan {
        points,
        violations,
        violation_count,
        model_extrapolated_points,
        nominal_bead: params.bead_at(params.travel_speed_mm_s),
        estimates,
    })
}
