//! [`GuidingCut`]: the learned state of one spatial cell, its construction,
//! inspection and memory.

use super::config::CutConfig;
use super::cut_node::{CutNode, Slot};
use crate::error::{ConfigError, unit};
use crate::light_tree::LightHierarchy;
use crate::math::{Counter, Side, SumBuffer};
use alloc::boxed::Box;
use alloc::vec;
use alloc::vec::Vec;
use glam::Vec3;

/// One cell's guiding cut: a weighted sub-tree of the global light tree from
/// its root down to the cut (the paper's Figure 2, right), in two copies.
///
/// - The *sampled* copy is `Vec<CutNode>` in depth-first pre-order (a child
///   always has a larger index than its parent), root first. An empty vector
///   means the cut ends at the light tree's root: the whole tree is one
///   cluster (a single-light scene, or `sigma >= 1`).
/// - The *accumulating* copy is a set of thread-safe sums (`src/math/sum.rs`), one per slot (sum
///   `2 i + side` for slot `side` of node `i`; a single sum for the root
///   cluster of an empty cut) and, last, one sum per unbounded light.
///
/// A cut is used through the [`CutRules`](super::CutRules) of its
/// light tree: [`CutRules::new_cut`](super::CutRules::new_cut) makes
/// one, [`CutRules::refine`](super::CutRules::refine) rebuilds the
/// sampled copy from the sums and zeroes them. Sampling, pmf and recording
/// take `&GuidingCut`; the sums take concurrent adds without locks.
#[derive(Clone, Debug)]
pub struct GuidingCut {
    pub(super) nodes: Vec<CutNode>,
    pub(super) sums: SumBuffer,
    /// Learned probability of each unbounded light among everything the
    /// cell collected (before the mixture with the prior); empty without
    /// unbounded lights.
    pub(super) unbounded: Box<[f32]>,
    /// Non-zero records recorded since the last rebuild (see
    /// [`CutConfig::min_records`]).
    pub(super) recorded: Counter,
    /// Weighted sums of the positions records came from (see `anchor_sums`),
    /// since the last rebuild: the anchor of
    /// [`Modulation::Importance`](super::Modulation::Importance). Empty
    /// (no sums) without modulation.
    pub(super) anchor: SumBuffer,
    /// Whether the sampled copy's `p_left` are learned factor ratios over
    /// the importance at an anchor (set by a rebuild that had one), so
    /// sampling modulates them by the importance at the shading point;
    /// else they are plain learned probabilities.
    pub(super) modulated: bool,
    /// The learned visibility of each slot, then of each unbounded light
    /// (indexed as the sums), in `[1/64, 1]`; empty unless
    /// [`CutConfig::visibility`](super::CutConfig::visibility).
    pub(super) visibility: Box<[f32]>,
    /// Per slot and unbounded light, the shadowed and the unshadowed
    /// values of the next-event records since the last rebuild (sums
    /// `2 i` and `2 i + 1`); empty unless visibility is learned.
    pub(super) seen: SumBuffer,
    /// Visibility records since the last rebuild.
    pub(super) seen_records: Counter,
    /// How much of what the sampled copy learned came from shading points
    /// inside the cut's own cell, in `[0, 1]`: 1 for a cut rebuilt from
    /// its cell's own records, less for a half of a cell that split, by
    /// its share of the records its parent learned from (see
    /// [`GuidingCut::confidence`]).
    pub(crate) confidence: f32,
}

