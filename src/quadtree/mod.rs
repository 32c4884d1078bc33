//! The directional quadtree of Practical Path Guiding (its "D-tree") over the
//! equal-area sphere map.
//!
//! A [`DirectionalTree`] learns a distribution of directions from radiance
//! records and samples it. It keeps two copies, as PPG does:
//! - the *sampling* copy answers [`DirectionalTree::sample`] and
//!   [`DirectionalTree::pdf`]; it is plain data, read-only between refines;
//! - the *building* copy collects [`DirectionalTree::record`]s from many
//!   threads through `&self` into thread-safe sums (`src/math/sum.rs`)
//!   (lock-free, no lost update, no `f32` accumulation error, bit-identical in
//!   [`Accumulation::Deterministic`](crate::Accumulation) mode).
//!
//! [`DirectionalTree::refine`] turns the building copy's sums into the next
//! sampling copy, then refines the building topology for the next iteration.
//!
//! ## Layout
//!
//! A node covers a square of the canonical domain `[0, 1]^2` and has four
//! quadrants, numbered `ix + 2 iy` (`ix` along `u = (cos theta + 1) / 2`,
//! `iy` along `v = phi / 2 pi`). A quadrant is either a leaf or has a child
//! node. The children of a node are stored contiguously in breadth-first
//! order: one `u32` first-child index and a 4-bit child mask per node, so the
//! tree has no 65,535-node limit. A sampling node is 24 bytes (four `f32`
//! quadrant probabilities and the link; [`NODE_BYTES`]); a building node is an
//! 8-byte link plus four sums in the `SumBuffer` (8 bytes each in `Fast`
//! mode, 48 in `Deterministic` mode).
//!
//! Depth counts node levels: the root is level 1 and its quadrants are cells
//! of side 1/2; a node at level `L` has quadrants of side `2^-L`.
//!
//! ## Density
//!
//! The tree part of the density is PPG's: the product over levels of
//! `4 * sum[q] / (sum of the node's four sums)`, per unit canonical area,
//! divided by the Jacobian `4 pi`. It is mixed with a small uniform part
//! ([`DirectionalTree::uniform_fraction`], default
//! [`DirectionalTree::DEFAULT_UNIFORM_FRACTION`]) so the pdf is never 0 for a valid direction,
//! even where nothing was learned. A tree that has never learned anything
//! (or learned only zeros) is exactly uniform, `1 / (4 pi)`.

mod cell;
mod config;
mod leaves;
mod node;
mod persist;
mod query;
mod record;
mod refine;
mod sums;
mod tree;

pub use config::{DirectionalFilter, QuadtreeConfig, UNIFORM_PDF};
pub use leaves::QuadLeaf;
pub use node::NODE_BYTES;
pub use tree::DirectionalTree;
