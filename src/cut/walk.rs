//! The walk table: the light tree re-laid out for the GLT's descent.
//!
//! Sampling a cut walks the light tree from its root to a leaf, and below
//! the cut it needs nothing of a node but its power split and where its
//! children are. Reading those from the light tree's 32-byte nodes costs
//! two cache lines per level (a right child lies far from its parent) plus
//! the split table's; profiles of the `render` example put the walk at 30%
//! of a frame, most of it waiting on those loads. The walk table keeps the
//! two numbers in 8 bytes per node and stores siblings side by side in one
//! 16-byte pair, so a level costs one aligned load that holds both
//! children, and pairs are laid out depth-first so a subtree's pairs are
//! near each other. On `ring` (24,576 emitters, `pt-glt`, 32 spp, one
//! thread) the time in the walk fell from 2.9-3.2 s to 1.8-2.3 s (perf
//! samples, two runs each; the command is in docs/benchmarks.md, "The walk
//! table").
//!
//! `pmf` does not use it: it knows the emitter's path, so it reads the
//! split table by node, loads that do not wait on each other.

use crate::light_tree::LightHierarchy;
use alloc::vec;
use alloc::vec::Vec;

/// Marks a leaf's link: the low 31 bits are its emitter.
const LEAF: u32 = 1 << 31;

/// A leaf whose emitter cannot be stored (an id of 2^31 or more, which no
/// hierarchy with `u32` node indices can have): never chosen.
const BAD_LEAF: u32 = u32::MAX;

/// One light-tree node as the walk sees it.
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C)]
pub(crate) struct WalkNode {
    /// The node's split-table entry (see `decode_split`); NaN for leaves.
    pub(crate) split: f32,
    /// An inner node's children pair, or `LEAF | emitter`.
    link: u32,
}

impl WalkNode {
    /// The index of the pair holding this node's children; `None` for a
    /// leaf.
    #[inline(always)]
    pub(crate) fn children(self) -> Option<u32> {
        (self.link & LEAF == 0).then_some(self.link)
    }

    /// The link word: the children pair, or `1 << 31` | the emitter of a
    /// leaf (`u32::MAX` for an unusable one).
    #[inline(always)]
    pub(crate) fn link(self) -> u32 {
        self.link
    }

    /// A leaf's emitter; `None` for an inner node or an unusable leaf.
    #[inline(always)]
    pub(crate) fn emitter(self) -> Option<u32> {
        (self.link & LEAF != 0 && self.link != BAD_LEAF).then_some(self.link & !LEAF)
    }

    /// The pair to read ahead for this node: its children's, or pair 0
    /// (always present, harmless to read) for a leaf. Branch-free, since
    /// whether a node is a leaf is not predictable.
    #[inline(always)]
    fn prefetch_index(self) -> usize {
        let inner = (self.link & LEAF == 0) as u32;
        (self.link * inner) as usize
    }
}

/// Two siblings, left then right, in one aligned 16-byte load.
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C, align(16))]
pub(crate) struct WalkPair(pub(crate) [WalkNode; 2]);

const _: () = assert!(core::mem::size_of::<WalkPair>() == 16);

/// The light tree as the walk reads it: pair 0 holds the root (its second
/// entry is unused); every other pair holds the two children of one inner
/// node.
#[derive(Clone, Debug)]
pub(crate) struct WalkTable {
    pairs: Vec<WalkPair>,
}

/// Visits every inner node of `tree` depth-first, left before right, as
/// `visit(k, (parent pair, side), node, children)`: `k` is the pair index
/// the node's children get (1, 2, ... in visiting order) and `(parent
/// pair, side)` where the node itself sits (the root at `(0, 0)`).
fn visit_pairs<H: LightHierarchy + ?Sized>(
    tree: &H,
    mut visit: impl FnMut(usize, (usize, usize), u32, [u32; 2]),
) {
    let Some(root) = tree.root() else {
        return;
    };
    let mut next = 1usize;
    let mut stack = vec![(root, 0usize, 0usize)];
    while let Some((node, pair, side)) = stack.pop() {
        let Some([l, r]) = tree.children(node) else {
            continue;
        };
        let k = next;
        next += 1;
        visit(k, (pair, side), node, [l, r]);
        // Left on top: its subtree's pairs come first, depth-first.
        stack.push((r, k, 1));
        stack.push((l, k, 0));
    }
}

impl WalkTable {
    /// Lays out `tree` with `split(node)` as each inner node's split entry.
    /// O(nodes), iterative (any depth).
    pub(crate) fn new<H: LightHierarchy + ?Sized>(tree: &H, split: impl Fn(u32) -> f32) -> Self {
        let leaf = |n: u32| WalkNode {
            split: f32::NAN,
            link: match tree.emitter(n) {
                Some(e) if e < LEAF - 1 => LEAF | e,
                _ => BAD_LEAF,
            },
        };
        let unused = WalkNode {
            split: f32::NAN,
            link: BAD_LEAF,
        };
        let Some(root) = tree.root() else {
            return Self { pairs: Vec::new() };
        };
        let mut pairs = Vec::with_capacity(tree.node_count() / 2 + 1);
        pairs.push(WalkPair([leaf(root), unused]));
        visit_pairs(tree, |k, (pair, side), node, [l, r]| {
            pairs[pair].0[side] = WalkNode {
                split: split(node),
                link: k as u32,
            };
            pairs.push(WalkPair([leaf(l), leaf(r)]));
        });
        Self { pairs }
    }

