//! **Stage 0 — part files.** Reads a part description (TOML, part frame, mm)
//! into a validated [`Part`]: the [`Tube`], its [`Substrate`], an optional
//! end plane, and the default slicing settings. The format is documented in
//! `parts/README.md`; every error names the file and the field.

use crate::geometry::guide::{
    CircleArc, CubicSpline, ExprCurve, Expression, GuideCurve, Helix, Line, PipeRun, PipeSegment,
};
pub use crate::geometry::Plane;
use crate::geometry::{
    FrameMethod, GeometryError, MeshSubstrate, ProfileLaw, ProfilePiece, Substrate, Tube, TubeRange,
};
use crate::math::{tol, Point3, UnitVector3, Vector3};
pub use crate::path::{Discretisation, Strategy};
use crate::path::{EndRule, SliceOptions};
use crate::process::{ProcessParameters, ProcessPreset};
use crate::toolaxis::{AxisRule, NormalMethod, ToolAxisOptions};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// Largest part file accepted (bytes).
pub const MAX_PART_FILE_BYTES: u64 = 4 * 1024 * 1024;

/// Errors reading a part file; each names the file, and the field when known.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum PartFileError {
    /// The file cannot be read.
    #[error("{file}: cannot read: {reason}")]
    Io {
        /// The file.
        file: String,
        /// The system's message.
        reason: String,
    },
    /// The TOML does not parse or does not match the format (syntax error,
    /// unknown or missing field, wrong type); the message gives line and column.
    #[error("{file}: {message}")]
    Syntax {
        /// The file.
        file: String,
        /// The parser's message, with line, column and field.
        message: String,
    },
    /// A field has an unusable value.
    #[error("{file}: field `{field}`: {reason}")]
    Field {
        /// The file.
        file: String,
        /// Dotted path of the field (`profile.radius`).
        field: String,
        /// What is wrong.
        reason: String,
    },
    /// The described tube is geometrically invalid (folds, zero radius, ...).
    #[error("{file}: {source}")]
    Geometry {
        /// The file.
        file: String,
        /// The geometry error, naming `t` or `v`.
        source: GeometryError,
    },
}

/// A scalar in a part file: a number or an expression of the part's constants
/// (`"PI/2"`, `"R + r"`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(untagged)]
pub enum Scalar {
    /// A plain number.
    Number(f64),
    /// A constant expression.
    Expr(String),
}

/// A 3-vector of [`Scalar`]s.
pub type Vec3Field = [Scalar; 3];

/// Guide curve section of a part file.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum GuideSpec {
    /// Straight line `origin + t·direction`, `t` in mm.
    Line {
        /// Point at `t = 0` (mm).
        origin: Vec3Field,
        /// Direction (normalised on reading).
        direction: Vec3Field,
    },
    /// Circle arc `centre + R (cos t·radial0 + sin t·tangent0)`, `t` in rad.
    Arc {
        /// Centre (mm).
        centre: Vec3Field,
        /// Radius (mm).
        radius: Scalar,
        /// From the centre to the point at `t = 0`.
        radial0: Vec3Field,
        /// Direction of travel at `t = 0`.
        tangent0: Vec3Field,
    },
    /// Helix about `axis`, `t` in rad.
    Helix {
        /// Point of the axis at the height of `t = 0` (mm).
        centre: Vec3Field,
        /// Axis direction.
        axis: Vec3Field,
        /// From the axis to the point at `t = 0`.
        radial0: Vec3Field,
        /// Helix radius (mm).
        radius: Scalar,
        /// Rise per turn (mm).
        pitch: Scalar,
    },
    /// Parametric curve `x(t), y(t), z(t)` (mm).
    Expr {
        /// `x(t)`.
        x: String,
        /// `y(t)`.
        y: String,
        /// `z(t)`.
        z: String,
    },
    /// Natural cubic spline through points, `t` = chord length (mm).
    Spline {
        /// The points (mm).
        points: Vec<[f64; 3]>,
    },
    /// Straight legs and bends chained tangentially, `t` = arc length (mm).
    Pipe {
        /// Start point (mm).
        start: Vec3Field,
        /// Start direction.
        direction: Vec3Field,
        /// The segments, in order.
        segments: Vec<PipeSegmentSpec>,
    },
}

