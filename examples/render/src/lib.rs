//! The toy path tracer that measures `guiding`: a small CPU path tracer
//! that uses only the crate's public API (with its `inspect` tier for the
//! research knobs), the way an outside renderer would, to compare
//! light-sampling and guiding methods on code-generated analogues of the
//! paper's scenes. Its binaries: `render` (the main job and every
//! comparison), `light_limit` (the light-selection instrument) and `farm`
//! (render workers that merge what they learned).
//!
//! One concept per file: `cli` (flags), `scenes/` (scene generators),
//! `scene` (scene container, effect declarations), `geometry` + `bvh`
//! (primitives, obvhs ray casting), `materials`, `lights`, `camera`,
//! `rng` (a PCG stream per seed, pass and tile), `integrator` (the path
//! tracer and its training records), `methods` (which crate objects a
//! method uses), `run` (passes, training schedule, combination), `tiles`
//! (pbrt-v3's tile order), `film` (EXR/PNG), `reference` (cache),
//! `metrics`, `report` (JSON records, tables), `json` (reading them back
//! for `--replot`), `crossing` (when a guided curve stays below its
//! counterpart's), `plot` (convergence plots), `sheet` (comparison
//! sheet), `raster` + `text` (the canvas and the font both draw with),
//! `shading_points` (the first non-specular vertices of camera paths),
//! `glt_variant` (a GLT configuration from `key=value` settings, which
//! `light_limit --glt` and `choice_cost --glt` read),
//! `animation` and `frames` (an animated scene and its frames rendered
//! three ways).
#![allow(missing_docs)]

pub mod animation;
pub mod bvh;
pub mod camera;
pub mod cli;
pub mod crossing;
pub mod film;
pub mod frames;
pub mod geometry;
pub mod glt_variant;
pub mod integrator;
pub mod json;
pub mod lights;
pub mod materials;
pub mod methods;
pub mod metrics;
pub mod plot;
pub mod raster;
pub mod reference;
pub mod report;
pub mod rng;
pub mod run;
pub mod scene;
pub mod scenes;
pub mod shading_points;
pub mod sheet;
pub mod text;
pub mod tiles;
