//! The end of an iteration: learned fractions, quadtrees, spatial splits.

use super::state::SdState;
use super::{SdCell, SdTree};
use crate::spatial::{BinaryTree, RefineOutcome};

impl SdState {
    /// Ends iteration `k = self.iteration` over the cells of `tree`: every
    /// cell's [`SdCell::end_iteration`] and then `per_cell` (what else the
    /// cell holds), then PPG's spatial split rule on the collected weights
    /// within `max_bytes`, counting `heap_bytes` per cell. Returns what the
    /// spatial pass did.
    pub(crate) fn refine<C: AsRef<SdCell> + AsMut<SdCell> + Clone>(
        &mut self,
        tree: &mut BinaryTree<C>,
        mut per_cell: impl FnMut(&mut C),
        heap_bytes: impl FnMut(&C) -> usize,
    ) -> RefineOutcome {
        for cell in tree.data_slice_mut() {
            cell.as_mut().end_iteration(&self.config);
            per_cell(cell);
        }
        let outcome = tree.split_by_weight(
            self.config.split_threshold(self.iteration),
            |cell| cell.as_ref().split_weight,
            |cell| cell.as_mut().split_weight *= 0.5,
            heap_bytes,
            self.config.max_bytes,
        );
        for cell in tree.data_slice_mut() {
            cell.as_mut().split_weight = 0.0;
        }
        self.iteration = self.iteration.saturating_add(1);
        outcome
    }
}

impl SdTree {
    /// Ends iteration `k = self.iteration()`: optimises the learned
    /// fractions, makes every cell's building quadtree its sampling one and
    /// refines its topology, splits cells whose weight exceeds
    /// `c * sqrt(2^k)` (copies with halved weight, recursively, within
    /// [`SdTreeConfig::max_bytes`](super::SdTreeConfig::max_bytes)), then
    /// zeroes the collected sums. Returns what the spatial pass did.
    pub fn refine(&mut self) -> RefineOutcome {
        self.state
            .refine(&mut self.tree, |_| {}, |cell| cell.heap_bytes())
    }
}
