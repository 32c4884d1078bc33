//! Inspecting either copy leaf by leaf: for tests, debugging views and
//! anything that wants the learned distribution as cells.

use super::cell::cell_size;
use super::node::{Link, quadrant_probability};
use super::sums::subtree_sums;
use super::tree::DirectionalTree;
use alloc::vec;
use alloc::vec::Vec;
use glam::Vec2;

/// One leaf cell of a [`DirectionalTree`] copy, in the canonical square
/// `[0, 1]^2` (`u = (cos theta + 1) / 2`, `v = phi / 2 pi`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct QuadLeaf {
    /// Lower corner `(u, v)`.
    pub min: [f64; 2],
    /// Side length, `2^-depth`.
    pub size: f64,
    /// Level of the node holding the leaf (1 for the root's quadrants).
    pub depth: u32,
    /// For [`DirectionalTree::sampling_leaves`]: the probability the tree
    /// part of the density gives the leaf (the leaves sum to 1). For
    /// [`DirectionalTree::building_leaves`]: the sum collected in the leaf.
    pub value: f64,
}

impl QuadLeaf {
    /// The leaf's centre.
    pub fn center(&self) -> Vec2 {
        let h = 0.5 * self.size;
        Vec2::new((self.min[0] + h) as f32, (self.min[1] + h) as f32)
    }

    /// The leaf's area in canonical space (`size^2`; times `4 pi` for its
    /// solid angle).
    pub fn area(&self) -> f64 {
        self.size * self.size
    }

    /// True when the canonical point `c` lies in the leaf (lower edges
    /// included, upper excluded).
    pub fn contains(&self, c: Vec2) -> bool {
        let (x, y) = (c.x as f64, c.y as f64);
        x >= self.min[0]
            && x < self.min[0] + self.size
            && y >= self.min[1]
            && y < self.min[1] + self.size
    }
}

impl DirectionalTree {
    /// The sampling copy's leaves with their probabilities, in depth-first
    /// order. `O(nodes)`.
    pub fn sampling_leaves(&self) -> Vec<QuadLeaf> {
        // Probability of reaching each node; parents precede children.
        let mut reach = vec![0.0f64; self.nodes.len()];
        reach[0] = 1.0;
        for (n, node) in self.nodes.iter().enumerate() {
            for q in 0..4 {
                if let Some(c) = node.link.child(q) {
                    reach[c] = reach[n] * quadrant_probability(&node.probs, q);
                }
            }
        }
        leaves(
            |n| self.nodes[n].link,
            |n, q| reach[n] * quadrant_probability(&self.nodes[n].probs, q),
        )
    }

    /// The building copy's leaves with the sums collected this iteration,
    /// box-filter mass on inner quadrants spread evenly to the leaves below,
    /// in depth-first order. `O(nodes)`: call it between iterations.
    pub fn building_leaves(&self) -> Vec<QuadLeaf> {
        let s = subtree_sums(&self.links, &self.sums);
        leaves(|n| self.links[n], |n, q| s[4 * n + q])
    }
}

/// Every leaf quadrant of a topology, depth first.
fn leaves(link: impl Fn(usize) -> Link, value: impl Fn(usize, usize) -> f64) -> Vec<QuadLeaf> {
    let mut out = Vec::new();
    // (node, level, cell x, cell y) of the node's square at level - 1.
    let mut stack = vec![(0usize, 1u32, 0u32, 0u32)];
    while let Some((n, level, ox, oy)) = stack.pop() {
        let size = cell_size(level);
        let l = link(n);
        for q in (0..4).rev() {
            let (ix, iy) = (2 * ox + (q & 1) as u32, 2 * oy + (q >> 1) as u32);
            match l.child(q) {
                Some(c) => stack.push((c, level + 1, ix, iy)),
                None => out.push(QuadLeaf {
                    min: [ix as f64 * size, iy as f64 * size],
                    size,
                    depth: level,
                    value: value(n, q),
                }),
            }
        }
    }
    out
}
