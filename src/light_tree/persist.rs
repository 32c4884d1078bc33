//! Saving and loading a [`LightTree`] (`src/persist/mod.rs` has the
//! header; `docs/format.md` the layout).

use super::LightTree;
use super::hierarchy::LightHierarchy;
use super::node::{LEAF_BIT, LightNode, NO_PARENT};
use super::shape::{hash_nodes, shape_fingerprint};
use crate::math::Aabb;
use crate::persist::{Kind, LoadError, Reader, Writer};
use alloc::vec;
use alloc::vec::Vec;

impl LightTree {
    /// The tree as bytes: a header, then the scene box, the nodes and each
    /// emitter's leaf (`src/persist/mod.rs`).
    pub fn to_bytes(&self) -> Vec<u8> {
        let mut w = Writer::default();
        self.write(&mut w);
        w.finish(Kind::LightTree)
    }

    /// The tree saved by [`LightTree::to_bytes`], checked: a tree that
    /// loads is a tree (every node reached once from the root, links and
    /// parents agree, each emitter on exactly one leaf, powers finite and
    /// non-negative), so it samples exactly like the one saved.
    pub fn from_bytes(bytes: &[u8]) -> Result<Self, LoadError> {
        let mut r = Reader::open(bytes, Kind::LightTree)?;
        let tree = Self::read(&mut r)?;
        r.end()?;
        Ok(tree)
    }

    pub(crate) fn write(&self, w: &mut Writer) {
        w.vec3(self.scene.min);
        w.vec3(self.scene.max);
        w.len(self.nodes.len());
        for n in &self.nodes {
            for x in n.words() {
                w.u32(x);
            }
        }
        w.len(self.leaf_of.len());
        for &l in &self.leaf_of {
            w.u32(l);
        }
        // Since version 5: each node's light sets, none when every node is
        // in every set.
        w.len(self.sets.len());
        for &s in &self.sets {
            w.u64(s);
        }
    }

    pub(crate) fn read(r: &mut Reader<'_>) -> Result<Self, LoadError> {
        let at = r.offset();
        let scene = crate::math::Aabb {
            min: r.vec3("light tree: scene box")?,
            max: r.vec3("light tree: scene box")?,
        };
        let count = r.len("light tree: node count", 32)?;
        let mut nodes = Vec::with_capacity(count);
        for _ in 0..count {
            let mut words = [0u32; 8];
            for x in &mut words {
                *x = r.u32("light tree: node")?;
            }
            nodes.push(LightNode::from_words(words));
        }
        let emitters = r.len("light tree: emitter count", 4)?;
        let leaf_at = r.offset();
        let mut leaf_of = Vec::with_capacity(emitters);
        for _ in 0..emitters {
            leaf_of.push(r.u32("light tree: leaf of emitter")?);
        }
        let box_ok = if nodes.is_empty() {
            scene == Aabb::EMPTY || (scene.min.is_finite() && scene.max.is_finite())
        } else {
            scene.min.is_finite() && scene.max.is_finite() && scene.min.cmple(scene.max).all()
        };
        if !box_ok {
            return Err(Reader::invalid("light tree: scene box", at));
        }
        let depth = check_structure(&nodes, &leaf_of).map_err(|field| {
            Reader::invalid(field, if field.contains("leaf") { leaf_at } else { at })
        })?;
        let sets = match r.version() {
            5.. => {
                let sets_at = r.offset();
                let count = r.len("light tree: light set count", 8)?;
                let mut sets = Vec::with_capacity(count);
                for _ in 0..count {
                    sets.push(r.u64("light tree: light sets")?);
                }
                if !check_sets(&nodes, &sets) {
                    return Err(Reader::invalid("light tree: light sets", sets_at));
                }
                sets
            }
            _ => Vec::new(),
        };
        let built_spread = super::build::spread(&nodes, &scene);
        Ok(Self {
            nodes,
            leaf_of,
            scene,
            depth,
            built_spread,
            sets,
        })
    }
}

/// Whether `sets` are a tree's light sets: none, or one per node with each
/// inner node's the union of its children's, and not every node in every
/// set (that is saved as none).
fn check_sets(nodes: &[LightNode], sets: &[u64]) -> bool {
    if sets.is_empty() {
        return true;
    }
    sets.len() == nodes.len()
        && sets.iter().any(|&s| s != u64::MAX)
        && nodes.iter().enumerate().all(|(i, n)| {
            n.is_leaf() || {
                let (l, r) = (i + 1, n.link() as usize);
                sets[i] == sets[l] | sets[r]
            }
        })
}