/// Why [`GuidingCut::check`] rejected a cut.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub enum CutError {
    /// A slot points at a cut node that does not exist.
    IndexOutOfRange {
        /// The node holding the slot.
        node: u32,
    },
    /// A slot points at a cut node at or before its parent (the nodes are not
    /// in pre-order, or a node is reached twice).
    NotPreOrder {
        /// The node holding the slot.
        node: u32,
    },
    /// A cut node is not reached from the root.
    Unreachable {
        /// The node.
        node: u32,
    },
    /// A cut node stands for a light-tree leaf (or a node that does not
    /// exist), so a root-to-leaf path would end inside the cut.
    NotInner {
        /// The node.
        node: u32,
    },
    /// An end slot records another light-tree node than the one it stands
    /// for.
    WrongEnd {
        /// The node holding the slot.
        node: u32,
    },
    /// A learned probability is NaN or outside `[0, 1]`.
    BadProbability {
        /// The node.
        node: u32,
    },
    /// The accumulating copy does not have one sum per slot plus one.
    SumCount,
    /// The light tree has no root but the cut has nodes.
    NoTree,
}

/// Bytes one cell's cut uses, by part.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct CutMemory {
    /// Number of cut nodes in the sampled copy.
    pub nodes: usize,
    /// Bytes of the sampled copy: its nodes ([`CutNode::BYTES`] each) and
    /// the unbounded lights' learned fractions (4 each).
    pub node_bytes: usize,
    /// Bytes of the accumulating copy's sums.
    pub sum_bytes: usize,
    /// Bytes of the [`GuidingCut`] value itself (vector headers, fraction).
    pub inline_bytes: usize,
}

impl CutMemory {
    /// Everything together.
    pub fn total(&self) -> usize {
        self.node_bytes + self.sum_bytes + self.inline_bytes
    }
}

impl core::ops::AddAssign for CutMemory {
    fn add_assign(&mut self, o: Self) {
        self.nodes += o.nodes;
        self.node_bytes += o.node_bytes;
        self.sum_bytes += o.sum_bytes;
        self.inline_bytes += o.inline_bytes;
    }
}

impl core::iter::Sum for CutMemory {
    fn sum<I: Iterator<Item = Self>>(iter: I) -> Self {
        iter.fold(Self::default(), |mut a, b| {
            a += b;
            a
        })
    }
}

impl GuidingCut {
    /// The initial cut (see [`CutRules::new_cut`](super::CutRules::new_cut)).
    pub(crate) fn new<H: LightHierarchy + ?Sized>(tree: &H, config: &CutConfig) -> Self {
        // Modulated, a cut that has learned nothing has equal factors on
        // both sides, so it samples by the importance at the shading point
        // (a dark side still gets nothing); else by the power prior.
        let modulated = config.modulation == super::Modulation::Importance;
        let nodes = match tree.root().and_then(|r| tree.children(r)) {
            Some([l, r]) => {
                let (el, er) = (tree.power(l) as f64, tree.power(r) as f64);
                let (el, er) = if modulated && el > 0.0 && er > 0.0 {
                    (1.0, 1.0)
                } else {
                    (el, er)
                };
                let p = crate::math::Descent::probabilities(el, er).map_or(0.5, |(pl, _)| pl);
                vec![CutNode::new(p as f32, [Slot::End(l), Slot::End(r)])]
            }
            None => Vec::new(),
        };
        let k = config.unbounded.count;
        let sums = SumBuffer::new(sum_count(nodes.len(), k), config.accumulation);
        let nodes_len = nodes.len();
        Self {
            nodes,
            sums,
            // Before any data, each unbounded light has its prior share.
            unbounded: vec![config.unbounded.each() as f32; k as usize].into_boxed_slice(),
            recorded: Counter::new(),
            anchor: SumBuffer::new(anchor_sums(config), config.accumulation),
            modulated,
            visibility: vec![1.0; visibility_slots(nodes_len, config)].into_boxed_slice(),
            seen: SumBuffer::new(2 * visibility_slots(nodes_len, config), config.accumulation),
            seen_records: Counter::new(),
            confidence: 1.0,
        }
    }

    /// The sampled copy's nodes, root first, in pre-order.
    #[inline]
    pub fn nodes(&self) -> &[CutNode] {
        &self.nodes
    }

