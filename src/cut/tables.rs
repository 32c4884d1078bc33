//! [`TreeTables`]: what the GLT's walks read of one light tree, and
//! [`Segment`]: the tables a walk is in, with the shading point as they
//! see it.
//!
//! A flat hierarchy has one set of tables and every walk is one segment.
//! Over an [`InstancedLightTree`](crate::InstancedLightTree) the top tree
//! has one and each mesh one (`instanced_tables.rs`), and a walk is two
//! segments: the top tree to an instance's leaf, then its mesh's tree with
//! the point moved into mesh space.

use super::child_weights::Lanes;
use super::config::ImportanceBound;
use super::importance_table::{FastQuery, ImportanceTable};
use super::split_table::encode_split;
use super::walk::{WalkNode, WalkTable};
use crate::light_tree::LightHierarchy;
use alloc::vec::Vec;

/// The tables of one light tree: each inner node's power split (4 bytes
/// per node, see `encode_split`), the tree re-laid out for sampling walks
/// (8 bytes per node, and a path code of 8 bytes per emitter: `walk.rs`),
/// the decoded importance table when a rule uses importance (32 bytes per
/// node) and, when the tree has light sets, both children's sets per
/// walk-table pair.
#[derive(Clone, Debug)]
pub(crate) struct TreeTables {
    split: Vec<f32>,
    walk: WalkTable,
    importance: Option<ImportanceTable>,
    /// The light sets of both children of each walk-table pair (the
    /// root's pair: the root's, twice); empty when the tree has no light
    /// sets.
    pair_sets: Vec<[u64; 2]>,
}

impl TreeTables {
    /// The tables of `tree`, the importance table (weighing children by
    /// `importance`'s bound) only when there is one. O(nodes).
    pub(crate) fn new<T: LightHierarchy + ?Sized>(
        tree: &T,
        importance: Option<ImportanceBound>,
    ) -> Self {
        let split: Vec<f32> = (0..tree.node_count() as u32)
            .map(|n| match tree.children(n) {
                Some([l, r]) => encode_split(tree.power(l), tree.power(r)),
                None => f32::NAN,
            })
            .collect();
        let walk = WalkTable::new(tree, |n| split.get(n as usize).copied().unwrap_or(f32::NAN));
        let importance = importance
            .map(|b| ImportanceTable::new(tree, WalkTable::pair_nodes(tree).into_iter(), b));
        let pair_sets = match tree.has_light_sets() {
            false => Vec::new(),
            true => WalkTable::pair_nodes(tree)
                .into_iter()
                .map(|pair| match pair {
                    Some(nodes) => nodes.map(|n| tree.light_sets(n)),
                    None => [tree.root().map_or(0, |r| tree.light_sets(r)); 2],
                })
                .collect(),
        };
        Self {
            split,
            walk,
            importance,
            pair_sets,
        }
    }

    /// Heap bytes.
    pub(crate) fn bytes(&self) -> usize {
        self.split.len() * core::mem::size_of::<f32>()
            + self.walk.bytes()
            + self.pair_sets.len() * core::mem::size_of::<[u64; 2]>()
            + self.importance.as_ref().map_or(0, ImportanceTable::bytes)
    }

    /// The walk table.
    pub(crate) fn walk(&self) -> &WalkTable {
        &self.walk
    }

    /// The decoded importance table, when built.
    #[inline(always)]
    pub(crate) fn importance(&self) -> Option<&ImportanceTable> {
        self.importance.as_ref()
    }

    /// A walk through these tables seeing the point as `fast`, reading
    /// importances from `importance` (this tree's own table, or one of
    /// its views: see `instanced_tables.rs`); `instance` names the
    /// instance whose mesh these tables are, `None` for the top.
    #[inline(always)]
    pub(crate) fn segment<'a>(
        &'a self,
        importance: Option<&'a ImportanceTable>,
        fast: FastQuery,
        instance: Option<u32>,
    ) -> Segment<'a> {
        Segment {
            split: &self.split,
            walk: &self.walk,
            importance,
            pair_sets: &self.pair_sets,
            fast,
            instance,
        }
    }
}

/// The tables a walk is in and the shading point as they see it: the
/// whole walk over a flat hierarchy; over an instanced one, the top tree
/// or, inside instance `instance`, its mesh's tree in mesh space.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Segment<'a> {
    split: &'a [f32],
    /// The tree laid out for sampling walks.
    pub(crate) walk: &'a WalkTable,
    /// The decoded importances, when a rule reads them.
    pub(crate) importance: Option<&'a ImportanceTable>,
    pair_sets: &'a [[u64; 2]],
    /// The shading point as these tables see it.
    pub(crate) fast: FastQuery,
    /// The instance this segment is inside; `None` for the top tree (or a
    /// flat one).
    pub(crate) instance: Option<u32>,
}

impl Segment<'_> {
    /// The raw split-table entry of `node` (NaN for leaves and indices out
    /// of range); `decode_split` turns it into probabilities.
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

    /// The weights at the point of the two children of the inner node
    /// `node` at depth `depth` of this segment's tree, by the table's
    /// [`ImportanceBound`], and the lanes it evaluated for the level below.
    /// With [`ImportanceBound::Grandchildren`]: at even depth by the four
    /// grandchildren's lanes (returned), at odd depth by the children's own
    /// two lanes, those `carried` from the parent (with the side the walk
    /// took there) or, without, evaluated here: the same bits either way.
    /// In the top tree of an instanced hierarchy a leaf child is an
    /// instance, and `root_lanes` gives its mesh root's children's lanes
    /// and their scales (`InstancedTables::root_lanes`), which stand for
    /// it as in the flattened tree (`None` for a flat hierarchy: the
    /// leaf's own bound stands).
    /// `None` without a table or at a leaf.
    #[inline(always)]
    pub(crate) fn child_weights(
        &self,
        node: WalkNode,
        depth: u32,
        carried: Option<(Lanes, usize)>,
        root_lanes: impl Fn(u32, &FastQuery) -> Option<(Lanes, f32, f32)>,
    ) -> (Option<(f64, f64)>, Option<Lanes>) {
        let Some(table) = self.importance else {
            return (None, None);
        };
        let Some(k) = node.children() else {
            return (None, None);
        };
        if table.bound == ImportanceBound::Children {
            return (Some(table.pair_importance(&self.fast, k)), None);
        }
        let wide = |(l, r): (f32, f32)| (f64::from(l), f64::from(r));
        if depth % 2 == 0 {
            let nodes = self.walk.pair(k).0;
            let children = nodes.map(WalkNode::children);
            let mut lanes = table.grandchild_lanes(&self.fast, k, children);
            // An instance's leaf weighs as its mesh root would in the
            // flattened tree: by the root's children, seen from mesh space.
            if let Some(l) = lanes.as_mut().filter(|_| self.instance.is_none()) {
                for (s, node) in nodes.iter().enumerate() {
                    let inner = node.emitter();
                    if let Some((m, power, distance2)) =
                        inner.and_then(|i| root_lanes(i, &self.fast))
                    {
                        *l = l.with_side(s, m, power, distance2);
                    }
                }
            }
            return (lanes.map(|l| wide(l.sides())), lanes);
        }
        let own = match carried {
            Some((lanes, side)) => Some(lanes.side(side)),
            None => table.child_lanes(&self.fast, k).map(|l| l.side(0)),
        };
        (own.map(wide), None)
    }
}
