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
//! One weight per iteration (from the variance averaged over the image), not
//! per pixel: per-pixel weights computed from the same few passes correlate
//! with the pixel values (a pixel whose passes happened to miss a bright
//! path looks both darker and less noisy) and bias the result. Averaged over
//! an image the estimate is nearly independent of any one pixel.
//!
//! ```
//! use guiding::schedule::{InverseVarianceCombiner, Iterations, PassStats};
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

pub use combine::{InverseVarianceCombiner, MAX_COMBINED};
pub use iterations::{Iteration, Iterations, next_iteration, next_iteration_by_time};
pub use pass_stats::PassStats;
