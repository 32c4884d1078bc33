//! [`GuidingField::refine`]: the SD-tree's step and the cuts' rebuilds in
//! one pass over the cells, then PPG's spatial rule.

use super::{FieldCell, GuidingField};
use crate::light_tree::LightHierarchy;
use crate::spatial::RefineOutcome;

impl<H: LightHierarchy> GuidingField<H> {
    /// Ends iteration `k = self.iteration()`: per cell, the SD-tree's step
    /// (fraction, quadtree) and the cut's rebuild from its sums (a cut that
    /// collected nothing is kept), then PPG's spatial rule: cells whose
    /// radiance-record weight exceeds `c * sqrt(2^k)` split, recursively,
    /// within [`SdTreeConfig::max_bytes`](crate::SdTreeConfig::max_bytes)
    /// (counted as `FieldMemory::capped`), both children holding copies
    /// of the quadtree, the weight halved, and the cut. Collected sums are
    /// zeroed. Returns what the spatial pass did.
    pub fn refine(&mut self) -> RefineOutcome {
        let rules = &self.rules;
        let outcome = self.sd.refine(
            &mut self.spatial,
            |cell| rules.growth(&cell.cut),
            |cell, scale| {
                let cap = scale.and_then(|_| rules.growth(&cell.cut).cap(scale));
                if rules.refine_within(&mut cell.cut, cap) {
                    // Learned from the cell's own light records.
                    cell.cut.confidence = 1.0;
                }
            },
            FieldCell::share_split,
            FieldCell::heap_bytes,
        );
        for cell in self.spatial.data_slice_mut() {
            cell.octants.reset();
        }
        outcome
    }
}
