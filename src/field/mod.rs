//! The guiding field the paper uses: one spatial tree whose cells each hold
//! an SD-tree cell (directional quadtree, statistical weight, BSDF sampling
//! fraction) and a Guiding Light Tree cut, so that one lookup per path
//! vertex serves directional guiding, NEE guiding and both splats.
//!
//! A renderer, at each path vertex `x`:
//! 1. looks the cell up once: [`GuidingField::vertex`] gives a
//!    [`FieldVertex`];
//! 2. samples the next direction from the BSDF or, with probability
//!    `1 - s` ([`FieldVertex::bsdf_fraction`]), from the quadtree
//!    ([`FieldVertex::sample_direction`]), and weighs with
//!    [`FieldVertex::mixture_pdf`];
//! 3. chooses a light for next-event estimation from the cell's cut: the
//!    vertex is a [`LightSampler`] (`sample` / `pmf`);
//! 4. records the direct-light estimate for the light it connected to
//!    ([`FieldVertex::splat_light`], the GLT's record) and, once the path
//!    is done, the incident radiance along the sampled direction
//!    ([`FieldVertex::splat_radiance`], PPG's record), optionally the
//!    fraction sample ([`FieldVertex::record_fraction`]).
//!
//! The same records can be made by position ([`GuidingField::splat_radiance`],
//! [`GuidingField::splat_light`], [`GuidingField::record_fraction`]), and the
//! field itself is a [`LightSampler`] that locates the cell of
//! `ctx.position`. Queries and records take `&self` from any number of
//! threads; [`GuidingField::refine`] takes `&mut self` between iterations.
//!
//! ## Semantics: the SD-tree's and the GLT's, shared
//!
//! Nothing here re-implements either structure: radiance splats, fraction
//! records, the per-cell SD refinement, the spatial filters, the split rule
//! and the dropped-input counting are the SD-tree's own functions run over
//! this field's cells, and light splats, cut sampling and cut refinement
//! are the [`CutRules`]'s. So, fed the same records (and random
//! numbers), the field's spatial tree and quadtrees equal those of an
//! [`SdTree`](crate::sd_tree::SdTree) with the same configuration bit for
//! bit, and each cell's cut equals a cut fed the light splats that landed
//! in that cell (tested in `tests/field.rs`).
//!
//! ## Refinement
//!
//! [`GuidingField::refine`] ends an iteration: per cell, the SD-tree's step
//! (learned fraction, quadtree rebuilt and refined, weight kept for the
//! split rule) and the cut's rebuild from its sums; then PPG's spatial rule
//! splits every cell whose radiance-splat weight exceeds `c * sqrt(2^k)`,
//! giving both children a copy of the quadtree *and* the cut (the paper:
//! "If a spatial cell is subdivided by the PPG refinement we copy its cut
//! to both children"). Light splats do not drive spatial splits: in the
//! paper every path vertex makes a radiance splat, so the SD weight already
//! counts the vertices. Refining the payloads before splitting gives the
//! same children as splitting first (they would refine identical copies)
//! with less work.
//!
//! ```
//! use glam::Vec3;
//! use guiding::field::{FieldConfig, GuidingField};
//! use guiding::light_tree::BuildHeuristic;
//! use guiding::math::Aabb;
//! use guiding::{Emitter, LightId, LightSampler, LightTree, ShadingContext};
//! use rand_core::SeedableRng;
//!
//! let lights = vec![
//!     Emitter::point(Vec3::new(-3.0, 2.0, 0.0), 1.0),
//!     Emitter::point(Vec3::new(3.0, 2.0, 0.0), 1.0),
//! ];
//! let tree = LightTree::build(&lights, BuildHeuristic::default())?;
//! let scene = Aabb::new(Vec3::splat(-4.0), Vec3::splat(4.0));
//! let mut config = FieldConfig::default();
//! config.sd.spatial_threshold = 200.0;
//! let mut field = GuidingField::new(&tree, scene, config)?;
//! let mut rng = rand_pcg::Pcg32::seed_from_u64(1);
//! // Two iterations: the first one's splits make a cell per side, the
//! // second one's cuts learn their side.
//! for _ in 0..2 {
//!     for i in 0..2000 {
//!         let x = Vec3::new((i % 20) as f32 * 0.4 - 3.8, 0.0, 0.0);
//!         let v = field.vertex(x).expect("finite point");
//!         // NEE: the light on the same side contributes, the other is
//!         // occluded.
//!         let ctx = ShadingContext::at(x);
//!         let s = v.sample(&ctx, (i % 7) as f32 / 7.0).expect("lights");
//!         let LightId::Emitter(e) = s.light else { unreachable!() };
//!         let seen = (e == 0) == (x.x < 0.0);
//!         v.splat_light(s.light, if seen { 1.0 / s.pmf } else { 0.0 }, &mut rng);
//!         // Radiance arrives from above.
//!         v.splat_radiance(Vec3::Y, 1.0, 1.0 / (4.0 * core::f32::consts::PI), &mut rng);
//!     }
//!     field.refine();
//! }
//! let v = field.vertex(Vec3::new(-3.0, 0.0, 0.0)).unwrap();
//! let ctx = ShadingContext::at(Vec3::new(-3.0, 0.0, 0.0));
//! assert!(v.pmf(&ctx, LightId::Emitter(0)) > 0.85);
//! assert!(v.direction_pdf(Vec3::Y) > 4.0 * v.direction_pdf(-Vec3::Y));
//! let (dir, pdf) = v.sample_direction([0.3, 0.6]);
//! assert_eq!(pdf, v.direction_pdf(dir));
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

