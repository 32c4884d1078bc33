//! The guiding field the paper uses: one spatial tree whose cells each hold
//! an SD-tree cell (directional quadtree, statistical weight, BSDF sampling
//! fraction) and a Guiding Light Tree cut, so that one lookup per path
//! vertex serves directional guiding, NEE guiding and both records.
//!
//! A renderer, at each path vertex `x`:
//! 1. looks the cell up once: [`GuidingField::vertex`] gives a
//!    [`FieldVertex`], its [`direction`](FieldVertex::direction) and its
//!    [`light`](FieldVertex::light) part;
//! 2. samples the next direction from the BSDF or, with probability
//!    `1 - s` ([`DirectionVertex::bsdf_fraction`]), from the quadtree
//!    ([`DirectionVertex::sample_direction`]), and weighs with
//!    [`DirectionVertex::mixture_pdf`];
//! 3. chooses a light for next-event estimation from the cell's cut: the
//!    light part is a [`LightChoice`](crate::LightChoice) (`sample(u)` /
//!    `pmf(light)`, the context given once at the lookup);
//! 4. records the direct-light estimate for the light it connected to
//!    ([`LightVertex::record_light`], the GLT's record) and, once the path
//!    is done, the incident radiance along the sampled direction
//!    ([`DirectionVertex::record_radiance`], PPG's record), optionally the
//!    fraction sample ([`DirectionVertex::record_fraction`]).
//!
//! The two parts are the same types an [`SdTree`](crate::SdTree)
//! and a [`Glt`](crate::Glt) give, so one integrator serves all three.
//! Queries and records take `&self` from any number of threads;
//! [`GuidingField::refine`] takes `&mut self` between iterations.
//!
//! [`DirectionVertex::bsdf_fraction`]: crate::DirectionVertex::bsdf_fraction
//! [`DirectionVertex::sample_direction`]: crate::DirectionVertex::sample_direction
//! [`DirectionVertex::mixture_pdf`]: crate::DirectionVertex::mixture_pdf
//! [`DirectionVertex::record_radiance`]: crate::DirectionVertex::record_radiance
//! [`DirectionVertex::record_fraction`]: crate::DirectionVertex::record_fraction
//! [`LightVertex::record_light`]: crate::LightVertex::record_light
//!
//! ## Semantics: the SD-tree's and the GLT's, shared
//!
//! Nothing here re-implements either structure: radiance records, fraction
//! records, the per-cell SD refinement, the spatial filters, the split rule
//! and the dropped-input counting are the SD-tree's own functions run over
//! this field's cells, and light records, cut sampling and cut refinement
//! are the [`CutRules`]'s. So, fed the same records (and random
//! numbers), the field's spatial tree and quadtrees equal those of an
//! [`SdTree`](crate::SdTree) with the same configuration bit for
//! bit, and each cell's cut equals a cut fed the light records that landed
//! in that cell (tested in `tests/field.rs`).
//!
//! ## Refinement
//!
//! [`GuidingField::refine`] ends an iteration: per cell, the SD-tree's step
//! (learned fraction, quadtree rebuilt and refined, weight kept for the
//! split rule) and the cut's rebuild from its sums; then PPG's spatial rule
//! splits every cell whose radiance-record weight exceeds `c * sqrt(2^k)`,
//! giving both children a copy of the quadtree *and* the cut (the paper:
//! "If a spatial cell is subdivided by the PPG refinement we copy its cut
//! to both children"). Light records do not drive spatial splits: in the
//! paper every path vertex makes a radiance record, so the SD weight already
//! counts the vertices. Refining the payloads before splitting gives the
//! same children as splitting first (they would refine identical copies)
//! with less work.
//!
//! ```
//! use glam::Vec3;
//! use guiding::{Aabb, BuildHeuristic, Emitter, FieldConfig, GuidingField, LightChoice};
//! use guiding::{LightId, LightTree, ShadingContext};
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
//! // Two iterations: the first one's splits make a cell per side, the
//! // second one's cuts learn their side.
//! for _ in 0..2 {
//!     for i in 0..2000 {
//!         let x = Vec3::new((i % 20) as f32 * 0.4 - 3.8, 0.0, 0.0);
//!         let ctx = ShadingContext::at(x);
//!         let v = field.vertex(&ctx).expect("finite point");
//!         // NEE: the light on the same side contributes, the other is
//!         // occluded.
//!         let s = v.light.sample((i % 7) as f32 / 7.0).expect("lights");
//!         let LightId::Emitter(e) = s.light else { unreachable!() };
//!         let seen = (e == 0) == (x.x < 0.0);
//!         v.light.record_light(s.light, if seen { 1.0 / s.pmf } else { 0.0 });
//!         // Radiance arrives from above.
//!         v.direction.record_radiance(Vec3::Y, 1.0, 1.0 / (4.0 * core::f32::consts::PI));
//!     }
//!     field.refine();
//! }
//! let ctx = ShadingContext::at(Vec3::new(-3.0, 0.0, 0.0));
//! let v = field.vertex(&ctx).unwrap();
//! assert!(v.light.pmf(LightId::Emitter(0)) > 0.85);
//! let d = v.direction;
//! assert!(d.direction_pdf(Vec3::Y) > 4.0 * d.direction_pdf(-Vec3::Y));
//! let (dir, pdf) = d.sample_direction([0.3, 0.6]);
//! assert_eq!(pdf, d.direction_pdf(dir));
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
//!
//! The same files as `glt/` and `sd_tree/`:
//! - `mod.rs`: [`GuidingField`], its construction and what it hands out;
//! - `config.rs`: [`FieldConfig`];
//! - `cell.rs`: [`FieldCell`], an SD-tree cell and a cut;
//! - `vertex.rs`: the one lookup per path vertex ([`FieldVertex`]) and
//!   where its two kinds of records go;
//! - `refine.rs`: both refinements in one pass over the cells;
//! - `persist.rs`: saving, loading and merging a field;
//! - `memory.rs`: [`FieldMemory`].

