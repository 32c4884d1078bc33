//! Light selection by descending a light hierarchy in proportion to each
//! cluster's importance at the shading point (Estevez & Kulla 2018, pbrt-v4's
//! `BVHLightSampler`).

use super::ShadingContext;
use super::importance::Query;
use super::{LightId, LightSample, LightSampler, tree_walk};
use crate::light_tree::LightHierarchy;
use crate::math::Descent;

/// Descends a [`LightHierarchy`] choosing, at each inner node, between the
/// two children in proportion to their importance (`light_sampler::importance`) at the shading
/// point: power x orientation bound / clamped distance^2, x the normal bound
/// when the context has a normal.
///
/// When both children of a node have zero importance (every light below is
/// behind the point, say), that node falls back to the children's powers,
/// so the pmf sums to 1 at every point whenever the tree has power; a
/// one-emitter tree gives that emitter pmf 1. A child with zero importance
/// next to one with positive importance is never chosen: it provably cannot
/// light the point.
///
/// One `u` drives the whole walk through the exact `f64` descent, and `pmf`
/// replays the emitter's path with the same weights, so sampled and
/// evaluated pmfs agree bit for bit. O(depth) importance evaluations (two per
/// level) per call.
#[derive(Clone, Copy, Debug)]
pub struct ImportanceTreeSampler<H: LightHierarchy> {
    tree: H,
}

impl<H: LightHierarchy> ImportanceTreeSampler<H> {
    /// A sampler over `light_tree`'s emitters.
    pub fn new(light_tree: H) -> Self {
        Self { tree: light_tree }
    }

    /// The hierarchy it descends.
    pub fn light_tree(&self) -> &H {
        &self.tree
    }

    /// The descent weights of children `l` and `r` at `ctx`: their
    /// importances, or their powers when those are both zero (or
    /// unusable); each times `seen` of the child (1, or 0 for a child with
    /// no emitter in the light sets the point receives).
    #[inline]
    fn weights<'a>(
        &'a self,
        ctx: &ShadingContext,
        seen: impl Fn(u32) -> f64 + 'a,
    ) -> impl Fn(u32, u32) -> (f64, f64) + 'a {
        let q = Query::new(ctx);
        move |l, r| {
            let (sl, sr) = (seen(l), seen(r));
            let il = q.importance(&self.tree.node_bounds(l)) * sl;
            let ir = q.importance(&self.tree.node_bounds(r)) * sr;
            if Descent::probabilities(il, ir).is_some() {
                (il, ir)
            } else {
                (
                    self.tree.power(l) as f64 * sl,
                    self.tree.power(r) as f64 * sr,
                )
            }
        }
    }
}

impl<H: LightHierarchy> LightSampler for ImportanceTreeSampler<H> {
    #[inline]
    fn sample(&self, ctx: &ShadingContext, u: f32) -> Option<LightSample> {
        if !ctx.is_finite() {
            return None;
        }
        let tree = &self.tree;
        match tree_walk::restriction(tree, ctx) {
            None => tree_walk::sample(tree, None, u, self.weights(ctx, |_| 1.0)),
            Some(r) => {
                let seen = move |n| tree_walk::seen(tree, r, n);
                tree_walk::sample(tree, Some(r), u, self.weights(ctx, seen))
            }
        }
    }

    #[inline]
    fn pmf(&self, ctx: &ShadingContext, light: LightId) -> f32 {
        if !ctx.is_finite() {
            return 0.0;
        }
        let tree = &self.tree;
        match tree_walk::restriction(tree, ctx) {
            None => tree_walk::pmf(tree, None, light, self.weights(ctx, |_| 1.0)),
            Some(r) => {
                let seen = move |n| tree_walk::seen(tree, r, n);
                tree_walk::pmf(tree, Some(r), light, self.weights(ctx, seen))
            }
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
