//! [`GltCell`]: what a cell of a [`Glt`](super::Glt) holds, when it
//! refines, and what each half of it inherits when it splits.
//!
//! A cell refines on what it has seen itself, not on a global clock: it
//! takes part in a refinement once it holds 3/2 of the records that fell
//! in it before its last one (for a half born of a split, its own share of
//! its parent's; any record before its first), and its spatial split
//! threshold is `c sqrt(2^g)` with `g` its own refinement count. A
//! renderer that refines after every pass of PPG's doubling schedule
//! makes every cell take part every time (each pass doubles the records),
//! which is PPG's rule; one that refines after every few tiles makes the
//! cells the tiles reached refine and leaves the others accumulating.
//!
//! The records are counted per octant of the cell, so when a cell splits
//! each half knows its share of the records its parent learned from (for
//! three levels: a split halves one axis and keeps the other two). A half
//! with less than a twentieth of them trusts the inherited cut less
//! ([`GuidingCut::confidence`]), down to the prior for a half the records
//! never reached, until it refines on records of its own.

use crate::cut::GuidingCut;
use crate::cut::OctantRecords;
use crate::spatial::split_threshold;

/// A cell takes part in a refinement once it has collected
/// `READY_NUM / READY_DEN` times the records that fell in it before its last.
const READY_NUM: u64 = 3;
const READY_DEN: u64 = 2;

/// One cell of a [`Glt`](super::Glt): its cut and what decides its
/// refinement.
#[derive(Clone, Debug)]
pub struct GltCell {
    pub(super) cut: GuidingCut,
    /// Records (zero values included) since the cell last took part in a
    /// refinement, per octant of the cell: bit 0 set for `x` at or above
    /// the cell's centre, bit 1 for `y`, bit 2 for `z`.
    pub(super) octants: OctantRecords,
    /// The records that fell in the cell before its last refinement (its
    /// share of them, for a half born of a split; 0 before the first).
    pub(super) used: u64,
    /// Refinements it took part in (a half starts from its parent's).
    pub(super) generation: u32,
    /// State of the refinement in progress (inside `Glt::refine` only).
    pub(super) pass: Pass,
}

/// A cell's part in the refinement in progress.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Pass {
    /// Whether the cell takes part.
    pub(super) ready: bool,
    /// The records the split rule sees: the cell's, halved at each split
    /// (PPG's rule).
    pub(super) count: u64,
    /// The confidence its cut keeps from this pass's splits: the product
    /// of `min(1, share / TRUSTED_SHARE)` over them.
    pub(super) factor: f32,
}

impl Default for Pass {
    fn default() -> Self {
        Self {
            ready: false,
            count: 0,
            factor: 1.0,
        }
    }
}

impl AsRef<GuidingCut> for GltCell {
    #[inline]
    fn as_ref(&self) -> &GuidingCut {
        &self.cut
    }
}

impl AsRef<OctantRecords> for GltCell {
    #[inline]
    fn as_ref(&self) -> &OctantRecords {
        &self.octants
    }
}

impl GltCell {
    /// A cell with `cut`, nothing recorded.
    pub(super) fn new(cut: GuidingCut) -> Self {
        Self::with_counts(cut, OctantRecords::default(), 0, 0)
    }

    /// A cell with `cut` and the given counts (a loaded one).
    pub(super) fn with_counts(
        cut: GuidingCut,
        octants: OctantRecords,
        used: u64,
        generation: u32,
    ) -> Self {
        Self {
            cut,
            octants,
            used,
            generation,
            pass: Pass::default(),
        }
    }

    /// The cell's cut.
    #[inline]
    pub fn cut(&self) -> &GuidingCut {
        &self.cut
    }

    /// Records (zero values included) received since the cell last took
    /// part in a refinement.
    #[inline]
    pub fn records(&self) -> u64 {
        self.octants.total()
    }

    /// [`GltCell::records`] per octant of the cell (bit 0 of the index set
    /// for `x` at or above the cell's centre, bit 1 for `y`, bit 2 for
    /// `z`).
    pub fn octant_records(&self) -> [u64; 8] {
        self.octants.get()
    }

    /// Refinements the cell took part in (a half counts its parent's).
    #[inline]
    pub fn generation(&self) -> u32 {
        self.generation
    }

    /// Starts a refinement: the cell takes part if it has 3/2 of the
    /// records that fell in it before its last one (any, before its first).
    pub(super) fn begin(&mut self) {
        let n = self.records();
        self.pass = Pass {
            ready: n > 0 && n.saturating_mul(READY_DEN) >= self.used.saturating_mul(READY_NUM),
            count: n,
            factor: 1.0,
        };
    }

    /// Whether the spatial split rule splits the cell, with threshold
    /// constant `c`: it takes part and its count is above `c sqrt(2^g)`.
    pub(super) fn splits(&self, c: f64) -> bool {
        self.pass.ready && self.pass.count as f64 > split_threshold(c, self.generation)
    }

    /// Splits the cell along `axis` (0, 1, 2): it becomes the lower half
    /// and the upper half is returned. Both keep the cut and its sums;
    /// each gets the octant counts that fell in it (along `axis` its own
    /// octants are not known: the count is shared evenly), its share of
    /// the records as a confidence factor, and half the split count.
    pub(super) fn split(&mut self, axis: usize) -> Self {
        self.pass.count /= 2;
        let mut upper = self.clone();
        let (counts, lower_factor, upper_factor) = self.octants.split(axis);
        upper.octants = counts;
        self.pass.factor *= lower_factor;
        upper.pass.factor *= upper_factor;
        upper
    }

