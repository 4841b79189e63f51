//! `Part`: a part file, read and validated once, and the long calls on a
//! part (`slice`, `plan`, `place`).

use std::path::PathBuf;

use pyo3::prelude::*;

use super::cell::PyCell;
use super::control::{HostControl, SliceKeywords};
use super::placed::PyPlacedCell;
use super::planned::PyPlannedPart;
use super::sliced::PySlicedPart;
use super::{json_to_py, stage_error, waam_error};
use crate::pipeline::{Part, PlaceRequest, PlanOptions, RzLaw};

/// A tube to build: geometry, substrate and the part file's slicing,
/// tool-axis and process settings. Part frame, mm.
#[pyclass(frozen, name = "Part", module = "waam_slicer")]
pub(crate) struct PyPart {
    pub part: Part,
    /// The fit, when the part was fitted to a mesh (`Part.from_mesh`).
    pub fitted: Option<crate::FittedPart>,
}

#[pymethods]
impl PyPart {
    /// Reads and validates a part file (TOML).
    #[staticmethod]
    fn read(path: PathBuf) -> PyResult<Self> {
        Ok(Self {
            part: Part::read(&path).map_err(stage_error)?,
            fitted: None,
        })
    }

    /// Parses part-file text; `name` stands for the file in messages, and
    /// relative paths in the text are resolved from its folder.
    #[staticmethod]
    #[pyo3(signature = (text, name = "<string>"))]
    fn from_toml(text: &str, name: &str) -> PyResult<Self> {
        Ok(Self {
            part: Part::from_toml_str(text, name).map_err(stage_error)?,
            fitted: None,
        })
    }

