//! A light hierarchy's shape: which nodes are children of which and which
//! emitter each leaf holds, without the bounds and powers a refit changes.
//! What the guides' learned state refers to (a cut names nodes, not
//! positions), so state learned over a tree stays valid over its refits.

use super::LightHierarchy;

/// True when `a` and `b` have the same shape: the same node count and
/// emitter count, the same children at every node and the same emitter at
/// every leaf. A tree and its refits ([`LightTree::refit`](super::LightTree::refit))
/// have; a tree rebuilt from moved lights usually has not. O(nodes); for
/// two [`InstancedLightTree`](super::InstancedLightTree)s, O(top and mesh
/// nodes + instances): the same top tree and mesh shapes and the same mesh
/// in every instance.
pub(crate) fn same_shape<A, B>(a: &A, b: &B) -> bool
where
    A: LightHierarchy + ?Sized,
    B: LightHierarchy + ?Sized,
{
    if let (Some(a), Some(b)) = (a.as_instanced(), b.as_instanced()) {
        return a.same_shape_as(b);
    }
    a.node_count() == b.node_count()
        && a.emitter_count() == b.emitter_count()
        && (0..a.node_count() as u32)
            .all(|n| a.children(n) == b.children(n) && a.emitter(n) == b.emitter(n))
}

/// A fingerprint of a hierarchy's shape: FNV-1a 64 over the node and
/// emitter counts, then every node's children and emitter, in node order.
/// Equal for a tree and its refits; what a saved GLT or field binds to
/// (format version 4 on).
///
/// For an [`InstancedLightTree`](super::InstancedLightTree), FNV-1a 64 over
/// its parts instead (its counts, the shape fingerprints of its top tree
/// and meshes, each instance's mesh), which fix the shape of the flat tree
/// it stands for: O(top and mesh nodes + instances), not O(placed
/// triangles). So state saved over an instanced tree loads over an
/// instanced tree of the same shape, not over a flat tree.
pub fn shape_fingerprint<H: LightHierarchy + ?Sized>(tree: &H) -> u64 {
    if let Some(inst) = tree.as_instanced() {
        return inst.hash_parts(shape_fingerprint, |_, _| {});
    }
    hash_nodes(tree, |_, _| {})
}

/// FNV-1a 64 over the node and emitter counts, then per node its children,
/// its emitter and what `more` adds for it, in node order: the shape, and
/// (through `more`) whatever else a fingerprint covers.
pub(super) fn hash_nodes<H: LightHierarchy + ?Sized>(
    tree: &H,
    mut more: impl FnMut(&mut crate::persist::Fnv, u32),
) -> u64 {
    let mut h = crate::persist::Fnv::new();
    let n = tree.node_count();
    h.u32(n as u32);
    h.u32(tree.emitter_count() as u32);
    for i in 0..n as u32 {
        let [l, r] = tree.children(i).unwrap_or([u32::MAX; 2]);
        h.u32(l);
        h.u32(r);
        h.u32(tree.emitter(i).unwrap_or(u32::MAX));
        more(&mut h, i);
    }
    h.finish()
}
