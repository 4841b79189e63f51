//! **Stage 7 — robot programs.** Takes a planned [`JointTrajectory`] (joints
//! per path point, rad), the path points it was computed for
//! ([`PathPointInput`]: layer structure, part-frame positions (mm), tool axes,
//! `R_Z`), the [`CellLayout`] and the travel speeds (mm/s), checks that the plan is
//! buildable, and returns a [`Program`]: one bead per layer, every point
//! carrying its arc flag, with an approach point before and a retract point
//! after each bead. Emitters turn a [`Program`] into controller files; every
//! format is read back and validated against the cell. SPEC §8, thesis
//! §3.1.2.
//!
//! | piece | module | entry points |
//! |---|---|---|
//! | the program as data, feasibility check | this module | [`build_program`], [`Program`], [`ProgramPoint`], [`ArcFlag`] |
//! | the vendor contract: options, emit, read, decode, one dispatch | [`contract`] | [`contract::Controller`], [`contract::emit`], [`contract::check_files`] |
//! | FANUC TP ASCII `.ls` (emitter, reader, decoder) | [`fanuc`] | [`fanuc::Fanuc`], [`fanuc::fanuc_files`], [`fanuc::parse_ls`], [`fanuc::validate_fanuc`] |
//! | KUKA KRL `.src` + `.dat` | [`kuka`] | [`kuka::Kuka`], [`kuka::kuka_files`], [`kuka::parse_krl`], [`kuka::validate_kuka`] |
//! | ABB RAPID `.mod` | [`abb`] | [`abb::Abb`], [`abb::abb_files`], [`abb::parse_mod`], [`abb::validate_abb`] |
//! | vendor-neutral words: move kinds, position modes | [`kinds`] | [`MoveKind`], [`PositionMode`] |
//! | cutting a build into groups within a memory budget | [`split`] | [`split::split_to_budget`], [`split::Budget`] |
//! | CSV of every point | [`csv`] | [`csv::write_csv`] |
//! | the whole cell against collisions along every motion | [`cell_check`] | [`cell_check::check_cell`] |
//! | the build's cycle time (per move, layer, build) | [`cycle`] | [`cycle::cycle_time`] |
//! | the one checker of decoded steps (file + cell) | [`validate`] | [`validate::check_steps`], [`validate::Step`] |
//! | approach and retract points | this module | [`build_program_with`], [`ProgramOptions`] |
//! | arc-off transits against the wall | [`transit`] | [`transit::joint_move_clearance`] |
//! | tool and work frames of every emitter | [`frames`] | [`frames::ToolFrames`], [`frames::held_tool`] |
//! | number formatting | [`fmt`] | [`fmt::Fixed`] |
//!
//! Each vendor's folder holds its emitter (`mod.rs`), its reader
//! (`read.rs`) and its decoder into the checker's steps (`decode.rs`), and
//! implements [`contract::Controller`]; nothing outside [`contract`]
//! chooses among vendors.
//!
//! JSON of every point: [`Program`] implements `serde::Serialize`; serialise
//! it with any serde format (the command-line tool uses `serde_json`).
//!
//! Files reach disk through [`write_files`] (atomic: temporary file, then
//! rename).

pub mod abb;
pub mod cell_check;
pub mod compress;
pub mod contract;
pub mod csv;
pub mod cycle;
pub mod fanuc;
pub mod fmt;
pub mod frames;
pub mod kinds;
pub mod kuka;
pub mod moves;
pub mod split;
pub mod transit;
pub mod validate;

pub use kinds::{MoveKind, PositionMode};

use std::path::Path;

use serde::{Deserialize, Serialize};

use crate::math::{Point3, UnitVector3, Vector3};
use crate::robot::cell::CellPoint;
use crate::robot::positioner::PositionerJoints;
use crate::robot::trajectory::{JointTrajectory, PathPointInput};
use crate::robot::{CellLayout, Configuration, Joints, Vendor};

/// Errors of the program stage; each names the point, field or file at fault.
/// `Clone` (an I/O error is shared), so that a plan can keep the program
/// stage's refusal as a value ([`PlannedPart::program`](crate::pipeline::PlannedPart::program)).
#[derive(Debug, Clone, thiserror::Error)]
#[non_exhaustive]
pub enum ProgramError {
    /// The plan has violations: no program is written for it.
    #[error(
        "refusing to write a program for an infeasible plan: {count} violation(s), first: {first}"
    )]
    Infeasible {
        /// Number of violations.
        count: usize,
        /// The first one, with its layer, point and joint.
        first: String,
        /// The layers the first one concerns (its own, and the next layer's
        /// for an arc-off move into it), so that a host (the placement
        /// search) reads them without parsing `first`.
        layers: Vec<usize>,
    },
    /// A layer of the plan is infeasible or has lost points: no program is
    /// written, so that no layer can silently vanish from it.
    #[error("refusing to write a program: layer {layer} cannot be built ({status}); {count} layer(s) in all")]
    InfeasibleLayer {
        /// The first such layer.
        layer: usize,
        /// How many layers are in that state.
        count: usize,
        /// Why it cannot be built.
        status: LayerRefusal,
    },
    /// The joint trajectory rebuilt from a plan fails (a point the plan
    /// solved no longer has a joint solution): the robot stage's error.
    #[error("joint trajectory: {source}")]
    Trajectory {
        /// The robot stage's error (names the point).
        #[source]
        source: crate::robot::RobotError,
    },
    /// Path points, trajectory and speeds do not describe the same path.
    #[error("input mismatch at index {index}: {reason}")]
    Mismatch {
        /// Index in the point list.
        index: usize,
        /// What differs.
        reason: String,
    },
    /// An option is out of its domain.
    #[error("program options: `{field}` = {value:?} is invalid ({reason})")]
    InvalidOptions {
        /// The field at fault.
        field: &'static str,
        /// The offending value.
        value: String,
        /// Why it is rejected.
        reason: &'static str,
    },
    /// One layer's bead alone does not fit the controller's memory budget:
    /// a build is cut between beads only ([`split`]), never inside one.
    #[error(
        "layer {layer} alone needs {size} {unit} in one program, more than `{field}` = {limit}: raise `{field}` if the controller holds more, or coarsen the layer (path_tolerance_mm, fewer points)"
    )]
    OverBudget {
        /// The cell-file key stating the budget, e.g. `[program.fanuc] max_positions`.
        field: &'static str,
        /// The budget, in `unit`.
        limit: usize,
        /// What is counted (`positions`, `bytes`).
        unit: &'static str,
        /// The layer whose bead does not fit.
        layer: usize,
        /// What its group alone needs, in `unit`.
        size: usize,
    },
    /// Two bodies of the cell come closer than `[program]
    /// collision_clearance_mm` along a motion ([`cell_check`]).
    #[error(
        "layer {layer}{}, {motion}: the {body_a} and the {body_b} come {} (clearance {clearance_mm} mm)",
        point.map_or(String::new(), |p| format!(", point {p}")),
        if *distance_mm < 0.0 { format!("{:.1} mm into each other", -distance_mm) } else { format!("within {distance_mm:.1} mm") }
    )]
    Collision {
        /// The layer the motion belongs to.
        layer: usize,
        /// The point (bead point, or the point a move goes to); `None` for
        /// a home move.
        point: Option<usize>,
        /// The motion: `bead`, `approach`, `retract`, `arc-off transit`,
        /// `home move`.
        motion: &'static str,
        /// One body (an arm link, `part`).
        body_a: String,
        /// The other (an arm link, the positioner's table or tilt body, a
        /// keep-out box by its name, `part`).
        body_b: String,
        /// Their distance (mm; negative: the penetration depth).
        distance_mm: f64,
        /// The clearance asked for (mm).
        clearance_mm: f64,
    },
    /// A file could not be written.
    #[error("{path}: cannot write: {source}")]
    Io {
        /// The file.
        path: String,
        /// The I/O error (shared: the error is `Clone`).
        source: std::sync::Arc<std::io::Error>,
    },
    /// The program's robot is another vendor's than the emitter's: its joints
    /// are in that vendor's controller convention and its Cartesian poses
    /// use that vendor's flange axes, meaningless on this controller.
    #[error(
        "the {emitter} emitter writes {emitter_vendor} programs, but the cell's robot `{robot}` has vendor {robot_vendor} (its joints are in the {robot_vendor} controller's convention): use the {robot_vendor} format"
    )]
    VendorMismatch {
        /// The emitter or validator, e.g. `KUKA KRL`.
        emitter: &'static str,
        /// The emitter's vendor.
        emitter_vendor: &'static str,
        /// The cell's robot (its name).
        robot: String,
        /// The robot's vendor.
        robot_vendor: &'static str,
    },
    /// A program file could not be read back.
    #[error("{file}:{line}: {reason}")]
    Read {
        /// The file (or program name).
        file: String,
        /// Line number, 1-based.
        line: usize,
        /// What is wrong.
        reason: String,
    },
}

