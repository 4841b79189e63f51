//! Planning a part in a cell in one call: slice → tool axes → `R_Z`
//! optimisation layer by layer (SPEC §7) → joint trajectory → program model
//! (SPEC §8), and writing the plan's files.

use std::path::{Path as FsPath, PathBuf};
use std::time::Instant;

use serde::ser::SerializeMap;
use serde::Serialize;

use super::summary::{
    deg6, finite, CellCheckSummary, CollisionSummary, CycleSummary, LayerSummary, ObjectiveSummary,
    PlanSummary, PositionerSummary, QualitySummary, SlowSummary, SolverSummary, SplitSummary,
    TransitionSummary, UnbuildableLayer, UnbuildableProof,
};
use super::{slice_part_with, Cell, Control, Part, PlanOptions, RzLaw, SlicedPart};
use crate::math::UnitVector3;
use crate::optimise::{
    layer_points, optimise_with, slow_refused_layers, split_refused_layers, LayerPlan, LayerPoints,
    OptimiseOptions, Plan, SplitPlan,
};
use crate::program::{check_vendor, write_files, ArcFlag, Program, ProgramError};
use crate::robot::Vendor;
use crate::toolaxis::bead_tool_axes;
use crate::Error;

/// Wall-clock time of each planning stage (s).
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize)]
pub struct PlanTimes {
    /// Slicing, distance map and tool axes (s).
    pub slice: f64,
    /// Tool axes and the layer points (s).
    pub tool_axes: f64,
    /// `R_Z` optimisation (s).
    pub optimise: f64,
    /// Joint trajectory and program model, the whole-cell collision check
    /// included (s).
    pub program: f64,
    /// The whole-cell collision check alone ([`crate::program::cell_check`]) (s).
    pub cell_check: f64,
}

/// A part planned in a cell: the sliced part, the optimised plan (one
/// [`LayerPlan`](crate::optimise::LayerPlan) per layer: status, `R_Z`, joints)
/// and, when every layer is feasible, the program model the emitters write.
///
/// Serialises (serde) as `{ "summary": …, "points": [...] }`: the summary
/// is [`PlannedPart::summary`]; each point gives its layer, index, position
/// (mm, part frame), `R_Z` (deg), joints (deg, controller convention; `null`
/// without solution) and positioner joints (deg).
#[derive(Debug, Clone)]
pub struct PlannedPart {
    /// The part as sliced for the plan.
    pub sliced: SlicedPart,
    /// The cell (robot base frame).
    pub cell: Cell,
    /// The layers as the cell sees them (part frame).
    pub layers: Vec<LayerPoints>,
    /// The optimiser's options (travel speed in mm/s among them).
    pub optimise: OptimiseOptions,
    /// The `R_Z` law asked for.
    pub rz: RzLaw,
    /// The program format the plan writes: [`PlanOptions::format`], else the
    /// cell robot's vendor's.
    pub format: Vendor,
    /// The optimised plan, one entry per layer.
    pub plan: Plan,
    /// The program model when every layer is feasible and the trajectory
    /// rebuilt from the plan passes the program stage's checks; else the
    /// program stage's refusal ([`ProgramError::InfeasibleLayer`] naming the
    /// first infeasible layer and its binding constraint, or the check that
    /// failed).
    pub program: Result<Program, ProgramError>,
    /// The closest approach of the cell's bodies per layer
    /// ([`crate::program::cell_check`]), when the program was built and
    /// passed the check (a collision is the program's refusal,
    /// [`ProgramError::Collision`]).
    pub clearance: Option<crate::program::cell_check::CellClearance>,
    /// Run times.
    pub times: PlanTimes,
    /// The beads split at corners: where a layer could not be built as one
    /// bead in a torch-carried cell with seams on corners, it is split at
    /// its corners inside the bead, each split here (in path order), and
    /// `layers` and `plan` hold its beads ([`crate::optimise::split`]).
    pub splits: Vec<crate::optimise::BeadSplit>,
    /// The beads slowed down: where a layer (or bead) could not be built at
    /// the process's speed, the torch slows where an axis binds, down to the
    /// process's `travel_speed_min_mm_s`, and the wire feed follows
    /// ([`crate::optimise::slow`]); `layers` hold their points' speeds.
    pub slowed: Vec<crate::optimise::SlowedBead>,
}

