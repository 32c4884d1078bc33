//! Spatial filters: how a record made at a point is spread over cells.
//!
//! One implementation for every structure that learns per cell (the
//! SD-tree's radiance records, the Guiding Light Tree's light records, the
//! combined guiding field's both): [`BinaryTree::spread`] turns a point into
//! `(cell, weight)` pairs and the caller records into each cell.

use super::{BinaryTree, CellId, SpatialTree};
use crate::math::Aabb;
use glam::Vec3;

/// How a record is spread over spatial cells.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum SpatialFilter {
    /// All of it goes to the cell containing the position.
    #[default]
    Nearest,
    /// The position is jittered uniformly within a box the size of the cell
    /// containing it (`+-1/2` cell per axis, from a hash of the record:
    /// `src/spatial/jitter.rs`), then the cell containing the jittered position
    /// (clamped to the root) takes all of it. Same cost as `Nearest`, the
    /// box filter in expectation.
    StochasticBox,
    /// The cell-sized box centred on the position is intersected with every
    /// cell it overlaps; each gets the fraction of the box's volume it
    /// covers, of both the value and the statistical weight. The box is
    /// clipped to the root first, so the fractions always sum to 1 (PPG
    /// loses the part outside the scene).
    Box,
}

/// The save format's byte for each [`SpatialFilter`] (its position).
pub(crate) const FILTERS: [SpatialFilter; 3] = [
    SpatialFilter::Nearest,
    SpatialFilter::StochasticBox,
    SpatialFilter::Box,
];

impl<T> BinaryTree<T> {
    /// Spreads a record made at `p` over the cells by `filter`: calls
    /// `visit(cell, weight)` for every cell that gets a part, with weights
    /// in `(0, 1]` that sum to 1 (to rounding, for [`SpatialFilter::Box`]).
    /// Returns false, visiting nothing, when `p` is not finite.
    ///
    /// The filter box is centred on `p` clamped onto the root cube and has
    /// the size of the cell holding `p`. `jitter` is called once, by
    /// [`SpatialFilter::StochasticBox`] only, and gives the offset from the
    /// centre in cell widths, each coordinate in `[-1/2, 1/2)`.
    #[inline]
    pub fn spread(
        &self,
        p: Vec3,
        filter: SpatialFilter,
        jitter: impl FnOnce() -> Vec3,
        visit: impl FnMut(CellId, f32),
    ) -> bool {
        match self.locate_with_bounds(p) {
            Some(at) => {
                self.spread_from(p, at, filter, jitter, visit);
                true
            }
            None => false,
        }
    }

    /// [`BinaryTree::spread`] for a point already located: `at` is what
    /// [`BinaryTree::locate_with_bounds`] returned for `p` (so one lookup
    /// per path vertex can serve its queries and its records).
    #[inline]
    pub fn spread_from(
        &self,
        p: Vec3,
        at: (CellId, Aabb),
        filter: SpatialFilter,
        jitter: impl FnOnce() -> Vec3,
        mut visit: impl FnMut(CellId, f32),
    ) {
        let (cell, bounds) = at;
        match filter {
            SpatialFilter::Nearest => visit(cell, 1.0),
            SpatialFilter::StochasticBox => {
                let q = self.root.clamp(p) + jitter() * bounds.diagonal();
                // About 42% of jittered points stay in their cell ((3/4)^3
                // for a point uniform in it): the cell's half-open bounds
                // are exactly what the lookup would compare against, so
                // skip it then.
                let home = q.cmpge(bounds.min).all() && q.cmplt(bounds.max).all();
                // `q` is finite: a finite point plus at most a cell's size.
                let at = if home {
                    cell
                } else {
                    self.locate(q).unwrap_or(cell)
                };
                visit(at, 1.0);
            }
            SpatialFilter::Box => self.spread_box(p, &bounds, visit),
        }
    }

    /// Spreads over the cells overlapping the cell-sized box around `p`,
    /// by overlap volume (the box is clipped to the root first).
    fn spread_box(&self, p: Vec3, cell_bounds: &Aabb, mut visit: impl FnMut(CellId, f32)) {
        let centre = self.root.clamp(p);
        let half = cell_bounds.diagonal() * 0.5;
        let region = Aabb {
            min: centre - half,
            max: centre + half,
        }
        .intersection(&self.root);
        let volume = volume64(&region);
        if volume.is_nan() || volume <= 0.0 {
            // Unreachable for a real cell; keep the record anyway.
            if let Some(c) = self.locate(centre) {
                visit(c, 1.0);
            }
            return;
        }
        self.for_each_overlapping(&region, |cell, bounds| {
            let w = volume64(&bounds.intersection(&region)) / volume;
            if w > 0.0 {
                visit(cell, w as f32);
            }
        });
    }
}

#[inline]
fn volume64(b: &Aabb) -> f64 {
    if b.is_empty() {
        return 0.0;
    }
    let d = b.diagonal();
    d.x as f64 * d.y as f64 * d.z as f64
}
