//! How much memory the guiding field uses, per structure.

use super::GuidingField;
use crate::cut::{CutMemory, CutNode};
use crate::light_tree::LightHierarchy;
use crate::quadtree::NODE_BYTES;
use crate::sd_tree::SdTreeMemory;

/// Bytes of a [`GuidingField`], per structure, so the cuts can be set
/// beside the quadtrees (the paper: at `sigma = 0.01` the cuts take about
/// what PPG's quadtrees take).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct FieldMemory {
    /// The SD-tree's part: spatial tree (its `spatial_bytes` hold the
    /// inline part of every [`FieldCell`](super::FieldCell), the cuts'
    /// inline parts included), quadtrees and statistics.
    pub sd: SdTreeMemory,
    /// The cuts together. Their `inline_bytes` are already in
    /// `sd.spatial_bytes` and are not added again in the totals.
    pub cuts: CutMemory,
    /// The [`CutRules`](crate::learned::CutRules)'s tables, shared by all
    /// cells ([`CutRules::bytes`](crate::learned::CutRules::bytes)).
    pub shared_bytes: usize,
}

impl FieldMemory {
    /// Everything.
    pub fn total(&self) -> usize {
        self.capped() + self.shared_bytes
    }

    /// What [`SdTreeConfig::max_bytes`](crate::SdTreeConfig::max_bytes)
    /// caps: everything but the shared table.
    pub fn capped(&self) -> usize {
        self.sd.total() + self.cut_bytes()
    }

    /// Heap bytes of all cuts: sampled nodes and accumulating sums.
    pub fn cut_bytes(&self) -> usize {
        self.cuts.node_bytes + self.cuts.sum_bytes
    }

    /// Heap bytes of all quadtrees: both copies and their sums.
    pub fn quadtree_bytes(&self) -> usize {
        self.sd.quadtree_bytes
    }

    /// `cut_bytes / quadtree_bytes`: the paper's comparison, both
    /// structures with their training copies.
    pub fn cut_to_quadtree(&self) -> f64 {
        self.cut_bytes() as f64 / self.quadtree_bytes().max(1) as f64
    }

    /// The same for the sampled copies alone: cut nodes
    /// ([`CutNode::BYTES`] each) against sampling quadtree nodes
    /// (`NODE_BYTES` each, the quadtree's node size), what queries read.
    pub fn sampled_cut_to_quadtree(&self) -> f64 {
        let cuts = self.cuts.nodes * CutNode::BYTES;
        let quadtrees = self.sd.quadtree_nodes * NODE_BYTES;
        cuts as f64 / quadtrees.max(1) as f64
    }
}

impl<H: LightHierarchy> GuidingField<H> {
    /// Bytes used, per structure.
    pub fn memory(&self) -> FieldMemory {
        FieldMemory {
            sd: SdTreeMemory::of(&self.spatial),
            cuts: self
                .spatial
                .data_slice()
                .iter()
                .map(|c| c.cut.memory())
                .sum(),
            shared_bytes: self.rules.bytes(),
        }
    }
}