/// The program name for a part: its name in upper case, letters, digits and
/// `_` only, starting with a letter (`P` prepended otherwise), at most 24
/// characters (the shortest limit of the three controllers, KUKA's).
pub fn program_name(part_name: &str) -> String {
    let mut n: String = part_name
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() {
                c.to_ascii_uppercase()
            } else {
                '_'
            }
        })
        .collect();
    if !n.starts_with(|c: char| c.is_ascii_alphabetic()) {
        n.insert(0, 'P');
    }
    n.truncate(24);
    n
}

/// Plans `part` in `cell`: slices it with its file's settings and the
/// overrides of `opts`, attaches tool axes, optimises `R_Z` layer by layer
/// with the cell's IK branch on every layer (a program must not reconfigure
/// the arm between layers), rebuilds the joint trajectory at the travel
/// speed and builds the program model. An infeasible layer is data, not an
/// error: see [`PlannedPart::is_feasible`].
///
/// # Errors
/// Bad input: the part's or the overrides' ([`Error::InPart`]), the
/// optimiser's options or the cell ([`Error::Optimise`]), a program format
/// the cell's robot cannot run ([`ProgramError::VendorMismatch`], checked
/// before any work); [`Error::Cancelled`].
pub fn plan_part(part: &Part, cell: &Cell, opts: &PlanOptions) -> Result<PlannedPart, Error> {
    plan_part_with(part, cell, opts, &Control::default())
}

/// [`plan_part`] with a host's progress reports and cancellation
/// ([`Control`]: progress from 0 to 1 through slicing, optimising and the
/// program; a cancel request is seen between layers).
///
/// # Errors
/// As [`plan_part`].
pub fn plan_part_with(
    part: &Part,
    cell: &Cell,
    opts: &PlanOptions,
    control: &Control,
) -> Result<PlannedPart, Error> {
    let format = opts.format.unwrap_or_else(|| cell.native_format());
    check_vendor(&cell.layout, format, format.emitter())?;
    let t = Instant::now();
    // Slicing is the first tenth of a plan's progress.
    let sliced = slice_part_with(
        part,
        &opts.slice.for_cell(part, cell),
        &control.within(0.0, 0.1),
    )?;
    let t_slice = t.elapsed().as_secs_f64() - sliced.times.tool_axes;
    // Reach up front, with this part's own extent (the cell reader allowed
    // a generic 1 m part): a point out of reach fails before optimising.
    let radius = sliced
        .path
        .layers
        .iter()
        .flat_map(|l| &l.points)
        .map(|p| p.position.coords.norm())
        .fold(0.0, f64::max);
    cell.layout.check_reach(radius).map_err(|e| Error::InPart {
        file: cell.file.clone(),
        source: Box::new(e.into()),
    })?;
    let t = Instant::now();
    let layers = layer_points(
        &sliced.path,
        &sliced.axes.frames,
        sliced.process.travel_speed_mm_s,
    );
    let t_axes = sliced.times.tool_axes + t.elapsed().as_secs_f64();
    let optimise_opts = opts.optimise;
    optimise_opts.validate()?;
    control.check("optimising")?;
    control.report("optimising", 0.1);
    let plan = optimise_with(&cell.layout, &layers, &optimise_opts, &|done, total| {
        control.report("optimising", 0.1 + 0.85 * done as f64 / total.max(1) as f64);
        !control.is_cancelled()
    })
    .map_err(|e| match e {
        crate::optimise::OptimiseError::Cancelled { .. } => Error::Cancelled {
            stage: "optimising",
        },
        e => e.into(),
    })?;
    control.check("optimising")?;
    let split = split_at_corners(cell, &sliced, layers, plan, &optimise_opts)?;
    control.check("optimising")?;
    let slow = slow_refused_layers(
        &cell.layout,
        split.layers,
        split.plan,
        sliced.process.travel_speed_min_mm_s,
        &optimise_opts,
    )?;
    let (layers, plan) = (slow.layers, slow.plan);
    control.check("optimising")?;
    control.report("program", 0.95);
    let t = Instant::now();
    let name = program_name(&part.name);
    let built = build(&name, cell, &sliced, &layers, &plan, &slow.slowed, true);
    let t_program = t.elapsed().as_secs_f64();
    let (program, clearance, t_check) = match built {
        Ok((p, c, t)) => (Ok(p), Some(c), t),
        Err(e) => (Err(e), None, 0.0),
    };
    control.report("program", 1.0);
    Ok(PlannedPart {
        times: PlanTimes {
            slice: t_slice,
            tool_axes: t_axes,
            optimise: plan.time_s,
            program: t_program,
            cell_check: t_check,
        },
        sliced,
        cell: cell.clone(),
        layers,
        optimise: optimise_opts,
        rz: opts.rz(),
        format,
        plan,
        program,
        clearance,
        splits: split.splits,
        slowed: slow.slowed,
    })
}

