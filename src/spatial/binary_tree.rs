//! Practical Path Guiding's spatial binary tree: storage, lookup and access.

use super::root_cube::{SpatialError, root_cube};
use super::{CellId, SpatialTree};
use crate::math::Aabb;
use alloc::vec;
use alloc::vec::Vec;
use glam::Vec3;

/// Set in a node word when the node is a leaf; the other bits hold the cell.
pub(super) const LEAF: u32 = 1 << 31;

/// Per-cell bookkeeping kept beside the user's data.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct CellMeta {
    pub(super) bounds: Aabb,
    pub(super) depth: u32,
    /// The leaf node that points at this cell.
    pub(super) node: u32,
}

/// A binary spatial tree over a cube, split at midpoints on cycling axes,
/// whose leaves (cells) each hold a `T`.
///
/// Storage: one `u32` per node (an inner node holds the index of its first
/// child, the second follows it; a leaf holds [`CellId`] with the top bit
/// set), plus per cell its `T`, its bounds and its depth. See
/// [`BinaryTree::bytes`].
///
/// Lookups take `&self` and never lock; `T` decides what may be done with a
/// cell concurrently.
#[derive(Clone, Debug)]
pub struct BinaryTree<T> {
    pub(super) nodes: Vec<u32>,
    pub(super) cells: Vec<T>,
    pub(super) meta: Vec<CellMeta>,
    pub(super) root: Aabb,
}

impl<T> BinaryTree<T> {
    /// A tree with one cell holding `data`, covering the cube around `scene`
    /// (`src/spatial/root_cube.rs`). Errors for empty or non-finite
    /// bounds.
    pub fn new(scene: Aabb, data: T) -> Result<Self, SpatialError> {
        let root = root_cube(&scene)?;
        Ok(Self {
            nodes: vec![LEAF],
            cells: vec![data],
            meta: vec![CellMeta {
                bounds: root,
                depth: 0,
                node: 0,
            }],
            root,
        })
    }

    /// The node words, root first: an inner node's word is the index of
    /// its first child (the second follows it), a leaf's is `1 << 31`
    /// | its cell. Children split their parent at its midpoint on axis
    /// x, y, z in turn from the root (the GPU snapshot copies them).
    #[inline]
    pub(crate) fn node_words(&self) -> &[u32] {
        &self.nodes
    }

    /// How many nodes (inner and leaf).
    #[inline]
    pub fn node_count(&self) -> usize {
        self.nodes.len()
    }

    /// Bytes of one node word.
    pub const NODE_BYTES: usize = core::mem::size_of::<u32>();

    /// Bytes of per-cell bookkeeping (bounds, depth, node), besides `T`.
    pub const CELL_META_BYTES: usize = core::mem::size_of::<CellMeta>();

    /// Bytes the tree's own storage uses: node words, per-cell bookkeeping
    /// and `size_of::<T>()` per cell. Memory that a `T` owns on the heap is
    /// not included (the owner of `T` adds it). Counted on lengths; the
    /// vectors are trimmed after every refinement.
    pub fn bytes(&self) -> usize {
        core::mem::size_of::<Self>()
            + self.nodes.len() * Self::NODE_BYTES
            + self.meta.len() * Self::CELL_META_BYTES
            + self.cells.len() * core::mem::size_of::<T>()
    }

    /// The deepest cell's depth.
    pub fn max_depth(&self) -> u32 {
        self.meta.iter().map(|m| m.depth).max().unwrap_or(0)
    }

    /// The cell holding `p` and that cell's bounds; `None` for non-finite
    /// `p`. Points outside the root are clamped onto it.
    #[inline]
    pub fn locate_with_bounds(&self, p: Vec3) -> Option<(CellId, Aabb)> {
        let cell = self.locate_cell(p)?;
        Some((cell, self.meta[cell.index()].bounds))
    }

    #[inline]
    fn locate_cell(&self, p: Vec3) -> Option<CellId> {
        if !p.is_finite() {
            return None;
        }
        let p = self.root.clamp(p);
        let mut node = 0usize;
        let mut bounds = self.root;
        let mut axis = 0usize;
        loop {
            let word = self.nodes[node];
            if word & LEAF != 0 {
                return Some(CellId(word & !LEAF));
            }
            let mid = split_plane(&bounds, axis);
            if p[axis] < mid {
                bounds.max[axis] = mid;
                node = word as usize;
            } else {
                bounds.min[axis] = mid;
                node = word as usize + 1;
            }
            axis = next_axis(axis);
        }
    }

    /// What `cell` holds, mutably.
    #[inline]
    pub fn data_mut(&mut self, cell: CellId) -> &mut T {
        &mut self.cells[cell.index()]
    }

    /// Every cell's data, indexed by [`CellId::index`].
    #[inline]
    pub fn data_slice(&self) -> &[T] {
        &self.cells
    }

    /// Every cell's data, mutably, indexed by [`CellId::index`].
    #[inline]
    pub fn data_slice_mut(&mut self) -> &mut [T] {
        &mut self.cells
    }

    /// The same subdivision with every cell's data replaced by `f(data)`
    /// (e.g. to give another structure the topology this one learned).
    pub fn map<U>(self, f: impl FnMut(T) -> U) -> BinaryTree<U> {
        BinaryTree {
            nodes: self.nodes,
            cells: self.cells.into_iter().map(f).collect(),
            meta: self.meta,
            root: self.root,
        }
    }

    /// Like [`BinaryTree::map`] without consuming the tree.
    pub fn map_ref<U>(&self, f: impl FnMut(&T) -> U) -> BinaryTree<U> {
        BinaryTree {
            nodes: self.nodes.clone(),
            cells: self.cells.iter().map(f).collect(),
            meta: self.meta.clone(),
            root: self.root,
        }
    }
}

impl<T> SpatialTree for BinaryTree<T> {
    type Data = T;

    #[inline]
    fn root_bounds(&self) -> Aabb {
        self.root
    }

    #[inline]
    fn locate(&self, p: Vec3) -> Option<CellId> {
        self.locate_cell(p)
    }

    #[inline]
    fn cell_count(&self) -> usize {
        self.cells.len()
    }

    #[inline]
    fn cell_bounds(&self, cell: CellId) -> Aabb {
        self.meta[cell.index()].bounds
    }

    #[inline]
    fn cell_depth(&self, cell: CellId) -> u32 {
        self.meta[cell.index()].depth
    }

    #[inline]
    fn data(&self, cell: CellId) -> &T {
        &self.cells[cell.index()]
    }

    fn visit_overlapping(&self, region: &Aabb, visit: &mut dyn FnMut(CellId)) {
        self.for_each_overlapping(region, |cell, _| visit(cell));
    }
}

/// The split coordinate of `bounds` along `axis`. Halves are added so that
/// huge coordinates cannot overflow; lookup and refinement share this.
#[inline]
pub(super) fn split_plane(bounds: &Aabb, axis: usize) -> f32 {
    bounds.min[axis] * 0.5 + bounds.max[axis] * 0.5
}

/// The axis after `axis` in the cycle x, y, z.
#[inline]
pub(super) fn next_axis(axis: usize) -> usize {
    if axis == 2 { 0 } else { axis + 1 }
}
