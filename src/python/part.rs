//! `Part` and `Cell`: a part file and a cell file, read and validated once,
//! and the two long calls on a part (`slice`, `plan`).

use std::path::PathBuf;

use pyo3::prelude::*;

use super::control::{HostControl, SliceKeywords};
use super::planned::PyPlannedPart;
use super::sliced::PySlicedPart;
use super::waam_error;
use crate::pipeline::{Cell, Part, PlanOptions, RzLaw};

/// A tube to build: geometry, substrate and the part file's slicing,
/// tool-axis and process settings. Part frame, mm.
#[pyclass(frozen, name = "Part", module = "waam_slicer")]
pub(crate) struct PyPart {
    pub part: Part,
}

#[pymethods]
impl PyPart {
    /// Reads and validates a part file (TOML).
    #[staticmethod]
    fn read(path: PathBuf) -> PyResult<Self> {
        Ok(Self {
            part: Part::read(&path).map_err(waam_error)?,
        })
    }

    /// Parses part-file text; `name` stands for the file in messages, and
    /// relative paths in the text are resolved from its folder.
    #[staticmethod]
    #[pyo3(signature = (text, name = "<string>"))]
    fn from_toml(text: &str, name: &str) -> PyResult<Self> {
        Ok(Self {
            part: Part::from_toml_str(text, name).map_err(waam_error)?,
        })
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

    /// Plans the part in `cell`: slice, tool axes, layer-by-layer `R_Z`
    /// optimisation, joint trajectory, program model. An infeasible layer
    /// is data (`feasible`, `violations`), not an exception. Releases the GIL.
    #[pyo3(signature = (cell, *, delta_mm = None, points = None, chord_mm = None, strategy = None,
        rz = None, travel_speed_mm_s = None, max_layers = None, progress = None))]
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
    ) -> PyResult<PyPlannedPart> {
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
        let host = HostControl::new(progress);
        let opts = PlanOptions {
            slice,
            rz,
            format: None,
            control: host.control.clone(),
        };
        let result = py.detach(|| crate::pipeline::plan_part(&self.part, &cell.cell, &opts));
        PyPlannedPart::new(py, host.finish(result)?)
    }
}

/// A robot cell: the robot and its layout (part carried under a fixed
/// torch, or torch carried over a positioner). Robot base frame, mm.
#[pyclass(frozen, name = "Cell", module = "waam_slicer")]
pub(crate) struct PyCell {
    pub cell: Cell,
}

#[pymethods]
impl PyCell {
    /// Reads and validates a cell file (TOML).
    #[staticmethod]
    fn read(path: PathBuf) -> PyResult<Self> {
        Ok(Self {
            cell: Cell::read(&path).map_err(waam_error)?,
        })
    }

    /// Parses cell-file text; `name` stands for the file in messages.
    #[staticmethod]
    #[pyo3(signature = (text, name = "<string>"))]
    fn from_toml(text: &str, name: &str) -> PyResult<Self> {
        Ok(Self {
            cell: Cell::from_toml_str(text, name).map_err(waam_error)?,
        })
    }

    /// The cell's name (the file's `name`).
    #[getter]
    fn name(&self) -> &str {
        &self.cell.name
    }

    /// The file it was read from, as given.
    #[getter]
    fn file(&self) -> &str {
        &self.cell.file
    }

    /// The program format of the robot's controller: `fanuc`, `kuka` or `abb`.
    #[getter]
    fn vendor(&self) -> &'static str {
        self.cell.native_format().name()
    }

    /// `True` when the torch is carried over a positioner: planned joints
    /// then have 8 columns.
    #[getter]
    fn has_positioner(&self) -> bool {
        matches!(self.cell.layout, crate::robot::Cell::TorchCarried(_))
    }

    fn __repr__(&self) -> String {
        format!(
            "Cell({:?}, file={:?}, vendor={:?})",
            self.cell.name,
            self.cell.file,
            self.vendor()
        )
    }
}
