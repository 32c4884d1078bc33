//! The Guiding Light Tree (Hamann, Jung and Dachsbacher, EGSR 2023) for
//! renderers without directional guiding: [`Glt`], one learned cut
//! ([`crate::cut`]) per cell of its own spatial tree, guiding next-event
//! estimation through its [`LightVertex`](crate::LightVertex).
//!
//! The same files as `sd_tree/` and `field/`:
//! - `mod.rs`: [`Glt`], its construction and what it hands out;
//! - `config.rs`: [`GltConfig`];
//! - `cell.rs`: [`GltCell`], a cell's cut and its readiness;
//! - `vertex.rs`: the one lookup per path vertex and where its records go;
//! - `refine.rs`: cells that refine on their own records;
//! - `persist.rs`: saving, loading and merging a GLT;
//! - `memory.rs`: [`GltMemory`].

mod cell;
mod config;
mod memory;
mod persist;
mod refine;
mod vertex;

pub use cell::GltCell;
pub use config::GltConfig;
pub use memory::GltMemory;

use crate::cut::CutRules;
use crate::dropped::{DropCounters, DroppedRecords};
use crate::error::Error;
#[cfg(doc)]
use crate::light_sampler::ShadingContext;
use crate::light_tree::LightHierarchy;
use crate::math::Aabb;
use crate::snapshot::{Snapshot, SnapshotError};
use crate::spatial::BinaryTree;

/// The Guiding Light Tree over its own spatial tree: one learned cut per
/// cell of PPG's binary tree over the scene, sampled by the GLT's sampling
/// rule (see `sampling.rs` and `GuidingCut`).
///
/// Per iteration a renderer locates each path vertex once
/// ([`Glt::vertex`]), samples lights and records what each sample found
/// through the [`LightVertex`](crate::LightVertex) (any number of threads), then calls
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
    pub(super) rules: CutRules<H>,
    pub(super) config: GltConfig,
    pub(super) spatial: BinaryTree<GltCell>,
    pub(super) iteration: u32,
    pub(super) dropped: DropCounters,
}

impl<H: LightHierarchy> Glt<H> {
    /// A GLT over the light hierarchy `light_tree` for shading points inside
    /// `scene` (the scene's geometry bounds; points outside are clamped
    /// onto the spatial tree's cube). One cell with the initial cut.
    /// Errors for an invalid configuration ([`GltConfig::validate`]) and
    /// for empty or non-finite `scene`.
    pub fn new(light_tree: H, scene: Aabb, config: GltConfig) -> Result<Self, Error> {
        config.validate()?;
        let rules = CutRules::new(light_tree, config.cut)?;
        let cell = GltCell::new(rules.new_cut());
        Ok(Self {
            rules,
            config,
            spatial: BinaryTree::new(scene, cell)?,
            iteration: 0,
            dropped: DropCounters::default(),
        })
    }

    /// The light hierarchy.
    pub fn light_tree(&self) -> &H {
        self.rules.light_tree()
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
    pub fn set_light_tree(&mut self, light_tree: H) -> Result<H, Error> {
        let old = self
            .rules
            .set_light_tree(light_tree)
            .map_err(|_| Error::LightTreeShape)?;
        self.restart();
        Ok(old)
    }

    /// The rules every cell's cut is sampled, recorded and refined by (the
    /// light tree, its tables and the [`CutConfig`](crate::CutConfig)).
    pub fn cut_rules(&self) -> &CutRules<H> {
        &self.rules
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

    /// What every cell learned, as plain-data arrays a GPU kernel samples
    /// ([`crate::snapshot`]): the same light choice as [`Glt::vertex`]'s
    /// up to `f32` rounding. A copy: take another after the next
    /// [`Glt::refine`]. Errors for light sets and instanced light trees,
    /// which a snapshot does not carry. O(cells + cut nodes + lights).
    pub fn snapshot(&self) -> Result<Snapshot, SnapshotError> {
        Snapshot::new(&self.rules, &self.spatial)
    }
}
