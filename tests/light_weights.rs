//! Per-light weights (`Emitters::weight`): every sampler chooses by power
//! times weight where it chooses by power, and by weight where it ignores
//! power; pmfs stay exact, sum to 1, and a weight of 0 is never chosen.

use glam::Vec3;
use guiding::light_sampler::{PowerSampler, PowerTreeSampler, UniformSampler, importance};
use guiding::light_tree::{BuildError, BuildHeuristic};
use guiding::math::Aabb;
use guiding::{
    Emitter, LightHierarchy, LightId, LightSampler, LightTree, ShadingContext, Strategy,
    UnboundedLights,
};

mod common;
use common::{Rand, emitter_draws, mixed_scene};

/// 60 mixed lights with weights: every fifth 0, every seventh 3, one 0.25,
/// the rest 1.
fn weighted_scene() -> Vec<Emitter> {
    mixed_scene(60, 91)
        .into_iter()
        .enumerate()
        .map(|(i, e)| {
            let w = match i {
                _ if i % 5 == 0 => 0.0,
                _ if i % 7 == 0 => 3.0,
                11 => 0.25,
                _ => 1.0,
            };
            e.with_weight(w)
        })
        .collect()
}

fn scene_bounds() -> Aabb {
    Aabb::new(Vec3::splat(-60.0), Vec3::splat(60.0))
}

#[test]
fn the_power_and_uniform_samplers_choose_by_weight() {
    let lights = weighted_scene();
    let ctx = ShadingContext::at(Vec3::ZERO);
    let power = PowerSampler::new(lights.as_slice());
    let total: f64 = lights.iter().map(|e| (e.power * e.weight) as f64).sum();
    let weights: f64 = lights.iter().map(|e| e.weight as f64).sum();
    let uniform = UniformSampler::weighted(lights.as_slice());
    for (i, e) in lights.iter().enumerate() {
        let id = LightId::Emitter(i as u32);
        let want = (e.power * e.weight) as f64 / total;
        let got = power.pmf(&ctx, id) as f64;
        assert!(
            (got - want).abs() <= want * 1e-6,
            "power {i}: {got} vs {want}"
        );
        let want = e.weight as f64 / weights;
        let got = uniform.pmf(&ctx, id) as f64;
        assert!(
            (got - want).abs() <= want * 1e-6,
            "uniform {i}: {got} vs {want}"
        );
    }
    // The control: a sampler that ignores the weights is told apart.
    let unweighted = PowerSampler::from_powers(lights.iter().map(|e| e.power));
    assert_ne!(
        unweighted.pmf(&ctx, LightId::Emitter(7)),
        power.pmf(&ctx, LightId::Emitter(7))
    );
    // All weights 1: exactly the plain uniform sampler.
    let plain = mixed_scene(60, 91);
    assert_eq!(
        UniformSampler::weighted(plain.as_slice()),
        UniformSampler::new(60)
    );
}

#[test]
fn the_weighted_uniform_sampler_draws_what_its_pmf_says() {
    let lights = weighted_scene();
    let s = UniformSampler::weighted(lights.as_slice());
    let ctx = ShadingContext::at(Vec3::ZERO);
    let (counts, z) = emitter_draws(&s.at(&ctx), lights.len(), 200_000, &mut Rand::new(92));
    assert!(z < 4.0, "chi-square z {z}");
    for (i, e) in lights.iter().enumerate() {
        if e.weight == 0.0 {
            assert_eq!(counts[i], 0, "light {i} has weight 0");
        }
    }
}

#[test]
fn the_tree_chooses_by_power_times_weight() {
    let lights = weighted_scene();
    // The tree over weighted lights is the tree over lights whose power is
    // power x weight, bit for bit.
    let baked: Vec<Emitter> = lights
        .iter()
        .map(|e| Emitter {
            power: e.power * e.weight,
            weight: 1.0,
            ..*e
        })
        .collect();
    for h in [BuildHeuristic::Sarh, BuildHeuristic::Saoh] {
        let a = LightTree::build(lights.as_slice(), h).unwrap();
        let b = LightTree::build(baked.as_slice(), h).unwrap();
        assert_eq!(a.to_bytes(), b.to_bytes(), "{h:?}");
    }
    // Doubling every weight changes no choice: pmfs are bit-identical.
    let doubled: Vec<Emitter> = lights
        .iter()
        .map(|e| e.with_weight(e.weight * 2.0))
        .collect();
    let a = LightTree::build(lights.as_slice(), BuildHeuristic::Sarh).unwrap();
    let b = LightTree::build(doubled.as_slice(), BuildHeuristic::Sarh).unwrap();
    let (sa, sb) = (PowerTreeSampler::new(&a), PowerTreeSampler::new(&b));
    let ctx = ShadingContext::at(Vec3::new(3.0, -2.0, 1.0));
    for e in 0..lights.len() as u32 {
        let id = LightId::Emitter(e);
        assert_eq!(sa.pmf(&ctx, id).to_bits(), sb.pmf(&ctx, id).to_bits());
    }
}

