//! The directional tree: its two copies, construction and size queries.

use super::config::{DEFAULT_UNIFORM_FRACTION, MIN_UNIFORM_FRACTION};
use super::node::{Link, NODE_BYTES, Node};
use crate::math::{Accumulation, SumBuffer};
use alloc::vec;
use alloc::vec::Vec;

/// PPG's directional quadtree: one per spatial cell, holding a sampling copy
/// (what [`sample`](Self::sample) and [`pdf`](Self::pdf) read) and a building
/// copy (what [`record`](Self::record) adds to).
///
/// `Clone` copies both copies, the sums collected so far included (a spatial
/// cell that splits gives both children its tree).
///
/// ```
/// use guiding::learned::{DirectionalTree, UNIFORM_PDF};
/// use guiding::{Accumulation, DirectionalFilter, QuadtreeConfig};
/// use glam::Vec3;
///
/// let mut tree = DirectionalTree::new(Accumulation::Fast);
/// assert_eq!(tree.pdf(Vec3::Z), UNIFORM_PDF);
/// for _ in 0..100 {
///     tree.record(Vec3::Z, 1.0, DirectionalFilter::Nearest);
/// }
/// tree.refine(&QuadtreeConfig::default());
/// assert!(tree.pdf(Vec3::Z) > 2.0 * UNIFORM_PDF);
/// let (dir, pdf) = tree.sample([0.3, 0.7]);
/// assert_eq!(pdf, tree.pdf(dir));
/// ```
#[derive(Clone, Debug)]
pub struct DirectionalTree {
    /// Sampling copy, breadth-first, root first.
    pub(super) nodes: Vec<Node>,
    /// Total the sampling copy was learned from; 0 means uniform.
    pub(super) sampling_total: f64,
    pub(super) sampling_depth: u32,
    /// Building copy's topology, breadth-first, root first.
    pub(super) links: Vec<Link>,
    pub(super) building_depth: u32,
    /// Four sums per building node (quadrant `q` of node `n` at `4 n + q`).
    /// A leaf quadrant's sum is what landed in it; an inner quadrant's sum is
    /// mass a box record spread evenly over all of it.
    pub(super) sums: SumBuffer,
    /// Weight of the uniform part of the density.
    pub(super) uniform_fraction: f64,
}

impl DirectionalTree {
    /// The default weight of the uniform part of the density (the
    /// defensive mixture). It costs one sample in a thousand and caps the
    /// sampling weight `1 / pdf` at `4 pi / 0.001` where nothing was
    /// learned.
    pub const DEFAULT_UNIFORM_FRACTION: f32 = DEFAULT_UNIFORM_FRACTION;

    /// The smallest uniform fraction: it keeps the pdf of every valid
    /// direction positive in `f32`.
    pub const MIN_UNIFORM_FRACTION: f32 = MIN_UNIFORM_FRACTION;

    /// An empty tree: a root whose four quadrants are leaves, sampling
    /// uniformly (pdf `1 / (4 pi)`), collecting sums in `mode`.
    pub fn new(mode: Accumulation) -> Self {
        Self {
            nodes: vec![Node::UNIFORM_LEAF],
            sampling_total: 0.0,
            sampling_depth: 1,
            links: vec![Link::LEAF],
            building_depth: 1,
            sums: SumBuffer::new(4, mode),
            uniform_fraction: DEFAULT_UNIFORM_FRACTION as f64,
        }
    }

    /// The weight of the uniform part of the density (the defensive mixture
    /// that keeps every direction's pdf positive).
    pub fn uniform_fraction(&self) -> f32 {
        self.uniform_fraction as f32
    }

    /// Sets the weight of the uniform part, clamped to
    /// `[`[`DirectionalTree::MIN_UNIFORM_FRACTION`]`, 1]` (NaN gives the default). It applies to
    /// the current sampling copy at once.
    pub fn set_uniform_fraction(&mut self, fraction: f32) {
        let f = if fraction.is_nan() {
            DEFAULT_UNIFORM_FRACTION
        } else {
            fraction.clamp(MIN_UNIFORM_FRACTION, 1.0)
        };
        self.uniform_fraction = f as f64;
    }

    /// How the building copy accumulates.
    pub fn accumulation(&self) -> Accumulation {
        self.sums.mode()
    }

    /// The total collected in the building copy this iteration (since the
    /// last [`refine`](Self::refine)). It reads every sum, `O(nodes)`: call
    /// it between iterations.
    pub fn building_total(&self) -> f64 {
        (0..self.sums.len()).map(|i| self.sums.get(i)).sum()
    }

    /// The total the sampling copy was learned from (0 while it is uniform).
    pub fn sampling_total(&self) -> f64 {
        self.sampling_total
    }

    /// True while the sampling copy is the uniform distribution (nothing
    /// learned yet, or only zeros).
    pub fn is_uniform(&self) -> bool {
        // Only ever set to a positive finite total.
        self.sampling_total == 0.0
    }

    /// Heap and inline bytes of both copies.
    pub fn bytes(&self) -> usize {
        core::mem::size_of::<Self>()
            + self.nodes.capacity() * NODE_BYTES
            + self.links.capacity() * core::mem::size_of::<Link>()
            + self.sums.bytes()
    }

    /// Nodes in the sampling copy (what queries walk).
    pub fn node_count(&self) -> usize {
        self.nodes.len()
    }

    /// Node levels in the sampling copy (1 for a root whose quadrants are
    /// leaves).
    pub fn depth(&self) -> usize {
        self.sampling_depth as usize
    }

    /// Nodes in the building copy (what records walk).
    pub fn building_node_count(&self) -> usize {
        self.links.len()
    }

    /// Node levels in the building copy.
    pub fn building_depth(&self) -> usize {
        self.building_depth as usize
    }
}

impl Default for DirectionalTree {
    /// An empty tree with [`Accumulation::Fast`] sums.
    fn default() -> Self {
        Self::new(Accumulation::Fast)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn new_tree_is_one_uniform_root() {
        let t = DirectionalTree::new(Accumulation::Deterministic);
        assert_eq!(t.node_count(), 1);
        assert_eq!(t.depth(), 1);
        assert_eq!(t.building_node_count(), 1);
        assert!(t.is_uniform());
        assert_eq!(t.building_total(), 0.0);
        assert_eq!(t.accumulation(), Accumulation::Deterministic);
        assert!(t.bytes() >= NODE_BYTES + 8 + 4 * 48);
    }

    #[test]
    fn uniform_fraction_is_clamped() {
        let mut t = DirectionalTree::default();
        t.set_uniform_fraction(0.0);
        assert_eq!(t.uniform_fraction(), MIN_UNIFORM_FRACTION);
        t.set_uniform_fraction(7.0);
        assert_eq!(t.uniform_fraction(), 1.0);
        t.set_uniform_fraction(f32::NAN);
        assert_eq!(t.uniform_fraction(), DEFAULT_UNIFORM_FRACTION);
    }
}
