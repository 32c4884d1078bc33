//! Python bindings of `guiding` (the module `guiding._guiding`, re-exported
//! by the package `guiding`): a scene's emitters and their light tree, the
//! Guiding Light Tree, Practical Path Guiding's SD-tree and the combined
//! field, with the Rust front's names. Every query takes a batch of points
//! as numpy arrays (one call per wavefront), copies its inputs once while
//! checking them, runs with the GIL released (in parallel from
//! `batch::PARALLEL_FROM` points) and returns numpy arrays. Bad input is a
//! `TypeError` or `ValueError` naming the argument and the row, never a
//! crash and never a silent wrong answer.

#![deny(unsafe_code)]

mod arrays;
mod batch;
mod config;
mod direction_ops;
mod error;
mod field;
mod glt;
mod guide_class;
mod light_ops;
mod lights;
mod sd_tree;
mod state;

use pyo3::prelude::*;

/// The native module.
#[pymodule]
fn _guiding(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<lights::Emitters>()?;
    m.add_class::<lights::LightTree>()?;
    m.add_class::<glt::Glt>()?;
    m.add_class::<sd_tree::SdTree>()?;
    m.add_class::<field::GuidingField>()?;
    m.add("PARALLEL_FROM", batch::PARALLEL_FROM)?;
    Ok(())
}