/// Why a layer of a plan cannot be built ([`ProgramError::InfeasibleLayer`]).
#[derive(Debug, Clone, PartialEq)]
pub enum LayerRefusal {
    /// The optimiser left the layer infeasible: its status names the
    /// binding constraint (joint, point, amount).
    Infeasible(crate::optimise::LayerStatus),
    /// The plan has no entry for the layer (a host dropped it, or the
    /// optimiser returned none).
    NoPlan,
    /// The plan's entry for the layer has another number of points, or is
    /// another layer's.
    PointCount {
        /// Points in the plan's entry.
        planned: usize,
        /// Points of the path's layer.
        path: usize,
        /// The layer the plan's entry is for.
        plan_layer: usize,
    },
    /// A point of the layer has no joint solution in the plan.
    NoJointSolution {
        /// The point's index in the layer.
        point: usize,
    },
}

impl std::fmt::Display for LayerRefusal {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            LayerRefusal::Infeasible(status) => write!(f, "{status}"),
            LayerRefusal::NoPlan => write!(f, "no plan for this layer"),
            LayerRefusal::PointCount {
                planned,
                path,
                plan_layer,
            } => write!(
                f,
                "the plan has {planned} point(s) for its {path} (layer {plan_layer})"
            ),
            LayerRefusal::NoJointSolution { point } => {
                write!(f, "point {point} has no joint solution")
            }
        }
    }
}

impl ProgramError {
    /// The layers (their [`LayerPoints::layer`](crate::optimise::LayerPoints::layer)
    /// numbers) the error names, from its typed fields: the first infeasible
    /// layer, or the layers of a program check's refusal (a violation's
    /// layer, an arc-off move's two layers); empty for errors about no
    /// layer. The placement search brings them into its subsample.
    pub fn layers(&self) -> Vec<usize> {
        match self {
            ProgramError::InfeasibleLayer { layer, .. } => vec![*layer],
            ProgramError::Infeasible { layers, .. } => layers.clone(),
            ProgramError::Collision { layer, .. } => vec![*layer],
            _ => Vec::new(),
        }
    }
}

/// What a point is for: a bead point with its arc switching meaning, or a
/// transit point with the arc off (rs-opw's `PathFlags`: approach, trace,
/// retract) [SPEC §8].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ArcFlag {
    /// Clearance point before a bead: the bead's first point moved away from
    /// the part along the tool axis by [`ProgramOptions::clearance_mm`],
    /// same orientation; reached by a joint move with the arc off, then left
    /// by a linear move to the bead's first point. Not a bead point.
    Approach,
    /// First point of a bead: reached with the arc off, exact stop, the arc
    /// starts here.
    Start,
    /// Reached with the arc on (blended).
    On,
    /// Last point of a bead: reached with the arc on, exact stop, the arc
    /// stops here.
    End,
    /// Clearance point after a bead: its last point moved away from the part
    /// along the tool axis; reached by a linear move with the arc off. The
    /// arc-off transition to the next layer goes from here to the next
    /// [`ArcFlag::Approach`] by a joint move. Not a bead point.
    Retract,
}

impl ArcFlag {
    /// `true` for the points of a bead (start, on, end), `false` for the
    /// approach and retract points.
    pub fn is_bead(&self) -> bool {
        matches!(self, ArcFlag::Start | ArcFlag::On | ArcFlag::End)
    }
}

/// One point of a program.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct ProgramPoint {
    /// Layer index (= bead index of this layer).
    pub layer: usize,
    /// Point index within the layer (approach and retract points: the index
    /// of the bead point they are offset from).
    pub point: usize,
    /// Deposition point, part frame (mm); for approach and retract points
    /// the torch tip, `clearance` away from the part along the tool axis.
    pub position_mm: Point3,
    /// Tool axis, part frame (unit).
    pub tool_axis: UnitVector3,
    /// Free angle about the tool axis `R_Z` (rad).
    pub r_z: f64,
    /// Robot joints, controller convention (rad).
    pub joints: Joints,
    /// Positioner joints `[q7, q8]` (rad), torch-carried cell only.
    pub positioner: Option<PositionerJoints>,
    /// Travel speed of the deposition point relative to the part on the way
    /// to this point (mm/s); on a bead's first point, the travel speed of
    /// its first segment; on approach and retract points the linear speed
    /// of the moves into and out of the bead (approach point → first point,
    /// last point → retract point), [`ProgramOptions::approach_speed_mm_s`].
    pub speed_mm_s: f64,
    /// Arc flag.
    pub arc: ArcFlag,
    /// This bead point is the via (circle) point of a circular move (FANUC
    /// `C`, KUKA `CIRC`, ABB `ArcC`/`MoveC`): the controller passes through
    /// its position on the circle from the previous point to the next one,
    /// which the move ends at and whose speed it carries
    /// ([`moves::thin_beads`]). Always an [`ArcFlag::On`] point between two
    /// bead points; `false` for every point of an unthinned program.
    #[serde(skip_serializing_if = "std::ops::Not::not")]
    pub via: bool,
}

/// A buildable program: points in path order, one bead per layer.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Program {
    /// Program name (controller-safe: letters, digits, `_`, starting with a letter).
    pub name: String,
    /// The cell the program is for.
    pub cell: CellLayout,
    /// The IK branch of every point.
    pub configuration: Configuration,
    /// The points.
    pub points: Vec<ProgramPoint>,
    /// Home position: the first and last motion (`None`: no home moves).
    pub home: Option<HomePosition>,
    /// What happens before each bead, one per bead in order (empty: nothing).
    pub bead_setup: Vec<BeadSetup>,
    /// The planned deposition points of every bead in order (part frame,
    /// mm), before the beads were thinned into moves
    /// ([`moves::thin_beads`]): what a checker compares the moves with.
    pub planned: Vec<Point3>,
}

impl Program {
    /// Checks that every number an emitter writes is finite (positions,
    /// tool axes, `R_Z`, joints, positioner joints, speeds > 0): a
    /// hand-built program must not put `NaN` or `inf` into a controller file.
    ///
    /// # Errors
    /// [`ProgramError::Mismatch`] naming the first bad point and field.
    pub fn check_finite(&self) -> Result<(), ProgramError> {
        for (index, p) in self.points.iter().enumerate() {
            let bad = |field: &str| ProgramError::Mismatch {
                index,
                reason: format!(
                    "layer {}, point {}: `{field}` is not finite",
                    p.layer, p.point
                ),
            };
            if !p.position_mm.iter().all(|v| v.is_finite()) {
                return Err(bad("position_mm"));
            }
            if !p.tool_axis.iter().all(|v| v.is_finite()) {
                return Err(bad("tool_axis"));
            }
            if !p.r_z.is_finite() {
                return Err(bad("r_z"));
            }
            if !p.joints.iter().all(|v| v.is_finite()) {
                return Err(bad("joints"));
            }
            if p.positioner
                .is_some_and(|q| !q.iter().all(|v| v.is_finite()))
            {
                return Err(bad("positioner"));
            }
            if !(p.speed_mm_s.is_finite() && p.speed_mm_s > 0.0) {
                return Err(bad("speed_mm_s (must be finite and > 0)"));
            }
        }
        Ok(())
    }

