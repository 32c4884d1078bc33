//! Dense cell numbers and the iterator over them.

use core::ops::Range;

/// The number of a cell (a leaf of a spatial tree), dense in
/// `0..cell_count()`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct CellId(pub u32);

impl CellId {
    /// The number as an index into per-cell tables.
    #[inline]
    pub fn index(self) -> usize {
        self.0 as usize
    }
}

/// Iterator over all cells `0..cell_count()` in number order.
#[derive(Clone, Debug)]
pub(crate) struct CellIds(pub(crate) Range<u32>);

impl Iterator for CellIds {
    type Item = CellId;

    #[inline]
    fn next(&mut self) -> Option<CellId> {
        self.0.next().map(CellId)
    }

    #[inline]
    fn size_hint(&self) -> (usize, Option<usize>) {
        self.0.size_hint()
    }
}

impl ExactSizeIterator for CellIds {}

impl DoubleEndedIterator for CellIds {
    #[inline]
    fn next_back(&mut self) -> Option<CellId> {
        self.0.next_back().map(CellId)
    }
}
