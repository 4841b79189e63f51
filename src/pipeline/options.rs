//! What a caller may change of a part file's settings, each given once: the
//! slicing, tool-axis and process overrides of [`SliceOverrides`], and for a
//! plan the `R_Z` law and the program format of [`PlanOptions`].

use std::fmt;
use std::str::FromStr;

use crate::optimise::{
    Abscissa, ConfigurationChoice, OptimiseOptions, Parameterisation, DEFAULT_STOP_RELATIVE_GAIN,
};
use crate::path::smooth::Smoothing;
use crate::path::{Discretisation, SliceOptions, Strategy};
use crate::process::ProcessParameters;
use crate::robot::Vendor;
use crate::toolaxis::{AxisRule, ToolAxisOptions};

/// Overrides of a part file's `[slicing]`, `[tool_axis]` and `[process]`
/// tables. `None` / `false` keeps the part file's value. Plain data.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct SliceOverrides {
    /// Slicing strategy.
    pub strategy: Option<Strategy>,
    /// Target interlayer distance `Delta` (mm, > 0).
    pub delta_mm: Option<f64>,
    /// Discretisation of each layer (points, chord error or spacing in mm).
    pub discretisation: Option<Discretisation>,
    /// Bound on the turning angle of constant-distance layers (SPEC §3.4).
    pub smoothing: Option<Smoothing>,
    /// Rotate the start of layer `k` by `k × stagger` (rad of `v`); setting it
    /// turns seam alignment off.
    pub stagger_rad: Option<f64>,
    /// A vertex of a layer turning more than this is a corner (rad, in
    /// (0, π)).
    pub corner_threshold_rad: Option<f64>,
    /// Whether closed layers with corners start and end at their sharpest
    /// one (`Some(false)` keeps the aligned and staggered seams everywhere).
    pub seams_on_corners: Option<bool>,
    /// Spiral only: profile angle where the spiral starts (rad).
    pub spiral_start_rad: Option<f64>,
    /// Spiral only: travel toward decreasing profile angle.
    pub spiral_reverse: bool,
    /// Stop after this many layers (or spiral turns).
    pub max_layers: Option<usize>,
    /// Tool-axis overrides.
    pub tool_axis: AxisOverrides,
    /// Process parameters replacing the part's whole `[process]` table (e.g.
    /// a [`ProcessPreset`](crate::process::ProcessPreset)'s).
    pub process: Option<ProcessParameters>,
    /// Programmed travel speed of the torch over the part (mm/s): the process
    /// estimates, the joint-speed constraints and the program all use it.
    pub travel_speed_mm_s: Option<f64>,
    /// Budget of computed points: a slice whose estimate
    /// ([`estimate_work`](crate::path::estimate_work)) is larger is
    /// refused before any work with [`Error::OverBudget`](crate::Error::OverBudget).
    /// `None`: [`DEFAULT_MAX_POINTS`].
    pub max_points: Option<u64>,
}

/// The default budget of computed points of a slice (5 M, about 1 GB of
/// path, distance map and tool axes).
pub const DEFAULT_MAX_POINTS: u64 = 5_000_000;

/// Overrides of a part file's `[tool_axis]` table. Plain data.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct AxisOverrides {
    /// Tool axis along the build direction: no lead, tilt, lean rule or rate
    /// bound (applied before the other overrides).
    pub plain: bool,
    /// Constant lead angle (rad, feed plane).
    pub lead_rad: Option<f64>,
    /// Constant tilt angle (rad, normal plane).
    pub tilt_rad: Option<f64>,
    /// The torch never leans more than this from the part's Z (rad; the
    /// thesis's 50° rule, eq. 3.20–3.21).
    pub max_lean_rad: Option<f64>,
    /// Bound on the turning rate of the torch axis along a layer (rad/mm).
    pub max_axis_rate_rad_per_mm: Option<f64>,
}

