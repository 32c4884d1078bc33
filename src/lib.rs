#![doc = include_str!("../README.md")]
//!
//! ## The front
//!
//! Everything a renderer needs is at the crate root:
//! - the lights and the shading point: [`Emitter`] (or your own
//!   [`Emitters`]), [`LightTree`] ([`BuildHeuristic`]), [`ShadingContext`],
//!   [`Aabb`];
//! - choosing lights: the [`LightSampler`] trait (pbrt-v4's
//!   `sample(&ctx, u)` / `pmf(&ctx, light)`, [`LightSample`], [`LightId`]),
//!   the baselines by name ([`Strategy`]: uniform, power, pbrt-v4's light
//!   BVH), the scene's sun and sky ([`UnboundedLights`]); the
//!   [`LightChoice`] trait for a choice fixed at one point (`sample(u)` /
//!   `pmf(light)`: a guide's [`LightVertex`], any sampler's
//!   [`SamplerAt`]), and `sample_with` beside every `u: f32` call for a
//!   renderer holding a [`rand_core`] generator;
//! - the guides: [`Glt`] (lights), [`SdTree`] (directions) and
//!   [`GuidingField`] (both in one spatial tree), each with its
//!   configuration ([`GltConfig`] and [`CutConfig`], [`SdTreeConfig`],
//!   [`FieldConfig`]);
//! - at a path vertex: `vertex(&ctx)` of a guide gives a [`LightVertex`]
//!   (the GLT's), a [`DirectionVertex`] (the SD-tree's) or both
//!   ([`FieldVertex`]), the same two types for every guide, so an
//!   integrator is written once; they sample, evaluate and record, and
//!   every record answers a [`RecordOutcome`];
//! - around the integrator: [`DirectLight`] (what a light sample
//!   contributes and records under pbrt-v4's or pbrt-v3's
//!   [`Convention`]), [`resample`] (resampled light choice),
//!   [`PathRecorder`] (a path's bookkeeping and its radiance records),
//!   [`Iterations`] and [`InverseVarianceCombiner`] (PPG's schedule and
//!   combination), [`SharedGuide`] (render threads sharing a guide that any
//!   of them refines);
//! - errors: [`Error`], [`ConfigError`], [`LoadError`], and the
//!   [`DroppedRecords`] count of bad input;
//! - on a GPU: [`Glt::snapshot`] gives what a GLT learned as plain-data
//!   arrays ([`snapshot::Snapshot`], the one public module), with the
//!   sampling rule over them on the CPU; `gpu/` samples them in WGSL.
//!
//! Each guide owns (or shares, or borrows) its light tree; constructors
//! validate their configuration. The `inspect` feature makes every module
//! public (a cut's nodes, the spatial tree's cells, the quadtrees, the save
//! format's pieces, the research knobs' types): the tests, benchmarks and
//! research examples use it; a renderer does not need it.
//!
//! ## Layers
//!
//! Each module (`src/`) only uses the ones before it: `persist` (the save
//! format's bytes, header and checks; it uses no other module, each
//! structure saves itself with it), `math` (boxes, cones, the sphere map,
//! the exact one-number descent, thread-safe sums), `emitter`,
//! `light_tree`, `spatial` (PPG's binary tree), `error`, `record` and
//! `dropped` (what records answer and count), `light_sampler`, `quadtree`
//! and `sd_tree`, `cut` (the learned cut, its sampling rule, records and
//! refinement), `snapshot` (a trained guide's cuts as plain arrays for GPU
//! kernels, and the sampling rule over them in `f32`), `glt` and `field`
//! (cuts in spatial trees), `schedule`, then
//! for the integrator `strategy`, `path_recorder`, `mis`, `resampling` and
//! `shared_guide`; last `config` and `learned`, the front's two small
//! modules of re-exports. `tests/layers.rs` holds the code to this order.
//!
//! ## Where things are
//!
//! `ARCHITECTURE.md` at the repository's root maps each concept to its
//! file (the GLT's sampling rule is `src/cut/sampling.rs`) and lists the
//! options the crate rejected; docs/design.md gives each decision's
//! reasons and measurements.
//!
//! ## Contracts
//!
//! - `sample` returns exactly the probability `pmf` (or `pdf`) reports for the
//!   same input, and pmfs sum to 1 (or are all 0 when nothing can be sampled).
//! - Queries and records take `&self` and may run from many threads; `refine`
//!   takes `&mut self` between iterations (or `&self` through
//!   [`SharedGuide`]). [`Accumulation::Deterministic`] makes learned state
//!   bit-identical whatever the thread count.
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
//! | a light's power ([`Emitter::power`], [`Emitters::power`]) | its flux, one scalar (the [`luminance`] of an RGB power, or any fixed positive weighting), the same unit for every kind: a point light of intensity `I`, `4 pi I`; a spot light of peak intensity `I`, `4 pi I` too (pbrt-v4's convention: a point light as bright, its cone bounds where it shines; [`Emitter::spot`]); a one-sided Lambertian area light of radiance `L` and area `A`, `pi L A` (two-sided: `2 pi L A`); a sphere of radius `r`, `4 pi^2 r^2 L`; textured emission: the integral of `pi L` over the surface (per side), which the renderer computes from its texture (`tests/textured_emission.rs` checks it is the flux, and that estimates over such powers are unbiased, against brute force) |
//! | a light that should be chosen more (or less) often than its power says | its weight ([`Emitters::weight`], [`Emitter::with_weight`]): every sampler chooses by power times weight (the uniform one by weight), the pmfs say so exactly; a GLT's learned choice follows what arrives, its prior the weights |
//! | sun, sky and other lights with no position | not emitters: [`UnboundedLights`] with their number and the probability they share; `0.25` shared is what the render example uses beside many lights (for the GLT it is only the prior's share and the defensive floor, each cell learns its own); pbrt-v4's fixed choice uses `count / (count + 1)` |
//! | which normal ([`ShadingContext::on_surface`]) | the shading normal, the one in the cosine of the estimate; its sign does not matter; none ([`ShadingContext::at`]) in media |
//! | what a light sample records ([`LightVertex::record_light`]) | [`luminance`]`(Le) * factor` with the [`DirectLight`] factor of its convention: the light's arriving radiance, not times the BSDF and cosine, MIS-weighted and divided by the pdf; [`DirectLight::estimate`] gives the contribution and the record from one call, for pbrt-v4's or pbrt-v3's convention ([`Convention`]) |
//! | random numbers for a record | none: the stochastic box filter (off by default for light records) takes its offset from a hash of the record (`src/spatial/jitter.rs`), so the same records learn the same state on any thread count |
//! | an occluded sample, a light behind the surface, a BSDF that is zero (and the shadow ray skipped) | record 0 or nothing, never a shadow ray for the record's sake: a zero adds nothing to what is learned; it only counts as a sample for the split and refinement rules, which then follow where paths go rather than where light arrives |
//! | when to call `refine` | after each of PPG's doubling iterations ([`Iterations`]); a renderer that renders tiles from a work queue with no tile hook or thread count (pbrt-v3, rs_pbrt): share the guide in a [`SharedGuide`], take its guard per path and call [`SharedGuide::refine_when_due`] after each; the GLT then refines whenever that costs under 2% of the time ([`RefineSchedule::GLT`]), each cell once it holds 3/2 of its records before ([`Glt::refine`]) |
//! | lights that moved or changed power since the last frame (same lights, same order) | [`LightTree::refit`] the guide's tree, then hand it over ([`Glt::set_light_tree`], [`GuidingField::set_light_tree`]): what was learned is kept and every cell refines on the new frame's records; when the refit's drift passes [`LightTree::REBUILD_RATIO`], build a new tree and guide instead. A saved guide loads over any refit of its tree (docs/format.md) |
//! | an object lit by some lights only (light linking) | the emitters' sets ([`Emitter::in_light_sets`], [`Emitters::light_sets`], up to 64) and the point's ([`ShadingContext::lit_by`]); unbounded lights by a per-point mask ([`ShadingContext::lit_by_unbounded`]). Every sampler renormalises exactly over what the point is lit by; with a GLT, keep one per receiver set over the shared tree (measured better than one masked GLT, docs/experiments/light-sets.md) |
//! | many instances of one emissive mesh | one [`LightTree`] per mesh in mesh space, the instances as [`Instance`]s, one [`InstancedLightTree`] (a [`LightHierarchy`] every sampler and the GLT take); emitter ids through [`InstancedLightTree::emitter_id`] and [`InstancedLightTree::locate`] |
//! | the spatial threshold | [`GltConfig::default`]'s, measured for renderers (docs/experiments/tile-order.md) |
//!
//! ## Features
//!
//! - `std` (default): use the standard library. Without it the crate is
//!   `#![no_std]` with `alloc` and uses `libm`.
//! - `inspect`: every module public (the second tier, above).

