//! Resampled light choice (resampled importance sampling, Talbot et al.
//! 2005; the candidate-reservoir form of ReSTIR, Bitterli et al. 2020):
//! draw `M` candidate lights from any [`LightChoice`] (a guide's vertex,
//! or a sampler at the point), let the renderer
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
//! renderer's factor, if any, times the square root of what the sampler
//! learned of the light's visibility, [`LightChoice::visibility`]), one
//! candidate `s` is kept with probability `w_s / sum w`, and
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
//! closed form, which `examples/render/src/bin/light_limit` computes
//! (`variance::resampled_parts`).
//!
//! Why the square root: the learned visibility `v` is the chance that a
//! light of a cluster reaches the cell's points, while at one point a
//! light is seen or not. The variance of many candidates is, up to terms
//! that do not depend on the target, `(sum_l t_l) (sum_l f_l^2 / t_l)`;
//! with `f_l` seen with probability `v_l`, its expectation `(sum_l g_l
//! s_l) (sum_l g_l v_l / s_l)` (`t_l = g_l s_l`) is smallest for `s_l`
//! proportional to `sqrt(v_l)` (Cauchy-Schwarz). Measured on `city` with 8
//! candidates and the BSDF sample: 1.53 with `v`, 1.13 with `sqrt(v)`,
//! 1.44 without any (docs/experiments/light-selection.md).
//!
//! One uniform number chooses among the candidates, in a single pass that
//! keeps only the current choice (weighted reservoir sampling, with the
//! number rescaled at each candidate as the crate's tree descents do), so
//! nothing is allocated and the renderer's payload of each candidate (its
//! light sample, say) is moved, never copied or stored `M` times.
//!
//! # The BSDF sample as a candidate
//!
//! The density of the kept light is not known in closed form, so MIS with
//! a BSDF sample needs care. The better way (on `city` at 8 candidates
//! the direct light's variance falls from 1.79 with the MIS proxy below to
//! 1.13, docs/experiments/light-selection.md) resamples
//! the BSDF sample *with* the light candidates, as ReSTIR's initial
//! candidates do: the renderer traces its BSDF sample first (the direction
//! it continues the path with, or pbrt's separate one), and passes the
//! light it found, if any, as one more candidate. Each candidate's weight
//! then follows the balance heuristic over the two strategies,
//!
//! ```text
//! w_j = c_j t_j / (M P(l_j) + p_b / p_l)
//! ```
//!
//! (`p_b` the BSDF sample's density of the candidate's direction, `p_l`
//! the light's own density of its point), one candidate is kept as above
//! and `weight = sum_j w_j / (c_s t_s)`. The kept light's estimate `f cos
//! Le V / p_l` times `weight` is the whole direct light of both strategies:
//! there is no MIS weight, and the emission the BSDF sample found counts
//! only through this estimate (the renderer does not add it again). Kept,
//! the BSDF candidate is known to be visible (its ray reached the light):
//! no shadow ray, and its target carries no learned visibility.
//!
//! A renderer that keeps its BSDF sample apart instead passes no BSDF
//! candidate and `p_b = 0` ([`Evaluated::new`]), and weighs the two
//! strategies with the candidate density as the light strategy's proxy
//! density, `P(l) p_l` (any weights that sum to one over the strategies
//! keep the combination unbiased): [`Resampled::pmf`] is that proxy's pmf,
//! [`crate::mis::resampled_light_sample`] weighs the light sample under
//! pbrt-v4's convention, and [`crate::Convention::PbrtV4`]`.bsdf_sample`
//! the BSDF sample, with the pmf of the light it hit, as without
//! resampling.

use crate::light_sampler::{LightChoice, LightId};
use crate::math::scalar::sqrt64;
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
    /// proxy density's pmf for MIS weights when the BSDF sample is kept
    /// apart.
    pub pmf: f32,
    /// Takes the place of `1 / pmf` in the renderer's estimate: the
    /// estimate `f cos Le V / p_l` of the kept light times `weight` is
    /// unbiased (with the BSDF sample as a candidate, it is the whole
    /// direct light, no MIS weight). Finite and positive.
    pub weight: f32,
    /// Light candidates drawn (the `M` of the estimator; candidates the
    /// sampler could not draw count too).
    pub candidates: u32,
    /// Whether the kept candidate is the BSDF sample's: its ray reached the
    /// light, so it is visible (no shadow ray).
    pub bsdf: bool,
}

/// What the renderer says of one candidate: its unshadowed contribution,
/// the densities of its direction, and the payload to keep if it is
/// chosen.
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
    /// The light's own solid-angle density of the point, `p_l`. Read only
    /// with a BSDF density.
    pub pdf_light: f32,
    /// The BSDF sample's solid-angle density of the candidate's direction
    /// when the BSDF sample takes part as a candidate (0 for a delta
    /// light); 0 when it does not. A candidate with a density that is
    /// negative or not finite, or a BSDF density without a positive light
    /// density, is ignored.
    pub pdf_bsdf: f32,
    /// Kept with the candidate if it is chosen.
    pub payload: T,
}

impl<T> Evaluated<T> {
    /// A candidate of unshadowed estimate `contribution`, factor 1, without
    /// a competing BSDF sample.
    #[inline]
    pub fn new(contribution: f32, payload: T) -> Self {
        Self {
            contribution,
            factor: 1.0,
            pdf_light: 0.0,
            pdf_bsdf: 0.0,
            payload,
        }
    }

    /// The same candidate with the densities its direction has under the
    /// light's own sampling (`pdf_light`) and under the BSDF sample that
    /// takes part as a candidate (`pdf_bsdf`).
    #[inline]
    pub fn with_densities(self, pdf_light: f32, pdf_bsdf: f32) -> Self {
        Self {
            pdf_light,
            pdf_bsdf,
            ..self
        }
    }

