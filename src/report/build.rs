//! The page's data: checks the input against the path, decimates, computes
//! the fields and the cell at every animation frame, and encodes it all as
//! one JSON object whose arrays are base64 typed arrays.

use super::cell_view::{snapshot, CHAIN_POINTS};

use super::encode::{f32s, i8s, u32s, unit_i8};
use super::page::{
    kept, script_safe_json, stride, BodyData, ClosestData, CollisionData, CornerData, FieldData,
    MarkData, PageData, PlanData,
};
use super::substrate::substrate_triangles;
use super::{PlanView, ReportError, ReportInput};
use crate::math::{Point3, Vector3};
use crate::program::cell_check::{
    arm_outlines, keep_out_outlines, positioner_outlines, BodyOutline, CollisionSummary, PART_NAME,
};
use crate::program::ProgramError;
use crate::robot::CellLayout;

fn check(input: &ReportInput) -> Result<(), ReportError> {
    let path = input.path;
    let o = &input.options;
    for (field, v) in [
        ("max_points", o.max_points),
        ("max_frames", o.max_frames),
        ("max_marks", o.max_marks),
    ] {
        if v < 2 {
            return Err(ReportError::InvalidOption {
                field,
                value: v as f64,
                reason: "must be at least 2",
            });
        }
    }
    if !(input.bead_width_mm > 0.0) || !input.bead_width_mm.is_finite() {
        return Err(ReportError::InvalidOption {
            field: "bead_width_mm",
            value: input.bead_width_mm,
            reason: "must be finite and > 0",
        });
    }
    if path.num_points() == 0 {
        return Err(ReportError::EmptyPath);
    }
    let shape = |what, layer, expected, got, unit| ReportError::Shape {
        what,
        layer,
        expected,
        got,
        unit,
    };
    let per_layer = |what: &'static str, counts: Vec<usize>| -> Result<(), ReportError> {
        if counts.len() != path.layers.len() {
            return Err(shape(what, None, path.layers.len(), counts.len(), "layers"));
        }
        for (l, (layer, got)) in path.layers.iter().zip(counts).enumerate() {
            if got != layer.points.len() {
                return Err(shape(what, Some(l), layer.points.len(), got, "points"));
            }
        }
        Ok(())
    };
    per_layer("frames", input.frames.iter().map(Vec::len).collect())?;
    per_layer(
        "distance map",
        input.map.points.iter().map(Vec::len).collect(),
    )?;
    if let Some(p) = input.process {
        per_layer("process", p.points.iter().map(Vec::len).collect())?;
    }
    if let Some(pv) = &input.plan {
        per_layer(
            "plan layers",
            pv.layers.iter().map(|l| l.points.len()).collect(),
        )?;
        per_layer(
            "plan",
            pv.plan.layers.iter().map(|l| l.points.len()).collect(),
        )?;
        if !(pv.travel_speed_mm_s > 0.0) || !pv.travel_speed_mm_s.is_finite() {
            return Err(ReportError::InvalidOption {
                field: "travel_speed_mm_s",
                value: pv.travel_speed_mm_s,
                reason: "must be finite and > 0",
            });
        }
    }
    for (l, (layer, fr)) in path.layers.iter().zip(input.frames).enumerate() {
        for (i, (p, f)) in layer.points.iter().zip(fr).enumerate() {
            let bad = |what| ReportError::NonFinite {
                what,
                layer: l,
                point: i,
            };
            if !p.position.iter().all(|v| v.is_finite()) {
                return Err(bad("position"));
            }
            for (what, v) in [
                ("tool axis", &f.tool),
                ("surface normal", &f.normal),
                ("build direction", &f.build),
            ] {
                if !v.iter().all(|c| c.is_finite()) {
                    return Err(bad(what));
                }
            }
        }
    }
    Ok(())
}

/// One colour field of the path.
struct Field {
    key: &'static str,
    name: &'static str,
    unit: &'static str,
    /// Diverging fields are coloured symmetrically about zero.
    diverging: bool,
    /// Least half-range of a diverging field's colours (its unit).
    min_half_range: f64,
    values: Vec<f32>,
}

/// A marker on the path: a violation or a process-window problem.
struct Mark {
    layer: usize,
    point: usize,
    text: String,
}