/// One pipe-run segment: `{ straight_mm = 40 }` or
/// `{ bend_radius_mm = 60, angle_deg = 90, toward = [1, 0, 0] }`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(untagged, deny_unknown_fields)]
pub enum PipeSegmentSpec {
    /// A straight leg.
    Straight {
        /// Length (mm).
        straight_mm: Scalar,
    },
    /// A bend.
    Bend {
        /// Centre-line radius (mm).
        bend_radius_mm: Scalar,
        /// Bend angle (degrees).
        angle_deg: Scalar,
        /// Direction the bend turns toward.
        toward: Vec3Field,
    },
}

/// Frame section.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct FrameSpec {
    /// `"rmf"` (default) or `"frenet"`.
    pub method: FrameMethod,
    /// Direction of `v = 0` at `t_min` (RMF only).
    pub reference: Option<Vec3Field>,
}

/// One piece of a piecewise profile.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ProfilePieceSpec {
    /// Upper bound of `t` (omit on the last piece).
    pub until: Option<Scalar>,
    /// `A(t)` (mm), an expression of `t` and the constants.
    pub radius: String,
}

/// Profile section.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum ProfileSpec {
    /// Constant radius (mm).
    Constant {
        /// Radius (mm).
        radius: Scalar,
    },
    /// `A(t)` as one expression (mm).
    Expr {
        /// The expression of `t`.
        radius: String,
    },
    /// Piecewise expressions.
    Piecewise {
        /// The pieces, by increasing `until`.
        pieces: Vec<ProfilePieceSpec>,
    },
}

/// Range section (guide parameter units).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RangeSpec {
    /// First parameter of the part.
    pub t_min: Scalar,
    /// Last parameter of the part.
    pub t_max: Scalar,
    /// Evaluable range before `t_min` (default 0).
    #[serde(default)]
    pub extend_before: Option<Scalar>,
    /// Evaluable range after `t_max` (default 0).
    #[serde(default)]
    pub extend_after: Option<Scalar>,
}

/// Substrate section.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum SubstrateSpec {
    /// Plane through `point` with `normal` toward the part.
    Plane {
        /// A point (mm).
        point: Vec3Field,
        /// Normal toward the part.
        normal: Vec3Field,
    },
    /// Cylinder.
    Cylinder {
        /// A point of the axis (mm).
        axis_point: Vec3Field,
        /// Axis direction.
        axis: Vec3Field,
        /// Radius (mm).
        radius: Scalar,
    },
    /// STL mesh, path relative to the part file.
    Mesh {
        /// STL file.
        file: String,
    },
}

/// End-plane section: where layers generated past the end are cut (SPEC §3.5).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PlaneSpec {
    /// A point (mm).
    pub point: Vec3Field,
    /// Outward normal.
    pub normal: Vec3Field,
}

/// Default slicing settings of a part.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SlicingSpec {
    /// Strategy (default `constant`).
    #[serde(default)]
    pub strategy: Strategy,
    /// Target interlayer distance `Delta` (mm).
    pub delta_mm: f64,
    /// Points per layer.
    pub points: Option<usize>,
    /// Max chord error (mm).
    pub chord_mm: Option<f64>,
    /// Max point spacing (mm).
    pub max_spacing_mm: Option<f64>,
    /// A vertex of a layer turning more than this is a corner (deg, in
    /// (0, 180); default 10), where it also turns more than 4 times the
    /// layer's median turning (SPEC §3.4).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub corner_threshold_deg: Option<Scalar>,
    /// Start and end each closed layer that has corners at its sharpest one
    /// (SPEC §3.3). Default: on in a torch-carried cell and when slicing
    /// alone, off in a part-carried cell ([`SliceOverrides::for_cell`](crate::SliceOverrides::for_cell)).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub seams_on_corners: Option<bool>,
}

