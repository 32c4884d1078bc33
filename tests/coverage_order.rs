//! Learning never makes the light choice worse than the prior where the
//! renderer has not been yet: a tile-order renderer refines after part of
//! the image, and the cells over the part it has not rendered must not
//! sample with another region's learned choice.

mod common;

use common::{Rand, scene, two_rooms, value};
use glam::Vec3;
use guiding::glt::{Glt, GltConfig};
use guiding::light_tree::BuildHeuristic;
use guiding::spatial::SpatialTree;
use guiding::{Emitter, LightHierarchy, LightId, LightSampler, LightTree, ShadingContext};

/// The variance of the one-sample estimate `f(e) / pmf(e)` of the direct
/// light at `p`, exactly: `sum f^2 / pmf - (sum f)^2`.
fn variance<S: LightSampler>(sampler: &S, lights: &[Emitter], p: Vec3) -> f64 {
    let ctx = ShadingContext::at(p);
    let (mut second, mut first) = (0.0f64, 0.0f64);
    for e in 0..lights.len() as u32 {
        let f = f64::from(value(lights, e, p));
        if f > 0.0 {
            let pmf = sampler.pmf_exact(&ctx, LightId::Emitter(e));
            assert!(pmf > 0.0, "light {e} unreachable at {p}");
            second += f * f / pmf;
            first += f;
        }
    }
    second - first * first
}

/// Trains `glt` from shading points in the half `x < 0` only (the left
/// room: the part of the image rendered so far), sampling from the GLT
/// as a renderer would, then refines.
fn train_left_half<H: LightHierarchy>(
    glt: &mut Glt<H>,
    lights: &[Emitter],
    rng: &mut Rand,
    n: usize,
) {
    for _ in 0..n {
        let q = rng.point(9.5);
        let p = Vec3::new(-q.x.abs().max(0.01), q.y, q.z);
        let Some(s) = glt.sample(&ShadingContext::at(p), rng.f()) else {
            continue;
        };
        let LightId::Emitter(e) = s.light else {
            continue;
        };
        glt.splat_at(p, s.light, value(lights, e, p) / s.pmf);
    }
    glt.refine();
}

#[test]
fn the_half_not_rendered_yet_keeps_the_prior_choice() {
    let lights = two_rooms();
    let tree = LightTree::build(&lights, BuildHeuristic::Sarh).unwrap();
    let config = GltConfig {
        spatial_threshold: 500.0,
        ..GltConfig::default()
    };
    let prior = Glt::new(&tree, scene(), config).unwrap();
    let mut glt = prior.clone();
    let mut rng = Rand::new(3);
    train_left_half(&mut glt, &lights, &mut rng, 20_000);
    assert!(glt.spatial().cell_count() > 8);
    // The left room learned: less variance than the prior there.
    let (mut better, mut n) = (0, 0);
    for k in 0..64 {
        let q = rng.point(9.0);
        let left = Vec3::new(-q.x.abs().max(0.5), q.y, q.z);
        let right = Vec3::new(q.x.abs().max(0.5), q.y, q.z);
        let (learned, untrained) = (
            variance(&glt, &lights, right),
            variance(&prior, &lights, right),
        );
        assert!(
            learned <= untrained * (1.0 + 1e-6),
            "at {right} (not rendered yet): variance {learned} against the prior's {untrained} (point {k})"
        );
        better += usize::from(variance(&glt, &lights, left) < variance(&prior, &lights, left));
        n += 1;
    }
    assert!(
        better * 4 > n * 3,
        "learned better at {better} of {n} left-room points"
    );
}