    /// The bead points (approach and retract points left out), in order.
    pub fn bead_points(&self) -> impl Iterator<Item = &ProgramPoint> {
        self.points.iter().filter(|p| p.arc.is_bead())
    }

    /// Sets the payload updates of a part-carried program (the robot
    /// carries the part as it grows): before bead 0 and before every
    /// `opts.payload_every_layers`-th bead, the substrate and fixture
    /// (`payload_base_kg` at `payload_base_cog_mm`, flange frame) plus the
    /// metal of the beads before it, bead `k` weighing `bead_mass_kg[k]`
    /// (kg) with its centre at the mean of its points (part frame, taken into
    /// the flange frame by the cell's `flange_from_part`). Nothing in a
    /// torch-carried cell (the positioner carries the part, not the arm) or
    /// with `payload_every_layers = 0`.
    ///
    /// # Errors
    /// [`ProgramError::Mismatch`] when `bead_mass_kg` has not one mass per
    /// bead or a mass is negative or not finite; [`ProgramError::InvalidOptions`]
    /// for bad options.
    pub fn set_payloads(
        &mut self,
        opts: &ProgramOptions,
        bead_mass_kg: &[f64],
    ) -> Result<(), ProgramError> {
        opts.validate()?;
        let beads = self.num_beads();
        if bead_mass_kg.len() != beads {
            return Err(ProgramError::Mismatch {
                index: bead_mass_kg.len().min(beads),
                reason: format!("{} bead masses for {beads} beads", bead_mass_kg.len()),
            });
        }
        if let Some(k) = bead_mass_kg
            .iter()
            .position(|m| !(m.is_finite() && *m >= 0.0))
        {
            return Err(ProgramError::Mismatch {
                index: k,
                reason: format!(
                    "bead {k}: mass {} kg is not finite and >= 0",
                    bead_mass_kg[k]
                ),
            });
        }
        let CellLayout::PartCarried(c) = &self.cell else {
            return Ok(());
        };
        if opts.payload_every_layers == 0 {
            return Ok(());
        }
        if self.bead_setup.len() != beads {
            self.bead_setup = self
                .points
                .iter()
                .filter(|p| p.arc == ArcFlag::Start)
                .map(|p| BeadSetup {
                    layer: p.layer,
                    payload: None,
                    dwell_s: 0.0,
                    wait_input: None,
                })
                .collect();
        }
        // the centre of each bead, flange frame
        let mut centres = Vec::with_capacity(beads);
        let (mut sum, mut n) = (Vector3::zeros(), 0usize);
        for p in self.bead_points() {
            sum += p.position_mm.coords;
            n += 1;
            if p.arc == ArcFlag::End {
                centres.push(c.flange_from_part * Point3::from(sum / n as f64));
                (sum, n) = (Vector3::zeros(), 0);
            }
        }
        let mut mass = opts.payload_base_kg;
        let mut moment = Vector3::from(opts.payload_base_cog_mm) * opts.payload_base_kg;
        let every = opts.payload_every_layers as usize;
        for (k, setup) in self.bead_setup.iter_mut().enumerate() {
            if k % every == 0 {
                let cog_mm = if mass > 0.0 {
                    Point3::from(moment / mass)
                } else {
                    Point3::from(opts.payload_base_cog_mm)
                };
                setup.payload = Some(Payload {
                    mass_kg: mass,
                    cog_mm,
                });
            }
            mass += bead_mass_kg[k];
            if let Some(centre) = centres.get(k) {
                moment += centre.coords * bead_mass_kg[k];
            }
        }
        Ok(())
    }

    /// Number of beads (arc starts).
    pub fn num_beads(&self) -> usize {
        self.points
            .iter()
            .filter(|p| p.arc == ArcFlag::Start)
            .count()
    }
}

/// Travel speeds of a program (mm/s).
#[derive(Debug, Clone, PartialEq)]
pub enum TravelSpeed {
    /// The same speed everywhere (mm/s).
    Constant(f64),
    /// One speed per point, the speed on the way to it (modulated travel
    /// speed, SPEC §5) (mm/s).
    PerPoint(Vec<f64>),
}

/// Checks that the plan is buildable and assembles the program.
///
/// `points` and `trajectory` must be the same path in the same order (the
/// trajectory computed for these points by
/// [`joint_trajectory`](crate::robot::trajectory::joint_trajectory) or an
/// optimiser); each layer becomes one bead of at least two points. Joint
/// speeds are re-checked at the given travel speeds.
///
/// # Errors
/// [`ProgramError::InvalidOptions`] for a bad name or speed,
/// [`ProgramError::Mismatch`] when the inputs differ in length, layer or
/// point indices, or a layer has one point, and [`ProgramError::Infeasible`]
/// when the trajectory reports violations or a point has no joints, naming
/// the first.
pub fn build_program(
    name: &str,
    cell: &CellLayout,
    points: &[PathPointInput],
    trajectory: &JointTrajectory,
    speed: &TravelSpeed,
) -> Result<Program, ProgramError> {
    build_program_with(
        name,
        cell,
        points,
        trajectory,
        speed,
        &ProgramOptions::default(),
    )
}