/// The layers the plan could not build whole split at their corners inside
/// the bead ([`Layer::inside_corners`](crate::path::Layer::inside_corners)),
/// where every bead then plans ([`split_refused_layers`]): in a
/// torch-carried cell with seams on corners only (part-carried cells turn
/// the part through a corner within the tool axis's rate bound).
fn split_at_corners(
    cell: &Cell,
    sliced: &SlicedPart,
    layers: Vec<LayerPoints>,
    plan: Plan,
    opts: &OptimiseOptions,
) -> Result<SplitPlan, Error> {
    let torch_carried = matches!(cell.layout, crate::robot::CellLayout::TorchCarried(_));
    if !(torch_carried && sliced.options.seams_on_corners) {
        return Ok(SplitPlan {
            layers,
            plan,
            splits: Vec::new(),
        });
    }
    let threshold = sliced.options.corner_threshold_rad;
    let path = &sliced.path;
    let beads_of = |lp: &LayerPoints| -> Vec<LayerPoints> {
        let (Some(layer), Some(frames)) =
            (path.layers.get(lp.layer), sliced.axes.frames.get(lp.layer))
        else {
            return Vec::new();
        };
        if lp.points.len() < 3 {
            return Vec::new();
        }
        let corners: Vec<usize> = layer
            .inside_corners(threshold)
            .iter()
            .map(|c| c.point)
            .collect();
        if corners.is_empty() {
            return Vec::new();
        }
        // each bead's tool axes as on an open layer from its first point to
        // its last, the corners left out (their frames lie half way round:
        // `split_at` gives each bead's end on a corner its neighbour's): the
        // rate bound spreads no corner across a bead's end
        let mut retooled = lp.clone();
        let first = lp.first_point;
        let last = first + lp.points.len() - 1;
        let ends: Vec<usize> = std::iter::once(first)
            .chain(corners.iter().copied())
            .chain(std::iter::once(last))
            .collect();
        for w in ends.windows(2) {
            let lo = if w[0] == first { w[0] } else { w[0] + 1 };
            let hi = if w[1] == last { w[1] } else { w[1] - 1 };
            let axes = bead_tool_axes(path, lp.layer, frames, lo..hi + 1, &sliced.tool_axis);
            for (i, t) in (lo..).zip(axes) {
                if let Some(p) = i
                    .checked_sub(first)
                    .and_then(|i| retooled.points.get_mut(i))
                {
                    p.tool_axis = UnitVector3::new_normalize(t);
                }
            }
        }
        retooled.split_at(&corners)
    };
    Ok(split_refused_layers(
        &cell.layout,
        layers,
        plan,
        &beads_of,
        opts,
    )?)
}

/// The program model of a plan ([`ProgramBuild`](super::program::ProgramBuild)):
/// every point at its own travel speed with its wire feed ([`wire_feeds`]:
/// the process's, following the speed on the beads `slowed`).
/// `every_layer`: `layers` are the whole build; `false` for a subsample (a
/// placement's screening).
pub(super) fn build(
    name: &str,
    cell: &Cell,
    sliced: &SlicedPart,
    layers: &[LayerPoints],
    plan: &Plan,
    slowed: &[crate::optimise::SlowedBead],
    every_layer: bool,
) -> Result<(Program, crate::program::cell_check::CellClearance, f64), ProgramError> {
    let wire: Vec<f64> = wire_feeds(layers, &sliced.process, slowed)
        .into_iter()
        .flatten()
        .collect();
    super::program::ProgramBuild {
        name,
        cell,
        layers,
        plan,
        wire_feed_mm_s: &wire,
        common: &cell.program.common,
        layer_masses_kg: &sliced
            .process_plan
            .layer_masses_kg(&sliced.path, &sliced.process),
        every_layer,
    }
    .build()
}

