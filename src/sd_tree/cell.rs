//! What one spatial cell of the SD-tree holds.

use super::fraction::{FRACTION_SUMS, FractionLearner};
use crate::math::{Accumulation, SumBuffer};
use crate::quadtree::DirectionalTree;

/// Index of the statistical weight in a cell's sums.
pub(super) const WEIGHT: usize = 0;
/// First index of the fraction statistics in a cell's sums.
pub(super) const FRACTION_BASE: usize = 1;

/// One SD-tree cell: a directional quadtree (sampling and building copies),
/// the statistical weight collected this iteration, and the BSDF sampling
/// fraction with its learning statistics.
#[derive(Clone, Debug)]
pub struct SdCell {
    pub(super) directions: DirectionalTree,
    /// `[WEIGHT]`, then (when learning) `FRACTION_SUMS` fraction sums.
    pub(super) stats: SumBuffer,
    pub(super) learner: FractionLearner,
    /// The weight the spatial split rule sees during `refine` (halved at
    /// each split).
    pub(super) split_weight: f64,
}

impl SdCell {
    pub(super) fn new(mode: Accumulation, learn: bool, fraction: f32) -> Self {
        let sums = 1 + if learn { FRACTION_SUMS } else { 0 };
        Self {
            directions: DirectionalTree::new(mode),
            stats: SumBuffer::new(sums, mode),
            learner: FractionLearner::new(fraction),
            split_weight: 0.0,
        }
    }

    /// The cell's directional quadtree.
    #[inline]
    pub fn directions(&self) -> &DirectionalTree {
        &self.directions
    }

    /// The BSDF sampling fraction queries at this cell use (fixed between
    /// refinements).
    #[inline]
    pub fn bsdf_fraction(&self) -> f32 {
        self.learner.fraction()
    }

    /// The learned fraction's logit `theta` (`bsdf_fraction =
    /// logistic(theta)`); only meaningful when learning is enabled.
    #[inline]
    pub fn fraction_logit(&self) -> f64 {
        self.learner.theta()
    }

    /// Statistical weight collected since the last refinement (about the
    /// number of splats; fractions of one with box filters). Read it between
    /// iterations.
    #[inline]
    pub fn building_weight(&self) -> f64 {
        self.stats.get(WEIGHT)
    }

    /// Bytes this cell owns on the heap: both quadtree copies and all sums
    /// (its inline size is `size_of::<SdCell>()`).
    pub fn heap_bytes(&self) -> usize {
        self.quadtree_heap_bytes() + self.stats.bytes()
    }

    /// Heap bytes of the quadtree's copies and sums.
    pub(super) fn quadtree_heap_bytes(&self) -> usize {
        self.directions
            .bytes()
            .saturating_sub(core::mem::size_of::<DirectionalTree>())
    }
}
