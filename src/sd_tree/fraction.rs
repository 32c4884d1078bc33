//! The learned BSDF sampling fraction of a cell: the statistics records leave
//! and the Adam optimiser that runs on them between iterations.
//!
//! The loss is the KL divergence from the (normalised) integrand `f` to the
//! mixture `q_s = s p_bsdf + (1 - s) p_guide`, up to a constant:
//! `L(s) = -E_q[(f / q) log q_s]`, estimated from the iteration's samples,
//! which were drawn from the mixture `q` of the fraction fixed during that
//! iteration. Writing `r = p_bsdf / (p_bsdf + p_guide)`,
//! `log q_s = log(p_bsdf + p_guide) + log(s r + (1 - s)(1 - r))` and the
//! first term does not depend on `s`. So the loss at *any* `s` only needs,
//! per sample, the weight `w = f / q` (the sample's contribution) and `r`.
//! Samples are binned by `log(p_bsdf / p_guide)` (unit-wide bins on
//! `[-6, 6]` plus two open-ended ones); each bin keeps `sum w` and
//! `sum w r` in exact or `f64` sums, and stands for its weighted mean `r`.

use crate::math::SumBuffer;
use crate::math::scalar::{exp64, ln64, sqrt64};

/// Bins of `r`: 12 unit-wide bins of `log(p_bsdf / p_guide)` on `[-6, 6]`
/// and one on each side.
const BINS: usize = 14;

/// Bin edges in `r`: `logistic(k)` for `k = -6..=6`.
const EDGES: [f64; BINS - 1] = [
    0.0024726231566347743,
    0.0066928509242848554,
    0.01798620996209156,
    0.04742587317756678,
    0.11920292202211755,
    0.2689414213699951,
    0.5,
    0.7310585786300049,
    0.8807970779778823,
    0.9525741268224334,
    0.9820137900379085,
    0.9933071490757153,
    0.9975273768433653,
];

/// Sums a cell keeps for the fraction: the number of informative samples,
/// then `sum w` per bin, then `sum w r` per bin.
pub(crate) const FRACTION_SUMS: usize = 1 + 2 * BINS;

/// Adam's learning rate (Müller 2019).
pub const LEARNING_RATE: f64 = 0.01;
/// Adam's first-moment decay.
pub const BETA1: f64 = 0.9;
/// Adam's second-moment decay.
pub const BETA2: f64 = 0.999;
/// Adam's denominator guard.
const EPSILON: f64 = 1.0e-8;
/// `theta` stays in `[-THETA_LIMIT, THETA_LIMIT]` (`s` in about
/// `[2e-9, 1 - 2e-9]`).
pub const THETA_LIMIT: f64 = 20.0;

#[inline]
fn logistic(theta: f64) -> f64 {
    1.0 / (1.0 + exp64(-theta))
}

/// A cell's fraction `s = logistic(theta)` and the optimiser's state.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct FractionLearner {
    theta: f64,
    m: f64,
    v: f64,
    beta1_t: f64,
    beta2_t: f64,
    /// What queries read; changes only in `optimise` (`&mut`).
    fraction: f32,
}

impl FractionLearner {
    /// Writes the optimiser's state and the fraction.
    pub(crate) fn write(&self, w: &mut crate::persist::Writer) {
        for x in [self.theta, self.m, self.v, self.beta1_t, self.beta2_t] {
            w.f64(x);
        }
        w.f32(self.fraction);
    }

    /// Reads what [`FractionLearner::write`] wrote: finite state, the
    /// fraction in `[0, 1]`.
    pub(crate) fn read(
        r: &mut crate::persist::Reader<'_>,
    ) -> Result<Self, crate::persist::LoadError> {
        use crate::persist::Reader;
        let mut x = [0.0f64; 5];
        for v in &mut x {
            *v = r.check("fraction learner", Reader::f64, |v| v.is_finite())?;
        }
        let fraction = r.check("fraction", Reader::f32, |f| (0.0..=1.0).contains(f))?;
        Ok(Self {
            theta: x[0],
            m: x[1],
            v: x[2],
            beta1_t: x[3],
            beta2_t: x[4],
            fraction,
        })
    }
}

impl FractionLearner {
    /// Starting at `fraction` (in `[0, 1]`; the ends map to `theta = -+20`).
    pub(crate) fn new(fraction: f32) -> Self {
        let f = fraction as f64;
        let theta = if f <= 0.0 {
            -THETA_LIMIT
        } else if f >= 1.0 {
            THETA_LIMIT
        } else {
            ln64(f / (1.0 - f)).clamp(-THETA_LIMIT, THETA_LIMIT)
        };
        Self {
            theta,
            m: 0.0,
            v: 0.0,
            beta1_t: 1.0,
            beta2_t: 1.0,
            fraction,
        }
    }

    /// The current fraction.
    #[inline]
    pub(crate) fn fraction(&self) -> f32 {
        self.fraction
    }

