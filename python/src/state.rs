//! A guide's state behind a lock: queries and records (`&self` in Rust)
//! take it shared, so any number of Python threads sample and record at
//! once; `refine`, `merge` and `clear_records` take it alone. Every lock is
//! taken with the GIL released, so a thread waiting for the lock never
//! holds the GIL that the thread holding the lock needs to return.

use crate::error::poisoned;
use pyo3::prelude::*;
use std::sync::{RwLock, RwLockReadGuard, RwLockWriteGuard};

/// One guide's state.
pub struct State<T>(RwLock<T>);

impl<T: Send + Sync> State<T> {
    pub fn new(value: T) -> Self {
        Self(RwLock::new(value))
    }

    /// `f` on the state, shared, with the GIL released.
    pub fn read<R: Send>(&self, py: Python<'_>, f: impl FnOnce(&T) -> R + Send) -> PyResult<R> {
        py.detach(|| {
            let guard: RwLockReadGuard<'_, T> = self.0.read().map_err(poisoned)?;
            Ok(f(&guard))
        })
    }

    /// `f` on the state, alone, with the GIL released.
    pub fn write<R: Send>(
        &self,
        py: Python<'_>,
        f: impl FnOnce(&mut T) -> R + Send,
    ) -> PyResult<R> {
        py.detach(|| {
            let mut guard: RwLockWriteGuard<'_, T> = self.0.write().map_err(poisoned)?;
            Ok(f(&mut guard))
        })
    }
}
