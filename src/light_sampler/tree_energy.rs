//! Light selection by descending a light hierarchy in proportion to subtree
//! energy: the rule the Guiding Light Tree uses below its cuts.

use super::{LightId, LightSample, LightSampler, pmf_to_f32};
use crate::emitter::ShadingContext;
use crate::light_tree::LightHierarchy;
use crate::light_tree::descend::{descend, energy_weights, follow};
use crate::math::Descent;

/// Descends a [`LightHierarchy`] from the root, choosing each child with
/// probability proportional to its subtree energy; the shading point is
/// ignored. In distribution this equals [`super::PowerSampler`] (up to the
/// `f32` rounding of the stored subtree energies).
///
/// One `u` drives the whole walk through the exact `f64` descent of
/// [`Descent`], so the choice is the inverse CDF of the leaves in tree order
/// at any depth. `pmf` replays the emitter's root-to-leaf path with the same
/// arithmetic, so both agree bit for bit. A zero-energy subtree is never
/// entered; when the root has no energy nothing is sampled. O(depth) per
/// call.
#[derive(Debug)]
pub struct EnergyTreeSampler<'a, H: LightHierarchy + ?Sized> {
    tree: &'a H,
}

impl<H: LightHierarchy + ?Sized> Clone for EnergyTreeSampler<'_, H> {
    fn clone(&self) -> Self {
        *self
    }
}

impl<H: LightHierarchy + ?Sized> Copy for EnergyTreeSampler<'_, H> {}

impl<'a, H: LightHierarchy + ?Sized> EnergyTreeSampler<'a, H> {
    /// A sampler over `tree`'s emitters.
    pub fn new(tree: &'a H) -> Self {
        Self { tree }
    }

    /// The hierarchy it descends.
    pub fn tree(&self) -> &'a H {
        self.tree
    }

    /// The root, when it has positive energy.
    #[inline]
    fn live_root(&self) -> Option<u32> {
        let root = self.tree.root()?;
        (self.tree.energy(root) > 0.0).then_some(root)
    }
}

impl<H: LightHierarchy + ?Sized> LightSampler for EnergyTreeSampler<'_, H> {
    #[inline]
    fn sample(&self, _ctx: &ShadingContext, u: f32) -> Option<LightSample> {
        let root = self.live_root()?;
        let mut d = Descent::new(u);
        let leaf = descend(self.tree, root, &mut d, energy_weights(self.tree))?;
        let emitter = self.tree.emitter(leaf)?;
        let pmf = pmf_to_f32(d.pmf());
        (pmf > 0.0).then_some(LightSample {
            light: LightId::Emitter(emitter),
            pmf,
        })
    }

    #[inline]
    fn pmf(&self, _ctx: &ShadingContext, light: LightId) -> f32 {
        let LightId::Emitter(emitter) = light else {
            return 0.0;
        };
        if self.live_root().is_none() {
            return 0.0;
        }
        let Some(path) = self.tree.path(emitter) else {
            return 0.0;
        };
        let mut d = Descent::evaluate();
        if !follow(self.tree, path.steps(), &mut d, energy_weights(self.tree)) {
            return 0.0;
        }
        pmf_to_f32(d.pmf())
    }

    #[inline]
    fn is_empty(&self) -> bool {
        self.live_root().is_none()
    }
}
