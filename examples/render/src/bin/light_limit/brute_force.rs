//! Every light's true contribution at a shading point, by brute force:
//! light samples on every emitter with real shadow rays, and BSDF samples
//! traced into the scene.

use crate::geometry::{NO_EMITTER, offset_origin};
use crate::rng::Sampler;
use crate::scene::Scene;
use crate::shading_points::ShadingPoint;
use guiding::LightId;
use guiding::luminance;
use std::collections::HashMap;

/// One light sample of the estimator's next-event part, kept where it
/// contributes (unoccluded, in front of the light, non-zero BSDF).
#[derive(Clone, Copy, Debug)]
pub struct NeeSample {
    /// Luminance of `f cos * Le` (visibility is 1: occluded samples are
    /// not kept).
    pub g: f64,
    /// Solid-angle pdf of the light point, given the light.
    pub pdf_light: f64,
    /// The BSDF's pdf of the same direction (for the MIS weight).
    pub pdf_bsdf: f64,
}

/// One light with a non-zero contribution at a point.
#[derive(Clone, Debug)]
pub struct LightTerm {
    /// The light.
    pub light: LightId,
    /// Its contributing samples from the evaluation set (`m` samples were
    /// drawn per light; the others contributed nothing).
    pub eval: Vec<NeeSample>,
    /// The evaluation set's occluded samples (in front of the light, with a
    /// non-zero BSDF): `g` is what they would contribute unoccluded.
    pub occluded: Vec<NeeSample>,
    /// Mean of `(g / pdf_light)^2` over an independent, stratified
    /// held-out set of samples: the light's second moment, as a
    /// clairvoyant pmf would know it without seeing the samples that
    /// evaluate it.
    pub held_out_m2: f64,
    /// Mean of the *unshadowed* `g / pdf_light` over the evaluation set
    /// (occluded samples included): the light's contribution without
    /// visibility, which a resampling target integrates to.
    pub unshadowed: f64,
    /// The light's visibility at the point from the held-out set: shadowed
    /// over unshadowed contribution (1 where it has no unshadowed one).
    pub held_out_visibility: f64,
    /// Mean of the unshadowed `(g / pdf_light)^2` over the held-out set.
    pub held_out_unshadowed_m2: f64,
}

/// One BSDF sample of the estimator that found an emitter.
#[derive(Clone, Copy, Debug)]
pub struct BsdfHit {
    /// Index of the light it hit in [`PointTerms::lights`].
    pub term: usize,
    /// Luminance of `f cos * Le`.
    pub g: f64,
    /// The BSDF's pdf of the direction.
    pub pdf_bsdf: f64,
    /// The solid-angle pdf with which sampling that light gives the point.
    pub pdf_light: f64,
}

/// Everything the exact variance needs at one shading point.
#[derive(Clone, Debug)]
pub struct PointTerms {
    /// The point.
    pub at: ShadingPoint,
    /// Lights with a non-zero unshadowed contribution in either sample set
    /// (or found by a BSDF sample).
    pub lights: Vec<LightTerm>,
    /// BSDF samples that hit an emitter.
    pub bsdf: Vec<BsdfHit>,
    /// Light samples drawn per light and per set.
    pub m: usize,
    /// BSDF samples drawn.
    pub k: usize,
    /// The direct light at the point (light-sampling estimate from the
    /// evaluation set, no MIS), for the relative normalisation.
    pub direct: f64,
}

/// Draws `m` samples of one light (emitter or unbounded) from `at`; calls
/// `keep` with each one that would contribute without occluders, and
/// whether it is visible. With `stratified`, and `m` a square, the sample
/// numbers are jittered in a `sqrt(m) x sqrt(m)` grid.
fn light_samples(
    scene: &Scene,
    at: &ShadingPoint,
    light: LightId,
    (m, stratified): (usize, bool),
    s: &mut Sampler,
    mut keep: impl FnMut(NeeSample, bool),
) {
    let side = (m as f64).sqrt().round() as usize;
    let grid = stratified && side * side == m;
    for i in 0..m {
        let u = if grid {
            let j = s.next2();
            let cell = glam::Vec2::new((i % side) as f32, (i / side) as f32);
            ((cell + j) / side as f32).min(glam::Vec2::splat(1.0 - f32::EPSILON / 2.0))
        } else {
            s.next2()
        };
        let (point, target, delta) = match light {
            LightId::Emitter(e) => (scene.lights[e as usize].sample(at.p, u), e, false),
            LightId::Unbounded(i) => {
                let light = &scene.unbounded[i as usize];
                (light.sample(at.n, u), NO_EMITTER, light.is_delta())
            }
        };
        let Some(lp) = point else { continue };
        if lp.pdf.is_nan() || lp.pdf <= 0.0 || lp.radiance.max_element() <= 0.0 {
            continue;
        }
        let (f, pdf_bsdf) = at.material.eval(at.n, at.wo, lp.wi);
        let g = f64::from(luminance(f * lp.radiance));
        if g.is_nan() || g <= 0.0 {
            continue;
        }
        let o = offset_origin(at.p, at.n, lp.wi);
        let visible = !scene.occluded(o, lp.wi, lp.dist, target);
        keep(
            NeeSample {
                g,
                pdf_light: f64::from(lp.pdf),
                // No BSDF sample competes with a delta light.
                pdf_bsdf: if delta { 0.0 } else { f64::from(pdf_bsdf) },
            },
            visible,
        );
    }
}

