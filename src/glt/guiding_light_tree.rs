//! [`Glt`]: the Guiding Light Tree over its own spatial tree, for renderers
//! without directional guiding. One guiding cut per cell of PPG's spatial
//! binary tree, each path vertex answered through its [`LightVertex`].

use super::cell::GltCell;
use super::config::GltConfig;
use super::memory::GltMemory;
use crate::cut::CutRules;
use crate::cut::{LightCells, LightVertex};
use crate::dropped::{DropCounters, DropReason, DroppedRecords};
use crate::error::Error;
use crate::light_sampler::LightId;
use crate::light_sampler::ShadingContext;
use crate::light_tree::LightHierarchy;
use crate::math::Aabb;
use crate::record::RecordOutcome;
use crate::snapshot::{Snapshot, SnapshotError};
use crate::spatial::{BinaryTree, CellId, Located, RefineOutcome, SpatialTree};
use crate::spatial::{Growth, content_scale};
use glam::Vec3;

/// The Guiding Light Tree over its own spatial tree: one learned cut per
/// cell of PPG's binary tree over the scene, sampled by the GLT's sampling
/// rule (see `sampling.rs` and `GuidingCut`).
///
/// Per iteration a renderer locates each path vertex once
/// ([`Glt::vertex`]), samples lights and records what each sample found
/// through the [`LightVertex`] (any number of threads), then calls
/// [`Glt::refine`] once.
///
/// `H` is the light hierarchy, held as the renderer chooses: owned
/// (`Glt<LightTree>`), shared with the scene (`Glt<Arc<LightTree>>`) or
/// borrowed (`Glt<&LightTree>`).
///
/// Under light linking (a point lit by some light sets only,
/// [`ShadingContext::lit_by`]) every query chooses only among the lights
/// the point is lit by, exactly normalised, whatever the GLT learned. Keep
/// one `Glt` per receiver set over the same shared tree, each fed and
/// asked by its own points: one GLT learning from every set's points
/// mixes what each set's points need, and measured 1.4-2.8x the
/// per-set GLTs' variance with 4 to 16 sets (`examples/light_sets.rs`,
/// docs/experiments/light-sets.md).
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

    /// Hands the GLT its light tree after a refit
    /// ([`LightTree::refit`](crate::LightTree::refit): the lights moved or
    /// changed power, the tree kept its shape) and returns the one it
    /// held. Everything learned is kept: each cell's cut names tree nodes,
    /// which still hold the same lights; the power splits and importance
    /// tables are rebuilt from the new tree, so sampling follows the
    /// lights' new powers and bounds at once, and a light that was dark
    /// and now shines is reachable through the prior. O(light-tree nodes).
    /// [`Error::LightTreeShape`] for a tree of another shape (a rebuild,
    /// other lights), and nothing changes. The lights have changed, so
    /// what the cells counted before describes the old ones: every cell
    /// takes part in the next refinement ([`Glt::restart`]).
    ///
    /// ```
    /// # use guiding::{Aabb, BuildHeuristic, Emitter, Glt, GltConfig, LightTree};
    /// # use guiding::glam::Vec3;
    /// let mut lights: Vec<Emitter> = (0..8)
    ///     .map(|i| Emitter::point(Vec3::new(i as f32, 1.0, 0.0), 1.0))
    ///     .collect();
    /// let tree = LightTree::build(lights.as_slice(), BuildHeuristic::default())?;
    /// let scene = Aabb::new(Vec3::splat(-10.0), Vec3::splat(10.0));
    /// let mut glt = Glt::new(tree, scene, GltConfig::default())?;
    /// // ... render a frame, refine ...
    /// for l in &mut lights {
    ///     l.bounds = Aabb::from_point(l.bounds.min + Vec3::Y * 0.1);
    /// }
    /// let mut tree = glt.light_tree().clone();
    /// let drift = tree.refit(lights.as_slice())?;
    /// assert!(drift < LightTree::REBUILD_RATIO);
    /// glt.set_light_tree(tree)?;
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn set_light_tree(&mut self, tree: H) -> Result<H, Error> {
        let old = self
            .guide
            .set_light_tree(tree)
            .map_err(|_| Error::LightTreeShape)?;
        self.restart();
        Ok(old)
    }

    /// Starts a new schedule from what was learned (the next frame of an
    /// animation, a guide loaded to render another image): every cell
    /// takes part in the next refinement with whatever it has collected by
    /// then, as before its first, instead of waiting for 3/2 of the splats
    /// it refined on last (which, after a long last iteration, a short
    /// frame may never collect). The cuts, their sums, the spatial tree and
    /// each cell's split clock are kept.
    pub fn restart(&mut self) {
        for cell in self.spatial.data_slice_mut() {
            cell.used = 0;
        }
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

    /// Records dropped as bad input so far: vertices asked for at
    /// non-finite positions in [`DroppedRecords::position`], the rest in
    /// [`DroppedRecords::light`]: non-finite or negative values, emitters out of range or
    /// with zero power, unbounded lights beyond the configured count.
    pub fn dropped_records(&self) -> DroppedRecords {
        self.dropped.snapshot()
    }

    /// Sets the dropped-input counters to zero.
    pub fn reset_dropped_records(&mut self) {
        self.dropped.reset();
    }

    /// Turns what was recorded into the cuts sampled next, cell by cell
    /// (`&mut self`: between passes or tiles, or through
    /// [`SharedGuide`](crate::shared_guide::SharedGuide)).
    ///
    /// A cell takes part once it holds 3/2 of the splats that fell in it
    /// before its last refinement (any, before its first; see
    /// `GltCell`); the others
    /// keep accumulating. A cell that takes part splits while its count is
    /// above `c sqrt(2^g)` (`c` the spatial threshold, `g` the refinements
    /// it took part in, a half taken to have half its parent's splats: PPG's
    /// rule, with the cell's own clock); both halves get a copy of the cut
    /// and its sums, and each the confidence of its share of the records
    /// (`GuidingCut::confidence`). Then its cut is rebuilt from its sums
    /// (`CutRules::refine`; a cut that collected nothing keeps its
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

    /// What every cell learned, as plain-data arrays a GPU kernel samples
    /// ([`crate::snapshot`]): the same light choice as [`Glt::vertex`]'s
    /// up to `f32` rounding. A copy: take another after the next
    /// [`Glt::refine`]. Errors for light sets and instanced light trees,
    /// which a snapshot does not carry. O(cells + cut nodes + lights).
    pub fn snapshot(&self) -> Result<Snapshot, SnapshotError> {
        Snapshot::new(&self.guide, &self.spatial)
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

    /// The one lookup per path vertex: the cell holding `ctx.position`
    /// (clamped onto the root cube), through which light selection and
    /// light records at that point go. `None` for a non-finite position
    /// (counted in [`DroppedRecords::position`]: nothing can be recorded
    /// there).
    #[inline]
    pub fn vertex(&self, ctx: &ShadingContext) -> Option<LightVertex<'_, H>> {
        let Some(v) = self.vertex_uncounted(ctx) else {
            self.dropped.count(DropReason::Position);
            return None;
        };
        Some(v)
    }

    /// [`Glt::vertex`] without counting a non-finite position (for
    /// [`Strategy`](crate::Strategy)'s queries by position).
    #[inline]
    pub(crate) fn vertex_uncounted(&self, ctx: &ShadingContext) -> Option<LightVertex<'_, H>> {
        let at = self.spatial.locate_with_bounds(ctx.position)?;
        let cut = &self.spatial.data(at.0).cut;
        Some(LightVertex::new(&self.guide, cut, ctx, at, self))
    }
}

impl<H: LightHierarchy> LightCells for Glt<H> {
    #[inline]
    fn record_light(&self, at: Located, light: LightId, value: f32) -> RecordOutcome {
        let cells = (&self.spatial, self.config.light_filter, &self.dropped);
        self.guide.record_in_cells(cells, at, light, value)
    }

    #[inline]
    fn dropped(&self) -> &DropCounters {
        &self.dropped
    }
}