/// The wire feed of every point of `layers` (mm/s): the process's
/// `wire_feed_speed_mm_s`, scaled on the beads `slowed` by the point's speed
/// over the process's, so that `WFS/TS` — the bead's cross-section
/// `pi d^2/4 · WFS/TS` (SPEC §5) — stays the process's where the torch slows.
pub(super) fn wire_feeds(
    layers: &[LayerPoints],
    process: &crate::process::ProcessParameters,
    slowed: &[crate::optimise::SlowedBead],
) -> Vec<Vec<f64>> {
    let (wfs, nominal) = (process.wire_feed_speed_mm_s, process.travel_speed_mm_s);
    layers
        .iter()
        .map(|lp| {
            let slow = slowed
                .iter()
                .any(|s| s.layer == lp.layer && s.bead == lp.bead);
            lp.points
                .iter()
                .map(|p| {
                    if slow {
                        wfs * p.travel_speed_mm_s / nominal
                    } else {
                        wfs
                    }
                })
                .collect()
        })
        .collect()
}

impl PlannedPart {
    /// `true` when every layer is feasible and the program model was built:
    /// [`PlannedPart::write_programs`] will write it.
    pub fn is_feasible(&self) -> bool {
        self.plan.is_feasible() && self.program.is_ok()
    }

    /// The program stage's refusal, `None` when the program was built.
    pub fn refusal(&self) -> Option<&ProgramError> {
        self.program.as_ref().err()
    }

    /// The nominal travel speed (mm/s): the process's, which every point
    /// runs at unless the plan slowed it ([`PlannedPart::point_process`]).
    pub fn travel_speed_mm_s(&self) -> f64 {
        self.sliced.process.travel_speed_mm_s
    }

    /// `true` when the cell has a positioner (torch carried): the joints
    /// have two more values.
    pub fn has_positioner(&self) -> bool {
        matches!(self.cell.layout, crate::robot::CellLayout::TorchCarried(_))
    }

    /// Writes `joints.csv` (see [`crate::io::joints_csv`]).
    ///
    /// # Errors
    /// I/O errors of `w`.
    pub fn write_joints_csv(&self, w: &mut dyn std::io::Write) -> std::io::Result<()> {
        crate::io::joints_csv::write_joints_csv(
            w,
            &self.layers,
            &self.plan,
            self.has_positioner(),
            &self.point_process(),
        )
    }

    /// Per point of `layers`: `[travel speed (mm/s), bead height (mm), wire
    /// feed (mm/s)]` — the speed the program runs on the way to the point,
    /// the height the plan asks for there (the point's local distance to
    /// the layer below, `Delta` on the first layer) and the wire feed: the
    /// process's, scaled by the slowdown on a slowed bead
    /// ([`PlannedPart::slowed`]) so that `WFS/TS`, the bead's cross-section
    /// (SPEC §5), stays that of the process's speed.
    pub fn point_process(&self) -> Vec<Vec<[f64; 3]>> {
        let path = &self.sliced.path;
        let wire = wire_feeds(&self.layers, &self.sliced.process, &self.slowed);
        self.layers
            .iter()
            .zip(wire)
            .map(|(lp, wire)| {
                lp.points
                    .iter()
                    .zip(wire)
                    .enumerate()
                    .map(|(m, (p, w))| {
                        let v = p.travel_speed_mm_s;
                        let h = path
                            .layers
                            .get(lp.layer)
                            .and_then(|l| l.points.get(lp.first_point + m))
                            .and_then(|p| p.delta)
                            .unwrap_or(path.delta_mm);
                        [v, h, w]
                    })
                    .collect()
            })
            .collect()
    }

    /// The emitted program files in the plan's [`PlannedPart::format`], not
    /// written.
    ///
    /// # Errors
    /// [`ProgramError::InfeasibleLayer`] naming the first infeasible layer,
    /// the program stage's refusal of the trajectory
    /// ([`PlannedPart::program`]'s error).
    pub fn program_files(&self) -> Result<Vec<crate::program::EmittedFile>, Error> {
        let format = self.format;
        check_vendor(&self.cell.layout, format, format.emitter())?;
        super::program::check_every_layer(&self.layers, &self.plan)?;
        let program = self.program.as_ref().map_err(Clone::clone)?;
        let settings = &self.cell.program;
        Ok(crate::program::registry::emit(program, settings)?)
    }

