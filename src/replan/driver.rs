//! **Stage 9 — the closed loop's driver**: slices (or takes the plan's
//! slice), reads the scan, rebuilds the layers after `K`, gives them tool
//! axes and a process, optimises them in the cell and builds the program
//! that resumes the build; each step is one function below.

use std::time::Instant;

use super::rebuild::{self, Window};
use super::{program_name_for, Measured, ScanEstimate};
use super::{scan, LayerCorrection, ReplanError, ReplanOptions, ReplanTimes, ReplannedPart};
use crate::math::{Point3, Vector3};
use crate::optimise::{layer_points, optimise_with, LayerPoints, OptimiseOptions, Plan};
use crate::pipeline::program::ProgramBuild;
use crate::pipeline::{
    slice_part_with, Cell, Control, Part, PlanOptions, PlanTimes, PlannedPart, RzLaw, SlicedPart,
};
use crate::process::PointProcess;
use crate::program::check_vendor;
use crate::robot::{CellLayout, Vendor};
use crate::Error;

/// Replans the layers of `part` after `after_layer` from its measured top:
/// slices the part as [`plan_part`](crate::plan_part) would (with `opts`),
/// reads `measured`, corrects the speeds and geometry, optimises the
/// remaining layers in `cell` and builds the program that resumes the
/// build. [`replan_planned`] does the same from a plan already made and
/// re-optimises only the corrected layers (the fast path during a dwell).
///
/// # Errors
/// As [`replan_part_with`].
pub fn replan_part(
    part: &Part,
    cell: &Cell,
    measured: &Measured,
    after_layer: usize,
    opts: &PlanOptions,
) -> Result<ReplannedPart, Error> {
    replan_part_with(
        part,
        cell,
        measured,
        after_layer,
        opts,
        &ReplanOptions::default(),
    )
}

/// [`replan_part`] with the scan options of `replan`.
///
/// # Errors
/// Bad input ([`Error::InPart`], [`Error::Optimise`], a program format the
/// cell's robot cannot run); [`Error::Replan`]: a refused scan (another
/// layer, another part, too little coverage: the message names the
/// distance), nothing left after `after_layer`, a path that is not on one
/// grid of closed layers.
pub fn replan_part_with(
    part: &Part,
    cell: &Cell,
    measured: &Measured,
    after_layer: usize,
    opts: &PlanOptions,
    replan: &ReplanOptions,
) -> Result<ReplannedPart, Error> {
    let t0 = Instant::now();
    let format = opts.format.unwrap_or_else(|| cell.native_format());
    check_vendor(&cell.layout, format, format.emitter())?;
    replan.validate()?;
    let sliced = slice_part_with(part, &opts.slice.for_cell(part, cell), &Control::default())?;
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
    let optimise = opts.optimise;
    optimise.validate()?;
    let t_slice = t0.elapsed().as_secs_f64();
    let mut r = replan_core(
        part,
        cell,
        sliced,
        None,
        optimise,
        opts.rz(),
        format,
        measured,
        after_layer,
        replan,
    )?;
    r.times.slice = t_slice;
    r.times.total = t0.elapsed().as_secs_f64();
    Ok(r)
}

/// Replans the layers of `planned` (a plan of `part`) after `after_layer`
/// from its measured top: as [`replan_part`], with the plan's slicing,
/// options, cell and format, reusing its layer plans where the layers are
/// unchanged (only the corrected layers are optimised again).
///
/// # Errors
/// As [`replan_part_with`]; [`ReplanError::PartMismatch`] when `planned` is
/// not a plan of `part`.
pub fn replan_planned(
    part: &Part,
    planned: &PlannedPart,
    measured: &Measured,
    after_layer: usize,
    replan: &ReplanOptions,
) -> Result<ReplannedPart, Error> {
    let t0 = Instant::now();
    replan.validate()?;
    if planned.sliced.part_name != part.name {
        return Err(ReplanError::PartMismatch {
            planned: planned.sliced.part_name.clone(),
            part: part.name.clone(),
        }
        .into());
    }
    let mut r = replan_core(
        part,
        &planned.cell,
        planned.sliced.clone(),
        Some((&planned.layers, &planned.plan)),
        planned.optimise,
        planned.rz,
        planned.format,
        measured,
        after_layer,
        replan,
    )?;
    r.times.total = t0.elapsed().as_secs_f64();
    Ok(r)
}

