//! The Guiding Light Tree (Hamann, Jung and Dachsbacher, EGSR 2023) for
//! renderers without directional guiding: [`Glt`], one learned cut
//! ([`crate::cut`]) per cell of its own spatial tree, guiding next-event
//! estimation through its [`LightVertex`](crate::LightVertex).
//!
//! Where to find what:
//! - `guiding_light_tree.rs`: [`Glt`], its vertices, records and
//!   refinement (cells that refine on their own records);
//! - `cell.rs`: [`GltCell`], a cell's cut and its readiness;
//! - `config.rs`: [`GltConfig`];
//! - `memory.rs`: [`GltMemory`];
//! - `persist.rs`: saving, loading and merging a GLT.

mod cell;
mod config;
mod guiding_light_tree;
mod memory;
mod persist;

pub use cell::GltCell;
pub use config::GltConfig;
pub use guiding_light_tree::Glt;
pub use memory::GltMemory;