/// How the torch axis is set, as written (`[tool_axis]`, degrees; SPEC §4).
/// Every field is optional: the default is the tool axis along the build
/// direction with analytic normals.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ToolAxisSpec {
    /// `auto` (default), `analytic` or `numeric`.
    #[serde(default)]
    pub normals: NormalMethod,
    /// Constant lead angle (deg, feed plane, positive toward the feed).
    pub lead_deg: Option<Scalar>,
    /// Constant tilt angle (deg, normal plane, positive toward the outside).
    pub tilt_deg: Option<Scalar>,
    /// The 50° rule (thesis eq. 3.20–3.21) with this angle (deg, in (0, 90)):
    /// the tool axis never leans more than it from `lean_axis`.
    pub max_lean_deg: Option<Scalar>,
    /// Axis of the lean cone (part frame; default `[0, 0, 1]`).
    pub lean_axis: Option<Vec3Field>,
    /// Project every build direction into the plane with this normal (part
    /// frame; thesis §3.3.1 uses `[1, 0, 0]` for the torus on a cylinder).
    pub project_build: Option<Vec3Field>,
    /// With `project_build`: a build direction within this angle (deg, in
    /// (0, 90)) of the plane is projected fully; beyond it the projection
    /// fades to none for a direction along the plane's normal, so the build
    /// direction stays continuous there (default: projected fully everywhere).
    pub project_build_full_deg: Option<Scalar>,
    /// First layer's build direction along the substrate normal (§2.4.2).
    #[serde(default)]
    pub first_layer_along_substrate: bool,
    /// Bound on the rate of the lead/tilt angles along a layer (deg per mm).
    pub max_rate_deg_per_mm: Option<Scalar>,
    /// Bound on the turning rate of the tool axis itself along a layer (deg
    /// per mm, part frame): spreads the jumps of the build direction at the
    /// cusps of constant-distance layers so that the wrist can follow.
    pub max_axis_rate_deg_per_mm: Option<Scalar>,
}

/// Deposition parameters, as written (`[process]`): a preset and optional
/// overrides (SPEC §5).
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ProcessSpec {
    /// `cmt-steel` (default), `pla` or `mag-steel`.
    #[serde(default)]
    pub preset: ProcessPreset,
    /// Nominal travel speed (mm/s); also the programmed speed of the robot.
    pub travel_speed_mm_s: Option<Scalar>,
    /// Wire feed speed (mm/s).
    pub wire_feed_speed_mm_s: Option<Scalar>,
    /// Slowest admissible travel speed (mm/s).
    pub travel_speed_min_mm_s: Option<Scalar>,
    /// Fastest admissible travel speed (mm/s).
    pub travel_speed_max_mm_s: Option<Scalar>,
    /// Exponent `a` of the bead height law `ln h = a ln v + b` (h in mm, v
    /// in mm/s; default −0.5), used by the closed loop (`waam replan`).
    #[serde(default)]
    pub bead_height_law_a: Option<Scalar>,
    /// Intercept `b` of that law (`ln mm`); default: the nominal travel
    /// speed lays a bead of `Delta`.
    #[serde(default)]
    pub bead_height_law_b: Option<Scalar>,
}

/// A part file as written (before validation).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PartSpec {
    /// Short name (used for output folders).
    pub name: String,
    /// One line saying what the part is.
    #[serde(default)]
    pub description: String,
    /// Where the numbers come from.
    #[serde(default)]
    pub source: String,
    /// Named constants usable in expressions.
    #[serde(default)]
    pub constants: BTreeMap<String, f64>,
    /// Guide curve.
    pub guide: GuideSpec,
    /// Frame along the guide.
    #[serde(default)]
    pub frame: FrameSpec,
    /// Profile radius law.
    pub profile: ProfileSpec,
    /// Parameter range.
    pub range: RangeSpec,
    /// Substrate.
    pub substrate: SubstrateSpec,
    /// Optional truncation plane.
    pub end_plane: Option<PlaneSpec>,
    /// Default slicing settings.
    pub slicing: SlicingSpec,
    /// How the tool axis is set (optional).
    pub tool_axis: Option<ToolAxisSpec>,
    /// Deposition parameters (optional; CMT steel when absent).
    pub process: Option<ProcessSpec>,
}

/// Validated slicing settings.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Slicing {
    /// Strategy.
    pub strategy: Strategy,
    /// Target interlayer distance (mm, > 0).
    pub delta_mm: f64,
    /// Discretisation of each layer.
    pub discretisation: Discretisation,
    /// Corner threshold (rad, in (0, π)).
    pub corner_threshold_rad: f64,
    /// Closed layers with corners start and end at their sharpest one
    /// (`None`: as the cell has it, [`SliceOverrides::for_cell`](crate::SliceOverrides::for_cell)).
    pub seams_on_corners: Option<bool>,
}

