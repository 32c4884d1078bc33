//! The end of an iteration: the building copy's sums become the sampling
//! copy, and the building topology is split and merged for the next one.
//!
//! The new topology is built top-down, breadth-first, from the sums just
//! collected (PPG's rule): a quadrant whose share of the total exceeds `rho`
//! gets a child node (unless at `max_depth`), any other quadrant becomes a
//! leaf, which merges whatever subtree it had. A quadrant that was a leaf and
//! splits passes a quarter of its sum to each new quadrant, so one refine can
//! split several levels below a bright leaf.

use super::config::QuadtreeConfig;
use super::node::NODE_BYTES;
use super::node::{Link, Node};
use super::sums::{node_total, subtree_sums};
use super::tree::DirectionalTree;
use crate::spatial::Growth;
use alloc::vec::Vec;

/// Where a node of the new building topology takes its quadrant sums from.
#[derive(Clone, Copy, Debug)]
enum Source {
    /// A node of the old topology.
    Old(usize),
    /// A new node under an old leaf (or another new node) whose quadrant had
    /// this sum: a quarter each.
    Fresh(f64),
}

/// The refined building topology.
pub(crate) struct Refined {
    pub(crate) links: Vec<Link>,
    /// The sums each new quadrant starts from before they are zeroed (what
    /// the split decisions used), four per node; kept for tests only.
    #[cfg(test)]
    pub(crate) sums: Vec<f64>,
    pub(crate) depth: u32,
}

impl DirectionalTree {
    /// Ends an iteration.
    ///
    /// The building copy's sums become the sampling distribution (its total
    /// is [`sampling_total`](Self::sampling_total)); the building topology is
    /// refined by `config` (split where the share is above `rho`, down to
    /// `max_depth`; merge at or below it; quarter initialisation under old
    /// leaves); then the building sums are zeroed.
    ///
    /// If nothing (or only zeros) was collected, there is nothing to learn
    /// from: the sampling copy and the building topology are kept as they
    /// are (a fresh tree stays uniform, a trained one keeps its last
    /// distribution). This differs from PPG, where an empty iteration makes
    /// the distribution uniform.
    pub fn refine(&mut self, config: &QuadtreeConfig) {
        self.refine_within(config, None);
    }

    /// [`DirectionalTree::refine`] with at most `max_nodes` nodes (at
    /// least 1) in the new building topology: while it would have more,
    /// it is rebuilt with `rho` doubled. Spatial structures use it to keep
    /// their quadtrees within a memory budget.
    pub(crate) fn refine_within(&mut self, config: &QuadtreeConfig, max_nodes: Option<usize>) {
        let total = self.building_total();
        if !(total > 0.0 && total.is_finite()) {
            self.sums.clear();
            return;
        }
        let sums = subtree_sums(&self.links, &self.sums);
        self.nodes = sampling_nodes(&self.links, &sums);
        self.sampling_total = total;
        self.sampling_depth = self.building_depth;
        let mut rho = config.effective_rho();
        let mut refined = refine_topology(&self.links, &sums, total, rho, config);
        while max_nodes.is_some_and(|cap| refined.links.len() > cap.max(1)) && rho < 1.0 {
            rho = (2.0 * rho).min(1.0);
            refined = refine_topology(&self.links, &sums, total, rho, config);
        }
        self.sums.reset(4 * refined.links.len());
        self.links = refined.links;
        self.links.shrink_to_fit();
        self.building_depth = refined.depth;
    }

    /// What [`DirectionalTree::refine`] (which this does not change) will
    /// leave: the heap bytes it cannot choose (the sampling copy, which
    /// takes the current building topology), the nodes of the new building
    /// topology, and the bytes each of those costs.
    pub(crate) fn growth(&self, config: &QuadtreeConfig) -> Growth {
        let per_node = core::mem::size_of::<Link>() + 4 * self.sums.bytes_per_sum();
        let total = self.building_total();
        if !(total > 0.0 && total.is_finite()) {
            // Kept as it is.
            let nodes = self.links.len();
            return Growth {
                fixed: self.bytes() - core::mem::size_of::<Self>() - nodes * per_node,
                nodes,
                per_node,
            };
        }
        let sums = subtree_sums(&self.links, &self.sums);
        let rho = config.effective_rho();
        Growth {
            fixed: self.links.len() * NODE_BYTES,
            nodes: refine_topology(&self.links, &sums, total, rho, config)
                .links
                .len(),
            per_node,
        }
    }
}

/// The sampling copy for topology `links` and consistent sums `s`: each
/// node's quadrant shares of its own total (even shares for a node that got
/// nothing).
fn sampling_nodes(links: &[Link], s: &[f64]) -> Vec<Node> {
    links
        .iter()
        .enumerate()
        .map(|(n, &link)| {
            let t = node_total(s, n);
            let probs = if t > 0.0 {
                core::array::from_fn(|q| (s[4 * n + q] / t) as f32)
            } else {
                [0.25; 4]
            };
            Node { probs, link }
        })
        .collect()
}

