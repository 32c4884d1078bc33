//! Light linking: a shading point lit by some light sets
//! (`ShadingContext::lit_by`) is lit only by the emitters of those sets
//! (`Emitters::light_sets`). Every sampler then chooses only among them,
//! its pmf exactly normalised over them and bit-equal to what sampling
//! reports; a point that receives every set sees what it saw without sets.

use glam::Vec3;
use guiding::LightChoice;
use guiding::glt::{Glt, GltConfig};
use guiding::light_sampler::{ImportanceTreeSampler, PowerTreeSampler};
use guiding::light_tree::BuildHeuristic;
use guiding::math::Aabb;
use guiding::{Emitter, LightId, LightSampler, LightTree, ShadingContext};

mod common;
use common::{LightsAt, Rand, emitter_draws, mixed_scene};

/// 300 mixed lights: a quarter in set 0, a quarter in set 1, a quarter in
/// both, a quarter in every set.
fn linked_scene() -> Vec<Emitter> {
    mixed_scene(300, 111)
        .into_iter()
        .enumerate()
        .map(|(i, e)| e.in_light_sets([0b01, 0b10, 0b11, u64::MAX][i % 4]))
        .collect()
}

fn bounds() -> Aabb {
    Aabb::new(Vec3::splat(-60.0), Vec3::splat(60.0))
}

fn trained_glt<'a>(tree: &'a LightTree, lights: &[Emitter]) -> Glt<&'a LightTree> {
    let mut glt = Glt::new(
        tree,
        bounds(),
        GltConfig {
            spatial_threshold: 1000.0,
            ..GltConfig::default()
        },
    )
    .unwrap();
    let mut r = Rand::new(112);
    let n = lights.len() as u32;
    for _ in 0..3 {
        for _ in 0..6000 {
            let p = r.point(50.0);
            let e = r.below(n);
            let c = lights[e as usize].bounds.center();
            let v = lights[e as usize].power / (c - p).length_squared().max(1.0);
            glt.record_light_at(p, LightId::Emitter(e), v * n as f32);
        }
        glt.refine();
    }
    glt
}

/// The contract at `ctx` for `s` over `lights`: normalised over the lights
/// the point receives (or nothing at all when it receives none), nothing
/// else ever chosen, samples report their pmf exactly.
fn check(name: &str, s: &dyn LightChoice, lights: &[Emitter], ctx: &ShadingContext, r: &mut Rand) {
    let receives = |e: &Emitter| e.light_sets & ctx.receives != 0 && e.power > 0.0;
    let any = lights.iter().any(receives);
    let mut total = 0.0;
    for (i, e) in lights.iter().enumerate() {
        let p = s.pmf_exact(LightId::Emitter(i as u32));
        if !receives(e) {
            assert_eq!(
                p, 0.0,
                "{name}: light {i} is not lit by sets {:b}",
                ctx.receives
            );
        }
        total += p;
    }
    if any {
        assert!((total - 1.0).abs() < 1e-6, "{name}: total {total}");
    } else {
        assert_eq!(total, 0.0, "{name}");
        assert!(s.sample(0.5).is_none(), "{name}");
        return;
    }
    for _ in 0..50 {
        let x = s.sample(r.f()).unwrap();
        let LightId::Emitter(e) = x.light else {
            panic!()
        };
        assert!(receives(&lights[e as usize]), "{name}: sampled light {e}");
        assert_eq!(x.pmf.to_bits(), s.pmf(x.light).to_bits(), "{name}");
    }
}

#[test]
fn every_tree_sampler_and_the_glt_choose_only_what_the_point_receives() {
    let lights = linked_scene();
    let tree = LightTree::build(lights.as_slice(), BuildHeuristic::Sarh).unwrap();
    assert!(guiding::LightHierarchy::has_light_sets(&tree));
    let glt = trained_glt(&tree, &lights);
    let fresh = Glt::new(&tree, bounds(), GltConfig::default()).unwrap();
    let importance = ImportanceTreeSampler::new(&tree);
    let power = PowerTreeSampler::new(&tree);
    let mut r = Rand::new(113);
    for _ in 0..25 {
        let p = r.point(50.0);
        for mask in [0b01u64, 0b10, 0b100, 0b11, 0, u64::MAX] {
            for ctx in [
                ShadingContext::at(p).lit_by(mask),
                ShadingContext::on_surface(p, r.dir()).lit_by(mask),
            ] {
                check("importance", &importance.at(&ctx), &lights, &ctx, &mut r);
                check("power tree", &power.at(&ctx), &lights, &ctx, &mut r);
                let v = glt.vertex(&ctx).unwrap();
                check("trained GLT", &v, &lights, &ctx, &mut r);
                let v = fresh.vertex(&ctx).unwrap();
                check("untrained GLT", &v, &lights, &ctx, &mut r);
            }
        }
    }
}

