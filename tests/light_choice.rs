//! One light choice for every sampler, the shading context given once
//! (`LightChoice`): a global sampler at a point (`SamplerAt`) answers as
//! the sampler does at that point, and the `*_with` conveniences, which
//! draw their numbers from a renderer's `rand_core::Rng`, choose exactly
//! as the calls given the number they drew.

mod common;

use common::{Rand, mixed_scene, train_on_own_choices};
use glam::Vec3;
use guiding::rand_core::Rng;
use guiding::{
    Aabb, Emitter, Glt, GltConfig, ImportanceTreeSampler, LightChoice, LightId, LightSampler,
    LightTree, SamplerAt, SdTree, SdTreeConfig, ShadingContext, Strategy, UnboundedLights,
};
use rand_pcg::Pcg32;
use rand_pcg::rand_core::SeedableRng;

/// The number `sample_with` documents it draws: one `next_u32`, its top
/// 24 bits times `2^-24`.
fn documented_f32(rng: &mut Pcg32) -> f32 {
    (rng.next_u32() >> 8) as f32 / (1u32 << 24) as f32
}

/// The number `sample_exact_with` documents it draws: one `next_u64`, its
/// top 53 bits times `2^-53`.
fn documented_f64(rng: &mut Pcg32) -> f64 {
    (rng.next_u64() >> 11) as f64 / (1u64 << 53) as f64
}

/// Checks, for 2,000 numbers, that `choice`'s generator-driven calls
/// equal its number-driven calls on the number drawn, and that they drew
/// exactly one word (the generator after them is the one after the
/// documented draw). Returns how many draws chose a light.
fn drives_as_its_numbers(choice: &impl LightChoice, seed: u64) -> usize {
    let (mut rng, mut twin) = (Pcg32::seed_from_u64(seed), Pcg32::seed_from_u64(seed));
    let mut chosen = 0;
    for _ in 0..2000 {
        let got = choice.sample_with(&mut rng);
        assert_eq!(got, choice.sample(documented_f32(&mut twin)));
        chosen += usize::from(got.is_some());
        let got = choice.sample_exact_with(&mut rng);
        assert_eq!(got, choice.sample_exact(documented_f64(&mut twin)));
    }
    assert_eq!(rng.next_u64(), twin.next_u64(), "one word per draw");
    chosen
}

/// A trained GLT over a mixed scene of 300 lights and two unbounded ones.
fn trained() -> (Vec<Emitter>, Glt<LightTree>) {
    let lights = mixed_scene(300, 5);
    let tree = LightTree::build(&lights, Default::default()).unwrap();
    let mut config = GltConfig::default();
    config.cut.unbounded = UnboundedLights::new(2, 0.1).unwrap();
    let scene = Aabb::new(Vec3::splat(-60.0), Vec3::splat(60.0));
    let mut glt = Glt::new(tree, scene, config).unwrap();
    train_on_own_choices(&mut glt, &lights, 55.0, (3, 20_000), &mut Rand::new(6));
    (lights, glt)
}

