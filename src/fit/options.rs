//! Options of the mesh fit: plain data with defaults, checked by
//! [`FitOptions::validate`] (which names the field).

use super::FitError;
use serde::{Deserialize, Serialize};
use std::path::PathBuf;

/// Which end of the tube is its start: the end built first, standing on the
/// substrate.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum StartEnd {
    /// The end whose centre is lowest (smallest Z of the mesh frame).
    #[default]
    Lowest,
    /// The end whose centre is highest.
    Highest,
    /// The end closed by a flat cap (a plate or bottom in the mesh); refused
    /// unless exactly one end is capped.
    Capped,
    /// The end whose centre is nearest this point (mesh frame, mm).
    Near([f64; 3]),
}

impl std::str::FromStr for StartEnd {
    type Err = String;

    /// `lowest`, `highest`, `capped`, or a point `x,y,z` (mm).
    fn from_str(s: &str) -> Result<Self, String> {
        match s.trim() {
            "lowest" => Ok(Self::Lowest),
            "highest" => Ok(Self::Highest),
            "capped" => Ok(Self::Capped),
            other => {
                let parts: Vec<&str> = other.split(',').collect();
                let xyz: Vec<f64> = parts
                    .iter()
                    .filter_map(|p| p.trim().parse::<f64>().ok())
                    .filter(|x| x.is_finite())
                    .collect();
                if parts.len() == 3 && xyz.len() == 3 {
                    Ok(Self::Near([xyz[0], xyz[1], xyz[2]]))
                } else {
                    Err(format!(
                        "`{s}`: expected `lowest`, `highest`, `capped` or a point `x,y,z` (mm)"
                    ))
                }
            }
        }
    }
}

/// The length unit of a mesh file's coordinates. The fit converts the mesh
/// to mm first; everything it prints, writes or takes is then in mm.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Units {
    /// Millimetres (the default).
    #[default]
    Mm,
    /// Centimetres.
    Cm,
    /// Metres (how many CAD tools export).
    M,
    /// Inches.
    In,
}

impl Units {
    /// Every unit, smallest first.
    pub const ALL: [Units; 4] = [Units::Mm, Units::Cm, Units::In, Units::M];

    /// Millimetres in one of this unit.
    pub fn mm_per_unit(self) -> f64 {
        match self {
            Units::Mm => 1.0,
            Units::Cm => 10.0,
            Units::M => 1000.0,
            Units::In => 25.4,
        }
    }

    /// The unit's name as typed: `mm`, `cm`, `m`, `in`.
    pub fn name(self) -> &'static str {
        match self {
            Units::Mm => "mm",
            Units::Cm => "cm",
            Units::M => "m",
            Units::In => "in",
        }
    }
}

/// A mesh's largest bounding-box side under this many of its unit looks
/// like a mesh in a larger unit (dimensionless).
pub const UNITS_SMALL_SIZE: f64 = 1.0;
/// A mesh's largest bounding-box side over this many of its unit looks like
/// a mesh in a smaller unit (dimensionless).
pub const UNITS_LARGE_SIZE: f64 = 10_000.0;
/// The size (mm) a tube printed by WAAM most likely has: the likely unit of
/// a mesh is the one that brings its size nearest this, on a log scale.
const TYPICAL_SIZE_MM: f64 = 200.0;

/// A warning naming the likely unit when `size` (the largest side of the
/// mesh's bounding box, in `units`) is under [`UNITS_SMALL_SIZE`] or over
/// [`UNITS_LARGE_SIZE`] and another unit gives a more usual size (nearer
/// 200 mm); `None` otherwise.
pub fn units_warning(size: f64, units: Units) -> Option<String> {
    if (UNITS_SMALL_SIZE..=UNITS_LARGE_SIZE).contains(&size) || !(size > 0.0) {
        return None;
    }
    let off = |u: Units| (size * u.mm_per_unit() / TYPICAL_SIZE_MM).ln().abs();
    let likely = Units::ALL
        .into_iter()
        .min_by(|a, b| off(*a).total_cmp(&off(*b)))
        .unwrap_or(units);
    let across = format!("the mesh is {size:.4} {units} across (its bounding box's largest side)");
    if likely != units {
        Some(format!(
            "{across}: it looks like a mesh in {likely} ({size:.4} {likely} = {:.1} mm; units = \"{likely}\", `--units {likely}`)",
            size * likely.mm_per_unit()
        ))
    } else {
        // Larger than any usual part even in the smallest unit offered.
        (size > UNITS_LARGE_SIZE).then(|| {
            format!("{across}: it looks like a mesh in a unit smaller than {units} (micrometres?); scale it to mm")
        })
    }
}

