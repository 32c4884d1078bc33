//! Light tree build time per heuristic at 1e3..1e6 emitters, and the tree's
//! memory (bytes per node and per emitter).
//!
//! `cargo bench --bench light_tree` runs everything (about 6 minutes on a
//! quiet 2-core machine, most of it the 1e6 builds); pass a filter such as
//! `-- build/Sarh` to run less.

use criterion::{BenchmarkId, Criterion, SamplingMode, criterion_group, criterion_main};
use glam::Vec3;
use guiding::light_tree::BuildHeuristic;
use guiding::math::{Aabb, LightCone};
use guiding::{Emitter, LightHierarchy, LightTree};
use rand_pcg::Pcg64Mcg;
use rand_pcg::rand_core::{Rng, SeedableRng};
use std::hint::black_box;
use std::time::Duration;

const HEURISTICS: [BuildHeuristic; 4] = [
    BuildHeuristic::Balanced,
    BuildHeuristic::Sah,
    BuildHeuristic::Sarh,
    BuildHeuristic::Saoh,
];
const SIZES: [usize; 4] = [1_000, 10_000, 100_000, 1_000_000];

struct Rand(Pcg64Mcg);

impl Rand {
    fn f(&mut self) -> f32 {
        (self.0.next_u32() >> 8) as f32 / (1u32 << 24) as f32
    }
    fn range(&mut self, lo: f32, hi: f32) -> f32 {
        lo + (hi - lo) * self.f()
    }
    fn dir(&mut self) -> Vec3 {
        loop {
            let v = Vec3::new(
                self.range(-1.0, 1.0),
                self.range(-1.0, 1.0),
                self.range(-1.0, 1.0),
            );
            if let Some(d) = v.try_normalize() {
                return d;
            }
        }
    }
}

fn quad(c: Vec3, n: Vec3, s: f32, power: f32) -> Emitter {
    let (t, b) = n.any_orthonormal_pair();
    let mut bounds = Aabb::EMPTY;
    for (u, v) in [(-1.0, -1.0), (-1.0, 1.0), (1.0, -1.0), (1.0, 1.0)] {
        bounds = bounds.extend(c + (t * u + b * v) * s);
    }
    Emitter::area(bounds, n, 4.0 * s * s, power)
}

/// The scene of the tests and the stats example: 40% quads (half facing
/// down), 30% spheres, 20% point and 10% spot lights in a 100^3 box, powers
/// log-uniform over five decades.
fn mixed_scene(n: usize, seed: u64) -> Vec<Emitter> {
    let mut r = Rand(Pcg64Mcg::seed_from_u64(seed));
    (0..n)
        .map(|_| {
            let c = Vec3::new(
                r.range(-50.0, 50.0),
                r.range(-50.0, 50.0),
                r.range(-50.0, 50.0),
            );
            let power = 10f32.powf(r.range(-2.0, 3.0));
            let kind = r.f();
            if kind < 0.4 {
                let normal = if r.f() < 0.5 { -Vec3::Y } else { r.dir() };
                let mut e = quad(c, normal, r.range(0.05, 2.0), power);
                e.two_sided = r.f() < 0.1;
                e
            } else if kind < 0.7 {
                Emitter::sphere(c, r.range(0.05, 1.0), power)
            } else if kind < 0.9 {
                Emitter::point(c, power)
            } else {
                let mut e = Emitter::point(c, power);
                e.cone = Some(LightCone::spot(r.dir(), r.range(0.1, 1.2)));
                e
            }
        })
        .collect()
}

/// Prints the tree's shape and memory once per heuristic and size.
fn report_memory() {
    let node = size_of::<guiding::light_tree::LightNode>();
    println!(
        "light tree memory (mixed scene; {node} bytes per node, plus a 4-byte leaf index per emitter):"
    );
    println!(
        "{:>9} {:>9} {:>6} {:>10} {:>14} {:>13} {:>10}",
        "heuristic", "emitters", "depth", "nodes", "node bytes", "bytes/emitter", "total MiB"
    );
    for &n in &SIZES[..3] {
        let scene = mixed_scene(n, 1);
        for h in HEURISTICS {
            let tree = LightTree::build(&scene, h).expect("valid scene");
            println!(
                "{:>9} {:>9} {:>6} {:>10} {:>14} {:>13.2} {:>10.2}",
                format!("{h:?}"),
                n,
                tree.depth(),
                tree.node_count(),
                size_of_val(tree.nodes()),
                tree.bytes() as f64 / n as f64,
                tree.bytes() as f64 / (1 << 20) as f64,
            );
        }
    }
}

fn build(c: &mut Criterion) {
    report_memory();
    let mut group = c.benchmark_group("build");
    group
        .sample_size(10)
        .sampling_mode(SamplingMode::Flat)
        .warm_up_time(Duration::from_millis(500))
        .measurement_time(Duration::from_secs(3));
    for n in SIZES {
        let scene = mixed_scene(n, 1);
        for h in HEURISTICS {
            group.bench_with_input(BenchmarkId::new(format!("{h:?}"), n), &scene, |b, s| {
                b.iter(|| LightTree::build(black_box(s.as_slice()), h).expect("valid scene"))
            });
        }
    }
    group.finish();
}

criterion_group!(benches, build);
criterion_main!(benches);