    /// `p_b / p_l`, the BSDF strategy's share in the candidate's
    /// denominator; `None` for densities that cannot be used.
    #[inline]
    fn bsdf_ratio(&self) -> Option<f64> {
        let (pl, pb) = (f64::from(self.pdf_light), f64::from(self.pdf_bsdf));
        if pb == 0.0 {
            Some(0.0)
        } else if pb > 0.0 && pb.is_finite() && pl > 0.0 && pl.is_finite() {
            Some(pb / pl)
        } else {
            None
        }
    }
}

/// How many candidates [`resample`] draws in one
/// [`LightChoice::sample_candidates`] call.
const BATCH: usize = 16;

/// The light the BSDF sample found, as a candidate ([`resample`]): the
/// light and the renderer's evaluation of the point it hit (its
/// `pdf_bsdf` positive).
pub type BsdfCandidate<T> = (LightId, Evaluated<T>);

/// Chooses a light at a shading point by resampling `candidates.len()`
/// candidates of the point's light choice `lights` (a guide's vertex, or
/// [`LightSampler::at`](crate::LightSampler::at) the point), and the BSDF
/// sample's light when it takes part: candidate `j` is drawn with
/// `lights.sample_with_visibility(candidates[j])` (all of them through
/// [`LightChoice::sample_candidates`], a batch at a time),
/// `evaluate(light, j)` says what it contributes without visibility (the
/// renderer samples a point on the light; `None` counts as no
/// contribution), and `u` keeps one in proportion to its weight (see the
/// module docs), whose target is `contribution * factor` times the square
/// root of the learned `sampler.visibility(ctx, light)` for light
/// candidates (the BSDF candidate is visible). `bsdf` is the light the
/// BSDF sample found, if it takes part and found one. `None` when no
/// candidate contributes (then neither would the light sample: the
/// estimate is 0) or there are no candidates.
///
/// Deterministic: the same numbers and evaluations give the same choice.
/// `evaluate` is called once per candidate the sampler draws, in order.
pub fn resample<L, T>(
    lights: &L,
    candidates: &[f32],
    u: f32,
    bsdf: Option<BsdfCandidate<T>>,
    mut evaluate: impl FnMut(LightId, usize) -> Option<Evaluated<T>>,
) -> Option<Resampled<T>>
where
    L: LightChoice + ?Sized,
{
    let m = candidates.len() as f64;
    let mut reservoir = Reservoir::new(u);
    // Drawn a batch at a time, so a guide's walks share their common steps
    // (`LightChoice::sample_candidates`).
    let mut drawn = [None; BATCH];
    for (b, batch) in candidates.chunks(BATCH).enumerate() {
        let drawn = &mut drawn[..batch.len()];
        lights.sample_candidates(batch, drawn);
        for (i, d) in drawn.iter().enumerate() {
            let Some((x, learned)) = *d else {
                continue;
            };
            let Some(e) = evaluate(x.light, b * BATCH + i) else {
                continue;
            };
            reservoir.offer(x.light, x.pmf, m, learned, e, false);
        }
    }
    if let Some((light, e)) = bsdf.filter(|(_, e)| e.pdf_bsdf > 0.0) {
        reservoir.offer(light, lights.pmf(light), m, 1.0, e, true);
    }
    let (light, pmf, target, payload, from_bsdf) = reservoir.kept?;
    let weight = (reservoir.total / target) as f32;
    (weight > 0.0 && weight.is_finite()).then_some(Resampled {
        light,
        payload,
        pmf,
        weight,
        candidates: candidates.len() as u32,
        bsdf: from_bsdf,
    })
}

/// One-number weighted reservoir sampling: the sum of the weights offered
/// and the one kept (light, pmf, target, payload, whether the BSDF's).
struct Reservoir<T> {
    choice: Descent,
    total: f64,
    kept: Option<(LightId, f32, f64, T, bool)>,
}

impl<T> Reservoir<T> {
    fn new(u: f32) -> Self {
        Self {
            choice: Descent::new(u),
            total: 0.0,
            kept: None,
        }
    }

    /// Offers candidate `light` of pmf `pmf` among `m` light candidates,
    /// with the sampler's learned visibility `learned` and the renderer's
    /// evaluation `e`; ignored unless its weight is positive and finite.
    fn offer(
        &mut self,
        light: LightId,
        pmf: f32,
        m: f64,
        learned: f32,
        e: Evaluated<T>,
        bsdf: bool,
    ) {
        // A contribution that is not positive and finite gives a weight
        // that is not either: ignored below with every other bad weight.
        let c = f64::from(e.contribution);
        let Some(ratio) = e.bsdf_ratio() else {
            return;
        };
        let valid = |x: f32| {
            let x = f64::from(x);
            if x > 0.0 && x.is_finite() { x } else { 1.0 }
        };
        // The square root of the learned visibility (module docs).
        let target = c * valid(e.factor) * sqrt64(valid(learned));
        let pmf64 = if pmf > 0.0 && pmf.is_finite() {
            f64::from(pmf)
        } else {
            0.0
        };
        let w = target / (m * pmf64 + ratio);
        if !(w > 0.0 && w.is_finite()) {
            return;
        }
        let before = self.total;
        self.total += w;
        // Keep the new one with probability w / total (the first always);
        // the number is rescaled, so one number makes every decision.
        if self.choice.choose(w, before) == Some(Side::Left) {
            self.kept = Some((light, pmf, target, e.payload, bsdf));
        }
    }
}
