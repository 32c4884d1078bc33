//! Light tree build time per heuristic at 1e3..1e6 emitters, the time to
//! refit a built tree to moved emitters, the tree's memory (bytes per node
//! and per emitter), and instanced emissive meshes: 8,000 instances of a
//! 5,000-triangle mesh built as an `InstancedLightTree` against the flat
//! tree of their triangles (built whole at 50 and 200 instances; the 8,000
//! figures scaled from them), and the GLT over it: its tables per mesh
//! against tables over every node (`Flattened`), built at 50 and 200
//! instances and scaled likewise; and what a query costs over instances
//! (`-- instanced-query`).
//!
//! `cargo bench --bench light_tree` runs everything (about 7 minutes on a
//! quiet 2-core machine, most of it the 1e6 builds); pass a filter such as
//! `-- build/Sarh`, `-- refit` or `-- instanced` to run less.

use criterion::measurement::WallTime;
use criterion::{
    BenchmarkGroup, BenchmarkId, Criterion, SamplingMode, criterion_group, criterion_main,
};
use glam::{Affine3A, Quat, Vec3};
use guiding::LightChoice;
use guiding::glt::{Glt, GltConfig};
use guiding::light_sampler::ImportanceTreeSampler;
use guiding::light_tree::{BuildHeuristic, shape_fingerprint};
use guiding::math::Aabb;
use guiding::{
    Emitter, Instance, InstancedLightTree, LightHierarchy, LightSampler, LightTree, ShadingContext,
};
use std::hint::black_box;
use std::time::Duration;

#[path = "../tests/common/mod.rs"]
mod common;
use common::{Flattened, Rand, mixed_scene, train_on_own_choices};

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

/// A mesh of `n` small emissive triangles in the unit box.
fn mesh(n: usize, r: &mut Rand) -> Vec<[Vec3; 3]> {
    (0..n)
        .map(|_| {
            let c = r.point(1.0);
            [c, c + r.dir() * 0.05, c + r.dir() * 0.05]
        })
        .collect()
}

/// `count` instances in a box 2,000 wide: turned, scaled 0.5-2x.
fn instances(count: usize, r: &mut Rand) -> Vec<Instance> {
    (0..count)
        .map(|_| {
            let turn = Quat::from_axis_angle(r.dir(), r.range(0.0, 6.0));
            let t = Affine3A::from_scale_rotation_translation(
                Vec3::splat(r.range(0.5, 2.0)),
                turn,
                r.point(1000.0),
            );
            Instance::new(0, t)
        })
        .collect()
}

fn instanced_tree(triangles: &[[Vec3; 3]], placed: &[Instance]) -> InstancedLightTree {
    let local: Vec<Emitter> = triangles
        .iter()
        .map(|&p| Emitter::triangle(p, 1.0, false))
        .collect();
    let mesh = LightTree::build(local.as_slice(), BuildHeuristic::Sarh).expect("valid mesh");
    InstancedLightTree::build(vec![mesh], placed, BuildHeuristic::Sarh).expect("valid instances")
}

fn flat(triangles: &[[Vec3; 3]], placed: &[Instance]) -> Vec<Emitter> {
    placed
        .iter()
        .flat_map(|inst| {
            triangles.iter().map(move |p| {
                let p = p.map(|c| inst.transform.transform_point3(c));
                Emitter::triangle(p, inst.power_scale, false)
            })
        })
        .collect()
}

