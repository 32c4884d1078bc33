//! The end of an iteration: learned fractions, quadtrees, spatial splits.

use super::state::SdState;
use super::{SdCell, SdTree};
use crate::spatial::{BinaryTree, Growth, RefineOutcome, content_scale};

impl SdState {
    /// Ends iteration `k = self.iteration` over the cells of `tree`: every
    /// cell's [`SdCell::end_iteration`] and then `per_cell` (what else the
    /// cell holds, whose growth `other` reports), then PPG's spatial split
    /// rule on the collected weights within `max_bytes`, counting
    /// `heap_bytes` per cell. Within `max_bytes` the quadtrees and the
    /// other content grow by one shared factor (`src/spatial/budget.rs`),
    /// passed to `per_cell`; `on_split(lower, upper, axis)` adjusts the
    /// two halves of a cell split along `axis` (the upper a copy of the
    /// lower). Returns what the spatial pass did.
    pub(crate) fn refine<C: AsRef<SdCell> + AsMut<SdCell> + Clone>(
        &mut self,
        tree: &mut BinaryTree<C>,
        other: impl Fn(&C) -> Growth,
        mut per_cell: impl FnMut(&mut C, Option<f64>),
        mut on_split: impl FnMut(&mut C, &mut C, usize),
        heap_bytes: impl FnMut(&C) -> usize,
    ) -> RefineOutcome {
        let config = self.config;
        let scale = content_scale(
            config.max_bytes,
            tree.bytes(),
            tree.data_slice()
                .iter()
                .flat_map(|c| [c.as_ref().growth(&config), other(c)]),
        );
        for cell in tree.data_slice_mut() {
            let cap = scale.and_then(|_| cell.as_ref().growth(&config).cap(scale));
            cell.as_mut().end_iteration(&config, cap);
            per_cell(cell, scale);
        }
        let threshold = config.split_threshold(self.iteration);
        let outcome = tree.refine_along(
            |cell, _| cell.as_ref().split_weight > threshold,
            |cell, axis| {
                cell.as_mut().split_weight *= 0.5;
                let mut upper = cell.clone();
                on_split(cell, &mut upper, axis);
                upper
            },
            heap_bytes,
            config.max_bytes,
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
        self.state.refine(
            &mut self.spatial,
            |_| Growth::default(),
            |_, _| {},
            |_, _, _| {},
            |cell| cell.heap_bytes(),
        )
    }
}
