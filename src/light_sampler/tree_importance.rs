//! Light selection by descending a light hierarchy in proportion to each
//! cluster's importance at the shading point (Estevez & Kulla 2018, pbrt-v4's
//! `BVHLightSampler`).

use super::ShadingContext;
use super::importance::Query;
use super::{LightId, LightSample, LightSampler, tree_walk};
use crate::light_tree::LightHierarchy;
use crate::math::Descent;

/// Descends a [`LightHierarchy`] choosing, at each inner node, between the
/// two children in proportion to their [`super::importance`] at the shading
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
    /// A sampler over `tree`'s emitters.
    pub fn new(tree: H) -> Self {
        Self { tree }
    }

    /// The hierarchy it descends.
    pub fn light_tree(&self) -> &H {
        &self.tree
    }

    /// The descent weights of children `l` and `r` at `ctx`: their
    /// importances, or their powers when those are both zero (or
    /// unusable).
    #[inline]
    fn weights(&self, ctx: &ShadingContext) -> impl Fn(u32, u32) -> (f64, f64) + '_ {
        let q = Query::new(ctx);
        move |l, r| {
            let il = q.importance(&self.tree.node_bounds(l));
            let ir = q.importance(&self.tree.node_bounds(r));
            if Descent::probabilities(il, ir).is_some() {
                (il, ir)
            } else {
                (self.tree.power(l) as f64, self.tree.power(r) as f64)
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
        tree_walk::sample(&self.tree, u, self.weights(ctx))
    }

    #[inline]
    fn pmf(&self, ctx: &ShadingContext, light: LightId) -> f32 {
        if !ctx.is_finite() {
            return 0.0;
        }
        tree_walk::pmf(&self.tree, light, self.weights(ctx))
    }

    #[inline]
    fn is_empty(&self) -> bool {
        tree_walk::live_root(&self.tree).is_none()
    }
}