impl std::fmt::Display for Units {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl std::str::FromStr for Units {
    type Err = String;

    /// `mm`, `cm`, `m` or `in`.
    fn from_str(s: &str) -> Result<Self, String> {
        Units::ALL
            .into_iter()
            .find(|u| u.name() == s.trim())
            .ok_or_else(|| format!("`{s}`: expected a length unit `mm`, `cm`, `m` or `in`"))
    }
}

/// How a tubular mesh is fitted ([`fit_tube`](super::fit_tube)). Lengths in
/// mm, angles in degrees (as typed by a user; converted inside).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct FitOptions {
    /// The unit of the mesh file's coordinates (default mm). The mesh is
    /// converted to mm first: every other length of these options, of the
    /// fit and of its report is in mm.
    pub units: Units,
    /// Which end stands on the substrate (default: the lowest).
    pub start: StartEnd,
    /// Largest RMS distance (mm) of the mesh's vertices to the fitted tube
    /// surface; above it the mesh is refused as not a tube.
    pub max_rms_mm: f64,
    /// Largest RMS distance of a section's points to their least-squares
    /// circle, as a fraction of its radius (or `max_rms_mm` when larger);
    /// above it the section is refused as not near a circle.
    pub max_section_rms_ratio: f64,
    /// Largest angular gap (degrees) between a section's points around its
    /// circle; three stations in a row above it are refused as not a closed
    /// ring.
    pub max_section_gap_deg: f64,
    /// Spacing (mm) of the stations along the guide where a circle is fitted;
    /// `None`: twice the median edge length, within `[0.5, radius / 4]`.
    pub station_spacing_mm: Option<f64>,
    /// Spacing (mm) of the spline's points (guide and radius law) inside
    /// the tube; quarter and half of it next to each end. `None`: half the
    /// radius at the start, within `[4, 12]`.
    pub knot_spacing_mm: Option<f64>,
    /// The iteration stops once no guide point moves more than this (mm),
    /// or once the moves stop shrinking below ten times this or a quarter of
    /// the sections' median RMS scatter, whichever is larger (the level of
    /// the mesh's noise).
    pub tolerance_mm: f64,
    /// Most refits of the guide.
    pub max_iterations: usize,
    /// Two triangles meeting at more than this angle (degrees) are on
    /// different faces: splits a closed wall into skins and flat end faces,
    /// and finds a flat cap. Used only on a surface that is not an open tube.
    pub crease_angle_deg: f64,
    /// A radius law whose values all lie within this (mm) of their mean is
    /// written as a constant radius.
    pub constant_radius_tol_mm: f64,
    /// Measure the distance of the fitted surface to the mesh as well (a
    /// parry3d BVH query per sample of the fitted tube): finds a fitted tube
    /// running past the mesh.
    pub check_surface: bool,
    /// A part file whose `[slicing]`, `[tool_axis]` and `[process]` tables
    /// the written part takes; `None`: constant-distance slicing with
    /// `Delta` = 2 mm, 400 points, the axis rate bounded to 10°/mm, CMT steel.
    pub template: Option<PathBuf>,
    /// The written part's name; `None`: the mesh file's stem.
    pub name: Option<String>,
    /// An STL mesh of the substrate (binary or ASCII, mesh frame = part
    /// frame, mm) that the tube's start end stands on; the written part's
    /// `[substrate]` is this mesh (by its absolute path) instead of the
    /// start end's plane. `None`: the start end's plane.
    pub substrate: Option<PathBuf>,
    /// Largest distance (mm) of the start end's rim (its fitted circle) to
    /// the [`substrate`](Self::substrate) mesh; a start end further away is
    /// refused ([`FitError::SubstrateFar`]).
    pub substrate_tolerance_mm: f64,
    /// Fit the longest tubular stretch of a mesh that carries features that
    /// are not tube (collars, flanges, blocks, lugs, tabs; on one skin or on
    /// a solid wall, holding an end or not), cut at the guide's normal
    /// planes just past them, and name the features in the report; `false`
    /// (the default): such a mesh is refused, naming the feature.
    pub trim: bool,
}