/// The replan from a nominal slice (and its plan, to reuse): the scan read,
/// the layers rebuilt, their tool axes and process, their joints optimised,
/// the program that resumes the build, each step timed.
#[allow(clippy::too_many_arguments)]
fn replan_core(
    part: &Part,
    cell: &Cell,
    sliced: SlicedPart,
    nominal: Option<(&[LayerPoints], &Plan)>,
    optimise: OptimiseOptions,
    rz: RzLaw,
    format: Vendor,
    measured: &Measured,
    k: usize,
    ropts: &ReplanOptions,
) -> Result<ReplannedPart, Error> {
    let mut times = ReplanTimes::default();
    let path = &sliced.path;
    check_replannable(path, k)?;
    let t = Instant::now();
    let cols = rebuild::columns(path, k)?;
    let frames = &sliced.axes.frames;
    let scan = scan::estimate(path, frames, k, measured, ropts)?;
    times.scan = t.elapsed().as_secs_f64();

    let t = Instant::now();
    let v_nom = sliced.process.travel_speed_mm_s;
    let process = &sliced.process.clone();
    let law = process.bead_height_law.anchored(v_nom, path.delta_mm);
    let window = Window {
        law,
        speed_min_mm_s: process.travel_speed_min_mm_s,
        speed_max_mm_s: process.travel_speed_max_mm_s,
    };
    let rebuilt = rebuilt_path(part, &sliced, k, &cols, &window, &scan, v_nom, ropts)?;
    times.rebuild = t.elapsed().as_secs_f64();

    let t = Instant::now();
    let map = crate::path::distance_map(&rebuilt.path);
    let axes = crate::toolaxis::tool_axes(
        &rebuilt.path,
        Some(&part.tube),
        Some(&part.substrate),
        &sliced.tool_axis,
    )
    .map_err(|e| Error::InPart {
        file: part.file.clone(),
        source: Box::new(e.into()),
    })?;
    let process_plan = rebuilt_process(&sliced, &rebuilt, k);
    let all_layers = layer_points(&rebuilt.path, &axes.frames, v_nom);
    let mut remaining: Vec<LayerPoints> = all_layers[k + 1..].to_vec();
    // every remaining point at its corrected speed (nominal where none)
    for (lp, c) in remaining.iter_mut().zip(&rebuilt.corrections) {
        for (p, v) in lp.points.iter_mut().zip(&c.speed_mm_s) {
            p.travel_speed_mm_s = *v;
        }
    }
    times.tool_axes = t.elapsed().as_secs_f64();

    let plan = optimise_remaining(cell, &remaining, &rebuilt, nominal, optimise)?;
    times.optimise = plan.time_s;

    // The program that resumes the build.
    let t = Instant::now();
    let corrections = rebuilt.corrections;
    let name = program_name_for(&part.name, k);
    // the payload of the deposited layers is the one the build resumes with
    let resume_payload = resume_payload(cell, &sliced, k);
    let mut common = cell.program.common;
    if let Some((mass, cog)) = resume_payload {
        common.payload_base_kg = mass;
        common.payload_base_cog_mm = [cog.x, cog.y, cog.z];
    }
    // the corrected speeds (the points') at the process's nominal wire
    // feed: the speed correction changes the height on purpose (SPEC §5:
    // TS modulated at the process's WFS)
    let points = remaining.iter().map(|l| l.points.len()).sum();
    let wire = vec![process.wire_feed_speed_mm_s; points];
    let checked = ProgramBuild {
        name: &name,
        cell,
        layers: &remaining,
        plan: &plan,
        wire_feed_mm_s: &wire,
        common: &common,
        layer_masses_kg: &process_plan.layer_masses_kg(&rebuilt.path, process),
        every_layer: true,
    }
    .build();
    times.program = t.elapsed().as_secs_f64();
    let (program, clearance, cell_check_s) = match checked {
        Ok((p, c, s)) => (Ok(p), Some(c), s),
        Err(e) => (Err(e), None, 0.0),
    };

    let sliced = SlicedPart {
        path: rebuilt.path,
        map,
        axes,
        process_plan,
        ..sliced
    };
    let planned = PlannedPart {
        times: PlanTimes {
            slice: 0.0,
            tool_axes: times.tool_axes,
            optimise: times.optimise,
            program: times.program,
            cell_check: cell_check_s,
        },
        sliced,
        cell: cell.clone(),
        layers: remaining,
        optimise,
        rz,
        format,
        plan,
        program,
        clearance,
        splits: Vec::new(),
        slowed: Vec::new(),
    };
    Ok(ReplannedPart {
        planned,
        after_layer: k,
        scan,
        corrections,
        law,
        law_anchored: process.bead_height_law.b.is_none(),
        speed_window_mm_s: [window.speed_min_mm_s, window.speed_max_mm_s],
        height_window_mm: [window.height_min_mm(), window.height_max_mm()],
        rejoined_at: rebuilt.rejoined_at,
        skipped: (k + 1..=k + rebuilt.skip).collect(),
        dropped_from: rebuilt.ended_at,
        resume_payload,
        times,
    })
}

