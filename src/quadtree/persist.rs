//! Saving and loading a [`DirectionalTree`] (both copies, the sums, the
//! uniform fraction), checked; merging two trees' sums.

use super::config::{MAX_DEPTH, MIN_UNIFORM_FRACTION};
use super::node::{Link, Node};
use super::tree::DirectionalTree;
use crate::math::{Accumulation, SumBuffer};
use crate::persist::{LoadError, Reader, Writer};
use alloc::vec;
use alloc::vec::Vec;

fn write_link(w: &mut Writer, l: Link) {
    let (first, mask) = l.raw();
    w.u32(first);
    w.u32(mask);
}

fn read_link(r: &mut Reader<'_>, field: &'static str) -> Result<Link, LoadError> {
    let first = r.u32(field)?;
    let at = r.offset();
    let mask = r.u32(field)?;
    if mask >= 16 {
        return Err(Reader::invalid(field, at));
    }
    Ok(Link::new(first, mask))
}

/// The depth (node levels) of the quadtree `links`, or `None` when they
/// are not one breadth-first tree: children after their parent, in range,
/// every node but the root the child of exactly one quadrant, at most
/// [`MAX_DEPTH`] levels.
fn topology_depth(links: &[Link]) -> Option<u32> {
    if links.is_empty() {
        return None;
    }
    let mut level = vec![0u32; links.len()];
    let mut parents = vec![0u8; links.len()];
    level[0] = 1;
    for (n, link) in links.iter().enumerate() {
        for q in 0..4 {
            if let Some(c) = link.child(q) {
                if c <= n || c >= links.len() {
                    return None;
                }
                parents[c] = parents[c].saturating_add(1);
                level[c] = level[n] + 1;
            }
        }
    }
    if parents[0] != 0 || parents[1..].iter().any(|&p| p != 1) {
        return None;
    }
    let depth = level.iter().copied().max()?;
    (level.iter().all(|&l| l > 0) && depth <= MAX_DEPTH).then_some(depth)
}

impl DirectionalTree {
    pub(crate) fn write(&self, w: &mut Writer) {
        w.len(self.nodes.len());
        for n in &self.nodes {
            for p in n.probs {
                w.f32(p);
            }
            write_link(w, n.link);
        }
        w.f64(self.sampling_total);
        w.len(self.links.len());
        for &l in &self.links {
            write_link(w, l);
        }
        self.sums.write(w);
        w.f64(self.uniform_fraction);
    }

    /// Reads a tree whose sums are in `mode`, checked: both copies are
    /// quadtrees, probabilities and totals finite and non-negative (each
    /// node's summing to a positive number), the uniform fraction in range.
    pub(crate) fn read(r: &mut Reader<'_>, mode: Accumulation) -> Result<Self, LoadError> {
        let at = r.offset();
        let count = r.len("quadtree: sampling nodes", 24)?;
        let mut nodes = Vec::with_capacity(count);
        for _ in 0..count {
            let mut probs = [0.0f32; 4];
            for p in &mut probs {
                *p = r.check("quadtree: probability", Reader::f32, |p| {
                    *p >= 0.0 && p.is_finite()
                })?;
            }
            let node_at = r.offset();
            if probs.iter().sum::<f32>() <= 0.0 {
                return Err(Reader::invalid("quadtree: probability", node_at));
            }
            nodes.push(Node {
                probs,
                link: read_link(r, "quadtree: sampling link")?,
            });
        }
        let sampling_links: Vec<Link> = nodes.iter().map(|n| n.link).collect();
        let sampling_depth = topology_depth(&sampling_links)
            .ok_or_else(|| Reader::invalid("quadtree: sampling nodes", at))?;
        let sampling_total = r.check("quadtree: sampling total", Reader::f64, |t| {
            *t >= 0.0 && t.is_finite()
        })?;
        let links_at = r.offset();
        let count = r.len("quadtree: building links", 8)?;
        let mut links = Vec::with_capacity(count);
        for _ in 0..count {
            links.push(read_link(r, "quadtree: building link")?);
        }
        let building_depth = topology_depth(&links)
            .ok_or_else(|| Reader::invalid("quadtree: building links", links_at))?;
        let sums = SumBuffer::read(r, "quadtree: sums", mode, 4 * links.len())?;
        let uniform_fraction = r.check("quadtree: uniform fraction", Reader::f64, |f| {
            (f64::from(MIN_UNIFORM_FRACTION)..=1.0).contains(f)
        })?;
        Ok(Self {
            nodes,
            sampling_total,
            sampling_depth,
            links,
            building_depth,
            sums,
            uniform_fraction,
        })
    }

    /// Zeroes the building sums (what was recorded since the last refine).
    pub(crate) fn clear_records(&mut self) {
        self.sums.clear();
    }

    /// Adds `other`'s building sums (same building topology) to this
    /// tree's; false, nothing changed, when the topologies differ.
    pub(crate) fn merge(&mut self, other: &Self) -> bool {
        self.links == other.links && self.sums.merge(&other.sums)
    }

    /// Whether `other` samples the same distribution and builds the same
    /// topology (what a merge requires).
    pub(crate) fn same_layout(&self, other: &Self) -> bool {
        self.links == other.links && self.nodes == other.nodes
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shared_children_are_refused_without_overflow() {
        // 300 nodes whose four quadrants all name node 300: one child
        // claimed 1,200 times (more than a u8 counts).
        let mut links = vec![Link::new(300, 0b1111); 300];
        links.extend([Link::LEAF; 4]);
        assert_eq!(topology_depth(&links), None);
        // A real tree: the root with two children, one with a child.
        let ok = [
            Link::new(1, 0b0101),
            Link::new(3, 0b0001),
            Link::LEAF,
            Link::LEAF,
        ];
        assert_eq!(topology_depth(&ok), Some(3));
    }
}
