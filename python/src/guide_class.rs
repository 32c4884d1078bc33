//! What the three guides' Python classes share: a guide's state behind its
//! lock, and the methods every guide has (refine, clear_records, merge,
//! to_bytes, iteration, dropped_records, nbytes, copies), written once.
//! `guide_class!` writes a class's one `#[pymethods]` block: these methods
//! and the class's own.

use guiding::{DroppedRecords, RefineOutcome};
use pyo3::prelude::*;
use pyo3::types::PyDict;

/// A refinement's outcome as a dict.
pub fn refine_outcome(py: Python<'_>, r: RefineOutcome) -> PyResult<Bound<'_, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("splits", r.splits)?;
    d.set_item("refused_by_budget", r.refused_by_budget)?;
    d.set_item("refused_by_precision", r.refused_by_precision)?;
    Ok(d)
}

/// Dropped records by reason, as a dict.
pub fn dropped(py: Python<'_>, d: DroppedRecords) -> PyResult<Bound<'_, PyDict>> {
    let out = PyDict::new(py);
    out.set_item("position", d.position)?;
    out.set_item("direction", d.direction)?;
    out.set_item("radiance", d.radiance)?;
    out.set_item("pdf", d.pdf)?;
    out.set_item("overflow", d.overflow)?;
    out.set_item("light", d.light)?;
    out.set_item("total", d.total())?;
    Ok(out)
}

/// `#[pymethods] impl $class { the shared methods; $own }` for a class
/// with fields `state: State<_>` and a `fn with_state(&self, State<_>) ->
/// Self` (a copy's constructor).
macro_rules! guide_class {
    ($class:ident, { $($own:tt)* }) => {
        #[pyo3::pymethods]
        impl $class {
            /// Ends a training iteration: splits cells and rebuilds what
            /// they learned from what was recorded (the GIL released).
            /// Returns the spatial refinement's counts.
            fn refine<'py>(&self, py: pyo3::Python<'py>) -> pyo3::PyResult<pyo3::Bound<'py, pyo3::types::PyDict>> {
                let r = self.state.write(py, |g| g.refine())?;
                crate::guide_class::refine_outcome(py, r)
            }

            /// Forgets the records of the current iteration (a farm
            /// worker's share starts from none).
            fn clear_records(&self, py: pyo3::Python<'_>) -> pyo3::PyResult<()> {
                self.state.write(py, |g| g.clear_records())
            }

            /// Adds `other`'s records to this guide's: copies of one guide
            /// after the same refinements, as a farm's workers hold.
            /// `ValueError` when they are not such copies.
            fn merge(&self, py: pyo3::Python<'_>, other: &$class) -> pyo3::PyResult<()> {
                let theirs = other.state.read(py, Clone::clone)?;
                if self.state.write(py, |g| g.merge(&theirs))? {
                    Ok(())
                } else {
                    Err(pyo3::exceptions::PyValueError::new_err(concat!(
                        stringify!($class),
                        ".merge: the guides are not copies of one guide \
                         (light tree, configuration, iteration and cells must match)"
                    )))
                }
            }

            /// Everything learned and recorded, as bytes (`from_bytes`
            /// reads them back).
            fn to_bytes<'py>(&self, py: pyo3::Python<'py>) -> pyo3::PyResult<pyo3::Bound<'py, pyo3::types::PyBytes>> {
                let bytes = self.state.read(py, |g| g.to_bytes())?;
                Ok(pyo3::types::PyBytes::new(py, &bytes))
            }

            /// Training iterations done (refinements).
            #[getter]
            fn iteration(&self, py: pyo3::Python<'_>) -> pyo3::PyResult<u32> {
                self.state.read(py, |g| g.iteration())
            }

            /// Records dropped as bad input since the last refinement, by
            /// reason, and their total.
            #[getter]
            fn dropped_records<'py>(&self, py: pyo3::Python<'py>) -> pyo3::PyResult<pyo3::Bound<'py, pyo3::types::PyDict>> {
                let d = self.state.read(py, |g| g.dropped_records())?;
                crate::guide_class::dropped(py, d)
            }

            /// Bytes the guide's learned state takes.
            #[getter]
            fn nbytes(&self, py: pyo3::Python<'_>) -> pyo3::PyResult<usize> {
                self.state.read(py, |g| g.memory().total())
            }

            /// A copy (`copy.copy` and `copy.deepcopy` alike: the light
            /// tree is shared, everything learned is copied).
            fn __copy__(&self, py: pyo3::Python<'_>) -> pyo3::PyResult<Self> {
                Ok(self.with_state(crate::state::State::new(self.state.read(py, Clone::clone)?)))
            }

            fn __deepcopy__(&self, py: pyo3::Python<'_>, _memo: &pyo3::Bound<'_, pyo3::PyAny>) -> pyo3::PyResult<Self> {
                self.__copy__(py)
            }

            $($own)*
        }
    };
}

pub(crate) use guide_class;
