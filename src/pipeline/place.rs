//! Placing a part in a cell in one call: slices the part, searches the
//! cell's placement variables within the cell file's `[placement]` bounds
//! ([`crate::optimise::place`]) and gives a complete cell file with the
//! placement found, which [`Cell::read`] and [`plan_part`](super::plan_part)
//! accept unchanged.

use std::f64::consts::PI;

use serde_json::{json, Value};

use super::{slice_part_with, Cell, Part, SliceOverrides};
use crate::optimise::place::{place_with, PlaceOptions, Placement, PlacementBounds, Refusal};
use crate::optimise::{layer_points, ConfigurationChoice, OptimiseError};
use crate::robot::orientation::FanucPose;
use crate::Error;

/// What to place and how hard to search.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct PlaceRequest {
    /// Overrides of the part file's settings (Delta, points, travel speed…).
    pub slice: SliceOverrides,
    /// The search's settings; its `optimise.travel_speed_mm_s` is replaced by
    /// the process's travel speed.
    pub search: PlaceOptions,
    /// Half-width (mm) of the box searched around the cell's placement when
    /// its file gives no `[placement]` bounds; 0 takes the default, 400 mm.
    pub half_box_mm: f64,
}

/// A placed cell: the search's account and the cell file to write.
#[derive(Debug, Clone)]
pub struct PlacedCell {
    /// The search's result (values, margins, candidates, full plan).
    pub placement: Placement,
    /// The bounds searched (mm, rad).
    pub bounds: PlacementBounds,
    /// The placed cell, as [`Cell::from_toml_str`] reads `toml`.
    pub cell: Cell,
    /// A complete cell file: the original's text (comments, key order and
    /// layout kept) with the placement's values, the bounds searched as its
    /// `[placement]` table, and a header comment giving the margins achieved.
    pub toml: String,
}

/// The bounds of `cell`'s `[placement]` table, or a box of `half_box_mm`
/// around its placement.
///
/// # Errors
/// [`OptimiseError::InvalidPlacement`] naming the variable.
pub fn placement_bounds(cell: &Cell, half_box_mm: f64) -> Result<PlacementBounds, OptimiseError> {
    let mut b = PlacementBounds::around(&cell.layout, half_box_mm);
    let Some(spec) = &cell.placement else {
        b.validate()?;
        return Ok(b);
    };
    if let (Some(lo), Some(hi)) = (spec.min_mm, spec.max_mm) {
        for k in 0..3 {
            b.variables[k].lower = lo[k];
            b.variables[k].upper = hi[k];
        }
    }
    if let Some([lo, hi]) = spec.rotation_deg {
        b.variables[3].lower = lo.to_radians();
        b.variables[3].upper = hi.to_radians();
    }
    for f in &spec.fixed {
        let k = ["x", "y", "z", "rotation"]
            .iter()
            .position(|n| n == f)
            .ok_or_else(|| OptimiseError::InvalidPlacement {
                field: format!("fixed: {f}"),
                reason: "expected x, y, z or rotation".into(),
            })?;
        b.variables[k].lower = b.variables[k].current;
        b.variables[k].upper = b.variables[k].current;
    }
    if let (Some(lo), Some(hi)) = (spec.keep_out_min_mm, spec.keep_out_max_mm) {
        b.keep_out = Some((lo, hi));
    }
    // Fixture and torch mount: searched only when the table gives a range
    // (the cell file reader has checked them and their cell kind).
    let part_carried = matches!(cell.layout, crate::robot::Cell::PartCarried(_));
    let extra = [
        (4, spec.tilt_x_deg, true),
        (5, spec.tilt_y_deg, true),
        (6, spec.offset_mm.filter(|_| part_carried), false),
        (6, spec.torch_rotation_deg.filter(|_| !part_carried), true),
    ];
    for (k, range, degrees) in extra {
        if let Some([lo, hi]) = range {
            let f = if degrees { lo.to_radians() } else { lo };
            let g = if degrees { hi.to_radians() } else { hi };
            b.variables[k].lower = f;
            b.variables[k].upper = g;
        }
    }
    b.validate()?;
    Ok(b)
}

