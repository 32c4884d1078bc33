//! [`Glt`]: the Guiding Light Tree over its own spatial tree, for renderers
//! without directional guiding. One [`GuidingCut`] per cell of PPG's spatial
//! binary tree; it is itself a [`LightSampler`].

use super::cell::GltCell;
use super::config::CutConfig;
use super::cut::{CutMemory, GuidingCut};
use super::cut_node::CutNode;
use super::cut_rules::CutRules;
use super::octants::octant_of;
use super::splat::SplatOutcome;
use super::visibility::valid_record;
use crate::dropped::{DropCounters, DropReason, DroppedSplats};
use crate::emitter::ShadingContext;
use crate::error::{ConfigError, Error};
use crate::light_sampler::{LightId, LightSample, LightSampler};
use crate::light_tree::LightHierarchy;
use crate::math::Aabb;
use crate::math::pmf_to_f32;
use crate::spatial::{
    BinaryTree, CellId, RefineOutcome, SpatialFilter, SpatialTree, jitter_offset,
};
use crate::spatial::{Growth, Jitter, content_scale};
use glam::Vec3;

/// Parameters of a [`Glt`]: the cuts' and the spatial tree's.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GltConfig {
    /// How each cell's cut is refined and sampled.
    pub cut: CutConfig,
    /// PPG's spatial threshold `c`: a cell that takes part in its `g`-th
    /// refinement (counted from 0, see [`Glt::refine`]) splits while its
    /// number of splats exceeds `c * sqrt(2^g)`; each split halves the
    /// count and gives both halves a copy of the cut and its statistics.
    /// Default 250: a cut learns from far fewer records than a quadtree,
    /// and finer cells paid off in every measurement (at 64 spp on `ring`
    /// and `city`, relMSE 0.206 and 0.491 at 250, 0.218 and 0.524 at
    /// 1000, 0.244 and 0.573 at PPG's 12,000, for 3x and 1.4x the memory
    /// of 12,000; docs/experiments/tile-order.md). Memory grows with the
    /// square root of the records (the threshold doubles every two
    /// refinements); cap it with `max_bytes`.
    pub spatial_threshold: f64,
    /// Cap, in bytes, on the spatial tree plus the cells' cuts (their
    /// nodes and sums) after every [`Glt::refine`]; `None` for none. Cell
    /// splits are refused once it is reached (a split is charged the cut
    /// it copies), then every cut's growth is scaled down by one factor:
    /// each is rebuilt with a coarser `sigma` until it has at most that
    /// share of the nodes it would have had (`src/spatial/budget.rs`). The
    /// cap cannot shrink below what the cells hold whatever their nodes
    /// (one sum each, the anchor sums).
    pub max_bytes: Option<usize>,
    /// The spatial filter of [`Glt::splat`]. Default
    /// [`SpatialFilter::Nearest`]: the estimate goes to the cell holding
    /// the shading point. A jittering filter carries a splat into the
    /// neighbouring cells, also through walls, where the light it saw may
    /// be invisible; a dim room beside bright ones then learns its
    /// neighbours' lights and samples worse than without learning
    /// (`tests/glt_walls.rs`).
    pub filter: SpatialFilter,
}

impl GltConfig {
    /// Checks every field: the cut's ([`CutConfig::validate`]) and
    /// `spatial_threshold` finite and positive (at 0 every cell would
    /// split on every splat).
    pub fn validate(&self) -> Result<(), ConfigError> {
        self.cut.validate()?;
        crate::error::positive("GltConfig::spatial_threshold", self.spatial_threshold)
    }
}

impl Default for GltConfig {
    fn default() -> Self {
        Self {
            cut: CutConfig::default(),
            spatial_threshold: 250.0,
            max_bytes: None,
            filter: SpatialFilter::Nearest,
        }
    }
}

/// Bytes a [`Glt`] uses, by part.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct GltMemory {
    /// Number of cells.
    pub cells: usize,
    /// The cuts together (nodes, sums, inline parts of the cells' cuts).
    pub cuts: CutMemory,
    /// The spatial tree's own storage: node words, per-cell bookkeeping and
    /// the inline [`GltCell`] values (which include the cuts' inline parts,
    /// so those are not added twice in [`GltMemory::total`]).
    pub spatial_bytes: usize,
    /// The [`CutRules`]'s split and walk tables, shared by all cells (12
    /// bytes per light-tree node, plus 8).
    pub shared_bytes: usize,
}