/// Options of [`build_program_with`], and the vendor-independent keys of a
/// cell file's `[program]` table (see [`ProgramSettings`]). Plain data.
///
/// Every program is built the same way whatever the controller: an optional
/// home move first and last, one bead per layer between an approach and a
/// retract point, and before each bead the set-up of its [`BeadSetup`]
/// (payload update, interlayer dwell, interpass wait). The emitters write
/// them in each controller's instructions; the validators read them back and
/// check them against these options (the `common` field of each vendor's
/// options).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ProgramOptions {
    /// Distance of the approach and retract points from the part along the
    /// tool axis (mm, ≥ 0; 0: no approach or retract points, each bead is
    /// reached by a joint move to its first point). Default 20 mm; where a
    /// point at that distance leaves a joint's travel, a half, a quarter or
    /// an eighth of it is used.
    pub clearance_mm: f64,
    /// Linear speed of the moves into and out of a bead (approach point →
    /// first point, last point → retract point), relative to the part
    /// (mm/s, > 0). Default 20 mm/s.
    pub approach_speed_mm_s: f64,
    /// Home position of the arm, joints in the controller's convention
    /// (deg): the program's first and last motion, a joint move with the arc
    /// off. `None` (default): no home moves (the program starts with the
    /// first bead's approach; the cell file should say where home is).
    pub home_deg: Option<[f64; 6]>,
    /// Positioner joints `[q7, q8]` at home (deg), torch-carried cells;
    /// `None`: `[0, 0]`.
    pub home_positioner_deg: Option<[f64; 2]>,
    /// Interlayer dwell (s, ≥ 0): before each bead after the first, the
    /// program waits this long with the arc off at the previous bead's
    /// retract point, so that the wall cools. Default 0.
    pub dwell_s: f64,
    /// Interpass wait: before each bead after the first, the program waits
    /// for this digital input to be on (the interpass temperature is
    /// reached): FANUC `DI[n]`, KUKA `$IN[n]`, ABB the signal of
    /// [`abb::AbbOptions`]. `None` (default): no wait.
    pub interpass_input: Option<u32>,
    /// Payload update every this many layers in the part-carried cell (the
    /// robot carries the part as it grows; 0: never). Before bead 0 and
    /// before every `N`-th bead the program sets the payload to the
    /// substrate and fixture ([`ProgramOptions::payload_base_kg`]) plus the
    /// metal deposited so far. Default 0.
    pub payload_every_layers: u32,
    /// Mass carried on the flange before the first layer: substrate and
    /// fixture (kg, ≥ 0). Default 0.
    pub payload_base_kg: f64,
    /// Centre of gravity of that mass, flange frame (mm). Default origin.
    pub payload_base_cog_mm: [f64; 3],
    /// Check every arc-off joint move (retract → next approach, home moves)
    /// against the wall deposited so far with the torch's collision model
    /// ([`crate::toolaxis::collision`]), and where one collides move the
    /// retract and approach points of that transition further along the tool
    /// axis, up to [`ProgramOptions::transit_max_clearance_mm`]. Default on.
    pub transit_check: bool,
    /// Largest retract and approach distance a transit may use (mm, ≥
    /// `clearance_mm`). Default 160 mm.
    pub transit_max_clearance_mm: f64,
    /// Radius of the deposited beads in the transit check (mm, > 0): the
    /// wall is the bead points as capsules of this radius. Default 2 mm.
    pub bead_radius_mm: f64,
    /// Positioner motion coordinated with the arm in torch-carried cells
    /// (FANUC `COORD`, KUKA math-coupled base, ABB `ufmec` work object).
    /// Default on.
    pub coordinated: bool,
    /// FANUC remote TCP (`RTCP`) in the part-carried cell: linear moves are
    /// about the fixed torch (joint positions only; a paid option that
    /// cannot be loaded with Coordinated Motion, whose Cartesian `RX…RR`
    /// positions are not publicly specified). Default off.
    pub remote_tcp: bool,
    /// Largest distance between the controller's interpolated path and the
    /// planned points, over the part (mm): each bead is written with the
    /// fewest linear moves within it ([`moves::thin_beads`]). 0: every
    /// planned point is a move. Default 0.05 mm.
    pub path_tolerance_mm: f64,
    /// Largest angle between the interpolated and the planned torch axis
    /// (deg, > 0) when beads are thinned. Default 0.5°.
    pub orientation_tolerance_deg: f64,
    /// Thinned beads may use circular moves (FANUC `C`, KUKA `CIRC`, ABB
    /// `ArcC`) where a stretch is a circle arc within the tolerances and
    /// that takes fewer positions than linear moves (a circular move writes
    /// two: its via and its end). Default on.
    pub circular_moves: bool,
    /// Smallest distance two bodies of the cell may come to along any
    /// motion (mm, ≥ 0; [`cell_check`]): arm links, positioner, keep-out
    /// boxes, the part. Default 10 mm.
    pub collision_clearance_mm: f64,
}

impl Default for ProgramOptions {
    fn default() -> Self {
        Self {
            clearance_mm: 20.0,
            approach_speed_mm_s: 20.0,
            home_deg: None,
            home_positioner_deg: None,
            dwell_s: 0.0,
            interpass_input: None,
            payload_every_layers: 0,
            payload_base_kg: 0.0,
            payload_base_cog_mm: [0.0; 3],
            transit_check: true,
            transit_max_clearance_mm: 160.0,
            bead_radius_mm: 2.0,
            coordinated: true,
            remote_tcp: false,
            path_tolerance_mm: 0.05,
            orientation_tolerance_deg: 0.5,
            circular_moves: true,
            collision_clearance_mm: cell_check::DEFAULT_CLEARANCE_MM,
        }
    }
}

impl ProgramOptions {
    /// Checks every field.
    ///
    /// # Errors
    /// [`ProgramError::InvalidOptions`] naming the field.
    pub fn validate(&self) -> Result<(), ProgramError> {
        let bad = |field: &'static str, value: String, reason: &'static str| {
            Err(ProgramError::InvalidOptions {
                field,
                value,
                reason,
            })
        };
        if !(self.clearance_mm.is_finite() && self.clearance_mm >= 0.0) {
            return bad(
                "clearance_mm",
                self.clearance_mm.to_string(),
                "must be finite and >= 0",
            );
        }
        if !(self.path_tolerance_mm.is_finite() && self.path_tolerance_mm >= 0.0) {
            return bad(
                "path_tolerance_mm",
                self.path_tolerance_mm.to_string(),
                "must be finite and >= 0 (0: every planned point is a move)",
            );
        }
        if !(self.orientation_tolerance_deg.is_finite() && self.orientation_tolerance_deg > 0.0) {
            return bad(
                "orientation_tolerance_deg",
                self.orientation_tolerance_deg.to_string(),
                "must be finite and > 0",
            );
        }
        if !(self.approach_speed_mm_s.is_finite() && self.approach_speed_mm_s > 0.0) {
            return bad(
                "approach_speed_mm_s",
                self.approach_speed_mm_s.to_string(),
                "must be finite and > 0",
            );
        }
        if let Some(h) = self.home_deg {
            if !h.iter().all(|v| v.is_finite()) {
                return bad("home_deg", format!("{h:?}"), "must be finite");
            }
        }
        if let Some(h) = self.home_positioner_deg {
            if !h.iter().all(|v| v.is_finite()) {
                return bad("home_positioner_deg", format!("{h:?}"), "must be finite");
            }
        }
        if !(self.dwell_s.is_finite() && (0.0..=86_400.0).contains(&self.dwell_s)) {
            return bad(
                "dwell_s",
                self.dwell_s.to_string(),
                "must be between 0 and 86400 s",
            );
        }
        if self.interpass_input == Some(0) {
            return bad("interpass_input", "0".into(), "must be >= 1");
        }
        if !(self.payload_base_kg.is_finite() && self.payload_base_kg >= 0.0) {
            return bad(
                "payload_base_kg",
                self.payload_base_kg.to_string(),
                "must be finite and >= 0",
            );
        }
        if !self.payload_base_cog_mm.iter().all(|v| v.is_finite()) {
            return bad(
                "payload_base_cog_mm",
                format!("{:?}", self.payload_base_cog_mm),
                "must be finite",
            );
        }
        if !(self.transit_max_clearance_mm.is_finite()
            && self.transit_max_clearance_mm >= self.clearance_mm)
        {
            return bad(
                "transit_max_clearance_mm",
                self.transit_max_clearance_mm.to_string(),
                "must be finite and >= clearance_mm",
            );
        }
        if !(self.collision_clearance_mm.is_finite() && self.collision_clearance_mm >= 0.0) {
            return bad(
                "collision_clearance_mm",
                self.collision_clearance_mm.to_string(),
                "must be finite and >= 0",
            );
        }
        if !(self.bead_radius_mm.is_finite() && self.bead_radius_mm > 0.0) {
            return bad(
                "bead_radius_mm",
                self.bead_radius_mm.to_string(),
                "must be finite and > 0",
            );
        }
        Ok(())
    }

    /// The home position in controller units inside (rad), if any.
    pub fn home(&self, cell: &CellLayout) -> Option<HomePosition> {
        let h = self.home_deg?;
        Some(HomePosition {
            joints: h.map(f64::to_radians),
            positioner: matches!(cell, CellLayout::TorchCarried(_)).then(|| {
                self.home_positioner_deg
                    .unwrap_or([0.0; 2])
                    .map(f64::to_radians)
            }),
        })
    }
}

/// The arm's (and positioner's) home position: the first and last motion of
/// a program, a joint move with the arc off.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct HomePosition {
    /// Robot joints, controller convention (rad).
    pub joints: Joints,
    /// Positioner joints `[q7, q8]` (rad), torch-carried cell only.
    pub positioner: Option<PositionerJoints>,
}

/// The payload carried on the flange (part-carried cell): substrate,
/// fixture and the metal deposited so far.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Payload {
    /// Mass (kg).
    pub mass_kg: f64,
    /// Centre of gravity, flange frame (mm).
    pub cog_mm: Point3,
}

