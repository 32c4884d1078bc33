//! `sample` and `pmf` per call for each baseline light sampler, at 1e3 to
//! 1e6 emitters.
//!
//! `cargo bench --bench light_samplers` (a few minutes); filter with e.g.
//! `cargo bench --bench light_samplers -- 'light_samplers/1000/'`.

use criterion::{
    BenchmarkGroup, Criterion, criterion_group, criterion_main, measurement::WallTime,
};
use glam::Vec3;
use guiding::light_sampler::{
    ImportanceTreeSampler, PowerSampler, PowerTreeSampler, UnboundedLights, UniformSampler,
    WithUnbounded,
};
use guiding::light_tree::BuildHeuristic;
use guiding::math::{Aabb, LightCone};
use guiding::{Emitter, LightId, LightSampler, LightTree, ShadingContext};
use rand_pcg::Pcg64;
use rand_pcg::rand_core::{Rng, SeedableRng};
use std::hint::black_box;
use std::time::Duration;

/// Queries cycled through by every benchmark (a power of two).
const QUERIES: usize = 1024;

fn unit(rng: &mut Pcg64) -> f32 {
    (rng.next_u32() >> 8) as f32 * (1.0 / (1u32 << 24) as f32)
}

fn point(rng: &mut Pcg64, half: f32) -> Vec3 {
    Vec3::new(unit(rng), unit(rng), unit(rng)) * (2.0 * half) - Vec3::splat(half)
}

fn direction(rng: &mut Pcg64) -> Vec3 {
    point(rng, 1.0).try_normalize().unwrap_or(Vec3::Z)
}

/// A scene of points, one-sided quads and spots in a 200-unit cube, powers
/// log-uniform over six decades.
fn emitters(n: usize, rng: &mut Pcg64) -> Vec<Emitter> {
    (0..n)
        .map(|i| {
            let p = point(rng, 100.0);
            let power = 10f32.powf(6.0 * unit(rng) - 3.0);
            let axis = direction(rng);
            match i % 3 {
                0 => Emitter::point(p, power),
                1 => Emitter::area(
                    Aabb::new(p, p + Vec3::new(0.5, 0.5, 0.0)),
                    axis,
                    0.25,
                    power,
                ),
                _ => Emitter {
                    cone: Some(LightCone::spot(axis, 0.6)),
                    ..Emitter::point(p, power)
                },
            }
        })
        .collect()
}

/// Shading points inside the scene with normals, a `u` each and an emitter
/// id for `pmf` (as MIS asks for a light hit by BSDF sampling).
struct Query {
    ctx: ShadingContext,
    u: f32,
    light: LightId,
}

fn queries(n: usize, rng: &mut Pcg64) -> Vec<Query> {
    (0..QUERIES)
        .map(|_| Query {
            ctx: ShadingContext::on_surface(point(rng, 110.0), direction(rng)),
            u: unit(rng),
            light: LightId::Emitter(rng.next_u32() % n as u32),
        })
        .collect()
}

fn bench_sampler<S: LightSampler>(
    group: &mut BenchmarkGroup<'_, WallTime>,
    name: &str,
    s: &S,
    queries: &[Query],
) {
    group.bench_function(format!("{name}/sample"), |b| {
        let mut i = 0;
        b.iter(|| {
            let q = &queries[i & (QUERIES - 1)];
            i += 1;
            black_box(s.sample(black_box(&q.ctx), black_box(q.u)))
        })
    });
    group.bench_function(format!("{name}/pmf"), |b| {
        let mut i = 0;
        b.iter(|| {
            let q = &queries[i & (QUERIES - 1)];
            i += 1;
            black_box(s.pmf(black_box(&q.ctx), black_box(q.light)))
        })
    });
}

fn light_samplers(c: &mut Criterion) {
    for n in [1_000, 10_000, 100_000, 1_000_000] {
        let mut rng = Pcg64::seed_from_u64(n as u64);
        let emitters = emitters(n, &mut rng);
        let queries = queries(n, &mut rng);
        let tree = LightTree::build(&emitters, BuildHeuristic::Sarh).expect("valid emitters");
        let mut group = c.benchmark_group(format!("light_samplers/{n}"));
        group
            .sample_size(10)
            .warm_up_time(Duration::from_millis(200))
            .measurement_time(Duration::from_millis(800));
        bench_sampler(&mut group, "uniform", &UniformSampler::new(n), &queries);
        bench_sampler(&mut group, "power", &PowerSampler::new(&emitters), &queries);
        bench_sampler(
            &mut group,
            "power_tree",
            &PowerTreeSampler::new(&tree),
            &queries,
        );
        bench_sampler(
            &mut group,
            "importance_tree",
            &ImportanceTreeSampler::new(&tree),
            &queries,
        );
        bench_sampler(
            &mut group,
            "unbounded+importance_tree",
            &WithUnbounded::new(
                ImportanceTreeSampler::new(&tree),
                UnboundedLights::new(2, 0.1).unwrap(),
            )
            .unwrap(),
            &queries,
        );
        group.finish();
    }
}

criterion_group!(benches, light_samplers);
criterion_main!(benches);
