//! [`FieldVertex`]: one located cell, serving every query and record at a
//! path vertex.

use super::{FieldCell, GuidingField};
use crate::emitter::ShadingContext;
use crate::glt::{GuidingCut, SplatOutcome};
use crate::light_sampler::{LightId, LightSample, LightSampler};
use crate::light_tree::LightHierarchy;
use crate::math::Aabb;
use crate::sd_tree::SdCell;
use crate::spatial::Jitter;
use crate::spatial::{CellId, SpatialTree, jitter_offset};
use glam::Vec3;

/// A path vertex located in a [`GuidingField`]: the cell found by the one
/// lookup ([`GuidingField::vertex`]), through which directional guiding,
/// light selection and both records at that point go without looking the
/// cell up again.
///
/// Every answer equals the field's by position at the same point. As a
/// [`LightSampler`] it samples the located cell's cut whatever
/// `ctx.position` is; `ctx` only feeds the importance below the cut
/// ([`BelowCut::Importance`](crate::glt::BelowCut::Importance)).
#[derive(Debug)]
pub struct FieldVertex<'f, H: LightHierarchy> {
    field: &'f GuidingField<H>,
    cell: &'f FieldCell,
    p: Vec3,
    at: (CellId, Aabb),
}

impl<H: LightHierarchy> Clone for FieldVertex<'_, H> {
    fn clone(&self) -> Self {
        *self
    }
}

impl<H: LightHierarchy> Copy for FieldVertex<'_, H> {}

impl<'f, H: LightHierarchy> FieldVertex<'f, H> {
    #[inline]
    pub(super) fn new(field: &'f GuidingField<H>, p: Vec3, at: (CellId, Aabb)) -> Self {
        Self {
            field,
            cell: field.cells.data(at.0),
            p,
            at,
        }
    }

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

    /// The cell's bounds.
    #[inline]
    pub fn bounds(&self) -> Aabb {
        self.at.1
    }

    /// The cell's SD-tree part.
    #[inline]
    pub fn sd(&self) -> &'f SdCell {
        &self.cell.sd
    }

    /// The cell's guiding cut.
    #[inline]
    pub fn cut(&self) -> &'f GuidingCut {
        &self.cell.cut
    }

    /// A direction drawn from the cell's guiding distribution with two
    /// uniform numbers, and its solid-angle pdf (equal to
    /// [`FieldVertex::direction_pdf`] of it, bit for bit).
    #[inline]
    pub fn sample_direction(&self, u: [f32; 2]) -> (Vec3, f32) {
        self.cell.sd.sample(u)
    }

    /// The solid-angle pdf of `dir` (any positive length) under the cell's
    /// guiding distribution; 0 for an invalid direction.
    #[inline]
    pub fn direction_pdf(&self, dir: Vec3) -> f32 {
        self.cell.sd.pdf(dir)
    }

    /// The probability `s` of sampling the BSDF rather than the guiding
    /// distribution here.
    #[inline]
    pub fn bsdf_fraction(&self) -> f32 {
        self.cell.sd.bsdf_fraction()
    }

    /// The pdf of the one-sample mixture:
    /// `s * bsdf_pdf + (1 - s) * direction_pdf(dir)`.
    #[inline]
    pub fn mixture_pdf(&self, dir: Vec3, bsdf_pdf: f32) -> f32 {
        self.cell.sd.mixture_pdf(dir, bsdf_pdf)
    }

    /// [`GuidingField::splat_radiance`] at this vertex's position.
    #[inline]
    pub fn splat_radiance<J: Jitter + ?Sized>(
        &self,
        dir: Vec3,
        radiance: f32,
        pdf: f32,
        jitter: &mut J,
    ) -> bool {
        self.field
            .splat_radiance_from(self.p, Some(self.at), dir, radiance, pdf, jitter)
    }

    /// [`GuidingField::splat_light`] at this vertex's position.
    #[inline]
    pub fn splat_light<J: Jitter + ?Sized>(
        &self,
        light: LightId,
        value: f32,
        jitter: &mut J,
    ) -> SplatOutcome {
        let filter = (self.field.light_filter, || jitter_offset(jitter));
        self.field
            .record_light((self.p, Some(self.at)), light, value, filter)
    }

    /// [`GuidingField::splat_visibility`] at this vertex's cell.
    #[inline]
    pub fn splat_visibility(&self, light: LightId, shadowed: f32, unshadowed: f32) -> SplatOutcome {
        let outcome =
            self.field
                .guide
                .splat_visibility(&self.cell.cut, light, shadowed, unshadowed);
        if outcome == SplatOutcome::Dropped {
            self.field
                .sd
                .dropped
                .count(crate::dropped::DropReason::Light);
        }
        outcome
    }

    /// [`GuidingField::record_fraction`] at this vertex's cell.
    #[inline]
    pub fn record_fraction(&self, bsdf_pdf: f32, guiding_pdf: f32, contribution: f32) -> bool {
        self.field
            .sd
            .record_fraction(Some(&self.cell.sd), bsdf_pdf, guiding_pdf, contribution)
    }
}

impl<H: LightHierarchy> LightSampler for FieldVertex<'_, H> {
    /// Applies the GLT's sampling rule with the located cell's cut.
    #[inline]
    fn sample(&self, ctx: &ShadingContext, u: f32) -> Option<LightSample> {
        self.field.guide.sample(&self.cell.cut, ctx, u)
    }

    #[inline]
    fn pmf(&self, ctx: &ShadingContext, light: LightId) -> f32 {
        self.field.guide.pmf(&self.cell.cut, ctx, light)
    }

    fn is_empty(&self) -> bool {
        self.field.guide.is_empty()
    }

    #[inline]
    fn sample_exact(&self, ctx: &ShadingContext, u: f64) -> Option<(LightId, f64)> {
        self.field.guide.sample_exact(&self.cell.cut, ctx, u)
    }

    #[inline]
    fn pmf_exact(&self, ctx: &ShadingContext, light: LightId) -> f64 {
        self.field.guide.pmf_exact(&self.cell.cut, ctx, light)
    }

    /// The learned visibility of `light` in the located cell.
    fn visibility(&self, _ctx: &ShadingContext, light: LightId) -> f32 {
        self.field.guide.visibility(&self.cell.cut, light)
    }

    /// One walk: the visibility is read where it leaves the cut.
    #[inline]
    fn sample_with_visibility(&self, ctx: &ShadingContext, u: f32) -> Option<(LightSample, f32)> {
        self.field
            .guide
            .sample_with_visibility(&self.cell.cut, ctx, u)
    }
}
