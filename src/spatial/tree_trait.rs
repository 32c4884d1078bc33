//! The interface every spatial subdivision offers.

use super::CellId;
use super::cell_id::CellIds;
use crate::math::Aabb;
use glam::Vec3;

/// A subdivision of space into cells, each holding a value of type
/// [`SpatialTree::Data`].
///
/// Object safe, so a renderer may hold a `&dyn SpatialTree<Data = T>`.
pub trait SpatialTree {
    /// What each cell holds.
    type Data;

    /// The box the tree covers; lookups outside it are clamped onto it.
    fn root_bounds(&self) -> Aabb;

    /// The cell holding `p` (clamped onto the root box first); `None` when
    /// `p` has a NaN or infinite coordinate.
    fn locate(&self, p: Vec3) -> Option<CellId>;

    /// How many cells; their numbers are `0..cell_count()`.
    fn cell_count(&self) -> usize;

    /// The bounds of `cell`. Panics on a number that is not a cell of this
    /// tree (numbers come from the tree itself).
    fn cell_bounds(&self, cell: CellId) -> Aabb;

    /// How many splits lie between the root and `cell` (the root is depth 0).
    fn cell_depth(&self, cell: CellId) -> u32;

    /// What `cell` holds.
    fn data(&self, cell: CellId) -> &Self::Data;

    /// Calls `visit` for every cell whose closed box intersects the closed
    /// box `region` (cells that only touch it are included; weigh by overlap
    /// volume to skip them). Nothing is visited for an empty or non-finite
    /// region.
    fn visit_overlapping(&self, region: &Aabb, visit: &mut dyn FnMut(CellId));

    /// All cells in number order (through `dyn SpatialTree`, count
    /// `0..cell_count()` instead).
    fn cells(&self) -> impl ExactSizeIterator<Item = CellId> + DoubleEndedIterator
    where
        Self: Sized,
    {
        let n = u32::try_from(self.cell_count()).unwrap_or(u32::MAX);
        CellIds(0..n)
    }
}
