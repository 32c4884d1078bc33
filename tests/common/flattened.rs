//! [`Flattened`]: an instanced light tree seen as a plain hierarchy.

use guiding::light_tree::NodeBounds;
use guiding::{InstancedLightTree, LightHierarchy};

/// The instanced tree without [`LightHierarchy::as_instanced`]: the GLT
/// over it builds its tables over every node of the flat tree it stands
/// for, in world space (what it did before its tables were shared per
/// mesh). The reference the per-mesh tables are checked and measured
/// against.
pub struct Flattened<'a>(pub &'a InstancedLightTree);

impl LightHierarchy for Flattened<'_> {
    fn root(&self) -> Option<u32> {
        self.0.root()
    }
    fn children(&self, node: u32) -> Option<[u32; 2]> {
        self.0.children(node)
    }
    fn parent(&self, node: u32) -> Option<u32> {
        self.0.parent(node)
    }
    fn power(&self, node: u32) -> f32 {
        self.0.power(node)
    }
    fn node_bounds(&self, node: u32) -> NodeBounds {
        self.0.node_bounds(node)
    }
    fn emitter(&self, node: u32) -> Option<u32> {
        self.0.emitter(node)
    }
    fn leaf(&self, emitter: u32) -> Option<u32> {
        self.0.leaf(emitter)
    }
    fn node_count(&self) -> usize {
        self.0.node_count()
    }
    fn emitter_count(&self) -> usize {
        self.0.emitter_count()
    }
}
