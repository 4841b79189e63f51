//! Command-line arguments of the `waam` example.

use clap::{Parser, Subcommand};
use std::path::PathBuf;

/// Plans wire-arc additive manufacturing of tubes: reads a part file, reports
/// its geometry (more stages to come: slice, plan, check).
#[derive(Debug, Parser)]
#[command(name = "waam", version, about)]
pub struct Args {
    /// What to do.
    #[command(subcommand)]
    pub command: Command,
    /// Print nothing but errors.
    #[arg(long, global = true)]
    pub quiet: bool,
}

/// Strategy names on the command line.
#[derive(Debug, Clone, Copy, clap::ValueEnum)]
pub enum StrategyArg {
    /// Constant local interlayer distance.
    Constant,
    /// Iso-parametric.
    Iso,
    /// Perpendicular to the guide.
    Perpendicular,
    /// Planar Z slices.
    Planar,
    /// Continuous spiral.
    Spiral,
}

/// Sub-commands.
#[derive(Debug, Subcommand)]
pub enum Command {
    /// Slice a part: writes path.csv and summary.json in --out.
    Slice(SliceArgs),
    /// Check a robot program against a cell — FANUC .ls (following its CALLs), KUKA .src + .dat,
    /// ABB .mod (and the part modules it loads; any group NAME_P01.. of a build cut to the memory
    /// budget brings all its groups): limits, speeds, reachability, configuration, beads, budget.
    /// Exit 0 valid, 2 problems, 1 unreadable.
    Check(CheckArgs),
    /// Plan a part in a cell: slice, tool axes, R_Z optimisation, joints;
    /// writes joints.csv and summary.json in --out (exit 2 if infeasible).
    Plan(PlanArgs),
    /// Place a part in a cell: search the deposition point (part carried) or the positioner's
    /// pose (torch carried) and the mount's rotation within the cell file's [placement] bounds
    /// so that every layer is feasible with the widest margin; writes cell.toml and placement.json
    /// in --out (exit 0 found, 2 none found, 1 bad input).
    Place(PlaceArgs),
    /// Fit a part to a tubular mesh (binary or ASCII STL: the mid-surface, or the inner and outer
    /// skins of the wall): a spline guide and a radius law from end to end; writes part.toml
    /// (which slice, plan and place take), fit.json (the residuals) and report.html (the mesh
    /// coloured by its distance to the fitted tube) in --out.
    /// Exit 0 fitted, 1 bad input or not a tube.
    Fit(FitArgs),
    /// Replan the layers after a measured layer K: reads the scan of layer K's top (points x,y,z or
    /// height errors layer,point,dh_mm), corrects the next layers' travel speeds (and, where the
    /// process window cannot absorb the error, their geometry), optimises them in the cell and writes
    /// joints.csv, summary.json, report.html and the program that resumes the build (exit 0 done, 2 infeasible,
    /// 1 bad input or a refused scan).
    Replan(ReplanArgs),
    /// List the sample parts (and cells) with one line each.
    Parts {
        /// Folder holding the part files.
        #[arg(long, default_value = "parts")]
        dir: PathBuf,
    },
    /// Read a part file and print its geometry: guide, profile, range, first layer.
    Geometry {
        /// The part file (TOML).
        part: PathBuf,
        /// Points on the first layer.
        #[arg(long, default_value_t = 360)]
        points: usize,
    },
}

/// Less common slicing settings.
#[derive(Debug, Clone, clap::Args)]
pub struct SliceExtras {
    /// Bound the turning angle of constant-distance layers to DEG degrees (smoothing QP).
    #[arg(long, value_name = "DEG")]
    pub smooth: Option<f64>,
    /// Distance tolerance of the smoothing, as a fraction of Delta.
    #[arg(long, default_value_t = 0.05)]
    pub smooth_tol: f64,
    /// Rotate the start of layer k by k × DEG degrees (seam staggering).
    #[arg(long, value_name = "DEG")]
    pub stagger: Option<f64>,
    /// Spiral: profile angle where the spiral starts (degrees).
    #[arg(long, value_name = "DEG")]
    pub spiral_start: Option<f64>,
    /// Spiral: travel toward decreasing profile angle.
    #[arg(long)]
    pub reverse: bool,
    /// Bead width for wall.stl (mm; default Delta).
    #[arg(long, value_name = "MM")]
    pub bead_width: Option<f64>,
    /// Do not write wall.stl.
    #[arg(long)]
    pub no_wall: bool,
    /// Stop after N layers (or spiral turns).
    #[arg(long, value_name = "N")]
    pub max_layers: Option<usize>,
}