mod cell;
mod config;
mod memory;
mod persist;
mod refine;
mod vertex;

pub use cell::FieldCell;
pub use config::FieldConfig;
pub use memory::FieldMemory;
pub use vertex::FieldVertex;

use crate::cut::CutRules;
use crate::dropped::DroppedRecords;
use crate::error::Error;
use crate::light_tree::LightHierarchy;
use crate::math::Aabb;
use crate::sd_tree::SdState;
use crate::snapshot::{Snapshot, SnapshotError};
use crate::spatial::{BinaryTree, SpatialFilter, SpatialTree};

/// The paper's guiding field: one spatial tree whose cells hold an SD-tree
/// cell and a guiding cut. See the module docs.
///
/// `H` is the light hierarchy, held as the renderer chooses: owned
/// (`GuidingField<LightTree>`), shared with the scene
/// (`GuidingField<Arc<LightTree>>`) or borrowed (`GuidingField<&LightTree>`).
#[derive(Clone, Debug)]
pub struct GuidingField<H: LightHierarchy> {
    spatial: BinaryTree<FieldCell>,
    /// The SD-tree's configuration, iteration count and drop counters.
    sd: SdState,
    rules: CutRules<H>,
    light_filter: SpatialFilter,
}

impl<H: LightHierarchy> GuidingField<H> {
    /// A field over the light hierarchy `light_tree` for shading points inside
    /// `scene` (the scene's geometry bounds; points outside are clamped
    /// onto the spatial tree's cube): one cell, with a uniform quadtree and
    /// the initial (power prior) cut. Errors for empty or non-finite
    /// bounds, and for an invalid configuration
    /// ([`FieldConfig::validate`]).
    pub fn new(light_tree: H, scene: Aabb, config: FieldConfig) -> Result<Self, Error> {
        config.validate()?;
        let rules = CutRules::new(light_tree, config.cut)?;
        let sd = SdState::new(config.sd);
        let cell = FieldCell::new(sd.new_cell(), rules.new_cut());
        Ok(Self {
            spatial: BinaryTree::new(scene, cell)?,
            sd,
            rules,
            light_filter: config.light_filter,
        })
    }

    /// The configuration.
    pub fn config(&self) -> FieldConfig {
        FieldConfig {
            sd: self.sd.config,
            cut: *self.rules.config(),
            light_filter: self.light_filter,
        }
    }

    /// The light hierarchy.
    pub fn light_tree(&self) -> &H {
        self.rules.light_tree()
    }

    /// Hands the field its light tree after a refit and returns the one it
    /// held, keeping everything learned, as
    /// [`Glt::set_light_tree`](crate::Glt::set_light_tree) does (the
    /// directional quadtrees are untouched). [`Error::LightTreeShape`] for
    /// a tree of another shape, and nothing changes.
    pub fn set_light_tree(&mut self, light_tree: H) -> Result<H, Error> {
        self.rules
            .set_light_tree(light_tree)
            .map_err(|_| Error::LightTreeShape)
    }

    /// Every cell's learned light choice as plain-data arrays a GPU
    /// kernel samples ([`crate::snapshot`], as
    /// [`Glt::snapshot`](crate::Glt::snapshot)); the directional half
    /// (the SD-trees) is not in it.
    pub fn snapshot(&self) -> Result<Snapshot, SnapshotError> {
        Snapshot::new(&self.rules, &self.spatial)
    }

    /// The rules every cell's cut is sampled, recorded and refined by (the
    /// light tree, its tables and the [`CutConfig`](crate::CutConfig)).
    pub fn cut_rules(&self) -> &CutRules<H> {
        &self.rules
    }

    /// The spatial tree and its cells.
    pub fn spatial(&self) -> &BinaryTree<FieldCell> {
        &self.spatial
    }

    /// How many refinements were made (the `k` of the next split threshold).
    pub fn iteration(&self) -> u32 {
        self.sd.iteration
    }

    /// Number of spatial cells.
    pub fn cell_count(&self) -> usize {
        self.spatial.cell_count()
    }

    /// Radiance and fraction records dropped for bad input so far, per
    /// reason: radiance records and fraction records as
    /// [`SdTree::dropped_records`](crate::SdTree::dropped_records)
    /// counts them, light records in [`DroppedRecords::light`] (as
    /// [`Glt::dropped_records`](crate::Glt::dropped_records)).
    pub fn dropped_records(&self) -> DroppedRecords {
        self.sd.dropped.snapshot()
    }

    /// Sets all dropped-input counters to zero.
    pub fn reset_dropped_records(&mut self) {
        self.sd.dropped.reset();
    }
}
