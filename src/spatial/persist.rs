//! Saving and loading a [`BinaryTree`]'s skeleton (the root cube and the
//! node words; bounds and depths are recomputed, not stored) with its
//! cells written and read by the owner.

use super::binary_tree::{BinaryTree, CellMeta, LEAF, split_plane};
use crate::math::Aabb;
use crate::persist::{LoadError, Reader, Writer};
use alloc::vec;
use alloc::vec::Vec;

impl<T> BinaryTree<T> {
    /// Whether `other` has the same cube and the same cells (the same
    /// splits, in the same order).
    pub(crate) fn same_layout<U>(&self, other: &BinaryTree<U>) -> bool {
        self.root == other.root && self.nodes == other.nodes
    }

    /// Writes the root cube, the node words and then each cell with
    /// `cell`.
    pub(crate) fn write(&self, w: &mut Writer, mut cell: impl FnMut(&T, &mut Writer)) {
        w.vec3(self.root.min);
        w.vec3(self.root.max);
        w.len(self.nodes.len());
        for &n in &self.nodes {
            w.u32(n);
        }
        w.len(self.cells.len());
        for c in &self.cells {
            cell(c, w);
        }
    }

    /// Reads what [`BinaryTree::write`] wrote, each cell with `cell`
    /// (which checks it), and checks the skeleton: a finite, non-empty
    /// root; every node reached once from the root, children after their
    /// parent, every cell on exactly one leaf; no split of a cell too small
    /// to halve. Cell bounds and depths are recomputed from the root.
    pub(crate) fn read(
        r: &mut Reader<'_>,
        mut cell: impl FnMut(&mut Reader<'_>) -> Result<T, LoadError>,
    ) -> Result<Self, LoadError> {
        let at = r.offset();
        let root = crate::math::Aabb {
            min: r.vec3("spatial tree: root")?,
            max: r.vec3("spatial tree: root")?,
        };
        if !(root.min.is_finite() && root.max.is_finite() && root.min.cmplt(root.max).all()) {
            return Err(Reader::invalid("spatial tree: root", at));
        }
        let nodes_at = r.offset();
        let count = r.len("spatial tree: node count", 4)?;
        let mut nodes = Vec::with_capacity(count);
        for _ in 0..count {
            nodes.push(r.u32("spatial tree: node")?);
        }
        let cells_count = r.len("spatial tree: cell count", 1)?;
        let mut cells = Vec::with_capacity(cells_count);
        for _ in 0..cells_count {
            cells.push(cell(r)?);
        }
        let meta = skeleton(&nodes, cells.len(), root)
            .ok_or_else(|| Reader::invalid("spatial tree: nodes", nodes_at))?;
        Ok(Self {
            nodes,
            cells,
            meta,
            root,
        })
    }
}

/// The cells' bookkeeping for node words `nodes` over `root`, or `None`
/// when the words are not one tree over `cells` cells.
fn skeleton(nodes: &[u32], cells: usize, root: Aabb) -> Option<Vec<CellMeta>> {
    if nodes.is_empty() || cells == 0 {
        return None;
    }
    let mut seen = vec![false; nodes.len()];
    let mut meta: Vec<Option<CellMeta>> = vec![None; cells];
    let mut stack = vec![(0usize, root, 0u32)];
    while let Some((i, bounds, depth)) = stack.pop() {
        if core::mem::replace(seen.get_mut(i)?, true) {
            return None;
        }
        let word = nodes[i];
        if word & LEAF != 0 {
            let slot = meta.get_mut((word & !LEAF) as usize)?;
            if slot.is_some() {
                return None;
            }
            *slot = Some(CellMeta {
                bounds,
                depth,
                node: i as u32,
            });
            continue;
        }
        let first = word as usize;
        if first <= i || first + 1 >= nodes.len() {
            return None;
        }
        let axis = (depth % 3) as usize;
        let mid = split_plane(&bounds, axis);
        if !(bounds.min[axis] < mid && mid < bounds.max[axis]) {
            return None;
        }
        let (mut lower, mut upper) = (bounds, bounds);
        lower.max[axis] = mid;
        upper.min[axis] = mid;
        stack.push((first, lower, depth + 1));
        stack.push((first + 1, upper, depth + 1));
    }
    if seen.iter().any(|s| !s) {
        return None;
    }
    meta.into_iter().collect()
}
