//! The crate's errors as Python exceptions: every typed error (a
//! configuration out of range, a light tree that cannot be built, a saved
//! guide that does not load) is a `ValueError` carrying the crate's message.

use pyo3::PyErr;
use pyo3::exceptions::{PyRuntimeError, PyValueError};

/// A crate error as a `ValueError` with its message.
pub fn value_error(e: impl core::fmt::Display) -> PyErr {
    PyValueError::new_err(e.to_string())
}

/// A lock poisoned by a panic in another thread: the guide's state may be
/// half-updated, so it is refused from then on rather than used.
pub fn poisoned<T>(_: T) -> PyErr {
    PyRuntimeError::new_err(
        "the guide is unusable: a call on another thread panicked while changing it",
    )
}