/// A validated part.
#[derive(Debug, Clone)]
pub struct Part {
    /// Short name.
    pub name: String,
    /// The file it was read from, as given (or the origin passed to
    /// [`parse_part`]); errors and reports name it.
    pub file: String,
    /// One-line description.
    pub description: String,
    /// Source of the numbers.
    pub source: String,
    /// The tube (part frame, mm).
    pub tube: Tube,
    /// The substrate (part frame, mm).
    pub substrate: Substrate,
    /// Truncation plane, if any.
    pub end_plane: Option<Plane>,
    /// Default slicing settings.
    pub slicing: Slicing,
    /// Tool-axis settings (`[tool_axis]`; defaults when absent), validated.
    pub tool_axis: ToolAxisOptions,
    /// Deposition parameters (`[process]`; CMT steel when absent), validated.
    pub process: ProcessParameters,
    /// The part as written.
    pub spec: PartSpec,
}

impl Part {
    /// The part's default slicing options: its strategy, `Delta` and
    /// discretisation and corners (seams on corners unless the file says
    /// otherwise); truncation by its end plane when it has one, else whole
    /// layers; seams aligned.
    pub fn slice_options(&self) -> SliceOptions {
        let mut o = SliceOptions::new(self.slicing.strategy, self.slicing.delta_mm);
        o.discretisation = self.slicing.discretisation;
        o.corner_threshold_rad = self.slicing.corner_threshold_rad;
        o.seams_on_corners = self.slicing.seams_on_corners.unwrap_or(true);
        o.end = match self.end_plane {
            Some(p) => EndRule::Truncate(p),
            None => EndRule::WholeLayers,
        };
        o
    }
}

/// Reads and validates a part file.
///
/// # Errors
/// [`PartFileError`] naming the file and the field.
pub fn read_part_file(path: &Path) -> Result<Part, PartFileError> {
    let file = path.display().to_string();
    let io = |e: std::io::Error| PartFileError::Io {
        file: file.clone(),
        reason: e.to_string(),
    };
    let meta = std::fs::metadata(path).map_err(io)?;
    if meta.len() > MAX_PART_FILE_BYTES {
        return Err(PartFileError::Io {
            file,
            reason: format!(
                "{} bytes; the limit for a part file is {MAX_PART_FILE_BYTES}",
                meta.len()
            ),
        });
    }
    // At most one byte past the limit: a device or pipe reports length 0.
    use std::io::Read as _;
    let mut bytes = Vec::new();
    std::fs::File::open(path)
        .map_err(io)?
        .take(MAX_PART_FILE_BYTES + 1)
        .read_to_end(&mut bytes)
        .map_err(io)?;
    if bytes.len() as u64 > MAX_PART_FILE_BYTES {
        return Err(PartFileError::Io {
            file,
            reason: format!("more than {MAX_PART_FILE_BYTES} bytes, the limit for a part file"),
        });
    }
    let text = String::from_utf8(bytes).map_err(|e| PartFileError::Syntax {
        file: file.clone(),
        message: format!(
            "not valid UTF-8 text (byte {})",
            e.utf8_error().valid_up_to()
        ),
    })?;
    let base = path.parent().map(Path::to_path_buf).unwrap_or_default();
    parse_part(&text, &file, &base)
}

/// Parses and validates part-file text. `file` names it in errors; `base_dir`
/// resolves relative paths (STL substrates).
///
/// # Errors
/// [`PartFileError`] naming `file` and the field.
pub fn parse_part(text: &str, file: &str, base_dir: &Path) -> Result<Part, PartFileError> {
    let spec: PartSpec = toml::from_str(text).map_err(|e| PartFileError::Syntax {
        file: file.to_string(),
        message: e.to_string().trim_end().to_string(),
    })?;
    build_part(spec, file, base_dir)
}

