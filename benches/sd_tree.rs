//! SD-tree costs per call on a trained tree: the spatial lookup alone,
//! `sample`, `pdf`, `record` (per filter and accumulation mode), and `refine`
//! per cell. Prints the memory report and bytes per node.

#[path = "../tests/common/mod.rs"]
mod common;
use common::DirectionsAt;
use criterion::{BatchSize, Criterion, Throughput, criterion_group, criterion_main};
use glam::{Vec2, Vec3};
use guiding::math::{Aabb, Accumulation, canonical_to_dir};
use guiding::quadtree::{DirectionalFilter, NODE_BYTES, UNIFORM_PDF};
use guiding::sd_tree::{SdTree, SdTreeConfig};
use guiding::spatial::SpatialFilter;
use guiding::spatial::SpatialTree;
use rand_pcg::Pcg32;
use rand_pcg::rand_core::{Rng, SeedableRng};
use std::hint::black_box;
use std::time::Duration;

const QUERIES: usize = 4096;

fn unit(rng: &mut Pcg32) -> f32 {
    (rng.next_u32() >> 8) as f32 / (1u32 << 24) as f32
}

fn scene() -> Aabb {
    Aabb::new(Vec3::new(-2.0, -1.0, -1.0), Vec3::new(2.0, 1.0, 1.0))
}

fn point(rng: &mut Pcg32) -> Vec3 {
    let b = scene();
    b.min + Vec3::new(unit(rng), unit(rng), unit(rng)) * b.diagonal()
}

/// A direction from one of eight lobes, narrow enough that the quadtrees
/// refine several levels deep.
fn lobe_dir(rng: &mut Pcg32) -> Vec3 {
    let k = rng.next_u32() % 8;
    let l = canonical_to_dir(Vec2::new(0.1 + 0.1 * k as f32, 0.13 * k as f32 + 0.05));
    let n = Vec3::new(unit(rng), unit(rng), unit(rng)) - 0.5;
    (l + 0.03 * n).normalize()
}

/// Five iterations of 2^k * 20000 lobe records with threshold c.
fn trained(config: SdTreeConfig) -> SdTree {
    let mut t = SdTree::new(scene(), config).unwrap();
    let mut rng = Pcg32::seed_from_u64(1);
    for k in 0..5 {
        for _ in 0..(20_000usize << k) {
            let (p, d) = (point(&mut rng), lobe_dir(&mut rng));
            t.record_radiance_at(p, d, 1.0, UNIFORM_PDF);
        }
        t.refine();
    }
    t
}

fn report(name: &str, t: &SdTree) {
    let m = t.memory();
    let max_qt_depth = t
        .spatial()
        .data_slice()
        .iter()
        .map(|c| c.directions().depth())
        .max()
        .unwrap_or(0);
    println!(
        "{name}: {} cells, {} spatial nodes ({} B/node word + {} B/cell), {} quadtree nodes \
         (sampling {} B/node, max depth {max_qt_depth}), total {} B: spatial {} B, quadtrees {} B, \
         statistics {} B; {:.1} B per quadtree node all in",
        m.cells,
        m.spatial_nodes,
        SdTree::SPATIAL_NODE_BYTES,
        guiding::spatial::BinaryTree::<guiding::sd_tree::SdCell>::CELL_META_BYTES
            + std::mem::size_of::<guiding::sd_tree::SdCell>(),
        m.quadtree_nodes,
        NODE_BYTES,
        m.total(),
        m.spatial_bytes,
        m.quadtree_bytes,
        m.statistics_bytes,
        m.quadtree_bytes as f64 / m.quadtree_building_nodes.max(1) as f64,
    );
}

fn queries(c: &mut Criterion) {
    let config = SdTreeConfig {
        spatial_threshold: 4000.0,
        ..SdTreeConfig::default()
    };
    let t = trained(config);
    report("fast", &t);
    let mut rng = Pcg32::seed_from_u64(2);
    let points: Vec<Vec3> = (0..QUERIES).map(|_| point(&mut rng)).collect();
    let us: Vec<[f32; 2]> = (0..QUERIES)
        .map(|_| [unit(&mut rng), unit(&mut rng)])
        .collect();
    let dirs: Vec<Vec3> = (0..QUERIES).map(|_| lobe_dir(&mut rng)).collect();

    let mut g = c.benchmark_group("sd_tree");
    g.throughput(Throughput::Elements(1));
    let mut i = 0;
    g.bench_function("locate", |b| {
        b.iter(|| {
            i = (i + 1) % QUERIES;
            black_box(t.spatial().locate(black_box(points[i])))
        })
    });
    g.bench_function("sample", |b| {
        b.iter(|| {
            i = (i + 1) % QUERIES;
            black_box(t.sample_direction_at(black_box(points[i]), black_box(us[i])))
        })
    });
    g.bench_function("pdf", |b| {
        b.iter(|| {
            i = (i + 1) % QUERIES;
            black_box(t.direction_pdf_at(black_box(points[i]), black_box(dirs[i])))
        })
    });
    let filters = [
        (
            "record/nearest",
            SpatialFilter::Nearest,
            DirectionalFilter::Nearest,
        ),
        (
            "record/stochastic_box+box",
            SpatialFilter::StochasticBox,
            DirectionalFilter::Box,
        ),
        ("record/box+box", SpatialFilter::Box, DirectionalFilter::Box),
    ];
    for (name, spatial_filter, directional_filter) in filters {
        let filtered = trained(SdTreeConfig {
            spatial_filter,
            directional_filter,
            ..config
        });
        g.bench_function(name, |b| {
            b.iter(|| {
                i = (i + 1) % QUERIES;
                black_box(filtered.record_radiance_at(points[i], dirs[i], 1.0, 0.5))
            })
        });
    }
    let det = trained(SdTreeConfig {
        accumulation: Accumulation::Deterministic,
        ..config
    });
    report("deterministic", &det);
    g.bench_function("record/nearest/deterministic", |b| {
        b.iter(|| {
            i = (i + 1) % QUERIES;
            black_box(det.record_radiance_at(points[i], dirs[i], 1.0, 0.5))
        })
    });
    g.finish();
}

fn refine(c: &mut Criterion) {
    // A tree holding one more iteration of records, refined from a clone.
    let config = SdTreeConfig {
        spatial_threshold: 4000.0,
        learn_bsdf_fraction: true,
        ..SdTreeConfig::default()
    };
    let t = trained(config);
    let mut rng = Pcg32::seed_from_u64(4);
    for _ in 0..200_000 {
        let (p, d) = (point(&mut rng), lobe_dir(&mut rng));
        t.record_radiance_at(p, d, 1.0, UNIFORM_PDF);
        t.record_fraction_at(p, unit(&mut rng), unit(&mut rng), unit(&mut rng));
    }
    let cells = t.cell_count() as u64;
    println!("refine: {cells} cells before refining (time per cell = median / cells)");
    let mut g = c.benchmark_group("sd_tree_refine");
    g.throughput(Throughput::Elements(cells));
    g.bench_function("refine", |b| {
        b.iter_batched(
            || t.clone(),
            |mut t| {
                t.refine();
                t
            },
            BatchSize::LargeInput,
        )
    });
    g.finish();
}

criterion_group! {
    name = benches;
    config = Criterion::default()
        .sample_size(20)
        .warm_up_time(Duration::from_millis(300))
        .measurement_time(Duration::from_secs(1));
    targets = queries, refine
}
criterion_main!(benches);