mod cell;
mod config;
mod memory;
mod persist;
mod splat;
mod vertex;

pub use cell::FieldCell;
pub use config::FieldConfig;
pub use memory::FieldMemory;
pub use vertex::FieldVertex;

use crate::dropped::{DropReason, DroppedSplats};
use crate::emitter::ShadingContext;
use crate::error::Error;
use crate::glt::{CutRules, SplatOutcome, octant_of};
use crate::light_sampler::{LightId, LightSample, LightSampler};
use crate::light_tree::LightHierarchy;
use crate::math::Aabb;
use crate::sd_tree::SdState;
use crate::spatial::{BinaryTree, CellId, RefineOutcome, SpatialFilter, SpatialTree};
use glam::Vec3;

/// The paper's guiding field: one spatial tree whose cells hold an SD-tree
/// cell and a guiding cut. See the [module docs](self).
///
/// `H` is the light hierarchy, held as the renderer chooses: owned
/// (`GuidingField<LightTree>`), shared with the scene
/// (`GuidingField<Arc<LightTree>>`) or borrowed (`GuidingField<&LightTree>`).
#[derive(Clone, Debug)]
pub struct GuidingField<H: LightHierarchy> {
    cells: BinaryTree<FieldCell>,
    /// The SD-tree's configuration, iteration count and drop counters.
    sd: SdState,
    guide: CutRules<H>,
    light_filter: SpatialFilter,
}

impl<H: LightHierarchy> GuidingField<H> {
    /// A field over the light hierarchy `lights` for shading points inside
    /// `scene` (the scene's geometry bounds; points outside are clamped
    /// onto the spatial tree's cube): one cell, with a uniform quadtree and
    /// the initial (power prior) cut. Errors for empty or non-finite
    /// bounds, and for an invalid configuration
    /// ([`FieldConfig::validate`]).
    pub fn new(lights: H, scene: Aabb, config: FieldConfig) -> Result<Self, Error> {
        config.validate()?;
        let guide = CutRules::new(lights, config.cut)?;
        let sd = SdState::new(config.sd);
        let cell = FieldCell::new(sd.new_cell(), guide.new_cut());
        Ok(Self {
            cells: BinaryTree::new(scene, cell)?,
            sd,
            guide,
            light_filter: config.light_filter,
        })
    }

