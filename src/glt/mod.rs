//! The Guiding Light Tree (Hamann, Jung and Dachsbacher, EGSR 2023): learned
//! adaptive cuts through the global light tree, one per spatial cell, that
//! guide next-event estimation.
//!
//! Where to find what:
//! - [`CutRules`] (`cut_rules.rs`): what all cells share, the light
//!   tree with its power prior precomputed and the [`CutConfig`]; every
//!   operation on a cut goes through it;
//! - [`GuidingCut`] (`cut.rs`): one cell's learned state, a weighted sub-tree
//!   of the light tree from its root down to the cut, in two copies (sampled
//!   [`CutNode`]s, accumulating sums);
//! - `cut_node.rs`: the 12-byte [`CutNode`] and its [`Slot`]s;
//! - `sampling.rs`: **the GLT's sampling rule** and its pmf (cut, then the
//!   light tree, mixed with the prior and the unbounded lights);
//! - `walk.rs`: the light tree re-laid out for the sampling walk (both
//!   children of a node in one 16-byte load);
//! - `splat.rs`: recording direct-light estimates ([`CutRules::splat`]);
//! - `refine.rs`: rebuilding the cut from its sums ([`CutRules::refine`]);
//! - `visibility.rs`: each cluster's learned visibility
//!   ([`CutRules::splat_visibility`], [`CutConfig::visibility`]), the
//!   target factor of resampled light choice;
//! - `config.rs`: [`CutConfig`], [`BelowCut`], [`SplitPrior`];
//! - `standalone.rs`: [`Glt`], one cut per cell of its own spatial tree, a
//!   [`crate::LightSampler`].
//!
//! How it differs from the paper's code (see the crate's reference notes):
//! the initial cut is the power prior, not 0.5/0.5; a defensive mixture
//! with a prior (`alpha`, default 0.2) keeps every emitter with
//! power at a non-zero pmf, so delta lights stay unbiased without MIS;
//! cut nodes take 12 bytes, not 20; sums accumulate in `f64` or exactly,
//! never in `f32`; the one-number descent is exact at any depth; paths have
//! no 32-level limit; single-light and empty scenes work; light splats go to
//! the cell of their shading point, not jittered into neighbours (through
//! walls). Beyond the paper, by default the learned cut follows the
//! shading point inside its cell ([`Modulation`], [`Prior`], importance
//! below the cut: [`CutConfig::with_importance`]), from a decoded
//! importance table (`src/light_sampler/importance_table.rs`);
//! [`CutConfig::with_paper_rules`] gives the paper's one distribution per
//! cell.

mod cell;
mod config;
mod cut;
mod cut_node;
mod cut_rules;
mod octants;
mod persist;
mod refine;
mod sampling;
mod splat;
mod standalone;
mod vertex;
mod visibility;
mod walk;

pub use cell::GltCell;
pub use config::{BelowCut, CutConfig, Modulation, Prior, SplitPrior};
pub use cut::{CutError, CutMemory, GuidingCut};
pub use cut_node::{CutNode, Slot};
pub use cut_rules::CutRules;
pub(crate) use octants::OctantSplats;
pub use standalone::{Glt, GltConfig, GltMemory};
pub(crate) use vertex::LightCells;
pub use vertex::LightVertex;
