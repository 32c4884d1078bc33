//! Visiting the cells that overlap a box (for box filters).

use super::binary_tree::{LEAF, next_axis, split_plane};
use super::{BinaryTree, CellId};
use crate::math::Aabb;
use smallvec::SmallVec;

impl<T> BinaryTree<T> {
    /// Calls `visit(cell, cell_bounds)` for every cell whose closed box
    /// intersects the closed box `region`, in depth-first order (lower child
    /// first). Nothing is visited for an empty or non-finite region. Cells
    /// that only touch `region` are visited too; weigh them by overlap
    /// volume.
    pub fn for_each_overlapping(&self, region: &Aabb, mut visit: impl FnMut(CellId, &Aabb)) {
        if !region.is_finite() || region.is_empty() || !intersects(region, &self.root) {
            return;
        }
        // (node, bounds, axis); the stack holds at most one pending sibling
        // per level, so it spills to the heap only for very deep trees.
        let mut stack: SmallVec<[(u32, Aabb, u8); 48]> = SmallVec::new();
        stack.push((0, self.root, 0));
        while let Some((node, bounds, axis)) = stack.pop() {
            let word = self.nodes[node as usize];
            if word & LEAF != 0 {
                visit(CellId(word & !LEAF), &bounds);
                continue;
            }
            let a = axis as usize;
            let mid = split_plane(&bounds, a);
            let next = next_axis(a) as u8;
            let mut upper = bounds;
            upper.min[a] = mid;
            let mut lower = bounds;
            lower.max[a] = mid;
            if region.max[a] >= mid {
                stack.push((word + 1, upper, next));
            }
            if region.min[a] <= mid {
                stack.push((word, lower, next));
            }
        }
    }
}

#[inline]
fn intersects(a: &Aabb, b: &Aabb) -> bool {
    a.min.cmple(b.max).all() && b.min.cmple(a.max).all()
}
