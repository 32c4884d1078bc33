//! The end of an iteration: learned fractions, quadtrees, spatial splits.

use super::SdTree;
use super::cell::{FRACTION_BASE, WEIGHT};
use crate::spatial::RefineOutcome;

impl SdTree {
    /// Ends iteration `k = self.iteration()`: optimises the learned
    /// fractions, makes every cell's building quadtree its sampling one and
    /// refines its topology, splits cells whose weight exceeds
    /// `c * sqrt(2^k)` (copies with halved weight, recursively, within
    /// [`SdTreeConfig::max_bytes`](super::SdTreeConfig::max_bytes)), then
    /// zeroes the collected sums. Returns what the spatial pass did.
    pub fn refine(&mut self) -> RefineOutcome {
        let learn = self.config.learn_bsdf_fraction;
        let steps = self.config.fraction_steps;
        let quadtree = self.config.quadtree;
        for cell in self.tree.data_slice_mut() {
            cell.split_weight = cell.stats.get(WEIGHT);
            if learn {
                cell.learner.optimise(&cell.stats, FRACTION_BASE, steps);
            }
            cell.directions.refine(&quadtree);
            cell.stats.clear();
        }
        let threshold = self.config.split_threshold(self.iteration);
        let outcome = self.tree.refine_with_heap(
            |cell, _| cell.split_weight > threshold,
            |cell| {
                cell.split_weight *= 0.5;
                cell.clone()
            },
            |cell| cell.heap_bytes(),
            self.config.max_bytes,
        );
        for cell in self.tree.data_slice_mut() {
            cell.split_weight = 0.0;
        }
        self.iteration = self.iteration.saturating_add(1);
        outcome
    }
}
