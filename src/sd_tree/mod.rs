//! The SD-tree of Practical Path Guiding (Müller et al. 2017): a spatial
//! binary tree ([`BinaryTree`]) whose cells ([`SdCell`]) hold directional
//! quadtrees ([`DirectionalTree`](crate::learned::DirectionalTree)).
//!
//! A renderer, at each path vertex, locates it once ([`SdTree::vertex`]) and
//! through the [`DirectionVertex`]:
//! - samples a direction with [`DirectionVertex::sample_direction`] (with
//!   probability `1 - s`, `s =` [`DirectionVertex::bsdf_fraction`]) or its
//!   BSDF, and weighs with [`DirectionVertex::mixture_pdf`];
//! - once the path is done, records the incident radiance it found along the
//!   sampled direction with [`DirectionVertex::record_radiance`]
//!   ([`PathRecorder`](crate::PathRecorder) does the bookkeeping);
//! - optionally reports the sample to the fraction learner with
//!   [`DirectionVertex::record_fraction`].
//!
//! Between iterations it calls [`SdTree::refine`]. Queries and records take
//! `&self` and may run from many threads; `refine` takes `&mut self`.
//!
//! ## What a radiance record records
//!
//! `record_radiance(dir, radiance, pdf)` is PPG's record: the directional
//! quadtree of the cell receives `radiance / pdf` (an estimate of the
//! irradiance-like integral that makes the learned density proportional to
//! incident radiance), and the cell's statistical weight grows by 1, the
//! count the spatial split rule uses. `radiance` is one number (luminance,
//! or any scalar); `pdf` is the solid-angle pdf with which `dir` was sampled
//! (the mixture's, as PPG). With the box filter each overlapped cell gets
//! the overlapped fraction of the box volume of both. Radiance 0 is valid:
//! it adds weight and no power. Invalid input is dropped, counted per
//! reason ([`SdTree::dropped_records`]) and never stored:
//! a NaN, infinite or zero-length direction, a NaN,
//! infinite or negative radiance, a zero, negative or non-finite pdf, or
//! `radiance / pdf` overflowing `f32`. Nothing panics.
//!
//! ## Refinement
//!
//! After iteration `k` (`k` = number of refinements so far),
//! [`SdTree::refine`] (1) optimises each cell's learned fraction from the
//! iteration's statistics, (2) turns each cell's building quadtree into its
//! sampling quadtree and refines the building topology (PPG's `rho` rule),
//! (3) splits every cell whose statistical weight exceeds
//! `c * sqrt(2^k)` (`c` = [`SdTreeConfig::spatial_threshold`]), copying
//! the cell to both children with the weight halved and asking the children
//! again, within [`SdTreeConfig::max_bytes`]. PPG splits before it refines
//! the quadtrees; both children then refine identical copies, so refining
//! first gives the same trees with less work. Children also inherit the
//! learned fraction and its optimiser state. (4) Collected sums are zeroed.
//!
//! ## The learned BSDF sampling fraction
//!
//! With [`SdTreeConfig::learn_bsdf_fraction`], each cell learns
//! `s = logistic(theta)` by minimising the KL divergence from the product
//! `f = |f_s cos| L_i` to the mixture `s p_bsdf + (1 - s) p_guide` with Adam
//! (learning rate 0.01, betas 0.9 / 0.999, `theta` clamped to `+-20`), as in
//! Müller's 2019 production notes.
//!
//! *Design.* The fraction that queries read is fixed for a whole iteration
//! and changes only in `refine` (`&mut self`), so sampling never races with
//! learning and needs no atomics or locks. The public implementation takes
//! one Adam step per sample, serialised per cell, with the gradient at the
//! current `s`; here the work at record time is only adding to
//! thread-safe sums (`src/math/sum.rs`): per cell a histogram of `log(p_bsdf / p_guide)` (14 bins) holding `sum f/q` and
//! `sum (f/q) r` with `r = p_bsdf / (p_bsdf + p_guide)`. That histogram
//! describes the iteration's Monte Carlo estimate of the loss at *every*
//! `s` (see `fraction.rs`), so `refine` runs up to
//! [`SdTreeConfig::fraction_steps`] full-batch Adam steps on it (at most one
//! per recorded sample, like the per-sample original). In `Deterministic`
//! mode the sums are exact integers and the Adam steps run sequentially in
//! `f64`, so the learned `theta` is bit-identical whatever the thread count.
//!
//! *Convergence.* An Adam step moves `theta` by at most about the learning
//! rate, so one refinement moves it by at most about `0.01 * steps` (2.56
//! with the default 256 steps; `s` from 0.5 to 0.93). On a fixed batch
//! full-batch Adam converges to the batch's optimum and then oscillates
//! within about the learning rate around it; as iterations double their
//! sample counts the batch optimum converges to the true one, and the Adam
//! moments carry over between iterations. Binning replaces each sample's
//! `r` by its bin's weighted mean; with unit-wide log-ratio bins the loss
//! barely curves within a bin: over 40 simulated random log-ratio
//! distributions the binned optimum stayed within 0.03 (absolute, in `s`)
//! of the exact one. The per-sample original instead follows the noisy
//! gradient of whichever samples arrive, in arrival order (not
//! reproducible), with steps concentrated where samples are.
//!
//! ```
//! use guiding::{Aabb, RecordOutcome, SdTree, SdTreeConfig, ShadingContext};
//! use glam::Vec3;
//!
//! let scene = Aabb::new(Vec3::splat(-1.0), Vec3::splat(1.0));
//! let mut tree = SdTree::new(scene, SdTreeConfig { spatial_threshold: 100.0, ..Default::default() })?;
//! for i in 0..1000 {
//!     let ctx = ShadingContext::at(Vec3::new((i % 10) as f32 * 0.2 - 0.9, 0.0, 0.0));
//!     let v = tree.vertex(&ctx).expect("a finite point");
//!     // Radiance 1 arriving from +z, sampled with pdf 1 / (4 pi).
//!     v.record_radiance(Vec3::Z, 1.0, 1.0 / (4.0 * core::f32::consts::PI));
//! }
//! let origin = ShadingContext::at(Vec3::ZERO);
//! let v = tree.vertex(&origin).unwrap();
//! assert_eq!(v.record_radiance(Vec3::Z, f32::NAN, 1.0), RecordOutcome::Dropped);
//! tree.refine();
//! assert!(tree.cell_count() > 1);
//! let v = tree.vertex(&origin).unwrap();
//! let (dir, pdf) = v.sample_direction([0.5, 0.5]);
//! assert_eq!(pdf, v.direction_pdf(dir));
//! assert!(v.direction_pdf(Vec3::Z) > 10.0 * v.direction_pdf(-Vec3::Z));
//! assert_eq!(tree.dropped_records().radiance, 1);
//! # Ok::<(), guiding::Error>(())
//! ```
//!
//! The same files as `glt/` and `field/`, and three of its own:
//! - `mod.rs`: [`SdTree`], its construction and what it hands out;
//! - `config.rs`: [`SdTreeConfig`];
//! - `cell.rs`: [`SdCell`], a cell's quadtree, weight and fraction;
//! - `vertex.rs`: the one lookup per path vertex ([`DirectionVertex`]) and
//!   where its records go;
//! - `refine.rs`: PPG's spatial and directional refinement;
//! - `persist.rs`: saving, loading and merging an SD-tree;
//! - `memory.rs`: [`SdTreeMemory`];
//! - `record.rs`, `validate.rs`, `state.rs`: the radiance and fraction
//!   records, what they drop, and the state an SD-tree and a guiding field
//!   share (configuration, iteration, drop counters);
//! - `fraction.rs`: the learned BSDF sampling fraction.