/// What a program does before a bead, from [`ProgramOptions`]: written
/// before the bead's approach move, in this order: payload, dwell, wait.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct BeadSetup {
    /// Layer of the bead.
    pub layer: usize,
    /// New payload before this bead (`None`: unchanged).
    pub payload: Option<Payload>,
    /// Dwell before this bead (s; 0: none). Always 0 on the first bead.
    pub dwell_s: f64,
    /// Digital input to wait for before this bead (`None`: no wait; always
    /// `None` on the first bead).
    pub wait_input: Option<u32>,
}

/// A cell file's `[program]` table: the vendor-independent
/// [`ProgramOptions`] and each vendor's emitter options
/// (`[program.fanuc]`, `[program.kuka]`, `[program.abb]`), whose `common`
/// field is set from the former by [`ProgramSettings::fanuc`] and its
/// siblings.
#[derive(Debug, Clone, PartialEq, Default, Serialize)]
pub struct ProgramSettings {
    /// The vendor-independent options.
    pub common: ProgramOptions,
    /// `[program.fanuc]`.
    pub fanuc: fanuc::FanucOptions,
    /// `[program.kuka]`.
    pub kuka: kuka::KukaOptions,
    /// `[program.abb]`.
    pub abb: abb::AbbOptions,
}

impl ProgramSettings {
    /// The FANUC emitter's options, `common` set.
    pub fn fanuc(&self) -> fanuc::FanucOptions {
        fanuc::FanucOptions {
            common: self.common,
            ..self.fanuc.clone()
        }
    }

    /// The KUKA emitter's options, `common` set.
    pub fn kuka(&self) -> kuka::KukaOptions {
        kuka::KukaOptions {
            common: self.common,
            ..self.kuka.clone()
        }
    }

    /// The ABB emitter's options, `common` set.
    pub fn abb(&self) -> abb::AbbOptions {
        abb::AbbOptions {
            common: self.common,
            ..self.abb.clone()
        }
    }
}

/// [`build_program`] with approach and retract points as `opts` say: before
/// each bead an [`ArcFlag::Approach`] point `clearance_mm` away from the part
/// along the tool axis (same orientation, same positioner joints), after it
/// an [`ArcFlag::Retract`] point, both checked like the bead points (joint
/// limits, and joint speeds of the linear moves into and out of the bead at
/// `approach_speed_mm_s`).
///
/// # Errors
/// As [`build_program`]; [`ProgramError::InvalidOptions`] for bad options;
/// [`ProgramError::Infeasible`] when an approach or retract point cannot be
/// reached, naming the layer.
pub fn build_program_with(
    name: &str,
    cell: &CellLayout,
    points: &[PathPointInput],
    trajectory: &JointTrajectory,
    speed: &TravelSpeed,
    opts: &ProgramOptions,
) -> Result<Program, ProgramError> {
    opts.validate()?;
    check_name(name)?;
    if points.len() != trajectory.points.len() {
        return Err(ProgramError::Mismatch {
            index: points.len().min(trajectory.points.len()),
            reason: format!(
                "{} path points but {} trajectory points",
                points.len(),
                trajectory.points.len()
            ),
        });
    }
    if points.is_empty() {
        return Err(ProgramError::Mismatch {
            index: 0,
            reason: "empty path".into(),
        });
    }
    let speeds: Vec<f64> = match speed {
        TravelSpeed::Constant(v) => vec![*v; points.len()],
        TravelSpeed::PerPoint(v) => {
            if v.len() != points.len() {
                return Err(ProgramError::Mismatch {
                    index: v.len().min(points.len()),
                    reason: format!("{} speeds for {} points", v.len(), points.len()),
                });
            }
            v.clone()
        }
    };
    for (i, v) in speeds.iter().enumerate() {
        if !(v.is_finite() && *v > 0.0) {
            return Err(ProgramError::InvalidOptions {
                field: "travel_speed_mm_s",
                value: format!("{v} (index {i})"),
                reason: "must be finite and > 0",
            });
        }
    }
    if let Some(v) = trajectory.report.violations.first() {
        return Err(ProgramError::Infeasible {
            count: trajectory.report.violations.len(),
            first: v.to_string(),
            layers: vec![v.layer],
        });
    }
    let robot = cell.robot();
    let mut out: Vec<ProgramPoint> = Vec::with_capacity(points.len());
    for (i, (p, jp)) in points.iter().zip(&trajectory.points).enumerate() {
        if p.layer != jp.layer || p.point != jp.point {
            return Err(ProgramError::Mismatch {
                index: i,
                reason: format!(
                    "path point is layer {}, point {} but trajectory point is layer {}, point {}",
                    p.layer, p.point, jp.layer, jp.point
                ),
            });
        }
        let Some(q) = jp.joints else {
            return Err(ProgramError::Infeasible {
                count: 1,
                first: format!("layer {}, point {}: no joint solution", p.layer, p.point),
                layers: vec![p.layer],
            });
        };
        let first = i == 0 || points[i - 1].layer != p.layer;
        let last = i + 1 == points.len() || points[i + 1].layer != p.layer;
        if first && last {
            return Err(ProgramError::Mismatch {
                index: i,
                reason: format!("layer {} has a single point: no bead", p.layer),
            });
        }
        // speed re-check at the programmed speed (the trajectory used one TS)
        if !first {
            let prev = &out[i - 1];
            let d = (p.position_mm - prev.position_mm).norm();
            let turns = || {
                joints_move(&q, &prev.joints)
                    || match (jp.positioner, prev.positioner) {
                        (Some(a), Some(b)) => joints_move(&a, &b),
                        _ => false,
                    }
            };
            if d == 0.0 && turns() {
                return Err(ProgramError::Infeasible {
                    count: 1,
                    first: format!(
                        "layer {}, point {}: same position as point {} while the joints turn: \
                         a zero-length segment has no travel time at any speed",
                        p.layer,
                        p.point,
                        points[i - 1].point
                    ),
                    layers: vec![p.layer],
                });
            }
            if d > 0.0 {
                let dt = d / speeds[i];
                for (j, (qj, pj)) in q.iter().zip(prev.joints).enumerate() {
                    let s = (qj - pj).abs() / dt;
                    if s > robot.max_speed_rad_s[j] {
                        return Err(ProgramError::Infeasible {
                            count: 1,
                            first: format!(
                                "layer {}, point {}: J{} needs {:.2}°/s at {} mm/s, maximum {:.1}°/s",
                                p.layer,
                                p.point,
                                j + 1,
                                s.to_degrees(),
                                speeds[i],
                                robot.max_speed_rad_s[j].to_degrees()
                            ),
                            layers: vec![p.layer],
                        });
                    }
                }
            }
        }
        out.push(ProgramPoint {
            layer: p.layer,
            point: p.point,
            position_mm: p.position_mm,
            tool_axis: p.tool_axis,
            r_z: p.r_z,
            joints: q,
            positioner: jp.positioner,
            speed_mm_s: if first && !last {
                speeds[i + 1]
            } else {
                speeds[i]
            },
            arc: if first {
                ArcFlag::Start
            } else if last {
                ArcFlag::End
            } else {
                ArcFlag::On
            },
            via: false,
        });
    }
    if opts.clearance_mm > 0.0 {
        let mut all = Vec::with_capacity(out.len() + 2 * trajectory.points.len().min(out.len()));
        for (p, input) in out.iter().zip(points) {
            if p.arc == ArcFlag::Start {
                all.push(clearance_point_within_travel(
                    cell,
                    p,
                    input,
                    ArcFlag::Approach,
                    opts,
                )?);
            }
            all.push(*p);
            if p.arc == ArcFlag::End {
                all.push(clearance_point_within_travel(
                    cell,
                    p,
                    input,
                    ArcFlag::Retract,
                    opts,
                )?);
            }
        }
        out = all;
    }
    let home = opts.home(cell);
    if let Some(h) = &home {
        check_home(cell, h)?;
    }
    unwind_turns(cell, &mut out, home.as_ref())?;
    let bead_setup = out
        .iter()
        .filter(|p| p.arc == ArcFlag::Start)
        .enumerate()
        .map(|(k, p)| BeadSetup {
            layer: p.layer,
            payload: None,
            dwell_s: if k > 0 { opts.dwell_s } else { 0.0 },
            wait_input: if k > 0 { opts.interpass_input } else { None },
        })
        .collect();
    let mut program = Program {
        name: name.to_string(),
        cell: cell.clone(),
        configuration: trajectory.configuration,
        points: out,
        home,
        bead_setup,
        planned: Vec::new(),
    };
    if opts.transit_check {
        safe_transits(&mut program, points, opts)?;
    }
    program.planned = program.bead_points().map(|p| p.position_mm).collect();
    moves::thin_beads(&mut program, opts)?;
    Ok(program)
}