    /// Fits a part to a tubular mesh (binary or ASCII STL, in `units`): a spline
    /// guide and a radius law from end to end (and the wall thickness when
    /// the mesh holds both skins), a flat substrate at the start end
    /// (`start`: `"lowest"`, `"highest"`, `"capped"` or a point `(x, y, z)`);
    /// `units`: the mesh's length unit, `"mm"` (default), `"cm"`, `"m"` or
    /// `"in"`; every other length, and the fit, is in mm. `trim=True` fits
    /// the longest tubular stretch of a mesh with features that are not
    /// tube (collars, flanges, blocks, tabs) and names them in the report's
    /// `features`. The other keywords are `FitOptions`' fields. Releases the
    /// GIL.
    #[staticmethod]
    #[pyo3(signature = (path, *, units = None, start = None, max_rms_mm = None, template = None, name = None,
        station_spacing_mm = None, knot_spacing_mm = None, check_surface = None, trim = None))]
    #[allow(clippy::too_many_arguments)]
    fn from_mesh(
        py: Python<'_>,
        path: PathBuf,
        units: Option<String>,
        start: Option<Bound<'_, PyAny>>,
        max_rms_mm: Option<f64>,
        template: Option<PathBuf>,
        name: Option<String>,
        station_spacing_mm: Option<f64>,
        knot_spacing_mm: Option<f64>,
        check_surface: Option<bool>,
        trim: Option<bool>,
    ) -> PyResult<Self> {
        let mut opts = crate::FitOptions::default();
        if let Some(u) = units {
            opts.units = u
                .parse()
                .map_err(|e: String| waam_error(format!("units: {e}")))?;
        }
        if let Some(s) = start {
            opts.start = match s.extract::<String>() {
                Ok(text) => text
                    .parse()
                    .map_err(|e: String| waam_error(format!("start: {e}")))?,
                Err(_) => {
                    let p: (f64, f64, f64) = s.extract().map_err(|_| {
                        waam_error("start: expected \"lowest\", \"highest\", \"capped\" or a point (x, y, z)")
                    })?;
                    crate::StartEnd::Near([p.0, p.1, p.2])
                }
            };
        }
        if let Some(x) = max_rms_mm {
            opts.max_rms_mm = x;
        }
        opts.template = template;
        opts.name = name;
        opts.station_spacing_mm = station_spacing_mm;
        opts.knot_spacing_mm = knot_spacing_mm;
        if let Some(c) = check_surface {
            opts.check_surface = c;
        }
        if let Some(t) = trim {
            opts.trim = t;
        }
        let fitted = py
            .detach(|| Part::from_mesh(&path, &opts))
            .map_err(stage_error)?;
        Ok(Self {
            part: fitted.part.clone(),
            fitted: Some(fitted),
        })
    }

    /// The fit report as a dict (the `fit.json` of `waam fit`), or `None`
    /// for a part read from a file.
    #[getter]
    fn fit_report<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyAny>>> {
        match &self.fitted {
            Some(f) => {
                let v = serde_json::to_value(f.report()).map_err(waam_error)?;
                Ok(Some(json_to_py(py, &v)?))
            }
            None => Ok(None),
        }
    }

    /// Writes `part.toml` and `fit.json` of a fitted part into `out`
    /// (created if missing); returns their paths. Raises `InputError` for a
    /// part that was not fitted.
    fn write_fit(&self, out: PathBuf) -> PyResult<Vec<PathBuf>> {
        let f = self.fitted.as_ref().ok_or_else(|| {
            waam_error("write_fit: this part was not fitted to a mesh (Part.from_mesh)")
        })?;
        f.write(&out).map_err(stage_error)
    }

    /// The part's name (the file's `name`).
    #[getter]
    fn name(&self) -> &str {
        &self.part.name
    }

    /// The file it was read from, as given.
    #[getter]
    fn file(&self) -> &str {
        &self.part.file
    }

    fn __repr__(&self) -> String {
        format!("Part({:?}, file={:?})", self.part.name, self.part.file)
    }

    /// Slices the part with its file's settings and the keyword overrides:
    /// path, distances, tool axes, process. Releases the GIL.
    #[pyo3(signature = (*, strategy = None, delta_mm = None, points = None, chord_mm = None,
        max_layers = None, travel_speed_mm_s = None, progress = None))]
    #[allow(clippy::too_many_arguments)]
    fn slice(
        &self,
        py: Python<'_>,
        strategy: Option<String>,
        delta_mm: Option<f64>,
        points: Option<i64>,
        chord_mm: Option<f64>,
        max_layers: Option<i64>,
        travel_speed_mm_s: Option<f64>,
        progress: Option<Py<PyAny>>,
    ) -> PyResult<PySlicedPart> {
        let overrides = SliceKeywords {
            strategy,
            delta_mm,
            points,
            chord_mm,
            max_layers,
            travel_speed_mm_s,
        }
        .overrides()?;
        let host = HostControl::new(progress);
        let control = &host.control;
        let result =
            py.detach(|| crate::pipeline::slice_part_with(&self.part, &overrides, control));
        PySlicedPart::new(py, host.finish(result)?)
    }

    /// Replans the layers after `after_layer` (K) from the measured top of
    /// layer K: `measured` is a scan file (CSV with the header `x,y,z` or
    /// `layer,point,dh_mm`) or an (N, 3) array of points of the deposited
    /// top, part frame, mm. Corrects the next layers' travel speeds (and
    /// their geometry where the speed window cannot absorb the error),
    /// optimises them in `cell` and returns the plan of the remaining
    /// layers: `write_program` writes the program that resumes the build,
    /// `summary()["replan"]` gives the outliers and per layer the predicted
    /// error before and after. A scan of another layer or part raises
    /// `InputError` naming the distance. Releases the GIL.
    #[pyo3(signature = (cell, measured, *, after_layer, delta_mm = None, points = None,
        chord_mm = None, rz = None, max_layers = None))]
    #[allow(clippy::too_many_arguments)]
    fn replan(
        &self,
        py: Python<'_>,
        cell: &PyCell,
        measured: &Bound<'_, PyAny>,
        after_layer: i64,
        delta_mm: Option<f64>,
        points: Option<i64>,
        chord_mm: Option<f64>,
        rz: Option<&str>,
        max_layers: Option<i64>,
    ) -> PyResult<PyPlannedPart> {
        use crate::replan::Measured;
        let measured = if let Ok(path) = measured.extract::<PathBuf>() {
            Measured::read(&path).map_err(stage_error)?
        } else {
            let rows: Vec<Vec<f64>> = measured.extract().map_err(|_| {
                waam_error("measured: expected a scan file path or an (N, 3) array of points (mm)")
            })?;
            let mut pts = Vec::with_capacity(rows.len());
            for (i, r) in rows.iter().enumerate() {
                match r[..] {
                    [x, y, z] if x.is_finite() && y.is_finite() && z.is_finite() => {
                        pts.push(crate::math::Point3::new(x, y, z))
                    }
                    _ => {
                        return Err(waam_error(format!(
                            "measured row {i}: expected 3 finite numbers (x, y, z in mm)"
                        )))
                    }
                }
            }
            Measured::Points(pts)
        };
        let after_layer = usize::try_from(after_layer)
            .map_err(|_| waam_error(format!("after_layer = {after_layer}: must be >= 0")))?;
        let slice = SliceKeywords {
            strategy: None,
            delta_mm,
            points,
            chord_mm,
            max_layers,
            travel_speed_mm_s: None,
        }
        .overrides()?;
        let rz = match rz {
            None => RzLaw::default(),
            Some(s) => s
                .parse()
                .map_err(|e| waam_error(format!("rz = {s:?}: {e}")))?,
        };
        let opts = PlanOptions {
            slice,
            ..PlanOptions::default()
        }
        .with_rz(rz);
        let result = py.detach(|| {
            crate::replan::replan_part(&self.part, &cell.cell, &measured, after_layer, &opts)
        });
        PyPlannedPart::from_replan(py, result.map_err(stage_error)?)
    }

    /// Plans the part in `cell`: slice, tool axes, layer-by-layer `R_Z`
    /// optimisation, joint trajectory, program model. An infeasible layer
    /// is data (`feasible`, `violations`), not an exception. Releases the GIL.
    /// `positioner`: `"optimised"` (default) or `"vertical"` (the thesis's
    /// exact vertical), torch-carried cells.
    #[pyo3(signature = (cell, *, delta_mm = None, points = None, chord_mm = None, strategy = None,
        rz = None, travel_speed_mm_s = None, max_layers = None, progress = None, positioner = None,
        format = None))]
    #[allow(clippy::too_many_arguments)]
    fn plan(
        &self,
        py: Python<'_>,
        cell: &PyCell,
        delta_mm: Option<f64>,
        points: Option<i64>,
        chord_mm: Option<f64>,
        strategy: Option<String>,
        rz: Option<&str>,
        travel_speed_mm_s: Option<f64>,
        max_layers: Option<i64>,
        progress: Option<Py<PyAny>>,
        positioner: Option<&str>,
        format: Option<&str>,
    ) -> PyResult<PyPlannedPart> {
        use crate::optimise::positioner::{PositionerMode, PositionerOptions};
        let mode = match positioner {
            None | Some("optimised") => PositionerMode::Optimised,
            Some("vertical") => PositionerMode::Vertical,
            Some(other) => {
                return Err(waam_error(format!(
                    "positioner = {other:?}: expected \"optimised\" or \"vertical\""
                )))
            }
        };
        let slice = SliceKeywords {
            strategy,
            delta_mm,
            points,
            chord_mm,
            max_layers,
            travel_speed_mm_s,
        }
        .overrides()?;
        let rz = match rz {
            None => RzLaw::default(),
            Some(s) => s
                .parse()
                .map_err(|e| waam_error(format!("rz = {s:?}: {e}")))?,
        };
        let format = match format {
            None => None,
            Some(s) => Some(
                s.parse::<crate::robot::Vendor>()
                    .map_err(|e| waam_error(format!("format = {s:?}: {e}")))?,
            ),
        };
        let host = HostControl::new(progress);
        let mut opts = PlanOptions {
            slice,
            format,
            ..PlanOptions::default()
        }
        .with_rz(rz);
        opts.optimise.positioner = PositionerOptions {
            mode,
            ..PositionerOptions::default()
        };
        let result = py.detach(|| {
            crate::pipeline::plan_part_with(&self.part, &cell.cell, &opts, &host.control)
        });
        PyPlannedPart::new(py, host.finish(result)?)
    }

    /// Searches where the part should sit in `cell` (the deposition point
    /// and the part's mount when the arm carries it, the positioner's pose
    /// and the part's offset on the table (within 150 mm of the turn axis
    /// unless `[placement]` says otherwise) when it carries the torch;
    /// fixture tilt, other offsets and rotations and torch clamp when the
    /// cell file's `[placement]` table gives their ranges) so that every
    /// layer is feasible with the widest margins; the cell as given is kept
    /// when it is as good. `samples`: candidates of the global screening
    /// (default 64); `half_box_mm`: half-width of the box searched around
    /// the cell's placement when its file has no `[placement]` bounds
    /// (default 400). A part no placement makes feasible is a `PlacedCell`
    /// with `feasible` False and `binding` naming why, not an exception.
    /// Releases the GIL.
    #[pyo3(signature = (cell, *, delta_mm = None, points = None, chord_mm = None,
        travel_speed_mm_s = None, samples = None, half_box_mm = None))]
    #[allow(clippy::too_many_arguments)]
    fn place(
        &self,
        py: Python<'_>,
        cell: &PyCell,
        delta_mm: Option<f64>,
        points: Option<i64>,
        chord_mm: Option<f64>,
        travel_speed_mm_s: Option<f64>,
        samples: Option<i64>,
        half_box_mm: Option<f64>,
    ) -> PyResult<PyPlacedCell> {
        let slice = SliceKeywords {
            delta_mm,
            points,
            chord_mm,
            travel_speed_mm_s,
            ..SliceKeywords::default()
        }
        .overrides()?;
        let mut req = PlaceRequest {
            slice,
            ..PlaceRequest::default()
        };
        if let Some(n) = samples {
            req.search.samples = usize::try_from(n)
                .ok()
                .filter(|n| *n >= 1)
                .ok_or_else(|| waam_error(format!("samples = {n}: must be at least 1")))?;
        }
        if let Some(h) = half_box_mm {
            if !(h.is_finite() && h > 0.0) {
                return Err(waam_error(format!(
                    "half_box_mm = {h}: must be positive and finite"
                )));
            }
            req.half_box_mm = Some(h);
        }
        let result = py.detach(|| crate::pipeline::place_part(&self.part, &cell.cell, &req));
        PyPlacedCell::new(py, result.map_err(stage_error)?)
    }
}