    /// Writes the robot program in the plan's [`PlannedPart::format`] into
    /// `dir` (created if missing), each file atomically; returns the written
    /// paths, the main program first.
    ///
    /// # Errors
    /// As [`PlannedPart::program_files`]; [`ProgramError::Io`] naming the file.
    pub fn write_programs(&self, dir: impl AsRef<FsPath>) -> Result<Vec<PathBuf>, Error> {
        let files = self.program_files()?;
        let dir = dir.as_ref();
        std::fs::create_dir_all(dir).map_err(|source| ProgramError::Io {
            path: dir.display().to_string(),
            source: source.into(),
        })?;
        write_files(dir, &files)?;
        Ok(files.iter().map(|f| dir.join(&f.name)).collect())
    }

    /// Writes the interactive 3-D report of the plan (`report.html`: the path
    /// and the robot animated through it, see [`crate::report`]) atomically
    /// to `dest`; bead width = Delta.
    ///
    /// # Errors
    /// [`Error::Report`] naming the input or the file.
    pub fn write_report(
        &self,
        dest: &FsPath,
        substrate: Option<&crate::geometry::Substrate>,
    ) -> Result<(), Error> {
        let title = format!(
            "{} in {}: {} layers, {}",
            self.sliced.part_name,
            self.cell.name,
            self.plan.layers.len(),
            if self.is_feasible() {
                "feasible"
            } else {
                "NOT feasible"
            }
        );
        let mut input = self
            .sliced
            .report_input(&title, substrate, self.sliced.path.delta_mm);
        let cycle = self.cycle_time();
        let (layers, plan) = self.whole_layers();
        let corners = self.sliced.corner_marks(&self.splits);
        input.corners = &corners;
        input.plan = Some(crate::report::PlanView {
            cell: &self.cell.layout,
            layers: &layers,
            plan: &plan,
            travel_speed_mm_s: self.travel_speed_mm_s(),
            cycle: cycle.as_ref(),
            keep_out: &self.cell.keep_out,
            clearance: self.clearance.as_ref(),
            refusal: self.refusal(),
        });
        crate::report::write_report(dest, &input)?;
        Ok(())
    }

    /// The plan with each layer split at its corners
    /// ([`PlannedPart::splits`]) joined again into one entry a layer, as
    /// the report draws the path: a split point, in both beads, is taken
    /// once, from the bead that ends there; each layer's status, branch and
    /// figures are its first bead's. The plan itself when nothing is split.
    pub fn whole_layers(&self) -> (Vec<LayerPoints>, Plan) {
        let mut layers: Vec<LayerPoints> = Vec::with_capacity(self.layers.len());
        let mut plans: Vec<LayerPlan> = Vec::with_capacity(self.plan.layers.len());
        for (lp, pl) in self.layers.iter().zip(&self.plan.layers) {
            match (layers.last_mut(), plans.last_mut()) {
                (Some(l), Some(p)) if lp.bead > 0 && l.layer == lp.layer => {
                    l.points.extend(lp.points.iter().skip(1).copied());
                    p.points.extend(pl.points.iter().skip(1).cloned());
                    p.violations.extend(pl.violations.iter().cloned());
                }
                _ => {
                    layers.push(lp.clone());
                    plans.push(pl.clone());
                }
            }
        }
        let plan = Plan {
            transitions: self
                .plan
                .transitions
                .iter()
                .filter(|t| t.from_layer != t.to_layer)
                .copied()
                .collect(),
            layers: plans,
            time_s: self.plan.time_s,
        };
        (layers, plan)
    }

    /// The options of the cycle time ([`crate::program::cycle`]) for the
    /// plan's format: the joint moves' speed as its emitter writes them
    /// ([`Controller::cycle_options`](crate::program::contract::Controller::cycle_options)),
    /// the assumed path acceleration.
    pub fn cycle_options(&self) -> crate::program::cycle::CycleOptions {
        self.format.cycle_options(&self.cell.program)
    }

    /// The cycle time of the program (s, per move, layer and build;
    /// [`crate::program::cycle`]); `None` when the program stage refused the plan.
    pub fn cycle_time(&self) -> Option<crate::program::cycle::CycleTime> {
        let program = self.program.as_ref().ok()?;
        Some(crate::program::cycle::cycle_time(
            program,
            &self.cycle_options(),
        ))
    }