/// Builds a validated [`Part`] from a [`PartSpec`].
///
/// # Errors
/// [`PartFileError`] naming `file` and the field.
pub fn build_part(spec: PartSpec, file: &str, base_dir: &Path) -> Result<Part, PartFileError> {
    let cx = Ctx {
        file,
        constants: &spec.constants,
    };
    for (k, v) in &spec.constants {
        if !v.is_finite() {
            return Err(cx.field(&format!("constants.{k}"), "must be a finite number"));
        }
    }
    if spec.name.trim().is_empty() {
        return Err(cx.field("name", "must not be empty"));
    }
    let guide = cx.guide(&spec.guide)?;
    let reference = match &spec.frame.reference {
        Some(r) => Some(cx.vec3("frame.reference", r)?),
        None => None,
    };
    let profile = cx.profile(&spec.profile)?;
    let range = TubeRange {
        t_min: cx.scalar("range.t_min", &spec.range.t_min)?,
        t_max: cx.scalar("range.t_max", &spec.range.t_max)?,
        extend_before: match &spec.range.extend_before {
            Some(s) => cx.non_negative("range.extend_before", s)?,
            None => 0.0,
        },
        extend_after: match &spec.range.extend_after {
            Some(s) => cx.non_negative("range.extend_after", s)?,
            None => 0.0,
        },
    };
    if range.t_min >= range.t_max {
        return Err(cx.field(
            "range",
            &format!(
                "empty t-range: t_min = {} must be below t_max = {}",
                range.t_min, range.t_max
            ),
        ));
    }
    let tube = Tube::new(guide, spec.frame.method, reference, profile, range)
        .map_err(|e| cx.geometry(e))?;
    let substrate = cx.substrate(&spec.substrate, base_dir)?;
    let end_plane = match &spec.end_plane {
        Some(p) => Some(Plane {
            point: Point3::from(cx.vec3("end_plane.point", &p.point)?),
            normal: cx.unit("end_plane.normal", &p.normal)?,
        }),
        None => None,
    };
    let slicing = cx.slicing(&spec.slicing)?;
    let tool_axis = cx.tool_axis(&spec.tool_axis.clone().unwrap_or_default())?;
    let process = cx.process(&spec.process.clone().unwrap_or_default())?;
    Ok(Part {
        name: spec.name.clone(),
        file: file.to_string(),
        description: spec.description.clone(),
        source: spec.source.clone(),
        tube,
        substrate,
        end_plane,
        slicing,
        tool_axis,
        process,
        spec,
    })
}

struct Ctx<'a> {
    file: &'a str,
    constants: &'a BTreeMap<String, f64>,
}

