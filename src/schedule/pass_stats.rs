//! Per-element running statistics over the passes of one iteration.

use alloc::vec;
use alloc::vec::Vec;

/// Running mean and sum of squared deviations (Welford, in `f64`) of every
/// element of the per-pass images of one iteration.
///
/// `variance_of_mean` is unbiased: `E[sum (x_i - mean)^2 / (n (n-1))] =
/// Var(mean)` for independent, identically distributed passes.
#[derive(Clone, Debug, PartialEq)]
pub struct PassStats {
    passes: u64,
    mean: Vec<f64>,
    m2: Vec<f64>,
}

impl PassStats {
    /// Statistics for images of `len` elements, no pass yet.
    pub fn new(len: usize) -> Self {
        Self {
            passes: 0,
            mean: vec![0.0; len],
            m2: vec![0.0; len],
        }
    }

    /// Adds one pass's image (its per-element average over that pass's
    /// samples). Returns false and adds nothing when the length differs.
    pub fn add_pass(&mut self, pass: &[f32]) -> bool {
        if pass.len() != self.mean.len() {
            return false;
        }
        self.passes += 1;
        let n = self.passes as f64;
        for ((m, m2), &x) in self.mean.iter_mut().zip(&mut self.m2).zip(pass) {
            let x = x as f64;
            let delta = x - *m;
            *m += delta / n;
            *m2 += delta * (x - *m);
        }
        true
    }

    /// Passes added.
    pub fn passes(&self) -> u64 {
        self.passes
    }

    /// Elements per image.
    pub fn len(&self) -> usize {
        self.mean.len()
    }

    /// True for images of no element.
    pub fn is_empty(&self) -> bool {
        self.mean.is_empty()
    }

    /// The iteration's image: the per-element mean over passes.
    pub fn mean(&self) -> &[f64] {
        &self.mean
    }

    /// Unbiased estimate of the variance of element `i` of [`PassStats::mean`];
    /// `None` with fewer than two passes or `i` out of range.
    pub fn variance_of_mean(&self, i: usize) -> Option<f64> {
        if self.passes < 2 || i >= self.m2.len() {
            return None;
        }
        let n = self.passes as f64;
        Some(self.m2[i] / (n * (n - 1.0)))
    }

    /// Unbiased estimate of the image's variance averaged over its elements
    /// (the expected squared error of the mean image per element); `None`
    /// with fewer than two passes, no element, or a non-finite result.
    pub fn image_variance(&self) -> Option<f64> {
        if self.passes < 2 || self.m2.is_empty() {
            return None;
        }
        let n = self.passes as f64;
        let sum: f64 = self.m2.iter().sum();
        let v = sum / (n * (n - 1.0)) / self.m2.len() as f64;
        v.is_finite().then_some(v)
    }
}