impl AxisOverrides {
    /// `base` (a part's `[tool_axis]` settings) with these overrides applied.
    pub fn apply(&self, base: &ToolAxisOptions) -> ToolAxisOptions {
        let mut o = base.clone();
        if self.plain {
            o.lead_rad = 0.0;
            o.tilt_rad = 0.0;
            o.rule = AxisRule::None;
            o.max_rate_rad_per_mm = None;
            o.max_axis_rate_rad_per_mm = None;
        }
        if let Some(r) = self.max_axis_rate_rad_per_mm {
            o.max_axis_rate_rad_per_mm = Some(r);
        }
        if let Some(a) = self.lead_rad {
            o.lead_rad = a;
        }
        if let Some(a) = self.tilt_rad {
            o.tilt_rad = a;
        }
        if let Some(a) = self.max_lean_rad {
            o.rule = AxisRule::MaxAngleFromAxis {
                axis: [0.0, 0.0, 1.0],
                max_angle_rad: a,
            };
        }
        o
    }
}

impl SliceOverrides {
    /// `base` (a part's slicing options) with these overrides applied.
    pub fn apply(&self, base: &SliceOptions) -> SliceOptions {
        let mut o = *base;
        if let Some(s) = self.strategy {
            o.strategy = s;
        }
        if let Some(d) = self.delta_mm {
            o.delta_mm = d;
        }
        if let Some(d) = self.discretisation {
            o.discretisation = d;
        }
        if self.smoothing.is_some() {
            o.smoothing = self.smoothing;
        }
        if let Some(s) = self.stagger_rad {
            o.stagger_rad = s;
            o.align_seams = false;
        }
        if let Some(c) = self.corner_threshold_rad {
            o.corner_threshold_rad = c;
        }
        if let Some(on) = self.seams_on_corners {
            o.seams_on_corners = on;
        }
        if let Some(s) = self.spiral_start_rad {
            o.spiral_start_rad = s;
        }
        o.spiral_reverse |= self.spiral_reverse;
        o.max_layers = self.max_layers.or(o.max_layers);
        o
    }

    /// These overrides for a plan of `part` in `cell`: where neither they
    /// nor the part file say whether seams go on corners, on in a
    /// torch-carried cell and off in a part-carried one. The torch-carried
    /// cell's positioner keeps `b` within the cone of the vertical, which
    /// no positioner speed does across a corner inside a bead (SPEC §9); in
    /// the part-carried cell the arm turns the part through a corner within
    /// the tool axis's rate bound, and moving the seams there cost the
    /// S-bend its placement in the ROBOWAM part-carried cell (issue 19's
    /// done-when test: no placement with seams on corners, as after commit
    /// 72338a1's smaller move).
    pub fn for_cell(&self, part: &super::Part, cell: &super::Cell) -> SliceOverrides {
        let mut o = self.clone();
        if o.seams_on_corners.is_none() && part.slicing.seams_on_corners.is_none() {
            o.seams_on_corners = Some(matches!(
                cell.layout,
                crate::robot::CellLayout::TorchCarried(_)
            ));
        }
        o
    }

    /// `base` (a part's process parameters) with the process and travel-speed
    /// overrides applied (not yet validated).
    pub fn apply_process(&self, base: &ProcessParameters) -> ProcessParameters {
        let mut p = self.process.clone().unwrap_or_else(|| base.clone());
        if let Some(v) = self.travel_speed_mm_s {
            p.travel_speed_mm_s = v;
        }
        p
    }
}

pub use crate::program::registry::ParseOptionError;

/// The `R_Z` law of a plan in its written form: `fixed:DEG`, `poly:N` (most
/// degree 0..=8, raised while it pays, SPEC §7), `spline` or `point` (the
/// point-by-point baseline).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RzLaw(pub Parameterisation);

impl Default for RzLaw {
    /// `poly:4`.
    fn default() -> Self {
        Self(Parameterisation::Polynomial {
            max_degree: 4,
            abscissa: Abscissa::Auto,
            stop_relative_gain: DEFAULT_STOP_RELATIVE_GAIN,
        })
    }
}

