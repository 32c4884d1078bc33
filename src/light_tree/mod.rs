//! The global light hierarchy: a binary tree with one emitter per leaf, the
//! structure every tree-based sampler and the Guiding Light Tree descend.
//!
//! [`LightHierarchy`] is the interface; [`LightTree`] is the BVH that
//! implements it, built with one of the [`BuildHeuristic`]s.

mod build;
pub(crate) mod descend;
mod error;
mod hierarchy;
mod instanced;
mod node;
mod path;
mod persist;
mod shape;
mod tree;

pub use build::BuildHeuristic;
pub use error::BuildError;
pub use hierarchy::{LightHierarchy, NodeBounds};
pub use instanced::{Instance, InstancedLightTree};
pub use node::LightNode;
pub use path::EmitterPath;
pub use persist::fingerprint;
pub(crate) use persist::read_fingerprint;
pub(crate) use shape::same_shape;
pub use shape::shape_fingerprint;
pub use tree::LightTree;
