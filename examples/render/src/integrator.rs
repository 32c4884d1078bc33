//! The path tracer: next-event estimation from a `guiding::LightSampler`,
//! MIS-combined (power heuristic) with BSDF sampling or, for the guided
//! methods, with PPG's one-sample mixture of BSDF and guided sampling
//! (from an SD-tree's or the combined field's direction vertex). While
//! training it records direct-light estimates through the GLT's (or the
//! field's) light vertex and, once a path is done, incident radiance
//! through the direction vertices (the SD-tree's or the field's).

use crate::bvh::Hit;
use crate::geometry::{NO_EMITTER, offset_origin};
use crate::rng::Sampler;
use crate::scene::Scene;
use glam::{Vec2, Vec3};
use guiding::LightChoice;
use guiding::field::GuidingField;
use guiding::glt::Glt;
use guiding::luminance;
use guiding::mis::Convention;
use guiding::resampling::{Evaluated, resample};
use guiding::sd_tree::SdTree;
use guiding::{
    DirectionVertex, LightId, LightSampler, LightTree, LightVertex, PathRecorder, SamplerAt,
    ShadingContext,
};

/// What a path consults and trains.
#[derive(Clone, Copy)]
pub struct Guides<'a> {
    /// Chooses lights for next-event estimation, for methods that learn no
    /// light choice (the others choose through the GLT's or the field's
    /// light vertex).
    pub lights: Option<&'a (dyn LightSampler + Sync)>,
    /// The Guiding Light Tree that chooses lights and learns (`pt-glt`).
    pub glt: Option<&'a Glt<&'a LightTree>>,
    /// The SD-tree that guides directions (`ppg`).
    pub sd_tree: Option<&'a SdTree>,
    /// The combined field (`ppg-glt`): guides directions and NEE with one
    /// lookup per vertex.
    pub field: Option<&'a GuidingField<&'a LightTree>>,
    /// Whether to record training data this pass.
    pub train: bool,
    /// Light records carry the full contribution `f cos Le w / p` instead of
    /// the paper's `Le w / p` (without the BSDF and cosine).
    pub contribution_records: bool,
    /// Candidates of resampled next-event estimation
    /// (`guiding::resampling`, at most [`MAX_CANDIDATES`]), resampled with
    /// the light the continuation finds; 0 samples the light sampler
    /// directly.
    pub resample: usize,
    /// Resample at the first this-many non-specular vertices (0: all).
    pub resample_vertices: u32,
    /// Light samples per vertex without resampling (at least 1), averaged;
    /// MIS weighs the light strategy as this many samples.
    pub nee_samples: u32,
    /// Take `nee_samples` at the first this-many non-specular vertices (0:
    /// all); the others take one.
    pub nee_samples_vertices: u32,
}

/// The most candidates a resampled light choice draws.
pub const MAX_CANDIDATES: usize = 64;

/// A path vertex's learned light choice: the GLT's or the field's cell.
type Lights<'a> = LightVertex<'a, &'a LightTree>;

/// The recorder of a path's segments, each with the direction vertex it
/// records into.
pub type Recorder<'a> = PathRecorder<'a>;

/// The last scattering vertex, for MIS at the next emitter hit.
#[derive(Clone, Copy)]
struct Vertex<'a> {
    /// The learned light choice here, which later records go to.
    light: Option<Lights<'a>>,
    pos: Vec3,
    normal: Vec3,
    pdf_dir: f32,
    /// `f cos` of the direction sampled here (for contribution records).
    f_cos: Vec3,
    delta: bool,
    /// Resampled NEE here took the light the continuation found as a
    /// candidate: that light's emission is not counted again.
    resampled: bool,
    /// Light samples next-event estimation took here (MIS counts them).
    nee: u32,
}

/// The scalar a light record starts from: the luminance of the arriving
/// radiance `le`, times `f cos` with contribution records.
#[inline]
fn record_value(guides: &Guides, f_cos: Vec3, le: Vec3) -> f32 {
    if guides.contribution_records {
        luminance(f_cos * le)
    } else {
        luminance(le)
    }
}

