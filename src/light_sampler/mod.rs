//! Light selection for next-event estimation: one trait, several samplers.
//!
//! Every sampler answers two questions for a shading point: *which light?*
//! ([`LightSampler::sample`], driven by one uniform number so any sampler,
//! QMC included, can feed it) and *with what probability?*
//! ([`LightSampler::pmf`]). The two agree bit for bit, and the pmf sums to 1
//! over all lights (or is 0 everywhere when nothing can be sampled).
//!
//! | sampler | rule |
//! | --- | --- |
//! | [`UniformSampler`] | every emitter equally |
//! | [`PowerSampler`] | proportional to power (alias table, O(1)) |
//! | [`PowerTreeSampler`] | descend a light tree by subtree power |
//! | [`ImportanceTreeSampler`] | descend by power x orientation / distance^2 (Estevez & Kulla, pbrt-v4) |
//! | [`WithUnbounded`] | any of the above plus the scene's unbounded lights (distant, infinite) with a fixed probability |
//! | [`crate::glt`] | the Guiding Light Tree: learned cuts, then the light tree |

mod choice;
mod context;
mod importance;
mod power;
mod tree_importance;
mod tree_power;
mod tree_walk;
mod unbounded;
mod uniform;

pub use choice::{LightChoice, SamplerAt};
pub use context::ShadingContext;
pub(crate) use importance::BACK_FACTOR;
pub use importance::importance;
pub use power::PowerSampler;
pub use tree_importance::ImportanceTreeSampler;
pub use tree_power::PowerTreeSampler;
pub(crate) use unbounded::choose_unbounded;
pub use unbounded::{UnboundedLights, WithUnbounded};
pub use uniform::UniformSampler;

pub(crate) use crate::math::pmf_to_f32;

/// A light a sampler can choose.
///
/// A renderer keeps its lights in two lists in its own order: the bounded
/// ones it described as [`crate::Emitters`] (`Emitter(i)` is the `i`-th)
/// and the unbounded ones ([`UnboundedLights`]: distant and infinite
/// lights, `Unbounded(i)` is the `i`-th). Both directions of the mapping
/// are then an index: a sampled id names the renderer's light, and a light
/// a BSDF sample hit names its id for the MIS pmf. A renderer whose lights
/// sit in one list, the emitters first, maps with [`LightId::index`] and
/// [`LightId::from_index`]; one whose list is mixed stores each light's
/// `LightId` beside it and the two index lists back (pbrt keeps such a map
/// for the same purpose).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum LightId {
    /// Emitter `i` of the scene's [`crate::Emitters`].
    Emitter(u32),
    /// Unbounded light `i` (see [`UnboundedLights`]), handled beside the
    /// emitters.
    Unbounded(u32),
}

impl LightId {
    /// The light's place in one list of a scene's lights that holds its
    /// `emitters` emitters first, then its unbounded lights: `Emitter(i)` is
    /// `i`, `Unbounded(i)` is `emitters + i` (saturating at `u32::MAX`).
    ///
    /// ```
    /// use guiding::LightId;
    /// assert_eq!(LightId::Unbounded(1).index(10), 11);
    /// assert_eq!(LightId::from_index(11, 10), LightId::Unbounded(1));
    /// assert_eq!(LightId::from_index(9, 10), LightId::Emitter(9));
    /// ```
    #[inline]
    pub fn index(self, emitters: u32) -> u32 {
        match self {
            Self::Emitter(i) => i,
            Self::Unbounded(i) => emitters.saturating_add(i),
        }
    }

    /// The light at `index` of such a list ([`LightId::index`]).
    #[inline]
    pub fn from_index(index: u32, emitters: u32) -> Self {
        match index.checked_sub(emitters) {
            Some(i) => Self::Unbounded(i),
            None => Self::Emitter(index),
        }
    }
}

/// A chosen light and the probability it was chosen with.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LightSample {
    /// The light.
    pub light: LightId,
    /// Its probability, in `(0, 1]`; equal to what [`LightSampler::pmf`]
    /// returns for it.
    pub pmf: f32,
}

/// Chooses lights for next-event estimation.
///
/// Implementations take `&self` and are `Sync` when their data is, so a
/// renderer shares one sampler between all its threads.
pub trait LightSampler {
    /// Chooses a light at `ctx` from one uniform number `u` in `[0, 1)`.
    /// `None` when no light can be chosen: no emitters, every one has zero
    /// power, or `ctx`'s position is not finite
    /// ([`ShadingContext::is_finite`]; every `pmf` is 0 there too).
    ///
    /// The same edges for every sampler of the crate
    /// (`tests/edge_semantics.rs`): a `u` outside `[0, 1)` is clamped into
    /// it and NaN counts as 0, so any sampler (QMC included) can drive it.
    fn sample(&self, ctx: &ShadingContext, u: f32) -> Option<LightSample>;

    /// The probability that [`LightSampler::sample`] chooses `light` at
    /// `ctx`: exactly the `pmf` it returns for it, and 0 for lights it never
    /// chooses (including ids out of range).
    fn pmf(&self, ctx: &ShadingContext, light: LightId) -> f32;

    /// True when `sample` returns `None` at every shading point.
    fn is_empty(&self) -> bool;

    /// True when `sample` returns `None` at `ctx`: the sampler is empty,
    /// the position is not finite, or no light the point is lit by has
    /// probability (light linking: [`ShadingContext::receives`]). A
    /// sampler wrapping another (`WithUnbounded`) asks it to give the
    /// wrapped lights' share to its own. The default answers
    /// [`LightSampler::is_empty`] for every finite point: right for a
    /// sampler that reads no light sets.
    fn is_empty_at(&self, ctx: &ShadingContext) -> bool {
        self.is_empty() || !ctx.is_finite()
    }