/// Brute force at one point: `m` evaluation samples and `held` stratified
/// held-out samples of every light, `k` BSDF samples.
pub fn measure(
    scene: &Scene,
    at: ShadingPoint,
    (m, held): (usize, usize),
    k: usize,
    seed: u64,
) -> PointTerms {
    let mut s = Sampler::new(seed, 0xb7u64, 1);
    let mut lights = Vec::new();
    let mut direct = 0.0;
    let ids = (0..scene.lights.len() as u32)
        .map(LightId::Emitter)
        .chain((0..scene.unbounded.len() as u32).map(LightId::Unbounded));
    for light in ids {
        let (mut eval, mut occluded) = (Vec::new(), Vec::new());
        let mut unshadowed = 0.0;
        light_samples(scene, &at, light, (m, false), &mut s, |x, visible| {
            unshadowed += x.g / x.pdf_light;
            if visible {
                eval.push(x);
            } else {
                occluded.push(x);
            }
        });
        let (mut m2, mut seen, mut all, mut m2u) = (0.0, 0.0, 0.0, 0.0);
        light_samples(scene, &at, light, (held, true), &mut s, |x, visible| {
            all += x.g / x.pdf_light;
            m2u += (x.g / x.pdf_light).powi(2);
            if visible {
                m2 += (x.g / x.pdf_light).powi(2);
                seen += x.g / x.pdf_light;
            }
        });
        if unshadowed == 0.0 && all == 0.0 {
            continue;
        }
        direct += eval.iter().map(|x| x.g / x.pdf_light).sum::<f64>() / m as f64;
        lights.push(LightTerm {
            light,
            eval,
            occluded,
            held_out_m2: m2 / held.max(1) as f64,
            unshadowed: unshadowed / m as f64,
            held_out_visibility: if all > 0.0 { seen / all } else { 1.0 },
            held_out_unshadowed_m2: m2u / held.max(1) as f64,
        });
    }
    let mut index: HashMap<LightId, usize> = lights
        .iter()
        .enumerate()
        .map(|(i, t)| (t.light, i))
        .collect();
    let mut bsdf = Vec::new();
    for _ in 0..k {
        let Some(bs) = at.material.sample(at.n, at.wo, s.next2(), s.next()) else {
            continue;
        };
        if bs.pdf.is_nan() || bs.pdf <= 0.0 {
            continue;
        }
        let f_cos = bs.weight * bs.pdf;
        let o = offset_origin(at.p, at.n, bs.wi);
        let (light, le, pdf_light) = match scene.intersect(o, bs.wi) {
            Some(hit) => {
                let prim = *scene.primitive(&hit);
                if prim.emitter == NO_EMITTER {
                    continue;
                }
                let l = &scene.lights[prim.emitter as usize];
                let y = o + bs.wi * hit.t;
                let ny = prim.normal(y);
                let dist = (y - at.p).length();
                (
                    LightId::Emitter(prim.emitter),
                    l.emitted(bs.wi, ny),
                    l.pdf(at.p, bs.wi, dist, ny),
                )
            }
            None => match scene.sky() {
                Some((id, sky)) => (id, sky.radiance, sky.pdf(at.n, bs.wi)),
                None => continue,
            },
        };
        let g = f64::from(luminance(f_cos * le));
        if g.is_nan() || g <= 0.0 {
            continue;
        }
        // A light found only by BSDF sampling still needs its pmf.
        let term = *index.entry(light).or_insert_with(|| {
            lights.push(LightTerm {
                light,
                eval: Vec::new(),
                occluded: Vec::new(),
                held_out_m2: 0.0,
                unshadowed: 0.0,
                held_out_visibility: 1.0,
                held_out_unshadowed_m2: 0.0,
            });
            lights.len() - 1
        });
        bsdf.push(BsdfHit {
            term,
            g,
            pdf_bsdf: f64::from(bs.pdf),
            pdf_light: f64::from(pdf_light),
        });
    }
    PointTerms {
        at,
        lights,
        bsdf,
        m,
        k,
        direct,
    }
}
