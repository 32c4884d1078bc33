use super::BuildError;
use super::build::{BuildHeuristic, build, refit, spread};
use super::hierarchy::{LightHierarchy, NodeBounds};
use super::node::{LEAF_BIT, LightNode, NO_PARENT};
use crate::emitter::Emitters;
use crate::math::Aabb;
use alloc::vec::Vec;

/// The global light tree: a binary BVH over the scene's emitters, one emitter
/// per leaf, 32 bytes per node (see `LightNode`) plus 4 bytes per emitter
/// for its leaf.
///
/// Built once from an [`Emitters`] list and `Sync`; when the emitters move
/// or change power (an animation's next frame), [`LightTree::refit`]
/// updates it in place, keeping its shape (and so what the guides learned
/// over it).
#[derive(Clone, Debug)]
pub struct LightTree {
    pub(super) nodes: Vec<LightNode>,
    pub(super) leaf_of: Vec<u32>,
    pub(super) scene: Aabb,
    pub(super) depth: usize,
    /// The tree's spread (`build/refit.rs`) when it was built or loaded.
    pub(super) built_spread: f32,
    /// Each node's light sets (the union of its emitters'); empty when
    /// every emitter is in every set.
    pub(super) sets: Vec<u64>,
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

    /// A refit whose drift ([`LightTree::refit`]) passes this is worth a
    /// rebuild, even at the price of what a guide learned over the tree:
    /// measured, a drift of 1.2 to 1.5 made importance sampling over the
    /// refitted tree 1.1 to 1.7 times as noisy as over a rebuilt one, about
    /// what carrying a guide's learned state over is worth in an animation
    /// (docs/experiments/refit.md).
    pub const REBUILD_RATIO: f32 = 1.3;

    /// Updates the tree to `emitters` after they moved, turned or changed
    /// power: the same count in the same order (emitter `i` stays on its
    /// leaf), every bound, cone and power recomputed bottom-up over the
    /// tree's shape, which is kept. O(n), no allocation beyond the
    /// emitters' copy. The guides learned over the tree keep what they
    /// learned: hand them the refitted tree
    /// ([`Glt::set_light_tree`](crate::Glt::set_light_tree)).
    ///
    /// Returns how far the tree drifted: the spread of its clusters (the
    /// sum of their boxes' squared diagonals, over the root's) over the
    /// spread when it was built, 1 when nothing moved; it grows as lights
    /// leave the ones they were clustered with, and stays 1 for changes of
    /// power alone. Past [`LightTree::REBUILD_RATIO`], build a new
    /// tree (and start learning again). Errors as [`LightTree::build`]
    /// does, and [`BuildError::EmitterCount`] for another number of
    /// emitters; on an error the tree is unchanged.
    pub fn refit<E: Emitters + ?Sized>(&mut self, emitters: &E) -> Result<f32, BuildError> {
        let refitted = refit(self, emitters)?;
        self.nodes = refitted.nodes;
        self.scene = refitted.scene;
        self.sets = refitted.sets;
        let now = spread(&self.nodes, &self.scene);
        Ok(match (now, self.built_spread) {
            (now, built) if built > 0.0 => now / built,
            (now, _) if now > 0.0 => f32::INFINITY,
            _ => 1.0,
        })
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
            + self.sets.len() * core::mem::size_of::<u64>()
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

    #[inline]
    fn light_sets(&self, node: u32) -> u64 {
        match self.sets.is_empty() {
            true => u64::MAX,
            false => self.sets.get(node as usize).copied().unwrap_or(0),
        }
    }

    #[inline]
    fn has_light_sets(&self) -> bool {
        !self.sets.is_empty()
    }
}