impl GltMemory {
    /// Bytes of one cut node.
    pub const BYTES_PER_CUT_NODE: usize = CutNode::BYTES;

    /// Everything together.
    pub fn total(&self) -> usize {
        self.spatial_bytes + self.shared_bytes + self.cuts.node_bytes + self.cuts.sum_bytes
    }

    /// Average bytes per cell (cut nodes, sums and spatial share; the
    /// shared table excluded).
    pub fn bytes_per_cell(&self) -> f64 {
        (self.total() - self.shared_bytes) as f64 / self.cells.max(1) as f64
    }
}

/// The Guiding Light Tree over its own spatial tree: one learned cut per
/// cell of PPG's binary tree over the scene, sampled by the GLT's sampling
/// rule (see `sampling.rs` and [`GuidingCut`]).
///
/// Per iteration a renderer samples lights with [`LightSampler::sample`]
/// (any number of threads), splats the resulting direct-light estimates
/// with [`Glt::splat`] (idem), then calls [`Glt::refine`] once.
///
/// `H` is the light hierarchy, held as the renderer chooses: owned
/// (`Glt<LightTree>`), shared with the scene (`Glt<Arc<LightTree>>`) or
/// borrowed (`Glt<&LightTree>`).
#[derive(Clone, Debug)]
pub struct Glt<H: LightHierarchy> {
    pub(super) guide: CutRules<H>,
    pub(super) config: GltConfig,
    pub(super) spatial: BinaryTree<GltCell>,
    pub(super) iteration: u32,
    pub(super) dropped: DropCounters,
}

impl<H: LightHierarchy> Glt<H> {
    /// A GLT over the light hierarchy `tree` for shading points inside
    /// `scene` (the scene's geometry bounds; points outside are clamped
    /// onto the spatial tree's cube). One cell with the initial cut.
    /// Errors for an invalid configuration ([`GltConfig::validate`]) and
    /// for empty or non-finite `scene`.
    pub fn new(tree: H, scene: Aabb, config: GltConfig) -> Result<Self, Error> {
        config.validate()?;
        let guide = CutRules::new(tree, config.cut)?;
        let cell = GltCell::new(guide.new_cut());
        Ok(Self {
            guide,
            config,
            spatial: BinaryTree::new(scene, cell)?,
            iteration: 0,
            dropped: DropCounters::default(),
        })
    }

    /// The light hierarchy.
    pub fn light_tree(&self) -> &H {
        self.guide.light_tree()
    }

    /// The guiding tree every cell's cut is used through.
    pub fn cut_rules(&self) -> &CutRules<H> {
        &self.guide
    }

    /// The configuration.
    pub fn config(&self) -> &GltConfig {
        &self.config
    }

    /// The spatial tree and its cells.
    pub fn spatial(&self) -> &BinaryTree<GltCell> {
        &self.spatial
    }

    /// Refinements done so far.
    pub fn iteration(&self) -> u32 {
        self.iteration
    }

    /// The cut of the cell holding `p` (`None` for a non-finite point).
    #[inline]
    pub(crate) fn cut_at(&self, p: Vec3) -> Option<&GuidingCut> {
        let cell = self.spatial.locate(p)?;
        Some(&self.spatial.data(cell).cut)
    }

    /// Splats dropped as bad input so far, all in [`DroppedSplats::light`]:
    /// non-finite or negative values or positions, emitters out of range or
    /// with zero power, unbounded lights beyond the configured count.
    pub fn dropped_splats(&self) -> DroppedSplats {
        self.dropped.snapshot()
    }

    /// Sets the dropped-input counters to zero.
    pub fn reset_dropped_splats(&mut self) {
        self.dropped.reset();
    }

    /// Records a direct-light estimate `value` for `light` seen from `p` (see
    /// [`CutRules::splat`] for what the value is) into the cell(s) that
    /// [`GltConfig::filter`] spreads `p` over: by default the cell holding
    /// `p`. With [`SpatialFilter::StochasticBox`] `p` is first jittered
    /// uniformly inside a box the size of its cell centred on it (PPG's
    /// stochastic box, +-1/2 cell per axis, the paper's code uses +-1/4;
    /// three numbers from `jitter`, see [`Jitter`]), which smooths cuts
    /// across cell borders but also carries light through walls. `&self`:
    /// any number of threads at once.
    pub fn splat<J: Jitter + ?Sized>(
        &self,
        p: Vec3,
        light: LightId,
        value: f32,
        jitter: &mut J,
    ) -> SplatOutcome {
        let at = self.spatial.locate_with_bounds(p);
        self.splat_filtered(p, at, light, value, self.config.filter, || {
            jitter_offset(jitter)
        })
    }

