//! Inverse-variance combination of the last iterations' images.

use super::PassStats;
use alloc::collections::VecDeque;
use alloc::vec;
use alloc::vec::Vec;

#[derive(Clone, Debug)]
struct Entry {
    image: Vec<f64>,
    variance: Option<f64>,
    passes: u64,
}

/// Blends the last [`InverseVarianceCombiner::MAX_COMBINED`] iteration images with one weight each,
/// proportional to the inverse of the image's estimated variance.
///
/// Weights sum to 1. Iterations without a variance estimate (one pass) get
/// weight 0 when another has one. If some iteration's estimate is exactly 0
/// the zero-variance iterations share the weight by pass count; with no
/// estimate at all, weights follow pass counts (plain pooling).
#[derive(Clone, Debug, Default)]
pub struct InverseVarianceCombiner {
    entries: VecDeque<Entry>,
}

impl InverseVarianceCombiner {
    /// How many of the latest iterations are combined (PPG: four).
    pub const MAX_COMBINED: usize = 4;

    /// An empty combiner.
    pub fn new() -> Self {
        Self::default()
    }

    /// Adds an iteration's image with its variance estimate (of the image
    /// averaged over elements; `None` if unknown) and pass count. The oldest
    /// is dropped beyond [`InverseVarianceCombiner::MAX_COMBINED`]. A negative or non-finite variance
    /// counts as unknown.
    pub fn push_image(&mut self, image: &[f32], variance: Option<f64>, passes: u64) {
        self.push(Entry {
            image: image.iter().map(|&x| x as f64).collect(),
            variance,
            passes,
        });
    }

    /// Adds an iteration from its `PassStats` (mean image, unbiased
    /// variance, pass count).
    pub fn push_stats(&mut self, stats: &PassStats) {
        self.push(Entry {
            image: stats.mean().to_vec(),
            variance: stats.image_variance(),
            passes: stats.passes(),
        });
    }

    fn push(&mut self, mut entry: Entry) {
        entry.variance = entry.variance.filter(|v| *v >= 0.0 && v.is_finite());
        if self.entries.len() == Self::MAX_COMBINED {
            self.entries.pop_front();
        }
        self.entries.push_back(entry);
    }

    /// Iterations held (at most [`InverseVarianceCombiner::MAX_COMBINED`]).
    pub fn len(&self) -> usize {
        self.entries.len()
    }

    /// True before the first push.
    pub fn is_empty(&self) -> bool {
        self.entries.is_empty()
    }

    /// The weight of each held iteration, oldest first; they sum to 1
    /// (empty when nothing was pushed).
    pub fn weights(&self) -> Vec<f64> {
        let raw: Vec<f64> = if self.entries.iter().any(|e| e.variance == Some(0.0)) {
            self.entries
                .iter()
                .map(|e| {
                    if e.variance == Some(0.0) {
                        e.passes.max(1) as f64
                    } else {
                        0.0
                    }
                })
                .collect()
        } else if self.entries.iter().any(|e| e.variance.is_some()) {
            self.entries
                .iter()
                .map(|e| e.variance.map_or(0.0, |v| 1.0 / v))
                .collect()
        } else {
            self.entries
                .iter()
                .map(|e| e.passes.max(1) as f64)
                .collect()
        };
        let total: f64 = raw.iter().sum();
        if !(total > 0.0 && total.is_finite()) {
            // Variances so small that 1/v overflowed: fall back to equal
            // weights among the infinite ones.
            let inf = raw.iter().filter(|w| w.is_infinite()).count().max(1) as f64;
            return raw
                .iter()
                .map(|w| if w.is_infinite() { 1.0 / inf } else { 0.0 })
                .collect();
        }
        raw.iter().map(|w| w / total).collect()
    }

    /// The estimated variance of the combined image (averaged over
    /// elements, like each iteration's): `sum w_i^2 v_i` over the held
    /// iterations, which for inverse-variance weights is
    /// `1 / sum (1 / v_i)`, below every single iteration's. `None` when an
    /// iteration with positive weight has no estimate (or nothing was
    /// pushed).
    pub fn combined_variance(&self) -> Option<f64> {
        if self.entries.is_empty() {
            return None;
        }
        let mut total = 0.0f64;
        for (e, w) in self.entries.iter().zip(self.weights()) {
            if w > 0.0 {
                total += w * w * e.variance?;
            }
        }
        Some(total)
    }

    /// The combined image (as long as the shortest held image).
    pub fn combine(&self) -> Vec<f32> {
        let len = self
            .entries
            .iter()
            .map(|e| e.image.len())
            .min()
            .unwrap_or(0);
        let mut out = vec![0.0f32; len];
        self.combine_into(&mut out);
        out
    }

    /// Writes the combined image into `out` (elements past the shortest held
    /// image are left alone).
    pub fn combine_into(&self, out: &mut [f32]) {
        let weights = self.weights();
        let len = self
            .entries
            .iter()
            .map(|e| e.image.len())
            .min()
            .unwrap_or(0)
            .min(out.len());
        for (i, o) in out.iter_mut().enumerate().take(len) {
            let mut acc = 0.0f64;
            for (e, w) in self.entries.iter().zip(&weights) {
                if *w > 0.0 {
                    acc += w * e.image[i];
                }
            }
            *o = acc as f32;
        }
    }
}
