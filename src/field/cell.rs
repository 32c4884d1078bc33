//! What one cell of the guiding field holds.

use crate::cut::{GuidingCut, OctantRecords};
use crate::sd_tree::SdCell;

/// One cell of a [`GuidingField`](super::GuidingField): an SD-tree cell
/// (directional quadtree, statistical weight, BSDF sampling fraction) and a
/// guiding cut. A spatial split gives both children a copy of both, each
/// cut trusted as far as the light records it learned from fell in that
/// child ([`GuidingCut::confidence`]).
#[derive(Clone, Debug)]
pub struct FieldCell {
    pub(super) sd: SdCell,
    pub(super) cut: GuidingCut,
    /// Light records since the last refinement per octant of the cell (as
    /// [`GltCell`](crate::learned::GltCell) counts them).
    pub(super) octants: OctantRecords,
}

impl FieldCell {
    /// The directional part: quadtree, weight and BSDF fraction.
    #[inline]
    pub fn sd(&self) -> &SdCell {
        &self.sd
    }

    /// The light-selection part: the cell's guiding cut.
    #[inline]
    pub fn cut(&self) -> &GuidingCut {
        &self.cut
    }

    /// A cell with `sd` and `cut`, no light record counted.
    pub(super) fn new(sd: SdCell, cut: GuidingCut) -> Self {
        Self::with_counts(sd, cut, OctantRecords::default())
    }

    /// A cell with `sd`, `cut` and the light records counted per octant.
    pub(super) fn with_counts(sd: SdCell, cut: GuidingCut, octants: OctantRecords) -> Self {
        Self { sd, cut, octants }
    }

    /// Light records since the last refinement, per octant of the cell.
    pub fn octant_records(&self) -> [u64; 8] {
        self.octants.get()
    }

    /// Splits the light records' counts between this cell (the lower half
    /// along `axis`) and `upper`, a copy of it, scaling each cut's
    /// confidence by its half's share.
    pub(super) fn share_split(&mut self, upper: &mut Self, axis: usize) {
        let (counts, lower_factor, upper_factor) = self.octants.split(axis);
        upper.octants = counts;
        self.cut.confidence *= lower_factor;
        upper.cut.confidence *= upper_factor;
    }

    /// Bytes the cell owns on the heap: the quadtree's copies, the SD sums
    /// and the cut's nodes and sums (its inline size is
    /// `size_of::<FieldCell>()`).
    pub fn heap_bytes(&self) -> usize {
        self.sd.heap_bytes() + self.cut.heap_bytes()
    }
}

impl AsRef<SdCell> for FieldCell {
    #[inline]
    fn as_ref(&self) -> &SdCell {
        &self.sd
    }
}

impl AsMut<SdCell> for FieldCell {
    #[inline]
    fn as_mut(&mut self) -> &mut SdCell {
        &mut self.sd
    }
}

impl AsRef<GuidingCut> for FieldCell {
    #[inline]
    fn as_ref(&self) -> &GuidingCut {
        &self.cut
    }
}

impl AsRef<OctantRecords> for FieldCell {
    #[inline]
    fn as_ref(&self) -> &OctantRecords {
        &self.octants
    }
}