impl Default for FitOptions {
    fn default() -> Self {
        Self {
            units: Units::Mm,
            start: StartEnd::Lowest,
            max_rms_mm: 0.5,
            max_section_rms_ratio: 0.03,
            max_section_gap_deg: 90.0,
            station_spacing_mm: None,
            knot_spacing_mm: None,
            tolerance_mm: 1e-3,
            max_iterations: 30,
            crease_angle_deg: 45.0,
            constant_radius_tol_mm: 0.01,
            check_surface: true,
            template: None,
            name: None,
            substrate: None,
            substrate_tolerance_mm: 1.0,
            trim: false,
        }
    }
}

impl FitOptions {
    /// The largest RMS (mm) of a section's points from their circle of
    /// `radius` (mm) that is still a circle: `max_section_rms_ratio` of the
    /// radius, at least `max_rms_mm`.
    pub(crate) fn section_rms_allowed(&self, radius: f64) -> f64 {
        (self.max_section_rms_ratio * radius).max(self.max_rms_mm)
    }

    /// Checks every field; `file` names the mesh in the error.
    ///
    /// # Errors
    /// [`FitError::InvalidOption`] naming the field.
    pub fn validate(&self, file: &str) -> Result<(), FitError> {
        let bad = |field: &str, reason: String| FitError::InvalidOption {
            file: file.to_string(),
            field: field.to_string(),
            reason,
        };
        let positive = |field: &str, x: f64| {
            if x.is_finite() && x > 0.0 {
                Ok(())
            } else {
                Err(bad(field, format!("must be positive and finite, got {x}")))
            }
        };
        positive("max_rms_mm", self.max_rms_mm)?;
        positive("max_section_rms_ratio", self.max_section_rms_ratio)?;
        positive("tolerance_mm", self.tolerance_mm)?;
        positive("constant_radius_tol_mm", self.constant_radius_tol_mm)?;
        positive("substrate_tolerance_mm", self.substrate_tolerance_mm)?;
        if let Some(s) = self.station_spacing_mm {
            positive("station_spacing_mm", s)?;
        }
        if let Some(s) = self.knot_spacing_mm {
            positive("knot_spacing_mm", s)?;
        }
        for (field, x) in [
            ("max_section_gap_deg", self.max_section_gap_deg),
            ("crease_angle_deg", self.crease_angle_deg),
        ] {
            if !(x > 0.0 && x < 180.0) {
                return Err(bad(
                    field,
                    format!("must be within (0, 180) degrees, got {x}"),
                ));
            }
        }
        if self.max_iterations == 0 {
            return Err(bad("max_iterations", "must be at least 1".into()));
        }
        if let StartEnd::Near(p) = self.start {
            if !p.iter().all(|x| x.is_finite()) {
                return Err(bad("start", format!("point {p:?} is not finite")));
            }
        }
        if self.substrate.is_some() && self.units != Units::Mm {
            return Err(bad(
                "units",
                format!(
                    "{}: a substrate mesh is named by the written part and read in mm by the later stages; give both meshes in mm",
                    self.units
                ),
            ));
        }
        if let Some(name) = &self.name {
            if name.trim().is_empty() {
                return Err(bad("name", "must not be empty".into()));
            }
        }
        Ok(())
    }
}