    /// The light-tree nodes of every pair, in the table's order (`None`
    /// for the root's placeholder pair 0): what tables laid out like this
    /// one are built from.
    pub(crate) fn pair_nodes<H: LightHierarchy + ?Sized>(tree: &H) -> Vec<Option<[u32; 2]>> {
        let mut nodes = Vec::new();
        if tree.root().is_some() {
            nodes.push(None);
            visit_pairs(tree, |_, _, _, children| nodes.push(Some(children)));
        }
        nodes
    }

    /// Every pair, pair 0 (the root's) first.
    pub(crate) fn pairs(&self) -> &[WalkPair] {
        &self.pairs
    }

    /// The root's entry; `None` for an empty tree.
    #[inline(always)]
    pub(crate) fn root(&self) -> Option<WalkNode> {
        Some(self.pairs.first()?.0[0])
    }

    /// The pair at `index` (one returned by [`WalkNode::children`]).
    #[inline(always)]
    pub(crate) fn pair(&self, index: u32) -> WalkPair {
        self.pairs[index as usize]
    }

    /// Reads, ahead of need, the children pairs of both nodes of `pair`;
    /// the walk picks the one it descends into once its choice is made.
    /// These loads do not depend on the random number, so they overlap
    /// with this level's arithmetic instead of following it.
    #[inline(always)]
    pub(crate) fn grandchildren(&self, pair: WalkPair) -> [WalkPair; 2] {
        let at = |n: WalkNode| self.pairs[n.prefetch_index()];
        [at(pair.0[0]), at(pair.0[1])]
    }

    /// Heap bytes.
    pub(crate) fn bytes(&self) -> usize {
        self.pairs.len() * core::mem::size_of::<WalkPair>()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::emitter::Emitter;
    use crate::light_tree::{BuildHeuristic, LightTree};
    use glam::Vec3;

    /// Every walk entry stands for the light-tree node it replaces: same
    /// children in the same order, same split, same emitter at the leaves;
    /// every pair but the root's is reached exactly once.
    fn check(tree: &LightTree) {
        let split = |n: u32| n as f32; // a tag that names the node
        let walk = WalkTable::new(tree, split);
        let nodes = WalkTable::pair_nodes(tree);
        assert_eq!(nodes.len(), walk.pairs.len());
        let Some(root) = tree.root() else {
            assert_eq!(walk.root(), None);
            assert_eq!(walk.bytes(), 0);
            return;
        };
        let mut seen = vec![false; walk.pairs.len()];
        let mut stack = vec![(root, walk.root().unwrap())];
        let mut leaves = 0;
        while let Some((node, entry)) = stack.pop() {
            match tree.children(node) {
                Some([l, r]) => {
                    assert_eq!(entry.split, node as f32);
                    let k = entry.children().expect("inner node");
                    assert_eq!(nodes[k as usize], Some([l, r]));
                    assert!(!core::mem::replace(&mut seen[k as usize], true));
                    let pair = walk.pair(k);
                    stack.push((l, pair.0[0]));
                    stack.push((r, pair.0[1]));
                }
                None => {
                    assert_eq!(entry.children(), None);
                    assert_eq!(entry.emitter(), tree.emitter(node));
                    leaves += 1;
                }
            }
        }
        assert_eq!(leaves, tree.emitter_count());
        assert!(seen.iter().skip(1).all(|&s| s));
        assert_eq!(walk.pairs.len(), tree.emitter_count());
    }

    #[test]
    fn walk_table_mirrors_the_light_tree() {
        let mut state = 0x9e37_79b9_u32;
        let mut next = move || {
            state ^= state << 13;
            state ^= state >> 17;
            state ^= state << 5;
            (state >> 8) as f32 / (1u32 << 24) as f32
        };
        for n in [0usize, 1, 2, 3, 7, 100, 1000] {
            let lights: Vec<Emitter> = (0..n)
                .map(|_| Emitter::point(Vec3::new(next(), next(), next()) * 10.0, next()))
                .collect();
            check(&LightTree::build(&lights, BuildHeuristic::default()).unwrap());
        }
        // A chain deeper than 64 levels (powers halving along one line).
        let chain: Vec<Emitter> = (0..100)
            .map(|i| Emitter::point(Vec3::new(i as f32, 0.0, 0.0), 0.5f32.powi(i)))
            .collect();
        let tree = LightTree::build(&chain, BuildHeuristic::default()).unwrap();
        check(&tree);
    }
}
