//! Bead geometry: cross-section area from volume conservation (eq. 1.1, Ding)
//! and height/width regressions of Xiong (eq. 1.2–1.3, MAG, steel ER70S,
//! 1.2 mm wire) [SPEC §5; thesis §1.2.2].

use serde::{Deserialize, Serialize};

/// Slack on the ends of a process window (the window's own unit: m/min, V,
/// mm): a value at the end up to rounding is inside.
const WINDOW_SLACK: f64 = 1e-12;

/// mm/s in one m/min.
pub const MM_S_PER_M_MIN: f64 = 1000.0 / 60.0;
/// mm/s in one cm/min.
pub const MM_S_PER_CM_MIN: f64 = 10.0 / 60.0;

/// Bead cross-section area `A_c = π η d_f² / 4` with `η = WFS/TS` (eq. 1.1),
/// mm². Wire diameter in mm, both speeds in the same unit (mm/s here).
pub fn bead_area_mm2(
    wire_diameter_mm: f64,
    wire_feed_speed_mm_s: f64,
    travel_speed_mm_s: f64,
) -> f64 {
    let eta = wire_feed_speed_mm_s / travel_speed_mm_s;
    std::f64::consts::PI * eta * wire_diameter_mm * wire_diameter_mm / 4.0
}

/// Xiong's bead height `H_c` (mm), eq. 1.2, in the regression's own units:
/// WFS in m/min, TS in cm/min, arc voltage `V_a` in V, stick-out `SO` in mm.
/// Fitted on 2.8–6 m/min, 15–45 cm/min, 16–22 V, 6–18 mm (table 1.1, \[72\]).
pub fn xiong_height_mm(wfs_m_min: f64, ts_cm_min: f64, voltage_v: f64, stick_out_mm: f64) -> f64 {
    let (w, t, v, s) = (wfs_m_min, ts_cm_min, voltage_v, stick_out_mm);
    -0.3514 + 0.48318 * w - 0.08477 * t + 0.4028 * v + 0.01431 * s - 0.006146 * w * t
        + 0.001168 * t * t
        - 0.012463 * v * v
}

/// Xiong's bead width `L_c` (mm), eq. 1.3, in the regression's own units
/// (as [`xiong_height_mm`]).
pub fn xiong_width_mm(wfs_m_min: f64, ts_cm_min: f64, voltage_v: f64, stick_out_mm: f64) -> f64 {
    let (w, t, v, s) = (wfs_m_min, ts_cm_min, voltage_v, stick_out_mm);
    8.9462 + 1.8088 * w - 0.3621 * t + 0.1739 * v - 0.5008 * s + 0.003556 * t * s + 0.01667 * v * s
        - 0.1169 * w * w
        + 0.003137 * t * t
}

/// Travel speeds (cm/min) at which Xiong's height (eq. 1.2) equals
/// `height_mm`, on the decreasing branch of the parabola (below its minimum,
/// where the regression was fitted). `None` when the height is below the
/// parabola's minimum (no speed gives it).
pub fn xiong_travel_speed_cm_min(
    wfs_m_min: f64,
    voltage_v: f64,
    stick_out_mm: f64,
    height_mm: f64,
) -> Option<f64> {
    let h0 = xiong_height_mm(wfs_m_min, 0.0, voltage_v, stick_out_mm);
    let (a, b, c) = (0.001168, -0.08477 - 0.006146 * wfs_m_min, h0 - height_mm);
    let disc = b * b - 4.0 * a * c;
    if disc < 0.0 {
        return None;
    }
    // Smaller root = decreasing branch; stable form.
    let q = -0.5 * (b - disc.sqrt());
    Some(c / q)
}

/// Ranges of Xiong's experiments (table 1.1, row \[72\]).
pub const XIONG_RANGE: XiongRange = XiongRange {
    wfs_m_min: (2.8, 6.0),
    ts_cm_min: (15.0, 45.0),
    voltage_v: (16.0, 22.0),
    stick_out_mm: (6.0, 18.0),
};

/// Ranges of a regression's experiments.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct XiongRange {
    /// Wire feed speed (m/min).
    pub wfs_m_min: (f64, f64),
    /// Travel speed (cm/min).
    pub ts_cm_min: (f64, f64),
    /// Arc voltage (V).
    pub voltage_v: (f64, f64),
    /// Stick-out (mm).
    pub stick_out_mm: (f64, f64),
}

impl XiongRange {
    /// Whether a set of parameters (regression units) is inside the ranges.
    pub fn contains(
        &self,
        wfs_m_min: f64,
        ts_cm_min: f64,
        voltage_v: f64,
        stick_out_mm: f64,
    ) -> bool {
        let inside =
            |x: f64, (lo, hi): (f64, f64)| x >= lo - WINDOW_SLACK && x <= hi + WINDOW_SLACK;
        inside(wfs_m_min, self.wfs_m_min)
            && inside(ts_cm_min, self.ts_cm_min)
            && inside(voltage_v, self.voltage_v)
            && inside(stick_out_mm, self.stick_out_mm)
    }
}

/// How bead height and width follow from the parameters.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case", tag = "kind", deny_unknown_fields)]
pub enum BeadModel {
    /// Xiong's regressions (eq. 1.2–1.3): steel, MAG, 1.2 mm wire.
    Xiong,
    /// A bead of constant width whose height is the area over the width
    /// (`h = A_c / w`): height inversely proportional to the travel speed —
    /// the proportional law the thesis used for the polymer (§3.3.1).
    ConstantWidth {
        /// Bead width (mm).
        width_mm: f64,
    },
}

/// One bead cross-section.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Bead {
    /// Area (mm², eq. 1.1).
    pub area_mm2: f64,
    /// Height (mm).
    pub height_mm: f64,
    /// Width (mm).
    pub width_mm: f64,
}