    /// The current `theta`.
    #[inline]
    pub(crate) fn theta(&self) -> f64 {
        self.theta
    }

    /// Adds one sample to `stats[base..base + FRACTION_SUMS]`. The caller
    /// has validated the inputs (finite, non-negative, pdfs not both 0).
    #[inline]
    pub(crate) fn record(stats: &SumBuffer, base: usize, bsdf_pdf: f32, guide_pdf: f32, w: f32) {
        if w == 0.0 {
            return;
        }
        let (pb, pg) = (bsdf_pdf as f64, guide_pdf as f64);
        let r = pb / (pb + pg);
        let bin = EDGES.partition_point(|&e| e < r);
        stats.add(base, 1.0);
        stats.add(base + 1 + bin, w);
        stats.add(base + 1 + BINS + bin, (w as f64 * r) as f32);
    }

    /// Runs up to `max_steps` full-batch Adam steps (at most one per
    /// recorded sample) on the loss the sums describe, then publishes the
    /// new fraction. Does nothing without samples.
    pub(crate) fn optimise(&mut self, stats: &SumBuffer, base: usize, max_steps: u32) {
        let samples = stats.get(base);
        let mut bins = [(0.0f64, 0.0f64); BINS];
        let mut total = 0.0;
        let mut used = 0;
        for b in 0..BINS {
            let w = stats.get(base + 1 + b);
            if w > 0.0 && w.is_finite() {
                let r = (stats.get(base + 1 + BINS + b) / w).clamp(0.0, 1.0);
                bins[used] = (w, r);
                used += 1;
                total += w;
            }
        }
        if !(total > 0.0 && total.is_finite() && samples >= 1.0) {
            return;
        }
        let bins = &bins[..used];
        let steps = (max_steps as f64).min(samples) as u32;
        for _ in 0..steps {
            let s = logistic(self.theta);
            // dL/ds = -sum w_b (2 r_b - 1) / (s r_b + (1 - s)(1 - r_b)) / W.
            let mut dl_ds = 0.0;
            for &(w, r) in bins {
                dl_ds -= w * (2.0 * r - 1.0) / (s * r + (1.0 - s) * (1.0 - r));
            }
            let grad = dl_ds / total * s * (1.0 - s);
            self.m = BETA1 * self.m + (1.0 - BETA1) * grad;
            self.v = BETA2 * self.v + (1.0 - BETA2) * grad * grad;
            self.beta1_t *= BETA1;
            self.beta2_t *= BETA2;
            let m_hat = self.m / (1.0 - self.beta1_t);
            let v_hat = self.v / (1.0 - self.beta2_t);
            let step = LEARNING_RATE * m_hat / (sqrt64(v_hat) + EPSILON);
            if step.is_finite() {
                self.theta = (self.theta - step).clamp(-THETA_LIMIT, THETA_LIMIT);
            }
        }
        self.fraction = logistic(self.theta) as f32;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::Accumulation;

    #[test]
    fn edges_are_logistic_of_integers() {
        for (k, e) in EDGES.iter().enumerate() {
            assert!((logistic(k as f64 - 6.0) - e).abs() < 1e-15);
        }
    }

    #[test]
    fn optimum_of_a_two_bin_loss() {
        // Half the weight where only the BSDF can sample (r = 1), half where
        // both are equal (r = 1/2): L(s) = -log(s) - log(1/2), minimised at
        // s = 1, so theta climbs to the limit.
        let stats = SumBuffer::new(FRACTION_SUMS, Accumulation::Deterministic);
        for _ in 0..1000 {
            FractionLearner::record(&stats, 0, 1.0, 0.0, 1.0);
            FractionLearner::record(&stats, 0, 1.0, 1.0, 1.0);
        }
        let mut l = FractionLearner::new(0.5);
        for _ in 0..20 {
            l.optimise(&stats, 0, 1000);
        }
        assert!(l.fraction() > 0.999, "{}", l.fraction());
        assert!(l.theta() <= THETA_LIMIT);
        // An interior optimum: w = 1 at r = 0.9 and w = 1 at r = 0.2:
        // dL/ds = 0 at s = 0.5 (by symmetry of (2r-1)/(s r + (1-s)(1-r))).
        let stats = SumBuffer::new(FRACTION_SUMS, Accumulation::Fast);
        FractionLearner::record(&stats, 0, 0.9, 0.1, 1.0);
        FractionLearner::record(&stats, 0, 0.1, 0.9, 1.0);
        let mut l = FractionLearner::new(0.9);
        for _ in 0..200 {
            l.optimise(&stats, 0, 2);
        }
        assert!((l.fraction() - 0.5).abs() < 0.02, "{}", l.fraction());
    }

    #[test]
    fn extremes_start_clamped() {
        assert_eq!(FractionLearner::new(0.0).theta(), -THETA_LIMIT);
        assert_eq!(FractionLearner::new(1.0).theta(), THETA_LIMIT);
        assert_eq!(FractionLearner::new(0.5).theta(), 0.0);
    }
}
