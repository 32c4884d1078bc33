//! The `guiding` crate's C API: opaque handles for the light tree, the
//! Guiding Light Tree, the SD-tree and the combined field, plain C structs for contexts and samples, `float u`
//! arguments so any sampler drives the queries, a status code from every
//! fallible call with a thread-local message, and no panic across the
//! boundary. `include/guiding.h` is this crate's header (cbindgen);
//! `include/guiding.hpp` wraps it for C++17 (RAII handles, exceptions).
//!
//! The names follow the Rust front and the Python bindings:
//! `guiding_emitters_*` (a scene's emitters), `guiding_light_tree_*`,
//! `guiding_glt_*` (`new`, `sample`, `pmf`, `record_light`, `refine`,
//! `clear_records`, `merge`, `save`, `load`), `guiding_sd_tree_*`
//! (`sample_direction`, `direction_pdf`, `bsdf_fraction`, `mixture_pdf`,
//! `record_radiance`, `record_fraction`, and the same five around passes)
//! and `guiding_field_*` (both sets, one lookup).
//!
//! Every exported function checks its pointers (null is an error, never a
//! crash), its numbers (NaN, infinities and out-of-range values are
//! `GUIDING_STATUS_INVALID_ARGUMENT`) and runs inside `catch_unwind`. The
//! guides sit behind a read-write lock: queries and records share it (the
//! Rust `&self` calls), refinement and merging take it alone, so even a
//! renderer that refines while other threads sample gets a wait, not
//! undefined behaviour.

#![deny(unsafe_op_in_unsafe_fn, missing_docs)]

mod buffer;
mod config;
mod context;
mod direction_calls;
mod emitters;
mod field;
mod glt;
mod handle;
mod light_calls;
mod light_tree;
mod sd_tree;
mod snapshot;
mod status;

pub use buffer::*;
pub use config::*;
pub use context::*;
pub use direction_calls::GuidingDirectionSample;
pub use emitters::*;
pub use field::*;
pub use glt::*;
pub use light_tree::*;
pub use sd_tree::*;
pub use snapshot::*;
pub use status::*;
