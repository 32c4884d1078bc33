//! [`CutRules`]: what every cell's cut shares: the light tree, the tables
//! the GLT's walk reads, and the cut configuration.

use super::config::CutConfig;
use super::guiding_cut::GuidingCut;
use super::importance_table::ImportanceTable;
use super::walk::WalkTable;
use crate::error::ConfigError;
use crate::light_tree::{LightHierarchy, same_shape};
use crate::math::Descent;
use alloc::vec::Vec;

/// The rules every cell's cut is sampled, splatted and refined by, with the
/// light-tree tables they read: the hierarchy, each inner node's power
/// split precomputed (4 bytes per node), the tree re-laid out for sampling
/// walks (8 bytes per node, see `src/cut/walk.rs`), the decoded importance
/// table when a rule uses importance (32 bytes per node), and the cut
/// configuration. One per scene; every cell's [`GuidingCut`] is sampled
/// ([`CutRules::sample`]), splatted ([`CutRules::splat`]) and refined
/// ([`CutRules::refine`]) through it.
///
/// The split table is why the GLT's walk is cheaper per level than a plain
/// power descent: the prior probabilities of a node's children come from
/// one 4-byte load instead of two 32-byte node loads (the right child lies
/// far from its parent in memory) and a division. Each entry stores the
/// probability of the *smaller* side in `f32`, its sign telling which side
/// that is, so both sides keep 24 bits of relative precision: a child with
/// 1e-9 of its parent's power keeps its 1e-9 (a plain `f32` `p_left` would
/// round the pair to 1 and 0 and lose the child's prior floor). A child with
/// any positive power gets a positive probability (at least the smallest
/// `f32`); both children dark is NaN (neither can be chosen).
#[derive(Clone, Debug)]
pub struct CutRules<H: LightHierarchy> {
    tree: H,
    split: Vec<f32>,
    walk: WalkTable,
    /// Every node decoded for the importance-based rules; built only when
    /// the configuration uses one.
    importance: Option<ImportanceTable>,
    config: CutConfig,
    has_power: bool,
    /// The light sets of both children of each walk-table pair (the
    /// root's pair: the root's, twice); empty when the tree has no light
    /// sets.
    pair_sets: Vec<[u64; 2]>,
}

/// Encodes the split of a node with child powers `el`, `er`.
fn encode_split(el: f32, er: f32) -> f32 {
    let (l, r) = (el as f64, er as f64);
    let Some((pl, pr)) = Descent::probabilities(l, r) else {
        return f32::NAN;
    };
    let tiny = f32::from_bits(1);
    if pl <= pr {
        let q = pl as f32;
        if l > 0.0 { q.max(tiny) } else { 0.0 }
    } else {
        let q = pr as f32;
        -(if r > 0.0 { q.max(tiny) } else { 0.0 })
    }
}

/// Decodes a split entry into `(p_left, p_right)`; `None` for a dark node.
///
/// Branch-free in the sign: which side is the smaller one is a coin flip
/// per level, and a mispredicted branch there would cost more than the
/// rest of the level.
#[inline(always)]
pub(crate) fn decode_split(s: f32) -> Option<(f64, f64)> {
    if s.is_nan() {
        return None;
    }
    let small = s.abs() as f64;
    let large = 1.0 - small;
    // All ones when the right side is the smaller one (sign bit set).
    let mask = ((s.to_bits() >> 31) as u64).wrapping_neg();
    let (a, b) = (small.to_bits(), large.to_bits());
    let left = f64::from_bits((a & !mask) | (b & mask));
    let right = f64::from_bits((b & !mask) | (a & mask));
    Some((left, right))
}

impl<H: LightHierarchy> CutRules<H> {
    /// Prepares `tree` for guiding with `config`. O(nodes). Errors for an
    /// invalid configuration ([`CutConfig::validate`]).
    pub fn new(tree: H, config: CutConfig) -> Result<Self, ConfigError> {
        config.validate()?;
        Ok(Self::with_valid_config(tree, config))
    }

