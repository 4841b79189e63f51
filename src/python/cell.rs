//! `Cell`: a cell file, read and validated once — what `Part.plan` and
//! `Part.place` take and `PlacedCell.cell` gives.

use std::path::PathBuf;

use pyo3::prelude::*;

use super::stage_error;
use crate::pipeline::Cell;

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
            cell: Cell::read(&path).map_err(stage_error)?,
        })
    }

    /// Parses cell-file text; `name` stands for the file in messages.
    #[staticmethod]
    #[pyo3(signature = (text, name = "<string>"))]
    fn from_toml(text: &str, name: &str) -> PyResult<Self> {
        Ok(Self {
            cell: Cell::from_toml_str(text, name).map_err(stage_error)?,
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
        self.cell.native_format().key()
    }

    /// `True` when the torch is carried over a positioner: planned joints
    /// then have 8 columns.
    #[getter]
    fn has_positioner(&self) -> bool {
        matches!(self.cell.layout, crate::robot::CellLayout::TorchCarried(_))
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