    /// Like [`Glt::splat`] with [`SpatialFilter::Nearest`] whatever the
    /// configuration: the estimate goes to the cell holding `p`.
    pub fn splat_at(&self, p: Vec3, light: LightId, value: f32) -> SplatOutcome {
        let at = self.spatial.locate_with_bounds(p);
        self.splat_filtered(p, at, light, value, SpatialFilter::Nearest, || Vec3::ZERO)
    }

    /// A light splat from `p`, located at `at` (`None`: non-finite `p`).
    pub(super) fn splat_filtered(
        &self,
        p: Vec3,
        at: Option<(CellId, Aabb)>,
        light: LightId,
        value: f32,
        filter: SpatialFilter,
        jitter: impl FnOnce() -> Vec3,
    ) -> SplatOutcome {
        let octant = at.map_or(0, |(_, bounds)| octant_of(p, &bounds));
        let outcome = self.guide.splat_spread(
            &self.spatial,
            (p, at),
            light,
            value,
            (filter, jitter),
            |cell| cell.octants.count(octant),
        );
        if outcome == SplatOutcome::Dropped {
            self.reject();
        }
        outcome
    }

    /// Records what a next-event sample of `light` from `p` saw, for the
    /// learned visibility ([`CutConfig::visibility`]): the value recorded
    /// for it (0 when blocked) and the value it would have been without
    /// occluders ([`CutRules::splat_visibility`]), into the cell holding
    /// `p` (visibility is never carried into neighbouring cells). Bad input
    /// is dropped and counted.
    ///
    /// [`CutConfig::visibility`]: super::CutConfig::visibility
    pub fn splat_visibility(
        &self,
        p: Vec3,
        light: LightId,
        shadowed: f32,
        unshadowed: f32,
    ) -> SplatOutcome {
        let outcome = if !self.config.cut.visibility {
            // Nothing is learned: the values are checked, `p` is not
            // looked up (the renderer may record whatever the
            // configuration, at no cost).
            if valid_record(shadowed, unshadowed) {
                SplatOutcome::Zero
            } else {
                SplatOutcome::Dropped
            }
        } else {
            match self.cut_at(p) {
                Some(cut) => self
                    .guide
                    .splat_visibility(cut, light, shadowed, unshadowed),
                None => SplatOutcome::Dropped,
            }
        };
        if outcome == SplatOutcome::Dropped {
            self.reject();
        }
        outcome
    }

    #[inline]
    fn reject(&self) {
        self.dropped.count(DropReason::Light);
    }

    /// Turns what was recorded into the cuts sampled next, cell by cell
    /// (`&mut self`: between passes or tiles, or through
    /// [`SharedGuide`](crate::shared_guide::SharedGuide)).
    ///
    /// A cell takes part once it holds 3/2 of the splats that fell in it
    /// before its last refinement (any, before its first; see
    /// [`GltCell`]); the others
    /// keep accumulating. A cell that takes part splits while its count is
    /// above `c sqrt(2^g)` (`c` the spatial threshold, `g` the refinements
    /// it took part in, a half taken to have half its parent's splats: PPG's
    /// rule, with the cell's own clock); both halves get a copy of the cut
    /// and its sums, and each the confidence of its share of the records
    /// ([`GuidingCut::confidence`]). Then its cut is rebuilt from its sums
    /// ([`CutRules::refine`]; a cut that collected nothing keeps its
    /// distribution) within the memory budget. A renderer that refines
    /// after every iteration of PPG's doubling schedule makes every cell
    /// take part every time; one that renders tile by tile may refine
    /// after every few tiles. Returns what the spatial refinement did, as
    /// [`SdTree::refine`](crate::sd_tree::SdTree::refine) and
    /// [`GuidingField::refine`](crate::field::GuidingField::refine) do.
    pub fn refine(&mut self) -> RefineOutcome {
        for cell in self.spatial.data_slice_mut() {
            cell.begin();
        }
        let c = self.config.spatial_threshold;
        let outcome = self.spatial.refine_along(
            |cell, _| cell.splits(c),
            |cell, axis| cell.split(axis),
            |cell| cell.cut.heap_bytes(),
            self.config.max_bytes,
        );
        // The cuts grow within what the budget leaves (src/spatial/budget.rs).
        let guide = &self.guide;
        let cells = self.spatial.data_slice();
        let scale = content_scale(
            self.config.max_bytes,
            self.spatial.bytes(),
            // A cell that does not take part keeps its cut as it is.
            cells.iter().map(|c| match c.pass.ready {
                true => guide.growth(&c.cut),
                false => Growth {
                    fixed: c.cut.heap_bytes(),
                    nodes: 0,
                    per_node: 0,
                },
            }),
        );
        for cell in self.spatial.data_slice_mut() {
            if !cell.pass.ready {
                continue;
            }
            let cap = scale.and_then(|_| guide.growth(&cell.cut).cap(scale));
            let rebuilt = guide.refine_within(&mut cell.cut, cap);
            cell.end(rebuilt);
        }
        self.iteration = self.iteration.saturating_add(1);
        outcome
    }

