//! `PlannedPart`: a plan's points, tool axes, layers, `R_Z` and joints as
//! numpy arrays, its violations as dicts, and writing its robot program.

use std::path::PathBuf;

use numpy::{PyArray1, PyArray2};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use super::{arrays, json_to_py, stage_error, InfeasiblePlan};
use crate::pipeline::PlannedPart;
use crate::robot::trajectory::{SingularityKind, Violation, ViolationKind};

/// A part planned in a cell: every planned point in deposition order.
#[pyclass(frozen, name = "PlannedPart", module = "waam_slicer")]
pub(crate) struct PyPlannedPart {
    planned: PlannedPart,
    points: Py<PyArray2<f64>>,
    tool_axis: Py<PyArray2<f64>>,
    layer: Py<PyArray1<i64>>,
    rz_deg: Py<PyArray1<f64>>,
    joints: Py<PyArray2<f64>>,
    /// Travel speed on the way to each point (N,), mm/s.
    speed: Py<PyArray1<f64>>,
    /// Wire feed on the way to each point (N,), mm/s.
    wire_feed: Py<PyArray1<f64>>,
    /// A replan's whole summary (with its `replan` object), when this is
    /// the plan of the remaining layers of a replan.
    replan_summary: Option<crate::replan::summary::ReplanSummary>,
}

impl PyPlannedPart {
    /// The plan of the remaining layers of a replan; its `summary()` is the
    /// replan's.
    pub fn from_replan(py: Python<'_>, replanned: crate::replan::ReplannedPart) -> PyResult<Self> {
        let summary = replanned.summary();
        let mut me = Self::new(py, replanned.planned)?;
        me.replan_summary = Some(summary);
        Ok(me)
    }

    pub fn new(py: Python<'_>, planned: PlannedPart) -> PyResult<Self> {
        let width = if planned.has_positioner() { 8 } else { 6 };
        let n: usize = planned.layers.iter().map(|l| l.points.len()).sum();
        let (mut points, mut axes) = (Vec::with_capacity(3 * n), Vec::with_capacity(3 * n));
        let (mut layer, mut rz) = (Vec::with_capacity(n), Vec::with_capacity(n));
        let mut joints = Vec::with_capacity(width * n);
        for (lp, pl) in planned.layers.iter().zip(&planned.plan.layers) {
            for (cp, pp) in lp.points.iter().zip(&pl.points) {
                points.extend_from_slice(&[cp.position_mm.x, cp.position_mm.y, cp.position_mm.z]);
                axes.extend_from_slice(&[cp.tool_axis.x, cp.tool_axis.y, cp.tool_axis.z]);
                layer.push(lp.layer as i64);
                rz.push(pp.r_z.to_degrees());
                match pp.joints {
                    Some(q) => joints.extend(q.iter().map(|v| v.to_degrees())),
                    None => joints.extend([f64::NAN; 6]),
                }
                if width == 8 {
                    match pp.positioner {
                        Some(e) => joints.extend(e.iter().map(|v| v.to_degrees())),
                        None => joints.extend([f64::NAN; 2]),
                    }
                }
            }
        }
        let process: Vec<[f64; 3]> = planned.point_process().into_iter().flatten().collect();
        Ok(Self {
            speed: arrays::floats(py, process.iter().map(|p| p[0]).collect())?,
            wire_feed: arrays::floats(py, process.iter().map(|p| p[2]).collect())?,
            points: arrays::matrix(py, points, 3)?,
            tool_axis: arrays::matrix(py, axes, 3)?,
            layer: arrays::ints(py, layer)?,
            rz_deg: arrays::floats(py, rz)?,
            joints: arrays::matrix(py, joints, width)?,
            planned,
            replan_summary: None,
        })
    }
}

/// How far a violation goes past its limit, in the unit named beside it.
fn what_and_amount(
    kind: &ViolationKind,
) -> (&'static str, Option<usize>, Option<f64>, &'static str) {
    match kind {
        ViolationKind::JointLimit {
            joint,
            value_rad,
            lower_rad,
            upper_rad,
        } => {
            let past = (value_rad - upper_rad).max(lower_rad - value_rad);
            ("joint_limit", Some(*joint), Some(past.to_degrees()), "deg")
        }
        ViolationKind::JointSpeed {
            joint,
            speed_rad_s,
            max_rad_s,
        } => (
            "joint_speed",
            Some(*joint),
            Some((speed_rad_s.abs() - max_rad_s).to_degrees()),
            "deg/s",
        ),
        ViolationKind::Singularity { kind, measure } => match kind {
            SingularityKind::Wrist => ("wrist_singularity", Some(5), Some(*measure), "|sin J5|"),
            SingularityKind::Elbow => ("elbow_singularity", Some(3), Some(*measure), "|cos gamma|"),
            SingularityKind::Shoulder => ("shoulder_singularity", Some(1), Some(*measure), "mm"),
        },
        ViolationKind::HoseTorsion {
            torsion_rad,
            max_rad,
        } => (
            "hose_torsion",
            None,
            Some((torsion_rad - max_rad).to_degrees()),
            "deg",
        ),
        ViolationKind::BuildTilt { tilt_rad, max_rad } => (
            "build_tilt",
            None,
            Some((tilt_rad - max_rad).to_degrees()),
            "deg",
        ),
        ViolationKind::NoSolution(_) => ("no_solution", None, None, ""),
    }
}

