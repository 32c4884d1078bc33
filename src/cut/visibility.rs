//! Each cut cluster's learned visibility ([`CutConfig::visibility`]): the
//! fraction of its unshadowed contribution that arrives at the cell's
//! points, the factor resampled light choice puts on its target
//! ([`crate::resampling`]).
//!
//! A next-event record carries the value the renderer records for the
//! light (0 when the shadow ray was blocked) and the value it would have
//! recorded unoccluded ([`CutRules::record_visibility`]); per slot the cut
//! sums both. At a rebuild each old slot's estimate is
//!
//! ```text
//! v = (S + k u v0) / (U + k u),   k = 4,  u = (sum of U) / records
//! ```
//!
//! (`S`, `U` the slot's shadowed and unshadowed sums, `v0` what the slot
//! had before: a slot with few records, compared with the cell's average
//! record, stays near its old value; one with none keeps it), floored at
//! 1/64, so no cluster's target ever reaches 0 from learning alone. A new
//! slot takes the estimate of the old slot that covered its light node or,
//! where the new cut is coarser, the unshadowed-weighted mean of the old
//! slots below it. The sums are zeroed at each rebuild; the estimates carry
//! over, and a cut that is not rebuilt ([`CutConfig::min_records`]) goes on
//! accumulating.
//!
//! [`CutConfig::visibility`]: super::CutConfig::visibility
//! [`CutConfig::min_records`]: super::CutConfig::min_records

use super::cut_node::{CutNode, Slot};
use super::cut_rules::CutRules;
use super::guiding_cut::{GuidingCut, MIN_VISIBILITY, visibility_slots};
use crate::light_sampler::LightId;
use crate::light_tree::LightHierarchy;
use crate::record::RecordOutcome;
use alloc::vec::Vec;

/// Pseudo-records of the shrinkage towards a slot's previous visibility.
const PRIOR_RECORDS: f64 = 4.0;

impl<H: LightHierarchy> CutRules<H> {
    /// Records what one next-event sample of `light` saw, for the cut's
    /// learned visibility: `shadowed` is the value recorded for it (0 when
    /// the shadow ray was blocked), `unshadowed` the value it would have
    /// been without occluders (the same scalar as
    /// [`CutRules::record`]'s). A sample the renderer skipped (a zero
    /// BSDF, say) is not a record. [`RecordOutcome::Ignored`] when the
    /// configuration learns no visibility (then nothing else is looked at
    /// but the values), [`RecordOutcome::Zero`] when `unshadowed` is 0; [`RecordOutcome::Dropped`] for
    /// values that are negative, not finite, or with `shadowed >
    /// unshadowed`, and, while learning, lights out of range. `&self`:
    /// any number of threads at once.
    pub fn record_visibility(
        &self,
        cut: &GuidingCut,
        light: LightId,
        shadowed: f32,
        unshadowed: f32,
    ) -> RecordOutcome {
        if !valid_record(shadowed, unshadowed) {
            return RecordOutcome::Dropped;
        }
        if cut.visibility.is_empty() {
            // Nothing to learn: no lookup either, so the renderer can make
            // these records whatever the configuration.
            return RecordOutcome::Ignored;
        }
        let Some(index) = self.sum_of(cut, light) else {
            return RecordOutcome::Dropped;
        };
        if unshadowed == 0.0 {
            return RecordOutcome::Zero;
        }
        cut.seen.add(2 * index, shadowed);
        cut.seen.add(2 * index + 1, unshadowed);
        cut.seen_records.bump();
        RecordOutcome::Recorded
    }

    /// The learned visibility of `light` in `cut`: its slot's (1 when the
    /// configuration learns none, or for lights out of range).
    pub fn visibility(&self, cut: &GuidingCut, light: LightId) -> f32 {
        if cut.visibility.is_empty() {
            return 1.0;
        }
        self.visibility_at(cut, self.sum_of(cut, light))
    }

    /// The learned visibility of the slot (or unbounded light) of sum
    /// `sum` in `cut` (1 for none), trusted as far as the cut's
    /// [`GuidingCut::confidence`]: `1 - confidence (1 - v)`, so a cut that
    /// learned nothing of its own assumes nothing is hidden.
    #[inline]
    pub(crate) fn visibility_at(&self, cut: &GuidingCut, sum: Option<usize>) -> f32 {
        let v = sum
            .and_then(|i| cut.visibility.get(i).copied())
            .unwrap_or(1.0);
        if cut.confidence >= 1.0 {
            v
        } else {
            1.0 - cut.confidence * (1.0 - v)
        }
    }

    /// The visibilities of a rebuilt cut whose nodes were `old` (the cut
    /// still holds the old visibilities and this iteration's sums) and are
    /// now `new`; zeroes and resizes the sums. Nothing without learned
    /// visibility.
    pub(super) fn relearn_visibility(&self, cut: &mut GuidingCut, old: &[CutNode]) {
        if cut.visibility.is_empty() {
            return;
        }
        let estimates = slot_estimates(cut);
        let tree = self.light_tree();
        let config = self.config();
        let k = config.unbounded.count as usize;
        let (old_slots, new_slots) = (
            estimates.len() - k,
            visibility_slots(cut.nodes.len(), config) - k,
        );
        let mut visibility = Vec::with_capacity(new_slots + k);
        if cut.nodes.is_empty() {
            let root = tree.root();
            visibility.push(root.map_or(1.0, |r| covering(tree, old, &estimates, r)));
        } else {
            for node in &cut.nodes {
                for side in [crate::math::Side::Left, crate::math::Side::Right] {
                    visibility.push(match node.slot(side) {
                        Slot::End(n) => covering(tree, old, &estimates, n),
                        // Slots that continue the cut are never looked up.
                        Slot::Child(_) => 1.0,
                    });
                }
            }
        }
        visibility.extend(estimates[old_slots..].iter().map(|e| e.0 as f32));
        cut.visibility = visibility.into_boxed_slice();
        cut.seen.reset(2 * (new_slots + k));
        cut.seen_records.reset();
    }
}