/// Places `part` in `cell` (see the module doc).
///
/// # Errors
/// Bad input: the part's or overrides' ([`Error::InPart`]), the bounds'
/// ([`Error::Optimise`] naming the variable); the cell file's text when it
/// cannot be rewritten. A part no placement makes feasible is a
/// [`PlacedCell`] whose `placement.feasible` is `false`.
pub fn place_part(part: &Part, cell: &Cell, req: &PlaceRequest) -> Result<PlacedCell, Error> {
    let half = if req.half_box_mm > 0.0 {
        req.half_box_mm
    } else {
        400.0
    };
    let bounds = placement_bounds(cell, half)?;
    let sliced = slice_part_with(part, &req.slice, &Default::default())?;
    let layers = layer_points(&sliced.path, &sliced.axes.frames);
    let mut search = req.search.clone();
    search.optimise.travel_speed_mm_s = sliced.process.travel_speed_mm_s;
    search.optimise.configuration = ConfigurationChoice::Cell;
    // A candidate feasible on every layer must also pass the program stage
    // (the arc-off transits against the deposited wall, the set-up), as
    // `plan` will check it.
    let name = super::program_name(&part.name);
    let accept = |layout: &crate::robot::Cell,
                  layers: &[crate::optimise::LayerPoints],
                  plan: &crate::optimise::Plan| {
        let c = Cell {
            layout: layout.clone(),
            ..cell.clone()
        };
        super::planned::build(&name, &c, &sliced, layers, plan, &search.optimise)
            .map(|_| ())
            .map_err(|e| {
                let reason = e.to_string();
                Refusal {
                    layers: layers_named(&reason),
                    reason,
                }
            })
    };
    let placement = place_with(&cell.layout, &layers, &bounds, &search, &accept)?;
    let toml = placed_toml(cell, &placement, &bounds)?;
    let mut placed = Cell::from_toml_str(&toml, &cell.file)?;
    placed.file = cell.file.clone();
    Ok(PlacedCell {
        placement,
        bounds,
        cell: placed,
        toml,
    })
}

/// The layer numbers a program-stage message names (`layer 80: … to layer
/// 81's approach`): every `layer N` in it.
fn layers_named(message: &str) -> Vec<usize> {
    let mut out = Vec::new();
    for (i, _) in message.match_indices("layer ") {
        let digits: String = message[i + 6..]
            .chars()
            .take_while(char::is_ascii_digit)
            .collect();
        if let Ok(n) = digits.parse() {
            if !out.contains(&n) {
                out.push(n);
            }
        }
    }
    out
}

fn toml_error(cell: &Cell, message: String) -> Error {
    crate::io::cell_file::CellFileError::Syntax {
        path: cell.file.clone(),
        message,
    }
    .into()
}

