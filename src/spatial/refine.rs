//! Refinement: splitting cells, several levels per pass, within a budget.

use super::BinaryTree;
use super::binary_tree::{CellMeta, LEAF, next_axis, split_plane};
use alloc::collections::VecDeque;

/// What one refinement pass did.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct RefineOutcome {
    /// Cells split (each split adds one cell and two nodes).
    pub splits: usize,
    /// Splits asked for but refused because the memory budget was reached.
    pub refused_by_budget: usize,
    /// Splits asked for but refused because the cell is too small to halve
    /// in `f32` or the tree reached 2^31 nodes.
    pub refused_by_precision: usize,
}

/// The most nodes a tree may have: node words keep one bit for the leaf flag.
const MAX_NODES: usize = (LEAF as usize) - 1;

impl<T> BinaryTree<T> {
    /// Splits cells while `should_split(data, depth)` says so.
    ///
    /// A split turns the cell into an inner node with two child cells. The
    /// lower child (coordinate below the midpoint) keeps the cell's number
    /// and its data, which `split` may modify in place; the upper child gets
    /// the next free number and the value `split` returns. PPG's rule is
    /// `should_split = weight > threshold` and `split = halve the weight,
    /// return a copy`.
    ///
    /// Both children are asked again, so one pass can split a cell several
    /// levels deep. Cells are visited breadth first (all existing cells,
    /// then their children, ...), so a budget is spent on coarse splits
    /// before fine ones. `should_split` may be called more than once for a
    /// cell.
    ///
    /// `max_bytes` caps [`BinaryTree::bytes`] after the pass (memory a
    /// `T` owns on the heap is not counted; see
    /// [`BinaryTree::refine_with_heap`]). A cell whose midpoint is not
    /// representable in `f32` is never split.
    pub fn refine(
        &mut self,
        should_split: impl FnMut(&T, u32) -> bool,
        split: impl FnMut(&mut T) -> T,
        max_bytes: Option<usize>,
    ) -> RefineOutcome {
        self.refine_with_heap(should_split, split, |_| 0, max_bytes)
    }

    /// Like [`BinaryTree::refine`], counting `heap_bytes(data)` per cell
    /// towards the budget as well: the pass keeps
    /// `bytes() + sum of heap_bytes` at or below `max_bytes`. A split is
    /// charged two nodes, one cell's bookkeeping and `T`, and the heap bytes
    /// of the cell before the split (the copy is assumed as large as the
    /// original); after the split the upper child's real size is charged.
    pub fn refine_with_heap(
        &mut self,
        should_split: impl FnMut(&T, u32) -> bool,
        mut split: impl FnMut(&mut T) -> T,
        heap_bytes: impl FnMut(&T) -> usize,
        max_bytes: Option<usize>,
    ) -> RefineOutcome {
        self.refine_along(should_split, |t, _| split(t), heap_bytes, max_bytes)
    }

    /// [`BinaryTree::refine_with_heap`] telling `split` the axis the cell
    /// is halved along (0, 1, 2: x, y, z).
    pub(crate) fn refine_along(
        &mut self,
        mut should_split: impl FnMut(&T, u32) -> bool,
        mut split: impl FnMut(&mut T, usize) -> T,
        mut heap_bytes: impl FnMut(&T) -> usize,
        max_bytes: Option<usize>,
    ) -> RefineOutcome {
        let mut outcome = RefineOutcome::default();
        let fixed = 2 * Self::NODE_BYTES + Self::CELL_META_BYTES + core::mem::size_of::<T>();
        let mut used = match max_bytes {
            Some(_) => self.bytes() + self.cells.iter().map(&mut heap_bytes).sum::<usize>(),
            None => 0,
        };
        let mut queue: VecDeque<u32> = (0..self.cells.len() as u32).collect();
        while let Some(c) = queue.pop_front() {
            let ci = c as usize;
            let meta = self.meta[ci];
            if !should_split(&self.cells[ci], meta.depth) {
                continue;
            }
            let axis = (meta.depth % 3) as usize;
            let mid = split_plane(&meta.bounds, axis);
            let halvable = meta.bounds.min[axis] < mid && mid < meta.bounds.max[axis];
            if !halvable || self.nodes.len() + 2 > MAX_NODES {
                outcome.refused_by_precision += 1;
                continue;
            }
            if let Some(budget) = max_bytes {
                let cost = fixed + heap_bytes(&self.cells[ci]);
                if used.saturating_add(cost) > budget {
                    outcome.refused_by_budget += 1;
                    continue;
                }
            }
            let upper_data = split(&mut self.cells[ci], axis);
            if max_bytes.is_some() {
                used += fixed + heap_bytes(&upper_data);
            }
            let first = self.nodes.len() as u32;
            let new_cell = self.cells.len() as u32;
            self.nodes[meta.node as usize] = first;
            self.nodes.push(c | LEAF);
            self.nodes.push(new_cell | LEAF);
            let mut lower = meta.bounds;
            lower.max[axis] = mid;
            let mut upper = meta.bounds;
            upper.min[axis] = mid;
            debug_assert_eq!(next_axis(axis), ((meta.depth + 1) % 3) as usize);
            self.meta[ci] = CellMeta {
                bounds: lower,
                depth: meta.depth + 1,
                node: first,
            };
            self.meta.push(CellMeta {
                bounds: upper,
                depth: meta.depth + 1,
                node: first + 1,
            });
            self.cells.push(upper_data);
            outcome.splits += 1;
            queue.push_back(c);
            queue.push_back(new_cell);
        }
        if outcome.splits > 0 {
            self.nodes.shrink_to_fit();
            self.meta.shrink_to_fit();
            self.cells.shrink_to_fit();
        }
        outcome
    }
}