/// Every strategy at a point answers each query as the strategy does at
/// that point, the surface's normal included. Control: a `SamplerAt` that
/// dropped the normal fails the context's equality and, without it, the
/// tree sampler's pmfs (and the `differs` count, since a `Strategy`
/// answers through `SamplerAt`: the normal matters at none of its points).
#[test]
fn a_sampler_at_a_point_answers_as_the_sampler_there() {
    let lights = mixed_scene(300, 5);
    let scene = Aabb::new(Vec3::splat(-60.0), Vec3::splat(60.0));
    let unbounded = UnboundedLights::new(1, 0.1).unwrap();
    let mut r = Rand::new(9);
    let tree = LightTree::build(&lights, Default::default()).unwrap();
    let mut samplers: Vec<(&str, Box<dyn LightSampler>)> = Strategy::NAMES
        .iter()
        .map(|&name| {
            let s = Strategy::new(name, &lights[..], unbounded, scene).unwrap();
            (name, Box::new(s) as Box<dyn LightSampler>)
        })
        .collect();
    // One not built on `SamplerAt` (a `Strategy` answers through it).
    samplers.push(("tree", Box::new(ImportanceTreeSampler::new(tree))));
    for (name, s) in samplers {
        let mut differs = 0;
        for _ in 0..300 {
            let ctx = ShadingContext::on_surface(r.point(55.0), r.dir());
            let here = s.at(&ctx);
            assert_eq!(here.context(), &ctx);
            let u = r.f();
            assert_eq!(here.sample(u), s.sample(&ctx, u), "{name}");
            assert_eq!(
                here.sample_exact(f64::from(u)),
                s.sample_exact(&ctx, f64::from(u))
            );
            assert_eq!(
                here.sample_with_visibility(u),
                s.sample_with_visibility(&ctx, u)
            );
            assert_eq!(here.is_empty(), s.is_empty_at(&ctx));
            for light in [LightId::Emitter(r.below(300)), LightId::Unbounded(0)] {
                assert_eq!(here.pmf(light).to_bits(), s.pmf(&ctx, light).to_bits());
                assert_eq!(here.pmf_exact(light), s.pmf_exact(&ctx, light));
                assert_eq!(here.visibility(light), s.visibility(&ctx, light));
            }
            let (light, blind) = (
                LightId::Emitter(r.below(300)),
                ShadingContext::at(ctx.position),
            );
            differs += usize::from(s.pmf(&blind, light) != s.pmf(&ctx, light));
        }
        if matches!(name, "importance" | "glt" | "tree") {
            assert!(
                differs > 150,
                "{name}: the normal matters at {differs} of 300"
            );
        }
    }
}

/// `sample_with` and `sample_exact_with` choose as `sample` and
/// `sample_exact` of the number they document, for a GLT's vertex, a
/// global sampler at a point (also through `&dyn`, and its own
/// `sample_with`), a GPU snapshot's
/// vertex, and the direction sampler of an SD-tree's vertex. Control: a
/// mapping that divided by `u32::MAX`, or drew two words, fails the
/// equality or the word count.
#[test]
fn generators_drive_every_choice_as_its_numbers() {
    let (lights, glt) = trained();
    let scene = Aabb::new(Vec3::splat(-60.0), Vec3::splat(60.0));
    let global = Strategy::new("importance", &lights[..], UnboundedLights::NONE, scene).unwrap();
    let snapshot = glt.snapshot().unwrap();
    let view = snapshot.view();
    let mut r = Rand::new(11);
    let mut chosen = 0;
    for k in 0..20 {
        let ctx = ShadingContext::on_surface(r.point(55.0), r.dir());
        chosen += drives_as_its_numbers(&glt.vertex(&ctx).unwrap(), k);
        chosen += drives_as_its_numbers(&view.vertex(&ctx).unwrap(), k);
        chosen += drives_as_its_numbers(&global.at(&ctx), k);
        let dynamic: &dyn LightSampler = &global;
        chosen += drives_as_its_numbers(&SamplerAt::new(dynamic, &ctx), k);
        // The global call draws the same number as the point's.
        let (mut a, mut b) = (Pcg32::seed_from_u64(k), Pcg32::seed_from_u64(k));
        assert_eq!(
            global.sample_with(&ctx, &mut a),
            global.at(&ctx).sample_with(&mut b)
        );
    }
    assert_eq!(chosen, 20 * 4 * 2000, "every draw chose a light");

    let tree = SdTree::new(Aabb::new(Vec3::ZERO, Vec3::ONE), SdTreeConfig::default()).unwrap();
    let v = tree.vertex(&ShadingContext::at(Vec3::splat(0.5))).unwrap();
    let (mut rng, mut twin) = (Pcg32::seed_from_u64(3), Pcg32::seed_from_u64(3));
    for _ in 0..500 {
        let u = [documented_f32(&mut twin), documented_f32(&mut twin)];
        assert_eq!(v.sample_direction_with(&mut rng), v.sample_direction(u));
    }
    assert_eq!(rng.next_u32(), twin.next_u32(), "two words per direction");
}
