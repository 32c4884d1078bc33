//! [`LightChoice`]: the light choice at one shading point, the context
//! given once; and [`SamplerAt`], any [`LightSampler`] at a point.

use super::{LightId, LightSample, LightSampler, ShadingContext};
use crate::math::{unit_f32, unit_f64};
use rand_core::Rng;

/// The light choice at one shading point: the context was given when the
/// choice was made for the point, so every query takes only its numbers or
/// its light.
///
/// A guide's vertex is one ([`Glt::vertex`](crate::Glt::vertex) gives a
/// [`LightVertex`](crate::LightVertex), the field's
/// [`FieldVertex::light`](crate::FieldVertex::light) too, a GPU snapshot's
/// [`SnapshotView::vertex`](crate::snapshot::SnapshotView::vertex) a
/// [`SnapshotVertex`](crate::snapshot::SnapshotVertex)), and so is any
/// [`LightSampler`] at a point ([`LightSampler::at`]), so an integrator is
/// written once over `impl LightChoice` (Open PGL's `Init`, then `Sample`
/// and `PDF`).
///
/// The contracts of every sampler in the crate hold:
/// [`LightChoice::sample`] returns exactly the probability
/// [`LightChoice::pmf`] reports for the light it chose, and the pmf sums
/// to 1 over the lights (or is 0 everywhere when nothing can be chosen).
///
/// ```
/// use guiding::glam::Vec3;
/// use guiding::{Emitter, LightChoice, LightId, LightSampler, PowerSampler, ShadingContext};
///
/// let lamps = [Emitter::point(Vec3::ZERO, 1.0), Emitter::point(Vec3::X, 3.0)];
/// let sampler = PowerSampler::new(&lamps[..]);
/// // The shading point, once; then numbers and lights.
/// let here = sampler.at(&ShadingContext::on_surface(Vec3::Y, Vec3::Y));
/// let s = here.sample(0.9).expect("a light");
/// assert_eq!((s.light, s.pmf), (LightId::Emitter(1), 0.75));
/// assert_eq!(here.pmf(LightId::Emitter(0)), 0.25);
/// ```
pub trait LightChoice {
    /// Chooses a light from one uniform number `u` in `[0, 1)` (outside it
    /// clamped, NaN as 0: any sampler, QMC included, can drive it); `None`
    /// when nothing can be chosen at this point.
    fn sample(&self, u: f32) -> Option<LightSample>;

    /// The probability that [`LightChoice::sample`] chooses `light`:
    /// exactly the `pmf` it returns for it, 0 for lights it never chooses
    /// (ids out of range included). The MIS weight of a BSDF sample that
    /// hit `light` needs it.
    fn pmf(&self, light: LightId) -> f32;

    /// True when [`LightChoice::sample`] returns `None` for every number:
    /// no light with probability lights this point.
    fn is_empty(&self) -> bool;

    /// [`LightChoice::sample`] from an `f64` number (53 bits), with the pmf
    /// before it is rounded to `f32`: equal bit for bit to
    /// [`LightChoice::pmf_exact`] of the chosen light. The default widens
    /// `sample`.
    fn sample_exact(&self, u: f64) -> Option<(LightId, f64)> {
        self.sample(u as f32).map(|s| (s.light, f64::from(s.pmf)))
    }

    /// The pmf before rounding to `f32` (see [`LightChoice::sample_exact`]);
    /// the default widens `pmf`.
    fn pmf_exact(&self, light: LightId) -> f64 {
        f64::from(self.pmf(light))
    }

    /// What was learned of `light`'s visibility here: the fraction of its
    /// unshadowed contribution that arrives, in `[1/64, 1]`; 1 where
    /// nothing is learned (the default). Resampled light choice
    /// ([`resample`](crate::resample)) puts it on its target.
    fn visibility(&self, _light: LightId) -> f32 {
        1.0
    }

    /// [`LightChoice::sample`] and the [`LightChoice::visibility`] of the
    /// light it chose, equal to calling both (a guide's vertex reads the
    /// visibility where its walk leaves the cut: one walk, not two).
    fn sample_with_visibility(&self, u: f32) -> Option<(LightSample, f32)> {
        let s = self.sample(u)?;
        Some((s, self.visibility(s.light)))
    }

