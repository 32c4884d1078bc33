//! A caterpillar light hierarchy as deep as it has leaves (shared by the
//! GLT's and the snapshot's deep-tree tests).

use glam::Vec3;
use guiding::LightHierarchy;
use guiding::light_tree::NodeBounds;
use guiding::math::{Aabb, LightCone};

/// A caterpillar hierarchy: inner node `k` has leaf `k` on the left and the
/// rest of the chain on the right, so leaf `k` sits at depth `k + 1` (the
/// last two at depth `n - 1`). Inner `k` = node `2k`, leaf `k` = node
/// `2k + 1`, the last leaf is node `2n - 2`.
pub struct Chain {
    power: Vec<f32>,
    subtree: Vec<f32>,
}

impl Chain {
    /// The chain of `power.len()` leaves with these powers.
    pub fn new(power: Vec<f32>) -> Self {
        let n = power.len();
        let mut subtree = vec![0.0f32; n];
        let mut acc = 0.0f64;
        for k in (0..n).rev() {
            acc += power[k] as f64;
            subtree[k] = acc as f32;
        }
        Self { power, subtree }
    }
    /// The 100-leaf chain of the deep-tree tests: powers 1 to 5.
    pub fn deep() -> Self {
        Self::new((0..100).map(|k| 1.0 + ((k * 7) % 5) as f32).collect())
    }

    /// What the deep-tree tests record for leaf `k` of [`Chain::deep`]:
    /// large for `k < 70` (skewed), a small tail whose total share (below
    /// the default sigma) ends the learned cut at depth 70. Fresh half
    /// splits reach a few levels deeper per refinement (16 take them
    /// there), power splits all the way.
    pub fn deep_target(k: u32) -> f32 {
        if k < 70 {
            1.0 + ((k * 3) % 7) as f32
        } else {
            0.05
        }
    }

    /// Number of leaves.
    pub fn n(&self) -> u32 {
        self.power.len() as u32
    }
    /// The node of leaf `e`.
    pub fn leaf_node(&self, e: u32) -> u32 {
        if e == self.n() - 1 { 2 * e } else { 2 * e + 1 }
    }
}

impl LightHierarchy for Chain {
    fn root(&self) -> Option<u32> {
        Some(0)
    }
    fn children(&self, node: u32) -> Option<[u32; 2]> {
        let n = self.n();
        if node % 2 == 1 || node == 2 * n - 2 {
            return None;
        }
        let k = node / 2;
        Some([2 * k + 1, 2 * k + 2])
    }
    fn parent(&self, node: u32) -> Option<u32> {
        if node == 0 {
            None
        } else if node % 2 == 1 {
            Some(node - 1)
        } else {
            Some(node - 2)
        }
    }
    fn power(&self, node: u32) -> f32 {
        match self.emitter(node) {
            Some(e) => self.power[e as usize],
            None => self.subtree[(node / 2) as usize],
        }
    }
    fn node_bounds(&self, node: u32) -> NodeBounds {
        NodeBounds {
            bounds: Aabb::new(Vec3::splat(-1.0), Vec3::splat(1.0)),
            cone: LightCone::SPHERE,
            two_sided: false,
            power: self.power(node),
        }
    }
    fn emitter(&self, node: u32) -> Option<u32> {
        let n = self.n();
        if node == 2 * n - 2 {
            Some(n - 1)
        } else if node % 2 == 1 {
            Some(node / 2)
        } else {
            None
        }
    }
    fn leaf(&self, emitter: u32) -> Option<u32> {
        (emitter < self.n()).then(|| self.leaf_node(emitter))
    }
    fn node_count(&self) -> usize {
        2 * self.power.len() - 1
    }
    fn emitter_count(&self) -> usize {
        self.power.len()
    }
}