    /// Ends a refinement for a cell that took part, after `rebuild`
    /// rebuilt its cut (`true`) or kept it: the cut's confidence becomes
    /// this pass's factor (rebuilt from the records the cell inherited)
    /// or is multiplied by it (kept), the cell remembers how many records
    /// it used and starts counting again.
    pub(super) fn end(&mut self, rebuilt: bool) {
        let factor = self.pass.factor;
        self.cut.confidence = if rebuilt {
            factor
        } else {
            self.cut.confidence * factor
        };
        // Its own records, not the split rule's halved count: a half that
        // got few of its parent's records refines again on few of its own.
        self.used = self.records();
        self.generation = self.generation.saturating_add(1);
        self.octants.reset();
        self.pass = Pass::default();
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cut::{CutConfig, CutRules};
    use crate::emitter::Emitter;
    use crate::light_tree::{BuildHeuristic, LightTree};
    use glam::Vec3;

    fn cell_with(octants: [u64; 8], used: u64) -> GltCell {
        let lights = [
            Emitter::point(Vec3::ZERO, 1.0),
            Emitter::point(Vec3::X, 1.0),
        ];
        let tree = LightTree::build(&lights[..], BuildHeuristic::Sarh).unwrap();
        let rules = CutRules::new(&tree, CutConfig::default()).unwrap();
        GltCell::with_counts(rules.new_cut(), OctantRecords::with(octants), used, 0)
    }

    /// A cell takes part once it has 3/2 of what its last refinement
    /// used; before its first, once it has anything.
    #[test]
    fn a_cell_takes_part_at_three_halves_of_its_last_count() {
        let ready = |n: u64, used: u64| {
            let mut c = cell_with([n, 0, 0, 0, 0, 0, 0, 0], used);
            c.begin();
            c.pass.ready
        };
        assert!(!ready(0, 0));
        assert!(ready(1, 0));
        assert!(!ready(149, 100));
        assert!(ready(150, 100));
        assert!(ready(u64::MAX, u64::MAX / 2));
    }

    /// Records all in one octant: the half that holds it keeps the full
    /// confidence, the other gets none; three levels deep the counts are
    /// exact. Records spread evenly: every half keeps the full confidence.
    #[test]
    fn each_half_gets_its_share_of_the_records() {
        let mut lower = cell_with([800, 0, 0, 0, 0, 0, 0, 0], 0);
        lower.begin();
        let upper = lower.split(0);
        assert_eq!((lower.records(), upper.records()), (800, 0));
        assert_eq!((lower.pass.factor, upper.pass.factor), (1.0, 0.0));
        assert_eq!(
            (lower.pass.count, upper.pass.count),
            (400, 400),
            "PPG's halving"
        );
        let lower_y = lower.split(1);
        assert_eq!((lower.records(), lower_y.records()), (800, 0));
        let upper_z = lower.split(2);
        assert_eq!((lower.records(), upper_z.records()), (800, 0));
        assert_eq!(upper_z.pass.factor, 0.0);
        // Along x again: unknown, shared evenly.
        let upper_x = lower.split(0);
        assert_eq!((lower.records(), upper_x.records()), (400, 400));
        assert_eq!((lower.pass.factor, upper_x.pass.factor), (1.0, 1.0));

        let mut even = cell_with([100; 8], 0);
        even.begin();
        let other = even.split(1);
        assert_eq!((even.records(), other.records()), (400, 400));
        assert_eq!((even.pass.factor, other.pass.factor), (1.0, 1.0));
        // A twentieth of the records: still the cell's own.
        let mut skewed = cell_with([190, 10, 190, 10, 190, 10, 190, 10], 0);
        skewed.begin();
        let right = skewed.split(0);
        assert_eq!((skewed.pass.factor, right.pass.factor), (1.0, 1.0));
        // A fortieth: half the confidence.
        let mut skewed = cell_with([195, 5, 195, 5, 195, 5, 195, 5], 0);
        skewed.begin();
        let right = skewed.split(0);
        assert_eq!((skewed.pass.factor, right.pass.factor), (1.0, 0.5));
    }

    /// A refinement the cell took part in: confidence from this pass's
    /// splits when the cut was rebuilt, multiplied into the old one when it
    /// was kept; the count restarts and the generation moves on.
    #[test]
    fn ending_a_pass_sets_the_confidence_and_restarts_the_count() {
        let mut c = cell_with([10, 390, 0, 0, 0, 0, 0, 0], 0);
        assert_eq!(c.octant_records(), [10, 390, 0, 0, 0, 0, 0, 0]);
        assert_eq!(c.generation(), 0);
        c.begin();
        let mut upper = c.split(0);
        upper.end(true);
        assert_eq!(upper.cut.confidence(), 1.0);
        c.end(false);
        assert_eq!(c.cut.confidence(), 0.5);
        assert_eq!((c.records(), c.used, c.generation), (0, 10, 1));
        assert_eq!((c.octant_records(), c.generation()), ([0; 8], 1));
        c.octants.count(3);
        assert_eq!(c.octant_records(), [0, 0, 0, 1, 0, 0, 0, 0]);
        c.begin();
        assert!(!c.pass.ready, "1 of the 15 it needs");
        for _ in 1..15 {
            c.octants.count(5);
        }
        c.begin();
        assert!(c.pass.ready, "15 of the 15 it needs");
    }
}