/// Shifts the positioner's turn of each bead's block of points (approach,
/// bead, retract) by whole turns into the turn's stroke
/// ([`Positioner::turn_stroke`](crate::robot::positioner::Positioner::turn_stroke)),
/// choosing, of the shifts that fit, the one that starts the block nearest
/// where the table is (the previous block's last point, or home): the
/// table unwinds during the arc-off joint move between beads, never during
/// a bead. The turn is periodic, so the arm's joints and the deposition
/// point are unchanged. Nothing to do without a positioner.
///
/// # Errors
/// [`ProgramError::Infeasible`] naming the layer whose bead turns the
/// table through more than the stroke holds.
fn unwind_turns(
    cell: &CellLayout,
    points: &mut [ProgramPoint],
    home: Option<&HomePosition>,
) -> Result<(), ProgramError> {
    use std::f64::consts::TAU;
    let CellLayout::TorchCarried(c) = cell else {
        return Ok(());
    };
    let stroke = contract::turn_stroke(cell).unwrap_or(c.positioner.limits[1]);
    let mut at = home.and_then(|h| h.positioner).map_or(0.0, |q| q[1]);
    for b in blocks(points) {
        let turns: Vec<f64> = points[b.first..=b.last]
            .iter()
            .filter_map(|p| p.positioner.map(|q| q[1]))
            .collect();
        let Some(&start) = turns.first() else {
            continue;
        };
        let lo = turns.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = turns.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        let Some((k_min, k_max)) = stroke.whole_turn_shifts(lo, hi) else {
            return Err(ProgramError::Infeasible {
                count: 1,
                first: format!(
                    "layer {}: the bead turns the positioner's table from {:.1}° to {:.1}° ({:.1}°), more than its stroke [{:.1}°, {:.1}°] holds",
                    points[b.start].layer,
                    lo.to_degrees(),
                    hi.to_degrees(),
                    (hi - lo).to_degrees(),
                    stroke.lower_rad.to_degrees(),
                    stroke.upper_rad.to_degrees()
                ),
                layers: vec![points[b.start].layer],
            });
        };
        let k = ((at - start) / TAU).round().clamp(k_min, k_max);
        for p in &mut points[b.first..=b.last] {
            if let Some(q) = &mut p.positioner {
                q[1] += k * TAU;
            }
        }
        at = points[b.last].positioner.map_or(at, |q| q[1]);
    }
    Ok(())
}

/// Refuses a home position outside the arm's (or positioner's) travel.
fn check_home(cell: &CellLayout, h: &HomePosition) -> Result<(), ProgramError> {
    let bad = |what: String| ProgramError::InvalidOptions {
        field: "home_deg",
        value: what,
        reason: "the home position must be inside the joints' travel",
    };
    if let Some((j, v)) = cell.robot().limit_violations(&h.joints).next() {
        return Err(bad(format!("J{} = {:.3}°", j + 1, v.to_degrees())));
    }
    if let (CellLayout::TorchCarried(c), Some(qp)) = (cell, h.positioner) {
        let turn = contract::turn_stroke(cell).unwrap_or(c.positioner.limits[1]);
        let stroke = [c.positioner.limits[0], turn];
        for (i, (l, v)) in stroke.iter().zip(qp).enumerate() {
            if !l.contains(v) {
                return Err(ProgramError::InvalidOptions {
                    field: "home_positioner_deg",
                    value: format!("J{} = {:.3}°", i + 7, v.to_degrees()),
                    reason: "the home position must be inside the positioner's travel",
                });
            }
        }
    }
    Ok(())
}

/// The points of one bead's block in a program: indices of its first point
/// (approach, or the bead's first point), its bead's first and last points,
/// its last point (retract, or the bead's last point), and of the bead's
/// first point among the path points.
#[derive(Debug, Clone, Copy)]
struct Block {
    first: usize,
    start: usize,
    end: usize,
    last: usize,
    start_input: usize,
}

fn blocks(points: &[ProgramPoint]) -> Vec<Block> {
    let arcs: Vec<ArcFlag> = points.iter().map(|p| p.arc).collect();
    let mut bead_points = 0;
    split::beads(&arcs)
        .into_iter()
        .map(|r| {
            let find = |flag| r.clone().find(|&i| arcs[i] == flag).unwrap_or(r.start);
            let block = Block {
                first: r.start,
                start: find(ArcFlag::Start),
                end: find(ArcFlag::End),
                last: r.end - 1,
                start_input: bead_points,
            };
            bead_points += arcs[r].iter().filter(|a| a.is_bead()).count();
            block
        })
        .collect()
}