    /// The splits of [`PlannedPart::splits`] as `summary.json` lists them,
    /// with the turning of the layer's polyline across each corner.
    pub fn split_summaries(&self) -> Vec<SplitSummary> {
        let threshold = self.sliced.options.corner_threshold_rad;
        self.splits
            .iter()
            .map(|s| {
                let turning = self
                    .sliced
                    .path
                    .layers
                    .get(s.layer)
                    .and_then(|l| {
                        l.inside_corners(threshold)
                            .into_iter()
                            .find(|c| c.point == s.point)
                    })
                    .map_or(f64::NAN, |c| c.turn_rad);
                SplitSummary {
                    layer: s.layer,
                    point: s.point,
                    bead: s.bead,
                    turning_deg: turning.to_degrees(),
                    why: s.why.clone(),
                }
            })
            .collect()
    }

    /// The content of `plan`'s `summary.json`: the part and cell files, the
    /// `R_Z` law, travel speed, feasibility, every violation, per layer the
    /// status, IK branch, law, objective, quality figures and solver counts,
    /// the layer transitions, run times (s) and the path summary
    /// ([`SlicedPart::path_summary`]); `serde_json::to_value` gives the JSON.
    pub fn summary(&self) -> PlanSummary {
        let plan = &self.plan;
        let cycle = self.cycle_time();
        let options = self.cycle_options();
        PlanSummary {
            part: self.sliced.part_name.clone(),
            part_file: self.sliced.part_file.clone(),
            cell_file: self.cell.file.clone(),
            rz: self.rz.to_string(),
            travel_speed_mm_s: self.travel_speed_mm_s(),
            feasible: plan.is_feasible(),
            infeasible_layers: plan.infeasible_layers().map(|l| l.layer).collect(),
            unbuildable_layers: plan.layers.iter().filter_map(unbuildable).collect(),
            violations: plan.violations().map(|v| v.to_string()).collect(),
            layer_plans: plan
                .layers
                .iter()
                .zip(&self.layers)
                .map(|(l, lp)| {
                    let mut summary = layer_summary(l);
                    summary.bead = lp.bead;
                    // the cycle's entries are a bead each, in program
                    // order: this bead's is its layer's `bead`-th
                    summary.cycle_time_s = cycle
                        .as_ref()
                        .and_then(|c| {
                            c.layers
                                .iter()
                                .filter(|lc| lc.layer == l.layer)
                                .nth(lp.bead)
                        })
                        .map(|lc| lc.total_s);
                    if let Some(lc) = self
                        .clearance
                        .as_ref()
                        .and_then(|c| c.layers.iter().find(|lc| lc.layer == l.layer))
                    {
                        summary.closest_approach_mm = finite(lc.closest_approach_mm);
                        summary.closest_pair = lc.closest_pair.clone().map(|(a, b)| [a, b]);
                    }
                    if let Ok(p) = &self.program {
                        summary.transit_vias = p
                            .points
                            .iter()
                            .filter(|q| {
                                q.arc == ArcFlag::Transit && q.layer == l.layer && q.bead == lp.bead
                            })
                            .count();
                    }
                    summary
                })
                .collect(),
            transitions: plan
                .transitions
                .iter()
                .map(|t| TransitionSummary {
                    from_layer: t.from_layer,
                    to_layer: t.to_layer,
                    joint_change_deg: deg6(&t.joint_change_rad),
                    branch_change: t.branch_change,
                    start_limit_distance_deg: t.start_limit_distance_rad.to_degrees(),
                })
                .collect(),
            program: None,
            program_refusal: match &self.program {
                Err(e) if plan.is_feasible() => Some(e.to_string()),
                _ => None,
            },
            collision: self.program.as_ref().err().and_then(CollisionSummary::of),
            cell_check: self.clearance.as_ref().map(|c| CellCheckSummary {
                samples: c.samples,
                exact_queries: c.exact_queries,
                culled: c.culled,
            }),
            cycle_time_s: cycle.as_ref().map(|c| c.total_s),
            cycle: cycle.map(|c| CycleSummary {
                arc_on_s: c.arc_on_s,
                home_return_s: c.home_return_s,
                interpass_waits: c.waits,
                joint_speed_fraction: options.joint_speed_fraction,
                path_acceleration_mm_s2: options.path_acceleration_mm_s2,
                layers: c.layers,
            }),
            splits: self.split_summaries(),
            slowed: self
                .slowed
                .iter()
                .map(|s| SlowSummary {
                    layer: s.layer,
                    bead: s.bead,
                    points_slowed: s.points_slowed,
                    slowest_mm_s: s.slowest_mm_s,
                    slowest_point: s.slowest_point,
                    wire_feed_min_mm_s: self.sliced.process.wire_feed_speed_mm_s * s.slowest_mm_s
                        / self.travel_speed_mm_s(),
                    why: s.why.clone(),
                })
                .collect(),
            run_time_s: self.times,
            path: {
                let mut path = self.sliced.path_summary();
                path.arc_starts += self.splits.len();
                path
            },
        }
    }
}

