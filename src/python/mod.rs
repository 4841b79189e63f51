//! **The Python extension module `waam_slicer`** (feature `python`, built by
//! maturin from `pyproject.toml`). Wraps the front door ([`crate::pipeline`])
//! for Python hosts: `Part.read` / `Cell.read`, `Part.slice` → `SlicedPart`,
//! `Part.plan` → `PlannedPart` (`write_program`), `Part.place` →
//! `PlacedCell` (`cell`, `write`), `check_program`. Per-point
//! data are numpy arrays built from one Rust buffer each (no per-point Python
//! object): positions in the part frame (mm), joints in degrees, controller
//! convention. Slicing, planning, writing and checking run with the GIL
//! released. Errors raise a subclass of `WaamError` by their kind
//! ([`crate::ErrorKind`]), each carrying the library's message (file, field,
//! layer or point): `InputError` (also a `ValueError`) for bad input,
//! `InfeasiblePlan` for a program asked of an infeasible plan, `Cancelled`
//! when the host stopped the run, `WaamIOError` (also an `OSError`) for a
//! file that cannot be read or written. The type stubs are
//! `waam_slicer.pyi` at the repository root.

mod arrays;
mod cell;
mod control;
mod part;
mod placed;
mod planned;
mod sliced;

use std::path::PathBuf;

use pyo3::create_exception;
use pyo3::exceptions::{PyException, PyOSError, PyValueError};
use pyo3::prelude::*;
use pyo3::sync::PyOnceLock;
use pyo3::types::{PyDict, PyTuple, PyType};

use crate::ErrorKind;

create_exception!(
    waam_slicer,
    WaamError,
    PyException,
    "Any error of the library: the message names the file, field, layer or point."
);
create_exception!(
    waam_slicer,
    InfeasiblePlan,
    WaamError,
    "A program was asked of a plan with an infeasible layer (an answer, not bad input)."
);
create_exception!(
    waam_slicer,
    Cancelled,
    WaamError,
    "The host stopped the run (a cancel flag, or an exception in the progress callback)."
);

/// `InputError(WaamError, ValueError)` and `WaamIOError(WaamError,
/// OSError)`: two bases each, made with Python's `type` when the module
/// loads (pyo3's exceptions have one base).
static TWO_BASED: PyOnceLock<[Py<PyType>; 2]> = PyOnceLock::new();

fn two_based(py: Python<'_>) -> PyResult<&[Py<PyType>; 2]> {
    TWO_BASED.get_or_try_init(py, || {
        let make = |name: &str, other: Bound<'_, PyType>, doc: &str| -> PyResult<Py<PyType>> {
            let dict = PyDict::new(py);
            dict.set_item("__doc__", doc)?;
            dict.set_item("__module__", "waam_slicer")?;
            let bases = PyTuple::new(py, [py.get_type::<WaamError>(), other])?;
            let t = py
                .import("builtins")?
                .getattr("type")?
                .call1((name, bases, dict))?;
            Ok(t.cast_into::<PyType>()?.unbind())
        };
        Ok([
            make(
                "InputError",
                py.get_type::<PyValueError>(),
                "Bad input: a part or cell file's field, a keyword, a program file; the message names it.",
            )?,
            make(
                "WaamIOError",
                py.get_type::<PyOSError>(),
                "A file could not be read or written (missing, permissions, disk); the message names it.",
            )?,
        ])
    })
}

/// The exception of `kind` with `message`.
fn raise(kind: ErrorKind, message: String) -> PyErr {
    Python::attach(|py| {
        let two = match two_based(py) {
            Ok(t) => t,
            Err(e) => return e,
        };
        match kind {
            ErrorKind::Input => PyErr::from_type(two[0].bind(py).clone(), message),
            ErrorKind::Io => PyErr::from_type(two[1].bind(py).clone(), message),
            ErrorKind::Infeasible => InfeasiblePlan::new_err(message),
            ErrorKind::Cancelled => Cancelled::new_err(message),
        }
    })
}

/// Bad input named by the binding itself (a keyword's value): `InputError`.
pub(crate) fn waam_error(e: impl std::fmt::Display) -> PyErr {
    raise(ErrorKind::Input, e.to_string())
}

/// A file that could not be written: `WaamIOError`.
pub(crate) fn io_error(e: std::io::Error) -> PyErr {
    raise(ErrorKind::Io, e.to_string())
}

/// The library's error as the `WaamError` subclass of its kind, its
/// message unchanged.
pub(crate) fn stage_error(e: impl Into<crate::Error>) -> PyErr {
    let e = e.into();
    raise(e.kind(), e.to_string())
}

/// A summary (any serialisable value) as Python objects, through its JSON
/// (keys sorted, as the CLI writes it) and `json.loads`.
pub(crate) fn json_to_py<'py>(
    py: Python<'py>,
    value: &impl serde::Serialize,
) -> PyResult<Bound<'py, PyAny>> {
    let value = serde_json::to_value(value).map_err(waam_error)?;
    let text = serde_json::to_string(&value).map_err(waam_error)?;
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
        .map_err(stage_error)?;
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
    m.add("Cancelled", py.get_type::<Cancelled>())?;
    let [input, io] = two_based(py)?;
    m.add("InputError", input.bind(py))?;
    m.add("WaamIOError", io.bind(py))?;
    m.add_class::<part::PyPart>()?;
    m.add_class::<cell::PyCell>()?;
    m.add_class::<sliced::PySlicedPart>()?;
    m.add_class::<planned::PyPlannedPart>()?;
    m.add_class::<placed::PyPlacedCell>()?;
    m.add_function(wrap_pyfunction!(check_program, m)?)?;
    Ok(())
}