/// Whether a visibility record's values can be taken: finite, not
/// negative, the shadowed at most the unshadowed.
#[inline]
pub(crate) fn valid_record(shadowed: f32, unshadowed: f32) -> bool {
    let valid = |x: f32| x >= 0.0 && x.is_finite();
    valid(shadowed) && valid(unshadowed) && shadowed <= unshadowed
}

/// Each old slot's (then unbounded light's) estimate and unshadowed sum.
fn slot_estimates(cut: &GuidingCut) -> Vec<(f64, f64)> {
    let n = cut.visibility.len();
    let total: f64 = (0..n).map(|i| cut.seen.get(2 * i + 1)).sum();
    let records = cut.seen_records.get() as f64;
    let mean = if records > 0.0 { total / records } else { 0.0 };
    (0..n)
        .map(|i| {
            let (s, u) = (cut.seen.get(2 * i), cut.seen.get(2 * i + 1));
            let v0 = f64::from(cut.visibility[i]);
            let k = PRIOR_RECORDS * mean;
            let v = if u + k > 0.0 && (u + k).is_finite() {
                (s + k * v0) / (u + k)
            } else {
                v0
            };
            (v.clamp(f64::from(MIN_VISIBILITY), 1.0), u)
        })
        .collect()
}

/// The estimate for light node `n` from the old cut `old`: the old slot
/// that covered it, or the unshadowed-weighted mean of the old slots below
/// it where the old cut went deeper.
fn covering<H: LightHierarchy + ?Sized>(
    tree: &H,
    old: &[CutNode],
    estimates: &[(f64, f64)],
    n: u32,
) -> f32 {
    let at = |i: usize| estimates.get(i).map_or(1.0, |e| e.0) as f32;
    if old.is_empty() {
        return at(0);
    }
    // A leaf below `n`, for a root-to-`n` path.
    let mut leaf = n;
    while let Some([l, _]) = tree.children(leaf) {
        leaf = l;
    }
    let Some(path) = tree.emitter(leaf).and_then(|e| tree.path(e)) else {
        return 1.0;
    };
    let mut i = 0usize;
    for &(node, side) in path.steps() {
        if node == n {
            return below(old, estimates, i);
        }
        match old.get(i).and_then(|o| o.child(side)) {
            Some(j) => i = j as usize,
            None => return at(2 * i + side.index()),
        }
    }
    1.0
}

/// The unshadowed-weighted mean estimate of the old slots below old cut
/// node `i` (the plain mean when none has a record).
fn below(old: &[CutNode], estimates: &[(f64, f64)], i: usize) -> f32 {
    let (mut vu, mut u, mut v, mut n) = (0.0, 0.0, 0.0, 0.0);
    let mut stack = alloc::vec![i];
    while let Some(j) = stack.pop() {
        let Some(node) = old.get(j) else { continue };
        for side in [crate::math::Side::Left, crate::math::Side::Right] {
            match node.child(side) {
                Some(c) => stack.push(c as usize),
                None => {
                    let (e, w) = estimates
                        .get(2 * j + side.index())
                        .copied()
                        .unwrap_or((1.0, 0.0));
                    vu += e * w;
                    u += w;
                    v += e;
                    n += 1.0;
                }
            }
        }
    }
    let mean = if u > 0.0 {
        vu / u
    } else if n > 0.0 {
        v / n
    } else {
        1.0
    };
    mean as f32
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cut::CutConfig;
    use crate::emitter::Emitter;
    use crate::light_sampler::UnboundedLights;
    use crate::light_tree::{BuildHeuristic, LightTree};
    use glam::Vec3;

    /// After every refine a cut with unbounded lights keeps one visibility
    /// per slot and unbounded light, and exactly two visibility sums
    /// (shadowed, unshadowed) for each: the slots are counted without the
    /// unbounded lights, which come after them (adding them twice sized
    /// the sums for lights that do not exist).
    #[test]
    fn relearned_visibility_sizes_its_sums_by_slot() {
        let lights: Vec<Emitter> = (0..40)
            .map(|i| Emitter::point(Vec3::new(i as f32, (i % 7) as f32, 0.0), 1.0 + i as f32))
            .collect();
        let tree = LightTree::build(&lights, BuildHeuristic::Sarh).unwrap();
        let k = 3;
        let config = CutConfig {
            min_records: 0,
            visibility: true,
            unbounded: UnboundedLights::new(k, 0.1).unwrap(),
            ..CutConfig::default()
        };
        let guide = CutRules::new(&tree, config).unwrap();
        let mut cut = guide.new_cut();
        for round in 0..3 {
            for e in 0..40u32 {
                let l = LightId::Emitter(e);
                guide.record(&cut, l, 1.0 + e as f32);
                guide.record_visibility(&cut, l, (e % 2) as f32, 1.0);
            }
            guide.record_visibility(&cut, LightId::Unbounded(2), 0.5, 1.0);
            guide.refine(&mut cut);
            let slots = visibility_slots(cut.nodes.len(), &config);
            assert_eq!(cut.visibility.len(), slots, "round {round}");
            assert_eq!(cut.seen.len(), 2 * slots, "round {round}");
        }
        assert!(cut.nodes.len() > 2, "the cut split");
    }
}
