//! The `LightSampler` skeleton of the tree samplers: one exact descent
//! from the root to sample, the same weights replayed along the emitter's
//! path for the pmf. [`super::PowerTreeSampler`] and
//! [`super::ImportanceTreeSampler`] differ only in the weights they pass.

use super::{LightId, LightSample, ShadingContext, pmf_to_f32};
use crate::light_tree::LightHierarchy;
use crate::light_tree::descend::{descend, follow};
use crate::math::Descent;

/// The root of `tree`, when it has positive power.
#[inline]
pub(super) fn live_root<H: LightHierarchy + ?Sized>(tree: &H) -> Option<u32> {
    let root = tree.root()?;
    (tree.power(root) > 0.0).then_some(root)
}

/// The light sets `ctx` restricts `tree`'s emitters to: `None` when it does
/// not (the point receives every set, or no emitter is in fewer), so the
/// walks of scenes without light linking do no work for it.
#[inline]
pub(super) fn restriction<H: LightHierarchy + ?Sized>(
    tree: &H,
    ctx: &ShadingContext,
) -> Option<u64> {
    ctx.restricts(tree.has_light_sets()).then_some(ctx.receives)
}

/// Whether a tree walk chooses nothing at `ctx`: no emitter with power,
/// a position that is not finite, or no emitter in the sets it receives.
pub(super) fn is_empty_at<H: LightHierarchy + ?Sized>(tree: &H, ctx: &ShadingContext) -> bool {
    match live_root(tree) {
        _ if !ctx.is_finite() => true,
        None => true,
        Some(root) => restriction(tree, ctx).is_some_and(|r| seen(tree, r, root) == 0.0),
    }
}

/// 1 for a node some emitter of which is in one of the sets `receives`,
/// else 0 (the factor its weight is multiplied by).
#[inline]
pub(super) fn seen<H: LightHierarchy + ?Sized>(tree: &H, receives: u64, node: u32) -> f64 {
    f64::from(u8::from(tree.light_sets(node) & receives != 0))
}

/// Samples an emitter of `tree` by descending from its live root with
/// `weights`, driven by `u`; nothing when the root has no emitter in the
/// sets `receives` (when restricted).
#[inline]
pub(super) fn sample<H: LightHierarchy + ?Sized>(
    tree: &H,
    receives: Option<u64>,
    u: f32,
    weights: impl Fn(u32, u32) -> (f64, f64),
) -> Option<LightSample> {
    let root = live_root(tree)?;
    if receives.is_some_and(|r| seen(tree, r, root) == 0.0) {
        return None;
    }
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
    receives: Option<u64>,
    light: LightId,
    weights: impl Fn(u32, u32) -> (f64, f64),
) -> f32 {
    let LightId::Emitter(emitter) = light else {
        return 0.0;
    };
    let Some(root) = live_root(tree) else {
        return 0.0;
    };
    if receives.is_some_and(|r| seen(tree, r, root) == 0.0) {
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