    /// Bytes used, by part.
    pub fn memory(&self) -> GltMemory {
        GltMemory {
            cells: self.spatial.cell_count(),
            cuts: self
                .spatial
                .data_slice()
                .iter()
                .map(|c| c.cut.memory())
                .sum(),
            spatial_bytes: self.spatial.bytes(),
            shared_bytes: self.guide.bytes(),
        }
    }

    /// The cell holding `p`, `None` for a non-finite point.
    pub fn locate(&self, p: Vec3) -> Option<CellId> {
        self.spatial.locate(p)
    }

    /// The one lookup per path vertex: the cell holding `p` (clamped onto
    /// the root cube), through which light selection and light splats at
    /// `p` go. `None` for a non-finite `p`.
    #[inline]
    pub fn vertex(&self, p: Vec3) -> Option<GltVertex<'_, H>> {
        let at = self.spatial.locate_with_bounds(p)?;
        Some(GltVertex {
            glt: self,
            cut: &self.spatial.data(at.0).cut,
            p,
            at,
        })
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

impl<H: LightHierarchy> CutRules<H> {
    /// Records the direct-light estimate `value` for `light` made at a point
    /// into the cuts of the cells of `cells` that `filter` spreads the point
    /// over (each cell's part `value * weight`), through
    /// [`CutRules::splat`]. `at` is the point and its
    /// `locate_with_bounds` (`None` for a non-finite point: dropped);
    /// `jitter` is that of [`BinaryTree::spread_from`]. `accepted` is called for every cell whose cut took its part
    /// ([`SplatOutcome::Recorded`] or [`SplatOutcome::Zero`]). The caller
    /// counts a [`SplatOutcome::Dropped`] result, once per call.
    ///
    /// Shared by [`Glt`] and the combined guiding field
    /// ([`crate::field`]).
    #[inline]
    pub(crate) fn splat_spread<C: AsRef<GuidingCut>>(
        &self,
        cells: &BinaryTree<C>,
        (p, at): (Vec3, Option<(CellId, Aabb)>),
        light: LightId,
        value: f32,
        (filter, jitter): (SpatialFilter, impl FnOnce() -> Vec3),
        accepted: impl Fn(&C),
    ) -> SplatOutcome {
        let Some(at) = at else {
            return SplatOutcome::Dropped;
        };
        let mut outcome = SplatOutcome::Zero;
        cells.spread_from(p, at, filter, jitter, |cell, weight| {
            let cell = cells.data(cell);
            match self.splat_weighted_from(cell.as_ref(), p, weight, light, value * weight) {
                SplatOutcome::Dropped => outcome = SplatOutcome::Dropped,
                o => {
                    accepted(cell);
                    if o == SplatOutcome::Recorded && outcome != SplatOutcome::Dropped {
                        outcome = o;
                    }
                }
            }
        });
        outcome
    }
}

impl<H: LightHierarchy> LightSampler for Glt<H> {
    /// Locates the cell of `ctx.position`, then applies the GLT's sampling
    /// rule with its cut. `None` for a non-finite position.
    #[inline]
    fn sample(&self, ctx: &ShadingContext, u: f32) -> Option<LightSample> {
        self.guide.sample(self.cut_at(ctx.position)?, ctx, u)
    }

    #[inline]
    fn pmf(&self, ctx: &ShadingContext, light: LightId) -> f32 {
        pmf_to_f32(self.pmf_exact(ctx, light))
    }

    fn is_empty(&self) -> bool {
        self.guide.is_empty()
    }

    #[inline]
    fn sample_exact(&self, ctx: &ShadingContext, u: f64) -> Option<(LightId, f64)> {
        self.guide.sample_exact(self.cut_at(ctx.position)?, ctx, u)
    }