/// Refuses a path the closed loop cannot replan after layer `k`: a spiral
/// (no layers to replan one by one), or no layer after `k`.
fn check_replannable(path: &crate::path::Path, k: usize) -> Result<(), Error> {
    let nlayers = path.layers.len();
    if path.spiral.is_some() {
        return Err(ReplanError::Unsupported {
            reason: "a spiral path has no layers to replan one by one".into(),
        }
        .into());
    }
    if k + 1 >= nlayers {
        return Err(ReplanError::NothingToReplan {
            after_layer: k,
            layers: nlayers,
        }
        .into());
    }
    Ok(())
}

/// The layers after `K` rebuilt from the scan: the whole path with them
/// (part frame, mm) and what was done to each remaining layer.
struct RebuiltPath {
    /// The nominal path with the rebuilt layers' points (their bead heights
    /// as deltas), the skipped nominal layers taken out and the layers after
    /// them renumbered, the dropped layers cut.
    path: crate::path::Path,
    /// The rebuilt layers (points, speeds, heights).
    layers: Vec<rebuild::RebuiltLayer>,
    /// Per remaining layer, in order.
    corrections: Vec<LayerCorrection>,
    /// Nominal layers skipped after `K`.
    skip: usize,
    /// One past the last remaining layer (the new numbering).
    end: usize,
    /// The first nominal layer dropped (`None`: every layer is kept).
    ended_at: Option<usize>,
    /// The first layer that lands on its nominal layer at every point.
    rejoined_at: Option<usize>,
}

/// Rebuilds the layers after `k` from the measured top (the rebuild that
/// rejoins the nominal layers soonest, [`rebuild_fewest`]) into the new
/// path, and says per remaining layer what was done.
#[allow(clippy::too_many_arguments)]
fn rebuilt_path(
    part: &Part,
    sliced: &SlicedPart,
    k: usize,
    cols: &[Vec<usize>],
    window: &Window,
    scan: &ScanEstimate,
    v_nom: f64,
    ropts: &ReplanOptions,
) -> Result<RebuiltPath, Error> {
    let path = &sliced.path;
    let frames = &sliced.axes.frames;
    let nlayers = path.layers.len();
    let t_meas = rebuild::measured_t(&part.tube, path, frames, k, &scan.error_mm);
    let chosen = rebuild_fewest(part, path, k, cols, &t_meas, window, scan, ropts)?;
    let (rebuilt, ended_at, s) = (chosen.layers, chosen.ended_at, chosen.skip);
    if ended_at == Some(k + 1) {
        return Err(ReplanError::NoRoot {
            layer: k + 1,
            point: 0,
            height_mm: window.height_min_mm(),
            reason: "the measured wall is already at the part's end: nothing remains to lay",
        }
        .into());
    }
    // a wall still too high near the top: the layers from `ended_at` on no
    // longer fit below the part's end and are dropped; the nominal layers
    // K+1..=K+s are skipped, the others renumbered (nominal l + s is layer l)
    let end = ended_at.unwrap_or(nlayers - s);
    let rejoined_at = rebuilt
        .last()
        .filter(|l| l.clamped.iter().all(|c| !c))
        .map(|l| l.layer);
    let mut new_path = path.clone();
    new_path.layers.truncate(end + s);
    new_path.layers.drain(k + 1..k + 1 + s);
    for l in &mut new_path.layers[k + 1..] {
        l.slice -= s;
    }
    let corrections = corrections(path, &new_path, &rebuilt, cols, scan, k, s, end, v_nom);
    // The new path: the corrected layers' points, their heights as deltas.
    for r in &rebuilt {
        for (m, p) in new_path.layers[r.layer].points.iter_mut().enumerate() {
            p.t = r.t[m];
            p.position = r.position[m];
            p.delta = Some(r.height_mm[m]);
        }
    }
    Ok(RebuiltPath {
        path: new_path,
        layers: rebuilt,
        corrections,
        skip: s,
        end,
        ended_at,
        rejoined_at,
    })
}