#![cfg_attr(not(feature = "std"), no_std)]
#![forbid(unsafe_code)]
#![warn(missing_docs)]
// Without `inspect` the modules are private and the second tier's items
// (used by the tests and benchmarks through `inspect`) are unreachable; with
// it every module is public, and the compiler checks what is truly unused.
#![cfg_attr(not(feature = "inspect"), allow(dead_code, unused_imports))]
// Every type in a public signature can be named from the front (the crate
// root and its public modules), so a renderer can write down what a call
// returns. Without `inspect` only the front is public, which this checks.
#![cfg_attr(not(feature = "inspect"), deny(unnameable_types))]

extern crate alloc;

// The crate's modules: private by default, so the crate root's re-exports
// below are the whole front a renderer sees; public with the `inspect`
// feature, which the tests, benchmarks and research examples enable to reach
// the second tier (a cut's nodes, the spatial tree's cells, the quadtrees,
// the save format's pieces). The private declarations are written out (not
// made by the macro) so that tools that find a crate's files by reading its
// `mod` items, such as cargo-mutants, see every module once.
#[cfg(not(feature = "inspect"))]
mod cut;
#[cfg(not(feature = "inspect"))]
mod dropped;
#[cfg(not(feature = "inspect"))]
mod emitter;
#[cfg(not(feature = "inspect"))]
mod error;
#[cfg(not(feature = "inspect"))]
mod field;
#[cfg(not(feature = "inspect"))]
mod glt;
#[cfg(not(feature = "inspect"))]
mod light_sampler;
#[cfg(not(feature = "inspect"))]
mod light_tree;
#[cfg(not(feature = "inspect"))]
mod math;
#[cfg(not(feature = "inspect"))]
mod mis;
#[cfg(not(feature = "inspect"))]
mod path_recorder;
#[cfg(not(feature = "inspect"))]
mod persist;
#[cfg(not(feature = "inspect"))]
mod quadtree;
#[cfg(not(feature = "inspect"))]
mod record;
#[cfg(not(feature = "inspect"))]
mod resampling;
#[cfg(not(feature = "inspect"))]
mod schedule;
#[cfg(not(feature = "inspect"))]
mod sd_tree;
#[cfg(feature = "std")]
#[cfg(not(feature = "inspect"))]
mod shared_guide;
#[cfg(not(feature = "inspect"))]
mod spatial;
#[cfg(not(feature = "inspect"))]
mod strategy;

