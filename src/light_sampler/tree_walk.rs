//! The `LightSampler` skeleton of the tree samplers: one exact descent
//! from the root to sample, the same weights replayed along the emitter's
//! path for the pmf. [`super::PowerTreeSampler`] and
//! [`super::ImportanceTreeSampler`] differ only in the weights they pass.

use super::{LightId, LightSample, pmf_to_f32};
use crate::light_tree::LightHierarchy;
use crate::light_tree::descend::{descend, follow};
use crate::math::Descent;

/// The root of `tree`, when it has positive power.
#[inline]
pub(super) fn live_root<H: LightHierarchy + ?Sized>(tree: &H) -> Option<u32> {
    let root = tree.root()?;
    (tree.power(root) > 0.0).then_some(root)
}

/// Samples an emitter of `tree` by descending from its live root with
/// `weights`, driven by `u`.
#[inline]
pub(super) fn sample<H: LightHierarchy + ?Sized>(
    tree: &H,
    u: f32,
    weights: impl Fn(u32, u32) -> (f64, f64),
) -> Option<LightSample> {
    let root = live_root(tree)?;
    let mut d = Descent::new(u);
    let leaf = descend(tree, root, &mut d, weights)?;
    let emitter = tree.emitter(leaf)?;
    let pmf = pmf_to_f32(d.pmf());
    (pmf > 0.0).then_some(LightSample {
        light: LightId::Emitter(emitter),
        pmf,
    })
}

/// The probability that [`sample`] with the same `weights` chooses `light`:
/// the emitter's root-to-leaf path replayed with the same arithmetic, so
/// both agree bit for bit.
#[inline]
pub(super) fn pmf<H: LightHierarchy + ?Sized>(
    tree: &H,
    light: LightId,
    weights: impl Fn(u32, u32) -> (f64, f64),
) -> f32 {
    let LightId::Emitter(emitter) = light else {
        return 0.0;
    };
    if live_root(tree).is_none() {
        return 0.0;
    }
    let Some(path) = tree.path(emitter) else {
        return 0.0;
    };
    let mut d = Descent::evaluate();
    if !follow(tree, path.steps(), &mut d, weights) {
        return 0.0;
    }
    pmf_to_f32(d.pmf())
}
