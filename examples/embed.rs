//! The shortest honest way to wire `guiding` into a renderer: build the
//! light tree from the scene's lights, choose lights for next-event
//! estimation (NEE) with the Guiding Light Tree, weigh NEE against BSDF
//! sampling by multiple importance sampling (MIS) with `sample` + `pmf`,
//! record what each sample found, and refine between iterations.
//!
//! The "renderer" here is tiny and exact: 32 sphere lights above a floor,
//! split by an infinite wall at x = 0, so each half of the floor sees only
//! its own side's lights. It estimates the irradiance at points of the floor,
//! compares with the closed form, and prints how the learned light choice
//! stops wasting samples on lights behind the wall.
//!
//! ```text
//! cargo run --release --example embed
//! ```

use guiding::glam::Vec3;
use guiding::{
    Aabb, BuildHeuristic, Convention, Emitter, Glt, GltConfig, LightChoice, LightId, LightSampler,
    LightTree, LightVertex, SamplerAt, ShadingContext, Strategy, UnboundedLights,
};
use rand_pcg::Pcg32;
use rand_pcg::rand_core::{Rng, SeedableRng};
use std::f32::consts::PI;
use std::process::ExitCode;

/// A spherical light of constant radiance.
struct Sphere {
    center: Vec3,
    radius: f32,
    radiance: f32,
}

/// The renderer's "ray caster": the infinite wall x = 0 blocks everything
/// that crosses it.
fn visible(p: Vec3, q: Vec3) -> bool {
    (p.x < 0.0) == (q.x < 0.0)
}

fn uniform(rng: &mut Pcg32) -> f32 {
    (rng.next_u32() >> 8) as f32 / 16_777_216.0
}

/// A direction in the cone that `s` subtends from `p`, with its solid-angle
/// pdf (uniform in the cone).
fn sample_sphere(s: &Sphere, p: Vec3, u: [f32; 2]) -> (Vec3, f32) {
    let d = s.center - p;
    let sin2 = s.radius * s.radius / d.length_squared();
    let one_minus_cos = sin2 / (1.0 + (1.0 - sin2).sqrt());
    let cos_t = 1.0 - u[0] * one_minus_cos;
    let sin_t = (1.0 - cos_t * cos_t).max(0.0).sqrt();
    let (a, b) = d.normalize().any_orthonormal_pair();
    let phi = 2.0 * PI * u[1];
    let dir =
        (a * (sin_t * phi.cos()) + b * (sin_t * phi.sin()) + d.normalize() * cos_t).normalize();
    (dir, 1.0 / (2.0 * PI * one_minus_cos))
}

/// The first light a ray from `p` along `dir` hits.
fn hit_light(lights: &[Sphere], p: Vec3, dir: Vec3) -> Option<usize> {
    let mut best = (f32::INFINITY, None);
    for (i, s) in lights.iter().enumerate() {
        let f = p - s.center;
        let b = f.dot(dir);
        let disc = b * b - (f.length_squared() - s.radius * s.radius);
        let t = -b - disc.max(0.0).sqrt();
        if disc >= 0.0 && t > 0.0 && t < best.0 {
            best = (t, Some(i));
        }
    }
    best.1
}

/// How next-event estimation chooses lights.
#[derive(Clone, Copy)]
enum Nee<'a> {
    /// A sampler that learns nothing.
    Fixed(&'a dyn LightSampler),
    /// The GLT, located at each shading point; with `learn`, every light
    /// sample is recorded into it.
    Guided {
        glt: &'a Glt<&'a LightTree>,
        learn: bool,
    },
}

impl<'a> Nee<'a> {
    /// Runs `f` with the light choice at `ctx`: the GLT's vertex there
    /// (one lookup; also what to record into when learning) or the fixed
    /// sampler at the point.
    fn at<R>(
        self,
        ctx: &ShadingContext,
        f: impl FnOnce(&dyn LightChoice, Option<&LightVertex<'a, &'a LightTree>>) -> R,
    ) -> R {
        match self {
            Nee::Fixed(s) => f(&SamplerAt::new(s, ctx), None),
            Nee::Guided { glt, learn } => {
                let v = glt.vertex(ctx).expect("the floor's points are finite");
                f(&v, learn.then_some(&v))
            }
        }
    }
}