/// 8,000 instances of a 5,000-triangle mesh: the instanced build (the
/// mesh's tree and the top tree) against the flat build at 50 and 200
/// instances (the flat one at 8,000 would hold 40 million leaves).
fn instanced(c: &mut Criterion) {
    const TRIANGLES: usize = 5_000;
    let mut r = Rand::new(9);
    let triangles = mesh(TRIANGLES, &mut r);
    let all = instances(8_000, &mut r);
    let tree = instanced_tree(&triangles, &all);
    println!("instanced emissive meshes ({TRIANGLES} triangles per mesh, SARH):");
    println!(
        "  instanced, 8000 instances: {} emitters, {} nodes as a hierarchy, {:.2} MiB",
        tree.emitter_count(),
        tree.node_count(),
        tree.bytes() as f64 / (1 << 20) as f64
    );
    for count in [50, 200] {
        let lights = flat(&triangles, &all[..count]);
        let t = LightTree::build(lights.as_slice(), BuildHeuristic::Sarh).expect("valid scene");
        let at_8000 = t.bytes() as f64 * 8000.0 / count as f64;
        println!(
            "  flat, {count} instances: {} emitters, {:.2} MiB; scaled to 8000: {:.0} MiB, {:.0}x the instanced",
            lights.len(),
            t.bytes() as f64 / (1 << 20) as f64,
            at_8000 / (1 << 20) as f64,
            at_8000 / tree.bytes() as f64
        );
    }
    // The GLT over them: its tables per mesh, against tables over every
    // node of the flat tree the instances stand for (`Flattened`).
    let scene = Aabb::new(Vec3::splat(-1100.0), Vec3::splat(1100.0));
    let glt = Glt::new(&tree, scene, GltConfig::default()).expect("valid configuration");
    println!(
        "  GLT over the instanced tree, 8000 instances: tables {:.2} MiB, total {:.2} MiB",
        glt.memory().shared_bytes as f64 / (1 << 20) as f64,
        glt.memory().total() as f64 / (1 << 20) as f64
    );
    // What hashing the flat tree node by node costs (what saving and
    // loading did before the fingerprint hashed the parts).
    let start = std::time::Instant::now();
    let every_node = shape_fingerprint(&Flattened(&tree));
    println!(
        "  shape fingerprint node by node, 8000 instances: {:.2} s ({every_node:x}); by parts: {:x}",
        start.elapsed().as_secs_f64(),
        shape_fingerprint(&tree)
    );
    let small: Vec<InstancedLightTree> = [50, 200]
        .map(|count| instanced_tree(&triangles, &all[..count]))
        .into();
    for t in &small {
        let count = t.top().emitter_count();
        let g = Glt::new(Flattened(t), scene, GltConfig::default()).expect("valid configuration");
        let at_8000 = g.memory().shared_bytes as f64 * 8000.0 / count as f64;
        println!(
            "  GLT with tables over every node, {count} instances: tables {:.2} MiB; scaled to 8000: {:.0} MiB, {:.0}x the per-mesh tables",
            g.memory().shared_bytes as f64 / (1 << 20) as f64,
            at_8000 / (1 << 20) as f64,
            at_8000 / glt.memory().shared_bytes as f64
        );
    }
    let mut group = group(c, "instanced");
    group.bench_function(BenchmarkId::new("instanced", "8000x5000"), |b| {
        b.iter(|| instanced_tree(black_box(&triangles), black_box(&all)))
    });
    group.bench_function(BenchmarkId::new("glt", "8000x5000"), |b| {
        b.iter(|| Glt::new(black_box(&tree), scene, GltConfig::default()))
    });
    // Saving and loading bind the state to the tree's shape fingerprint,
    // over an instanced tree hashed by its parts.
    let saved = glt.to_bytes();
    group.bench_function(BenchmarkId::new("glt-save", "8000x5000"), |b| {
        b.iter(|| black_box(&glt).to_bytes())
    });
    group.bench_function(BenchmarkId::new("glt-load", "8000x5000"), |b| {
        b.iter(|| Glt::from_bytes(black_box(&saved), &tree))
    });
    for t in &small {
        let count = t.top().emitter_count();
        group.bench_function(
            BenchmarkId::new("glt-every-node", format!("{count}x5000")),
            |b| b.iter(|| Glt::new(Flattened(black_box(t)), scene, GltConfig::default())),
        );
    }
    for count in [50, 200] {
        let lights = flat(&triangles, &all[..count]);
        group.bench_with_input(
            BenchmarkId::new("flat", format!("{count}x5000")),
            &lights,
            |b, l| b.iter(|| LightTree::build(black_box(l.as_slice()), BuildHeuristic::Sarh)),
        );
    }
    group.finish();
}