/// Builds the page's data object (JSON text).
pub(crate) fn report_data(input: &ReportInput) -> Result<String, ReportError> {
    check(input)?;
    let path = input.path;
    let total = path.num_points();
    let k = stride(total, input.options.max_points);
    let delta = path.delta_mm;
    let drawn = drawn_points(input, k);
    let (layer_start, pos, tool, normal, build) = (
        drawn.layer_start,
        drawn.pos,
        drawn.tool,
        drawn.normal,
        drawn.build,
    );
    let shown = pos.len() / 3;
    let fields = fields(input, drawn.values);
    let mut marks = marks(input);
    let marks_total = marks.len();
    marks.truncate(input.options.max_marks);

    let mut notes: Vec<String> = vec![];
    if k > 1 {
        notes.push(format!(
            "{total} path points: {shown} drawn (every {k}th point of each layer and its last); hover shows the drawn points' own indices."
        ));
    }
    if marks_total > marks.len() {
        notes.push(format!(
            "{marks_total} violations: the first {} are marked.",
            marks.len()
        ));
    }
    let corners = corners(input);
    if !corners.is_empty() {
        let splits = corners.iter().filter(|c| c.split).count();
        notes.push(format!(
            "{} corners marked on {} layers (orange){}.",
            corners.len(),
            {
                let mut layers: Vec<usize> = corners.iter().map(|c| c.layer).collect();
                layers.dedup();
                layers.len()
            },
            if splits > 0 {
                format!("; the bead is split at {splits} of them (cyan): one bead ends there, the next starts there after an arc-off move")
            } else {
                String::new()
            }
        ));
    }

    let (substrate, substrate_note) = substrate_triangles(input.substrate, &pos);
    if let Some(n) = substrate_note {
        notes.push(n.into());
    }
    let plan = input.plan.as_ref().map(|pv| {
        let (plan, plan_notes) = plan_data(input, pv);
        notes.extend(plan_notes);
        plan
    });
    let data = PageData {
        version: 1,
        title: input.title,
        strategy: path.strategy.name(),
        delta_mm: delta,
        bead_width_mm: input.bead_width_mm,
        points_total: total,
        points_shown: shown,
        stride: k,
        length_mm: path.length_mm(),
        layer_slice: path.layers.iter().map(|l| l.slice).collect(),
        layer_closed: path.layers.iter().map(|l| u8::from(l.closed)).collect(),
        layer_points: path.layers.iter().map(|l| l.points.len()).collect(),
        layer_start: u32s(&layer_start),
        pos: f32s(&pos),
        tool: i8s(&tool),
        normal: i8s(&normal),
        build: i8s(&build),
        fields: fields
            .iter()
            .map(|f| FieldData {
                key: f.key,
                name: f.name,
                unit: f.unit,
                diverging: f.diverging,
                min_half_range: f.min_half_range,
                data: f32s(&f.values),
                mesh: false,
            })
            .collect(),
        substrate: substrate.map(|t| f32s(&t)),
        marks: marks
            .iter()
            .map(|m| {
                let p = path.layers[m.layer].points[m.point].position;
                MarkData {
                    layer: m.layer,
                    point: m.point,
                    text: &m.text,
                    at: [p.x, p.y, p.z],
                }
            })
            .collect(),
        marks_total,
        corners,
        plan,
        notes,
        fit: None,
    };
    script_safe_json(&data)
}

/// The drawn points of the path (every `k`-th point of each layer and its
/// last, part frame): each layer's first drawn point, positions (mm), unit
/// tool, normal and build vectors (× 127), and the colour fields' values.
struct Drawn {
    layer_start: Vec<u32>,
    pos: Vec<f32>,
    tool: Vec<i8>,
    normal: Vec<i8>,
    build: Vec<i8>,
    values: FieldValues,
}

/// Per drawn point, the values of the colour fields (empty when the input
/// has no process or plan for them).
#[derive(Default)]
struct FieldValues {
    /// Interlayer distance − Delta (mm).
    dev: Vec<f32>,
    /// Lean of the tool axis from part Z (deg).
    lean: Vec<f32>,
    /// Travel speed (mm/s).
    speed: Vec<f32>,
    /// `R_Z` (deg).
    rz: Vec<f32>,
    /// Smallest joint-limit margin (deg).
    margin: Vec<f32>,
    /// The build direction's tilt from the vertical in the world (deg;
    /// torch carried).
    tilt: Vec<f32>,
    /// Whether the cell is torch carried (the tilt field is drawn).
    torch_carried: bool,
}

