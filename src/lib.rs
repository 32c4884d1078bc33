#![doc = include_str!("../README.md")]
//!
//! ## Layers
//!
//! Each module only uses the ones above it:
//! 1. [`math`]: boxes, cones, the sphere map, the exact one-number
//!    descent (`src/math/descent.rs`), thread-safe sums (`src/math/sum.rs`);
//! 2. [`emitter`]: the [`Emitters`] trait and [`ShadingContext`];
//! 3. [`light_tree`]: [`LightHierarchy`] and the [`LightTree`] BVH;
//! 4. [`light_sampler`]: [`LightSampler`] and its baselines;
//! 5. [`spatial`]: the spatial tree trait and PPG's binary tree;
//! 6. [`quadtree`] and [`sd_tree`]: PPG's directional quadtree and SD-tree;
//! 7. [`glt`]: the Guiding Light Tree, itself a [`LightSampler`];
//! 8. [`field`]: one spatial tree holding a quadtree and a cut per cell, as
//!    the paper uses them; [`schedule`]: PPG's iteration schedule and the
//!    inverse-variance combination of the last iterations;
//! 9. for the integrator: [`Strategy`] (a light sampler by name),
//!    [`PathRecorder`] (a path's bookkeeping and its records) and [`mis`]
//!    (the MIS heuristics, and what a direct-light sample contributes and
//!    records under pbrt-v4's or pbrt-v3's convention); with `std`,
//!    [`shared_guide`] (a guide the render threads share and any of them
//!    refines, through `&self`);
//! 10. [`persist`]: saving, loading and merging what was learned.
//!
//! Each of [`sd_tree::SdTree`], [`glt::Glt`] and [`field::GuidingField`]
//! locates a path vertex once with `vertex(&ctx)` and answers and records
//! through what it gives: a [`DirectionVertex`] (the SD-tree's), a
//! [`LightVertex`] (the GLT's) or both ([`FieldVertex`]), the same two
//! types for every structure, so an integrator is written once; every
//! record answers a [`RecordOutcome`]. Each owns (or shares, or borrows)
//! its light tree; constructors validate their configuration ([`Error`]).
//!
//! ## Where things are
//!
//! | what | file |
//! | --- | --- |
//! | the GLT's sampling rule and pmf | `src/glt/sampling.rs` |
//! | resampled light choice (candidates, reservoir, weight) | `src/resampling.rs` |
//! | each cut cluster's learned visibility (the resampling target's factor) | `src/glt/visibility.rs` |
//! | the light tree laid out for the GLT's walk | `src/glt/walk.rs` |
//! | cut refinement (split / merge by sigma, `min_splats`) | `src/glt/refine.rs` |
//! | the tables every cut reads (`CutRules`) | `src/glt/cut_rules.rs` |
//! | a path's radiance records | `src/path_recorder.rs` |
//! | the save format and its checks | `src/persist/`, `docs/format.md` |
//! | light-tree build heuristics | `src/light_tree/build.rs` |
//! | the importance of a light cluster | `src/light_sampler/importance.rs` |
//! | the same, from decoded nodes in `f32` (the GLT's importance rules) | `src/light_sampler/importance_table.rs` |
//! | the one-number descent | `src/math/descent.rs` |
//! | quadtree sampling and pdf | `src/quadtree/query.rs` |
//!
//! ## Contracts
//!
//! - `sample` returns exactly the probability `pmf` (or `pdf`) reports for the
//!   same input, and pmfs sum to 1 (or are all 0 when nothing can be sampled).
//! - Queries and records take `&self` and may run from many threads; `refine`
//!   takes `&mut self` between iterations (or `&self` through
//!   [`shared_guide::SharedGuide`]). [`math::Accumulation::Deterministic`]
//!   makes learned state bit-identical whatever the thread count.
//! - Bad input never panics: builds return typed errors, records drop and
//!   count it ([`DroppedRecords`]); invalid configuration is an error, never
//!   a silent clamp.
//!
//! ## What a renderer passes and records
//!
//! Each convention a renderer has to choose when it wires the crate in,
//! answered once (the render example follows every one):
//!
//! | question | answer |
//! | --- | --- |
//! | a light's power ([`Emitter::power`], [`Emitters::power`]) | its flux, one scalar (the luminance of an RGB power, or any fixed positive weighting), the same unit for every kind: a point light of intensity `I`, `4 pi I`; a spot light of peak intensity `I`, `4 pi I` too (pbrt-v4's convention: a point light as bright, its cone bounds where it shines; [`Emitter::spot`]); a one-sided Lambertian area light of radiance `L` and area `A`, `pi L A` (two-sided: `2 pi L A`); a sphere of radius `r`, `4 pi^2 r^2 L`; textured emission: the integral of `pi L` over the surface (per side) |
//! | sun, sky and other lights with no position | not emitters: [`UnboundedLights`] with their number and the probability they share; `0.25` shared is what the render example uses beside many lights (for the GLT it is only the prior's share and the defensive floor, each cell learns its own); pbrt-v4's fixed choice uses `count / (count + 1)` |
//! | which normal ([`ShadingContext::on_surface`]) | the shading normal, the one in the cosine of the estimate; its sign does not matter; none ([`ShadingContext::at`]) in media |
//! | what a light sample records ([`LightVertex::record_light`]) | `luminance(Le) * factor` with the [`mis::DirectLight`] factor of its convention: the light's arriving radiance, not times the BSDF and cosine, MIS-weighted and divided by the pdf; [`mis::DirectLight::estimate`] gives the contribution and the record from one call, for pbrt-v4's or pbrt-v3's convention ([`mis::Convention`]) |
//! | random numbers for a record | none: the stochastic box filter (off by default for light records) takes its offset from a hash of the record (`src/spatial/jitter.rs`), so the same records learn the same state on any thread count |
//! | an occluded sample, a light behind the surface, a BSDF that is zero (and the shadow ray skipped) | record 0 or nothing, never a shadow ray for the record's sake: a zero adds nothing to what is learned; it only counts as a sample for the split and refinement rules, which then follow where paths go rather than where light arrives ([`schedule`]) |
//! | when to call `refine` | after each of PPG's doubling iterations ([`schedule::Iterations`]); a renderer that renders each tile to completion, after every wave of tiles (as many as it has threads): a GLT cell refines once it holds 3/2 of its records before ([`glt::GltCell`], [`schedule`]) |
//! | the spatial threshold | [`glt::GltConfig::default`]'s, measured for renderers (docs/experiments/tile-order.md) |
//!
//! ## Features
//!
//! - `std` (default): use the standard library. Without it the crate is
//!   `#![no_std]` with `alloc` and uses `libm`.