/// A GLT over `tree` trained as a renderer trains it, without shadows: 3
/// rounds of 20,000 records, each the contribution of a light the GLT
/// chooses at a random point on a random surface, over its pmf.
fn trained<H: LightHierarchy>(tree: H, lights: &[Emitter], scene: Aabb) -> Glt<H> {
    let mut glt = Glt::new(tree, scene, GltConfig::default()).expect("valid configuration");
    let half = scene.max.x - 2.0;
    train_on_own_choices(&mut glt, lights, half, (3, 20_000), &mut Rand::new(10));
    glt
}

/// A query over 200 instances of a 500-triangle mesh (turned, scaled
/// 0.5-2x, in a box 100 wide): importance sampling over the flat tree and
/// the instanced one, and the GLT over the flat tree, over the instanced
/// one with tables over every node (`Flattened`), and with its tables per
/// mesh; one sample and its pmf at a random point on a random surface.
fn instanced_queries(c: &mut Criterion) {
    let mut r = Rand::new(3);
    let triangles: Vec<[Vec3; 3]> = (0..500)
        .map(|_| {
            let c = r.point(1.0);
            [c, c + r.dir() * 0.05, c + r.dir() * 0.05]
        })
        .collect();
    let placed: Vec<Instance> = (0..200)
        .map(|_| {
            let turn = Quat::from_axis_angle(r.dir(), r.range(0.0, 6.0));
            let scale = Vec3::splat(r.range(0.5, 2.0));
            Instance::new(
                0,
                Affine3A::from_scale_rotation_translation(scale, turn, r.point(50.0)),
            )
        })
        .collect();
    let tree = instanced_tree(&triangles, &placed);
    let lights = flat(&triangles, &placed);
    let flat_tree = LightTree::build(lights.as_slice(), BuildHeuristic::Sarh).expect("valid scene");
    let scene = Aabb::new(Vec3::splat(-52.0), Vec3::splat(52.0));
    let queries: Vec<(ShadingContext, f32)> = (0..1000)
        .map(|_| (ShadingContext::on_surface(r.point(50.0), r.dir()), r.f()))
        .collect();
    let mut group = c.benchmark_group("instanced-query");
    let per_query = |s: &dyn LightSampler, ctx: &ShadingContext, u: f32| {
        s.sample(ctx, u)
            .map_or(0.0, |x| x.pmf + s.pmf(ctx, x.light))
    };
    for (name, s) in [
        (
            "bvh-flat",
            &ImportanceTreeSampler::new(&flat_tree) as &dyn LightSampler,
        ),
        ("bvh-instanced", &ImportanceTreeSampler::new(&tree)),
    ] {
        group.bench_function(name, |b| {
            b.iter(|| {
                queries
                    .iter()
                    .map(|(ctx, u)| per_query(s, ctx, *u))
                    .sum::<f32>()
            })
        });
    }
    fn glt_queries<H: LightHierarchy>(glt: &Glt<H>, queries: &[(ShadingContext, f32)]) -> f32 {
        queries
            .iter()
            .map(|(ctx, u)| {
                glt.vertex(ctx).map_or(0.0, |v| {
                    v.sample(*u).map_or(0.0, |x| x.pmf + v.pmf(x.light))
                })
            })
            .sum()
    }
    let (a, b, c) = (
        trained(&flat_tree, &lights, scene),
        trained(Flattened(&tree), &lights, scene),
        trained(&tree, &lights, scene),
    );
    group.bench_function("glt-flat", |bench| bench.iter(|| glt_queries(&a, &queries)));
    group.bench_function("glt-every-node", |bench| {
        bench.iter(|| glt_queries(&b, &queries))
    });
    group.bench_function("glt-per-mesh", |bench| {
        bench.iter(|| glt_queries(&c, &queries))
    });
    group.finish();
}

criterion_group!(benches, build, refit, instanced, instanced_queries);
criterion_main!(benches);
