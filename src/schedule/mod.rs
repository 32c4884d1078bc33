//! Iteration schedule of guided rendering and the inverse-variance
//! combination of its last iterations, as in Practical Path Guiding.
//!
//! Renderer-agnostic: nothing here knows pixels or colours, only slices of
//! `f32` (any number of channels, flattened) and pass counts.
//!
//! - [`Iterations`] plans how many passes each training iteration renders:
//!   iteration `k` gets `2^k` passes, and when the rest of the budget could
//!   not pay for the iteration after, the current one becomes the last and
//!   takes all that is left, so the last iteration always renders at least
//!   half of the budget. [`next_iteration_by_time`] makes the same decision
//!   from a time budget and a measured time per pass.
//! - [`PassStats`] collects the per-pass images of one iteration (running
//!   mean and squared deviations per element, in `f64`) and gives the
//!   iteration's image with an *unbiased* estimate of its variance: the
//!   sample variance of the per-pass values divided by the pass count,
//!   `sum (x_i - mean)^2 / (n (n - 1))`. PPG's estimator uses the second
//!   moment where the variance belongs and so overestimates by `mean^2 / n`,
//!   which penalises bright images and young iterations; the per-pass sample
//!   variance has no such term, and because whole passes are the samples it
//!   stays unbiased when the samples inside a pass are stratified or QMC.
//! - [`InverseVarianceCombiner`] keeps the last (up to) four iterations and
//!   blends them with weights `1 / variance`, normalised to sum to 1.
//!
//! ## Renderers that render in one pass
//!
//! A progressive renderer (one image, refined sample round by sample
//! round, no separate training pass) follows the same plan with its own
//! rounds: render round after round into the current iteration's
//! [`PassStats`], recording into the guiding structure as it goes; when the
//! iteration's passes are done, call `refine()` (the one `&mut` step,
//! between rounds, while no thread records), hand the iteration's image to
//! the combiner and start the next iteration. A renderer whose thread pool
//! renders all its samples at once, with no point where the main thread
//! holds `&mut`, shares the structure through
//! `shared_guide::SharedGuide` (`std`): workers take it per tile, and the
//! worker that completes an iteration's last tile calls its `refine(&self)`,
//! which waits for the tiles in flight to end. Every round's image is an
//! unbiased estimate whatever the guide learned, so the combination of the
//! last iterations is the image at any moment. A tile-based renderer does
//! the same with "all tiles of one round" as its pass. Records of the last
//! iteration are not needed (nothing refines after it): stop recording
//! there to save their cost.
//!
//! A renderer that renders each tile to completion (pbrt-v3, rs_pbrt:
//! all of a tile's samples, tile after tile, from a work queue) has no
//! rounds and often no tile hook: it shares the guide in a
//! [`SharedGuide`](crate::SharedGuide), records as it goes and calls
//! [`SharedGuide::refine_when_due`](crate::SharedGuide::refine_when_due)
//! after every path, which refines the GLT whenever the refinement's cost
//! is amortized ([`RefineSchedule::GLT`](crate::RefineSchedule::GLT)).
//! That beats refining after every wave of tiles (rs_pbrt's rooms and
//! street, docs/experiments/tile-order.md). The GLT refines cell by cell
//! ([`GltCell`](crate::learned::GltCell)): a cell takes part once it holds 3/2 of the records
//! that fell in it before its last refinement, so the cells the tiles
//! have reached learn while the others wait for records of their own, and
//! a half of a cell that the records never reached falls back to the prior
//! ([`GuidingCut::confidence`](crate::learned::GuidingCut::confidence)) instead of sampling with a choice
//! learned elsewhere. (The field's cells refine on PPG's clock, every
//! refinement, as its SD-tree needs; their halves fall back to the prior
//! as the GLT's do.)
//!
//! Zero-valued records (an occluded shadow ray, a path that found no light)
//! are valid observations everywhere in the crate: they add nothing to the
//! sums but count as samples for the spatial split rules, so record them as
//! they come (the light records return `RecordOutcome::Zero` for them).
//!
//! One weight per iteration (from the variance averaged over the image), not
//! per pixel: per-pixel weights computed from the same few passes correlate
//! with the pixel values (a pixel whose passes happened to miss a bright
//! path looks both darker and less noisy) and bias the result. Averaged over
//! an image the estimate is nearly independent of any one pixel.
//!
//! ```
//! use guiding::{InverseVarianceCombiner, Iterations, PassStats};
//!
//! let plan: Vec<u64> = Iterations::new(100).map(|it| it.passes).collect();
//! assert_eq!(plan, [1, 2, 4, 8, 16, 69]);
//!
//! let mut combiner = InverseVarianceCombiner::new();
//! for it in Iterations::new(100) {
//!     let mut stats = PassStats::new(2); // a 2-element "image"
//!     for pass in 0..it.passes {
//!         let noise = if pass % 2 == 0 { 0.1 } else { -0.1 };
//!         stats.add_pass(&[1.0 + noise, 2.0 - noise]);
//!     }
//!     combiner.push_stats(&stats);
//! }
//! let weights = combiner.weights();
//! assert_eq!(weights.len(), 4);
//! assert!((weights.iter().sum::<f64>() - 1.0).abs() < 1e-12);
//! let image = combiner.combine();
//! assert!((image[0] - 1.0).abs() < 0.01);
//! ```

mod combine;
mod iterations;
mod pass_stats;

pub use combine::InverseVarianceCombiner;
pub use iterations::{Iteration, Iterations, next_iteration, next_iteration_by_time};
pub use pass_stats::PassStats;
