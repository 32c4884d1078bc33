//! Uniform light selection: the baseline every other sampler is measured
//! against.

use super::{LightId, LightSample, LightSampler, pmf_to_f32};
use super::{PowerSampler, ShadingContext};
use crate::emitter::Emitters;
use crate::math::Descent;

/// The most emitters a [`LightId::Emitter`] can name.
const MAX_EMITTERS: u64 = u32::MAX as u64 + 1;

/// Chooses every emitter with the same probability `1 / count`, whatever its
/// power or position; over emitters with weights
/// ([`UniformSampler::weighted`]), in proportion to their weights.
///
/// `u` maps to emitter `floor(u * count)` (an inverse CDF, so stratified `u`
/// stays stratified). Counts beyond 2^32 are capped at 2^32, the number of
/// ids a [`LightId::Emitter`] can hold. With `count == 0` nothing is
/// sampled.
#[derive(Clone, Debug, PartialEq)]
pub struct UniformSampler {
    count: u64,
    pmf: f32,
    /// The weights' alias table, when some weight is not 1.
    weighted: Option<PowerSampler>,
}

impl UniformSampler {
    /// A sampler over emitters `0..count`.
    pub fn new(count: usize) -> Self {
        let count = (count as u64).min(MAX_EMITTERS);
        let pmf = if count == 0 {
            0.0
        } else {
            pmf_to_f32(1.0 / count as f64)
        };
        Self {
            count,
            pmf,
            weighted: None,
        }
    }

    /// A sampler over `emitters` that chooses each in proportion to its
    /// weight ([`Emitters::weight`]; one that is not a positive finite
    /// number counts as zero), and among the emitters of the light sets a
    /// point receives ([`Emitters::light_sets`]): exactly
    /// [`UniformSampler::new`] when every weight is 1 and every emitter in
    /// every set, else an alias table of the weights (16 bytes per
    /// emitter, and the sets).
    pub fn weighted<E: Emitters + ?Sized>(emitters: &E) -> Self {
        let n = emitters.len();
        let plain = (0..n).all(|i| emitters.weight(i) == 1.0 && emitters.light_sets(i) == u64::MAX);
        if plain {
            return Self::new(n);
        }
        let weights = PowerSampler::from_powers((0..n).map(|i| emitters.weight(i)));
        Self {
            weighted: Some(weights.linked_by(emitters)),
            ..Self::new(n)
        }
    }

    /// Number of emitters it chooses from.
    pub fn count(&self) -> usize {
        self.count as usize
    }
}

impl LightSampler for UniformSampler {
    #[inline]
    fn sample(&self, ctx: &ShadingContext, u: f32) -> Option<LightSample> {
        if let Some(w) = &self.weighted {
            return w.sample(ctx, u);
        }
        // A point lit by no light set: every emitter here is in every set.
        if self.is_empty() || !ctx.is_finite() || ctx.restricts(false) {
            return None;
        }
        let u = Descent::new(u).u();
        // u >= 0, so truncation is floor (and avoids a libm call).
        let i = ((u * self.count as f64) as u64).min(self.count - 1);
        Some(LightSample {
            light: LightId::Emitter(i as u32),
            pmf: self.pmf,
        })
    }

    #[inline]
    fn pmf(&self, ctx: &ShadingContext, light: LightId) -> f32 {
        if let Some(w) = &self.weighted {
            return w.pmf(ctx, light);
        }
        if !ctx.is_finite() || ctx.restricts(false) {
            return 0.0;
        }
        match light {
            LightId::Emitter(i) if (i as u64) < self.count => self.pmf,
            _ => 0.0,
        }
    }

    #[inline]
    fn is_empty(&self) -> bool {
        match &self.weighted {
            Some(w) => w.is_empty(),
            None => self.count == 0,
        }
    }

    fn is_empty_at(&self, ctx: &ShadingContext) -> bool {
        match &self.weighted {
            Some(w) => w.is_empty_at(ctx),
            None => self.count == 0 || !ctx.is_finite() || ctx.restricts(false),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    #[test]
    fn inverse_cdf_and_edges() {
        let s = UniformSampler::new(4);
        let ctx = ShadingContext::at(Vec3::ZERO);
        let pick = |u: f32| s.sample(&ctx, u).map(|x| x.light);
        assert_eq!(pick(0.0), Some(LightId::Emitter(0)));
        assert_eq!(pick(0.2499), Some(LightId::Emitter(0)));
        assert_eq!(pick(0.25), Some(LightId::Emitter(1)));
        assert_eq!(pick(0.99999994), Some(LightId::Emitter(3)));
        assert_eq!(pick(1.0), Some(LightId::Emitter(3)));
        assert_eq!(pick(f32::NAN), Some(LightId::Emitter(0)));
        assert_eq!(pick(f32::INFINITY), Some(LightId::Emitter(3)));
        assert_eq!(s.pmf(&ctx, LightId::Emitter(3)), 0.25);
        assert_eq!(s.pmf(&ctx, LightId::Emitter(4)), 0.0);
        assert_eq!(s.pmf(&ctx, LightId::Unbounded(0)), 0.0);
    }

    /// Counts are capped at the 2^32 ids a `LightId::Emitter` holds, and
    /// the last of them is reachable.
    #[test]
    #[cfg(target_pointer_width = "64")]
    fn counts_beyond_the_ids_are_capped() {
        let ctx = ShadingContext::at(Vec3::ZERO);
        assert_eq!(UniformSampler::new(5).count(), 5);
        let s = UniformSampler::new(usize::MAX);
        assert_eq!(s.count(), 1 << 32);
        assert_eq!(s.pmf(&ctx, LightId::Emitter(u32::MAX)), 2f32.powi(-32));
        let last = s.sample(&ctx, 1.0).unwrap().light;
        assert_eq!(last, LightId::Emitter(u32::MAX));
    }

    #[test]
    fn empty_samples_nothing() {
        let s = UniformSampler::new(0);
        let ctx = ShadingContext::at(Vec3::ZERO);
        assert!(s.is_empty());
        assert_eq!(s.sample(&ctx, 0.5), None);
        assert_eq!(s.pmf(&ctx, LightId::Emitter(0)), 0.0);
    }
}
