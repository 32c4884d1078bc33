//! The directional quadtree per call against depth: `sample`, `pdf`,
//! `record` (both filters, both accumulation modes) and `refine` per tree,
//! plus bytes per node (printed before the timings).
//!
//! `cargo bench --bench quadtree`; medians are in
//! `target/criterion/quadtree_*/*/new/estimates.json`.

use criterion::{BatchSize, BenchmarkId, Criterion, criterion_group, criterion_main};
use glam::{Vec2, Vec3};
use guiding::math::{Accumulation, canonical_to_dir};
use guiding::quadtree::{DirectionalFilter, DirectionalTree, NODE_BYTES, QuadtreeConfig};
use rand_pcg::Pcg64;
use rand_pcg::rand_core::{Rng, SeedableRng};
use std::hint::black_box;

const DEPTHS: [u32; 4] = [4, 8, 12, 16];
/// Inputs cycled through per measured call.
const BATCH: usize = 1024;

fn unit(r: &mut Pcg64) -> f32 {
    (r.next_u32() >> 8) as f32 * (1.0 / 16_777_216.0)
}

fn random_dir(r: &mut Pcg64) -> Vec3 {
    canonical_to_dir(Vec2::new(unit(r), unit(r)))
}

/// Radiance from a broad lobe, a narrow lobe, a point-like source and a dim
/// background: enough structure to refine to any depth.
fn draw(r: &mut Pcg64) -> (Vec3, f32) {
    let lobes = [
        (Vec3::new(0.3, 0.5, 0.8), 0.2),
        (Vec3::new(-0.7, 0.1, -0.2), 0.02),
        (Vec3::new(0.05, -0.9, -0.4), 0.0),
    ];
    let x = unit(r);
    if x < 0.1 {
        return (random_dir(r), 0.5);
    }
    let (centre, spread) = lobes[(x * 3.0) as usize % 3];
    let dir = (centre.normalize() + spread * unit(r) * random_dir(r)).normalize();
    (dir, 1.0 + unit(r))
}

/// A tree refined until its sampling copy is `depth` levels deep, holding
/// one iteration of records in its building copy.
fn trained(depth: u32, mode: Accumulation) -> (DirectionalTree, QuadtreeConfig) {
    let config = QuadtreeConfig {
        rho: 0.01,
        max_depth: depth,
    };
    let mut r = Pcg64::seed_from_u64(depth as u64);
    let mut tree = DirectionalTree::new(mode);
    let record = |tree: &DirectionalTree, r: &mut Pcg64| {
        for _ in 0..50_000 {
            let (d, v) = draw(r);
            tree.record(d, v, DirectionalFilter::Nearest);
        }
    };
    for _ in 0..16 {
        record(&tree, &mut r);
        tree.refine(&config);
        if tree.depth() as u32 >= depth && tree.building_depth() as u32 >= depth {
            break;
        }
    }
    record(&tree, &mut r);
    (tree, config)
}

fn report_memory(c: &mut Criterion) {
    let _ = c;
    println!("quadtree: sampling node = {NODE_BYTES} bytes");
    for mode in [Accumulation::Fast, Accumulation::Deterministic] {
        for depth in DEPTHS {
            let (tree, _) = trained(depth, mode);
            let nodes = tree.node_count() + tree.building_node_count();
            println!(
                "quadtree {mode:?} depth {depth}: depth {} / {}, nodes {} sampling + {} building, \
                 {} bytes, {:.1} bytes per node (both copies)",
                tree.depth(),
                tree.building_depth(),
                tree.node_count(),
                tree.building_node_count(),
                tree.bytes(),
                tree.bytes() as f64 / nodes as f64,
            );
        }
    }
}

fn queries(c: &mut Criterion) {
    for depth in DEPTHS {
        let (tree, _) = trained(depth, Accumulation::Fast);
        let mut r = Pcg64::seed_from_u64(99);
        let us: Vec<[f32; 2]> = (0..BATCH).map(|_| [unit(&mut r), unit(&mut r)]).collect();
        let dirs: Vec<Vec3> = us.iter().map(|&u| tree.sample(u).0).collect();

        let mut g = c.benchmark_group("quadtree_sample");
        let mut i = 0;
        g.bench_function(BenchmarkId::from_parameter(depth), |b| {
            b.iter(|| {
                i = (i + 1) % BATCH;
                tree.sample(black_box(us[i]))
            })
        });
        g.finish();

        let mut g = c.benchmark_group("quadtree_pdf");
        g.bench_function(BenchmarkId::from_parameter(depth), |b| {
            b.iter(|| {
                i = (i + 1) % BATCH;
                tree.pdf(black_box(dirs[i]))
            })
        });
        g.finish();
    }
}

fn records(c: &mut Criterion) {
    let cases = [
        (
            "quadtree_record_nearest",
            Accumulation::Fast,
            DirectionalFilter::Nearest,
        ),
        (
            "quadtree_record_box",
            Accumulation::Fast,
            DirectionalFilter::Box,
        ),
        (
            "quadtree_record_nearest_deterministic",
            Accumulation::Deterministic,
            DirectionalFilter::Nearest,
        ),
        (
            "quadtree_record_box_deterministic",
            Accumulation::Deterministic,
            DirectionalFilter::Box,
        ),
    ];
    for (name, mode, filter) in cases {
        let mut g = c.benchmark_group(name);
        for depth in DEPTHS {
            let (tree, _) = trained(depth, mode);
            let mut r = Pcg64::seed_from_u64(7);
            let input: Vec<(Vec3, f32)> = (0..BATCH).map(|_| draw(&mut r)).collect();
            let mut i = 0;
            g.bench_function(BenchmarkId::from_parameter(depth), |b| {
                b.iter(|| {
                    i = (i + 1) % BATCH;
                    let (d, v) = input[i];
                    tree.record(black_box(d), black_box(v), filter)
                })
            });
        }
        g.finish();
    }
}

fn refine(c: &mut Criterion) {
    for mode in [Accumulation::Fast, Accumulation::Deterministic] {
        let name = match mode {
            Accumulation::Fast => "quadtree_refine",
            Accumulation::Deterministic => "quadtree_refine_deterministic",
        };
        let mut g = c.benchmark_group(name);
        for depth in DEPTHS {
            let (tree, config) = trained(depth, mode);
            g.bench_function(BenchmarkId::from_parameter(depth), |b| {
                b.iter_batched(
                    || tree.clone(),
                    |mut t| {
                        t.refine(&config);
                        t
                    },
                    BatchSize::LargeInput,
                )
            });
        }
        g.finish();
    }
}

criterion_group!(benches, report_memory, queries, records, refine);
criterion_main!(benches);