/// The cell file's text with the placement's values and the bounds searched:
/// the original's comments, key order and layout kept (toml_edit), only the
/// placement keys rewritten and the `[placement]` table's keys replaced.
fn placed_toml(cell: &Cell, p: &Placement, bounds: &PlacementBounds) -> Result<String, Error> {
    use toml_edit::{value, Array, DocumentMut, Item, Table};
    let mut doc: DocumentMut = cell
        .text
        .parse()
        .map_err(|e: toml_edit::TomlError| toml_error(cell, e.to_string()))?;
    let arr = |v: &[f64]| {
        let mut a: Array = v.iter().map(|x| round6(*x)).collect();
        a.fmt();
        value(a)
    };
    let table = |doc: &mut DocumentMut, name: &str| -> Result<Table, Error> {
        match doc.get(name).and_then(Item::as_table) {
            Some(t) => Ok(t.clone()),
            None => Err(toml_error(cell, format!("no [{name}] table"))),
        }
    };
    match &p.cell {
        crate::robot::Cell::PartCarried(c) => {
            let mut t = table(&mut doc, "part_carried")?;
            t["deposition_point_mm"] = arr(c.deposition_point_mm.coords.as_slice());
            if p.values[3..].iter().any(|v| *v != 0.0) || t.contains_key("flange_from_part_xyzwpr")
            {
                let pose = FanucPose::from_isometry(&c.flange_from_part).to_xyzwpr_deg();
                t["flange_from_part_xyzwpr"] = arr(&pose);
            }
            doc["part_carried"] = Item::Table(t);
        }
        crate::robot::Cell::TorchCarried(c) => {
            let mut t = table(&mut doc, "torch_carried")?;
            let pose = FanucPose::from_isometry(&c.base_from_positioner).to_xyzwpr_deg();
            t["positioner_pose_xyzwpr"] = arr(&pose);
            if p.values[4..6].iter().any(|v| *v != 0.0) || t.contains_key("table_from_part_xyzwpr")
            {
                let pose = FanucPose::from_isometry(&c.table_from_part).to_xyzwpr_deg();
                t["table_from_part_xyzwpr"] = arr(&pose);
            }
            if p.values[6] != 0.0 {
                let pose = FanucPose::from_isometry(&c.flange_from_tcp).to_xyzwpr_deg();
                t["tool_xyzwpr"] = arr(&pose);
            }
            doc["torch_carried"] = Item::Table(t);
        }
    }
    // The bounds searched, around the original placement, so that placing
    // again from this file searches the same box. An existing [placement]
    // table keeps its place and comments; its keys are replaced.
    let v = &bounds.variables;
    let mut spec = doc
        .get("placement")
        .and_then(Item::as_table)
        .cloned()
        .unwrap_or_default();
    spec.clear();
    spec["min_mm"] = arr(&[v[0].lower, v[1].lower, v[2].lower]);
    spec["max_mm"] = arr(&[v[0].upper, v[1].upper, v[2].upper]);
    let (lo, hi) = (v[3].lower - p.values[3], v[3].upper - p.values[3]);
    // The rotation is relative to the mount written above.
    let span = (hi - lo).min(2.0 * PI);
    spec["rotation_deg"] = arr(&[lo.to_degrees(), (lo + span).to_degrees()]);
    // Fixture and torch mount ranges, relative to the mount written above
    // (exact for one free tilt axis; with both, placing again searches a
    // slightly different box about the found mount).
    let part_carried = matches!(p.cell, crate::robot::Cell::PartCarried(_));
    let extra = [
        (4, "tilt_x_deg", true),
        (5, "tilt_y_deg", true),
        (
            6,
            if part_carried {
                "offset_mm"
            } else {
                "torch_rotation_deg"
            },
            !part_carried,
        ),
    ];
    for (k, key, degrees) in extra {
        if v[k].is_free() {
            let (lo, hi) = (v[k].lower - p.values[k], v[k].upper - p.values[k]);
            let r = if degrees {
                [lo.to_degrees(), hi.to_degrees()]
            } else {
                [lo, hi]
            };
            spec[key] = arr(&r);
        }
    }
    let fixed: Array = ["x", "y", "z", "rotation"]
        .iter()
        .zip(v)
        .filter(|(_, var)| var.lower == var.upper)
        .map(|(n, _)| *n)
        .collect();
    if !fixed.is_empty() {
        spec["fixed"] = value(fixed);
    }
    if let Some((lo, hi)) = bounds.keep_out {
        spec["keep_out_min_mm"] = arr(&lo);
        spec["keep_out_max_mm"] = arr(&hi);
    }
    doc["placement"] = Item::Table(spec);
    let body = doc.to_string();
    // A file placed before starts with our header: not repeated.
    let body = strip_placed_header(&body);
    let m = &p.margins;
    let b = &p.margins_before;
    Ok(format!(
        "# Placed by waam place from {} ({}).\n\
         # Worst-layer margins after: {:.2} deg from a joint stop, speed headroom {:.1} %, dexterity {:.4}, {:.1} mm inside the arm's reach, {} infeasible layer(s).\n\
         # Before (on the search's subsample of layers and points): {:.2} deg, {:.1} %, {:.4}, {:.1} mm, {} infeasible layer(s).\n\
         # Candidates {}, feasible on the subsample {:.0} %, certified on the full path {}, {:.1} s.\n{body}",
        cell.file,
        if p.feasible { "feasible" } else { "NOT feasible" },
        m.joint_limit_deg,
        100.0 * m.speed_headroom,
        m.dexterity,
        m.reach_mm,
        m.infeasible_layers,
        b.joint_limit_deg,
        100.0 * b.speed_headroom,
        b.dexterity,
        b.reach_mm,
        b.infeasible_layers,
        p.candidates,
        100.0 * p.feasible_fraction,
        p.certified,
        p.time_s,
    ))
}