    /// How much of what the cut learned comes from its own cell, in
    /// `[0, 1]`. Sampling trusts the learned distribution by this much
    /// and the prior for the rest: the defensive weight becomes
    /// `1 - (1 - alpha) confidence`, so a cut that learned
    /// nothing of its own samples exactly as the prior does.
    ///
    /// A cut rebuilt from its cell's records has confidence 1. When a
    /// cell splits, each half inherits the cut its parent learned, from
    /// records that may have fallen mostly in one half; a half whose share
    /// `s` of those records is below a twentieth gets its parent's
    /// confidence times `20 s` (a tile-order renderer that has rendered
    /// only part of a cell leaves the other half at the prior, not at
    /// another region's choice). The crate's spatial structures set it
    /// ([`Glt`](crate::Glt), [`GuidingField`](crate::GuidingField));
    /// a cut used on its own keeps 1 unless
    /// [`GuidingCut::set_confidence`] says otherwise.
    #[inline]
    pub fn confidence(&self) -> f32 {
        self.confidence
    }

    /// Sets [`GuidingCut::confidence`], for a spatial structure of one's
    /// own that copies a cut into a region the cut's records did not come
    /// from (the crate's structures set it themselves). Refuses a value
    /// outside `[0, 1]` (NaN included) and keeps the old one.
    pub fn set_confidence(&mut self, confidence: f32) -> Result<(), ConfigError> {
        unit("GuidingCut::confidence", f64::from(confidence))?;
        self.confidence = confidence;
        Ok(())
    }

    /// The learned fraction of each unbounded light (before the mixture
    /// with its prior), in the order of [`crate::LightId::Unbounded`];
    /// empty without unbounded lights.
    #[inline]
    pub fn unbounded_fractions(&self) -> &[f32] {
        &self.unbounded
    }

    /// What has been recorded since the last refinement: the emitters' total
    /// and the unbounded lights' total.
    pub fn accumulated(&self) -> (f64, f64) {
        let n = self.sums.len();
        let first = self.first_unbounded_sum();
        let total = |r: core::ops::Range<usize>| r.map(|i| self.sums.get(i)).sum();
        (total(0..first), total(first..n))
    }

    /// The light-tree nodes where the cut ends (the clusters), each with the
    /// learned probability of reaching it through the cut, left to right.
    /// An empty cut gives the root with probability 1.
    pub fn clusters<H: LightHierarchy + ?Sized>(&self, tree: &H) -> Vec<(u32, f64)> {
        let mut out = Vec::new();
        let Some(root) = tree.root() else {
            return out;
        };
        if self.nodes.is_empty() {
            out.push((root, 1.0));
            return out;
        }
        // (cut node, light node, probability); right pushed first.
        let mut stack = vec![(0u32, root, 1.0f64)];
        while let Some((i, light, p)) = stack.pop() {
            let (Some(node), Some(children)) = (self.nodes.get(i as usize), tree.children(light))
            else {
                continue;
            };
            let (pl, pr) = node.probabilities();
            for side in [Side::Right, Side::Left] {
                let q = p * if side == Side::Left { pl } else { pr };
                let c = children[side.index()];
                match node.child(side) {
                    Some(j) => stack.push((j, c, q)),
                    None => out.push((c, q)),
                }
            }
        }
        out
    }