/// The path's points drawn at stride `k`, with their vectors and fields.
fn drawn_points(input: &ReportInput, k: usize) -> Drawn {
    let path = input.path;
    let delta = path.delta_mm;
    let nl = path.layers.len();

    let mut layer_start = Vec::with_capacity(nl + 1);
    let (mut pos, mut tool, mut normal, mut build) = (vec![], vec![], vec![], vec![]);
    let mut v = FieldValues::default();
    let torch_carried = match input.plan.as_ref().map(|pv| pv.cell) {
        Some(CellLayout::TorchCarried(c)) => Some(c),
        _ => None,
    };
    let robot = input.plan.as_ref().map(|pv| pv.cell.robot());
    for (l, layer) in path.layers.iter().enumerate() {
        layer_start.push(u32::try_from(pos.len() / 3).unwrap_or(u32::MAX));
        for i in kept(layer.points.len(), k) {
            let p = &layer.points[i];
            let f = &input.frames[l][i];
            pos.extend([
                p.position.x as f32,
                p.position.y as f32,
                p.position.z as f32,
            ]);
            for (out, v) in [
                (&mut tool, f.tool),
                (&mut normal, f.normal),
                (&mut build, f.build),
            ] {
                let u = v.try_normalize(0.0).unwrap_or_else(Vector3::zeros);
                out.extend([unit_i8(u.x), unit_i8(u.y), unit_i8(u.z)]);
            }
            v.dev.push(match input.map.points[l][i] {
                Some((d, false)) => (d - delta) as f32,
                _ => f32::NAN,
            });
            let t = f.tool.try_normalize(0.0).unwrap_or_else(Vector3::z);
            v.lean.push(t.z.clamp(-1.0, 1.0).acos().to_degrees() as f32);
            if let Some(pr) = input.process {
                v.speed.push(pr.points[l][i].travel_speed_mm_s as f32);
            }
            if let (Some(pv), Some(robot)) = (&input.plan, robot) {
                let pp = &pv.plan.layers[l].points[i];
                v.rz.push(pp.r_z.to_degrees() as f32);
                v.margin.push(match pp.joints {
                    Some(q) => limit_margin_rad(robot, &q).to_degrees() as f32,
                    None => f32::NAN,
                });
                if let Some(c) = torch_carried {
                    let cp = &pv.layers[l].points[i];
                    v.tilt.push(match pp.positioner.or(cp.positioner) {
                        Some(e) => c.build_tilt(cp, &e).to_degrees() as f32,
                        None => f32::NAN,
                    });
                }
            }
        }
    }
    layer_start.push(u32::try_from(pos.len() / 3).unwrap_or(u32::MAX));
    v.torch_carried = torch_carried.is_some();
    Drawn {
        layer_start,
        pos,
        tool,
        normal,
        build,
        values: v,
    }
}

/// The colour fields of the path's page, from their values per drawn point.
fn fields(input: &ReportInput, v: FieldValues) -> Vec<Field> {
    let delta = input.path.delta_mm;
    let mut fields = vec![
        Field {
            key: "deviation",
            name: "interlayer distance − Delta",
            unit: "mm",
            diverging: true,
            // 2 % of Delta: a constant-distance path's rounding noise stays neutral
            min_half_range: 0.02 * delta,
            values: v.dev,
        },
        Field {
            key: "lean",
            name: "lean of the tool axis from part Z",
            unit: "deg",
            diverging: false,
            min_half_range: 0.0,
            values: v.lean,
        },
    ];
    if input.process.is_some() {
        fields.push(Field {
            key: "speed",
            name: "travel speed",
            unit: "mm/s",
            diverging: false,
            min_half_range: 0.0,
            values: v.speed,
        });
    }
    if input.plan.is_some() {
        fields.push(Field {
            key: "rz",
            name: "R_Z (free angle about the tool axis)",
            unit: "deg",
            diverging: false,
            min_half_range: 0.0,
            values: v.rz,
        });
        fields.push(Field {
            key: "margin",
            name: "smallest joint-limit margin",
            unit: "deg",
            diverging: false,
            min_half_range: 0.0,
            values: v.margin,
        });
        if v.torch_carried {
            fields.push(Field {
                key: "tilt",
                name: "build direction from the vertical (positioner)",
                unit: "deg",
                diverging: false,
                min_half_range: 0.0,
                values: v.tilt,
            });
        }
    }
    fields
}

