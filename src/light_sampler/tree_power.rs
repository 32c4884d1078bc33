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
    /// A sampler over `tree`'s emitters.
    pub fn new(tree: H) -> Self {
        Self { tree }
    }

    /// The hierarchy it descends.
    pub fn light_tree(&self) -> &H {
        &self.tree
    }
}

impl<H: LightHierarchy> LightSampler for PowerTreeSampler<H> {
    #[inline]
    fn sample(&self, ctx: &ShadingContext, u: f32) -> Option<LightSample> {
        if !ctx.is_finite() {
            return None;
        }
        tree_walk::sample(&self.tree, u, power_weights(&self.tree))
    }

    #[inline]
    fn pmf(&self, ctx: &ShadingContext, light: LightId) -> f32 {
        if !ctx.is_finite() {
            return 0.0;
        }
        tree_walk::pmf(&self.tree, light, power_weights(&self.tree))
    }

    #[inline]
    fn is_empty(&self) -> bool {
        tree_walk::live_root(&self.tree).is_none()
    }
}
