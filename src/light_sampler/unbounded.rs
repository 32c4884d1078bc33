//! Unbounded lights (distant and infinite) beside any emitter sampler, and
//! the description of them every sampler shares ([`UnboundedLights`]).

use super::ShadingContext;
use super::{LightId, LightSample, LightSampler, pmf_to_f32};
use crate::error::{self, ConfigError};
use crate::math::{Descent, Side};

/// A renderer's unbounded lights: lights with no position a light tree
/// could bound (pbrt's distant lights and infinite / environment lights: a
/// sun and a sky are two). They are [`LightId::Unbounded`]`(0..count)`, in
/// the renderer's own order (see [`LightId`] for the mapping).
///
/// `probability` is the share they get together, equally split: the fixed
/// probability of choosing one for `WithUnbounded`, the prior (the
/// defensive floor, mixed in by `alpha`) for the GLT, which learns each
/// one's share per cell. pbrt-v4's BVH light sampler uses
/// `count / (count + 1)`.
///
/// ```
/// use guiding::UnboundedLights;
/// let sun_and_sky = UnboundedLights::new(2, 0.25)?;
/// assert_eq!(sun_and_sky.each(), 0.125);
/// assert!(UnboundedLights::new(2, 0.0).is_err()); // never sampled: biased
/// assert!(UnboundedLights::new(0, 0.3).is_err()); // a share for nothing
/// # Ok::<(), guiding::ConfigError>(())
/// ```
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct UnboundedLights {
    /// How many unbounded lights the scene has.
    pub count: u32,
    /// The probability of choosing one of them: in `(0, 1)` when `count >
    /// 0` (0 would never sample them, which is biased for a distant light
    /// no BSDF sample can hit; 1 would never sample an emitter), 0 when
    /// `count` is 0.
    pub probability: f64,
}

impl UnboundedLights {
    /// No unbounded light (the default).
    pub const NONE: Self = Self {
        count: 0,
        probability: 0.0,
    };

    /// `count` unbounded lights sharing `probability`, validated.
    pub fn new(count: u32, probability: f64) -> Result<Self, ConfigError> {
        let s = Self { count, probability };
        s.validate()?;
        Ok(s)
    }

    /// Checks `probability` against `count` (see the field).
    pub fn validate(&self) -> Result<(), ConfigError> {
        let p = self.probability;
        if self.count == 0 {
            error::check(
                "UnboundedLights::probability",
                p,
                p == 0.0,
                "0 when count is 0",
            )
        } else {
            error::check(
                "UnboundedLights::probability",
                p,
                p > 0.0 && p < 1.0,
                "in (0, 1) when count > 0",
            )
        }
    }

    /// The probability share of each one.
    #[inline]
    pub fn each(&self) -> f64 {
        if self.count == 0 {
            0.0
        } else {
            self.probability / f64::from(self.count)
        }
    }

    /// Whether `light` is one of these.
    #[inline]
    pub(crate) fn contains(&self, light: LightId) -> bool {
        matches!(light, LightId::Unbounded(i) if i < self.count)
    }
}

/// Chooses one of `count` unbounded lights with weights `weight(i)`
/// (summing to a positive total) from `d`'s number: a chain of two-way
/// choices, `i` against all after it. `None` when no weight is positive.
#[inline]
pub(crate) fn choose_unbounded(
    d: &mut Descent,
    count: u32,
    weight: impl Fn(u32) -> f64,
) -> Option<u32> {
    for i in 0..count {
        let rest: f64 = (i + 1..count).map(&weight).sum();
        match Descent::probabilities(weight(i), rest) {
            Some((pl, pr)) => {
                if d.choose_with(pl, pr) == Side::Left {
                    return Some(i);
                }
            }
            // Neither this one nor any after it: nothing to choose.
            None => return None,
        }
    }
    None
}

/// Wraps an emitter sampler `S` with a scene's unbounded lights, chosen
/// with a fixed probability.
///
/// [`LightId::Unbounded`]`(i)` gets probability `p / count` each and every
/// emitter `(1 - p)` times its pmf under `S` (`p` is
/// [`UnboundedLights::probability`]). When `S` is empty the unbounded
/// lights share probability 1; with no unbounded light the wrapper behaves
/// exactly like `S`. So the pmf sums to 1 (or to 0 when nothing can be
/// sampled).
///
/// Under light linking the same holds among the lights the point is lit
/// by: `count` is the number of unbounded lights it receives
/// ([`ShadingContext::receives_unbounded`]), and `S` counts as empty where
/// it has no emitter for the point ([`LightSampler::is_empty_at`]).
///
/// One `u` does every choice: `u < p` picks an unbounded light (`u / p`
/// then picks which), otherwise the rescaled `(u - p) / (1 - p)` drives
/// `S`, with the same `f64` arithmetic in `sample` and `pmf` so both agree
/// bit for bit. `S` should not choose unbounded lights itself; if it does,
/// that draw is refused (`None`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WithUnbounded<S> {
    inner: S,
    unbounded: UnboundedLights,
}

