//! How much memory an SD-tree uses.

use super::{SdCell, SdTree};
use crate::spatial::BinaryTree;

/// Bytes and node counts of an [`SdTree`]. `total()` is what
/// [`SdTreeConfig::max_bytes`](super::SdTreeConfig::max_bytes) caps.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct SdTreeMemory {
    /// Spatial tree nodes (inner and leaf).
    pub spatial_nodes: usize,
    /// Spatial cells (leaves).
    pub cells: usize,
    /// Bytes of the spatial tree: node words, per-cell bounds and depth,
    /// and the inline part of every cell (`size_of::<SdCell>()`).
    pub spatial_bytes: usize,
    /// Nodes of all sampling quadtrees.
    pub quadtree_nodes: usize,
    /// Nodes of all building quadtrees.
    pub quadtree_building_nodes: usize,
    /// Heap bytes of all quadtrees, both copies and their sums.
    pub quadtree_bytes: usize,
    /// Heap bytes of the per-cell statistical weights and fraction
    /// statistics.
    pub statistics_bytes: usize,
}

impl SdTreeMemory {
    /// Everything.
    pub fn total(&self) -> usize {
        self.spatial_bytes + self.quadtree_bytes + self.statistics_bytes
    }

    /// The report for a spatial tree of cells holding [`SdCell`]s (the
    /// inline size of the whole cell type counts as spatial bytes).
    pub(crate) fn of<C: AsRef<SdCell>>(tree: &BinaryTree<C>) -> Self {
        let cells = || tree.data_slice().iter().map(AsRef::as_ref);
        Self {
            spatial_nodes: tree.node_count(),
            cells: tree.data_slice().len(),
            spatial_bytes: tree.bytes(),
            quadtree_nodes: cells().map(|c| c.directions.node_count()).sum(),
            quadtree_building_nodes: cells().map(|c| c.directions.building_node_count()).sum(),
            quadtree_bytes: cells().map(|c| c.quadtree_heap_bytes()).sum(),
            statistics_bytes: cells().map(|c| c.stats.bytes()).sum(),
        }
    }
}

impl SdTree {
    /// Bytes and node counts, per structure.
    pub fn memory(&self) -> SdTreeMemory {
        SdTreeMemory::of(&self.spatial)
    }

    /// Bytes per spatial node word.
    pub const SPATIAL_NODE_BYTES: usize = BinaryTree::<super::SdCell>::NODE_BYTES;
}