/// One irradiance estimate at `p` (normal +y): one NEE sample and one
/// cosine-sampled direction, MIS-combined. With `Nee::Guided { learn:
/// true, .. }`, both are recorded into the GLT.
fn estimate(lights: &[Sphere], nee: Nee, p: Vec3, rng: &mut Pcg32) -> f32 {
    let ctx = ShadingContext::on_surface(p, Vec3::Y);
    nee.at(&ctx, |choice, record| {
        estimate_with(lights, choice, record, p, rng)
    })
}

/// [`estimate`] with the light choice at `p` made.
fn estimate_with(
    lights: &[Sphere],
    choice: &dyn LightChoice,
    record: Option<&LightVertex<&LightTree>>,
    p: Vec3,
    rng: &mut Pcg32,
) -> f32 {
    let n = Vec3::Y;
    let mut e = 0.0;
    // NEE: choose a light (its number drawn from the renderer's own
    // generator), then a direction towards it.
    if let Some(s) = (&choice).sample_with(rng) {
        let LightId::Emitter(i) = s.light else {
            unreachable!("no unbounded lights here")
        };
        let light = &lights[i as usize];
        let (dir, pdf_dir) = sample_sphere(light, p, [uniform(rng), uniform(rng)]);
        let cos = n.dot(dir);
        let d = Convention::PbrtV4.light_sample(s.pmf, pdf_dir, cos.max(0.0) / PI);
        // Occluded (or below the horizon): a valid sample of value 0.
        let le = if cos > 0.0 && visible(p, light.center) {
            light.radiance
        } else {
            0.0
        };
        e += le * cos * d.factor;
        if let Some(v) = &record {
            v.record_light(s.light, le * d.factor);
        }
    }
    // BSDF sampling (cosine-weighted for a diffuse floor).
    let (u1, u2) = (uniform(rng), uniform(rng));
    let (r, phi) = (u1.sqrt(), 2.0 * PI * u2);
    let dir = Vec3::new(r * phi.cos(), (1.0 - u1).sqrt(), r * phi.sin());
    let pdf_bsdf = dir.y / PI;
    if let Some(i) = hit_light(lights, p, dir) {
        let light = &lights[i];
        if visible(p, light.center) {
            let (_, pdf_dir) = sample_sphere(light, p, [0.0, 0.0]);
            let id = LightId::Emitter(i as u32);
            let d = Convention::PbrtV4.bsdf_sample(choice.pmf(id), pdf_dir, pdf_bsdf);
            e += light.radiance * dir.y * d.factor;
            if let Some(v) = &record {
                v.record_light(id, light.radiance * d.factor);
            }
        }
    }
    e
}

/// Closed-form irradiance at `p` from the lights it sees.
fn exact(lights: &[Sphere], p: Vec3) -> f32 {
    lights
        .iter()
        .filter(|s| visible(p, s.center))
        .map(|s| {
            let d = s.center - p;
            let d2 = d.length_squared();
            PI * s.radiance * s.radius * s.radius / d2 * d.y / d2.sqrt()
        })
        .sum()
}

/// Relative RMSE of `spp`-sample estimates over the points.
fn error(lights: &[Sphere], nee: Nee, points: &[Vec3], spp: u32, rng: &mut Pcg32) -> f32 {
    let mut sum = 0.0;
    for &p in points {
        let est: f32 = (0..spp).map(|_| estimate(lights, nee, p, rng)).sum::<f32>() / spp as f32;
        let e = exact(lights, p);
        sum += ((est - e) / e).powi(2);
    }
    (sum / points.len() as f32).sqrt()
}