/// The layers' corners of the page ([`ReportInput::corners`]), those naming
/// a point of the path, with their hover text.
fn corners(input: &ReportInput) -> Vec<CornerData> {
    input
        .corners
        .iter()
        .filter_map(|c| {
            let p = input
                .path
                .layers
                .get(c.layer)?
                .points
                .get(c.point)?
                .position;
            let mut text = format!(
                "layer {}, point {}: corner, turning {:.1}°",
                c.layer, c.point, c.turning_deg
            );
            if c.on_seam {
                text += ", on the seam";
            }
            if c.split {
                text += "; the bead is split here";
            }
            Some(CornerData {
                layer: c.layer,
                point: c.point,
                split: c.split,
                text,
                at: [p.x, p.y, p.z],
            })
        })
        .collect()
}

/// The marks of the path's page: the plan's violations, a collision
/// refusal, the process window's violations; only those naming a point of
/// the path.
fn marks(input: &ReportInput) -> Vec<Mark> {
    let path = input.path;
    let mut marks: Vec<Mark> = vec![];
    if let Some(pv) = &input.plan {
        marks.extend(pv.plan.violations().map(|v| Mark {
            layer: v.layer,
            point: v.point,
            text: v.to_string(),
        }));
    }
    // a collision refusal marks its point (the layer's first for a home move)
    if let Some(pv) = &input.plan {
        if let Some(e @ ProgramError::Collision { layer, point, .. }) = pv.refusal {
            if let Some(l) = pv.layers.iter().position(|lp| lp.layer == *layer) {
                let n = path.layers[l].points.len();
                marks.push(Mark {
                    layer: l,
                    point: point.unwrap_or(0).min(n.saturating_sub(1)),
                    text: format!("collision: {e}"),
                });
            }
        }
    }
    if let Some(pr) = input.process {
        marks.extend(pr.violations.iter().map(|v| Mark {
            layer: v.layer,
            point: v.point,
            text: format!(
                "layer {}, point {}: travel speed window: {:?} (local distance {:.3} mm{})",
                v.layer,
                v.point,
                v.side,
                v.delta_mm,
                v.needed_mm_s
                    .map(|s| format!(", needs {s:.2} mm/s"))
                    .unwrap_or_default()
            ),
        }));
    }
    // A mark names a point of the path; anything else is dropped (counted).
    marks.retain(|m| {
        path.layers
            .get(m.layer)
            .is_some_and(|l| m.point < l.points.len())
    });
    marks
}

/// Smallest distance of `q` to its joint limits (rad; negative outside),
/// unlimited joints left out; `+inf` if every joint is unlimited.
pub(crate) fn limit_margin_rad(robot: &crate::robot::model::RobotModel, q: &[f64; 6]) -> f64 {
    robot
        .limits
        .iter()
        .zip(q)
        .filter(|(l, _)| !l.is_unlimited())
        .map(|(l, v)| (v - l.lower_rad).min(l.upper_rad - v))
        .fold(f64::INFINITY, f64::min)
}