/// `Delta` and the discretisation, shared by `slice` and `plan`; each
/// overrides the part file's `[slicing]` value.
#[derive(Debug, Clone, clap::Args)]
pub struct GridArgs {
    /// Interlayer distance Delta in mm (default: the part file's).
    #[arg(long)]
    pub delta: Option<f64>,
    /// Points per layer.
    #[arg(long, conflicts_with = "chord")]
    pub points: Option<usize>,
    /// Max chord error in mm.
    #[arg(long)]
    pub chord: Option<f64>,
    /// Refuse a run estimated at more computed points than this (default 5000000).
    #[arg(long, value_name = "N")]
    pub max_points: Option<u64>,
    /// A layer's vertex turning more than DEG degrees is a corner (default: the part file's, 10).
    #[arg(long, value_name = "DEG")]
    pub corner_threshold: Option<f64>,
    /// Keep the aligned, staggered seams on layers with corners instead of starting them at
    /// their sharpest corner.
    #[arg(long)]
    pub no_corner_seams: bool,
}

impl GridArgs {
    /// Applies the overrides given to `o`.
    pub fn apply(&self, o: &mut waam_slicer::SliceOverrides) {
        use waam_slicer::path::Discretisation;
        o.delta_mm = self.delta.or(o.delta_mm);
        if let Some(n) = self.points {
            o.discretisation = Some(Discretisation::Points(n));
        }
        if let Some(e) = self.chord {
            o.discretisation = Some(Discretisation::ChordError(e));
        }
        o.max_points = self.max_points.or(o.max_points);
        if let Some(d) = self.corner_threshold {
            o.corner_threshold_rad = Some(d.to_radians());
        }
        if self.no_corner_seams {
            o.seams_on_corners = Some(false);
        }
    }
}

/// Tool-axis and process settings shared by `slice` and `plan`; each
/// overrides the part file's `[tool_axis]` / `[process]` value.
#[derive(Debug, Clone, clap::Args)]
pub struct AxisArgs {
    /// Constant lead angle of the torch (degrees, feed plane).
    #[arg(long, value_name = "DEG", allow_negative_numbers = true)]
    pub lead: Option<f64>,
    /// Constant tilt angle of the torch (degrees, normal plane).
    #[arg(long, value_name = "DEG", allow_negative_numbers = true)]
    pub tilt: Option<f64>,
    /// The 50° rule with this angle: the torch never leans more than DEG from the part's Z.
    #[arg(long, value_name = "DEG")]
    pub max_lean: Option<f64>,
    /// Bound the turning rate of the torch axis along a layer (degrees per mm of path).
    #[arg(long, value_name = "DEG_PER_MM")]
    pub max_axis_rate: Option<f64>,
    /// Tool axis along the build direction, ignoring the part file's lead, tilt, lean rule and rate bounds.
    #[arg(long, conflicts_with_all = ["lead", "tilt", "max_lean", "max_axis_rate"])]
    pub plain_axes: bool,
    /// Process preset: cmt-steel (CMT ER70S-6), pla (thesis table 3.1) or mag-steel.
    #[arg(long, value_name = "PRESET")]
    pub process: Option<waam_slicer::process::ProcessPreset>,
    /// Travel speed (mm/s): the programmed torch speed over the part.
    #[arg(long, value_name = "MM_S")]
    pub travel_speed: Option<f64>,
}

impl AxisArgs {
    /// Applies the tool-axis and process overrides given to `o`.
    pub fn apply(&self, o: &mut waam_slicer::SliceOverrides) {
        o.tool_axis = waam_slicer::pipeline::AxisOverrides {
            plain: self.plain_axes,
            lead_rad: self.lead.map(f64::to_radians),
            tilt_rad: self.tilt.map(f64::to_radians),
            max_lean_rad: self.max_lean.map(f64::to_radians),
            max_axis_rate_rad_per_mm: self.max_axis_rate.map(f64::to_radians),
        };
        o.process = self.process.map(|p| p.parameters());
        o.travel_speed_mm_s = self.travel_speed;
    }
}