mod cell;
mod config;
mod fraction;
mod memory;
mod persist;
mod record;
mod refine;
mod state;
mod validate;
mod vertex;

pub use cell::SdCell;
pub use config::SdTreeConfig;
pub use memory::SdTreeMemory;
pub(crate) use state::SdState;
pub use vertex::DirectionVertex;
pub(crate) use vertex::RadianceCells;

use crate::dropped::DroppedRecords;
use crate::error::Error;
use crate::math::Aabb;
use crate::spatial::BinaryTree;

/// Practical Path Guiding's SD-tree. See the module docs.
#[derive(Clone, Debug)]
pub struct SdTree {
    spatial: BinaryTree<SdCell>,
    state: SdState,
}

impl SdTree {
    /// One cell over the cube around `scene` (flat and point scenes are
    /// padded), sampling uniformly. Errors for an invalid configuration
    /// ([`SdTreeConfig::validate`]) and for empty or non-finite bounds.
    pub fn new(scene: Aabb, config: SdTreeConfig) -> Result<Self, Error> {
        config.validate()?;
        let state = SdState::new(config);
        Ok(Self {
            spatial: BinaryTree::new(scene, state.new_cell())?,
            state,
        })
    }

    /// The spatial tree and its cells.
    #[inline]
    pub fn spatial(&self) -> &BinaryTree<SdCell> {
        &self.spatial
    }

    /// The configuration.
    #[inline]
    pub fn config(&self) -> &SdTreeConfig {
        &self.state.config
    }

    /// How many refinements were made (the `k` of the next split threshold).
    #[inline]
    pub fn iteration(&self) -> u32 {
        self.state.iteration
    }

    /// Number of spatial cells.
    #[inline]
    pub fn cell_count(&self) -> usize {
        self.spatial.data_slice().len()
    }

    /// Radiance and fraction records dropped for bad input so far, per reason.
    pub fn dropped_records(&self) -> DroppedRecords {
        self.state.dropped.snapshot()
    }

    /// Sets the dropped-input counters to zero.
    pub fn reset_dropped_records(&mut self) {
        self.state.dropped.reset();
    }
}