/// The plan part of the data: cell, limits and the cell at every frame.
fn plan_data<'a>(input: &ReportInput<'a>, pv: &PlanView<'a>) -> (PlanData<'a>, Vec<String>) {
    let total: usize = pv.layers.iter().map(|l| l.points.len()).sum();
    let k = stride(total, input.options.max_frames);
    let robot = pv.cell.robot();
    // The clock: time under the arc along every point (and across layer
    // changes) at the process speed of the point, else the travel speed.
    let speed_at = |l: usize, i: usize| -> f64 {
        input
            .process
            .map(|p| p.points[l][i].travel_speed_mm_s)
            .filter(|v| *v > 0.0 && v.is_finite())
            .unwrap_or(pv.travel_speed_mm_s)
    };
    let (mut f_layer, mut f_point, mut f_time, mut f_rz) = (vec![], vec![], vec![], vec![]);
    let (mut f_joints, mut f_chain, mut f_torch, mut f_table, mut f_part) =
        (vec![], vec![], vec![], vec![], vec![]);
    // the check's bodies: the arm's capsules and the table move, the tilt
    // body and the keep-out boxes do not
    let q0 = [0.0; 6];
    let mut moving_bodies = arm_outlines(robot, &q0);
    let mut fixed_bodies: Vec<BodyOutline> = Vec::new();
    if let CellLayout::TorchCarried(c) = pv.cell {
        let [table, tilt] = positioner_outlines(c, &[0.0, 0.0]);
        moving_bodies.push(table);
        fixed_bodies.push(tilt);
    }
    fixed_bodies.extend(keep_out_outlines(pv.keep_out));
    let arm_bodies = arm_outlines(robot, &q0).len();
    let mut f_bodies: Vec<f32> = vec![];
    let mut clock = 0.0;
    let mut prev: Option<Point3> = None;
    let mut g = 0usize;
    let last = total.saturating_sub(1);
    let mut q8_hint = 0.0;
    for (l, (lp, pl)) in pv.layers.iter().zip(&pv.plan.layers).enumerate() {
        for (i, (cp, pp)) in lp.points.iter().zip(&pl.points).enumerate() {
            if let Some(p0) = prev {
                clock += (cp.position_mm - p0).norm() / speed_at(l, i);
            }
            prev = Some(cp.position_mm);
            if let Some(e) = pp.positioner {
                q8_hint = e[1];
            }
            if g % k == 0 || g == last {
                f_layer.push(l as u32);
                f_point.push(i as u32);
                f_time.push(clock as f32);
                f_rz.push(pp.r_z.to_degrees() as f32);
                let q = pp.joints;
                for j in 0..6 {
                    f_joints.push(q.map_or(f32::NAN, |q| q[j].to_degrees() as f32));
                }
                for j in 0..2 {
                    f_joints.push(pp.positioner.map_or(f32::NAN, |e| e[j].to_degrees() as f32));
                }
                let positioner = pp.positioner.or_else(|| match pv.cell {
                    // without a planned positioner pose, turn it as the cell would
                    CellLayout::TorchCarried(c) => c.positioner_angles(cp, q8_hint).ok(),
                    CellLayout::PartCarried(_) => None,
                });
                let s = snapshot(pv.cell, q.as_ref(), positioner.as_ref(), cp, pp.r_z);
                match s.chain {
                    Some(c) => c
                        .iter()
                        .for_each(|p| f_chain.extend([p.x as f32, p.y as f32, p.z as f32])),
                    None => f_chain.extend([f32::NAN; 3 * CHAIN_POINTS]),
                }
                for p in s.torch {
                    f_torch.extend([p.x as f32, p.y as f32, p.z as f32]);
                }
                match s.positioner {
                    Some((c7, c8, n)) => {
                        for v in [c7.coords, c8.coords, n] {
                            f_table.extend([v.x as f32, v.y as f32, v.z as f32]);
                        }
                    }
                    None => f_table.extend([f32::NAN; 9]),
                }
                // the moving bodies in the order of `moving_bodies`: the arm's
                // capsules (NaN without joints), the table (NaN without a pose)
                let mut put = |o: Option<&BodyOutline>| match o {
                    Some(o) => {
                        f_bodies.extend([o.a, o.b].iter().flat_map(|p| p.iter().map(|v| *v as f32)))
                    }
                    None => f_bodies.extend([f32::NAN; 6]),
                };
                let arm = q.map(|q| arm_outlines(robot, &q));
                for k in 0..arm_bodies {
                    put(arm.as_ref().and_then(|a| a.get(k)));
                }
                if let CellLayout::TorchCarried(c) = pv.cell {
                    let table = positioner.as_ref().map(|e| positioner_outlines(c, e));
                    put(table.as_ref().map(|[t, _]| t));
                }
                match s.base_from_part {
                    Some(t) => {
                        let r = t.rotation.to_rotation_matrix();
                        // column-major 3×3, then the translation
                        f_part.extend(r.matrix().iter().map(|v| *v as f32));
                        f_part.extend(t.translation.vector.iter().map(|v| *v as f32));
                    }
                    None => f_part.extend([f32::NAN; 12]),
                }
            }
            g += 1;
        }
    }
    let frames = f_layer.len();
    let span =
        |l: &crate::robot::model::JointLimit| [l.lower_rad.to_degrees(), l.upper_rad.to_degrees()];
    let mut limits_deg: Vec<[f64; 2]> = robot.limits.iter().map(span).collect();
    if let CellLayout::TorchCarried(c) = pv.cell {
        limits_deg.extend(c.positioner.limits.iter().map(span));
    }
    let g = &robot.geometry;
    let data = PlanData {
        cell_kind: match pv.cell {
            CellLayout::PartCarried(_) => "part carried",
            CellLayout::TorchCarried(_) => "torch carried",
        },
        cell: pv.cell.name(),
        robot: &robot.name,
        reach_mm: g.upper_arm_mm + g.forearm_mm + g.wrist_to_flange_mm,
        limits_deg,
        max_hose_deg: match pv.cell {
            CellLayout::TorchCarried(c) => Some(c.max_hose_torsion_rad.to_degrees()),
            CellLayout::PartCarried(_) => None,
        },
        feasible: pv.plan.is_feasible(),
        infeasible_layers: pv.plan.infeasible_layers().map(|l| l.layer).collect(),
        frames,
        points_total: total,
        frame_stride: k,
        duration_s: f_time.last().map_or(0.0, |t| f64::from(*t)),
        cycle_time_s: pv.cycle.map(|c| c.total_s),
        cycle_layers: pv
            .cycle
            .map(|c| c.layers.iter().map(|l| l.layer).collect())
            .unwrap_or_default(),
        cycle_layer_s: pv
            .cycle
            .map(|c| c.layers.iter().map(|l| l.total_s).collect())
            .unwrap_or_default(),
        f_layer: u32s(&f_layer),
        f_point: u32s(&f_point),
        f_time: f32s(&f_time),
        f_rz: f32s(&f_rz),
        f_joints: f32s(&f_joints),
        f_chain: f32s(&f_chain),
        f_torch: f32s(&f_torch),
        f_table: f32s(&f_table),
        f_part: f32s(&f_part),
        bodies: moving_bodies
            .into_iter()
            .map(|o| body_data(o, true))
            .chain(fixed_bodies.into_iter().map(|o| body_data(o, false)))
            .collect(),
        f_bodies: f32s(&f_bodies),
        closest: closest_per_layer(pv),
        collision: collision_data(pv),
        part_body: PART_NAME,
    };
    let mut notes = vec![];
    if k > 1 {
        notes.push(format!(
            "{total} planned points: the animation shows {frames} of them (every {k}th and the last)."
        ));
    }
    (data, notes)
}