    /// [`CutRules::new`] for a `config` known to be valid.
    fn with_valid_config(tree: H, config: CutConfig) -> Self {
        let lights = &tree;
        let split: Vec<f32> = (0..lights.node_count() as u32)
            .map(|n| match lights.children(n) {
                Some([l, r]) => encode_split(lights.power(l), lights.power(r)),
                None => f32::NAN,
            })
            .collect();
        let walk = WalkTable::new(lights, |n| {
            split.get(n as usize).copied().unwrap_or(f32::NAN)
        });
        let importance = config
            .uses_importance()
            .then(|| ImportanceTable::new(lights, WalkTable::pair_nodes(lights).into_iter()));
        let has_power = lights.root().is_some_and(|r| lights.power(r) > 0.0);
        let pair_sets = match lights.has_light_sets() {
            false => Vec::new(),
            true => WalkTable::pair_nodes(lights)
                .into_iter()
                .map(|pair| match pair {
                    Some(nodes) => nodes.map(|n| lights.light_sets(n)),
                    None => [lights.root().map_or(0, |r| lights.light_sets(r)); 2],
                })
                .collect(),
        };
        Self {
            tree,
            split,
            walk,
            importance,
            config,
            has_power,
            pair_sets,
        }
    }

    /// Puts `tree` in place of the light hierarchy, which it must have the
    /// shape of (a refit of it: the same nodes, links and emitter order),
    /// and rebuilds the tables from its powers and bounds; returns the
    /// hierarchy it replaces. Every cut over the old hierarchy is a valid
    /// cut over the new one: cuts name nodes, not positions. `Err(tree)`,
    /// and nothing changes, for another shape. O(nodes).
    pub(crate) fn set_light_tree(&mut self, tree: H) -> Result<H, H> {
        if !same_shape(&self.tree, &tree) {
            return Err(tree);
        }
        let new = Self::with_valid_config(tree, self.config);
        Ok(core::mem::replace(self, new).tree)
    }

    /// The light hierarchy.
    #[inline]
    pub fn light_tree(&self) -> &H {
        &self.tree
    }

    /// The configuration.
    #[inline]
    pub fn config(&self) -> &CutConfig {
        &self.config
    }

    /// True when some emitter has positive power.
    #[inline]
    pub fn has_power(&self) -> bool {
        self.has_power
    }

    /// Heap bytes of the split table and the walk table (12 per
    /// light-tree node).
    pub fn bytes(&self) -> usize {
        self.split.len() * core::mem::size_of::<f32>()
            + self.walk.bytes()
            + self.pair_sets.len() * core::mem::size_of::<[u64; 2]>()
            + self.importance.as_ref().map_or(0, ImportanceTable::bytes)
    }

    /// The raw split-table entry of `node` (NaN for leaves and indices out
    /// of range); [`decode_split`] turns it into probabilities.
    #[inline(always)]
    pub(crate) fn raw_split(&self, node: u32) -> f32 {
        self.split.get(node as usize).copied().unwrap_or(f32::NAN)
    }

    /// The light sets of the children in walk-table pair `k` (`u64::MAX`
    /// each when the tree has none).
    #[inline(always)]
    pub(crate) fn pair_sets(&self, k: u32) -> [u64; 2] {
        match self.pair_sets.get(k as usize) {
            Some(&s) => s,
            None => [u64::MAX; 2],
        }
    }

    /// The light tree laid out for sampling walks.
    #[inline(always)]
    pub(crate) fn walk(&self) -> &WalkTable {
        &self.walk
    }

    /// The decoded nodes of the importance-based rules, when the
    /// configuration uses one.
    #[inline(always)]
    pub(crate) fn importance_table(&self) -> Option<&ImportanceTable> {
        self.importance.as_ref()
    }

    /// The initial cut of a cell: the light tree's root split by power,
    /// `p_left = E(left) / (E(left) + E(right))` (the paper's code starts at
    /// 0.5/0.5 whatever the power), so sampling it is exactly
    /// tree-by-power sampling (below the cut as [`BelowCut`](super::BelowCut)
    /// says). With [`Modulation::Importance`](super::Modulation::Importance) both sides start with equal factors, so
    /// the cut samples by the importance at the shading point. A tree whose root is a leaf (or that is
    /// empty) gets the empty cut. Each unbounded light's fraction starts at
    /// its prior share.
    pub fn new_cut(&self) -> GuidingCut {
        GuidingCut::new(&self.tree, &self.config)
    }
}