/// A light (`id`, radiance `le`) found by the direction sampled at `prev`
/// (none for a camera ray or after a specular bounce: weight 1): its
/// MIS-weighted radiance joins the path, and, when training, its record
/// the light's (`pdf_light` is the light's solid-angle pdf from `prev`).
#[inline]
fn found_light(
    guides: &Guides,
    prev: Option<Vertex>,
    id: LightId,
    pdf_light: impl Fn(&Vertex) -> f32,
    le: Vec3,
    recorder: &mut Recorder,
) {
    let Some(v) = prev.filter(|v| !v.delta) else {
        recorder.add_radiance(le);
        return;
    };
    // The light strategy took `v.nee` samples at `v`.
    let ctx = ShadingContext::on_surface(v.pos, v.normal);
    let pmf = match (&v.light, guides.lights) {
        (Some(l), _) => l.pmf(id),
        (None, Some(fixed)) => fixed.pmf(&ctx, id),
        (None, None) => 0.0,
    } * v.nee as f32;
    let d = Convention::PbrtV4.bsdf_sample(pmf, pdf_light(&v), v.pdf_dir);
    recorder.add_radiance(le * d.weight);
    let value = record_value(guides, v.f_cos, le) * d.factor;
    if let Some(l) = v.light.filter(|_| guides.train && value > 0.0) {
        l.record_light(id, value);
    }
}

