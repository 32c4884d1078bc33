//! Light selection by descending a light hierarchy in proportion to subtree
//! power: the rule the Guiding Light Tree uses below its cuts.

use super::ShadingContext;
use super::{LightId, LightSample, LightSampler, tree_walk};
use crate::light_tree::LightHierarchy;
use crate::light_tree::descend::power_weights;

/// Descends a [`LightHierarchy`] from the root, choosing each child with
/// probability proportional to its subtree power; the shading point is
/// ignored. In distribution this equals [`super::PowerSampler`] (up to the
/// `f32` rounding of the stored subtree powers).
///
/// One `u` drives the whole walk through the exact `f64` descent of
/// `Descent` (`src/math/descent.rs`), so the choice is the inverse CDF of
/// the leaves in tree order at any depth. `pmf` replays the emitter's
/// root-to-leaf path with the same arithmetic, so both agree bit for bit. A zero-power subtree is never
/// entered; when the root has no power nothing is sampled. O(depth) per
/// call.
#[derive(Clone, Copy, Debug)]
pub struct PowerTreeSampler<H: LightHierarchy> {
    tree: H,
}

impl<H: LightHierarchy> PowerTreeSampler<H> {
    /// A sampler over `light_tree`'s emitters.
    pub fn new(light_tree: H) -> Self {
        Self { tree: light_tree }
    }

    /// The hierarchy it descends.
    pub fn light_tree(&self) -> &H {
        &self.tree
    }
}

/// The power weights of the children of the emitters in the sets
/// `receives` (a child with none weighs 0).
#[inline]
fn masked<H: LightHierarchy + ?Sized>(
    tree: &H,
    receives: u64,
) -> impl Fn(u32, u32) -> (f64, f64) + '_ {
    let power = power_weights(tree);
    move |l, r| {
        let (pl, pr) = power(l, r);
        (
            pl * tree_walk::seen(tree, receives, l),
            pr * tree_walk::seen(tree, receives, r),
        )
    }
}

impl<H: LightHierarchy> LightSampler for PowerTreeSampler<H> {
    #[inline]
    fn sample(&self, ctx: &ShadingContext, u: f32) -> Option<LightSample> {
        if !ctx.is_finite() {
            return None;
        }
        let tree = &self.tree;
        match tree_walk::restriction(tree, ctx) {
            None => tree_walk::sample(tree, None, u, power_weights(tree)),
            Some(r) => tree_walk::sample(tree, Some(r), u, masked(tree, r)),
        }
    }

    #[inline]
    fn pmf(&self, ctx: &ShadingContext, light: LightId) -> f32 {
        if !ctx.is_finite() {
            return 0.0;
        }
        let tree = &self.tree;
        match tree_walk::restriction(tree, ctx) {
            None => tree_walk::pmf(tree, None, light, power_weights(tree)),
            Some(r) => tree_walk::pmf(tree, Some(r), light, masked(tree, r)),
        }
    }

    #[inline]
    fn is_empty(&self) -> bool {
        tree_walk::live_root(&self.tree).is_none()
    }

    fn is_empty_at(&self, ctx: &ShadingContext) -> bool {
        tree_walk::is_empty_at(&self.tree, ctx)
    }
}