/// One violation as a dict: layer, point, joint (1-based, or None), what,
/// amount (past the limit; the measure itself for a singularity), unit,
/// message.
fn violation_dict<'py>(py: Python<'py>, v: &Violation) -> PyResult<Bound<'py, PyDict>> {
    let (what, joint, amount, unit) = what_and_amount(&v.kind);
    let d = PyDict::new(py);
    d.set_item("layer", v.layer)?;
    d.set_item("point", v.point)?;
    d.set_item("joint", joint)?;
    d.set_item("what", what)?;
    d.set_item("amount", amount)?;
    d.set_item("unit", unit)?;
    d.set_item("message", v.to_string())?;
    Ok(d)
}

#[pymethods]
impl PyPlannedPart {
    /// `True` when every layer is feasible and the program can be written.
    #[getter]
    fn feasible(&self) -> bool {
        self.planned.is_feasible()
    }

    /// Every violation of the planned trajectory, in path order, as dicts
    /// (`layer`, `point`, `joint`, `what`, `amount`, `unit`, `message`).
    #[getter]
    fn violations<'py>(&self, py: Python<'py>) -> PyResult<Vec<Bound<'py, PyDict>>> {
        self.planned
            .plan
            .violations()
            .map(|v| violation_dict(py, v))
            .collect()
    }

    /// Why no program can be written (None when the plan is feasible).
    #[getter]
    fn refusal(&self) -> Option<String> {
        match (&self.planned.program, self.planned.is_feasible()) {
            (Err(e), _) => Some(e.to_string()),
            (Ok(_), false) => Some("a layer is infeasible".into()),
            (Ok(_), true) => None,
        }
    }

    /// Positions of the planned points (N, 3), part frame, mm.
    #[getter]
    fn points<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        self.points.bind(py).clone()
    }

    /// Tool axes (N, 3), unit vectors, part frame.
    #[getter]
    fn tool_axis<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        self.tool_axis.bind(py).clone()
    }

    /// Layer index of each point (N,).
    #[getter]
    fn layer<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<i64>> {
        self.layer.bind(py).clone()
    }

    /// `R_Z` of each point (N,), degrees.
    #[getter]
    fn rz_deg<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        self.rz_deg.bind(py).clone()
    }

    /// Joints (N, 6) in degrees, the robot controller's convention; (N, 8)
    /// with a positioner (its two joints last). NaN where a point has no
    /// joint solution.
    #[getter]
    fn joints<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        self.joints.bind(py).clone()
    }

    /// The process's travel speed (mm/s): every point's, but where the
    /// plan slowed the torch down (`point_speed_mm_s`).
    #[getter]
    fn travel_speed_mm_s(&self) -> f64 {
        self.planned.travel_speed_mm_s()
    }

    /// Travel speed on the way to each point (N,), mm/s: the process's, or
    /// slower where an axis could not keep up (the summary's `slowed`).
    #[getter]
    fn point_speed_mm_s<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        self.speed.bind(py).clone()
    }

    /// Wire feed on the way to each point (N,), mm/s: the process's, scaled
    /// with the speed where the torch slows (WFS/TS, the bead's
    /// cross-section, stays).
    #[getter]
    fn wire_feed_mm_s<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        self.wire_feed.bind(py).clone()
    }

    /// The program format written by default: the cell robot's vendor's.
    #[getter]
    fn format(&self) -> &'static str {
        self.planned.format.key()
    }

    /// The content of `summary.json` (as the command-line `plan` writes it).
    fn summary<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        if let Some(s) = &self.replan_summary {
            return json_to_py(py, s);
        }
        json_to_py(py, &self.planned.summary())
    }

    /// Writes the robot program into `dir` (created if missing), each file
    /// atomically, in the plan's format (`Part.plan(format=...)`, else the
    /// cell vendor's); returns the written paths, in the order the cell
    /// runs them. Raises `InfeasiblePlan` when a layer is infeasible.
    #[pyo3(signature = (dir,))]
    fn write_program(&self, py: Python<'_>, dir: PathBuf) -> PyResult<Vec<PathBuf>> {
        if let Some(why) = self.refusal() {
            return Err(InfeasiblePlan::new_err(format!(
                "{}: no program written: {why}",
                self.planned.sliced.part_file
            )));
        }
        py.detach(|| self.planned.write_programs(&dir))
            .map_err(stage_error)
    }

    fn __len__(&self) -> usize {
        self.planned.layers.iter().map(|l| l.points.len()).sum()
    }

    fn __repr__(&self) -> String {
        format!(
            "PlannedPart({:?}, cell={:?}, feasible={}, layers={}, points={})",
            self.planned.sliced.part_name,
            self.planned.cell.name,
            if self.feasible() { "True" } else { "False" },
            self.planned.layers.len(),
            self.__len__()
        )
    }
}