    /// Checks that the cut is a valid cut of `tree`: every cut node is
    /// reached exactly once from the root, in pre-order, stands for an
    /// inner light-tree node, end slots record the right light node, the
    /// probabilities lie in `[0, 1]` and there is one sum per slot plus one.
    /// Then each root-to-leaf path of the light tree crosses exactly one
    /// slot that ends the cut.
    pub fn check<H: LightHierarchy + ?Sized>(&self, tree: &H) -> Result<(), CutError> {
        if self.sums.len() != sum_count(self.nodes.len(), self.unbounded.len() as u32) {
            return Err(CutError::SumCount);
        }
        if self.nodes.is_empty() {
            return Ok(());
        }
        let root = tree.root().ok_or(CutError::NoTree)?;
        let mut seen = vec![false; self.nodes.len()];
        let mut stack = vec![(0u32, root)];
        while let Some((i, light)) = stack.pop() {
            let node = &self.nodes[i as usize];
            if seen[i as usize] {
                return Err(CutError::NotPreOrder { node: i });
            }
            seen[i as usize] = true;
            let children = tree.children(light).ok_or(CutError::NotInner { node: i })?;
            let p = node.p_left();
            if !(0.0..=1.0).contains(&p) {
                return Err(CutError::BadProbability { node: i });
            }
            for side in [Side::Left, Side::Right] {
                let c = children[side.index()];
                match node.slot(side) {
                    Slot::Child(j) => {
                        if j as usize >= self.nodes.len() {
                            return Err(CutError::IndexOutOfRange { node: i });
                        }
                        if j <= i {
                            return Err(CutError::NotPreOrder { node: i });
                        }
                        stack.push((j, c));
                    }
                    Slot::End(n) => {
                        if c < 1 << 31 && n != c {
                            return Err(CutError::WrongEnd { node: i });
                        }
                    }
                }
            }
        }
        match seen.iter().position(|s| !s) {
            Some(i) => Err(CutError::Unreachable { node: i as u32 }),
            None => Ok(()),
        }
    }

    /// Bytes this cut uses, by part (counted on lengths).
    pub fn memory(&self) -> CutMemory {
        CutMemory {
            nodes: self.nodes.len(),
            node_bytes: self.nodes.len() * CutNode::BYTES
                + (self.unbounded.len() + self.visibility.len()) * 4,
            sum_bytes: self.sums.bytes() + self.anchor.bytes() + self.seen.bytes(),
            inline_bytes: core::mem::size_of::<Self>(),
        }
    }

    /// Heap bytes (nodes, sums and the unbounded lights' fractions),
    /// without the value itself.
    pub fn heap_bytes(&self) -> usize {
        self.nodes.len() * CutNode::BYTES
            + self.sums.bytes()
            + self.anchor.bytes()
            + self.seen.bytes()
            + (self.unbounded.len() + self.visibility.len()) * 4
    }

    /// The learned visibility of each slot, then of each unbounded light,
    /// in the order of the sums (see the type's docs); empty unless
    /// [`CutConfig::visibility`](super::CutConfig::visibility).
    pub fn visibility(&self) -> &[f32] {
        &self.visibility
    }

    /// Adds the position `p` a record came from, with `weight` (its share
    /// of the record after filtering), to the anchor's sums. Non-finite
    /// positions and cuts without anchor sums are ignored.
    #[inline]
    pub(crate) fn record_position(&self, p: Vec3, weight: f32) {
        if self.anchor.is_empty() || !p.is_finite() || weight.is_nan() || weight <= 0.0 {
            return;
        }
        // The sums take non-negative values: each coordinate's positive and
        // negative parts go to sums of their own.
        for (i, x) in p.to_array().into_iter().enumerate() {
            let v = x * weight;
            if v >= 0.0 {
                self.anchor.add(i, v);
            } else {
                self.anchor.add(3 + i, -v);
            }
        }
        self.anchor.add(6, weight);
    }

    /// The mean position the records since the last rebuild came from;
    /// `None` when none carried a position.
    pub fn anchor(&self) -> Option<Vec3> {
        if self.anchor.is_empty() {
            return None;
        }
        let w = self.anchor.get(6);
        if w.is_nan() || w <= 0.0 {
            return None;
        }
        let c = |i| ((self.anchor.get(i) - self.anchor.get(3 + i)) / w) as f32;
        let a = Vec3::new(c(0), c(1), c(2));
        a.is_finite().then_some(a)
    }

    /// Index of the first unbounded light's sum (the number of cluster
    /// sums).
    #[inline]
    pub(super) fn first_unbounded_sum(&self) -> usize {
        self.sums.len() - self.unbounded.len()
    }
}