/// The strategies by name honour the sets too: the uniform and power
/// samplers (exactly, in O(n) per query at a point lit by some sets only),
/// the light BVH and the GLT.
#[test]
fn every_strategy_chooses_only_what_the_point_receives() {
    use guiding::{Strategy, UnboundedLights};
    let lights = linked_scene();
    let mut r = Rand::new(116);
    for name in Strategy::NAMES {
        let s = Strategy::new(name, lights.as_slice(), UnboundedLights::NONE, bounds()).unwrap();
        for _ in 0..10 {
            let p = r.point(50.0);
            for mask in [0b01u64, 0b10, 0b100, 0, u64::MAX] {
                let ctx = ShadingContext::at(p).lit_by(mask);
                check(name, &s.at(&ctx), &lights, &ctx, &mut r);
            }
        }
    }
}

/// The trained GLT's draws at a point lit by set 1 follow its pmf
/// (chi-square), and the restriction is what excludes the other lights
/// (the control: lit by every set, lights of set 0 only are chosen).
#[test]
fn the_restricted_glt_draws_what_its_pmf_says() {
    let lights = linked_scene();
    let tree = LightTree::build(lights.as_slice(), BuildHeuristic::Sarh).unwrap();
    let glt = trained_glt(&tree, &lights);
    let p = Vec3::new(5.0, -3.0, 12.0);
    let v = glt.vertex(&ShadingContext::at(p).lit_by(0b10)).unwrap();
    let (_, z) = emitter_draws(&v, lights.len(), 200_000, &mut Rand::new(114));
    assert!(z < 4.0, "chi-square z {z}");
    let all = glt.light_at(p);
    let only_set_0 = (0..lights.len()).filter(|i| i % 4 == 0);
    let outside: f64 = only_set_0
        .map(|i| all.pmf_exact(LightId::Emitter(i as u32)))
        .sum();
    assert!(outside > 0.05, "the control: {outside}");
    // Candidates drawn together follow the same restricted walk.
    let mut r = Rand::new(115);
    let mut answered = 0;
    for sets in [0b01, 0b10, 0b100, u64::MAX] {
        let ctx = ShadingContext::on_surface(r.point(50.0), r.dir()).lit_by(sets);
        answered += common::candidates_match(&glt.vertex(&ctx).unwrap(), &mut r);
    }
    assert!(answered > 300, "{answered} candidates answered");
}

/// Without restriction a tree with light sets samples bit for bit as the
/// same tree without them.
#[test]
fn receiving_every_set_is_having_no_sets() {
    let lights = linked_scene();
    let plain: Vec<Emitter> = lights.iter().map(|e| e.in_light_sets(u64::MAX)).collect();
    let a = LightTree::build(lights.as_slice(), BuildHeuristic::Sarh).unwrap();
    let b = LightTree::build(plain.as_slice(), BuildHeuristic::Sarh).unwrap();
    let (ga, gb) = (trained_glt(&a, &lights), trained_glt(&b, &plain));
    let mut r = Rand::new(115);
    for _ in 0..50 {
        let p = r.point(50.0);
        let ctx = ShadingContext::at(p);
        let (va, vb) = (ga.light_at(p), gb.light_at(p));
        let (ia, ib) = (
            ImportanceTreeSampler::new(&a),
            ImportanceTreeSampler::new(&b),
        );
        for e in 0..lights.len() as u32 {
            let id = LightId::Emitter(e);
            assert_eq!(va.pmf(id).to_bits(), vb.pmf(id).to_bits());
            assert_eq!(ia.pmf(&ctx, id).to_bits(), ib.pmf(&ctx, id).to_bits());
        }
    }
}

/// The contract over emitters and `k` unbounded lights at `ctx`: the pmf
/// sums to 1 over the lights the point is lit by (emitters of the sets it
/// receives, unbounded lights of its unbounded mask) and is 0 elsewhere;
/// where it is lit by none, nothing is chosen and `is_empty_at` says so.
fn check_with_unbounded(
    name: &str,
    s: &dyn LightSampler,
    lights: &[Emitter],
    k: u32,
    ctx: &ShadingContext,
    r: &mut Rand,
) {
    let emitter_lit = |e: &Emitter| e.light_sets & ctx.receives != 0 && e.power > 0.0;
    let unbounded_lit = |i: u32| i >= 64 || ctx.receives_unbounded & (1 << i) != 0;
    let mut total = 0.0;
    for (i, e) in lights.iter().enumerate() {
        let p = s.pmf_exact(ctx, LightId::Emitter(i as u32));
        assert!(emitter_lit(e) || p == 0.0, "{name}: emitter {i} at {ctx:?}");
        total += p;
    }
    for i in 0..k {
        let p = s.pmf_exact(ctx, LightId::Unbounded(i));
        assert!(
            unbounded_lit(i) || p == 0.0,
            "{name}: unbounded {i} at {ctx:?}"
        );
        total += p;
    }
    let any = lights.iter().any(emitter_lit) || (0..k).any(unbounded_lit);
    assert_eq!(s.is_empty_at(ctx), !any, "{name} at {ctx:?}");
    if !any {
        assert_eq!(total, 0.0, "{name}");
        assert!(s.sample(ctx, r.f()).is_none(), "{name}");
        return;
    }
    assert!(
        (total - 1.0).abs() < 1e-6,
        "{name}: total {total} at {ctx:?}"
    );
    for _ in 0..50 {
        let x = s.sample(ctx, r.f()).unwrap();
        match x.light {
            LightId::Emitter(e) => assert!(emitter_lit(&lights[e as usize]), "{name}"),
            LightId::Unbounded(i) => assert!(unbounded_lit(i), "{name}: drew unbounded {i}"),
        }
        assert_eq!(x.pmf.to_bits(), s.pmf(ctx, x.light).to_bits(), "{name}");
    }
}

