//! A path tracer over rs_pbrt's public types (its scene, camera, BSDFs and
//! lights), written here because rs_pbrt's integrators cannot take a light
//! sampler from outside. It is pbrt-v3's `PathIntegrator` in behaviour:
//! emission counted at the camera vertex only, one light per vertex
//! chosen by a [`LightStrategy`], that light estimated by one light sample
//! and one BSDF sample with the power heuristic (the crate's
//! `Convention::PbrtV3`), Russian roulette after three bounces. Every
//! strategy, rs_pbrt's and the GLT, runs through this same loop, so the
//! comparison differs only in the light choice.

use crate::scene_file::Loaded;
use guiding::glam::Vec3;
use guiding::{Convention, DirectLight};
use rayon::prelude::*;
use rs_pbrt::core::camera::CameraSample;
use rs_pbrt::core::geometry::{Point2f, Ray, Vector3f, vec3_abs_dot_nrmf};
use rs_pbrt::core::interaction::{Interaction, InteractionCommon, SurfaceInteraction};
use rs_pbrt::core::light::{Light, VisibilityTester, is_delta_light};
use rs_pbrt::core::lightdistrib::{LightDistribution, create_light_sample_distribution};
use rs_pbrt::core::material::TransportMode;
use rs_pbrt::core::pbrt::Spectrum;
use rs_pbrt::core::reflection::BxdfType;
use rs_pbrt::core::sampling::Distribution1D;
use std::cell::Cell;
use std::sync::Arc;
use std::time::Instant;

/// Chooses one light per shading point.
pub trait LightStrategy: Sync {
    /// What the strategy knows at one shading point.
    type At<'a>: LightAt
    where
        Self: 'a;
    /// The strategy's view from `it` (one lookup per vertex).
    fn at<'a>(&'a self, it: &SurfaceInteraction) -> Self::At<'a>;
    /// Called after every pass of samples over the image.
    fn refine(&mut self) {}
}

/// The light choice at one shading point.
pub trait LightAt {
    /// rs_pbrt's index of the chosen light and its probability.
    fn choose(&self, u: f32) -> Option<(usize, f32)>;
    /// What the chosen light's estimate found (the crate's light record).
    fn record(&self, _light: usize, _value: f32) {}
}

/// One of rs_pbrt's own light sample distributions (`uniform`, `power`,
/// `spatial`: pbrt-v3's `lightsamplestrategy`).
pub struct RsPbrtStrategy(Arc<LightDistribution>);

impl RsPbrtStrategy {
    /// rs_pbrt's distribution named `name` over `loaded`'s lights.
    pub fn new(name: &str, loaded: &Loaded) -> Self {
        Self(
            create_light_sample_distribution(name.to_string(), &loaded.scene)
                .expect("a distribution"),
        )
    }
}

impl LightStrategy for RsPbrtStrategy {
    type At<'a> = Arc<Distribution1D>;
    fn at<'a>(&'a self, it: &SurfaceInteraction) -> Self::At<'a> {
        self.0.lookup(&it.common.p)
    }
}

impl LightAt for Arc<Distribution1D> {
    fn choose(&self, u: f32) -> Option<(usize, f32)> {
        let mut pmf = 0.0;
        let light = self.sample_discrete(u, Some(&mut pmf));
        (pmf > 0.0).then_some((light, pmf))
    }
}

/// A small, fast generator (PCG32) per pixel and pass.
pub struct Rng(u64);

impl Rng {
    /// The stream of pixel `pixel` in pass `pass`.
    pub fn new(pixel: u64, pass: u64) -> Self {
        let mut r = Rng((pixel << 20 ^ pass).wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1);
        r.f32();
        r
    }
    /// A number in `[0, 1)`.
    pub fn f32(&mut self) -> f32 {
        let old = self.0;
        self.0 = old
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        let x = (((old >> 18) ^ old) >> 27) as u32;
        let x = x.rotate_right((old >> 59) as u32);
        (x >> 8) as f32 * (1.0 / (1u32 << 24) as f32)
    }
    fn p2(&mut self) -> Point2f {
        Point2f {
            x: self.f32(),
            y: self.f32(),
        }
    }
}