    /// The one lookup per path vertex: the cell holding `p` (clamped onto
    /// the root cube), through which all queries and records at `p` go.
    /// `None` for a non-finite `p`.
    #[inline]
    pub fn vertex(&self, p: Vec3) -> Option<FieldVertex<'_, H>> {
        let at = self.cells.locate_with_bounds(p)?;
        Some(FieldVertex::new(self, p, at))
    }

    /// The cell holding `p`, `None` for a non-finite point.
    #[inline]
    pub fn locate(&self, p: Vec3) -> Option<CellId> {
        self.cells.locate(p)
    }

    /// The data of the cell holding `p`.
    #[inline]
    fn cell_at(&self, p: Vec3) -> Option<&FieldCell> {
        self.cells.locate(p).map(|c| self.cells.data(c))
    }

    /// Ends iteration `k = self.iteration()`: per cell, the SD-tree's step
    /// (fraction, quadtree) and the cut's rebuild from its sums (a cut that
    /// collected nothing is kept), then PPG's spatial rule: cells whose
    /// radiance-splat weight exceeds `c * sqrt(2^k)` split, recursively,
    /// within [`SdTreeConfig::max_bytes`](crate::sd_tree::SdTreeConfig::max_bytes)
    /// (counted as [`FieldMemory::capped`]), both children holding copies
    /// of the quadtree, the weight halved, and the cut. Collected sums are
    /// zeroed. Returns what the spatial pass did.
    pub fn refine(&mut self) -> RefineOutcome {
        let guide = &self.guide;
        let outcome = self.sd.refine(
            &mut self.cells,
            |cell| guide.growth(&cell.cut),
            |cell, scale| {
                let cap = scale.and_then(|_| guide.growth(&cell.cut).cap(scale));
                if guide.refine_within(&mut cell.cut, cap) {
                    // Learned from the cell's own light splats.
                    cell.cut.confidence = 1.0;
                }
            },
            FieldCell::share_split,
            FieldCell::heap_bytes,
        );
        for cell in self.cells.data_slice_mut() {
            cell.octants.reset();
        }
        outcome
    }

    /// The configuration.
    pub fn config(&self) -> FieldConfig {
        FieldConfig {
            sd: self.sd.config,
            cut: *self.guide.config(),
            light_filter: self.light_filter,
        }
    }

    /// The light hierarchy.
    pub fn light_tree(&self) -> &H {
        self.guide.light_tree()
    }

    /// The guiding tree every cell's cut is used through.
    pub fn cut_rules(&self) -> &CutRules<H> {
        &self.guide
    }

    /// The spatial tree and its cells.
    pub fn spatial(&self) -> &BinaryTree<FieldCell> {
        &self.cells
    }

    /// How many refinements were made (the `k` of the next split threshold).
    pub fn iteration(&self) -> u32 {
        self.sd.iteration
    }

    /// Number of spatial cells.
    pub fn cell_count(&self) -> usize {
        self.cells.cell_count()
    }

    /// Splats and fraction records dropped for bad input so far, per
    /// reason: radiance splats and fraction records as
    /// [`SdTree::dropped_splats`](crate::sd_tree::SdTree::dropped_splats)
    /// counts them, light splats in [`DroppedSplats::light`] (as
    /// [`Glt::dropped_splats`](crate::glt::Glt::dropped_splats)).
    pub fn dropped_splats(&self) -> DroppedSplats {
        self.sd.dropped.snapshot()
    }

    /// Sets all dropped-input counters to zero.
    pub fn reset_dropped_splats(&mut self) {
        self.sd.dropped.reset();
    }

    /// A light splat through the shared GLT record, counting a drop.
    #[inline]
    fn record_light(
        &self,
        (p, at): (Vec3, Option<(CellId, Aabb)>),
        light: LightId,
        value: f32,
        filter: (SpatialFilter, impl FnOnce() -> Vec3),
    ) -> SplatOutcome {
        let octant = at.map_or(0, |(_, bounds)| octant_of(p, &bounds));
        let outcome = self
            .guide
            .splat_spread(&self.cells, (p, at), light, value, filter, |cell| {
                cell.octants.count(octant);
            });
        if outcome == SplatOutcome::Dropped {
            self.sd.dropped.count(DropReason::Light);
        }
        outcome
    }
}

impl<H: LightHierarchy> LightSampler for GuidingField<H> {
    /// Locates the cell of `ctx.position`, then applies the GLT's sampling
    /// rule with its cut. `None` for a non-finite position.
    #[inline]
    fn sample(&self, ctx: &ShadingContext, u: f32) -> Option<LightSample> {
        self.guide.sample(&self.cell_at(ctx.position)?.cut, ctx, u)
    }

    #[inline]
    fn pmf(&self, ctx: &ShadingContext, light: LightId) -> f32 {
        self.cell_at(ctx.position)
            .map_or(0.0, |cell| self.guide.pmf(&cell.cut, ctx, light))
    }

    fn is_empty(&self) -> bool {
        self.guide.is_empty()
    }

    #[inline]
    fn sample_exact(&self, ctx: &ShadingContext, u: f64) -> Option<(LightId, f64)> {
        self.guide
            .sample_exact(&self.cell_at(ctx.position)?.cut, ctx, u)
    }

    #[inline]
    fn pmf_exact(&self, ctx: &ShadingContext, light: LightId) -> f64 {
        self.cell_at(ctx.position)
            .map_or(0.0, |cell| self.guide.pmf_exact(&cell.cut, ctx, light))
    }

    /// The learned visibility of `light` in the cell of `ctx.position`
    /// (1, without a lookup, when none is learned).
    fn visibility(&self, ctx: &ShadingContext, light: LightId) -> f32 {
        if !self.guide.config().visibility {
            return 1.0;
        }
        self.cell_at(ctx.position)
            .map_or(1.0, |cell| self.guide.visibility(&cell.cut, light))
    }

    /// One lookup and one walk.
    fn sample_with_visibility(&self, ctx: &ShadingContext, u: f32) -> Option<(LightSample, f32)> {
        let cell = self.cell_at(ctx.position)?;
        self.guide.sample_with_visibility(&cell.cut, ctx, u)
    }
}
