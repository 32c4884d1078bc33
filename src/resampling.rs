//! Resampled light choice (resampled importance sampling, Talbot et al.
//! 2005; the candidate-reservoir form of ReSTIR, Bitterli et al. 2020):
//! draw `M` candidate lights from any [`LightSampler`], let the renderer
//! evaluate each one's *unshadowed* contribution (it samples the point on
//! the light itself, no shadow ray), and keep one in proportion to that
//! contribution over its pmf. The kept light comes with a weight that takes
//! the place of `1 / pmf` in the renderer's estimate, and the estimate stays
//! unbiased whatever the sampler and whatever the contributions, as long as
//! a candidate that can contribute has a non-zero evaluated contribution
//! (an unshadowed contribution is never below the shadowed one).
//!
//! With candidates `x_j = (l_j, y_j)` drawn with density `q = P(l) p_l(y)`
//! and the renderer's unshadowed estimate `c_j = f cos Le / p_l` at `y_j`,
//! the candidate weights are `w_j = c_j t_j / P(l_j)` (`t_j` the
//! renderer's factor, if any, times what the sampler learned of the
//! light's visibility, [`LightSampler::visibility`]), one candidate `s` is
//! kept with probability `w_s / sum w`, and
//!
//! ```text
//! weight = (sum_j w_j / M) / (c_s t_s)
//! ```
//!
//! so the renderer's usual per-light estimate times `weight`,
//! `f cos Le V / p_l * weight`, is the unbiased resampled estimate
//! (`E[f(x) W] = integral of f` for `W = weight / p_l`, the unbiased
//! contribution weight of resampled importance sampling). At `M = 1` the
//! weight is exactly `1 / pmf`. Its variance for i.i.d. candidates has a
//! closed form, which `examples/light_limit` computes
//! (`variance::resampled_parts`).
//!
//! One uniform number chooses among the candidates, in a single pass that
//! keeps only the current choice (weighted reservoir sampling, with the
//! number rescaled at each candidate as the crate's tree descents do), so
//! nothing is allocated and the renderer's payload of each candidate (its
//! light sample, say) is moved, never copied or stored `M` times.
//!
//! MIS with BSDF sampling: the density of the kept light is not known in
//! closed form. Weigh both strategies with the candidate density as the
//! NEE strategy's proxy density, `P(l) p_l` (what the renderer computes
//! today with [`LightSampler::pmf`]): any weights that sum to one over the
//! strategies keep the combination unbiased, and [`Resampled::pmf`] is that
//! proxy's pmf. [`crate::mis::resampled_light_sample`] weighs the light
//! sample under pbrt-v4's convention ([`crate::mis::Convention::PbrtV4`]`.bsdf_sample`
//! the BSDF sample, with the pmf of the light it hit, as today).

use crate::emitter::ShadingContext;
use crate::light_sampler::{LightId, LightSampler};
use crate::math::{Descent, Side};

/// The light a resampled choice kept ([`resample`]), with what the renderer
/// needs to weigh it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Resampled<T> {
    /// The light.
    pub light: LightId,
    /// The renderer's payload for it (what its evaluation returned: the
    /// point on the light it sampled, say).
    pub payload: T,
    /// The light's pmf under the sampler the candidates came from: the
    /// proxy density's pmf for MIS weights.
    pub pmf: f32,
    /// Takes the place of `1 / pmf` in the renderer's estimate: the
    /// estimate of the kept light times `weight` is unbiased. Finite and
    /// positive.
    pub weight: f32,
    /// Candidates drawn (the `M` of the estimator; candidates the sampler
    /// could not draw count too).
    pub candidates: u32,
}

/// What the renderer says of one candidate: its unshadowed contribution
/// and the payload to keep if it is chosen.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Evaluated<T> {
    /// The unshadowed estimate of the candidate light, `f cos Le / p_l`
    /// at the point the renderer sampled on it (a scalar: luminance, or any
    /// fixed scalar of the spectrum). 0 (or negative, NaN) when it cannot
    /// contribute: it is then never kept.
    pub contribution: f32,
    /// The renderer's own factor on the target, in `(0, inf)`; 1 for none
    /// (the sampler's learned visibility is applied on top). Values that
    /// are not finite and positive count as 1.
    pub factor: f32,
    /// Kept with the candidate if it is chosen.
    pub payload: T,
}

impl<T> Evaluated<T> {
    /// A candidate of unshadowed estimate `contribution`, factor 1.
    #[inline]
    pub fn new(contribution: f32, payload: T) -> Self {
        Self {
            contribution,
            factor: 1.0,
            payload,
        }
    }
}

/// Chooses a light at `ctx` by resampling `candidates.len()` candidates of
/// `sampler`: candidate `j` is drawn with `sampler.sample(ctx,
/// candidates[j])`, `evaluate(light, j)` says what it contributes without
/// visibility (the renderer samples a point on the light; `None` counts as
/// no contribution), and `u` keeps one in proportion to `contribution *
/// factor * sampler.visibility(ctx, light) / pmf` (see the module docs for
/// the weight). `None` when no
/// candidate contributes (then neither would the light sample: the
/// estimate is 0) or `candidates` is empty.
///
/// Deterministic: the same numbers and evaluations give the same choice.
/// `evaluate` is called once per candidate the sampler draws, in order.
pub fn resample<S, T>(
    sampler: &S,
    ctx: &ShadingContext,
    candidates: &[f32],
    u: f32,
    mut evaluate: impl FnMut(LightId, usize) -> Option<Evaluated<T>>,
) -> Option<Resampled<T>>
where
    S: LightSampler + ?Sized,
{
    let mut choice = Descent::new(u);
    let mut total = 0.0f64;
    let mut kept: Option<(LightId, f32, f64, T)> = None;
    for (j, &uj) in candidates.iter().enumerate() {
        let Some(x) = sampler.sample(ctx, uj) else {
            continue;
        };
        let Some(e) = evaluate(x.light, j) else {
            continue;
        };
        let c = f64::from(e.contribution);
        if !(c > 0.0 && c.is_finite()) {
            continue;
        }
        let valid = |x: f32| {
            let x = f64::from(x);
            if x > 0.0 && x.is_finite() { x } else { 1.0 }
        };
        let factor = valid(e.factor) * valid(sampler.visibility(ctx, x.light));
        let target = c * factor;
        let w = target / f64::from(x.pmf);
        if !(w > 0.0 && w.is_finite()) {
            continue;
        }
        let before = total;
        total += w;
        // Keep the new one with probability w / total (the first always);
        // the number is rescaled, so one number makes every decision.
        if choice.choose(w, before) == Some(Side::Left) {
            kept = Some((x.light, x.pmf, target, e.payload));
        }
    }
    let (light, pmf, target, payload) = kept?;
    let m = candidates.len() as f64;
    let weight = (total / m / target) as f32;
    (weight > 0.0 && weight.is_finite()).then_some(Resampled {
        light,
        payload,
        pmf,
        weight,
        candidates: candidates.len() as u32,
    })
}