const NON_SPECULAR: u8 = BxdfType::BsdfAll as u8 & !(BxdfType::BsdfSpecular as u8);

fn rgb(s: Spectrum) -> Vec3 {
    Vec3::from(s.c)
}

/// The chosen light's direct light at `it`: a light sample and a BSDF
/// sample of that light, MIS-weighted and divided by its pmf; each
/// sample's record goes to the strategy.
fn direct(loaded: &Loaded, it: &SurfaceInteraction, at: &impl LightAt, rng: &mut Rng) -> Vec3 {
    let Some(bsdf) = it.bsdf.as_ref() else {
        return Vec3::ZERO;
    };
    let Some((index, pmf)) = at.choose(rng.f32()) else {
        return Vec3::ZERO;
    };
    let light: &Light = &loaded.scene.lights[index];
    let (wo, ns) = (it.common.wo, it.shading.n);
    let mut sum = Vec3::ZERO;
    // The light sample.
    let mut wi = Vector3f::default();
    let (mut pdf_light, mut p_light) = (0.0, InteractionCommon::default());
    let mut vis = VisibilityTester::default();
    let le = light.sample_li(
        &it.common,
        &mut p_light,
        rng.p2(),
        &mut wi,
        &mut pdf_light,
        &mut vis,
    );
    let delta = is_delta_light(light.get_flags());
    if pdf_light > 0.0 && !le.is_black() {
        let f_cos = rgb(bsdf.f(&wo, &wi, NON_SPECULAR)) * vec3_abs_dot_nrmf(&wi, &ns);
        if f_cos != Vec3::ZERO {
            let pdf_bsdf = if delta {
                0.0
            } else {
                bsdf.pdf(&wo, &wi, NON_SPECULAR)
            };
            let d = Convention::PbrtV3.light_sample(pmf, pdf_light, pdf_bsdf);
            let e = d.estimate(rgb(le), f_cos, vis.unoccluded(&loaded.scene));
            sum += e.contribution;
            at.record(index, e.record);
        }
    }
    if delta {
        return sum;
    }
    // The BSDF sample: it counts if it reaches this light.
    let (mut pdf_bsdf, mut sampled) = (0.0, 0u8);
    let f = bsdf.sample_f(
        &wo,
        &mut wi,
        &rng.p2(),
        &mut pdf_bsdf,
        NON_SPECULAR,
        &mut sampled,
    );
    let f_cos = rgb(f) * vec3_abs_dot_nrmf(&wi, &ns);
    if f_cos == Vec3::ZERO || pdf_bsdf <= 0.0 {
        return sum;
    }
    let pdf_light = light.pdf_li(it, &wi);
    if pdf_light <= 0.0 {
        return sum;
    }
    let d: DirectLight = Convention::PbrtV3.bsdf_sample(pmf, pdf_light, pdf_bsdf);
    let ray = it.spawn_ray(&wi);
    let mut hit = SurfaceInteraction::default();
    let le = if loaded.scene.intersect(&ray, &mut hit) {
        let on_light = hit.primitive.map(|p| p as usize) == loaded.primitive_of[index];
        if on_light {
            rgb(hit.le(&-wi))
        } else {
            Vec3::ZERO
        }
    } else {
        rgb(light.le(&ray))
    };
    let e = d.estimate(le, f_cos, le != Vec3::ZERO);
    sum += e.contribution;
    at.record(index, e.record);
    sum
}

