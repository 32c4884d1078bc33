//! The combined guiding field per path vertex: the one lookup
//! (`vertex`), then a guided direction and a light from the same cell,
//! beside the same work on a separate SD-tree and GLT (two lookups), and the
//! two records a vertex makes. Prints the memory report (cuts beside
//! quadtrees).
//!
//! 10,000 lights in a 200^3 box; the field is trained for four iterations
//! (50k, 100k, 200k, 400k vertices) with synthetic records: a fragmented
//! quarter of the lights is visible, with inverse-square falloff, and
//! radiance arrives from the visible lights. The separate SD-tree and GLT
//! are trained on the same stream. Short run: `cargo bench --bench field --
//! --warm-up-time 0.3 --measurement-time 1 --sample-size 20`.

use criterion::{Criterion, criterion_group, criterion_main};
use glam::Vec3;
use guiding::LightChoice;
use guiding::RecordOutcome;
use guiding::field::{FieldConfig, GuidingField};
use guiding::glt::{Glt, GltConfig};
use guiding::light_tree::BuildHeuristic;
use guiding::math::Aabb;
use guiding::quadtree::UNIFORM_PDF;
use guiding::sd_tree::{SdTree, SdTreeConfig};
use guiding::spatial::SpatialTree;
use guiding::{Emitter, LightId, LightSampler, LightTree, ShadingContext};
use std::hint::black_box;

#[path = "../tests/common/mod.rs"]
mod common;
use common::Rand;
use common::{ByPosition, DirectionsAt, LightsAt};

const LIGHTS: usize = 10_000;
const QUERIES: usize = 4096;

fn scene() -> Aabb {
    Aabb::new(Vec3::splat(-100.0), Vec3::splat(100.0))
}

fn lights() -> Vec<Emitter> {
    let mut rng = Rand::new(1);
    (0..LIGHTS)
        .map(|i| {
            let (p, power) = (rng.point(100.0), rng.range(0.1, 10.0));
            if i % 2 == 0 {
                Emitter::point(p, power)
            } else {
                Emitter::sphere(p, 0.5, power)
            }
        })
        .collect()
}

/// The synthetic direct illumination of light `e` at `p`: a fragmented
/// quarter of the lights is visible, with inverse-square falloff.
fn contribution(lights: &[Emitter], e: u32, p: Vec3) -> f32 {
    let l = &lights[e as usize];
    if (e.wrapping_mul(2_654_435_761) >> 16) % 4 != 0 {
        return 0.0;
    }
    l.power / (l.bounds.center() - p).length_squared().max(1.0)
}

/// One training record: a point, a light sample's number, and radiance
/// from a random visible light (its direction and value).
struct Record {
    p: Vec3,
    u: f32,
    dir: Vec3,
    radiance: f32,
}

fn record(lights: &[Emitter], rng: &mut Rand) -> Record {
    let p = rng.point(100.0);
    let u = rng.f();
    let e = ((rng.f() * LIGHTS as f32) as u32 & !3).min(LIGHTS as u32 - 4);
    let to = lights[e as usize].bounds.center() - p;
    Record {
        p,
        u,
        dir: to.normalize_or(Vec3::Z),
        radiance: contribution(lights, e, p),
    }
}

struct Trained<'a> {
    field: GuidingField<&'a LightTree>,
    sd: SdTree,
    glt: Glt<&'a LightTree>,
}