impl FromStr for RzLaw {
    type Err = ParseOptionError;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let bad = || ParseOptionError {
            given: s.to_string(),
            expected: "fixed:DEG, poly:N (0..=8), spline or point",
        };
        let law = match s.split_once(':') {
            Some(("fixed", d)) => {
                let deg: f64 = d.parse().map_err(|_| bad())?;
                if !deg.is_finite() {
                    return Err(bad());
                }
                Parameterisation::Fixed {
                    r_z_rad: deg.to_radians(),
                }
            }
            Some(("poly", n)) => {
                let n: usize = n.parse().map_err(|_| bad())?;
                if n > 8 {
                    return Err(bad());
                }
                Parameterisation::Polynomial {
                    max_degree: n,
                    abscissa: Abscissa::Auto,
                    stop_relative_gain: DEFAULT_STOP_RELATIVE_GAIN,
                }
            }
            None if s == "spline" => Parameterisation::SmoothingSpline { smoothness: 1.0 },
            None if s == "point" => Parameterisation::PointByPoint,
            _ => return Err(bad()),
        };
        Ok(Self(law))
    }
}

impl fmt::Display for RzLaw {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.0 {
            Parameterisation::Fixed { r_z_rad } => write!(f, "fixed:{}", r_z_rad.to_degrees()),
            Parameterisation::Polynomial { max_degree, .. } => write!(f, "poly:{max_degree}"),
            Parameterisation::SmoothingSpline { .. } => f.write_str("spline"),
            Parameterisation::PointByPoint => f.write_str("point"),
        }
    }
}

/// Options of [`plan_part`](crate::plan_part): the slicing overrides, the
/// program format and the optimiser's options (the `R_Z` law and the
/// positioner's mode among them). Plain data (a host's progress callback
/// and cancel flag go to [`plan_part_with`](crate::plan_part_with) as a
/// [`Control`](super::Control)); `Default` plans with the part file's
/// settings, `poly:4`, the cell's IK branch on every layer and the cell
/// robot's vendor's format.
#[derive(Debug, Clone, PartialEq)]
pub struct PlanOptions {
    /// Overrides of the part file's slicing, tool-axis and process settings
    /// (the travel speed among them, given once).
    pub slice: SliceOverrides,
    /// Program format; `None`: the cell robot's vendor's. The one place a
    /// format is asked: checked against the cell's robot before any work
    /// (another vendor's is refused), kept as [`PlannedPart::format`](crate::PlannedPart::format)
    /// and written by [`PlannedPart::write_programs`](crate::PlannedPart::write_programs).
    pub format: Option<Vendor>,
    /// The optimiser's options, used as given (the `R_Z` law in
    /// `parameterisation`, see [`PlanOptions::with_rz`]; the torch-carried
    /// cell's positioner in `positioner`) but for `travel_speed_mm_s`, which
    /// is the process's: the part file's or [`SliceOverrides`]'s, the one
    /// place the travel speed is given.
    pub optimise: OptimiseOptions,
}

impl Default for PlanOptions {
    fn default() -> Self {
        Self {
            slice: SliceOverrides::default(),
            format: None,
            optimise: OptimiseOptions {
                parameterisation: RzLaw::default().0,
                configuration: ConfigurationChoice::Cell,
                ..OptimiseOptions::default()
            },
        }
    }
}

impl PlanOptions {
    /// These options with the `R_Z` law `law` (its command-line form parses
    /// into an [`RzLaw`]: `"poly:4"`, `"fixed:90"`, ...).
    #[must_use]
    pub fn with_rz(mut self, law: RzLaw) -> Self {
        self.optimise.parameterisation = law.0;
        self
    }

    /// The `R_Z` law of these options.
    pub fn rz(&self) -> RzLaw {
        RzLaw(self.optimise.parameterisation)
    }
}