/// Arguments of `waam slice`.
#[derive(Debug, Clone, clap::Args)]
pub struct SliceArgs {
    /// The part file (TOML).
    pub part: PathBuf,
    /// Strategy (default: the part file's).
    #[arg(long, value_enum)]
    pub strategy: Option<StrategyArg>,
    /// Delta and the discretisation of each layer.
    #[command(flatten)]
    pub grid: GridArgs,
    /// Output folder (default out/<part name>).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Extra slicing settings.
    #[command(flatten)]
    pub more: SliceExtras,
    /// Tool axis and process.
    #[command(flatten)]
    pub axes: AxisArgs,
}

/// Arguments of `plan`.
#[derive(Debug, clap::Args)]
pub struct PlanArgs {
    /// The part file (TOML).
    pub part: PathBuf,
    /// The cell file (TOML, parts/cells/).
    #[arg(long)]
    pub cell: PathBuf,
    /// Delta and the discretisation of each layer.
    #[command(flatten)]
    pub grid: GridArgs,
    /// Robot program format written when the plan is feasible; default:
    /// the cell robot's vendor. Another vendor's format is refused (exit 2):
    /// the joints are in the cell robot's controller convention.
    #[arg(long, value_parser = vendor_keys())]
    pub format: Option<String>,
    /// R_Z law: fixed:DEG, poly:N (max degree), spline, point.
    #[arg(long, default_value = "poly:4")]
    pub rz: String,
    /// Torch-carried cells: the positioner's tilt and turn optimised within
    /// the cell's cone of the vertical (`optimised`), or turning the build
    /// direction exactly vertical at every point as in the thesis (`vertical`).
    #[arg(long, default_value = "optimised", value_parser = ["optimised", "vertical"])]
    pub positioner: String,
    /// Bound the turning angle of constant-distance layers to DEG degrees
    /// (smoothing QP, as `slice --smooth`).
    #[arg(long, value_name = "DEG")]
    pub smooth: Option<f64>,
    /// Distance tolerance of the smoothing, as a fraction of Delta.
    #[arg(long, default_value_t = 0.05)]
    pub smooth_tol: f64,
    /// Plan the first N layers only.
    #[arg(long, value_name = "N")]
    pub max_layers: Option<usize>,
    /// Tool axis and process.
    #[command(flatten)]
    pub axes: AxisArgs,
    /// Output folder (default out/<part name>).
    #[arg(long)]
    pub out: Option<PathBuf>,
}

/// Arguments of `check`.
#[derive(Debug, clap::Args)]
pub struct CheckArgs {
    /// The program: FANUC .ls, KUKA .src (its .dat beside it) or ABB .mod; a build cut into groups is read whole from any of them; or the folder `plan` wrote, holding one program.
    pub program: PathBuf,
    /// The cell file (TOML, parts/cells/).
    #[arg(long)]
    pub cell: PathBuf,
}

/// Arguments of `place`.
#[derive(Debug, clap::Args)]
pub struct PlaceArgs {
    /// The part file (TOML).
    pub part: PathBuf,
    /// The cell file (TOML, parts/cells/).
    #[arg(long)]
    pub cell: PathBuf,
    /// Delta and the discretisation of each layer.
    #[command(flatten)]
    pub grid: GridArgs,
    /// Tool axis and process.
    #[command(flatten)]
    pub axes: AxisArgs,
    /// Coarse candidates sampled in the placement box.
    #[arg(long, default_value_t = 64)]
    pub samples: usize,
    /// Half-width (mm) of the box searched when the cell file has no [placement] bounds.
    #[arg(long, default_value_t = 400.0)]
    pub half_box: f64,
    /// Output folder (default out/<part name>-placed).
    #[arg(long)]
    pub out: Option<PathBuf>,
}