fn body_data(o: BodyOutline, moving: bool) -> BodyData {
    let xyz = |p: Point3| [p.x, p.y, p.z];
    BodyData {
        name: o.name,
        kind: o.kind,
        radius_mm: o.radius_mm,
        moving,
        a: (!moving).then(|| xyz(o.a)),
        b: (!moving).then(|| xyz(o.b)),
    }
}

/// The whole-cell check's closest approach and pair of every layer of the
/// plan, in the plan's order (empty without a check).
pub(crate) fn closest_per_layer(pv: &PlanView) -> Vec<ClosestData> {
    let Some(c) = pv.clearance else {
        return Vec::new();
    };
    pv.layers
        .iter()
        .map(|l| {
            let lc = c.layers.iter().find(|lc| lc.layer == l.layer);
            ClosestData {
                layer: l.layer,
                distance_mm: lc
                    .map(|lc| lc.closest_approach_mm)
                    .filter(|d| d.is_finite()),
                pair: lc
                    .and_then(|lc| lc.closest_pair.clone())
                    .map(|(a, b)| [a, b]),
            }
        })
        .collect()
}

fn collision_data(pv: &PlanView) -> Option<CollisionData> {
    let e = pv.refusal?;
    let c = CollisionSummary::of(e)?;
    let [body_a, body_b] = c.bodies;
    Some(CollisionData {
        layer_index: pv.layers.iter().position(|l| l.layer == c.layer),
        layer: c.layer,
        point: c.point,
        motion: c.motion,
        body_a,
        body_b,
        distance_mm: c.distance_mm,
        clearance_mm: c.clearance_mm,
        text: e.to_string(),
    })
}
