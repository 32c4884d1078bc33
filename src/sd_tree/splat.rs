//! Recording radiance and fraction samples, with the spatial filters.

use super::cell::{FRACTION_BASE, WEIGHT};
use super::dropped::DropReason;
use super::fraction::FractionLearner;
use super::validate::{splat_value, unit_direction};
use super::{SdTree, SpatialFilter};
use crate::math::Aabb;
use crate::quadtree::DirectionalFilter;
use crate::spatial::SpatialTree;
use glam::Vec3;
use rand_core::Rng;

/// A uniform number in `[0, 1)` from 24 random bits.
#[inline]
fn unit_f32<R: Rng + ?Sized>(rng: &mut R) -> f32 {
    (rng.next_u32() >> 8) as f32 * (1.0 / (1u32 << 24) as f32)
}

impl SdTree {
    /// PPG's record with the configured filters: `radiance / pdf` into the
    /// quadtree of the cell at `p` along `dir`, statistical weight 1 (see
    /// the [module docs](super#what-a-splat-records)). `rng` is only used
    /// by [`SpatialFilter::StochasticBox`]. Returns false, counting the
    /// reason, when the input is invalid.
    #[inline]
    pub fn splat<R: Rng + ?Sized>(
        &self,
        p: Vec3,
        dir: Vec3,
        radiance: f32,
        pdf: f32,
        rng: &mut R,
    ) -> bool {
        self.splat_filtered(
            p,
            dir,
            radiance,
            pdf,
            self.config.spatial_filter,
            self.config.directional_filter,
            rng,
        )
    }

    /// [`SdTree::splat`] with explicit filters.
    #[allow(clippy::too_many_arguments)]
    pub fn splat_filtered<R: Rng + ?Sized>(
        &self,
        p: Vec3,
        dir: Vec3,
        radiance: f32,
        pdf: f32,
        spatial: SpatialFilter,
        directional: DirectionalFilter,
        rng: &mut R,
    ) -> bool {
        match self.try_splat(p, dir, radiance, pdf, spatial, directional, rng) {
            Ok(()) => true,
            Err(reason) => {
                self.dropped.count(reason);
                false
            }
        }
    }

    #[allow(clippy::too_many_arguments)]
    #[inline]
    fn try_splat<R: Rng + ?Sized>(
        &self,
        p: Vec3,
        dir: Vec3,
        radiance: f32,
        pdf: f32,
        spatial: SpatialFilter,
        directional: DirectionalFilter,
        rng: &mut R,
    ) -> Result<(), DropReason> {
        let (cell, bounds) = self
            .tree
            .locate_with_bounds(p)
            .ok_or(DropReason::Position)?;
        unit_direction(dir).ok_or(DropReason::Direction)?;
        let value = splat_value(radiance, pdf)?;
        match spatial {
            SpatialFilter::Nearest => self.splat_cell(cell.index(), dir, value, 1.0, directional),
            SpatialFilter::StochasticBox => {
                let size = bounds.diagonal();
                let jitter = Vec3::new(unit_f32(rng), unit_f32(rng), unit_f32(rng)) - 0.5;
                let q = self.tree.root_bounds().clamp(p) + jitter * size;
                // `q` is finite: a finite point plus at most a cell's size.
                let c = self.tree.locate(q).unwrap_or(cell);
                self.splat_cell(c.index(), dir, value, 1.0, directional);
            }
            SpatialFilter::Box => self.splat_box(p, &bounds, dir, value, directional),
        }
        Ok(())
    }

    /// Spreads over the cells overlapping the cell-sized box around `p`,
    /// by overlap volume (the box is clipped to the root first).
    fn splat_box(
        &self,
        p: Vec3,
        cell_bounds: &Aabb,
        dir: Vec3,
        value: f32,
        directional: DirectionalFilter,
    ) {
        let root = self.tree.root_bounds();
        let centre = root.clamp(p);
        let half = cell_bounds.diagonal() * 0.5;
        let region = Aabb {
            min: centre - half,
            max: centre + half,
        }
        .intersection(&root);
        let volume = volume64(&region);
        if volume.is_nan() || volume <= 0.0 {
            // Unreachable for a real cell; keep the splat anyway.
            if let Some(c) = self.tree.locate(centre) {
                self.splat_cell(c.index(), dir, value, 1.0, directional);
            }
            return;
        }
        self.tree.for_each_overlapping(&region, |cell, bounds| {
            let w = volume64(&bounds.intersection(&region)) / volume;
            if w > 0.0 {
                self.splat_cell(cell.index(), dir, value, w as f32, directional);
            }
        });
    }

    #[inline]
    fn splat_cell(
        &self,
        cell: usize,
        dir: Vec3,
        value: f32,
        weight: f32,
        directional: DirectionalFilter,
    ) {
        let c = &self.tree.data_slice()[cell];
        c.stats.add(WEIGHT, weight);
        c.directions.splat(dir, value * weight, directional);
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
        if !self.config.learn_bsdf_fraction {
            return false;
        }
        let Some(cell) = self.tree.locate(p) else {
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
        let c = self.tree.data(cell);
        FractionLearner::record(&c.stats, FRACTION_BASE, bsdf_pdf, guiding_pdf, contribution);
        true
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