/// Per remaining layer `k+1..end` (the new numbering, `s` nominal layers
/// skipped): the predicted errors before and after (mm), speeds (mm/s) and
/// heights (mm); a layer not rebuilt keeps the nominal speed `v_nom`.
#[allow(clippy::too_many_arguments)]
fn corrections(
    path: &crate::path::Path,
    new_path: &crate::path::Path,
    rebuilt: &[rebuild::RebuiltLayer],
    cols: &[Vec<usize>],
    scan: &ScanEstimate,
    k: usize,
    s: usize,
    end: usize,
    v_nom: f64,
) -> Vec<LayerCorrection> {
    (k + 1..end)
        .map(|l| {
            let before: Vec<f64> = cols[l + s - k].iter().map(|&c| scan.error_mm[c]).collect();
            match rebuilt.iter().find(|r| r.layer == l) {
                Some(r) => LayerCorrection {
                    layer: l,
                    nominal_layer: r.nominal,
                    corrected: true,
                    speed_mm_s: r.speed_mm_s.clone(),
                    height_mm: r.height_mm.clone(),
                    clamped: r.clamped.clone(),
                    error_before_mm: before,
                    error_after_mm: r.error_after_mm.clone(),
                },
                None => {
                    let pts = &new_path.layers[l].points;
                    LayerCorrection {
                        layer: l,
                        nominal_layer: l + s,
                        corrected: false,
                        speed_mm_s: vec![v_nom; pts.len()],
                        height_mm: pts
                            .iter()
                            .map(|p| p.delta.unwrap_or(path.delta_mm))
                            .collect(),
                        clamped: vec![false; pts.len()],
                        error_before_mm: before,
                        error_after_mm: vec![0.0; pts.len()],
                    }
                }
            }
        })
        .collect()
}

/// The process plan of the new path: the nominal one with the skipped and
/// dropped layers taken out, the rebuilt layers at their corrected speeds
/// (and the bead of each), its estimates recomputed.
fn rebuilt_process(
    sliced: &SlicedPart,
    rebuilt: &RebuiltPath,
    k: usize,
) -> crate::process::ProcessPlan {
    let (s, end) = (rebuilt.skip, rebuilt.end);
    let process = &sliced.process;
    let mut process_plan = sliced.process_plan.clone();
    process_plan.points.truncate(end + s);
    process_plan.points.drain(k + 1..k + 1 + s);
    for r in &rebuilt.layers {
        process_plan.points[r.layer] = r
            .speed_mm_s
            .iter()
            .map(|&v| PointProcess {
                travel_speed_mm_s: v,
                bead: process.bead_at(v),
            })
            .collect();
    }
    let speeds: Vec<Vec<f64>> = process_plan
        .points
        .iter()
        .map(|l| l.iter().map(|p| p.travel_speed_mm_s).collect())
        .collect();
    process_plan.estimates = crate::process::estimate::estimate(
        &rebuilt.path,
        &speeds,
        process.wire_diameter_mm,
        process.wire_feed_speed_mm_s,
        process.density_kg_m3,
    );
    process_plan
}