/// A sun and a sky linked like emitters: every strategy (the fixed-share
/// wrapper around the uniform, power and BVH samplers, and the GLT with its
/// learned shares, trained and fresh) gives the share of the lights a
/// point is not lit by to those it is, exactly. The cases that matter: a
/// point lit by no emitter (the unbounded lights take everything), by no
/// unbounded light (the emitters do), by nothing at all.
#[test]
fn unbounded_lights_are_linked_and_the_shares_renormalised() {
    use guiding::{Strategy, UnboundedLights};
    let lights = linked_scene();
    let sun_and_sky = UnboundedLights::new(2, 0.3).unwrap();
    let mut r = Rand::new(117);
    let mut strategies: Vec<Strategy> = Strategy::NAMES
        .iter()
        .map(|name| Strategy::new(name, lights.as_slice(), sun_and_sky, bounds()).unwrap())
        .collect();
    // Train the GLT a little, sun and sky included.
    let n = lights.len() as u32;
    for _ in 0..2 {
        let glt = strategies[3].glt_mut().unwrap();
        for _ in 0..4000 {
            let p = r.point(50.0);
            let light = match r.below(n + 2) {
                e if e < n => LightId::Emitter(e),
                i => LightId::Unbounded(i - n),
            };
            glt.record_light_at(p, light, 1.0);
        }
        glt.refine();
    }
    let fresh = Strategy::new("glt", lights.as_slice(), sun_and_sky, bounds()).unwrap();
    strategies.push(fresh);
    for s in &strategies {
        for _ in 0..6 {
            let p = r.point(50.0);
            for sets in [0b01u64, 0b100, 0, u64::MAX] {
                for unbounded in [0b01u64, 0b10, 0, u64::MAX] {
                    let ctx = ShadingContext::at(p)
                        .lit_by(sets)
                        .lit_by_unbounded(unbounded);
                    check_with_unbounded(s.name(), s, &lights, 2, &ctx, &mut r);
                }
            }
        }
    }
}

/// A point lit by no light set in a scene without light sets (every
/// emitter is then in every set) is lit by no emitter, in every strategy;
/// its unbounded lights still light it.
#[test]
fn a_point_lit_by_no_set_is_lit_by_no_emitter() {
    use guiding::{Strategy, UnboundedLights};
    let lights = mixed_scene(100, 118);
    let mut r = Rand::new(119);
    for name in Strategy::NAMES {
        for (unbounded, k) in [
            (UnboundedLights::NONE, 0),
            (UnboundedLights::new(1, 0.2).unwrap(), 1),
        ] {
            let s = Strategy::new(name, lights.as_slice(), unbounded, bounds()).unwrap();
            for _ in 0..5 {
                let ctx = ShadingContext::at(r.point(50.0)).lit_by(0);
                check_with_unbounded(name, &s, &lights, k, &ctx, &mut r);
            }
        }
    }
}

/// A renderer's own emitter list that says nothing of light sets puts
/// every emitter in every set: its tree keeps no sets, and a point lit by
/// any set is lit by every emitter, as a point lit by all.
#[test]
fn emitters_that_name_no_set_are_in_every_set() {
    struct Plain(Vec<Emitter>);
    impl guiding::Emitters for Plain {
        fn len(&self) -> usize {
            self.0.len()
        }
        fn bounds(&self, i: usize) -> Aabb {
            self.0[i].bounds
        }
        fn power(&self, i: usize) -> f32 {
            self.0[i].power
        }
        fn area(&self, i: usize) -> f32 {
            self.0[i].area
        }
        fn cone(&self, i: usize) -> Option<guiding::math::LightCone> {
            self.0[i].cone
        }
    }
    let plain = Plain(mixed_scene(200, 120));
    let tree = LightTree::build(&plain, BuildHeuristic::Sarh).unwrap();
    assert!(!guiding::LightHierarchy::has_light_sets(&tree));
    let s = ImportanceTreeSampler::new(&tree);
    let mut r = Rand::new(121);
    for _ in 0..10 {
        let p = r.point(50.0);
        let (all, one) = (ShadingContext::at(p), ShadingContext::at(p).lit_by(0b100));
        for e in 0..200 {
            let id = LightId::Emitter(e);
            assert_eq!(s.pmf(&one, id).to_bits(), s.pmf(&all, id).to_bits());
        }
        check("plain emitters", &s.at(&one), &plain.0, &one, &mut r);
    }
}
