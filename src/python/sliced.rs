//! `SlicedPart`: a sliced part's points, layers, local interlayer distances
//! and tool axes as numpy arrays (part frame, mm), and its summary.

use numpy::{PyArray1, PyArray2};
use pyo3::prelude::*;

use super::{arrays, json_to_py};
use crate::pipeline::SlicedPart;

/// A sliced part: every point of the path in deposition order.
#[pyclass(frozen, name = "SlicedPart", module = "waam_slicer")]
pub(crate) struct PySlicedPart {
    sliced: SlicedPart,
    points: Py<PyArray2<f64>>,
    layer: Py<PyArray1<i64>>,
    delta: Py<PyArray1<f64>>,
    tool_axis: Py<PyArray2<f64>>,
}

impl PySlicedPart {
    pub fn new(py: Python<'_>, sliced: SlicedPart) -> PyResult<Self> {
        let n = sliced.path.num_points();
        let (mut points, mut axes) = (Vec::with_capacity(3 * n), Vec::with_capacity(3 * n));
        let (mut layer, mut delta) = (Vec::with_capacity(n), Vec::with_capacity(n));
        for (k, (l, frames)) in sliced
            .path
            .layers
            .iter()
            .zip(&sliced.axes.frames)
            .enumerate()
        {
            for (p, f) in l.points.iter().zip(frames) {
                points.extend_from_slice(&[p.position.x, p.position.y, p.position.z]);
                axes.extend_from_slice(&[f.tool.x, f.tool.y, f.tool.z]);
                layer.push(k as i64);
                delta.push(p.delta.unwrap_or(f64::NAN));
            }
        }
        Ok(Self {
            points: arrays::matrix(py, points, 3)?,
            layer: arrays::ints(py, layer)?,
            delta: arrays::floats(py, delta)?,
            tool_axis: arrays::matrix(py, axes, 3)?,
            sliced,
        })
    }
}

#[pymethods]
impl PySlicedPart {
    /// Positions (N, 3), part frame, mm, in deposition order.
    #[getter]
    fn points<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        self.points.bind(py).clone()
    }

    /// Layer index of each point (N,), from 0.
    #[getter]
    fn layer<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<i64>> {
        self.layer.bind(py).clone()
    }

    /// Local distance of each point to the layer below (N,), mm; NaN on the
    /// first layer.
    #[getter]
    fn delta<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        self.delta.bind(py).clone()
    }

    /// Tool axis of each point (N, 3), unit vectors, part frame.
    #[getter]
    fn tool_axis<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        self.tool_axis.bind(py).clone()
    }

    /// The target interlayer distance Delta used (mm).
    #[getter]
    fn delta_mm(&self) -> f64 {
        self.sliced.path.delta_mm
    }

    /// The strategy used.
    #[getter]
    fn strategy(&self) -> &'static str {
        self.sliced.path.strategy.name()
    }

    /// Number of layers.
    #[getter]
    fn layers(&self) -> usize {
        self.sliced.path.layers.len()
    }

    /// The content of `summary.json` (as the command-line `slice` writes it).
    fn summary<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        json_to_py(py, &self.sliced.summary())
    }

    fn __len__(&self) -> usize {
        self.sliced.path.num_points()
    }

    fn __repr__(&self) -> String {
        format!(
            "SlicedPart({:?}, strategy={:?}, delta_mm={}, layers={}, points={})",
            self.sliced.part_name,
            self.strategy(),
            self.delta_mm(),
            self.layers(),
            self.__len__()
        )
    }
}
