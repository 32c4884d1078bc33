//! [`Glt::refine`]: each cell that holds enough new records splits and
//! rebuilds its cut; [`Glt::restart`] starts that clock again.

use super::Glt;
use crate::light_tree::LightHierarchy;
use crate::spatial::{Growth, RefineOutcome, content_scale};

impl<H: LightHierarchy> Glt<H> {
    /// Turns what was recorded into the cuts sampled next, cell by cell
    /// (`&mut self`: between passes or tiles, or through
    /// [`SharedGuide`](crate::SharedGuide)).
    ///
    /// A cell takes part once it holds 3/2 of the records that fell in it
    /// before its last refinement (any, before its first; see
    /// [`GltCell`](crate::learned::GltCell)); the others
    /// keep accumulating. A cell that takes part splits while its count is
    /// above `c sqrt(2^g)` (`c` the spatial threshold, `g` the refinements
    /// it took part in, a half taken to have half its parent's records: PPG's
    /// rule, with the cell's own clock); both halves get a copy of the cut
    /// and its sums, and each the confidence of its share of the records
    /// ([`GuidingCut::confidence`](crate::learned::GuidingCut::confidence)).
    /// Then its cut is rebuilt from its sums
    /// ([`CutRules::refine`](crate::learned::CutRules::refine); a cut that collected nothing keeps its
    /// distribution) within the memory budget. A renderer that refines
    /// after every iteration of PPG's doubling schedule makes every cell
    /// take part every time; one that renders tile by tile may refine
    /// after every few tiles. Returns what the spatial refinement did, as
    /// [`SdTree::refine`](crate::SdTree::refine) and
    /// [`GuidingField::refine`](crate::GuidingField::refine) do.
    pub fn refine(&mut self) -> RefineOutcome {
        for cell in self.spatial.data_slice_mut() {
            cell.begin();
        }
        let c = self.config.spatial_threshold;
        let outcome = self.spatial.refine_along(
            |cell, _| cell.splits(c),
            |cell, axis| cell.split(axis),
            |cell| cell.cut.heap_bytes(),
            self.config.max_bytes,
        );
        // The cuts grow within what the budget leaves (src/spatial/budget.rs).
        let rules = &self.rules;
        let cells = self.spatial.data_slice();
        let scale = content_scale(
            self.config.max_bytes,
            self.spatial.bytes(),
            // A cell that does not take part keeps its cut as it is.
            cells.iter().map(|c| match c.pass.ready {
                true => rules.growth(&c.cut),
                false => Growth {
                    fixed: c.cut.heap_bytes(),
                    nodes: 0,
                    per_node: 0,
                },
            }),
        );
        for cell in self.spatial.data_slice_mut() {
            if !cell.pass.ready {
                continue;
            }
            let cap = scale.and_then(|_| rules.growth(&cell.cut).cap(scale));
            let rebuilt = rules.refine_within(&mut cell.cut, cap);
            cell.end(rebuilt);
        }
        self.iteration = self.iteration.saturating_add(1);
        outcome
    }

    /// Starts a new schedule from what was learned (the next frame of an
    /// animation, a guide loaded to render another image): every cell
    /// takes part in the next refinement with whatever it has collected by
    /// then, as before its first, instead of waiting for 3/2 of the records
    /// it refined on last (which, after a long last iteration, a short
    /// frame may never collect). The cuts, their sums, the spatial tree and
    /// each cell's split clock are kept.
    pub fn restart(&mut self) {
        for cell in self.spatial.data_slice_mut() {
            cell.used = 0;
        }
    }
}
