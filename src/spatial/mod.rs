//! Spatial subdivision: the trait and Practical Path Guiding's binary tree,
//! generic over what a cell holds.
//!
//! [`BinaryTree`] is PPG's spatial tree: a cube around the scene bounds,
//! split at the midpoint along `x`, `y`, `z` in turn (the axis of a node at
//! depth `d` is `d % 3`). Leaves are the *cells*; each holds one value of
//! type `T` (a directional quadtree for the SD-tree, a light cut for the
//! Guiding Light Tree, both for the combined guiding field).
//!
//! Cells are numbered densely by [`CellId`] (`0..cell_count()`), so per-cell
//! side tables are plain vectors. A split keeps the old number for the lower
//! child and gives the upper child the next free number.
//!
//! Shared by everything that learns per cell: [`BinaryTree::spread`] spreads
//! a record made at a point over cells by a [`SpatialFilter`], and
//! [`split_threshold`] is PPG's split rule (`c * sqrt(2^k)`), which the
//! structures apply through [`BinaryTree::refine_with_heap`].
//!
//! Lookups clamp points outside the root cube onto it and reject non-finite
//! points with `None`; nothing in here panics on bad input. Depth is only
//! limited by `f32` precision (a cell stops splitting once its midpoint
//! cannot be represented), so trees hundreds of levels deep work.
//!
//! ```
//! use guiding::Aabb;
//! use guiding::learned::{BinaryTree, SpatialTree};
//! use glam::Vec3;
//!
//! // Cells count the points that fall in them; split any cell above 2.
//! let mut tree = BinaryTree::new(Aabb::new(Vec3::ZERO, Vec3::ONE), 8.0f32).unwrap();
//! tree.refine(|w: &f32, _depth| *w > 2.0, |w: &mut f32| { *w *= 0.5; *w }, None);
//! assert_eq!(tree.cell_count(), 4);
//! let cell = tree.locate(Vec3::splat(0.9)).unwrap();
//! assert_eq!(*tree.data(cell), 2.0);
//! assert_eq!(tree.cell_depth(cell), 2);
//! ```

mod binary_tree;
mod budget;
mod cell_id;
mod filter;
mod jitter;
mod overlap;
mod persist;
mod refine;
mod root_cube;
mod split_rule;
mod tree_trait;

pub use binary_tree::BinaryTree;
pub(crate) use budget::{Growth, content_scale};
pub use cell_id::CellId;

/// A point and where a spatial tree located it: the cell and its bounds.
pub(crate) type Located = (glam::Vec3, (CellId, crate::math::Aabb));
pub(crate) use filter::FILTERS;
pub use filter::SpatialFilter;
pub(crate) use jitter::{direction_salt, record_offset};
pub use refine::RefineOutcome;
pub use root_cube::SpatialError;
pub use split_rule::split_threshold;
pub use tree_trait::SpatialTree;
