//! The cut machinery the Guiding Light Tree (Hamann, Jung and
//! Dachsbacher, EGSR 2023) is made of: a learned adaptive cut through the
//! global light tree, its sampling rule, its records and its refinement,
//! for one spatial cell. [`crate::glt`] and [`crate::field`] hold one cut
//! per cell of their spatial trees and stand on this module, as
//! [`crate::sd_tree`] stands on [`crate::quadtree`].
//!
//! Where to find what:
//! - [`CutRules`] (`cut_rules.rs`): what all cells share, the light
//!   tree with its power split precomputed (`split_table.rs`) and the [`CutConfig`]; every
//!   operation on a cut goes through it;
//! - [`GuidingCut`] (`guiding_cut.rs`): one cell's learned state, a weighted sub-tree
//!   of the light tree from its root down to the cut, in two copies (sampled
//!   [`CutNode`]s, accumulating sums);
//! - `cut_node.rs`: the 12-byte [`CutNode`] and its [`Slot`]s;
//! - `sampling.rs`: **the GLT's sampling rule** and its pmf (cut, then the
//!   light tree, mixed with the prior and the unbounded lights);
//! - `walk.rs`: the light tree re-laid out for the sampling walk (both
//!   children of a node in one 16-byte load);
//! - `split_table.rs`: each inner node's power split in one signed `f32`;
//! - `tables.rs`: a light tree's tables as the walks read them, and the
//!   `Segment` a walk is in; `instanced_tables.rs`: those of an
//!   [`crate::InstancedLightTree`], one set per mesh shared by its
//!   instances;
//! - `record.rs`: recording direct-light estimates into a cut
//!   ([`CutRules::record`]);
//! - `vertex.rs`: [`LightVertex`], a located cell's cut as a
//!   [`crate::LightSampler`] with its records, for the GLT and the field;
//! - `refine.rs`: rebuilding the cut from its sums ([`CutRules::refine`]);
//! - `visibility.rs`: each cluster's learned visibility
//!   ([`CutRules::record_visibility`], [`CutConfig::visibility`]), the
//!   target factor of resampled light choice;
//! - `importance_table.rs`: the light tree's nodes decoded for the
//!   importance rules, sibling pairs in the walk's order;
//! - `octants.rs`: a cell's records counted per octant, which split cells
//!   share by;
//! - `config.rs`: [`CutConfig`], [`BelowCut`], [`Modulation`], [`Prior`],
//!   [`SplitPrior`];
//! - `persist.rs`: a cut's and its configuration's saved bytes.
//!
//! How it differs from the paper's code (see the crate's reference notes):
//! the initial cut is the power split, not 0.5/0.5; a defensive mixture
//! with a prior (`alpha`, default 0.2) keeps every emitter with
//! power at a non-zero pmf, so delta lights stay unbiased without MIS;
//! cut nodes take 12 bytes, not 20; sums accumulate in `f64` or exactly,
//! never in `f32`; the one-number descent is exact at any depth; paths have
//! no 32-level limit; single-light and empty scenes work; light records go
//! to the cell of their shading point, not jittered into neighbours
//! (through walls). Beyond the paper, by default the learned cut follows
//! the shading point inside its cell ([`Modulation`], [`Prior`], importance
//! below the cut: [`CutConfig::with_importance`]), from a decoded
//! importance table (`importance_table.rs`);
//! [`CutConfig::with_paper_rules`] gives the paper's one distribution per
//! cell.

mod child_weights;
mod config;
mod cut_node;
mod cut_rules;
mod entry;
mod guiding_cut;
mod importance_table;
mod instanced_tables;
mod octants;
mod persist;
mod record;
mod refine;
mod sampling;
mod split_table;
mod tables;
mod vertex;
mod visibility;
mod walk;

pub use config::{BelowCut, CutConfig, ImportanceBound, Modulation, Prior, SplitPrior};
pub use cut_node::{CutNode, Slot};
pub use cut_rules::CutRules;
pub use guiding_cut::{CutError, CutMemory, GuidingCut};
pub(crate) use octants::OctantRecords;
pub(crate) use tables::TreeTables;
// The importance lanes and their record, shared with the GPU snapshot
// (`src/snapshot/importance.rs`).
pub(crate) use child_weights::lanes;
pub(crate) use entry::Entry;
pub(crate) use vertex::LightCells;
pub use vertex::LightVertex;
