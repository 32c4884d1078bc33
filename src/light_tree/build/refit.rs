//! Refitting a built tree to emitters that moved or changed power, and the
//! spread that says when a refitted tree has drifted far enough from a
//! good one to be rebuilt.

use super::cone_bound::ConeBound;
use super::items::validate;
use super::{Aggregate, Encoded, aggregate_and_encode};
use crate::emitter::Emitters;
use crate::light_tree::node::{LEAF_BIT, LightNode};
use crate::light_tree::{BuildError, LightTree};
use crate::math::Aabb;
use alloc::vec::Vec;

/// The nodes, scene box and light sets of `tree`'s shape over `emitters` (the same
/// count, emitter `i` on the leaf that held emitter `i`): every leaf from
/// its emitter, every inner node aggregated as the build does, then
/// quantised against the new root's bounds. Bit-identical to the build's
/// nodes when nothing moved.
pub(in crate::light_tree) fn refit<E: Emitters + ?Sized>(
    tree: &LightTree,
    emitters: &E,
) -> Result<Encoded, BuildError> {
    if emitters.len() != tree.leaf_of.len() {
        return Err(BuildError::EmitterCount {
            tree: tree.leaf_of.len(),
            given: emitters.len(),
        });
    }
    let items = validate(emitters)?;
    let mut agg: Vec<Aggregate> = tree
        .nodes
        .iter()
        .map(|n| {
            let (link, parent) = (n.link(), n.parent());
            match items
                .get((link & !LEAF_BIT) as usize)
                .filter(|_| n.is_leaf())
            {
                Some(it) => Aggregate {
                    bounds: it.bounds,
                    cone: ConeBound::of(&it.cone),
                    two_sided: it.two_sided,
                    sets: it.sets,
                    power: it.power as f64,
                    link,
                    parent,
                },
                None => Aggregate {
                    bounds: Aabb::EMPTY,
                    cone: ConeBound::sphere(0.0),
                    two_sided: false,
                    sets: 0,
                    power: 0.0,
                    link,
                    parent,
                },
            }
        })
        .collect();
    aggregate_and_encode(&mut agg)
}

/// The tree's spread: over its inner nodes, the sum of their boxes'
/// squared diagonals, over the root's. Every cluster counts alike, so the
/// many small clusters near the leaves weigh most: lights that move apart
/// from the ones they were clustered with grow it, while a scene that only
/// grows or shrinks as a whole keeps it. 0 when the root's box is a point
/// (every emitter at one point: then every shape is as good as another).
///
/// Measured (`cargo run --release --example refit_drift`,
/// docs/experiments/refit.md): the variance of importance sampling over a
/// refitted tree grows with this ratio (a drift of 1.2 to 1.5: 1.1 to 1.7
/// times a rebuilt tree's), whereas a cost weighted by power (SAOH's terms)
/// stayed within 1.1 while the variance doubled; changes of power alone
/// cost nothing (the refitted tree sampled no worse than a rebuilt one).
pub(in crate::light_tree) fn spread(nodes: &[LightNode], scene: &Aabb) -> f32 {
    let squared_diagonal = |n: &LightNode| {
        let d = n.decode(scene).bounds.diagonal();
        [d.x, d.y, d.z]
            .map(|x| x as f64 * x as f64)
            .iter()
            .sum::<f64>()
    };
    let Some(root) = nodes.first().map(squared_diagonal) else {
        return 0.0;
    };
    if !(root > 0.0 && root.is_finite()) {
        return 0.0;
    }
    let inner: f64 = nodes
        .iter()
        .filter(|n| !n.is_leaf())
        .map(squared_diagonal)
        .sum();
    (inner / root) as f32
}
