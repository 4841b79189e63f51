//! `PlacedCell`: the result of `Part.place` — whether a placement was found,
//! the placed cell (ready for `Part.plan`), its cell-file text, the values
//! found and the search's account, and writing `placement.json` and
//! `cell.toml`.

use std::path::PathBuf;

use pyo3::prelude::*;
use pyo3::types::PyDict;

use super::cell::PyCell;
use super::{io_error, json_to_py};
use crate::pipeline::PlacedCell;

/// A part placed in a cell (or the search's account of why it cannot be).
#[pyclass(frozen, name = "PlacedCell", module = "waam_slicer")]
pub(crate) struct PyPlacedCell {
    placed: PlacedCell,
    cell: Py<PyCell>,
}

impl PyPlacedCell {
    pub fn new(py: Python<'_>, placed: PlacedCell) -> PyResult<Self> {
        let cell = Py::new(
            py,
            PyCell {
                cell: placed.cell.clone(),
            },
        )?;
        Ok(Self { placed, cell })
    }
}

#[pymethods]
impl PyPlacedCell {
    /// `True` when a placement makes every layer feasible and the program
    /// stage accepts the plan.
    #[getter]
    fn feasible(&self) -> bool {
        self.placed.placement.feasible
    }

    /// The placed cell (the best candidate when none was found), as
    /// `Cell.from_toml(toml)` reads it: pass it to `Part.plan`.
    #[getter]
    fn cell(&self, py: Python<'_>) -> Py<PyCell> {
        self.cell.clone_ref(py)
    }

    /// The complete cell file of the placed cell (TOML text, with the
    /// margins achieved in its header comment).
    #[getter]
    fn toml(&self) -> &str {
        &self.placed.toml
    }

    /// The constraint that bound when no placement was found (with the
    /// share of candidates or layers it bound), None when found.
    #[getter]
    fn binding(&self) -> Option<String> {
        self.placed
            .placement
            .binding
            .as_ref()
            .map(|b| format!("{b} ({:.0} %)", 100.0 * b.share()))
    }

    /// The placement variables: name → value found, in mm or degrees (the
    /// unit is in `summary()["variables"]`).
    #[getter]
    fn values<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        let p = &self.placed.placement;
        for (v, x) in self
            .placed
            .bounds
            .variables
            .iter()
            .zip(p.values.in_table_order(&p.cell))
        {
            d.set_item(v.name, if v.angle { x.to_degrees() } else { x })?;
        }
        Ok(d)
    }

    /// The content of `placement.json`: bounds, values given and found,
    /// margins before and after, candidates, rounds, phase times.
    fn summary<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        json_to_py(py, &self.placed.summary())
    }

    /// Writes `placement.json` and, when a placement was found, `cell.toml`
    /// into `dir` (created if missing), each atomically; returns the paths.
    fn write(&self, py: Python<'_>, dir: PathBuf) -> PyResult<Vec<PathBuf>> {
        py.detach(|| self.placed.write(&dir)).map_err(io_error)
    }

    fn __repr__(&self) -> String {
        format!(
            "PlacedCell({:?}, feasible={})",
            self.placed.cell.name,
            if self.placed.placement.feasible {
                "True"
            } else {
                "False"
            }
        )
    }
}