    /// [`LightSampler::sample`] from an `f64` number (53 bits), returning
    /// the pmf before it is rounded to `f32`: equal bit for bit to
    /// [`LightSampler::pmf_exact`] of the chosen light. The GLT's samplers
    /// compute in `f64` and override this; the default widens `sample`.
    fn sample_exact(&self, ctx: &ShadingContext, u: f64) -> Option<(LightId, f64)> {
        self.sample(ctx, u as f32)
            .map(|s| (s.light, f64::from(s.pmf)))
    }

    /// The pmf before rounding to `f32` (see
    /// [`LightSampler::sample_exact`]); the default widens `pmf`.
    fn pmf_exact(&self, ctx: &ShadingContext, light: LightId) -> f64 {
        f64::from(self.pmf(ctx, light))
    }

    /// What the sampler learned of `light`'s visibility at `ctx`: the
    /// fraction of its unshadowed contribution that arrives, in
    /// `[1/64, 1]`. Resampled light choice (`crate::resampling`) puts it
    /// on its target. 1 for samplers that learn none (the default), and
    /// for the GLT unless [`crate::CutConfig::visibility`] is on.
    fn visibility(&self, _ctx: &ShadingContext, _light: LightId) -> f32 {
        1.0
    }

    /// [`LightSampler::sample`] and [`LightSampler::visibility`] of the
    /// light it chose, equal to calling both; the GLT's samplers read the
    /// visibility where their walk leaves the cut (one walk instead of
    /// two: resampling asks this of every candidate).
    fn sample_with_visibility(&self, ctx: &ShadingContext, u: f32) -> Option<(LightSample, f32)> {
        let s = self.sample(ctx, u)?;
        Some((s, self.visibility(ctx, s.light)))
    }

    /// The sampler at one shading point: a [`LightChoice`] whose queries
    /// take no context, the shape a guide's vertex has, so one integrator
    /// drives both. (A `dyn LightSampler` makes its own with
    /// [`SamplerAt::new`].)
    #[inline]
    fn at(&self, ctx: &ShadingContext) -> SamplerAt<'_, Self>
    where
        Self: Sized,
    {
        SamplerAt::new(self, ctx)
    }

    /// [`LightSampler::sample`] with the number drawn from a renderer's
    /// generator ([`rand_core::Rng`]): one `next_u32`, its top 24 bits
    /// times `2^-24`, so the choice equals `sample` of that number.
    #[inline]
    fn sample_with<R: rand_core::Rng + ?Sized>(
        &self,
        ctx: &ShadingContext,
        rng: &mut R,
    ) -> Option<LightSample>
    where
        Self: Sized,
    {
        self.sample(ctx, crate::math::unit_f32(rng))
    }
}

/// A borrowed or boxed sampler is a sampler (every method forwarded,
/// the exact variants included).
macro_rules! forward_sampler {
    ($($ptr:ty),*) => {$(
        impl<S: LightSampler + ?Sized> LightSampler for $ptr {
            #[inline]
            fn sample(&self, ctx: &ShadingContext, u: f32) -> Option<LightSample> {
                (**self).sample(ctx, u)
            }

            #[inline]
            fn pmf(&self, ctx: &ShadingContext, light: LightId) -> f32 {
                (**self).pmf(ctx, light)
            }

            #[inline]
            fn is_empty(&self) -> bool {
                (**self).is_empty()
            }

            #[inline]
            fn is_empty_at(&self, ctx: &ShadingContext) -> bool {
                (**self).is_empty_at(ctx)
            }

            #[inline]
            fn sample_exact(&self, ctx: &ShadingContext, u: f64) -> Option<(LightId, f64)> {
                (**self).sample_exact(ctx, u)
            }

            #[inline]
            fn pmf_exact(&self, ctx: &ShadingContext, light: LightId) -> f64 {
                (**self).pmf_exact(ctx, light)
            }

            #[inline]
            fn visibility(&self, ctx: &ShadingContext, light: LightId) -> f32 {
                (**self).visibility(ctx, light)
            }

            #[inline]
            fn sample_with_visibility(
                &self,
                ctx: &ShadingContext,
                u: f32,
            ) -> Option<(LightSample, f32)> {
                (**self).sample_with_visibility(ctx, u)
            }
        }
    )*};
}

forward_sampler!(&S, alloc::boxed::Box<S>);

#[cfg(test)]
mod tests {
    use super::LightId;

    /// One list, emitters first: every place maps to one light and back,
    /// at the boundary too (place `emitters` is the first unbounded light;
    /// a `>` for `>=` there would make it an emitter past the last).
    #[test]
    fn one_list_maps_both_ways() {
        for emitters in [0u32, 1, 5, u32::MAX - 2] {
            for index in [
                0u32,
                1,
                4,
                5,
                6,
                emitters,
                emitters.saturating_add(1),
                u32::MAX,
            ] {
                let id = LightId::from_index(index, emitters);
                assert_eq!(id.index(emitters), index, "{index} of {emitters}");
                let emitter = index < emitters;
                assert_eq!(
                    matches!(id, LightId::Emitter(_)),
                    emitter,
                    "{index} of {emitters}"
                );
            }
        }
        assert_eq!(LightId::Unbounded(5).index(u32::MAX - 2), u32::MAX);
    }
}
