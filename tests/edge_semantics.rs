//! The same edge semantics for every light sampler: a random number outside
//! `[0, 1)` is clamped into it and NaN counts as 0; a non-finite shading
//! position chooses nothing (`sample` is `None`, every `pmf` is 0); the
//! exact (`f64`) variants agree bit for bit.

mod common;
use common::{ByPosition, LightsAt};

use common::{Rand, scene, two_rooms, value};
use glam::Vec3;
use guiding::cut::{CutConfig, CutRules, GuidingCut};
use guiding::field::{FieldConfig, GuidingField};
use guiding::glt::{Glt, GltConfig};
use guiding::light_sampler::{
    ImportanceTreeSampler, PowerSampler, PowerTreeSampler, UniformSampler, WithUnbounded,
};
use guiding::light_tree::BuildHeuristic;
use guiding::{
    LightChoice, LightId, LightSample, LightSampler, LightTree, ShadingContext, UnboundedLights,
};

/// The largest `f32` below one.
const BELOW_ONE: f32 = 1.0 - f32::EPSILON / 2.0;

/// Checks the edge semantics of `s` (over `n` emitters) at finite points.
/// One cell's cut behind the sampler interface: every query through the
/// cut's vertex at the query's point (`CutRules::vertex`).
struct LoneCut<'a>(&'a CutRules<&'a LightTree>, &'a GuidingCut);

impl LightSampler for LoneCut<'_> {
    fn sample(&self, ctx: &ShadingContext, u: f32) -> Option<LightSample> {
        self.0.vertex(self.1, ctx).sample(u)
    }
    fn pmf(&self, ctx: &ShadingContext, light: LightId) -> f32 {
        self.0.vertex(self.1, ctx).pmf(light)
    }
    fn is_empty(&self) -> bool {
        self.0.is_empty()
    }
    fn is_empty_at(&self, ctx: &ShadingContext) -> bool {
        self.0.vertex(self.1, ctx).is_empty()
    }
    fn sample_exact(&self, ctx: &ShadingContext, u: f64) -> Option<(LightId, f64)> {
        self.0.vertex(self.1, ctx).sample_exact(u)
    }
    fn pmf_exact(&self, ctx: &ShadingContext, light: LightId) -> f64 {
        self.0.vertex(self.1, ctx).pmf_exact(light)
    }
}

fn check(name: &str, s: &dyn LightSampler, n: u32) {
    let mut rng = Rand::new(4);
    for _ in 0..50 {
        let p = rng.point(9.0);
        let ctx = ShadingContext::on_surface(p, rng.dir());
        for (u, as_u) in [
            (f32::NAN, 0.0),
            (-1.0, 0.0),
            (f32::NEG_INFINITY, 0.0),
            (-0.0, 0.0),
            (1.0, BELOW_ONE),
            (7.5, BELOW_ONE),
            (f32::INFINITY, BELOW_ONE),
        ] {
            assert_eq!(s.sample(&ctx, u), s.sample(&ctx, as_u), "{name}: u = {u}");
        }
        // Non-finite positions: nothing is chosen, nothing has probability.
        for bad in [
            Vec3::new(f32::NAN, 0.0, 0.0),
            Vec3::new(0.0, f32::INFINITY, 0.0),
            Vec3::splat(f32::NEG_INFINITY),
        ] {
            for ctx in [
                ShadingContext::at(bad),
                ShadingContext::on_surface(bad, Vec3::Y),
            ] {
                assert_eq!(s.sample(&ctx, 0.3), None, "{name}: {bad}");
                for e in 0..n {
                    assert_eq!(s.pmf(&ctx, LightId::Emitter(e)), 0.0, "{name}: {bad}");
                }
                assert_eq!(s.pmf(&ctx, LightId::Unbounded(0)), 0.0, "{name}: {bad}");
            }
        }
        // The exact variants: one place (the trait), the same contract.
        let u = rng.f64();
        if let Some((light, p)) = s.sample_exact(&ctx, u) {
            assert_eq!(p.to_bits(), s.pmf_exact(&ctx, light).to_bits(), "{name}");
            assert_eq!(s.pmf(&ctx, light), p as f32, "{name}");
        }
        // A non-finite normal counts as no normal.
        let no_normal = ShadingContext::at(p);
        let nan_normal = ShadingContext {
            position: p,
            normal: Some(Vec3::NAN),
            ..ShadingContext::at(Vec3::ZERO)
        };
        let u = rng.f();
        assert_eq!(s.sample(&nan_normal, u), s.sample(&no_normal, u), "{name}");
    }
}

#[test]
fn every_sampler_has_the_same_edges() {
    let lights = two_rooms();
    let n = lights.len() as u32;
    let tree = LightTree::build(&lights, BuildHeuristic::Sarh).unwrap();
    check("uniform", &UniformSampler::new(lights.len()), n);
    check("power", &PowerSampler::new(&lights), n);
    check("power tree", &PowerTreeSampler::new(&tree), n);
    check("importance tree", &ImportanceTreeSampler::new(&tree), n);
    check(
        "with environment",
        &WithUnbounded::new(
            PowerSampler::new(&lights),
            UnboundedLights::new(2, 0.25).unwrap(),
        )
        .unwrap(),
        n,
    );
    let mut glt = Glt::new(&tree, scene(), GltConfig::default()).unwrap();
    let mut rng = Rand::new(1);
    for _ in 0..3 {
        for _ in 0..3000 {
            let p = rng.point(9.5);
            let s = ByPosition(&glt)
                .sample(&ShadingContext::at(p), rng.f())
                .unwrap();
            if let LightId::Emitter(e) = s.light {
                glt.record_light_at(p, s.light, value(&lights, e, p) / s.pmf);
            }
        }
        glt.refine();
    }
    check("glt", &ByPosition(&glt), n);
    let guide = CutRules::new(&tree, CutConfig::default()).unwrap();
    let cut = guide.new_cut();
    check("cut sampler", &LoneCut(&guide, &cut), n);
    let field = GuidingField::new(&tree, scene(), FieldConfig::default()).unwrap();
    check("field", &ByPosition(&field), n);
}
