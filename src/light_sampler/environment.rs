//! An environment (infinite) light beside any emitter sampler.

use super::{LightId, LightSample, LightSampler, pmf_to_f32};
use crate::emitter::ShadingContext;
use crate::math::{Descent, Side};

/// Wraps an emitter sampler `S` with an environment light chosen with a fixed
/// probability `p`.
///
/// [`LightId::Environment`] gets probability `p` and every emitter `(1 - p)`
/// times its pmf under `S`. Two special cases keep the pmf summing to 1 (or
/// to 0 when nothing can be sampled): when `S` is empty the environment gets
/// probability 1 (if `p > 0`); with `p = 0` the environment is never chosen
/// and the wrapper behaves exactly like `S`.
///
/// One `u` does both choices: `u < p` picks the environment, otherwise the
/// rescaled `(u - p) / (1 - p)` drives `S`, with the same `f64` arithmetic
/// in `sample` and `pmf` so both agree bit for bit. `S` should not choose the
/// environment itself; if it does, that draw is refused (`None`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WithEnvironment<S> {
    inner: S,
    probability: f64,
}

impl<S: LightSampler> WithEnvironment<S> {
    /// Wraps `inner` with an environment chosen with probability
    /// `probability`, clamped into `[0, 1]` (NaN counts as 0).
    pub fn new(inner: S, probability: f32) -> Self {
        let probability = if probability > 0.0 {
            probability.min(1.0) as f64
        } else {
            0.0
        };
        Self { inner, probability }
    }

    /// The wrapped emitter sampler.
    pub fn inner(&self) -> &S {
        &self.inner
    }

    /// Unwraps the emitter sampler.
    pub fn into_inner(self) -> S {
        self.inner
    }

    /// The environment probability set by the user (after clamping); the
    /// effective one is 1 when the inner sampler is empty.
    pub fn probability(&self) -> f32 {
        self.probability as f32
    }

    /// (environment, emitters) probabilities.
    #[inline]
    fn split(&self) -> (f64, f64) {
        let p = self.probability;
        if p == 0.0 {
            (0.0, 1.0)
        } else if self.inner.is_empty() {
            (1.0, 0.0)
        } else {
            (p, 1.0 - p)
        }
    }
}

impl<S: LightSampler> LightSampler for WithEnvironment<S> {
    #[inline]
    fn sample(&self, ctx: &ShadingContext, u: f32) -> Option<LightSample> {
        if !ctx.is_finite() {
            return None;
        }
        let (pe, pl) = self.split();
        let mut d = Descent::new(u);
        match d.choose_with(pe, pl) {
            Side::Left => {
                let pmf = pmf_to_f32(d.pmf());
                (pmf > 0.0).then_some(LightSample {
                    light: LightId::Environment,
                    pmf,
                })
            }
            Side::Right => {
                let s = self.inner.sample(ctx, d.u() as f32)?;
                if s.light == LightId::Environment {
                    return None;
                }
                let pmf = pmf_to_f32(d.pmf() * s.pmf as f64);
                (pmf > 0.0).then_some(LightSample {
                    light: s.light,
                    pmf,
                })
            }
        }
    }

    #[inline]
    fn pmf(&self, ctx: &ShadingContext, light: LightId) -> f32 {
        if !ctx.is_finite() {
            return 0.0;
        }
        let (pe, pl) = self.split();
        let mut d = Descent::evaluate();
        match light {
            LightId::Environment => {
                d.follow_with(pe, pl, Side::Left);
                pmf_to_f32(d.pmf())
            }
            LightId::Emitter(_) => {
                if !d.follow_with(pe, pl, Side::Right) {
                    return 0.0;
                }
                pmf_to_f32(d.pmf() * self.inner.pmf(ctx, light) as f64)
            }
        }
    }

    #[inline]
    fn is_empty(&self) -> bool {
        self.probability == 0.0 && self.inner.is_empty()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::light_sampler::UniformSampler;
    use glam::Vec3;

    #[test]
    fn splits_one_number() {
        let ctx = ShadingContext::at(Vec3::ZERO);
        let s = WithEnvironment::new(UniformSampler::new(2), 0.25);
        let pick = |u: f32| s.sample(&ctx, u).unwrap();
        assert_eq!(pick(0.1).light, LightId::Environment);
        assert_eq!(pick(0.1).pmf, 0.25);
        assert_eq!(pick(0.5).light, LightId::Emitter(0));
        assert_eq!(pick(0.7).light, LightId::Emitter(1));
        assert_eq!(pick(0.7).pmf, 0.375);
        assert_eq!(s.pmf(&ctx, LightId::Emitter(1)), 0.375);
        assert_eq!(s.pmf(&ctx, LightId::Emitter(2)), 0.0);
    }

    #[test]
    fn special_probabilities() {
        let ctx = ShadingContext::at(Vec3::ZERO);
        // Empty inner: the environment takes everything.
        let s = WithEnvironment::new(UniformSampler::new(0), 0.3);
        assert_eq!(s.pmf(&ctx, LightId::Environment), 1.0);
        assert_eq!(s.sample(&ctx, 0.9).unwrap().light, LightId::Environment);
        assert!(!s.is_empty());
        // p = 0 (or NaN): never the environment.
        for p in [0.0, -1.0, f32::NAN] {
            let s = WithEnvironment::new(UniformSampler::new(3), p);
            assert_eq!(s.pmf(&ctx, LightId::Environment), 0.0);
            assert_eq!(s.sample(&ctx, 0.0).unwrap().light, LightId::Emitter(0));
            let e = WithEnvironment::new(UniformSampler::new(0), p);
            assert!(e.is_empty());
            assert_eq!(e.sample(&ctx, 0.5), None);
            assert_eq!(e.pmf(&ctx, LightId::Environment), 0.0);
        }
        // p = 1 (or more): only the environment.
        let s = WithEnvironment::new(UniformSampler::new(3), 7.0);
        assert_eq!(s.pmf(&ctx, LightId::Environment), 1.0);
        assert_eq!(s.pmf(&ctx, LightId::Emitter(0)), 0.0);
        assert_eq!(s.sample(&ctx, 0.9999).unwrap().light, LightId::Environment);
    }
}