impl<S: LightSampler> WithUnbounded<S> {
    /// Wraps `inner` with `unbounded` (validated first).
    pub fn new(inner: S, unbounded: UnboundedLights) -> Result<Self, ConfigError> {
        unbounded.validate()?;
        Ok(Self { inner, unbounded })
    }

    /// The wrapped emitter sampler.
    pub fn inner(&self) -> &S {
        &self.inner
    }

    /// Unwraps the emitter sampler.
    pub fn into_inner(self) -> S {
        self.inner
    }

    /// The unbounded lights, as given (their effective share is 1 when the
    /// inner sampler is empty).
    pub fn unbounded(&self) -> UnboundedLights {
        self.unbounded
    }

    /// (unbounded lights together, emitters) probabilities at `ctx`, and
    /// how many unbounded lights share the first.
    #[inline]
    fn split(&self, ctx: &ShadingContext) -> (f64, f64, u32) {
        let p = self.unbounded.probability;
        let k = ctx.unbounded_received(self.unbounded.count);
        if k == 0 {
            (0.0, 1.0, 0)
        } else if self.inner.is_empty_at(ctx) {
            (1.0, 0.0, k)
        } else {
            (p, 1.0 - p, k)
        }
    }
}

impl<S: LightSampler> LightSampler for WithUnbounded<S> {
    #[inline]
    fn sample(&self, ctx: &ShadingContext, u: f32) -> Option<LightSample> {
        if !ctx.is_finite() {
            return None;
        }
        let (pu, pe, k) = self.split(ctx);
        let mut d = Descent::new(u);
        let (light, pmf) = match d.choose_with(pu, pe) {
            Side::Left => {
                let weight = |i| f64::from(u8::from(ctx.is_lit_by_unbounded(i)));
                let i = choose_unbounded(&mut d, self.unbounded.count, weight)?;
                (LightId::Unbounded(i), pu / f64::from(k))
            }
            Side::Right => {
                let s = self.inner.sample(ctx, d.u() as f32)?;
                if !matches!(s.light, LightId::Emitter(_)) {
                    return None;
                }
                (s.light, pe * f64::from(s.pmf))
            }
        };
        let pmf = pmf_to_f32(pmf);
        (pmf > 0.0).then_some(LightSample { light, pmf })
    }

    #[inline]
    fn pmf(&self, ctx: &ShadingContext, light: LightId) -> f32 {
        if !ctx.is_finite() {
            return 0.0;
        }
        let (pu, pe, k) = self.split(ctx);
        match light {
            LightId::Unbounded(i)
                if self.unbounded.contains(light) && ctx.is_lit_by_unbounded(i) =>
            {
                pmf_to_f32(pu / f64::from(k))
            }
            LightId::Unbounded(_) => 0.0,
            // An empty inner sampler has `pe` 0 and every pmf 0.
            LightId::Emitter(_) => pmf_to_f32(pe * f64::from(self.inner.pmf(ctx, light))),
        }
    }

    #[inline]
    fn is_empty(&self) -> bool {
        self.unbounded.count == 0 && self.inner.is_empty()
    }

