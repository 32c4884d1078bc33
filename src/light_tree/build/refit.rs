//! Refitting a built tree to emitters that moved or changed power, and the
//! cost that says when a refitted tree has drifted far enough from a good
//! one to be rebuilt.

use super::cone_bound::ConeBound;
use super::heuristic::m_omega;
use super::items::validate;
use super::{Aggregate, aggregate_and_encode};
use crate::emitter::Emitters;
use crate::light_tree::node::{LEAF_BIT, LightNode};
use crate::light_tree::{BuildError, LightTree};
use crate::math::Aabb;
use crate::math::scalar::safe_acos;
use alloc::vec::Vec;

/// The nodes and scene box of `tree`'s shape over `emitters` (the same
/// count, emitter `i` on the leaf that held emitter `i`): every leaf from
/// its emitter, every inner node aggregated as the build does, then
/// quantised against the new root's bounds. Bit-identical to the build's
/// nodes when nothing moved.
pub(in crate::light_tree) fn refit<E: Emitters + ?Sized>(
    tree: &LightTree,
    emitters: &E,
) -> Result<(Vec<LightNode>, Aabb), BuildError> {
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
                    power: it.power as f64,
                    link,
                    parent,
                },
                None => Aggregate {
                    bounds: Aabb::EMPTY,
                    cone: ConeBound::sphere(0.0),
                    two_sided: false,
                    power: 0.0,
                    link,
                    parent,
                },
            }
        })
        .collect();
    aggregate_and_encode(&mut agg)
}

/// The tree's cost: over its inner nodes, the sum of power x squared
/// diagonal x orientation measure (SAOH's terms, with the diagonal for the
/// surface area, which vanishes for lights in a row), over the root's own. A tree whose
/// clusters are tight in space and direction costs little; one whose
/// clusters were pulled apart (emitters that moved since the build) costs
/// more. 0 when the root's measure is 0 (every emitter at one point, or no
/// power): then every shape is as good as another.
pub(in crate::light_tree) fn cost(nodes: &[LightNode], scene: &Aabb) -> f32 {
    let measure = |n: &LightNode| {
        let b = n.decode(scene);
        let m = m_omega(safe_acos(b.cone.cos_theta_o), b.cone.cos_theta_e);
        let d = b.bounds.diagonal();
        let d2 = [d.x, d.y, d.z]
            .map(|x| x as f64 * x as f64)
            .iter()
            .sum::<f64>();
        b.power as f64 * d2 * m as f64
    };
    let Some(root) = nodes.first().map(measure) else {
        return 0.0;
    };
    if !(root > 0.0 && root.is_finite()) {
        return 0.0;
    }
    let inner: f64 = nodes.iter().filter(|n| !n.is_leaf()).map(measure).sum();
    (inner / root) as f32
}
