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
//! `pmf` follows it too, by the emitter's [`PathCode`] (its sides from the
//! root in one word), so it reads the same split entries `sample` read.

use crate::light_tree::LightHierarchy;
use crate::math::Side;
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
/// node. Beside it, each emitter's way down as a [`PathCode`].
#[derive(Clone, Debug)]
pub(crate) struct WalkTable {
    pairs: Vec<WalkPair>,
    /// By emitter id: its path code (0 where the emitter is deeper than
    /// [`PathCode::MAX_DEPTH`] or not in the tree).
    codes: Vec<u64>,
}

/// An emitter's way from the root to its leaf in one word: bit `l` is the
/// side taken at depth `l` (1 right), above the last level a 1 marks the
/// depth. A pmf and a record follow it (down the walk table, down the
/// cut) instead of rebuilding the path from parent links (two dependent
/// loads a level, far apart): callgrind on trained `city` cuts, the pmf of
/// a BSDF-hit light 7,316 -> 6,306 instructions, a record 1,559 -> 621
/// (docs/benchmarks.md, "The light choice's cost"). 8 bytes per emitter.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct PathCode(u64);

impl PathCode {
    /// The deepest leaf a code can name (deeper ones take the parent links).
    pub(crate) const MAX_DEPTH: u32 = 63;

    /// The number of steps from the root to the leaf.
    #[inline(always)]
    pub(crate) fn depth(self) -> u32 {
        63 - self.0.leading_zeros()
    }

    /// The side taken at depth `level` (below [`PathCode::depth`]).
    #[inline(always)]
    pub(crate) fn side(self, level: u32) -> Side {
        if self.0 >> level & 1 == 0 {
            Side::Left
        } else {
            Side::Right
        }
    }
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
            return Self {
                pairs: Vec::new(),
                codes: Vec::new(),
            };
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
        let codes = path_codes(&pairs, tree.emitter_count());
        Self { pairs, codes }
    }

    /// The path code of `emitter`; `None` out of range or deeper than
    /// [`PathCode::MAX_DEPTH`].
    #[inline(always)]
    pub(crate) fn code(&self, emitter: u32) -> Option<PathCode> {
        let code = *self.codes.get(emitter as usize)?;
        (code != 0).then_some(PathCode(code))
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
            + self.codes.len() * core::mem::size_of::<u64>()
    }
}

/// Every emitter's path code, by emitter id (`emitters` of them), from the
/// laid-out `pairs`; iterative (any depth; deeper than
/// [`PathCode::MAX_DEPTH`] gets 0).
fn path_codes(pairs: &[WalkPair], emitters: usize) -> Vec<u64> {
    let mut codes = vec![0u64; emitters];
    let Some(root) = pairs.first().map(|p| p.0[0]) else {
        return codes;
    };
    let mut stack = vec![(root, 0u32, 0u64)];
    while let Some((node, depth, bits)) = stack.pop() {
        match node.children() {
            Some(k) => {
                if depth < PathCode::MAX_DEPTH {
                    let [l, r] = pairs[k as usize].0;
                    stack.push((l, depth + 1, bits));
                    stack.push((r, depth + 1, bits | 1 << depth));
                }
            }
            None => {
                if let Some(c) = node.emitter().and_then(|e| codes.get_mut(e as usize)) {
                    *c = 1 << depth | bits;
                }
            }
        }
    }
    codes
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
        // Every emitter's code leads down the table to its own leaf by the
        // light tree's path, sides and length alike; one deeper than a
        // code holds has none.
        let mut coded = 0;
        for e in 0..tree.emitter_count() as u32 {
            let path = tree.path(e).expect("every emitter has a path");
            let Some(code) = walk.code(e) else {
                assert!(
                    path.steps().len() > PathCode::MAX_DEPTH as usize,
                    "emitter {e}"
                );
                continue;
            };
            assert_eq!(code.depth() as usize, path.steps().len());
            let mut at = walk.root().unwrap();
            for (level, &(_, side)) in path.steps().iter().enumerate() {
                assert_eq!(code.side(level as u32), side);
                at = walk.pair(at.children().unwrap()).0[side.index()];
            }
            assert_eq!(at.emitter(), Some(e));
            coded += 1;
        }
        assert!(coded > 0 || tree.emitter_count() == 0);
        assert_eq!(walk.code(tree.emitter_count() as u32), None);
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
        // A chain deeper than 64 levels: boxes and powers halving towards
        // the origin (powers halving alone build only 7 levels), so codes
        // end at 63 levels and deeper leaves take the parent links.
        let chain: Vec<Emitter> = (0..100)
            .map(|k| {
                let s = 2f32.powi(-k);
                let b = crate::math::Aabb::new(
                    Vec3::new(s, 0.0, 0.0),
                    Vec3::new(1.1 * s, 0.1 * s, 0.1 * s),
                );
                Emitter::area(b, Vec3::Z, 0.01 * s * s, s)
            })
            .collect();
        let tree = LightTree::build(&chain, BuildHeuristic::Sarh).unwrap();
        assert!(tree.depth() > 64, "depth {}", tree.depth());
        check(&tree);
    }
}
