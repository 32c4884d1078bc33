//! What one cell of the guiding field holds.

use crate::glt::GuidingCut;
use crate::sd_tree::SdCell;

/// One cell of a [`GuidingField`](super::GuidingField): an SD-tree cell
/// (directional quadtree, statistical weight, BSDF sampling fraction) and a
/// guiding cut. A spatial split gives both children a copy of both.
#[derive(Clone, Debug)]
pub struct FieldCell {
    pub(super) sd: SdCell,
    pub(super) cut: GuidingCut,
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
