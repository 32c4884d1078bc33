//! A strategy by name samples exactly as the sampler it names, owns its
//! tree, and reports unknown names and unbuildable emitters as errors.

mod common;
use common::{ByPosition, LightsAt};

use common::{Rand, scene, two_rooms, value};
use glam::Vec3;
use guiding::glt::{Glt, GltConfig};
use guiding::light_sampler::{ImportanceTreeSampler, PowerSampler, UniformSampler, WithUnbounded};
use guiding::light_tree::{BuildError, BuildHeuristic};
use guiding::{
    Emitter, Error, LightId, LightSampler, LightTree, ShadingContext, Strategy, UnboundedLights,
};

const NONE: UnboundedLights = UnboundedLights::NONE;

#[test]
fn each_name_is_its_sampler() {
    fn assert_send_sync<T: Send + Sync>() {}
    assert_send_sync::<Strategy>();
    let lights = two_rooms();
    let tree = LightTree::build(&lights, BuildHeuristic::default()).unwrap();
    let glt = Glt::new(&tree, scene(), GltConfig::default()).unwrap();
    let direct: [Box<dyn LightSampler + '_>; 4] = [
        Box::new(UniformSampler::new(lights.len())),
        Box::new(PowerSampler::new(&lights[..])),
        Box::new(ImportanceTreeSampler::new(&tree)),
        Box::new(ByPosition(&glt)),
    ];
    let mut rng = Rand::new(3);
    for (name, reference) in Strategy::NAMES.iter().zip(&direct) {
        let s = Strategy::new(name, &lights[..], NONE, scene()).unwrap();
        assert_eq!(s.name(), *name);
        assert_eq!(s.is_empty(), reference.is_empty());
        for _ in 0..200 {
            let ctx = ShadingContext::on_surface(rng.point(9.0), rng.dir());
            let u = rng.f();
            let x = s.sample(&ctx, u);
            assert_eq!(x, reference.sample(&ctx, u), "{name}");
            assert_eq!(
                s.sample_with_visibility(&ctx, u),
                reference.sample_with_visibility(&ctx, u),
                "{name}"
            );
            let x = x.unwrap();
            assert_eq!(s.pmf(&ctx, x.light), x.pmf, "{name}");
        }
    }
}

/// With a sun and a sky, every name samples as its sampler wrapped with
/// them (the GLT with them as its prior), and all keep the pmf summing to 1.
#[test]
fn each_name_takes_unbounded_lights() {
    let lights = two_rooms();
    let tree = LightTree::build(&lights, BuildHeuristic::default()).unwrap();
    let sun_and_sky = UnboundedLights::new(2, 0.3).unwrap();
    let with =
        |s| -> Box<dyn LightSampler> { Box::new(WithUnbounded::new(s, sun_and_sky).unwrap()) };
    let mut config = GltConfig::default();
    config.cut.unbounded = sun_and_sky;
    let glt = Glt::new(&tree, scene(), config).unwrap();
    let direct: [Box<dyn LightSampler + '_>; 4] = [
        Box::new(WithUnbounded::new(UniformSampler::new(lights.len()), sun_and_sky).unwrap()),
        Box::new(WithUnbounded::new(PowerSampler::new(&lights[..]), sun_and_sky).unwrap()),
        with(ImportanceTreeSampler::new(&tree)),
        Box::new(ByPosition(&glt)),
    ];
    let mut rng = Rand::new(4);
    for (name, reference) in Strategy::NAMES.iter().zip(&direct) {
        let s = Strategy::new(name, &lights[..], sun_and_sky, scene()).unwrap();
        for _ in 0..50 {
            let ctx = ShadingContext::on_surface(rng.point(9.0), rng.dir());
            let u = rng.f();
            assert_eq!(s.sample(&ctx, u), reference.sample(&ctx, u), "{name}");
            let ids = (0..lights.len() as u32).map(LightId::Emitter);
            let total: f64 = ids
                .chain([LightId::Unbounded(0), LightId::Unbounded(1)])
                .map(|l| s.pmf_exact(&ctx, l))
                .sum();
            assert!((total - 1.0).abs() < 1e-5, "{name}: {total}");
            assert!(s.pmf(&ctx, LightId::Unbounded(1)) > 0.0, "{name}");
        }
    }
    let bad = UnboundedLights {
        count: 2,
        probability: 1.0,
    };
    for name in Strategy::NAMES {
        assert!(matches!(
            Strategy::new(name, &lights[..], bad, scene()),
            Err(Error::Config(_))
        ));
    }
}

#[test]
fn the_glt_strategy_trains() {
    let lights = two_rooms();
    let mut s = Strategy::new("glt", &lights[..], NONE, scene()).unwrap();
    let ctx = ShadingContext::at(Vec3::new(-5.0, 0.0, 0.0));
    let right = |s: &Strategy| -> f32 { (40..80).map(|e| s.pmf(&ctx, LightId::Emitter(e))).sum() };
    let before = right(&s);
    assert!(
        Strategy::new("power", &lights[..], NONE, scene())
            .unwrap()
            .glt_mut()
            .is_none()
    );
    let mut rng = Rand::new(1);
    // Enough records per iteration for the default threshold (12000) to
    // split the scene at the wall.
    for _ in 0..4 {
        let glt = s.glt_mut().unwrap();
        for _ in 0..40000 {
            let p = rng.point(9.5);
            let x = ByPosition(&*glt)
                .sample(&ShadingContext::at(p), rng.f())
                .unwrap();
            let LightId::Emitter(e) = x.light else {
                panic!()
            };
            glt.record_light_at(p, x.light, value(&lights, e, p) / x.pmf);
        }
        glt.refine();
    }
    // Learned: from the left room, the right room's lights (behind the
    // wall) became rare.
    let after = right(&s);
    assert!(after < 0.5 * before, "{before} -> {after}");
}

#[test]
fn errors_are_typed() {
    let lights = two_rooms();
    assert_eq!(
        Strategy::new("bvh", &lights[..], NONE, scene()).unwrap_err(),
        Error::UnknownStrategy {
            known: &Strategy::NAMES
        }
    );
    let message = Strategy::new("bvh", &lights[..], NONE, scene())
        .unwrap_err()
        .to_string();
    for name in Strategy::NAMES {
        assert!(message.contains(name), "{message}");
    }
    let bad = [Emitter::point(Vec3::ZERO, f32::NAN)];
    for name in ["importance", "glt"] {
        assert!(matches!(
            Strategy::new(name, &bad[..], NONE, scene()),
            Err(Error::Build(BuildError::InvalidPower { emitter: 0, .. }))
        ));
    }
}