/// The radiance arriving at the camera along `origin + t dir`, and the
/// path's non-specular vertices (where it chooses a light) added to
/// `vertices`. `recorder` is reused between paths (it keeps its storage).
pub fn radiance<'a>(
    scene: &Scene,
    guides: &Guides<'a>,
    mut origin: Vec3,
    mut dir: Vec3,
    s: &mut Sampler,
    recorder: &mut Recorder<'a>,
    vertices: &mut u64,
) -> Vec3 {
    let max_depth = scene.effects.max_depth;
    let train_light = guides.train && (guides.glt.is_some() || guides.field.is_some());
    let train_sd = guides.train && (guides.sd_tree.is_some() || guides.field.is_some());
    let mut prev: Option<Vertex> = None;
    // True while every vertex so far was a delta (specular) one.
    let mut specular_chain = true;
    // The continuation ray's hit when the last vertex traced it already
    // (resampled NEE takes the light it finds as a candidate).
    let mut traced: Option<Option<Hit>> = None;
    // Non-specular vertices so far.
    let mut scattered = 0u32;
    recorder.clear();
    for depth in 0..max_depth {
        let hit = traced
            .take()
            .unwrap_or_else(|| scene.intersect(origin, dir));
        // With resampling, the light the last vertex's direction found
        // was one of its candidates: it counts only through that estimate.
        let counted = prev.is_some_and(|v| v.resampled);
        let Some(hit) = hit else {
            // The sky (the sun is a delta light: no BSDF sample finds it).
            if let Some((id, sky)) = scene.sky().filter(|_| !counted) {
                let pdf_light = |v: &Vertex| sky.pdf(v.normal, dir);
                found_light(guides, prev, id, pdf_light, sky.radiance, recorder);
            }
            break;
        };
        let prim = *scene.primitive(&hit);
        let p = origin + dir * hit.t;
        let ng = prim.normal(p);
        // "Directly visible" includes through specular (delta) chains.
        let seen_by_camera = prev.is_none_or(|v| v.delta && specular_chain);
        if prim.emitter != NO_EMITTER && !counted && (scene.camera_sees_emitters || !seen_by_camera)
        {
            let light = &scene.lights[prim.emitter as usize];
            let le = light.emitted(dir, ng);
            if le.max_element() > 0.0 {
                let id = LightId::Emitter(prim.emitter);
                let pdf_light = |v: &Vertex| light.pdf(v.pos, dir, (p - v.pos).length(), ng);
                found_light(guides, prev, id, pdf_light, le, recorder);
            }
        }
        let mat = scene.materials[prim.material as usize];
        if mat.is_black() || depth + 1 >= max_depth {
            break;
        }
        let wo = -dir;
        if mat.is_delta() {
            let Some(bs) = mat.sample(ng, wo, s.next2(), s.next()) else {
                break;
            };
            recorder.scatter_unrecorded(bs.weight);
            prev = Some(Vertex {
                light: None,
                pos: p,
                normal: ng,
                pdf_dir: 0.0,
                f_cos: Vec3::ONE,
                delta: true,
                resampled: false,
                nee: 1,
            });
            origin = offset_origin(p, ng, bs.wi);
            dir = bs.wi;
            continue;
        }
        specular_chain = false;
        let n = if ng.dot(wo) < 0.0 { -ng } else { ng };
        let ctx = ShadingContext::on_surface(p, n);
        // One lookup per structure: the field's vertex serves both
        // directions and lights.
        let field_vertex = guides.field.and_then(|f| f.vertex(&ctx));
        let light_vertex = match (field_vertex, guides.glt) {
            (Some(v), _) => Some(v.light),
            (None, Some(g)) => g.vertex(&ctx),
            (None, None) => None,
        };
        let cell: Option<DirectionVertex> = match (field_vertex, guides.sd_tree) {
            (Some(v), _) => Some(v.direction),
            (None, Some(t)) => t.vertex(&ctx),
            (None, None) => None,
        };
        let resampled = guides.resample > 0
            && (guides.resample_vertices == 0 || scattered < guides.resample_vertices);
        let draws = if resampled
            || (guides.nee_samples_vertices > 0 && scattered >= guides.nee_samples_vertices)
        {
            1
        } else {
            guides.nee_samples
        };
        scattered += 1;
        let here = Vertex {
            light: light_vertex,
            pos: p,
            normal: n,
            pdf_dir: 0.0,
            f_cos: Vec3::ONE,
            delta: false,
            resampled,
            nee: draws,
        };
        let frac = cell.map_or(1.0, |c| c.bsdf_fraction());
        let dir_pdf = |wi: Vec3, bsdf_pdf: f32| match cell {
            Some(c) => {
                let g = c.direction_pdf(wi);
                (frac * bsdf_pdf + (1.0 - frac) * g, g)
            }
            None => (bsdf_pdf, 0.0),
        };
        // The light vertex samples its cell's cut without a lookup per
        // query.
        let fixed_here;
        let nee: &dyn LightChoice = match (&light_vertex, guides.lights) {
            (Some(v), _) => v,
            (None, Some(fixed)) => {
                fixed_here = SamplerAt::new(fixed, &ctx);
                &fixed_here
            }
            (None, None) => break,
        };

        // The direction the path continues in: BSDF sampling, or PPG's
        // mixture. Chosen first: resampled NEE takes the light it finds as
        // a candidate.
        let u_tech = s.next();
        let (u2, u_lobe) = (s.next2(), s.next());
        let continuation = if u_tech < frac || cell.is_none() {
            mat.sample(n, wo, u2, u_lobe)
                .map(|bs| (bs.wi, bs.weight * bs.pdf, bs.pdf))
        } else {
            cell.map(|c| {
                let wi = c.sample_direction([u2.x, u2.y]).0;
                let (f, bsdf_pdf) = mat.eval(n, wo, wi);
                (wi, f, bsdf_pdf)
            })
        }
        .map(|(wi, f_cos, bsdf_pdf)| {
            let (pdf, guide_pdf) = dir_pdf(wi, bsdf_pdf);
            (wi, f_cos, bsdf_pdf, pdf, guide_pdf)
        })
        .filter(|c| c.3 > 0.0 && c.1.max_element() > 0.0);

        // Next-event estimation: one light from the sampler, or the one
        // resampling keeps of several candidates and the light the
        // continuation found (each with its light point and the weight
        // that replaces 1 / pmf).
        let point_on = |light: LightId, u: Vec2| match light {
            LightId::Emitter(e) => (scene.lights[e as usize].sample(p, u), false),
            LightId::Unbounded(i) => {
                let light = &scene.unbounded[i as usize];
                (light.sample(n, u), light.is_delta())
            }
        };
        // Without resampling, `nee_samples` light samples share the
        // estimate (MIS counts the light strategy's density that many
        // times).
        for _ in 0..draws {
            let chosen = if resampled {
                let m = guides.resample.min(MAX_CANDIDATES);
                let mut cands = [0.0f32; MAX_CANDIDATES];
                cands[..m].iter_mut().for_each(|c| *c = s.next());
                let u_keep = s.next();
                // Trace the continuation now; the next vertex reuses the hit.
                let found = continuation.and_then(|(wi, f_cos, _, pdf, _)| {
                    let next = scene.intersect(offset_origin(p, n, wi), wi);
                    traced = Some(next);
                    let (light, lp) = light_found(scene, p, n, wi, next)?;
                    let c = luminance(f_cos * lp.radiance) / lp.pdf;
                    Some((
                        light,
                        Evaluated::new(c, (lp, false)).with_densities(lp.pdf, pdf),
                    ))
                });
                resample(nee, &cands[..m], u_keep, found, |light, _| {
                    let (lp, delta) = point_on(light, s.next2());
                    let lp = lp?;
                    let (f, bsdf_pdf) = mat.eval(n, wo, lp.wi);
                    // The unshadowed estimate, `f cos Le / p_l`; the
                    // continuation's density of the direction (none for a
                    // delta light).
                    let c = luminance(f * lp.radiance) / lp.pdf;
                    let pdf = if delta {
                        0.0
                    } else {
                        dir_pdf(lp.wi, bsdf_pdf).0
                    };
                    Some(Evaluated::new(c, (lp, delta)).with_densities(lp.pdf, pdf))
                })
                .map(|r| (r.light, r.pmf, Some((r.weight, r.bsdf)), Some(r.payload)))
            } else {
                nee.sample(s.next())
                    .map(|ls| (ls.light, ls.pmf * draws as f32, None, None))
            };
            let Some((light, pmf, resampled, point)) = chosen else {
                continue;
            };
            let (point, delta) = match point {
                Some((lp, delta)) => (Some(lp), delta),
                None => point_on(light, s.next2()),
            };
            let ls = guiding::LightSample { light, pmf };
            let Some(lp) = point else {
                continue;
            };
            let (f, bsdf_pdf) = mat.eval(n, wo, lp.wi);
            if !(f.max_element() > 0.0 && lp.pdf > 0.0 && lp.radiance.max_element() > 0.0) {
                continue;
            }
            // A delta light has no competing BSDF sample.
            let p_dir = if delta {
                0.0
            } else {
                dir_pdf(lp.wi, bsdf_pdf).0
            };
            // Resampled with the continuation: its weight is the whole
            // estimate's (no MIS weight); the light the continuation found
            // is visible.
            let (factor, known_visible) = match resampled {
                Some((w, from_bsdf)) => (w / lp.pdf, from_bsdf),
                None => (
                    Convention::PbrtV4
                        .light_sample(ls.pmf, lp.pdf, p_dir)
                        .factor,
                    false,
                ),
            };
            let visible = known_visible || {
                let o = offset_origin(p, n, lp.wi);
                let target = match ls.light {
                    LightId::Emitter(e) => e,
                    LightId::Unbounded(_) => NO_EMITTER,
                };
                !scene.occluded(o, lp.wi, lp.dist, target)
            };
            let c = f * lp.radiance * factor;
            if !c.is_finite() {
                continue;
            }
            let value = record_value(guides, f, lp.radiance) * factor;
            if visible {
                recorder.add_radiance(c);
                if let Some(l) = here.light.filter(|_| train_light) {
                    l.record_light(ls.light, value);
                }
            }
            // Visibility records come from light samples only (the
            // continuation's light is visible by construction).
            if let Some(l) = here.light.filter(|_| train_light && !known_visible) {
                let seen = if visible { value } else { 0.0 };
                l.record_visibility(ls.light, seen, value);
            }
        }

        // Continue the path.
        let Some((wi, f_cos, bsdf_pdf, pdf, guide_pdf)) = continuation else {
            break;
        };
        let weight = f_cos / pdf;
        if train_sd {
            recorder.push_segment(cell, wi, pdf, bsdf_pdf, guide_pdf, weight);
        } else {
            recorder.scatter_unrecorded(weight);
        }
        prev = Some(Vertex {
            pdf_dir: pdf,
            f_cos,
            ..here
        });
        origin = offset_origin(p, n, wi);
        dir = wi;
    }
    if train_sd {
        recorder.finish();
    }
    *vertices += u64::from(scattered);
    let l = recorder.estimate();
    if l.is_finite() { l } else { Vec3::ZERO }
}

