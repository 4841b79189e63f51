//! Per-point data as numpy arrays: each array is one Rust buffer handed to
//! numpy without a copy (no per-point Python object), marked read-only so
//! that the object that holds it keeps describing the plan it came from.

use numpy::ndarray::{Array1, Array2, Dimension};
use numpy::{Element, PyArray, PyArray1, PyArray2};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use super::waam_error;

/// `a`, made read-only.
fn read_only<T: Element, D: Dimension>(a: Bound<'_, PyArray<T, D>>) -> PyResult<Py<PyArray<T, D>>> {
    let kw = PyDict::new(a.py());
    kw.set_item("write", false)?;
    a.call_method("setflags", (), Some(&kw))?;
    Ok(a.unbind())
}

/// An `(N, width)` float64 array from `values` (row-major, `N * width` long).
pub(crate) fn matrix(
    py: Python<'_>,
    values: Vec<f64>,
    width: usize,
) -> PyResult<Py<PyArray2<f64>>> {
    let rows = values.len() / width.max(1);
    let a = Array2::from_shape_vec((rows, width), values).map_err(waam_error)?;
    read_only(PyArray2::from_owned_array(py, a))
}

/// An `(N,)` float64 array.
pub(crate) fn floats(py: Python<'_>, values: Vec<f64>) -> PyResult<Py<PyArray1<f64>>> {
    read_only(PyArray1::from_owned_array(py, Array1::from_vec(values)))
}

/// An `(N,)` int64 array.
pub(crate) fn ints(py: Python<'_>, values: Vec<i64>) -> PyResult<Py<PyArray1<i64>>> {
    read_only(PyArray1::from_owned_array(py, Array1::from_vec(values)))
}