/// Optimises the remaining layers: the corrected layers at their points'
/// corrected speeds, the others at the nominal speed or as the nominal plan
/// has them when their points are unchanged. The plan's `time_s` is this step's run time (s).
fn optimise_remaining(
    cell: &Cell,
    remaining: &[LayerPoints],
    rebuilt: &RebuiltPath,
    nominal: Option<(&[LayerPoints], &Plan)>,
    optimise: OptimiseOptions,
) -> Result<Plan, Error> {
    let t = Instant::now();
    let s = rebuilt.skip;
    let r_count = rebuilt.layers.len();
    let never = |_: usize, _: usize| true;
    let mut plan_layers =
        optimise_with(&cell.layout, &remaining[..r_count], &optimise, &never)?.layers;
    let rest = &remaining[r_count..];
    let reused: Option<Vec<_>> = nominal.and_then(|(layers, plan)| {
        rest.iter()
            .map(|lp| {
                // the nominal layer it stands for (renumbered after a skip)
                let i = layers.iter().position(|n| n.layer == lp.layer + s)?;
                let same = layers[i].points.len() == lp.points.len()
                    && layers[i].points.iter().zip(&lp.points).all(|(a, b)| {
                        (a.position_mm - b.position_mm).norm() <= 1e-9
                            && (a.tool_axis.into_inner() - b.tool_axis.into_inner()).norm() <= 1e-9
                    });
                let pl = plan.layers.get(i).filter(|p| p.layer == lp.layer + s)?;
                same.then(|| renumbered(pl, lp.layer))
            })
            .collect()
    });
    match reused {
        Some(mut r) => plan_layers.append(&mut r),
        None if !rest.is_empty() => {
            plan_layers.append(&mut optimise_with(&cell.layout, rest, &optimise, &never)?.layers)
        }
        None => {}
    }
    Ok(Plan {
        transitions: crate::optimise::transitions(&cell.layout, &plan_layers),
        layers: plan_layers,
        time_s: t.elapsed().as_secs_f64(),
    })
}

/// The rebuild that rejoins the nominal layers in the fewest layers: the
/// march aimed at `K+1, K+2, ..` and, when `ropts` allows it and the wall
/// stands half a layer high or more somewhere, the marches aimed `s` nominal
/// layers further on, `s` up to the highest point's height in layers
/// (rounded). A skip is taken only when it rejoins in strictly fewer layers
/// (or the march without it never rejoins); a march with a skip that fails
/// or does not rejoin is left aside.
#[allow(clippy::too_many_arguments)]
fn rebuild_fewest(
    part: &Part,
    path: &crate::path::Path,
    k: usize,
    cols: &[Vec<usize>],
    t_meas: &[f64],
    window: &Window,
    scan: &ScanEstimate,
    ropts: &ReplanOptions,
) -> Result<rebuild::Rebuilt, ReplanError> {
    let mut best = rebuild::rebuild(&part.tube, path, k, cols, t_meas, window, 0)?;
    if !ropts.skip_nominal_layers {
        return Ok(best);
    }
    let highest = scan.error_mm.iter().copied().fold(0.0, f64::max);
    let room = path.layers.len().saturating_sub(k + 2);
    let max_skip = ((highest / path.delta_mm).round() as usize).min(room);
    for skip in 1..=max_skip {
        let Ok(r) = rebuild::rebuild(&part.tube, path, k, cols, t_meas, window, skip) else {
            continue;
        };
        if let Some(j) = r.layers_to_rejoin() {
            if best.layers_to_rejoin().is_none_or(|b| j < b) {
                best = r;
            }
        }
    }
    Ok(best)
}

/// A nominal layer's plan as the replanned layer `layer` (renumbered after
/// skipped nominal layers).
fn renumbered(plan: &crate::optimise::LayerPlan, layer: usize) -> crate::optimise::LayerPlan {
    let mut p = plan.clone();
    p.layer = layer;
    for v in &mut p.violations {
        v.layer = layer;
    }
    p
}

/// The payload on the flange when layer `k` is done (part-carried cell with
/// payload updates): the substrate and fixture plus the layers `0..=k`,
/// each at the mean of its points (flange frame). Mass in kg, centre in mm.
fn resume_payload(cell: &Cell, sliced: &SlicedPart, k: usize) -> Option<(f64, Point3)> {
    let CellLayout::PartCarried(c) = &cell.layout else {
        return None;
    };
    let common = &cell.program.common;
    if common.payload_every_layers == 0 {
        return None;
    }
    let masses = sliced
        .process_plan
        .layer_masses_kg(&sliced.path, &sliced.process);
    let mut mass = common.payload_base_kg;
    let mut moment = Vector3::from(common.payload_base_cog_mm) * common.payload_base_kg;
    for (l, m) in masses.iter().enumerate().take(k + 1) {
        let pts = &sliced.path.layers[l].points;
        if pts.is_empty() {
            continue;
        }
        let centre = pts.iter().map(|p| p.position.coords).sum::<Vector3>() / pts.len() as f64;
        moment += (c.flange_from_part * Point3::from(centre)).coords * *m;
        mass += m;
    }
    let cog = if mass > 0.0 {
        Point3::from(moment / mass)
    } else {
        Point3::from(common.payload_base_cog_mm)
    };
    Some((mass, cog))
}