impl Ctx<'_> {
    fn field(&self, field: &str, reason: &str) -> PartFileError {
        PartFileError::Field {
            file: self.file.to_string(),
            field: field.to_string(),
            reason: reason.to_string(),
        }
    }

    fn geometry(&self, e: GeometryError) -> PartFileError {
        match e {
            GeometryError::InvalidField { field, reason } => self.field(&field, &reason),
            GeometryError::Pipe { index, reason } => {
                self.field(&format!("guide.segments[{index}]"), &reason)
            }
            GeometryError::Spline { index, reason } => {
                self.field(&format!("guide.points[{index}]"), &reason)
            }
            other => PartFileError::Geometry {
                file: self.file.to_string(),
                source: other,
            },
        }
    }

    fn scalar(&self, field: &str, s: &Scalar) -> Result<f64, PartFileError> {
        let x = match s {
            Scalar::Number(x) => *x,
            Scalar::Expr(text) => {
                let e = Expression::parse(text, "t", self.constants)
                    .map_err(|e| self.field(field, &e.to_string()))?;
                if e.depends_on_param() {
                    return Err(self.field(field, "must be a constant expression (it uses `t`)"));
                }
                e.eval(0.0)
            }
        };
        if !x.is_finite() {
            return Err(self.field(field, &format!("must be a finite number, got {x}")));
        }
        Ok(x)
    }

    fn positive(&self, field: &str, s: &Scalar) -> Result<f64, PartFileError> {
        let x = self.scalar(field, s)?;
        if x <= 0.0 {
            return Err(self.field(field, &format!("must be positive, got {x}")));
        }
        Ok(x)
    }

    fn non_negative(&self, field: &str, s: &Scalar) -> Result<f64, PartFileError> {
        let x = self.scalar(field, s)?;
        if x < 0.0 {
            return Err(self.field(field, &format!("must not be negative, got {x}")));
        }
        Ok(x)
    }

    fn vec3(&self, field: &str, v: &Vec3Field) -> Result<Vector3, PartFileError> {
        Ok(Vector3::new(
            self.scalar(&format!("{field}[0]"), &v[0])?,
            self.scalar(&format!("{field}[1]"), &v[1])?,
            self.scalar(&format!("{field}[2]"), &v[2])?,
        ))
    }

    fn unit(&self, field: &str, v: &Vec3Field) -> Result<UnitVector3, PartFileError> {
        let x = self.vec3(field, v)?;
        UnitVector3::try_new(x, tol::DEGENERATE)
            .ok_or_else(|| self.field(field, "must be a non-zero direction"))
    }

    fn expr(&self, field: &str, text: &str) -> Result<Expression, PartFileError> {
        Expression::parse(text, "t", self.constants).map_err(|e| self.field(field, &e.to_string()))
    }

    fn guide(&self, g: &GuideSpec) -> Result<Arc<dyn GuideCurve>, PartFileError> {
        Ok(match g {
            GuideSpec::Line { origin, direction } => Arc::new(Line {
                origin: Point3::from(self.vec3("guide.origin", origin)?),
                direction: self.unit("guide.direction", direction)?,
            }),
            GuideSpec::Arc {
                centre,
                radius,
                radial0,
                tangent0,
            } => {
                let e1 = self.unit("guide.radial0", radial0)?;
                let e2 = self.unit("guide.tangent0", tangent0)?;
                if e1.dot(&e2).abs() > tol::ANGLE_RAD {
                    return Err(
                        self.field("guide.tangent0", "must be perpendicular to guide.radial0")
                    );
                }
                Arc::new(CircleArc {
                    centre: Point3::from(self.vec3("guide.centre", centre)?),
                    radius: self.positive("guide.radius", radius)?,
                    radial0: e1,
                    tangent0: e2,
                })
            }
            GuideSpec::Helix {
                centre,
                axis,
                radial0,
                radius,
                pitch,
            } => {
                let a = self.unit("guide.axis", axis)?;
                let e1 = self.unit("guide.radial0", radial0)?;
                if a.dot(&e1).abs() > tol::ANGLE_RAD {
                    return Err(self.field("guide.radial0", "must be perpendicular to guide.axis"));
                }
                Arc::new(Helix {
                    centre: Point3::from(self.vec3("guide.centre", centre)?),
                    axis: a,
                    radial0: e1,
                    radius: self.positive("guide.radius", radius)?,
                    pitch: self.scalar("guide.pitch", pitch)?,
                })
            }
            GuideSpec::Expr { x, y, z } => Arc::new(ExprCurve {
                x: self.expr("guide.x", x)?,
                y: self.expr("guide.y", y)?,
                z: self.expr("guide.z", z)?,
            }),
            GuideSpec::Spline { points } => {
                let pts: Vec<Point3> = points
                    .iter()
                    .map(|p| Point3::new(p[0], p[1], p[2]))
                    .collect();
                Arc::new(CubicSpline::new(&pts).map_err(|e| self.geometry(e))?)
            }
            GuideSpec::Pipe {
                start,
                direction,
                segments,
            } => {
                let mut segs = Vec::with_capacity(segments.len());
                for (i, s) in segments.iter().enumerate() {
                    let f = |name: &str| format!("guide.segments[{i}].{name}");
                    segs.push(match s {
                        PipeSegmentSpec::Straight { straight_mm } => PipeSegment::Straight {
                            length: self.positive(&f("straight_mm"), straight_mm)?,
                        },
                        PipeSegmentSpec::Bend {
                            bend_radius_mm,
                            angle_deg,
                            toward,
                        } => PipeSegment::Bend {
                            radius: self.positive(&f("bend_radius_mm"), bend_radius_mm)?,
                            angle: self.positive(&f("angle_deg"), angle_deg)?.to_radians(),
                            toward: self.vec3(&f("toward"), toward)?,
                        },
                    });
                }
                Arc::new(
                    PipeRun::new(
                        Point3::from(self.vec3("guide.start", start)?),
                        self.unit("guide.direction", direction)?,
                        &segs,
                    )
                    .map_err(|e| self.geometry(e))?,
                )
            }
        })
    }

    fn profile(&self, p: &ProfileSpec) -> Result<ProfileLaw, PartFileError> {
        Ok(match p {
            ProfileSpec::Constant { radius } => {
                ProfileLaw::Constant(self.positive("profile.radius", radius)?)
            }
            ProfileSpec::Expr { radius } => {
                ProfileLaw::Expression(self.expr("profile.radius", radius)?)
            }
            ProfileSpec::Piecewise { pieces } => {
                if pieces.is_empty() {
                    return Err(self.field("profile.pieces", "needs at least one piece"));
                }
                let mut out = Vec::with_capacity(pieces.len());
                let mut last = f64::NEG_INFINITY;
                for (i, piece) in pieces.iter().enumerate() {
                    let until = match (&piece.until, i + 1 == pieces.len()) {
                        (Some(u), _) => self.scalar(&format!("profile.pieces[{i}].until"), u)?,
                        (None, true) => f64::INFINITY,
                        (None, false) => {
                            return Err(self.field(
                                &format!("profile.pieces[{i}].until"),
                                "missing (only the last piece may omit it)",
                            ))
                        }
                    };
                    if until <= last {
                        return Err(self.field(
                            &format!("profile.pieces[{i}].until"),
                            "must increase from piece to piece",
                        ));
                    }
                    last = until;
                    out.push(ProfilePiece {
                        until,
                        radius: self.expr(&format!("profile.pieces[{i}].radius"), &piece.radius)?,
                    });
                }
                ProfileLaw::Piecewise(out)
            }
        })
    }

    fn substrate(&self, s: &SubstrateSpec, base_dir: &Path) -> Result<Substrate, PartFileError> {
        let sub = match s {
            SubstrateSpec::Plane { point, normal } => Substrate::Plane {
                point: Point3::from(self.vec3("substrate.point", point)?),
                normal: self.unit("substrate.normal", normal)?,
            },
            SubstrateSpec::Cylinder {
                axis_point,
                axis,
                radius,
            } => Substrate::Cylinder {
                axis_point: Point3::from(self.vec3("substrate.axis_point", axis_point)?),
                axis: self.unit("substrate.axis", axis)?,
                radius: self.positive("substrate.radius", radius)?,
            },
            SubstrateSpec::Mesh { file } => {
                let path: PathBuf = base_dir.join(file);
                Substrate::Mesh(Box::new(MeshSubstrate::from_stl_file(&path).map_err(
                    |e| match e {
                        GeometryError::Stl { reason, .. } => {
                            self.field("substrate.file", &format!("{}: {reason}", path.display()))
                        }
                        other => self.geometry(other),
                    },
                )?))
            }
        };
        sub.validate().map_err(|e| self.geometry(e))?;
        Ok(sub)
    }

    fn slicing(&self, s: &SlicingSpec) -> Result<Slicing, PartFileError> {
        if !(s.delta_mm.is_finite() && s.delta_mm > 0.0) {
            return Err(self.field(
                "slicing.delta_mm",
                &format!("must be positive and finite, got {}", s.delta_mm),
            ));
        }
        let discretisation = match (s.points, s.chord_mm, s.max_spacing_mm) {
            (Some(n), None, None) => {
                if n < 3 {
                    return Err(self.field(
                        "slicing.points",
                        &format!("a layer needs at least 3 points, got {n}"),
                    ));
                }
                Discretisation::Points(n)
            }
            (None, Some(e), None) => {
                if !(e.is_finite() && e > 0.0) {
                    return Err(self.field(
                        "slicing.chord_mm",
                        &format!("must be positive and finite, got {e}"),
                    ));
                }
                Discretisation::ChordError(e)
            }
            (None, None, Some(d)) => {
                if !(d.is_finite() && d > 0.0) {
                    return Err(self.field(
                        "slicing.max_spacing_mm",
                        &format!("must be positive and finite, got {d}"),
                    ));
                }
                Discretisation::MaxSpacing(d)
            }
            (None, None, None) => Discretisation::Points(500),
            _ => {
                return Err(self.field(
                    "slicing",
                    "give only one of `points`, `chord_mm`, `max_spacing_mm`",
                ));
            }
        };
        let corner_threshold_rad = match &s.corner_threshold_deg {
            Some(v) => {
                let field = "slicing.corner_threshold_deg";
                let d = self.positive(field, v)?;
                if d >= 180.0 {
                    return Err(self.field(field, &format!("must be below 180 degrees, got {d}")));
                }
                d.to_radians()
            }
            None => crate::path::SEAM_CORNER_RAD,
        };
        Ok(Slicing {
            strategy: s.strategy,
            delta_mm: s.delta_mm,
            discretisation,
            corner_threshold_rad,
            seams_on_corners: s.seams_on_corners,
        })
    }

    fn tool_axis(&self, s: &ToolAxisSpec) -> Result<ToolAxisOptions, PartFileError> {
        let angle = |field: &str, v: &Option<Scalar>| -> Result<f64, PartFileError> {
            match v {
                Some(v) => {
                    let d = self.scalar(field, v)?;
                    if d.abs() >= 90.0 {
                        return Err(self
                            .field(field, &format!("must be within (-90, 90) degrees, got {d}")));
                    }
                    Ok(d.to_radians())
                }
                None => Ok(0.0),
            }
        };
        // an angle in (0, 90) degrees, in rad
        let acute = |field: &str, v: &Scalar| -> Result<f64, PartFileError> {
            let d = self.positive(field, v)?;
            if d >= 90.0 {
                return Err(self.field(field, &format!("must be below 90 degrees, got {d}")));
            }
            Ok(d.to_radians())
        };
        let rule = match &s.max_lean_deg {
            Some(v) => {
                let max_angle_rad = acute("tool_axis.max_lean_deg", v)?;
                let axis = match &s.lean_axis {
                    Some(a) => self.unit("tool_axis.lean_axis", a)?.into_inner(),
                    None => Vector3::z(),
                };
                AxisRule::MaxAngleFromAxis {
                    axis: axis.into(),
                    max_angle_rad,
                }
            }
            None if s.lean_axis.is_some() => {
                return Err(self.field(
                    "tool_axis.lean_axis",
                    "has no effect without `max_lean_deg`",
                ))
            }
            None => AxisRule::None,
        };
        let opts = ToolAxisOptions {
            normals: s.normals,
            lead_rad: angle("tool_axis.lead_deg", &s.lead_deg)?,
            tilt_rad: angle("tool_axis.tilt_deg", &s.tilt_deg)?,
            rule,
            project_build: match &s.project_build {
                Some(n) => Some(self.unit("tool_axis.project_build", n)?.into_inner().into()),
                None => None,
            },
            project_build_full_rad: match &s.project_build_full_deg {
                Some(_) if s.project_build.is_none() => {
                    return Err(self.field(
                        "tool_axis.project_build_full_deg",
                        "has no effect without `project_build`",
                    ))
                }
                Some(v) => Some(acute("tool_axis.project_build_full_deg", v)?),
                None => None,
            },
            first_layer_along_substrate: s.first_layer_along_substrate,
            max_rate_rad_per_mm: match &s.max_rate_deg_per_mm {
                Some(v) => Some(
                    self.positive("tool_axis.max_rate_deg_per_mm", v)?
                        .to_radians(),
                ),
                None => None,
            },
            max_axis_rate_rad_per_mm: match &s.max_axis_rate_deg_per_mm {
                Some(v) => Some(
                    self.positive("tool_axis.max_axis_rate_deg_per_mm", v)?
                        .to_radians(),
                ),
                None => None,
            },
        };
        opts.validate()
            .map_err(|e| self.field("tool_axis", &e.to_string()))?;
        Ok(opts)
    }

    fn process(&self, s: &ProcessSpec) -> Result<ProcessParameters, PartFileError> {
        let mut p = s.preset.parameters();
        for (name, value, slot) in [
            (
                "travel_speed_mm_s",
                &s.travel_speed_mm_s,
                &mut p.travel_speed_mm_s,
            ),
            (
                "wire_feed_speed_mm_s",
                &s.wire_feed_speed_mm_s,
                &mut p.wire_feed_speed_mm_s,
            ),
            (
                "travel_speed_min_mm_s",
                &s.travel_speed_min_mm_s,
                &mut p.travel_speed_min_mm_s,
            ),
            (
                "travel_speed_max_mm_s",
                &s.travel_speed_max_mm_s,
                &mut p.travel_speed_max_mm_s,
            ),
        ] {
            if let Some(v) = value {
                *slot = self.positive(&format!("process.{name}"), v)?;
            }
        }
        if let Some(a) = &s.bead_height_law_a {
            p.bead_height_law.a = self.scalar("process.bead_height_law_a", a)?;
        }
        if let Some(b) = &s.bead_height_law_b {
            p.bead_height_law.b = Some(self.scalar("process.bead_height_law_b", b)?);
        }
        p.validate().map_err(|e| match e {
            crate::process::ProcessError::InvalidParameter { field, reason } => {
                self.field(&format!("process.{field}"), &reason)
            }
            other => self.field("process", &other.to_string()),
        })?;
        Ok(p)
    }
}