/// Sums of the anchor position when the cut's probabilities are
/// modulated (the positive and negative parts of x, y, z and the weight),
/// none otherwise.
#[inline]
pub(super) fn anchor_sums(config: &CutConfig) -> usize {
    match config.modulation {
        super::Modulation::None => 0,
        super::Modulation::Importance => 7,
    }
}

/// The smallest learned visibility: learning alone never takes a cluster's
/// resampling target to 0.
pub(crate) const MIN_VISIBILITY: f32 = 1.0 / 64.0;

/// Learned visibilities for a cut of `nodes` nodes: one per sum when
/// visibility is learned, none otherwise.
pub(super) fn visibility_slots(nodes: usize, config: &CutConfig) -> usize {
    if config.visibility {
        sum_count(nodes, config.unbounded.count)
    } else {
        0
    }
}

/// Sums for a cut of `nodes` nodes: one per slot (one for the root cluster
/// of an empty cut) plus one per unbounded light.
#[inline]
pub(super) fn sum_count(nodes: usize, unbounded: u32) -> usize {
    (2 * nodes).max(1) + unbounded as usize
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::emitter::Emitter;
    use crate::light_tree::{BuildHeuristic, LightTree};

    /// `check` names each way a cut can be broken, at the node that breaks
    /// it.
    #[test]
    fn check_names_each_broken_cut() {
        let two = vec![
            Emitter::point(Vec3::ZERO, 1.0),
            Emitter::point(Vec3::X, 2.0),
        ];
        let tree = LightTree::build(&two, BuildHeuristic::Sarh).unwrap();
        let config = CutConfig::default();
        let [l, r] = tree.children(tree.root().unwrap()).unwrap();
        let cut = |nodes: Vec<CutNode>| {
            let mut c = GuidingCut::new(&tree, &config);
            c.sums = SumBuffer::new(sum_count(nodes.len(), 0), config.accumulation);
            c.nodes = nodes;
            c
        };
        let node = |p: f32, a: Slot, b: Slot| CutNode::new(p, [a, b]);
        let ends = node(0.5, Slot::End(l), Slot::End(r));
        assert_eq!(GuidingCut::new(&tree, &config).check(&tree), Ok(()));
        assert_eq!(cut(vec![ends]).check(&tree), Ok(()));
        let broken = [
            (
                vec![node(0.5, Slot::End(r), Slot::End(l))],
                CutError::WrongEnd { node: 0 },
            ),
            (
                vec![node(1.5, Slot::End(l), Slot::End(r))],
                CutError::BadProbability { node: 0 },
            ),
            (
                vec![node(f32::NAN, Slot::End(l), Slot::End(r))],
                CutError::BadProbability { node: 0 },
            ),
            (
                vec![node(0.5, Slot::Child(3), Slot::End(r))],
                CutError::IndexOutOfRange { node: 0 },
            ),
            (
                vec![node(0.5, Slot::Child(0), Slot::End(r))],
                CutError::NotPreOrder { node: 0 },
            ),
            (vec![ends, ends], CutError::Unreachable { node: 1 }),
            // The left child is a leaf: a cut node cannot stand for it.
            (
                vec![node(0.5, Slot::Child(1), Slot::End(r)), ends],
                CutError::NotInner { node: 1 },
            ),
        ];
        for (nodes, want) in broken {
            assert_eq!(cut(nodes).check(&tree), Err(want));
        }
        let mut short = cut(vec![ends]);
        short.sums = SumBuffer::new(1, config.accumulation);
        assert_eq!(short.check(&tree), Err(CutError::SumCount));
        let none: Vec<Emitter> = Vec::new();
        let empty = LightTree::build(&none, BuildHeuristic::Sarh).unwrap();
        assert_eq!(cut(vec![ends]).check(&empty), Err(CutError::NoTree));
    }
}