/// The first lines of the comment [`placed_toml`] puts at the top.
const PLACED_HEADER: [&str; 4] = [
    "# Placed by waam place ",
    "# Worst-layer margins after: ",
    "# Before (on the search's subsample",
    "# Candidates ",
];

/// `text` without the header [`placed_toml`] puts first (a cell file placed
/// again keeps one header, the new one, and the original's own comments).
fn strip_placed_header(text: &str) -> &str {
    let mut rest = text;
    while PLACED_HEADER.iter().any(|h| rest.starts_with(h)) {
        rest = rest.split_once('\n').map_or("", |(_, r)| r);
    }
    rest
}

fn round6(x: f64) -> f64 {
    let r = (x * 1e6).round() / 1e6;
    if r == 0.0 {
        0.0
    } else {
        r
    }
}

impl PlacedCell {
    /// The content of `placement.json`: the bounds, the values found, the
    /// margins before and after, candidates, feasible fraction, binding
    /// constraint and time (s).
    pub fn summary(&self) -> Value {
        let p = &self.placement;
        json!({
            "feasible": p.feasible,
            "variables": self.bounds.variables.iter().zip(&p.values).map(|(v, x)| {
                let deg = v.angle;
                let k = if deg { 180.0 / PI } else { 1.0 };
                json!({
                    "name": v.name,
                    "unit": if deg { "deg" } else { "mm" },
                    "lower": v.lower * k,
                    "upper": v.upper * k,
                    "given": v.current * k,
                    "found": x * k,
                })
            }).collect::<Vec<_>>(),
            "keep_out": self.bounds.keep_out.map(|(a, b)| json!({"min_mm": a, "max_mm": b})),
            "margins": p.margins,
            "margins_before": p.margins_before,
            "candidates": p.candidates,
            "certified": p.certified,
            "rounds": p.rounds,
            "stopped_on": p.stopped_on,
            "subsample_layers": p.subsample_layers.0,
            "subsample_layers_full": p.subsample_layers.1,
            "times": p.times,
            "feasible_fraction": p.feasible_fraction,
            "binding": p.binding.as_ref().map(|(c, share)| json!({"constraint": c, "share": share})),
            "infeasible_layers": p.plan.infeasible_layers().map(|l| json!({"layer": l.layer, "status": l.status.to_string()})).collect::<Vec<_>>(),
            "time_s": p.time_s,
        })
    }
}

impl PlacedCell {
    /// Writes `placement.json` ([`PlacedCell::summary`]) and, when a
    /// placement was found, `cell.toml` ([`PlacedCell::toml`]) into `dir`
    /// (created if missing), each atomically; returns the paths written.
    ///
    /// # Errors
    /// The I/O error, its message naming the file.
    pub fn write(&self, dir: &std::path::Path) -> std::io::Result<Vec<std::path::PathBuf>> {
        let named = |path: &std::path::Path| {
            let path = path.display().to_string();
            move |e: std::io::Error| std::io::Error::new(e.kind(), format!("{path}: {e}"))
        };
        std::fs::create_dir_all(dir).map_err(named(dir))?;
        let json = dir.join("placement.json");
        crate::io::atomic::write_atomic(&json, |w| {
            serde_json::to_writer_pretty(&mut *w, &self.summary())
                .map_err(std::io::Error::other)?;
            writeln!(w)
        })
        .map_err(named(&json))?;
        let mut written = vec![json];
        if self.placement.feasible {
            let toml = dir.join("cell.toml");
            crate::io::atomic::write_atomic(&toml, |w| w.write_all(self.toml.as_bytes()))
                .map_err(named(&toml))?;
            written.push(toml);
        }
        Ok(written)
    }
}

#[cfg(test)]
mod tests {
    use super::layers_named;

    #[test]
    fn layers_named_reads_every_layer_number_of_a_program_message() {
        let m = "refusing to write a program for an infeasible plan: 1 violation(s), first: \
                 layer 80: the arc-off joint move to layer 81's approach passes 2.0 mm into the wall";
        assert_eq!(layers_named(m), vec![80, 81]);
        assert_eq!(
            layers_named("layer 85: the arc-off joint move to home"),
            vec![85]
        );
        assert!(layers_named("no layers here, layer x").is_empty());
    }
}