/// Checks that `nodes` is one depth-first tree from node 0 whose leaves
/// hold each emitter of `leaf_of` once, with finite non-negative powers;
/// returns its depth.
fn check_structure(nodes: &[LightNode], leaf_of: &[u32]) -> Result<usize, &'static str> {
    let n = nodes.len();
    if n == 0 {
        return if leaf_of.is_empty() {
            Ok(0)
        } else {
            Err("light tree: leaf of emitter")
        };
    }
    if nodes[0].parent() != NO_PARENT {
        return Err("light tree: root parent");
    }
    let mut seen = vec![false; n];
    let mut leaves = 0usize;
    let mut depth = 0usize;
    let mut stack = vec![(0usize, 0usize)];
    while let Some((i, d)) = stack.pop() {
        if core::mem::replace(&mut seen[i], true) {
            return Err("light tree: node reached twice");
        }
        let node = &nodes[i];
        let p = node.power();
        if !(p >= 0.0 && p.is_finite()) {
            return Err("light tree: node power");
        }
        depth = depth.max(d);
        if node.is_leaf() {
            let e = (node.link() & !LEAF_BIT) as usize;
            if leaf_of.get(e) != Some(&(i as u32)) {
                return Err("light tree: leaf of emitter");
            }
            leaves += 1;
            continue;
        }
        let (l, r) = (i + 1, node.link() as usize);
        if l >= n || r >= n || r <= l {
            return Err("light tree: child link");
        }
        for c in [l, r] {
            if nodes[c].parent() as usize != i {
                return Err("light tree: parent link");
            }
            stack.push((c, d + 1));
        }
    }
    if seen.iter().any(|s| !s) {
        return Err("light tree: node not reached");
    }
    if leaves != leaf_of.len() {
        return Err("light tree: leaf of emitter");
    }
    Ok(depth)
}

/// Reads the saved binding of learned state to its light hierarchy and
/// checks it against `tree`: since format version 4 the hierarchy's shape
/// ([`shape_fingerprint`]: a tree and its refits match), before it the
/// whole tree ([`fingerprint`]: bounds and powers too).
pub(crate) fn read_fingerprint<H: LightHierarchy + ?Sized>(
    r: &mut crate::persist::Reader<'_>,
    tree: &H,
) -> Result<(), crate::persist::LoadError> {
    let saved = r.u64("light tree fingerprint")?;
    let given = match r.version() {
        4.. => shape_fingerprint(tree),
        _ => fingerprint(tree),
    };
    if saved == given {
        Ok(())
    } else {
        Err(crate::persist::LoadError::LightTreeMismatch { saved, given })
    }
}

/// A fingerprint of a light hierarchy: FNV-1a 64 over every node's
/// children, emitter, power, decoded bounds and (when it has any) light
/// sets, in node order. Equal
/// hierarchies (the same lights built the same way) have equal
/// fingerprints; before format version 4, learned state was only loaded
/// against its own (now: [`shape_fingerprint`]). For an
/// [`InstancedLightTree`](super::InstancedLightTree), FNV-1a 64 over its
/// parts: its counts, the fingerprints of its top tree and meshes, each
/// instance's mesh, transform and power scale (O(top and mesh nodes +
/// instances)).
pub fn fingerprint<H: LightHierarchy + ?Sized>(tree: &H) -> u64 {
    if let Some(inst) = tree.as_instanced() {
        return inst.hash_parts(fingerprint, |h, p| {
            let m = p.transform.to_cols_array();
            for x in m.into_iter().chain([p.power_scale]) {
                h.u32(x.to_bits());
            }
        });
    }
    hash_nodes(tree, |h, i| {
        let b = tree.node_bounds(i);
        h.u32(b.power.to_bits());
        for v in [b.bounds.min, b.bounds.max, b.cone.axis] {
            for x in v.to_array() {
                h.u32(x.to_bits());
            }
        }
        h.u32(b.cone.cos_theta_o.to_bits());
        h.u32(b.cone.cos_theta_e.to_bits());
        h.u32(u32::from(b.two_sided));
        // Light sets only when there are any: fingerprints of trees without
        // them are what they were.
        if tree.has_light_sets() {
            let s = tree.light_sets(i);
            h.u32(s as u32);
            h.u32((s >> 32) as u32);
        }
    })
}
