//! What one spatial cell of the SD-tree holds, and everything done to one
//! cell: queries, recording a record or a fraction sample, the end of an
//! iteration. The SD-tree and the combined guiding field
//! ([`crate::field`]) both work through these.

use super::config::SdTreeConfig;
use super::fraction::{FRACTION_SUMS, FractionLearner};
use crate::math::unit_direction;
use crate::math::{Accumulation, SumBuffer};
use crate::quadtree::{DirectionalFilter, DirectionalTree};
use crate::spatial::Growth;
use glam::Vec3;

/// Index of the statistical weight in a cell's sums.
const WEIGHT: usize = 0;
/// First index of the fraction statistics in a cell's sums.
const FRACTION_BASE: usize = 1;

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

    /// A direction drawn from the cell's guiding distribution with two
    /// uniform numbers, and its solid-angle pdf, which equals
    /// [`SdCell::pdf`] of that direction bit for bit.
    #[inline]
    pub fn sample(&self, u: [f32; 2]) -> (Vec3, f32) {
        self.directions.sample(u)
    }

    /// The solid-angle pdf of `dir` (any positive length) under the cell's
    /// guiding distribution; 0 for a NaN, infinite or zero direction.
    #[inline]
    pub fn pdf(&self, dir: Vec3) -> f32 {
        match unit_direction(dir) {
            // The quadtree normalises `dir` itself, exactly as when it
            // sampled it, so sampled and evaluated pdfs agree bit for bit.
            Some(_) => self.directions.pdf(dir),
            None => 0.0,
        }
    }

    /// The pdf of the one-sample mixture of the BSDF and the guiding
    /// distribution: `s * bsdf_pdf + (1 - s) * pdf(dir)` with
    /// `s = bsdf_fraction()`.
    #[inline]
    pub fn mixture_pdf(&self, dir: Vec3, bsdf_pdf: f32) -> f32 {
        let guide = self.pdf(dir);
        let s = self.bsdf_fraction();
        s * bsdf_pdf + (1.0 - s) * guide
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
    /// number of records; fractions of one with box filters). Read it between
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

    /// Records the `weight` part of a validated record: `weight` to the
    /// statistical weight, `value * weight` to the quadtree along `dir`.
    #[inline]
    pub(super) fn record(&self, dir: Vec3, value: f32, weight: f32, filter: DirectionalFilter) {
        self.stats.add(WEIGHT, weight);
        self.directions.record(dir, value * weight, filter);
    }

    /// Records a validated sample for the fraction learner.
    #[inline]
    pub(super) fn record_fraction(&self, bsdf_pdf: f32, guiding_pdf: f32, contribution: f32) {
        FractionLearner::record(
            &self.stats,
            FRACTION_BASE,
            bsdf_pdf,
            guiding_pdf,
            contribution,
        );
    }

    /// The end of an iteration for this cell: keeps the collected weight
    /// for the spatial split rule, optimises the learned fraction, makes
    /// the building quadtree the sampling one (refining its topology) and
    /// zeroes the collected sums.
    pub(super) fn end_iteration(&mut self, config: &SdTreeConfig, max_nodes: Option<usize>) {
        self.split_weight = self.stats.get(WEIGHT);
        if config.learn_bsdf_fraction {
            self.learner
                .optimise(&self.stats, FRACTION_BASE, config.fraction_steps);
        }
        self.directions.refine_within(&config.quadtree, max_nodes);
        self.stats.clear();
    }

    /// What the cell's heap will hold after [`SdCell::end_iteration`]: the
    /// quadtree's growth, the statistics as fixed bytes.
    pub(super) fn growth(&self, config: &SdTreeConfig) -> Growth {
        let mut g = self.directions.growth(&config.quadtree);
        g.fixed += self.stats.bytes();
        g
    }
}

impl AsRef<SdCell> for SdCell {
    #[inline]
    fn as_ref(&self) -> &SdCell {
        self
    }
}

impl AsMut<SdCell> for SdCell {
    #[inline]
    fn as_mut(&mut self) -> &mut SdCell {
        self
    }
}
