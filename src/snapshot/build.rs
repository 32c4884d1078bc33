//! Taking a snapshot: a guide's spatial tree, its cells' cuts and the
//! shared light-tree tables copied into the plain-data arrays.

use super::layout::{
    BELOW_IMPORTANCE, Bounds, BoundsPair, Cell, GRANDCHILDREN, Header, LEAF, MAGIC, MODULATED,
    PRIOR, PRIOR_IMPORTANCE, TreeEntry, TreePair, VERSION,
};
use super::{Snapshot, SnapshotError};
use crate::cut::{BelowCut, CutNode, CutRules, GuidingCut, ImportanceBound, Prior, TreeTables};
use crate::light_tree::LightHierarchy;
use crate::spatial::{BinaryTree, SpatialTree};
use alloc::vec;
use alloc::vec::Vec;

/// The largest count or index a snapshot stores (31 bits: the top bit of
/// link words marks leaves).
const MAX_INDEX: usize = (LEAF - 1) as usize;

/// `n` as a snapshot index, or [`SnapshotError::TooLarge`] naming `what`.
fn index(n: usize, what: &'static str) -> Result<u32, SnapshotError> {
    if n <= MAX_INDEX {
        Ok(n as u32)
    } else {
        Err(SnapshotError::TooLarge(what))
    }
}

impl Snapshot {
    /// The snapshot of the cuts in `cells` (a GLT's or a field's spatial
    /// tree) over `rules`' light tree. O(cells + cut nodes + light-tree
    /// nodes).
    pub(crate) fn new<H: LightHierarchy, C: AsRef<GuidingCut>>(
        rules: &CutRules<H>,
        cells: &BinaryTree<C>,
    ) -> Result<Self, SnapshotError> {
        let tree = rules.light_tree();
        if tree.as_instanced().is_some() {
            return Err(SnapshotError::Unsupported("instanced light trees"));
        }
        if tree.has_light_sets() {
            return Err(SnapshotError::Unsupported("light sets"));
        }
        let config = rules.config();
        let k = config.unbounded.count as usize;
        let (tree_pairs, first_right, leaf_position) =
            light_tree_arrays(rules.tables(), tree.emitter_count())?;
        let bounds = bounds_pairs(rules.tables(), tree_pairs.len());

        let mut out_cells = Vec::with_capacity(cells.cell_count());
        let (mut cut_nodes, mut fractions, mut visibility) = (Vec::new(), Vec::new(), Vec::new());
        for data in cells.data_slice() {
            let cut: &GuidingCut = data.as_ref();
            let w = rules.cell_weights(cut);
            let flags =
                if w.modulate { MODULATED } else { 0 } | if w.prior > 0.0 { PRIOR } else { 0 };
            out_cells.push(Cell {
                first_node: index(cut_nodes.len(), "cut nodes")?,
                nodes: index(cut.nodes().len(), "cut nodes")?,
                first_visibility: index(visibility.len(), "visibilities")?,
                flags,
                unbounded: w.unbounded as f32,
                learned: w.learned as f32,
                floor: w.floor as f32,
                cut: w.cut as f32,
                prior: w.prior as f32,
                pad: [0; 3],
            });
            cut_nodes.extend_from_slice(cut.nodes());
            let f = cut.unbounded_fractions();
            fractions.extend((0..k).map(|i| f.get(i).copied().unwrap_or(0.0)));
            visibility
                .extend((0..cut.visibility().len()).map(|i| rules.visibility_at(cut, Some(i))));
        }
        let (root, spatial) = (cells.root_bounds(), cells.node_words().to_vec());
        let header = Header {
            magic: MAGIC,
            version: VERSION,
            flags: if config.below_cut == BelowCut::Importance {
                BELOW_IMPORTANCE
            } else {
                0
            } | if config.prior == Prior::Importance {
                PRIOR_IMPORTANCE
            } else {
                0
            } | if config.importance_bound == ImportanceBound::Grandchildren {
                GRANDCHILDREN
            } else {
                0
            },
            unbounded: index(k, "unbounded lights")?,
            root_min: root.min.to_array(),
            spatial_nodes: index(spatial.len(), "spatial nodes")?,
            root_max: root.max.to_array(),
            cells: index(out_cells.len(), "cells")?,
            cut_nodes: index(cut_nodes.len(), "cut nodes")?,
            tree_pairs: index(tree_pairs.len(), "light-tree nodes")?,
            emitters: index(leaf_position.len(), "emitters")?,
            visibilities: index(visibility.len(), "visibilities")?,
        };
        Ok(Self {
            header,
            spatial,
            cells: out_cells,
            cut_nodes,
            fractions,
            visibility,
            tree: tree_pairs,
            first_right,
            bounds,
            leaf_position,
        })
    }
}