    #[inline]
    fn pmf_exact(&self, ctx: &ShadingContext, light: LightId) -> f64 {
        self.cut_at(ctx.position)
            .map_or(0.0, |cut| self.guide.pmf_exact(cut, ctx, light))
    }

    /// The learned visibility of `light` in the cell of `ctx.position`
    /// (1, without a lookup, when none is learned).
    fn visibility(&self, ctx: &ShadingContext, light: LightId) -> f32 {
        if !self.config.cut.visibility {
            return 1.0;
        }
        self.cut_at(ctx.position)
            .map_or(1.0, |cut| self.guide.visibility(cut, light))
    }

    /// One lookup and one walk.
    fn sample_with_visibility(&self, ctx: &ShadingContext, u: f32) -> Option<(LightSample, f32)> {
        let cut = self.cut_at(ctx.position)?;
        self.guide.sample_with_visibility(cut, ctx, u)
    }
}

/// A path vertex located in a [`Glt`] ([`Glt::vertex`]): light selection
/// and light splats at that point without looking the cell up again, as
/// [`FieldVertex`](crate::field::FieldVertex) does for the combined field.
/// Every answer equals the GLT's by position at the same point.
#[derive(Debug)]
pub struct GltVertex<'g, H: LightHierarchy> {
    glt: &'g Glt<H>,
    cut: &'g GuidingCut,
    p: Vec3,
    at: (CellId, Aabb),
}

impl<H: LightHierarchy> Clone for GltVertex<'_, H> {
    fn clone(&self) -> Self {
        *self
    }
}

impl<H: LightHierarchy> Copy for GltVertex<'_, H> {}

impl<'g, H: LightHierarchy> GltVertex<'g, H> {
    /// The point this vertex was located from.
    #[inline]
    pub fn position(&self) -> Vec3 {
        self.p
    }

    /// The cell's number.
    #[inline]
    pub fn cell(&self) -> CellId {
        self.at.0
    }

    /// The located cell's cut.
    #[inline]
    pub fn cut(&self) -> &'g GuidingCut {
        self.cut
    }

    /// [`Glt::splat`] at this vertex's position: a direct-light estimate
    /// `value` for `light` (`Le * w_mis / pmf` for NEE, see
    /// [`CutRules::splat`]).
    #[inline]
    pub fn splat_light<J: Jitter + ?Sized>(
        &self,
        light: LightId,
        value: f32,
        jitter: &mut J,
    ) -> SplatOutcome {
        let g = self.glt;
        g.splat_filtered(self.p, Some(self.at), light, value, g.config.filter, || {
            jitter_offset(jitter)
        })
    }
}

impl<H: LightHierarchy> GltVertex<'_, H> {
    /// [`Glt::splat_visibility`] at this vertex's cell.
    #[inline]
    pub fn splat_visibility(&self, light: LightId, shadowed: f32, unshadowed: f32) -> SplatOutcome {
        let outcome = self
            .glt
            .guide
            .splat_visibility(self.cut, light, shadowed, unshadowed);
        if outcome == SplatOutcome::Dropped {
            self.glt.reject();
        }
        outcome
    }
}

impl<H: LightHierarchy> LightSampler for GltVertex<'_, H> {
    /// Applies the GLT's sampling rule with the located cell's cut.
    #[inline]
    fn sample(&self, ctx: &ShadingContext, u: f32) -> Option<LightSample> {
        self.glt.guide.sample(self.cut, ctx, u)
    }

    #[inline]
    fn pmf(&self, ctx: &ShadingContext, light: LightId) -> f32 {
        self.glt.guide.pmf(self.cut, ctx, light)
    }

    fn is_empty(&self) -> bool {
        self.glt.guide.is_empty()
    }

    #[inline]
    fn sample_exact(&self, ctx: &ShadingContext, u: f64) -> Option<(LightId, f64)> {
        self.glt.guide.sample_exact(self.cut, ctx, u)
    }

    #[inline]
    fn pmf_exact(&self, ctx: &ShadingContext, light: LightId) -> f64 {
        self.glt.guide.pmf_exact(self.cut, ctx, light)
    }

    /// The learned visibility of `light` in the located cell.
    fn visibility(&self, _ctx: &ShadingContext, light: LightId) -> f32 {
        self.glt.guide.visibility(self.cut, light)
    }

    /// One walk: the visibility is read where it leaves the cut.
    #[inline]
    fn sample_with_visibility(&self, ctx: &ShadingContext, u: f32) -> Option<(LightSample, f32)> {
        self.glt.guide.sample_with_visibility(self.cut, ctx, u)
    }
}