/// Checks every arc-off joint move between two beads (and the last one, to
/// home) against the wall deposited so far ([`transit`]); where one
/// collides, moves that transition's retract and approach points further
/// along the tool axis (2, 4, 8… times `clearance_mm`, up to
/// `transit_max_clearance_mm`) until it clears.
fn safe_transits(
    program: &mut Program,
    inputs: &[PathPointInput],
    opts: &ProgramOptions,
) -> Result<(), ProgramError> {
    use rayon::prelude::*;
    let torch = crate::toolaxis::collision::Torch::new(&Default::default()).map_err(|e| {
        ProgramError::InvalidOptions {
            field: "transit_check",
            value: e.to_string(),
            reason: "the torch model for the transit check is invalid",
        }
    })?;
    let blocks = blocks(&program.points);
    // Each bead decimated once; the wall after bead k is the union of at
    // most log2(k + 1) + 1 blocks of them, each block's tree built once.
    let mut decimated = transit::WallBeads::default();
    for b in &blocks {
        let bead: Vec<Point3> = program.points[b.start..=b.end]
            .iter()
            .map(|p| p.position_mm)
            .collect();
        decimated.push(&bead);
    }
    let n = blocks.len();
    let target = |program: &Program, k: usize| -> Option<(Joints, Option<PositionerJoints>)> {
        if k + 1 < n {
            let p = &program.points[blocks[k + 1].first];
            Some((p.joints, p.positioner))
        } else {
            program.home.map(|h| (h.joints, h.positioner))
        }
    };
    let check = |program: &Program, k: usize| -> Result<transit::TransitClearance, ProgramError> {
        let inf = transit::TransitClearance {
            min_clearance_mm: f64::INFINITY,
            at_fraction: 0.0,
            tip_mm: Point3::origin(),
        };
        let Some((qb, pb)) = target(program, k) else {
            return Ok(inf);
        };
        let wall = decimated.wall(k + 1, opts.bead_radius_mm);
        let from = &program.points[blocks[k].last];
        transit::joint_move_clearance(
            &program.cell,
            &wall,
            &torch,
            (&from.joints, from.positioner),
            (&qb, pb),
        )
        .map_err(|e| ProgramError::Infeasible {
            count: 1,
            first: format!("layer {}: transit check: {e}", from.layer),
            layers: vec![from.layer],
        })
    };
    let first: Vec<Result<transit::TransitClearance, ProgramError>> =
        (0..n).into_par_iter().map(|k| check(program, k)).collect();
    for (k, r) in first.into_iter().enumerate() {
        let r = r?;
        if r.min_clearance_mm > 0.0 {
            continue;
        }
        let layer = program.points[blocks[k].end].layer;
        let next_layer = (k + 1 < n).then(|| program.points[blocks[k + 1].start].layer);
        let to_what = match next_layer {
            Some(l) => format!("layer {l}'s approach"),
            None => "home".to_string(),
        };
        let layers: Vec<usize> = std::iter::once(layer)
            .chain(next_layer.filter(|&l| l != layer))
            .collect();
        let refuse = |why: String| ProgramError::Infeasible {
            count: 1,
            first: format!(
                "layer {layer}: the arc-off joint move to {to_what} passes {:.1} mm into the \
                 deposited wall at {:.0}% of the move (torch tip at [{:.1}, {:.1}, {:.1}] mm, \
                 part frame){why}",
                -r.min_clearance_mm,
                100.0 * r.at_fraction,
                r.tip_mm.x,
                r.tip_mm.y,
                r.tip_mm.z
            ),
            layers: layers.clone(),
        };
        let has_retract = program.points[blocks[k].last].arc == ArcFlag::Retract;
        let next_approach = (k + 1 < n)
            .then(|| blocks[k + 1])
            .filter(|b| program.points[b.first].arc == ArcFlag::Approach);
        if opts.clearance_mm <= 0.0 || !has_retract {
            return Err(refuse(
                " and the program has no retract points to raise (clearance_mm = 0)".into(),
            ));
        }
        let mut c = opts.clearance_mm;
        let mut fixed = false;
        while c < opts.transit_max_clearance_mm && !fixed {
            c = (2.0 * c).min(opts.transit_max_clearance_mm);
            let end = program.points[blocks[k].end];
            let end_input = &inputs[blocks[k].start_input + (blocks[k].end - blocks[k].start)];
            let Ok(retract) =
                clearance_point(&program.cell, &end, end_input, ArcFlag::Retract, opts, c)
            else {
                continue;
            };
            let approach = match next_approach {
                Some(b) => {
                    let start = program.points[b.start];
                    match clearance_point(
                        &program.cell,
                        &start,
                        &inputs[b.start_input],
                        ArcFlag::Approach,
                        opts,
                        c,
                    ) {
                        Ok(a) => Some((b.first, a)),
                        Err(_) => continue,
                    }
                }
                None => None,
            };
            let old_retract = program.points[blocks[k].last];
            let old_approach = approach.map(|(i, _)| program.points[i]);
            program.points[blocks[k].last] = retract;
            if let Some((i, a)) = approach {
                program.points[i] = a;
            }
            if check(program, k)?.min_clearance_mm > 0.0 {
                fixed = true;
            } else {
                program.points[blocks[k].last] = old_retract;
                if let (Some((i, _)), Some(a)) = (approach, old_approach) {
                    program.points[i] = a;
                }
            }
        }
        if !fixed {
            return Err(refuse(format!(
                ", even with the retract and approach points raised up to {} mm along the tool \
                 axis (transit_max_clearance_mm)",
                opts.transit_max_clearance_mm
            )));
        }
    }
    Ok(())
}

/// The approach or retract point of bead point `p` at `clearance_mm`, or,
/// where that one leaves a joint's travel (a bead that ends with J5 a
/// fraction of a degree inside its stop), at a half, a quarter or an eighth
/// of it; refused with the full clearance's reason if none works.
fn clearance_point_within_travel(
    cell: &CellLayout,
    p: &ProgramPoint,
    input: &PathPointInput,
    flag: ArcFlag,
    opts: &ProgramOptions,
) -> Result<ProgramPoint, ProgramError> {
    let mut first_error = None;
    for divisor in [1.0, 2.0, 4.0, 8.0] {
        match clearance_point(cell, p, input, flag, opts, opts.clearance_mm / divisor) {
            Ok(point) => return Ok(point),
            Err(e) => {
                first_error.get_or_insert(e);
            }
        }
    }
    Err(first_error.expect("at least one clearance tried"))
}

/// The approach or retract point of bead point `p`: `clearance_mm` along the
/// tool axis, same orientation and positioner joints, joints unwrapped
/// towards `p`'s; refused if a joint leaves its travel or the linear move
/// between it and `p` outruns a joint at the approach speed.
fn clearance_point(
    cell: &CellLayout,
    p: &ProgramPoint,
    input: &PathPointInput,
    flag: ArcFlag,
    opts: &ProgramOptions,
    clearance_mm: f64,
) -> Result<ProgramPoint, ProgramError> {
    let what = if flag == ArcFlag::Approach {
        "approach"
    } else {
        "retract"
    };
    let infeasible = |msg: String| ProgramError::Infeasible {
        count: 1,
        first: format!(
            "layer {}, {what} point ({} mm from point {} along the tool axis): {msg}",
            p.layer, clearance_mm, p.point
        ),
        layers: vec![p.layer],
    };
    let position_mm = p.position_mm + p.tool_axis.into_inner() * clearance_mm;
    let cp = CellPoint {
        position_mm,
        tool_axis: p.tool_axis,
        build_direction: input.build_direction,
        // the planned positioner as the program writes it (its turn
        // unwound by whole turns, `unwind_turns`)
        positioner: input.positioner.and(p.positioner),
    };
    let q8 = p.positioner.map_or(0.0, |q| q[1]);
    let (q, pose) = cell
        .joints(&cp, p.r_z, Some(&p.joints), q8)
        .map_err(|e| infeasible(e.to_string()))?;
    if let (Some(a), Some(b)) = (pose.positioner, p.positioner) {
        if (a[0] - b[0]).abs() > 1e-9 || (a[1] - b[1]).abs() > 1e-9 {
            return Err(infeasible("the positioner would have to move".into()));
        }
    }
    let robot = cell.robot();
    if let Some((j, v)) = robot.limit_violations(&q).next() {
        return Err(infeasible(format!(
            "J{} = {:.3}° outside its travel",
            j + 1,
            v.to_degrees()
        )));
    }
    let dt = clearance_mm / opts.approach_speed_mm_s;
    for (j, (qj, pj)) in q.iter().zip(p.joints).enumerate() {
        let s = (qj - pj).abs() / dt;
        if s > robot.max_speed_rad_s[j] {
            return Err(infeasible(format!(
                "J{} needs {:.2}°/s at {} mm/s, maximum {:.1}°/s",
                j + 1,
                s.to_degrees(),
                opts.approach_speed_mm_s,
                robot.max_speed_rad_s[j].to_degrees()
            )));
        }
    }
    Ok(ProgramPoint {
        position_mm,
        joints: q,
        positioner: pose.positioner,
        speed_mm_s: opts.approach_speed_mm_s,
        arc: flag,
        via: false,
        ..*p
    })
}

/// `true` when point `i` of `program` is reached by a joint move (FANUC
/// `J`, KUKA `PTP`, ABB `MoveAbsJ`): an approach point, or a bead's first
/// point without one; every other point is reached by a linear move.
pub fn joint_move_target(program: &Program, i: usize) -> bool {
    opens_bead(
        i.checked_sub(1).map(|k| program.points[k].arc),
        program.points[i].arc,
    )
}

/// `true` when a point with flag `arc`, after one with flag `prev` (`None`
/// for the first point), opens a bead's block of points: an approach point,
/// or a bead's first point without one. Such a point is reached by a joint
/// move ([`joint_move_target`]) and a program is split only before one
/// ([`split::beads`]).
pub fn opens_bead(prev: Option<ArcFlag>, arc: ArcFlag) -> bool {
    match arc {
        ArcFlag::Approach => true,
        ArcFlag::Start => prev != Some(ArcFlag::Approach),
        _ => false,
    }
}

