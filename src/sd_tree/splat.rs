//! Recording radiance and fraction samples, with the spatial filters.

use super::state::SdState;
use super::validate::splat_value;
use super::{SdCell, SdTree};
use crate::dropped::DropReason;
use crate::math::Aabb;
use crate::math::unit_direction;
use crate::quadtree::DirectionalFilter;
use crate::spatial::Jitter;
use crate::spatial::SpatialFilter;
use crate::spatial::{BinaryTree, CellId, SpatialTree, jitter_offset};
use glam::Vec3;

/// The located cell and the value to record, or why the splat is dropped
/// (the first failing check, in this order: position, direction, radiance,
/// pdf, overflow).
#[inline]
fn check(
    at: Option<(CellId, Aabb)>,
    dir: Vec3,
    radiance: f32,
    pdf: f32,
) -> Result<((CellId, Aabb), f32), DropReason> {
    let at = at.ok_or(DropReason::Position)?;
    unit_direction(dir).ok_or(DropReason::Direction)?;
    Ok((at, splat_value(radiance, pdf)?))
}

impl SdState {
    /// PPG's record into the cells of `tree` (see [`SdTree::splat`]); `at`
    /// is `tree.locate_with_bounds(p)`. Returns false, counting the reason,
    /// when the input is invalid. The stochastic box draws three
    /// numbers from `jitter`.
    #[allow(clippy::too_many_arguments)]
    #[inline]
    pub(crate) fn splat<C: AsRef<SdCell>, J: Jitter + ?Sized>(
        &self,
        tree: &BinaryTree<C>,
        p: Vec3,
        at: Option<(CellId, Aabb)>,
        dir: Vec3,
        radiance: f32,
        pdf: f32,
        filters: (SpatialFilter, DirectionalFilter),
        jitter: &mut J,
    ) -> bool {
        let (at, value) = match check(at, dir, radiance, pdf) {
            Ok(c) => c,
            Err(reason) => {
                self.dropped.count(reason);
                return false;
            }
        };
        tree.spread_from(
            p,
            at,
            filters.0,
            || jitter_offset(jitter),
            |cell, weight| {
                tree.data(cell)
                    .as_ref()
                    .record(dir, value, weight, filters.1)
            },
        );
        true
    }

    /// Reports a fraction sample to `cell` (`None` for a non-finite
    /// position); see [`SdTree::record_fraction`].
    pub(crate) fn record_fraction(
        &self,
        cell: Option<&SdCell>,
        bsdf_pdf: f32,
        guiding_pdf: f32,
        contribution: f32,
    ) -> bool {
        if !self.config.learn_bsdf_fraction {
            return false;
        }
        let Some(cell) = cell else {
            self.dropped.count(DropReason::Position);
            return false;
        };
        if !(contribution >= 0.0 && contribution.is_finite()) {
            self.dropped.count(DropReason::Radiance);
            return false;
        }
        let ok = |x: f32| x >= 0.0 && x.is_finite();
        if !(ok(bsdf_pdf) && ok(guiding_pdf) && bsdf_pdf + guiding_pdf > 0.0) {
            self.dropped.count(DropReason::Pdf);
            return false;
        }
        cell.record_fraction(bsdf_pdf, guiding_pdf, contribution);
        true
    }
}

impl SdTree {
    /// PPG's record with the configured filters: `radiance / pdf` into the
    /// quadtree of the cell at `p` along `dir`, statistical weight 1 (see
    /// the [module docs](super#what-a-splat-records)). `jitter` is only used
    /// by [`SpatialFilter::StochasticBox`]. Returns false, counting the
    /// reason, when the input is invalid.
    #[inline]
    pub fn splat<J: Jitter + ?Sized>(
        &self,
        p: Vec3,
        dir: Vec3,
        radiance: f32,
        pdf: f32,
        jitter: &mut J,
    ) -> bool {
        let c = &self.state.config;
        self.splat_filtered(
            p,
            dir,
            radiance,
            pdf,
            c.spatial_filter,
            c.directional_filter,
            jitter,
        )
    }

    /// [`SdTree::splat`] with explicit filters.
    #[allow(clippy::too_many_arguments)]
    pub fn splat_filtered<J: Jitter + ?Sized>(
        &self,
        p: Vec3,
        dir: Vec3,
        radiance: f32,
        pdf: f32,
        spatial: SpatialFilter,
        directional: DirectionalFilter,
        jitter: &mut J,
    ) -> bool {
        let at = self.tree.locate_with_bounds(p);
        let filters = (spatial, directional);
        self.state
            .splat(&self.tree, p, at, dir, radiance, pdf, filters, jitter)
    }

    /// Reports one direction sample to the BSDF-fraction learner of the
    /// cell at `p`: `bsdf_pdf` and `guiding_pdf` are the two techniques'
    /// solid-angle pdfs of the sampled direction, and `contribution` is the
    /// sample's estimate `|f_s cos| L_i / q` (one number, e.g. luminance),
    /// with `q` the mixture pdf it was drawn with
    /// ([`SdTree::mixture_pdf`]). Do not report samples of delta BSDF
    /// lobes.
    ///
    /// Returns false when learning is disabled (nothing is counted) or the
    /// input is invalid (counted: non-finite position; negative or
    /// non-finite contribution; a negative or non-finite pdf, or both 0).
    pub fn record_fraction(
        &self,
        p: Vec3,
        bsdf_pdf: f32,
        guiding_pdf: f32,
        contribution: f32,
    ) -> bool {
        self.state
            .record_fraction(self.cell_at(p), bsdf_pdf, guiding_pdf, contribution)
    }
}
