use super::{EmitterPath, InstancedLightTree};
use crate::math::{Aabb, LightCone, Side};

/// What a tree node knows about the lights below it: enough for the
/// importance heuristics of Estevez & Kulla and pbrt-v4.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NodeBounds {
    /// Bounds of every emitter below (conservative).
    pub bounds: Aabb,
    /// Bound of their emission directions (conservative).
    pub cone: LightCone,
    /// Whether any emitter below is two-sided.
    pub two_sided: bool,
    /// Total power below.
    pub power: f32,
}

/// A binary light hierarchy with one emitter per leaf.
///
/// Nodes are named by `u32` indices. Every emitter `0..emitter_count()` has
/// exactly one leaf. Implementations answer in O(1) per call except
/// [`LightHierarchy::path`], which is O(depth) and has no depth limit.
pub trait LightHierarchy {
    /// The root; `None` when there are no emitters.
    fn root(&self) -> Option<u32>;

    /// The two children of an inner node; `None` for a leaf.
    fn children(&self, node: u32) -> Option<[u32; 2]>;

    /// The parent of `node`; `None` for the root.
    fn parent(&self, node: u32) -> Option<u32>;

    /// Total power (flux) of the emitters below `node`.
    fn power(&self, node: u32) -> f32;

    /// Spatial and directional bounds of the emitters below `node`.
    fn node_bounds(&self, node: u32) -> NodeBounds;

    /// The emitter of a leaf; `None` for an inner node.
    fn emitter(&self, node: u32) -> Option<u32>;

    /// The leaf of `emitter`; `None` when out of range.
    fn leaf(&self, emitter: u32) -> Option<u32>;

    /// Number of nodes.
    fn node_count(&self) -> usize;

    /// Number of emitters (leaves).
    fn emitter_count(&self) -> usize;

    /// The light sets of the emitters below `node` (the union of theirs,
    /// see [`Emitters::light_sets`](crate::Emitters::light_sets)); every
    /// set by default.
    fn light_sets(&self, _node: u32) -> u64 {
        u64::MAX
    }

    /// Whether some emitter is not in every light set (else the walks skip
    /// the sets entirely); false by default.
    fn has_light_sets(&self) -> bool {
        false
    }

    /// This hierarchy as an [`InstancedLightTree`], when it is one: the
    /// GLT then lays out its tables once per mesh, shared by the mesh's
    /// instances, instead of once per node of the flat tree it stands for
    /// (a few megabytes instead of gigabytes for thousands of instances of
    /// a large mesh). `None` by default, which a hierarchy of your own
    /// keeps.
    fn as_instanced(&self) -> Option<&InstancedLightTree> {
        None
    }

    /// The root-to-leaf path of `emitter`, at any depth; `None` when out of
    /// range.
    fn path(&self, emitter: u32) -> Option<EmitterPath> {
        let mut node = self.leaf(emitter)?;
        let mut path = EmitterPath::new();
        path.push_leaf(node);
        while let Some(parent) = self.parent(node) {
            let [left, _] = self.children(parent)?;
            let side = if left == node {
                Side::Left
            } else {
                Side::Right
            };
            path.push_parent(parent, side);
            node = parent;
        }
        path.finish();
        Some(path)
    }
}

/// A shared or borrowed hierarchy is a hierarchy: the guiding structures own
/// their light tree through any of these, so a renderer chooses between
/// `Glt<LightTree>` (owned), `Glt<Arc<LightTree>>` (shared with the scene)
/// and `Glt<&LightTree>` (borrowed).
macro_rules! forward_hierarchy {
    ($($ptr:ty),*) => {$(
        impl<T: LightHierarchy + ?Sized> LightHierarchy for $ptr {
            #[inline(always)]
            fn root(&self) -> Option<u32> {
                (**self).root()
            }
            #[inline(always)]
            fn children(&self, node: u32) -> Option<[u32; 2]> {
                (**self).children(node)
            }
            #[inline(always)]
            fn parent(&self, node: u32) -> Option<u32> {
                (**self).parent(node)
            }
            #[inline(always)]
            fn power(&self, node: u32) -> f32 {
                (**self).power(node)
            }
            #[inline(always)]
            fn node_bounds(&self, node: u32) -> NodeBounds {
                (**self).node_bounds(node)
            }
            #[inline(always)]
            fn emitter(&self, node: u32) -> Option<u32> {
                (**self).emitter(node)
            }
            #[inline(always)]
            fn leaf(&self, emitter: u32) -> Option<u32> {
                (**self).leaf(emitter)
            }
            #[inline(always)]
            fn node_count(&self) -> usize {
                (**self).node_count()
            }
            #[inline(always)]
            fn emitter_count(&self) -> usize {
                (**self).emitter_count()
            }
            #[inline(always)]
            fn path(&self, emitter: u32) -> Option<EmitterPath> {
                (**self).path(emitter)
            }
            #[inline(always)]
            fn light_sets(&self, node: u32) -> u64 {
                (**self).light_sets(node)
            }
            #[inline(always)]
            fn has_light_sets(&self) -> bool {
                (**self).has_light_sets()
            }
            #[inline(always)]
            fn as_instanced(&self) -> Option<&InstancedLightTree> {
                (**self).as_instanced()
            }
        }
    )*};
}

forward_hierarchy!(
    &T,
    alloc::boxed::Box<T>,
    alloc::rc::Rc<T>,
    alloc::sync::Arc<T>
);
