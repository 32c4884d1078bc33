//! Sampling and evaluating the learned directional distribution at a point.

use super::{SdCell, SdTree};
use crate::spatial::SpatialTree;
use glam::Vec3;

impl SdTree {
    /// The cell holding `p` (clamped into the scene); `None` for a
    /// non-finite `p`.
    #[inline]
    pub(crate) fn cell_at(&self, p: Vec3) -> Option<&SdCell> {
        self.tree.locate(p).map(|c| self.tree.data(c))
    }

    /// A direction drawn from the guiding distribution at `p` with two
    /// uniform numbers, and its solid-angle pdf, which equals
    /// [`SdTree::pdf`]`(p, direction)`. `None` for a non-finite `p`.
    #[inline]
    pub fn sample(&self, p: Vec3, u: [f32; 2]) -> Option<(Vec3, f32)> {
        self.cell_at(p).map(|c| c.sample(u))
    }

    /// The solid-angle pdf of `dir` (any positive length) under the guiding
    /// distribution at `p`; 0 for a non-finite `p` or an invalid direction.
    #[inline]
    pub fn pdf(&self, p: Vec3, dir: Vec3) -> f32 {
        self.cell_at(p).map_or(0.0, |c| c.pdf(dir))
    }

    /// The probability `s` of sampling the BSDF rather than the guiding
    /// distribution at `p` (learned per cell, or the configured constant).
    /// Fixed between refinements. The configured value for a non-finite `p`.
    #[inline]
    pub fn bsdf_fraction(&self, p: Vec3) -> f32 {
        match self.cell_at(p) {
            Some(c) => c.bsdf_fraction(),
            None => self.state.config.effective_bsdf_fraction(),
        }
    }

    /// The pdf of the one-sample mixture at `p`:
    /// `s * bsdf_pdf + (1 - s) * pdf(p, dir)` with `s = bsdf_fraction(p)`.
    #[inline]
    pub fn mixture_pdf(&self, p: Vec3, dir: Vec3, bsdf_pdf: f32) -> f32 {
        self.cell_at(p)
            .map_or(0.0, |c| c.mixture_pdf(dir, bsdf_pdf))
    }
}