/// The walk table's pairs, each pair's first-right leaf position and each
/// emitter's leaf position (`u32::MAX` for an emitter that is no leaf).
type TreeArrays = (Vec<TreePair>, Vec<u32>, Vec<u32>);

/// The light tree's arrays from its walk table: the pairs as they are,
/// then one depth-first pass (left first, an explicit stack: any depth)
/// numbering the leaves.
fn light_tree_arrays(tables: &TreeTables, emitters: usize) -> Result<TreeArrays, SnapshotError> {
    let walk = tables.walk().pairs();
    index(walk.len(), "light-tree nodes")?;
    let pairs: Vec<TreePair> = walk
        .iter()
        .map(|p| TreePair {
            nodes: p.0.map(|n| TreeEntry {
                split: n.split,
                link: n.link(),
            }),
        })
        .collect();
    let mut first_right = vec![0u32; pairs.len()];
    let mut leaf_position = vec![u32::MAX; emitters];
    let Some(root) = pairs.first().map(|p| p.nodes[0]) else {
        return Ok((pairs, first_right, leaf_position));
    };
    // Entries to visit; `Err(k)` marks where pair `k`'s right child starts.
    let mut stack: Vec<Result<TreeEntry, u32>> = vec![Ok(root)];
    let mut leaves = 0u32;
    while let Some(item) = stack.pop() {
        match item {
            Err(k) => first_right[k as usize] = leaves,
            Ok(entry) if entry.link & LEAF == 0 => {
                let k = entry.link;
                let [l, r] = pairs[k as usize].nodes;
                stack.extend([Ok(r), Err(k), Ok(l)]);
            }
            Ok(entry) => {
                let e = (entry.link & !LEAF) as usize;
                if let Some(slot) = leaf_position.get_mut(e) {
                    *slot = leaves;
                }
                leaves += 1;
            }
        }
    }
    Ok((pairs, first_right, leaf_position))
}

/// The importance table's entries as it holds them (the lanes of
/// `src/cut/child_weights.rs` read them as they are: weighing a child by
/// its children compares records of different pairs, so no pair may be
/// scaled on its own); none when no rule reads importance.
fn bounds_pairs(tables: &TreeTables, pairs: usize) -> Vec<BoundsPair> {
    let Some(table) = tables.importance() else {
        return Vec::new();
    };
    (0..pairs)
        .map(|k| BoundsPair {
            nodes: match table.entry_bytes(k) {
                Some(bytes) => bytes.map(|b| bytemuck::pod_read_unaligned(&b)),
                None => [Bounds::default(); 2],
            },
        })
        .collect()
}

/// `CutNode` is the snapshot's cut-node record as it is.
const _: () = assert!(core::mem::size_of::<CutNode>() == 12);

#[cfg(test)]
mod tests {
    use super::*;

    /// Counts and indices up to 2^31 - 1 fit; 2^31 (the leaf flag) is
    /// refused, named.
    #[test]
    fn indices_stop_below_the_leaf_flag() {
        assert_eq!(index((1 << 31) - 1, "x"), Ok((1 << 31) - 1));
        assert_eq!(index(1 << 31, "x"), Err(SnapshotError::TooLarge("x")));
    }
}