/// The light a ray from `p` (normal `n`) along `wi` reaches, `next` its
/// hit: an emitter's point, or the sky when it escapes; as the light point
/// light sampling would have given (its solid-angle pdf, the radiance
/// arriving). `None` when it reaches no light or one that sends nothing
/// this way.
fn light_found(
    scene: &Scene,
    p: Vec3,
    n: Vec3,
    wi: Vec3,
    next: Option<Hit>,
) -> Option<(LightId, crate::lights::LightPoint)> {
    let (light, lp) = match next {
        Some(hit) => {
            let prim = scene.primitive(&hit);
            if prim.emitter == NO_EMITTER {
                return None;
            }
            let light = &scene.lights[prim.emitter as usize];
            let y = offset_origin(p, n, wi) + wi * hit.t;
            let ny = prim.normal(y);
            let dist = (y - p).length();
            let lp = crate::lights::LightPoint {
                wi,
                dist,
                pdf: light.pdf(p, wi, dist, ny),
                radiance: light.emitted(wi, ny),
            };
            (LightId::Emitter(prim.emitter), lp)
        }
        None => {
            let (id, sky) = scene.sky()?;
            let lp = crate::lights::LightPoint {
                wi,
                dist: f32::INFINITY,
                pdf: sky.pdf(n, wi),
                radiance: sky.radiance,
            };
            (id, lp)
        }
    };
    (lp.pdf > 0.0 && lp.pdf.is_finite() && lp.radiance.max_element() > 0.0).then_some((light, lp))
}