#![cfg_attr(not(feature = "std"), no_std)]
#![forbid(unsafe_code)]
#![warn(missing_docs)]

extern crate alloc;

mod dropped;
pub mod emitter;
pub mod error;
pub mod field;
pub mod glt;
pub mod light_sampler;
pub mod light_tree;
pub mod math;
pub mod mis;
pub mod path_recorder;
pub mod persist;
pub mod quadtree;
mod record;
pub mod resampling;
pub mod schedule;
pub mod sd_tree;
#[cfg(feature = "std")]
pub mod shared_guide;
pub mod spatial;
mod strategy;

/// The vector types of the public API (`Vec3`, ...): glam 0.34, re-exported
/// so a renderer on another glam version names the crate's own.
pub use glam;
/// The random-number trait that filtered records take (`RngCore`):
/// rand_core 0.10, re-exported so a renderer on another version can wrap
/// its generator in this one's trait.
pub use rand_core;

pub use dropped::DroppedRecords;
pub use emitter::{Emitter, Emitters, ShadingContext};
pub use error::{ConfigError, Error};
pub use field::FieldVertex;
pub use glt::LightVertex;
pub use light_sampler::{
    ImportanceTreeSampler, LightId, LightSample, LightSampler, PowerSampler, PowerTreeSampler,
    UnboundedLights, UniformSampler, WithUnbounded,
};
pub use light_tree::{LightHierarchy, LightTree};
pub use path_recorder::PathRecorder;
pub use persist::LoadError;
pub use record::RecordOutcome;
pub use sd_tree::DirectionVertex;
pub use strategy::Strategy;