fn train<'a>(lights: &[Emitter], tree: &'a LightTree) -> Trained<'a> {
    let sd_config = SdTreeConfig::improved();
    let mut field = GuidingField::new(
        tree,
        scene(),
        FieldConfig {
            sd: sd_config,
            ..FieldConfig::default()
        },
    )
    .unwrap();
    let mut sd = SdTree::new(scene(), sd_config).unwrap();
    let glt_config = GltConfig {
        spatial_threshold: sd_config.spatial_threshold,
        ..GltConfig::default()
    };
    let mut glt = Glt::new(tree, scene(), glt_config).unwrap();
    let mut rng = Rand::new(2);
    for k in 0..4 {
        for _ in 0..(50_000usize << k) {
            let r = record(lights, &mut rng);
            let ctx = ShadingContext::at(r.p);
            let v = field.vertex(&ShadingContext::at(r.p)).unwrap();
            if let Some(s) = v.light.sample(r.u) {
                let LightId::Emitter(e) = s.light else {
                    continue;
                };
                let value = contribution(lights, e, r.p) / s.pmf;
                v.light.record_light(s.light, value);
            }
            if let Some(s) = ByPosition(&glt).sample(&ctx, r.u) {
                let LightId::Emitter(e) = s.light else {
                    continue;
                };
                glt.record_light_at(r.p, s.light, contribution(lights, e, r.p) / s.pmf);
            }
            v.direction.record_radiance(r.dir, r.radiance, UNIFORM_PDF);
            sd.record_radiance_at(r.p, r.dir, r.radiance, UNIFORM_PDF);
        }
        field.refine();
        sd.refine();
        glt.refine();
    }
    Trained { field, sd, glt }
}

fn bench_field(c: &mut Criterion) {
    let lights = lights();
    let tree = LightTree::build(&lights, BuildHeuristic::Sarh).unwrap();
    let Trained { field, sd, glt } = train(&lights, &tree);
    let m = field.memory();
    eprintln!(
        "field: {} cells (separate: SD-tree {}, GLT {}), cuts {} B ({} nodes) vs quadtrees {} B \
         ({} sampling nodes): {:.2}x, sampled copies {:.2}x; total {} B",
        m.sd.cells,
        sd.cell_count(),
        glt.spatial().cell_count(),
        m.cut_bytes(),
        m.cuts.nodes,
        m.quadtree_bytes(),
        m.sd.quadtree_nodes,
        m.cut_to_quadtree(),
        m.sampled_cut_to_quadtree(),
        m.total()
    );
    let mut rng = Rand::new(3);
    let queries: Vec<(ShadingContext, [f32; 3])> = (0..QUERIES)
        .map(|_| {
            let ctx = ShadingContext::on_surface(rng.point(100.0), Vec3::Y);
            (ctx, [rng.f(), rng.f(), rng.f()])
        })
        .collect();
    let mut k = 0usize;
    let mut next = move || {
        k = (k + 1) % QUERIES;
        k
    };
    let mut group = c.benchmark_group("field");
    group.bench_function("vertex", |b| {
        b.iter(|| field.vertex(&ShadingContext::at(black_box(queries[next()].0.position))))
    });
    // One path vertex's queries: the lookup, a guided direction, a light.
    group.bench_function("vertex+direction+light", |b| {
        b.iter(|| {
            let (ctx, u) = black_box(&queries[next()]);
            let v = field.vertex(ctx).unwrap();
            let d = v.direction.sample_direction([u[0], u[1]]);
            (d, v.light.sample(u[2]))
        })
    });
    // The same with a separate SD-tree and GLT: two lookups.
    group.bench_function("separate-sd+glt/direction+light", |b| {
        b.iter(|| {
            let (ctx, u) = black_box(&queries[next()]);
            let d = sd.sample_direction_at(ctx.position, [u[0], u[1]]);
            (d, ByPosition(&glt).sample(ctx, u[2]))
        })
    });
    // The whole vertex: queries and both records (both through the
    // stochastic box, as configured).
    group.bench_function("vertex+direction+light+records", |b| {
        b.iter(|| {
            let (ctx, u) = black_box(&queries[next()]);
            let v = field.vertex(ctx).unwrap();
            let (dir, pdf) = v.direction.sample_direction([u[0], u[1]]);
            let outcome = match v.light.sample(u[2]) {
                Some(s) => v.light.record_light(s.light, 0.5 / s.pmf),
                None => RecordOutcome::Dropped,
            };
            (v.direction.record_radiance(dir, 1.0, pdf), outcome)
        })
    });
    group.finish();
}

criterion_group!(benches, bench_field);
criterion_main!(benches);