/// Runs the demonstration, printing as it goes; true when every check holds.
pub fn run() -> bool {
    let mut rng = Pcg32::seed_from_u64(5);
    // 1. The scene's lights, described to the crate: power = 4 pi^2 r^2 Le
    //    for a sphere.
    let lights: Vec<Sphere> = (0..32)
        .map(|i| Sphere {
            center: Vec3::new(
                if i % 2 == 0 { -1.0 } else { 1.0 } * (1.0 + 3.0 * uniform(&mut rng)),
                1.0 + uniform(&mut rng),
                -2.0 + 4.0 * uniform(&mut rng),
            ),
            radius: 0.05,
            radiance: 50.0 + 100.0 * uniform(&mut rng),
        })
        .collect();
    let emitters: Vec<Emitter> = lights
        .iter()
        .map(|s| {
            Emitter::sphere(
                s.center,
                s.radius,
                4.0 * PI * PI * s.radius * s.radius * s.radiance,
            )
        })
        .collect();
    // 2. The global light tree, built once.
    let tree = LightTree::build(&emitters, BuildHeuristic::default()).expect("valid lights");
    // 3. The GLT over the region shading points live in.
    let bounds = Aabb::new(Vec3::new(-4.0, 0.0, -2.0), Vec3::new(4.0, 2.0, 2.0));
    let mut glt = Glt::new(&tree, bounds, GltConfig::default()).expect("finite bounds");
    let points: Vec<Vec3> = (0..64)
        .map(|i| {
            let x = 0.5 + 3.5 * ((i / 2) % 8) as f32 / 7.0;
            Vec3::new(
                if i % 2 == 0 { -x } else { x },
                0.0,
                -1.5 + 3.0 * (i / 16) as f32 / 3.0,
            )
        })
        .collect();
    let left = ShadingContext::on_surface(Vec3::new(-2.0, 0.0, 0.0), Vec3::Y);
    let hidden = |nee: Nee| -> f32 {
        nee.at(&left, |s, _| {
            (1..32).step_by(2).map(|i| s.pmf(LightId::Emitter(i))).sum()
        })
    };
    let uniform_sampler =
        Strategy::new("uniform", &emitters[..], UnboundedLights::NONE, bounds).expect("lights");
    let by_uniform = Nee::Fixed(&uniform_sampler);
    println!("32 sphere lights, a wall at x = 0; 64 floor points; 16 samples per estimate");
    println!(
        "uniform NEE: relative RMSE {:.4}",
        error(&lights, by_uniform, &points, 16, &mut rng)
    );
    // 4. Iterations: sample + record with `&self` (any number of threads
    //    could), then refine with `&mut self`.
    for iteration in 0..6 {
        let passes = 1u32 << iteration;
        for _ in 0..passes {
            for &p in &points {
                for _ in 0..8 {
                    let learning = Nee::Guided {
                        glt: &glt,
                        learn: true,
                    };
                    estimate(&lights, learning, p, &mut rng);
                }
            }
        }
        glt.refine();
        let guided = Nee::Guided {
            glt: &glt,
            learn: false,
        };
        println!(
            "after iteration {iteration}: GLT NEE relative RMSE {:.4}, probability of choosing a light behind the wall from x = -2: {:.3}",
            error(&lights, guided, &points, 16, &mut rng),
            hidden(guided)
        );
    }
    let guided = Nee::Guided {
        glt: &glt,
        learn: false,
    };
    // 5. Checkable: the estimates are unbiased, the hidden lights lost their
    //    probability (down to the defensive mixture), and the error fell.
    let mean_ratio: f32 = points
        .iter()
        .map(|&p| {
            (0..256)
                .map(|_| estimate(&lights, guided, p, &mut rng))
                .sum::<f32>()
                / 256.0
                / exact(&lights, p)
        })
        .sum::<f32>()
        / points.len() as f32;
    let (e_glt, e_uni) = (
        error(&lights, guided, &points, 16, &mut rng),
        error(&lights, by_uniform, &points, 16, &mut rng),
    );
    println!(
        "mean estimate / exact = {mean_ratio:.4}; hidden-light probability {:.3} (uniform: {:.3}); relative RMSE GLT {e_glt:.4} vs uniform {e_uni:.4}",
        hidden(guided),
        hidden(by_uniform)
    );
    let ok = (mean_ratio - 1.0).abs() < 0.02 && hidden(guided) < 0.25 && e_glt < e_uni;
    println!("{}", if ok { "OK" } else { "FAILED" });
    ok
}

fn main() -> ExitCode {
    if run() {
        ExitCode::SUCCESS
    } else {
        ExitCode::FAILURE
    }
}
