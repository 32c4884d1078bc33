//! [`GltMemory`]: the bytes a [`Glt`] uses, by part.

use super::Glt;
use crate::cut::{CutMemory, CutNode};
use crate::light_tree::LightHierarchy;
use crate::spatial::SpatialTree;

/// Bytes a [`Glt`] uses, by part.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct GltMemory {
    /// Number of cells.
    pub cells: usize,
    /// The cuts together (nodes, sums, inline parts of the cells' cuts).
    pub cuts: CutMemory,
    /// The spatial tree's own storage: node words, per-cell bookkeeping and
    /// the inline [`GltCell`](super::GltCell) values (which include the cuts' inline parts,
    /// so those are not added twice in [`GltMemory::total`]).
    pub spatial_bytes: usize,
    /// The [`CutRules`](crate::learned::CutRules)'s tables, shared by all
    /// cells ([`CutRules::bytes`](crate::learned::CutRules::bytes)).
    pub shared_bytes: usize,
}

impl GltMemory {
    /// Bytes of one cut node.
    pub const BYTES_PER_CUT_NODE: usize = CutNode::BYTES;

    /// Everything together.
    pub fn total(&self) -> usize {
        self.spatial_bytes + self.shared_bytes + self.cuts.node_bytes + self.cuts.sum_bytes
    }

    /// Average bytes per cell (cut nodes, sums and spatial share; the
    /// shared table excluded).
    pub fn bytes_per_cell(&self) -> f64 {
        (self.total() - self.shared_bytes) as f64 / self.cells.max(1) as f64
    }
}

impl<H: LightHierarchy> Glt<H> {
    /// Bytes used, by part.
    pub fn memory(&self) -> GltMemory {
        GltMemory {
            cells: self.spatial.cell_count(),
            cuts: self
                .spatial
                .data_slice()
                .iter()
                .map(|c| c.cut.memory())
                .sum(),
            spatial_bytes: self.spatial.bytes(),
            shared_bytes: self.rules.bytes(),
        }
    }
}
