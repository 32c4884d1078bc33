//! Recording radiance and fraction samples, with the spatial filters.

use super::SdCell;
use super::state::SdState;
use super::validate::record_value;
use crate::dropped::DropReason;
use crate::math::unit_direction;
use crate::record::RecordOutcome;
use crate::spatial::{BinaryTree, Located, SpatialTree, direction_salt, record_offset};
use glam::Vec3;

/// The value to record, or why the record is dropped (the first failing
/// check, in this order: direction, radiance, pdf, overflow).
#[inline]
fn check(dir: Vec3, radiance: f32, pdf: f32) -> Result<f32, DropReason> {
    unit_direction(dir).ok_or(DropReason::Direction)?;
    record_value(radiance, pdf)
}

impl SdState {
    /// PPG's record into the cells of `tree`: `radiance / pdf` along `dir`
    /// from the point `p` located at `at`, spread by the configured filters
    /// (see
    /// [`DirectionVertex::record_radiance`](super::DirectionVertex::record_radiance)).
    /// Invalid input is dropped and counted.
    #[inline]
    pub(crate) fn record_radiance<C: AsRef<SdCell>>(
        &self,
        tree: &BinaryTree<C>,
        (p, at): Located,
        dir: Vec3,
        radiance: f32,
        pdf: f32,
    ) -> RecordOutcome {
        let filters = (self.config.spatial_filter, self.config.directional_filter);
        let value = match check(dir, radiance, pdf) {
            Ok(v) => v,
            Err(reason) => {
                self.dropped.count(reason);
                return RecordOutcome::Dropped;
            }
        };
        tree.spread_from(
            p,
            at,
            filters.0,
            || record_offset(p, direction_salt(dir)),
            |cell, weight| {
                tree.data(cell)
                    .as_ref()
                    .record(dir, value, weight, filters.1)
            },
        );
        if value == 0.0 {
            RecordOutcome::Zero
        } else {
            RecordOutcome::Recorded
        }
    }

    /// Reports a fraction sample to `cell`; see
    /// [`DirectionVertex::record_fraction`](super::DirectionVertex::record_fraction).
    pub(crate) fn record_fraction(
        &self,
        cell: &SdCell,
        bsdf_pdf: f32,
        guiding_pdf: f32,
        contribution: f32,
    ) -> RecordOutcome {
        let ok = |x: f32| x >= 0.0 && x.is_finite();
        if !ok(contribution) {
            self.dropped.count(DropReason::Radiance);
            return RecordOutcome::Dropped;
        }
        if !(ok(bsdf_pdf) && ok(guiding_pdf) && bsdf_pdf + guiding_pdf > 0.0) {
            self.dropped.count(DropReason::Pdf);
            return RecordOutcome::Dropped;
        }
        if !self.config.learn_bsdf_fraction {
            return RecordOutcome::Ignored;
        }
        cell.record_fraction(bsdf_pdf, guiding_pdf, contribution);
        if contribution == 0.0 {
            RecordOutcome::Zero
        } else {
            RecordOutcome::Recorded
        }
    }
}