/// Arguments of `waam fit`.
#[derive(Debug, Clone, clap::Args)]
pub struct FitArgs {
    /// The mesh (STL, binary or ASCII; in --units).
    pub mesh: PathBuf,
    /// The unit of the mesh's coordinates: mm, cm, m or in. Every length printed, written or
    /// taken (--start, --max-rms, --substrate-tolerance) is in mm.
    #[arg(long, default_value = "mm", value_parser = parse_units)]
    pub units: waam_slicer::fit::Units,
    /// Output folder.
    #[arg(long, default_value = "out/fit")]
    pub out: PathBuf,
    /// A part file whose [slicing], [tool_axis] and [process] tables the written part takes.
    #[arg(long, value_name = "PART.toml")]
    pub template: Option<PathBuf>,
    /// The start end (on the substrate): lowest, highest, capped, or a point X,Y,Z (mm) it is nearest.
    #[arg(long, default_value = "lowest", value_parser = parse_start)]
    pub start: waam_slicer::StartEnd,
    /// Refuse the mesh if its vertices are further than this from the fitted tube (RMS, mm).
    #[arg(long, value_name = "MM", default_value_t = 0.5)]
    pub max_rms: f64,
    /// Name of the written part (default: the mesh file's stem).
    #[arg(long)]
    pub name: Option<String>,
    /// An STL mesh of the substrate the start end stands on: the written part's substrate
    /// (by its absolute path) instead of the start end's plane.
    #[arg(long, value_name = "SUB.stl")]
    pub substrate: Option<PathBuf>,
    /// Refuse a start end further than this from the --substrate mesh (mm).
    #[arg(long, value_name = "MM", default_value_t = 1.0)]
    pub substrate_tolerance: f64,
    /// A mesh with features that are not tube (collars, flanges, blocks, lugs, tabs): fit its
    /// longest tubular stretch and name the features in fit.json, instead of refusing it.
    #[arg(long)]
    pub trim: bool,
    /// The guide's knot spacing (mm; default from the end radius, 4 to 12 mm). A coarse coil
    /// whose rings of vertices lie far apart fits smooth between them with knots 1.5 times
    /// the rings' distance apart (fit.json warns with the value).
    #[arg(long, value_name = "MM")]
    pub knot_spacing: Option<f64>,
    /// The stations' spacing along the guide (mm; default from the mesh's median edge).
    #[arg(long, value_name = "MM")]
    pub station_spacing: Option<f64>,
}

fn parse_units(s: &str) -> Result<waam_slicer::fit::Units, String> {
    s.parse()
}

fn parse_start(s: &str) -> Result<waam_slicer::StartEnd, String> {
    s.parse()
}

/// Arguments of `replan`.
#[derive(Debug, clap::Args)]
pub struct ReplanArgs {
    /// The part file (TOML).
    pub part: PathBuf,
    /// The cell file (TOML, parts/cells/).
    #[arg(long)]
    pub cell: PathBuf,
    /// The measured layer: a CSV of points `x,y,z` of its deposited top
    /// (part frame, mm) or of height errors `layer,point,dh_mm`.
    #[arg(long)]
    pub measured: PathBuf,
    /// The layer the scan measured (K): layers K+1.. are replanned.
    #[arg(long, value_name = "K")]
    pub after_layer: usize,
    /// Delta and the discretisation of each layer (as the build was planned).
    #[command(flatten)]
    pub grid: GridArgs,
    /// Robot program format; default: the cell robot's vendor.
    #[arg(long, value_parser = vendor_keys())]
    pub format: Option<String>,
    /// R_Z law: fixed:DEG, poly:N (max degree), spline, point.
    #[arg(long, default_value = "poly:4")]
    pub rz: String,
    /// Plan the first N layers only (as the build was planned).
    #[arg(long, value_name = "N")]
    pub max_layers: Option<usize>,
    /// Scan rows farther than MM from layer K's planned top are outliers
    /// (default max(3 Delta, 3 mm)).
    #[arg(long, value_name = "MM")]
    pub outlier_distance: Option<f64>,
    /// Output folder (default out/<part name>-replan-K).
    #[arg(long)]
    pub out: Option<PathBuf>,
}

/// The `--format` values: every registered vendor's key
/// ([`Vendor::key`](waam_slicer::robot::Vendor::key)), in the registry's order.
fn vendor_keys() -> clap::builder::PossibleValuesParser {
    clap::builder::PossibleValuesParser::new(
        waam_slicer::program::registry::VENDORS
            .iter()
            .map(|v| v.key()),
    )
}
