//! Recording direct-light estimates into a cut's accumulating copy.

use super::config::Modulation;
use super::cut_rules::CutRules;
use super::guiding_cut::GuidingCut;
use crate::light_sampler::LightId;
use crate::light_tree::LightHierarchy;
use crate::math::Side;
use crate::record::RecordOutcome;
use glam::Vec3;

impl GuidingCut {
    /// Index of the sum that a record for `emitter` goes to: the first slot on
    /// its root-to-leaf path that ends the cut. `None` for an emitter out of
    /// range or with zero power.
    pub(crate) fn slot_of<H: LightHierarchy + ?Sized>(
        &self,
        tree: &H,
        emitter: u32,
    ) -> Option<usize> {
        let path = tree.path(emitter)?;
        let power = tree.power(path.leaf());
        self.slot_along(power, path.steps().iter().map(|&(_, side)| side))
    }

    /// [`GuidingCut::slot_of`] an emitter of power `power` whose path from
    /// the root takes `sides`.
    #[inline]
    pub(crate) fn slot_along(
        &self,
        power: f32,
        sides: impl Iterator<Item = Side>,
    ) -> Option<usize> {
        if power.is_nan() || power <= 0.0 {
            return None;
        }
        if self.nodes.is_empty() {
            return Some(0);
        }
        let mut i = 0u32;
        for side in sides {
            let node = self.nodes.get(i as usize)?;
            match node.child(side) {
                Some(j) => i = j,
                None => return Some(2 * i as usize + side.index()),
            }
        }
        // The path ended inside the cut: only possible for a cut that does
        // not belong to `tree`.
        None
    }
}

impl<H: LightHierarchy> CutRules<H> {
    /// Index of the sum (and learned visibility) of `light` in `cut`: its
    /// slot ([`GuidingCut::slot_of`]) or its unbounded light's. `None` for
    /// lights out of range and emitters without power.
    #[inline]
    pub(super) fn sum_of(&self, cut: &GuidingCut, light: LightId) -> Option<usize> {
        match light {
            // The path code (flat trees, at most 63 levels) spares
            // rebuilding the path from parent links.
            LightId::Emitter(e) => match (self.instanced(), self.tables().walk().code(e)) {
                (None, Some(code)) => {
                    let tree = self.light_tree();
                    let power = tree.leaf(e).map_or(0.0, |n| tree.power(n));
                    let sides = (0..code.depth()).map(|l| code.side(l));
                    cut.slot_along(power, sides)
                }
                _ => cut.slot_of(self.light_tree(), e),
            },
            LightId::Unbounded(i) => {
                (i < self.config().unbounded.count).then(|| cut.first_unbounded_sum() + i as usize)
            }
        }
    }

    /// Records into `cut` `value`, the MIS-weighted direct-light estimate for `light`
    /// seen from a point of this cell, without BSDF and cosine: from NEE,
    /// `Le * T * w_mis / (pdf_solid_angle * pmf)`; from a BSDF-sampled
    /// emitter hit, `Le * w_mis / pdf_direction` (use the luminance, or any
    /// fixed scalar, of a spectral value). The value goes to the first slot
    /// on the emitter's path that ends the cut (or to the unbounded light's
    /// sum). Takes `&self`: any number of threads may record at once, no
    /// update is lost.
    ///
    /// The record carries no position, so a cut trained only through this
    /// call has no anchor for [`Modulation::Importance`]; use
    /// [`CutRules::record_from`] there.
    pub fn record(&self, cut: &GuidingCut, light: LightId, value: f32) -> RecordOutcome {
        if !(value >= 0.0 && value.is_finite()) {
            return RecordOutcome::Dropped;
        }
        let Some(index) = self.sum_of(cut, light) else {
            return RecordOutcome::Dropped;
        };
        if value == 0.0 {
            return RecordOutcome::Zero;
        }
        if cut.sums.add(index, value) {
            // Only the data floor reads the count: the paper's rule
            // (`min_records` 0) pays no second atomic per record.
            if self.config().min_records > 0 {
                cut.recorded.bump();
            }
            RecordOutcome::Recorded
        } else {
            RecordOutcome::Dropped
        }
    }

    /// [`CutRules::record`] of an estimate made at the shading point
    /// `from`: with [`Modulation::Importance`] a record also adds
    /// `from` to the cut's anchor (the mean position its learned weights
    /// come from). The cells of [`crate::Glt`] and of the combined
    /// field record this way.
    pub fn record_from(
        &self,
        cut: &GuidingCut,
        from: Vec3,
        light: LightId,
        value: f32,
    ) -> RecordOutcome {
        self.record_weighted_from(cut, from, 1.0, light, value)
    }

    /// [`CutRules::record_from`] for the share `weight` of a record that
    /// a spatial filter spread over several cells (`value` is already
    /// scaled; the anchor takes `from` with this weight).
    #[inline]
    pub(crate) fn record_weighted_from(
        &self,
        cut: &GuidingCut,
        from: Vec3,
        weight: f32,
        light: LightId,
        value: f32,
    ) -> RecordOutcome {
        let outcome = self.record(cut, light, value);
        if outcome == RecordOutcome::Recorded && self.config().modulation != Modulation::None {
            cut.record_position(from, weight);
        }
        outcome
    }
}