/// The radiance along the camera ray `ray` (pbrt-v3's path tracer, at most
/// `max_depth` bounces).
pub fn radiance(
    loaded: &Loaded,
    strategy: &impl LightStrategy,
    ray: Ray,
    rng: &mut Rng,
    max_depth: u32,
) -> Vec3 {
    let (mut l, mut beta, mut ray, mut specular) = (Vec3::ZERO, Vec3::ONE, ray, false);
    for bounce in 0..=max_depth {
        // Emission is counted where no light sample could have found it.
        let count_emission = bounce == 0 || specular;
        let mut isect = SurfaceInteraction::default();
        if !loaded.scene.intersect(&ray, &mut isect) {
            if count_emission {
                for light in &loaded.scene.infinite_lights {
                    l += beta * rgb(light.le(&ray));
                }
            }
            break;
        }
        if count_emission {
            l += beta * rgb(isect.le(&-ray.d));
        }
        if bounce == max_depth {
            break;
        }
        isect.compute_scattering_functions(&ray, true, TransportMode::Radiance);
        let Some(bsdf) = isect.bsdf.as_ref() else {
            break;
        };
        if bsdf.num_components(NON_SPECULAR) > 0 {
            let at = strategy.at(&isect);
            l += beta * direct(loaded, &isect, &at, rng);
        }
        let (mut wi, mut pdf, mut sampled) = (Vector3f::default(), 0.0, 0u8);
        let wo = isect.common.wo;
        let f = bsdf.sample_f(
            &wo,
            &mut wi,
            &rng.p2(),
            &mut pdf,
            BxdfType::BsdfAll as u8,
            &mut sampled,
        );
        if f.is_black() || pdf <= 0.0 {
            break;
        }
        beta *= rgb(f) * vec3_abs_dot_nrmf(&wi, &isect.shading.n) / pdf;
        specular = sampled & BxdfType::BsdfSpecular as u8 != 0;
        ray = isect.spawn_ray(&wi);
        if bounce > 3 {
            let q = (1.0 - beta.max_element()).max(0.05);
            if rng.f32() < q {
                break;
            }
            beta /= 1.0 - q;
        }
    }
    if l.is_finite() { l } else { Vec3::ZERO }
}

/// One camera sample of pixel `(x, y)`: its ray's radiance times the
/// camera's weight.
pub fn sample_pixel(
    loaded: &Loaded,
    strategy: &impl LightStrategy,
    (x, y): (usize, usize),
    rng: &mut Rng,
) -> Vec3 {
    let sample = CameraSample {
        p_film: Point2f {
            x: x as f32 + rng.f32(),
            y: y as f32 + rng.f32(),
        },
        p_lens: rng.p2(),
        time: 0.0,
    };
    let mut ray = Ray {
        t_max: Cell::new(f32::INFINITY),
        ..Default::default()
    };
    let weight = loaded.camera.generate_ray_differential(&sample, &mut ray);
    if weight > 0.0 {
        weight * radiance(loaded, strategy, ray, rng, loaded.max_depth)
    } else {
        Vec3::ZERO
    }
}

/// A linear RGB image, row-major.
#[derive(Clone)]
pub struct Image {
    /// Width and height in pixels.
    pub size: (usize, usize),
    /// The pixels' summed radiance.
    pub sum: Vec<Vec3>,
    /// Samples per pixel summed so far.
    pub spp: u32,
}

impl Image {
    /// An empty image of `size`.
    pub fn new(size: (usize, usize)) -> Self {
        Self {
            size,
            sum: vec![Vec3::ZERO; size.0 * size.1],
            spp: 0,
        }
    }
    /// The mean radiance of each pixel.
    pub fn pixels(&self) -> Vec<Vec3> {
        self.sum
            .iter()
            .map(|s| *s / self.spp.max(1) as f32)
            .collect()
    }
}

/// Adds one pass of `spp` samples per pixel to `image` (pass number `pass`
/// seeds the random numbers), rows in parallel. Pixels not started by
/// `deadline` are skipped, and then the pass is not added: false.
pub fn render_pass(
    loaded: &Loaded,
    strategy: &impl LightStrategy,
    image: &mut Image,
    spp: u32,
    pass: u64,
    deadline: Instant,
) -> bool {
    let w = image.size.0;
    let mut sum = image.sum.clone();
    let finished = sum
        .par_chunks_mut(w)
        .enumerate()
        .map(|(y, row)| {
            for (x, px) in row.iter_mut().enumerate() {
                if Instant::now() > deadline {
                    return false;
                }
                let mut rng = Rng::new((y * w + x) as u64, pass);
                for _ in 0..spp {
                    *px += sample_pixel(loaded, strategy, (x, y), &mut rng);
                }
            }
            true
        })
        .reduce(|| true, |a, b| a && b);
    if finished {
        image.sum = sum;
        image.spp += spp;
    }
    finished
}
