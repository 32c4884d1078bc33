//! [`CutRules`]: what every cell's cut shares: the light tree, the tables
//! the GLT's walk reads, and the cut configuration.

use super::child_weights::Lanes;
use super::config::CutConfig;
use super::guiding_cut::GuidingCut;
use super::importance_table::FastQuery;
use super::instanced_tables::InstancedTables;
use super::tables::{Segment, TreeTables};
use super::walk::WalkNode;
use crate::error::ConfigError;
use crate::light_tree::{InstancedLightTree, LightHierarchy, same_shape};

/// The rules every cell's cut is sampled, recorded and refined by, with the
/// light-tree tables they read: the hierarchy, each inner node's power
/// split precomputed (4 bytes per node), the tree re-laid out for sampling
/// walks (8 bytes per node, see `src/cut/walk.rs`), the decoded importance
/// table when a rule uses importance (32 bytes per node), and the cut
/// configuration. One per scene; every cell's [`GuidingCut`] is sampled
/// ([`CutRules::sample`]), recorded ([`CutRules::record`]) and refined
/// ([`CutRules::refine`]) through it. Over an
/// [`InstancedLightTree`] the tables are its top tree's and one set per
/// mesh, shared by the mesh's instances (`src/cut/instanced_tables.rs`).
///
/// The split table (`split_table.rs`) is why the GLT's walk is cheaper per
/// level than a plain power descent.
#[derive(Clone, Debug)]
pub struct CutRules<H: LightHierarchy> {
    tree: H,
    /// The tables of the hierarchy, or of the top tree of an instanced
    /// one.
    tables: TreeTables,
    /// An instanced hierarchy's per-mesh tables
    /// ([`LightHierarchy::as_instanced`]).
    instanced: Option<InstancedTables>,
    config: CutConfig,
    has_power: bool,
}

impl<H: LightHierarchy> CutRules<H> {
    /// Prepares `light_tree` for guiding with `config`. O(nodes). Errors for an
    /// invalid configuration ([`CutConfig::validate`]).
    pub fn new(light_tree: H, config: CutConfig) -> Result<Self, ConfigError> {
        config.validate()?;
        Ok(Self::with_valid_config(light_tree, config))
    }

    /// [`CutRules::new`] for a `config` known to be valid.
    fn with_valid_config(tree: H, config: CutConfig) -> Self {
        let importance = config.uses_importance().then_some(config.importance_bound);
        let (tables, instanced) = match tree.as_instanced() {
            Some(inst) => (
                TreeTables::new(inst.top(), importance),
                Some(InstancedTables::new(inst, importance)),
            ),
            None => (TreeTables::new(&tree, importance), None),
        };
        let has_power = tree.root().is_some_and(|r| tree.power(r) > 0.0);
        Self {
            tree,
            tables,
            instanced,
            config,
            has_power,
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

    /// Heap bytes of the tables (about 12 per light-tree node, 44 when a
    /// rule uses importance; over an instanced tree, per node of its top
    /// tree and meshes, plus 128 per instance).
    pub fn bytes(&self) -> usize {
        self.tables.bytes() + self.instanced.as_ref().map_or(0, InstancedTables::bytes)
    }

    /// The tables of the hierarchy (of the top tree of an instanced one).
    #[inline]
    pub(crate) fn tables(&self) -> &TreeTables {
        &self.tables
    }

    /// The tables at the root, seeing the point as `fast`.
    #[inline(always)]
    pub(crate) fn top_segment(&self, fast: FastQuery) -> Segment<'_> {
        self.tables.segment(self.tables.importance(), fast, None)
    }

    /// Whether the walks read decoded importances (the configuration uses
    /// importance).
    #[inline(always)]
    pub(crate) fn reads_importance(&self) -> bool {
        self.tables.importance().is_some()
    }

    /// The per-mesh tables and the instanced tree, when the hierarchy is
    /// one. Known `None` at compile time for a hierarchy that is not
    /// ([`LightHierarchy::as_instanced`]'s default), so flat walks carry
    /// no instancing code.
    #[inline(always)]
    pub(crate) fn instanced(&self) -> Option<(&InstancedTables, &InstancedLightTree)> {
        let tree = self.tree.as_instanced()?;
        Some((self.instanced.as_ref()?, tree))
    }

    /// The weights of the children of `node` at depth `depth` of `seg` and
    /// the lanes for the level below ([`Segment::child_weights`]), an
    /// instance's leaf in the top tree weighed by its mesh root's children.
    #[inline(always)]
    pub(crate) fn child_weights(
        &self,
        seg: &Segment,
        node: WalkNode,
        depth: u32,
        carried: Option<(Lanes, usize)>,
    ) -> (Option<(f64, f64)>, Option<Lanes>) {
        let instances = self.instanced().map(|(tables, _)| tables);
        seg.child_weights(node, depth, carried, |i, fast| {
            instances?.root_lanes(i, fast)
        })
    }

    /// Where a walk at `node` of `seg` goes on when `node` is the top
    /// tree's leaf of an instance: its mesh's root, in its mesh's tables.
    /// `None` anywhere else (the walk stays where it is): inside an
    /// instance, and at inner nodes, which name no emitter.
    #[inline(always)]
    pub(crate) fn enter<'a>(
        &'a self,
        seg: &Segment<'a>,
        node: WalkNode,
    ) -> Option<(Segment<'a>, WalkNode)> {
        let (tables, _) = self.instanced()?;
        if seg.instance.is_some() {
            return None;
        }
        let inner = tables.segment(node.emitter()?, &seg.fast)?;
        Some((inner, inner.walk.root()?))
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