    /// Resampling candidates: `out[j]` becomes
    /// [`LightChoice::sample_with_visibility`]`(u[j])` for every `j` (up
    /// to the shorter of the two slices), exactly. The default calls it
    /// once per number; a guide's vertex computes each step the walks
    /// share once (the candidates of one point pass through the same
    /// nodes near the root and, where the learned choice is sharp, most
    /// of the way down), so `M` candidates cost less than `M` samples.
    fn sample_candidates(&self, u: &[f32], out: &mut [Option<(LightSample, f32)>]) {
        for (o, &u) in out.iter_mut().zip(u) {
            *o = self.sample_with_visibility(u);
        }
    }

    /// [`LightChoice::sample`] with the number drawn from a renderer's
    /// generator: one `next_u32`, its top 24 bits times `2^-24` (in
    /// `[0, 1)`, never 1), so the choice equals `sample` of that number.
    fn sample_with<R: Rng + ?Sized>(&self, rng: &mut R) -> Option<LightSample>
    where
        Self: Sized,
    {
        self.sample(unit_f32(rng))
    }

    /// [`LightChoice::sample_exact`] with the number drawn from a
    /// renderer's generator: one `next_u64`, its top 53 bits times
    /// `2^-53`.
    fn sample_exact_with<R: Rng + ?Sized>(&self, rng: &mut R) -> Option<(LightId, f64)>
    where
        Self: Sized,
    {
        self.sample_exact(unit_f64(rng))
    }
}

/// A [`LightSampler`] at one shading point ([`LightSampler::at`]): the
/// [`LightChoice`] of a sampler that chooses by the point, each query
/// answered by the sampler with the context it keeps.
#[derive(Clone, Copy, Debug)]
pub struct SamplerAt<'a, S: ?Sized> {
    sampler: &'a S,
    ctx: ShadingContext,
}

impl<'a, S: LightSampler + ?Sized> SamplerAt<'a, S> {
    /// `sampler` at `ctx`.
    #[inline]
    pub fn new(sampler: &'a S, ctx: &ShadingContext) -> Self {
        Self { sampler, ctx: *ctx }
    }

    /// The shading point it answers for.
    #[inline]
    pub fn context(&self) -> &ShadingContext {
        &self.ctx
    }
}

impl<S: LightSampler + ?Sized> LightChoice for SamplerAt<'_, S> {
    #[inline]
    fn sample(&self, u: f32) -> Option<LightSample> {
        self.sampler.sample(&self.ctx, u)
    }

    #[inline]
    fn pmf(&self, light: LightId) -> f32 {
        self.sampler.pmf(&self.ctx, light)
    }

    #[inline]
    fn is_empty(&self) -> bool {
        self.sampler.is_empty_at(&self.ctx)
    }

    #[inline]
    fn sample_exact(&self, u: f64) -> Option<(LightId, f64)> {
        self.sampler.sample_exact(&self.ctx, u)
    }

    #[inline]
    fn pmf_exact(&self, light: LightId) -> f64 {
        self.sampler.pmf_exact(&self.ctx, light)
    }

    #[inline]
    fn visibility(&self, light: LightId) -> f32 {
        self.sampler.visibility(&self.ctx, light)
    }

    #[inline]
    fn sample_with_visibility(&self, u: f32) -> Option<(LightSample, f32)> {
        self.sampler.sample_with_visibility(&self.ctx, u)
    }
}

/// A borrowed choice is a choice (every method forwarded).
impl<C: LightChoice + ?Sized> LightChoice for &C {
    #[inline]
    fn sample(&self, u: f32) -> Option<LightSample> {
        (**self).sample(u)
    }

    #[inline]
    fn pmf(&self, light: LightId) -> f32 {
        (**self).pmf(light)
    }

    #[inline]
    fn is_empty(&self) -> bool {
        (**self).is_empty()
    }

    #[inline]
    fn sample_exact(&self, u: f64) -> Option<(LightId, f64)> {
        (**self).sample_exact(u)
    }

    #[inline]
    fn pmf_exact(&self, light: LightId) -> f64 {
        (**self).pmf_exact(light)
    }

    #[inline]
    fn visibility(&self, light: LightId) -> f32 {
        (**self).visibility(light)
    }

    #[inline]
    fn sample_with_visibility(&self, u: f32) -> Option<(LightSample, f32)> {
        (**self).sample_with_visibility(u)
    }

    #[inline]
    fn sample_candidates(&self, u: &[f32], out: &mut [Option<(LightSample, f32)>]) {
        (**self).sample_candidates(u, out)
    }
}
