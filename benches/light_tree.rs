//! Light tree build time per heuristic at 1e3..1e6 emitters, the time to
//! refit a built tree to moved emitters, and the tree's memory (bytes per
//! node and per emitter).
//!
//! `cargo bench --bench light_tree` runs everything (about 6 minutes on a
//! quiet 2-core machine, most of it the 1e6 builds); pass a filter such as
//! `-- build/Sarh` or `-- refit` to run less.

use criterion::measurement::WallTime;
use criterion::{
    BenchmarkGroup, BenchmarkId, Criterion, SamplingMode, criterion_group, criterion_main,
};
use guiding::light_tree::BuildHeuristic;
use guiding::{LightHierarchy, LightTree};
use std::hint::black_box;
use std::time::Duration;

#[path = "../tests/common/mod.rs"]
mod common;
use common::mixed_scene;

const HEURISTICS: [BuildHeuristic; 4] = [
    BuildHeuristic::Balanced,
    BuildHeuristic::Sah,
    BuildHeuristic::Sarh,
    BuildHeuristic::Saoh,
];
const SIZES: [usize; 4] = [1_000, 10_000, 100_000, 1_000_000];

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

/// A benchmark group of 10 flat samples of about 3 s (the 1e6 builds take
/// seconds each).
fn group<'a>(c: &'a mut Criterion, name: &str) -> BenchmarkGroup<'a, WallTime> {
    let mut group = c.benchmark_group(name);
    group
        .sample_size(10)
        .sampling_mode(SamplingMode::Flat)
        .warm_up_time(Duration::from_millis(500))
        .measurement_time(Duration::from_secs(3));
    group
}

fn build(c: &mut Criterion) {
    report_memory();
    let mut group = group(c, "build");
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

/// Refitting a SARH tree to its emitters moved (`LightTree::refit`, what a
/// renderer does per frame instead of a build), beside the SARH build.
fn refit(c: &mut Criterion) {
    let mut group = group(c, "refit");
    for n in SIZES {
        let scene = mixed_scene(n, 1);
        let moved: Vec<guiding::Emitter> = scene
            .iter()
            .map(|e| guiding::Emitter {
                bounds: guiding::Aabb::new(e.bounds.min + 0.1, e.bounds.max + 0.1),
                ..*e
            })
            .collect();
        let tree = LightTree::build(&scene, BuildHeuristic::Sarh).expect("valid scene");
        group.bench_with_input(BenchmarkId::new("Sarh", n), &moved, |b, m| {
            b.iter_batched_ref(
                || tree.clone(),
                |t| t.refit(black_box(m.as_slice())).expect("valid scene"),
                criterion::BatchSize::LargeInput,
            )
        });
    }
    group.finish();
}

criterion_group!(benches, build, refit);
criterion_main!(benches);
