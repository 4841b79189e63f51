//! Placing a part in a cell in one call: slices the part, searches the
//! cell's placement variables within the cell file's `[placement]` bounds
//! (the placement stage, [`crate::place`]) with the program stage's check,
//! and gives a complete cell file with the placement found
//! ([`crate::io::cell_file::placed_cell_file`]), which [`Cell::read`] and
//! [`plan_part`](super::plan_part) accept unchanged.

use std::f64::consts::PI;

use super::summary::{
    BindingSummary, InfeasibleLayerSummary, KeepOutSummary, PlacementSummary,
    PlacementVariableSummary,
};
use super::{slice_part_with, Cell, Part, SliceOverrides};
use crate::io::cell_file::placed_cell_file;
use crate::optimise::{layer_points, ConfigurationChoice, OptimiseError, OptimiseOptions};
use crate::place::{place_with, PlaceOptions, Placement, PlacementBounds};
use crate::Error;

/// Half-width (mm) of the box searched around a cell's placement when its
/// file gives no `[placement]` bounds and the request none either.
pub const DEFAULT_HALF_BOX_MM: f64 = 400.0;

/// What to place and how hard to search: what the caller sets, nothing
/// replaced. The optimiser plans each candidate at the process's travel
/// speed (from the part file and [`PlaceRequest::slice`]) with the cell's
/// own IK branch choice.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct PlaceRequest {
    /// Overrides of the part file's settings (Delta, points, travel speed…).
    pub slice: SliceOverrides,
    /// The search's settings.
    pub search: PlaceOptions,
    /// Half-width (mm) of the box searched around the cell's placement when
    /// its file gives no `[placement]` bounds; `None` takes
    /// [`DEFAULT_HALF_BOX_MM`].
    pub half_box_mm: Option<f64>,
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
    // Fixture and torch mount: the table's range where it gives one (the
    // cell file reader has checked them and their cell kind), else the
    // default's (the offset on a torch-carried cell's table searched, the
    // rest kept).
    let part_carried = matches!(cell.layout, crate::robot::CellLayout::PartCarried(_));
    let extra = [
        (4, spec.tilt_x_deg, true),
        (5, spec.tilt_y_deg, true),
        (6, spec.offset_mm.filter(|_| part_carried), false),
        (6, spec.torch_rotation_deg.filter(|_| !part_carried), true),
        (7, spec.offset_x_mm, false),
        (8, spec.offset_y_mm, false),
        (9, spec.fixture_rotation_deg.filter(|_| !part_carried), true),
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
/// Bad input: the part's or overrides' ([`Error::InPart`]), the bounds' or
/// the request's ([`Error::Optimise`] naming the variable or
/// `half_box_mm`); the cell file's text when it cannot be rewritten. A part
/// no placement makes feasible is a [`PlacedCell`] whose
/// `placement.feasible` is `false`.
pub fn place_part(part: &Part, cell: &Cell, req: &PlaceRequest) -> Result<PlacedCell, Error> {
    let half = match req.half_box_mm {
        None => DEFAULT_HALF_BOX_MM,
        Some(h) if h.is_finite() && h > 0.0 => h,
        Some(h) => {
            return Err(OptimiseError::InvalidPlacement {
                field: "half_box_mm".into(),
                reason: format!("{h}: must be positive and finite"),
            }
            .into())
        }
    };
    let bounds = placement_bounds(cell, half)?;
    let sliced = slice_part_with(part, &req.slice.for_cell(part, cell), &Default::default())?;
    let layers = layer_points(
        &sliced.path,
        &sliced.axes.frames,
        sliced.process.travel_speed_mm_s,
    );
    let optimise = OptimiseOptions {
        configuration: ConfigurationChoice::Cell,
        ..OptimiseOptions::default()
    };
    // A candidate feasible on every layer must also pass the program stage
    // (the arc-off transits against the deposited wall, the set-up), as
    // `plan` will check it. On the screening subsample the whole-cell check
    // leaves out the motions between beads: they join layers far apart,
    // motions the build never makes (certification checks every one).
    let name = super::program_name(&part.name);
    let every_layer = layers.len();
    let accept = |layout: &crate::robot::CellLayout,
                  layers: &[crate::optimise::LayerPoints],
                  plan: &crate::optimise::Plan| {
        let c = Cell {
            layout: layout.clone(),
            ..cell.clone()
        };
        let whole_build = layers.len() == every_layer;
        super::planned::build(&name, &c, &sliced, layers, plan, &[], whole_build).map(|_| ())
    };
    let placement = place_with(
        &cell.layout,
        &layers,
        &bounds,
        &req.search,
        &optimise,
        &accept,
    )?;
    let toml = placed_cell_file(&cell.text, &cell.file, &placement, &bounds)?;
    let mut placed = Cell::from_toml_str(&toml, &cell.file)?;
    placed.file = cell.file.clone();
    Ok(PlacedCell {
        placement,
        bounds,
        cell: placed,
        toml,
    })
}

impl PlacedCell {
    /// The content of `placement.json`: the bounds, the values found, the
    /// margins before and after, candidates, feasible fraction, binding
    /// constraint and time (s); `serde_json::to_value` gives the JSON.
    pub fn summary(&self) -> PlacementSummary {
        let p = &self.placement;
        let variables = self
            .bounds
            .variables
            .iter()
            .zip(p.values.in_table_order(&p.cell))
            .map(|(v, x)| {
                let k = if v.angle { 180.0 / PI } else { 1.0 };
                PlacementVariableSummary {
                    name: v.name,
                    unit: if v.angle { "deg" } else { "mm" },
                    lower: v.lower * k,
                    upper: v.upper * k,
                    given: v.current * k,
                    found: x * k,
                }
            })
            .collect();
        PlacementSummary {
            feasible: p.feasible,
            variables,
            keep_out: self
                .bounds
                .keep_out
                .map(|(min_mm, max_mm)| KeepOutSummary { min_mm, max_mm }),
            margins: p.margins,
            margins_before: p.margins_before,
            candidates: p.candidates,
            certified: p.certified,
            rounds: p.rounds,
            stopped_on: p.stopped_on.as_ref().map(ToString::to_string),
            subsample_layers: p.subsample_layers.0,
            subsample_layers_full: p.subsample_layers.1,
            times: p.times,
            feasible_fraction: p.feasible_fraction,
            binding: p.binding.as_ref().map(|b| BindingSummary {
                constraint: b.to_string(),
                share: b.share(),
            }),
            infeasible_layers: p
                .plan
                .infeasible_layers()
                .map(|l| InfeasibleLayerSummary {
                    layer: l.layer,
                    status: l.status.to_string(),
                })
                .collect(),
            time_s: p.time_s,
        }
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
