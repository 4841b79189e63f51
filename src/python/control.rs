//! Keyword arguments of `Part.slice` / `Part.plan` as the library's
//! [`SliceOverrides`], and a Python progress callback as a [`Control`] that
//! also stops the run on Ctrl-C or an exception raised by the callback.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};

use pyo3::prelude::*;

use super::{stage_error, waam_error};
use crate::path::{Discretisation, Strategy};
use crate::pipeline::{Control, SliceOverrides};

/// The slicing keywords shared by `slice` and `plan`, as given.
#[derive(Debug, Default)]
pub(crate) struct SliceKeywords {
    pub strategy: Option<String>,
    pub delta_mm: Option<f64>,
    pub points: Option<i64>,
    pub chord_mm: Option<f64>,
    pub max_layers: Option<i64>,
    pub travel_speed_mm_s: Option<f64>,
}

const STRATEGIES: [Strategy; 5] = [
    Strategy::Constant,
    Strategy::Iso,
    Strategy::Perpendicular,
    Strategy::Planar,
    Strategy::Spiral,
];

/// A count keyword: a whole number, not negative (the library checks its
/// range, naming the part file).
fn count(name: &str, n: Option<i64>) -> PyResult<Option<usize>> {
    n.map(|n| {
        usize::try_from(n).map_err(|_| waam_error(format!("{name} = {n}: must not be negative")))
    })
    .transpose()
}

impl SliceKeywords {
    /// The overrides; values are checked by the library when it slices
    /// (naming the part file and the field), names and counts here.
    pub fn overrides(&self) -> PyResult<SliceOverrides> {
        let strategy = match &self.strategy {
            None => None,
            Some(s) => Some(
                STRATEGIES
                    .into_iter()
                    .find(|k| k.name() == s.as_str())
                    .ok_or_else(|| {
                        let names: Vec<_> = STRATEGIES.iter().map(|k| k.name()).collect();
                        waam_error(format!(
                            "strategy = {s:?}: expected one of {}",
                            names.join(", ")
                        ))
                    })?,
            ),
        };
        let discretisation = match (count("points", self.points)?, self.chord_mm) {
            (Some(_), Some(_)) => {
                return Err(waam_error("give points or chord_mm, not both"));
            }
            (Some(n), None) => Some(Discretisation::Points(n)),
            (None, Some(e)) => Some(Discretisation::ChordError(e)),
            (None, None) => None,
        };
        Ok(SliceOverrides {
            strategy,
            delta_mm: self.delta_mm,
            discretisation,
            max_layers: count("max_layers", self.max_layers)?,
            travel_speed_mm_s: self.travel_speed_mm_s,
            ..SliceOverrides::default()
        })
    }
}

/// A [`Control`] for one run: calls `progress(fraction)` (when given) with
/// the GIL held, and cancels the run at its next check when the callback
/// raises or Ctrl-C was pressed; [`HostControl::finish`] then raises that
/// Python exception instead of the library's `Cancelled`.
pub(crate) struct HostControl {
    pub control: Control,
    raised: Arc<Mutex<Option<PyErr>>>,
}

impl HostControl {
    pub fn new(progress: Option<Py<PyAny>>) -> Self {
        let raised: Arc<Mutex<Option<PyErr>>> = Arc::default();
        let cancel = Arc::new(AtomicBool::new(false));
        let (slot, flag) = (raised.clone(), cancel.clone());
        let control =
            Control::default()
                .with_cancel(cancel)
                .with_progress(move |_stage, fraction| {
                    Python::attach(|py| {
                        let outcome = match &progress {
                            Some(f) => f.call1(py, (fraction,)).map(drop),
                            None => Ok(()),
                        }
                        .and_then(|()| py.check_signals());
                        if let Err(e) = outcome {
                            let mut slot = slot.lock().unwrap_or_else(|p| p.into_inner());
                            slot.get_or_insert(e);
                            flag.store(true, Ordering::Relaxed);
                        }
                    });
                });
        Self { control, raised }
    }

    /// The run's result, or the exception the callback raised (or the
    /// KeyboardInterrupt) during it.
    pub fn finish<T>(self, result: Result<T, crate::Error>) -> PyResult<T> {
        let raised = self.raised.lock().unwrap_or_else(|p| p.into_inner()).take();
        match (raised, result) {
            (Some(e), _) => Err(e),
            (None, r) => r.map_err(stage_error),
        }
    }
}