/// PPG's split-and-merge of the topology `links` with consistent sums `s`
/// whose total is `total`.
pub(crate) fn refine_topology(
    links: &[Link],
    s: &[f64],
    total: f64,
    rho: f64,
    config: &QuadtreeConfig,
) -> Refined {
    let max_depth = config.effective_max_depth();
    // Node i of the new topology comes from queue[i]; children are appended
    // as their parent is processed, so siblings are contiguous.
    let mut queue: Vec<(Source, u32)> = Vec::with_capacity(links.len());
    queue.push((Source::Old(0), 1));
    let mut out = Vec::with_capacity(links.len());
    #[cfg(test)]
    let mut new_sums = Vec::with_capacity(4 * links.len());
    let mut depth = 1;
    let mut i = 0;
    while i < queue.len() {
        let (source, level) = queue[i];
        let (quads, old): ([f64; 4], [Option<usize>; 4]) = match source {
            Source::Old(n) => (
                core::array::from_fn(|q| s[4 * n + q]),
                core::array::from_fn(|q| links[n].child(q)),
            ),
            Source::Fresh(v) => ([0.25 * v; 4], [None; 4]),
        };
        let first = queue.len();
        let mut mask = 0;
        for q in 0..4 {
            if level < max_depth && quads[q] / total > rho {
                mask |= 1 << q;
                let child = match old[q] {
                    Some(c) => Source::Old(c),
                    None => Source::Fresh(quads[q]),
                };
                queue.push((child, level + 1));
                depth = depth.max(level + 1);
            }
        }
        let first = if mask == 0 { 0 } else { first as u32 };
        out.push(Link::new(first, mask));
        #[cfg(test)]
        new_sums.extend_from_slice(&quads);
        i += 1;
    }
    // The tree lives for the next iteration: hold no spare capacity.
    out.shrink_to_fit();
    Refined {
        links: out,
        #[cfg(test)]
        sums: new_sums,
        depth,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cfg(rho: f32, max_depth: u32) -> QuadtreeConfig {
        QuadtreeConfig { rho, max_depth }
    }

    #[test]
    fn one_bright_leaf_splits_by_quarters() {
        let links = [Link::LEAF];
        let s = [0.0, 0.0, 8.0, 0.0];
        let r = refine_topology(
            &links,
            &s,
            8.0,
            cfg(0.01, 20).effective_rho(),
            &cfg(0.01, 20),
        );
        // 1 -> 1/4 -> 1/16 -> 1/64 > 0.01 -> 1/256: levels 2..5 under q 2.
        assert_eq!(r.links.len(), 1 + 1 + 4 + 16 + 64);
        assert_eq!(r.depth, 5);
        assert_eq!(r.links[0].child(2), Some(1));
        assert_eq!(r.sums[4..8], [2.0; 4]);
        let capped = refine_topology(&links, &s, 8.0, cfg(0.01, 3).effective_rho(), &cfg(0.01, 3));
        assert_eq!(capped.depth, 3);
        assert_eq!(capped.links.len(), 1 + 1 + 4);
    }

    #[test]
    fn splitting_preserves_power_and_merging_drops_subtrees() {
        // Root: quadrant 0 has a child node, quadrant 3 is a leaf.
        let links = [Link::new(1, 0b0001), Link::LEAF];
        let s = [
            0.5, 0.0, 0.0, 99.5, // root
            0.125, 0.125, 0.125, 0.125, // under quadrant 0
        ];
        let r = refine_topology(
            &links,
            &s,
            100.0,
            cfg(0.01, 20).effective_rho(),
            &cfg(0.01, 20),
        );
        // Quadrant 0 (share 0.005) merges; quadrant 3 splits.
        assert_eq!(r.links[0].child(0), None);
        assert!(r.links[0].child(3).is_some());
        // Every node's quadrants add up to its parent's quadrant, and the
        // leaves add up to the total.
        let mut leaves = 0.0;
        for (n, link) in r.links.iter().enumerate() {
            for q in 0..4 {
                match link.child(q) {
                    Some(c) => {
                        let t = node_total(&r.sums, c);
                        assert!((t - r.sums[4 * n + q]).abs() <= 1e-12 * t);
                    }
                    None => leaves += r.sums[4 * n + q],
                }
            }
        }
        assert!((leaves - 100.0).abs() < 1e-12);
    }

    #[test]
    fn children_are_contiguous_and_breadth_first() {
        let links = [Link::LEAF];
        let s = [1.0; 4];
        let r = refine_topology(
            &links,
            &s,
            4.0,
            cfg(0.01, 20).effective_rho(),
            &cfg(0.01, 20),
        );
        for (n, link) in r.links.iter().enumerate() {
            for q in 0..4 {
                if let Some(c) = link.child(q) {
                    assert!(c > n && c < r.links.len());
                }
            }
        }
        // Shares 1/4 -> 1/16 -> 1/64 -> 1/256: three levels below the root.
        assert_eq!(r.depth, 4);
        assert_eq!(r.links.len(), 1 + 4 + 16 + 64);
    }
}