/// Smallest joint change (rad) counted as motion between two consecutive
/// points.
pub const JOINT_STILL_RAD: f64 = 1e-9;

/// `true` when any of `a` differs from `b` by more than [`JOINT_STILL_RAD`]
/// (joints or positioner joints, rad).
pub fn joints_move(a: &[f64], b: &[f64]) -> bool {
    a.iter()
        .zip(b)
        .any(|(x, y)| (x - y).abs() > JOINT_STILL_RAD)
}

/// Largest positioner motion over a segment still counted as a positioner
/// at rest (deg): above it, a torch-carried cell's segment is
/// [`positioner_moves`] and emitters time it instead of giving a TCP speed.
pub const POSITIONER_STILL_DEG: f64 = 0.01;

/// `true` when the positioner turns by more than [`POSITIONER_STILL_DEG`]
/// on either axis between point `i - 1` and point `i` of `program` (never
/// for `i = 0` or without a positioner). On such a segment the TCP's
/// travel in the robot frame is not the deposition point's travel over the
/// part (the part turns under a nearly still torch), so a TCP speed would
/// not give the planned travel speed.
pub fn positioner_moves(program: &Program, i: usize) -> bool {
    let Some(prev) = move_start(program, i).map(|k| &program.points[k]) else {
        return false;
    };
    match (program.points[i].positioner, prev.positioner) {
        (Some(a), Some(b)) => {
            (a[0] - b[0]).abs().max((a[1] - b[1]).abs()) > POSITIONER_STILL_DEG.to_radians()
        }
        _ => false,
    }
}

/// Length of the move into point `i` of `program`, the deposition point's
/// travel over the part (part frame, mm): the chord from the previous
/// point, or for a circular move the arc from [`move_start`] through the via
/// ([`compress::arc_length`]); 0 for `i = 0`.
pub fn segment_length_mm(program: &Program, i: usize) -> f64 {
    let Some(k) = move_start(program, i) else {
        return 0.0;
    };
    let end = &program.points[i].position_mm;
    let start = &program.points[k].position_mm;
    if k + 2 == i {
        let via = &program.points[k + 1].position_mm;
        crate::program::compress::arc_length(start, via, end)
    } else {
        (end - start).norm()
    }
}

/// Where the move into point `i` of `program` starts: the point before it,
/// or the one before the via when point `i` ends a circular move
/// ([`ProgramPoint::via`]); `None` for `i = 0`.
pub fn move_start(program: &Program, i: usize) -> Option<usize> {
    let k = i.checked_sub(1)?;
    match (k.checked_sub(1), program.points[k].via) {
        (Some(before), true) => Some(before),
        _ => Some(k),
    }
}

/// Checks a controller program name: an ASCII letter first, then letters,
/// digits or `_`, at most 32 characters (RAPID identifiers take 32; FANUC
/// TP program names take up to 36 characters on recent controllers, 8 on
/// old ones, where shorter names are the user's choice; KRL names take 24,
/// which [`kuka::kuka_files`] checks on top of this).
///
/// # Errors
/// [`ProgramError::InvalidOptions`] naming `name`.
pub fn check_name(name: &str) -> Result<(), ProgramError> {
    let ok = !name.is_empty()
        && name.len() <= 32
        && name.starts_with(|c: char| c.is_ascii_alphabetic())
        && name.chars().all(|c| c.is_ascii_alphanumeric() || c == '_');
    if ok {
        Ok(())
    } else {
        Err(ProgramError::InvalidOptions {
            field: "name",
            value: name.to_string(),
            reason: "a letter, then letters, digits or `_`, at most 32 characters",
        })
    }
}

/// The vendor's name as written in messages (`FANUC`, `KUKA`, `ABB`).
pub fn vendor_name(vendor: Vendor) -> &'static str {
    match vendor {
        Vendor::Fanuc => "FANUC",
        Vendor::Kuka => "KUKA",
        Vendor::Abb => "ABB",
    }
}

/// Checks that `cell`'s robot is a `vendor` arm, the only one whose joints
/// (controller convention, rad) and flange poses the `emitter` (e.g. `KUKA
/// KRL`) may write or read.
///
/// # Errors
/// [`ProgramError::VendorMismatch`] naming both vendors and the robot.
pub fn check_vendor(
    cell: &CellLayout,
    vendor: Vendor,
    emitter: &'static str,
) -> Result<(), ProgramError> {
    let robot = cell.robot();
    if robot.vendor == vendor {
        Ok(())
    } else {
        Err(ProgramError::VendorMismatch {
            emitter,
            emitter_vendor: vendor_name(vendor),
            robot: robot.name.clone(),
            robot_vendor: vendor_name(robot.vendor),
        })
    }
}

/// How a bead is started and stopped (SPEC §8).
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ProcessControl {
    /// Welding: the controller's arc instructions with weld schedule `schedule`
    /// (FANUC `Arc Start[n]`/`Arc End[n]`, ABB `weld<n>`, KUKA output `n`).
    Arc {
        /// Weld schedule (procedure) number, ≥ 1.
        schedule: u32,
    },
    /// User-given instruction lines (e.g. a polymer extruder's I/O), written
    /// as they are where the bead starts and stops.
    Custom {
        /// Instruction starting a bead, e.g. `DO[1]=ON`.
        start: String,
        /// Instruction stopping a bead, e.g. `DO[1]=OFF`.
        end: String,
    },
}

impl Default for ProcessControl {
    fn default() -> Self {
        ProcessControl::Arc { schedule: 1 }
    }
}

impl ProcessControl {
    /// Checks the schedule number and that custom lines are single, non-empty
    /// ASCII lines (controllers reject other bytes).
    ///
    /// # Errors
    /// [`ProgramError::InvalidOptions`] naming the field.
    pub fn validate(&self) -> Result<(), ProgramError> {
        match self {
            ProcessControl::Arc { schedule } if *schedule == 0 => {
                Err(ProgramError::InvalidOptions {
                    field: "process.schedule",
                    value: "0".into(),
                    reason: "must be >= 1",
                })
            }
            ProcessControl::Custom { start, end } => {
                for (field, s) in [("process.start", start), ("process.end", end)] {
                    if s.trim().is_empty() || s.contains(['\n', '\r', ';']) || !s.is_ascii() {
                        return Err(ProgramError::InvalidOptions {
                            field,
                            value: s.clone(),
                            reason: "must be one non-empty ASCII line without `;`",
                        });
                    }
                }
                Ok(())
            }
            _ => Ok(()),
        }
    }
}

/// One emitted file: its name (with extension) and its content.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct EmittedFile {
    /// File name, e.g. `HEMI.ls`.
    pub name: String,
    /// Content.
    pub text: String,
}

/// Writes every file into `dir`, each atomically (temporary file, then rename).
///
/// # Errors
/// [`ProgramError::Io`] naming the file.
pub fn write_files(dir: &Path, files: &[EmittedFile]) -> Result<(), ProgramError> {
    for f in files {
        let path = dir.join(&f.name);
        crate::util::atomic::write_atomic(&path, |w| w.write_all(f.text.as_bytes())).map_err(
            |source| ProgramError::Io {
                path: path.display().to_string(),
                source: source.into(),
            },
        )?;
    }
    Ok(())
}

/// Renders a writer function into a `String`.
pub(crate) fn render(
    f: impl FnOnce(&mut dyn std::io::Write) -> std::io::Result<()>,
) -> Result<String, ProgramError> {
    let mut buf: Vec<u8> = Vec::new();
    f(&mut buf).map_err(|source| ProgramError::Io {
        path: "<memory>".into(),
        source: source.into(),
    })?;
    String::from_utf8(buf).map_err(|e| ProgramError::Io {
        path: "<memory>".into(),
        source: std::io::Error::other(e).into(),
    })
}