    #[inline]
    fn is_empty_at(&self, ctx: &ShadingContext) -> bool {
        !ctx.is_finite()
            || (ctx.unbounded_received(self.unbounded.count) == 0 && self.inner.is_empty_at(ctx))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::light_sampler::UniformSampler;
    use glam::Vec3;

    fn with(n: usize, count: u32, p: f64) -> WithUnbounded<UniformSampler> {
        WithUnbounded::new(
            UniformSampler::new(n),
            UnboundedLights::new(count, p).unwrap(),
        )
        .unwrap()
    }

    /// An inner sampler that always draws emitter 0 with the smallest
    /// positive `f32` pmf.
    struct Tiny;

    impl LightSampler for Tiny {
        fn sample(&self, _: &ShadingContext, _: f32) -> Option<LightSample> {
            Some(LightSample {
                light: LightId::Emitter(0),
                pmf: f32::from_bits(1),
            })
        }
        fn pmf(&self, _: &ShadingContext, light: LightId) -> f32 {
            match light {
                LightId::Emitter(0) => f32::from_bits(1),
                _ => 0.0,
            }
        }
        fn is_empty(&self) -> bool {
            false
        }
    }

    /// A light whose wrapped pmf rounds to 0 in `f32` is never drawn, and
    /// the wrapper reports the unbounded lights it was given.
    #[test]
    fn a_pmf_that_rounds_to_zero_is_never_sampled() {
        let ctx = ShadingContext::at(Vec3::ZERO);
        let lights = UnboundedLights::new(1, 0.5).unwrap();
        let s = WithUnbounded::new(Tiny, lights).unwrap();
        assert_eq!(s.unbounded(), lights);
        assert_eq!(
            s.pmf(&ctx, LightId::Emitter(0)),
            0.0,
            "half the smallest f32"
        );
        assert_eq!(s.sample(&ctx, 0.75), None);
        assert_eq!(
            s.sample(&ctx, 0.25).map(|x| x.light),
            Some(LightId::Unbounded(0))
        );
    }

    #[test]
    fn splits_one_number() {
        let ctx = ShadingContext::at(Vec3::ZERO);
        let s = with(2, 1, 0.25);
        let pick = |u: f32| s.sample(&ctx, u).unwrap();
        assert_eq!(pick(0.1).light, LightId::Unbounded(0));
        assert_eq!(pick(0.1).pmf, 0.25);
        assert_eq!(pick(0.5).light, LightId::Emitter(0));
        assert_eq!(pick(0.7).light, LightId::Emitter(1));
        assert_eq!(pick(0.7).pmf, 0.375);
        assert_eq!(s.pmf(&ctx, LightId::Emitter(1)), 0.375);
        assert_eq!(s.pmf(&ctx, LightId::Emitter(2)), 0.0);
        assert_eq!(s.pmf(&ctx, LightId::Unbounded(1)), 0.0);
    }

    #[test]
    fn several_unbounded_lights_share_equally() {
        let ctx = ShadingContext::at(Vec3::ZERO);
        let s = with(4, 3, 0.6);
        for (u, i) in [(0.05, 0), (0.25, 1), (0.5, 2)] {
            let got = s.sample(&ctx, u).unwrap();
            assert_eq!(got.light, LightId::Unbounded(i), "u {u}");
            assert_eq!(got.pmf, s.pmf(&ctx, got.light));
            assert_eq!(got.pmf, 0.2);
        }
        let total: f32 = (0..3)
            .map(|i| s.pmf(&ctx, LightId::Unbounded(i)))
            .chain((0..4).map(|i| s.pmf(&ctx, LightId::Emitter(i))))
            .sum();
        assert!((total - 1.0).abs() < 1e-6);
    }

    #[test]
    fn special_cases() {
        let ctx = ShadingContext::at(Vec3::ZERO);
        // Empty inner: the unbounded lights take everything.
        let s = with(0, 2, 0.3);
        assert_eq!(s.pmf(&ctx, LightId::Unbounded(1)), 0.5);
        assert_eq!(s.sample(&ctx, 0.9).unwrap().light, LightId::Unbounded(1));
        assert!(!s.is_empty());
        // None: exactly the inner sampler.
        let s = WithUnbounded::new(UniformSampler::new(3), UnboundedLights::NONE).unwrap();
        assert_eq!(s.pmf(&ctx, LightId::Unbounded(0)), 0.0);
        assert_eq!(s.sample(&ctx, 0.0).unwrap().light, LightId::Emitter(0));
        let e = WithUnbounded::new(UniformSampler::new(0), UnboundedLights::NONE).unwrap();
        assert!(e.is_empty());
        assert_eq!(e.sample(&ctx, 0.5), None);
        // Invalid shares are errors, not clamps.
        for (count, p) in [
            (1, 0.0),
            (1, 1.0),
            (1, 7.0),
            (1, f64::NAN),
            (0, 0.5),
            (2, -0.1),
        ] {
            let bad = UnboundedLights {
                count,
                probability: p,
            };
            assert!(
                WithUnbounded::new(UniformSampler::new(3), bad).is_err(),
                "{count} {p}"
            );
        }
    }
}
