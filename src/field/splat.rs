//! Recording into the field by position: PPG's radiance splat, the GLT's
//! light splat, the fraction learner's sample.

use super::GuidingField;
use crate::glt::SplatOutcome;
use crate::light_sampler::LightId;
use crate::light_tree::LightHierarchy;
use crate::spatial::Jitter;
use crate::spatial::{SpatialFilter, jitter_offset};
use glam::Vec3;

impl<H: LightHierarchy> GuidingField<H> {
    /// PPG's record, exactly as [`SdTree::splat`](crate::sd_tree::SdTree::splat):
    /// `radiance / pdf` into the quadtree of the cell at `p` along `dir`,
    /// statistical weight 1, spread by the configured SD filters (`jitter` is
    /// used by the stochastic box only). Returns false, counting the reason
    /// in [`GuidingField::dropped_splats`], for invalid input.
    #[inline]
    pub fn splat_radiance<J: Jitter + ?Sized>(
        &self,
        p: Vec3,
        dir: Vec3,
        radiance: f32,
        pdf: f32,
        jitter: &mut J,
    ) -> bool {
        let at = self.cells.locate_with_bounds(p);
        self.splat_radiance_from(p, at, dir, radiance, pdf, jitter)
    }

    /// [`GuidingField::splat_radiance`] for a located point.
    #[inline]
    pub(super) fn splat_radiance_from<J: Jitter + ?Sized>(
        &self,
        p: Vec3,
        at: Option<(crate::spatial::CellId, crate::math::Aabb)>,
        dir: Vec3,
        radiance: f32,
        pdf: f32,
        jitter: &mut J,
    ) -> bool {
        let c = &self.sd.config;
        let filters = (c.spatial_filter, c.directional_filter);
        self.sd
            .splat(&self.cells, p, at, dir, radiance, pdf, filters, jitter)
    }

    /// The GLT's record, as [`Glt::splat`](crate::glt::Glt::splat): the
    /// direct-light estimate `value` for `light` seen from `p` (see
    /// [`CutRules::splat`](crate::glt::CutRules::splat) for what it
    /// is) into the cut of the cell(s) that
    /// [`FieldConfig::light_filter`](super::FieldConfig::light_filter)
    /// spreads `p` over (by default the cell holding `p`; the stochastic
    /// box takes three numbers from `jitter`, see [`Jitter`]). Bad input
    /// is dropped and counted in [`GuidingField::dropped_splats`]
    /// (`light`). Light splats add no spatial weight.
    #[inline]
    pub fn splat_light<J: Jitter + ?Sized>(
        &self,
        p: Vec3,
        light: LightId,
        value: f32,
        jitter: &mut J,
    ) -> SplatOutcome {
        let at = self.cells.locate_with_bounds(p);
        let filter = (self.light_filter, || jitter_offset(jitter));
        self.record_light((p, at), light, value, filter)
    }

    /// Like [`GuidingField::splat_light`] without filter: the estimate goes
    /// to the cell holding `p` (as [`Glt::splat_at`](crate::glt::Glt::splat_at)).
    #[inline]
    pub fn splat_light_at(&self, p: Vec3, light: LightId, value: f32) -> SplatOutcome {
        let at = self.cells.locate_with_bounds(p);
        self.record_light(
            (p, at),
            light,
            value,
            (SpatialFilter::Nearest, || Vec3::ZERO),
        )
    }

    /// [`Glt::splat_visibility`](crate::glt::Glt::splat_visibility) for
    /// the cell holding `p`: what a next-event sample saw, for the learned
    /// visibility. Bad input is dropped and counted.
    pub fn splat_visibility(
        &self,
        p: Vec3,
        light: LightId,
        shadowed: f32,
        unshadowed: f32,
    ) -> SplatOutcome {
        let outcome = if !self.guide.config().visibility {
            // As the GLT's: values checked, `p` not looked up.
            if crate::glt::valid_record(shadowed, unshadowed) {
                SplatOutcome::Zero
            } else {
                SplatOutcome::Dropped
            }
        } else {
            match self.cell_at(p) {
                Some(cell) => self
                    .guide
                    .splat_visibility(&cell.cut, light, shadowed, unshadowed),
                None => SplatOutcome::Dropped,
            }
        };
        if outcome == SplatOutcome::Dropped {
            self.sd.dropped.count(crate::dropped::DropReason::Light);
        }
        outcome
    }

    /// Reports one direction sample to the BSDF-fraction learner of the
    /// cell at `p`, exactly as
    /// [`SdTree::record_fraction`](crate::sd_tree::SdTree::record_fraction).
    pub fn record_fraction(
        &self,
        p: Vec3,
        bsdf_pdf: f32,
        guiding_pdf: f32,
        contribution: f32,
    ) -> bool {
        let cell = self.cell_at(p).map(|c| &c.sd);
        self.sd
            .record_fraction(cell, bsdf_pdf, guiding_pdf, contribution)
    }
}