/// Whether `e` can light the point `ctx`: its own bound there (a tree of
/// it alone) is not 0.
fn lights_point(e: &Emitter, ctx: &ShadingContext) -> bool {
    let tree = LightTree::build(core::slice::from_ref(e), BuildHeuristic::Sarh).unwrap();
    tree.root()
        .is_some_and(|r| importance(ctx, &tree.node_bounds(r)) > 0.0)
}

#[test]
fn every_strategy_honours_the_weights() {
    let lights = weighted_scene();
    let sky = UnboundedLights::new(1, 0.1).unwrap();
    let mut r = Rand::new(93);
    let plain: Vec<Emitter> = lights.iter().map(|e| e.with_weight(1.0)).collect();
    for name in Strategy::NAMES {
        let s = Strategy::new(name, lights.as_slice(), sky, scene_bounds()).unwrap();
        let p = Strategy::new(name, plain.as_slice(), sky, scene_bounds()).unwrap();
        let (mut heavier, mut reachable) = (0, 0);
        for _ in 0..30 {
            let ctx = ShadingContext::at(r.point(50.0));
            let total: f64 = (0..lights.len() as u32)
                .map(LightId::Emitter)
                .chain([LightId::Unbounded(0)])
                .map(|l| s.pmf_exact(&ctx, l))
                .sum();
            assert!((total - 1.0).abs() < 1e-6, "{name}: {total}");
            for _ in 0..20 {
                let x = s.sample(&ctx, r.f()).unwrap();
                assert_eq!(x.pmf.to_bits(), s.pmf(&ctx, x.light).to_bits(), "{name}");
            }
            for (i, e) in lights.iter().enumerate() {
                let id = LightId::Emitter(i as u32);
                if e.weight == 0.0 {
                    assert_eq!(s.pmf(&ctx, id), 0.0, "{name}: light {i}");
                }
            }
            // The lights of weight 3 are chosen more often than without
            // it (where they can light the point at all, by their own
            // bound: a tighter cluster bound may rule out, in one tree,
            // a light that the other's looser one lets through): nearly
            // always, not always, as the weights also change how the tree
            // clusters.
            for e in (0..lights.len()).filter(|&e| lights[e].weight == 3.0) {
                let id = LightId::Emitter(e as u32);
                if p.pmf(&ctx, id) > 0.0 && lights_point(&lights[e], &ctx) {
                    reachable += 1;
                    heavier += usize::from(s.pmf(&ctx, id) > p.pmf(&ctx, id));
                }
            }
        }
        assert!(
            reachable > 50 && heavier * 4 >= reachable * 3,
            "{name}: weight 3 made a light likelier in {heavier} of {reachable} cases"
        );
    }
}

#[test]
fn bad_weights_are_typed_errors() {
    let mut lights = weighted_scene();
    lights[4].weight = f32::NAN;
    let err = LightTree::build(lights.as_slice(), BuildHeuristic::Sarh).unwrap_err();
    assert!(
        matches!(err, BuildError::InvalidWeight { emitter: 4, .. }),
        "{err:?}"
    );
    assert!(err.to_string().contains("weight"));
    lights[4].weight = -2.0;
    assert!(matches!(
        LightTree::build(lights.as_slice(), BuildHeuristic::Sarh),
        Err(BuildError::InvalidWeight {
            emitter: 4,
            weight: -2.0
        })
    ));
    // Power times weight past f32: the total overflows.
    let big = [
        Emitter::point(Vec3::ZERO, 3e38).with_weight(2.0),
        Emitter::point(Vec3::ONE, 1.0),
    ];
    assert_eq!(
        LightTree::build(big.as_slice(), BuildHeuristic::Sarh).unwrap_err(),
        BuildError::PowerOverflow
    );
    // The power sampler takes a bad product as zero, as it takes bad powers.
    let ctx = ShadingContext::at(Vec3::ZERO);
    let s = PowerSampler::new(lights.as_slice());
    assert_eq!(s.pmf(&ctx, LightId::Emitter(4)), 0.0);
}
