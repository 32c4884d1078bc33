//! [`SdVertex`]: one located SD-tree cell, serving every query and record
//! at a path vertex.

use super::{SdCell, SdTree};
use crate::math::Aabb;
use crate::spatial::Jitter;
use crate::spatial::{CellId, SpatialTree};
use glam::Vec3;

/// A path vertex located in an [`SdTree`] ([`SdTree::vertex`]): directional
/// guiding and both records at that point without looking the cell up
/// again, with the same methods as
/// [`FieldVertex`](crate::field::FieldVertex). Every answer equals the
/// tree's by position at the same point.
#[derive(Clone, Copy, Debug)]
pub struct SdVertex<'t> {
    tree: &'t SdTree,
    cell: &'t SdCell,
    p: Vec3,
    at: (CellId, Aabb),
}

impl SdTree {
    /// The one lookup per path vertex: the cell holding `p` (clamped into
    /// the scene). `None` for a non-finite `p`.
    #[inline]
    pub fn vertex(&self, p: Vec3) -> Option<SdVertex<'_>> {
        let at = self.tree.locate_with_bounds(p)?;
        Some(SdVertex {
            tree: self,
            cell: self.tree.data(at.0),
            p,
            at,
        })
    }
}

impl<'t> SdVertex<'t> {
    /// The point this vertex was located from.
    #[inline]
    pub fn position(&self) -> Vec3 {
        self.p
    }

    /// The cell's number.
    #[inline]
    pub fn cell(&self) -> CellId {
        self.at.0
    }

    /// The located cell (its quadtree and learned fraction).
    #[inline]
    pub fn sd(&self) -> &'t SdCell {
        self.cell
    }

    /// A direction from the cell's guiding distribution and its pdf
    /// ([`SdTree::sample`]).
    #[inline]
    pub fn sample_direction(&self, u: [f32; 2]) -> (Vec3, f32) {
        self.cell.sample(u)
    }

    /// The guiding distribution's pdf of `dir` ([`SdTree::pdf`]).
    #[inline]
    pub fn direction_pdf(&self, dir: Vec3) -> f32 {
        self.cell.pdf(dir)
    }

    /// The probability of sampling the BSDF rather than the guide
    /// ([`SdTree::bsdf_fraction`]).
    #[inline]
    pub fn bsdf_fraction(&self) -> f32 {
        self.cell.bsdf_fraction()
    }

    /// The one-sample mixture's pdf ([`SdTree::mixture_pdf`]).
    #[inline]
    pub fn mixture_pdf(&self, dir: Vec3, bsdf_pdf: f32) -> f32 {
        self.cell.mixture_pdf(dir, bsdf_pdf)
    }

    /// [`SdTree::splat`] at this vertex's position, with the configured
    /// filters.
    #[inline]
    pub fn splat_radiance<J: Jitter + ?Sized>(
        &self,
        dir: Vec3,
        radiance: f32,
        pdf: f32,
        jitter: &mut J,
    ) -> bool {
        let t = self.tree;
        let c = &t.state.config;
        let filters = (c.spatial_filter, c.directional_filter);
        t.state.splat(
            &t.tree,
            self.p,
            Some(self.at),
            dir,
            radiance,
            pdf,
            filters,
            jitter,
        )
    }

    /// [`SdTree::record_fraction`] at this vertex's cell.
    #[inline]
    pub fn record_fraction(&self, bsdf_pdf: f32, guiding_pdf: f32, contribution: f32) -> bool {
        self.tree
            .state
            .record_fraction(Some(self.cell), bsdf_pdf, guiding_pdf, contribution)
    }
}