/// The same modules, public: the `inspect` tier.
macro_rules! inspect_tier {
    ($($(#[$attr:meta])* $name:ident;)*) => {
        $(
            $(#[$attr])*
            #[cfg(feature = "inspect")]
            pub mod $name;
        )*
    };
}

// Always public, each a small module of its own: the configuration's
// knobs, what a guide learned (to read), and a trained guide's light choice
// as plain-data arrays for GPU kernels with its sampling rule over them.
pub mod config;
pub mod learned;
pub mod snapshot;

inspect_tier! {
    cut;
    dropped;
    emitter;
    error;
    field;
    glt;
    light_sampler;
    light_tree;
    math;
    mis;
    path_recorder;
    persist;
    quadtree;
    record;
    resampling;
    schedule;
    sd_tree;
    #[cfg(feature = "std")]
    shared_guide;
    spatial;
    strategy;
}

/// The vector types of the public API (`Vec3`, ...): glam 0.34, re-exported
/// so a renderer on another glam version names the crate's own.
pub use glam;

/// The random-generator traits (rand_core 0.10), re-exported so a renderer
/// on another version names the crate's own: the `*_with` conveniences
/// ([`LightChoice::sample_with`], [`LightSampler::sample_with`],
/// [`DirectionVertex::sample_direction_with`]) draw their numbers from any
/// [`rand_core::Rng`].
pub use rand_core;

// The lights and the shading point.
pub use emitter::{Emitter, Emitters};
pub use light_tree::{
    BuildError, BuildHeuristic, EmitterPath, Instance, InstancedLightTree, LightHierarchy,
    LightTree, NodeBounds,
};
pub use math::{Aabb, Accumulation, LightCone, Side, luminance};
// Choosing lights.
pub use light_sampler::{
    ImportanceTreeSampler, LightChoice, LightId, LightSample, LightSampler, PowerSampler,
    PowerTreeSampler, SamplerAt, ShadingContext, UnboundedLights, UniformSampler, WithUnbounded,
};
pub use strategy::Strategy;
// The guides, their configurations and their vertices.
pub use cut::{CutConfig, LightVertex};
pub use field::{FieldConfig, FieldVertex, GuidingField};
pub use glt::{Glt, GltConfig};
pub use quadtree::{DirectionalFilter, QuadtreeConfig};
pub use sd_tree::{DirectionVertex, SdTree, SdTreeConfig};
pub use spatial::{RefineOutcome, SpatialFilter};
// What a renderer records and computes with them.
pub use dropped::DroppedRecords;
pub use mis::{Convention, DirectEstimate, DirectLight};
pub use path_recorder::{PathRecorder, PathSegment};
pub use record::RecordOutcome;
pub use resampling::{BsdfCandidate, Evaluated, Resampled, resample};
pub use schedule::{InverseVarianceCombiner, Iteration, Iterations, PassStats};
#[cfg(feature = "std")]
pub use shared_guide::{Refine, RefineSchedule, SharedGuide};
// Errors.
pub use error::{ConfigError, Error};
pub use persist::LoadError;
pub use spatial::SpatialError;
