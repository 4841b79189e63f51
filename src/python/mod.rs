//! **The Python extension module `waam_slicer`** (feature `python`, built by
//! maturin from `pyproject.toml`). Wraps the front door ([`crate::pipeline`])
//! for Python hosts: `Part.read` / `Cell.read`, `Part.slice` → `SlicedPart`,
//! `Part.plan` → `PlannedPart` (`write_program`), `Part.place` →
//! `PlacedCell` (`cell`, `write`), `check_program`. Per-point
//! data are numpy arrays built from one Rust buffer each (no per-point Python
//! object): positions in the part frame (mm), joints in degrees, controller
//! convention. Slicing, planning, writing and checking run with the GIL
//! released. Bad input raises `WaamError` (a `ValueError`) carrying the
//! library's message (file, field, layer or point); writing an infeasible
//! plan raises `InfeasiblePlan`. The type stubs are `waam_slicer.pyi` at the
//! repository root.

mod arrays;
mod cell;
mod control;
mod part;
mod placed;
mod planned;
mod sliced;

use std::path::PathBuf;

use pyo3::create_exception;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;

create_exception!(
    waam_slicer,
    WaamError,
    PyValueError,
    "Bad input or a failed stage: the message names the file, field, layer or point."
);
create_exception!(
    waam_slicer,
    InfeasiblePlan,
    WaamError,
    "A program was asked of a plan with an infeasible layer."
);

/// The library's error as a Python `WaamError`, its message unchanged.
pub(crate) fn waam_error(e: impl std::fmt::Display) -> PyErr {
    WaamError::new_err(e.to_string())
}

/// A `serde_json` value (a summary) as Python objects, through `json.loads`.
pub(crate) fn json_to_py<'py>(
    py: Python<'py>,
    value: &serde_json::Value,
) -> PyResult<Bound<'py, PyAny>> {
    let text = serde_json::to_string(value).map_err(waam_error)?;
    py.import("json")?.call_method1("loads", (text,))
}

/// Reads the program at `path` (FANUC `.ls` main program and the programs it
/// calls, KUKA `.src`/`.dat`, ABB `.mod`) and checks it against `cell`:
/// joint limits, speeds, reachability, configuration, beads. Returns every
/// problem as a dict (`file`, `line`, `kind`, `message`; `kind` as
/// `ProblemKind::name`, e.g. `joint_limit`), `[]` when clean.
#[pyfunction]
fn check_program<'py>(
    py: Python<'py>,
    path: PathBuf,
    cell: &cell::PyCell,
) -> PyResult<Vec<Bound<'py, PyDict>>> {
    let report = py
        .detach(|| crate::pipeline::check_program(&path, &cell.cell))
        .map_err(waam_error)?;
    report
        .problems
        .iter()
        .map(|p| {
            let d = PyDict::new(py);
            d.set_item("file", &p.file)?;
            d.set_item("line", p.line)?;
            d.set_item("kind", p.kind.name())?;
            d.set_item("message", &p.message)?;
            Ok(d)
        })
        .collect()
}

/// The module: classes, exceptions and functions.
#[pymodule]
fn waam_slicer(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add("WaamError", py.get_type::<WaamError>())?;
    m.add("InfeasiblePlan", py.get_type::<InfeasiblePlan>())?;
    m.add_class::<part::PyPart>()?;
    m.add_class::<cell::PyCell>()?;
    m.add_class::<sliced::PySlicedPart>()?;
    m.add_class::<planned::PyPlannedPart>()?;
    m.add_class::<placed::PyPlacedCell>()?;
    m.add_function(wrap_pyfunction!(check_program, m)?)?;
    Ok(())
}