/// A layer's entry under `unbuildable_layers`, when its positioner laws
/// prove it unbuildable from the geometry.
fn unbuildable(l: &LayerPlan) -> Option<UnbuildableLayer> {
    let law = l.positioner.as_ref()?;
    law.proven_infeasible.then(|| UnbuildableLayer {
        layer: l.layer,
        proof: if law.required_rate_rad_s > law.available_rate_rad_s {
            UnbuildableProof::Rate
        } else {
            UnbuildableProof::Reachability
        },
        required_rate_deg_s: finite(law.required_rate_rad_s.to_degrees()),
        available_rate_deg_s: finite(law.available_rate_rad_s.to_degrees()),
        between_points: [law.required_between.0, law.required_between.1],
        unreachable_point: law.unreachable_point,
    })
}

/// A layer's entry under `layer_plans`.
fn layer_summary(l: &LayerPlan) -> LayerSummary {
    let q = &l.quality;
    LayerSummary {
        layer: l.layer,
        bead: 0,
        status: l.status.to_string(),
        feasible: l.status.is_feasible(),
        configuration: l.configuration.chosen.to_string(),
        configuration_reason: l.configuration.reason.clone(),
        law: l.law.clone(),
        points: l.points.len(),
        objective: ObjectiveSummary {
            joint_displacement: l.objective.joint_displacement,
            uncertainty_sum_sq_mm2: l.objective.uncertainty_sum_sq_mm2,
            mean_uncertainty_mm: l.objective.mean_uncertainty_mm,
            centring: l.objective.centring,
        },
        quality: QualitySummary {
            joint_travel_deg: deg6(&q.joint_travel_rad),
            peak_speed_deg_s: deg6(&q.peak_speed_rad_s),
            peak_acceleration_deg_s2: deg6(&q.peak_acceleration_rad_s2),
            summed_acceleration_j1_j5_deg_s: q.summed_acceleration_rad_s.to_degrees(),
            direction_reversals: q.direction_reversals,
            min_dexterity: q.min_dexterity,
            min_limit_distance_deg: q.min_limit_distance_rad.to_degrees(),
            min_limit_distance_joint: q.min_limit_distance_joint,
            max_hose_torsion_deg: q.max_hose_torsion_rad.to_degrees(),
        },
        positioner: l.positioner.as_ref().map(PositionerSummary::from),
        cycle_time_s: None,
        closest_approach_mm: None,
        closest_pair: None,
        transit_vias: 0,
        solver: SolverSummary {
            iterations: l.solver.iterations,
            qp_solves: l.solver.qp_solves,
            qp_failures: l.solver.qp_failures,
            branches_tried: l.solver.branches_tried,
            samples: l.solver.samples,
            time_s: l.solver.time_s,
        },
    }
}

/// `true` for 0 (a layer's first bead is not written).
fn is_zero(k: &usize) -> bool {
    *k == 0
}

/// One planned point as serialised.
#[derive(Serialize)]
struct PointView {
    layer: usize,
    #[serde(skip_serializing_if = "is_zero")]
    bead: usize,
    point: usize,
    position_mm: [f64; 3],
    rz_deg: f64,
    joints_deg: Option<[f64; 6]>,
    positioner_deg: Option<[f64; 2]>,
}

impl Serialize for PlannedPart {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        let points: Vec<PointView> = self
            .layers
            .iter()
            .zip(&self.plan.layers)
            .flat_map(|(lp, pl)| {
                lp.points
                    .iter()
                    .zip(&pl.points)
                    .enumerate()
                    .map(move |(m, (cp, pp))| PointView {
                        layer: lp.layer,
                        bead: lp.bead,
                        point: lp.first_point + m,
                        position_mm: cp.position_mm.coords.into(),
                        rz_deg: pp.r_z.to_degrees(),
                        joints_deg: pp.joints.map(|q| q.map(f64::to_degrees)),
                        positioner_deg: pp.positioner.map(|e| e.map(f64::to_degrees)),
                    })
            })
            .collect();
        let mut m = s.serialize_map(Some(2))?;
        m.serialize_entry("summary", &self.summary())?;
        m.serialize_entry("points", &points)?;
        m.end()
    }
}
