use super::BuildError;
use super::build::{BuildHeuristic, build};
use super::hierarchy::{LightHierarchy, NodeBounds};
use super::node::{LEAF_BIT, LightNode, NO_PARENT};
use crate::emitter::Emitters;
use crate::math::Aabb;
use alloc::vec::Vec;

/// The global light tree: a binary BVH over the scene's emitters, one emitter
/// per leaf, 32 bytes per node (see `LightNode`) plus 4 bytes per emitter
/// for its leaf.
///
/// Built once from an [`Emitters`] list; immutable and `Sync` afterwards.
#[derive(Clone, Debug)]
pub struct LightTree {
    pub(super) nodes: Vec<LightNode>,
    pub(super) leaf_of: Vec<u32>,
    pub(super) scene: Aabb,
    pub(super) depth: usize,
}

impl LightTree {
    /// Builds the tree over `emitters` with `heuristic`.
    ///
    /// An empty list gives an empty tree. Emitters with zero power are kept
    /// (they are simply never sampled by power). Non-finite or empty bounds,
    /// NaN, infinite or negative power or area, and non-finite cones are
    /// typed errors naming the emitter. O(n log n).
    pub fn build<E: Emitters + ?Sized>(
        emitters: &E,
        heuristic: BuildHeuristic,
    ) -> Result<Self, BuildError> {
        build(emitters, heuristic)
    }

    /// The nodes, root first, depth-first.
    pub fn nodes(&self) -> &[LightNode] {
        &self.nodes
    }

    /// The box every node's bounds are quantised in (the root's bounds).
    pub fn scene_bounds(&self) -> Aabb {
        self.scene
    }

    /// The depth of the deepest leaf (0 for a single emitter).
    pub fn depth(&self) -> usize {
        self.depth
    }

    /// Total power of all emitters.
    pub fn total_power(&self) -> f32 {
        self.nodes.first().map_or(0.0, LightNode::power)
    }

    /// Bytes of heap memory the tree holds.
    pub fn bytes(&self) -> usize {
        self.nodes.len() * core::mem::size_of::<LightNode>()
            + self.leaf_of.len() * core::mem::size_of::<u32>()
    }

    #[inline]
    fn node(&self, node: u32) -> Option<&LightNode> {
        self.nodes.get(node as usize)
    }
}

impl LightHierarchy for LightTree {
    #[inline]
    fn root(&self) -> Option<u32> {
        (!self.nodes.is_empty()).then_some(0)
    }

    #[inline]
    fn children(&self, node: u32) -> Option<[u32; 2]> {
        let n = self.node(node)?;
        (!n.is_leaf()).then(|| [node + 1, n.link()])
    }

    #[inline]
    fn parent(&self, node: u32) -> Option<u32> {
        let p = self.node(node)?.parent();
        (p != NO_PARENT).then_some(p)
    }

    #[inline]
    fn power(&self, node: u32) -> f32 {
        self.node(node).map_or(0.0, LightNode::power)
    }

    #[inline]
    fn node_bounds(&self, node: u32) -> NodeBounds {
        match self.node(node) {
            Some(n) => n.decode(&self.scene),
            None => NodeBounds {
                bounds: Aabb::EMPTY,
                cone: crate::math::LightCone::SPHERE,
                two_sided: false,
                power: 0.0,
            },
        }
    }

    #[inline]
    fn emitter(&self, node: u32) -> Option<u32> {
        let n = self.node(node)?;
        n.is_leaf().then(|| n.link() & !LEAF_BIT)
    }

    #[inline]
    fn leaf(&self, emitter: u32) -> Option<u32> {
        self.leaf_of.get(emitter as usize).copied()
    }

    fn node_count(&self) -> usize {
        self.nodes.len()
    }

    fn emitter_count(&self) -> usize {
        self.leaf_of.len()
    }
}
