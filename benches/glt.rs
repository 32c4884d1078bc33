//! Microbenchmarks of the Guiding Light Tree: `sample`, `pmf` and both per
//! call for sigma in {0.05, 0.01, 0.002} and 1e2..1e6 lights, beside
//! tree-by-power sampling on the same tree; a whole GLT's `sample` and
//! `sample` + `pmf` beside its GPU snapshot's `f32` sampler on the CPU;
//! `record` per call; `refine` per cell; bytes per cut node and per cell
//! (printed).
//!
//! Cuts are trained with synthetic records (a fragmented visible subset with
//! distance falloff, sampled from the cut itself as a renderer would) so they
//! reach realistic sizes. Short run: `cargo bench --bench glt --
//! --warm-up-time 0.3 --measurement-time 1 --sample-size 20`; set
//! `GLT_BENCH_LIGHTS=100,10000` to build and train only those sizes (the
//! 1e6 scene takes ~30 s to set up).
//!
//! `cut-untrained/sample+pmf` samples exactly the power distribution (the
//! initial cut), so its ratio to `power/sample+pmf` is the rule's own
//! overhead; trained cuts choose other leaves, whose path lengths are
//! printed beside the tree's.

use criterion::{BatchSize, BenchmarkId, Criterion, criterion_group, criterion_main};
use glam::Vec3;
use guiding::cut::{BelowCut, CutConfig, CutNode, CutRules, GuidingCut};
use guiding::glt::{Glt, GltConfig};
use guiding::light_sampler::PowerTreeSampler;
use guiding::light_tree::BuildHeuristic;
use guiding::math::Aabb;
use guiding::{
    Emitter, LightChoice, LightHierarchy, LightId, LightSampler, LightTree, ShadingContext,
};
use std::hint::black_box;

#[path = "../tests/common/mod.rs"]
mod common;
use common::Rand;
use common::{ByPosition, LightsAt};

const LIGHTS: [usize; 5] = [100, 1_000, 10_000, 100_000, 1_000_000];
const SIGMAS: [f64; 3] = [0.05, 0.01, 0.002];

fn scene(n: usize) -> (Vec<Emitter>, LightTree) {
    let mut rng = Rand::new(n as u64);
    let lights: Vec<Emitter> = (0..n)
        .map(|i| {
            let p = Vec3::new(
                rng.range(-100.0, 100.0),
                rng.range(-100.0, 100.0),
                rng.range(-100.0, 100.0),
            );
            let power = rng.range(0.1, 10.0);
            if i % 2 == 0 {
                Emitter::point(p, power)
            } else {
                Emitter::sphere(p, 0.5, power)
            }
        })
        .collect();
    let heuristic = if n > 100_000 {
        BuildHeuristic::Balanced
    } else {
        BuildHeuristic::Sarh
    };
    let tree = LightTree::build(&lights, heuristic).unwrap();
    (lights, tree)
}

/// The synthetic direct illumination at `p`: a fragmented quarter of the
/// lights is visible, with inverse-square falloff.
fn contribution(lights: &[Emitter], e: u32, p: Vec3) -> f32 {
    let visible = (e.wrapping_mul(2_654_435_761) >> 16) % 4 == 0;
    let l = &lights[e as usize];
    if !visible {
        return 0.0;
    }
    l.power / (l.bounds.center() - p).length_squared().max(1.0)
}

const POINT: Vec3 = Vec3::new(10.0, -20.0, 5.0);

fn trained_cut(lights: &[Emitter], guide: &CutRules<&LightTree>) -> GuidingCut {
    let mut rng = Rand::new(7);
    let ctx = ShadingContext::on_surface(POINT, Vec3::Y);
    let mut cut = guide.new_cut();
    let per_iteration = (4 * lights.len()).clamp(20_000, 200_000);
    for _ in 0..4 {
        for _ in 0..per_iteration {
            let Some(s) = guide.sample(&cut, &ctx, rng.f()) else {
                continue;
            };
            let LightId::Emitter(e) = s.light else {
                continue;
            };
            guide.record_from(&cut, POINT, s.light, contribution(lights, e, POINT) / s.pmf);
        }
        guide.refine(&mut cut);
    }
    cut
}

fn us(n: usize) -> Vec<f32> {
    let mut rng = Rand::new(n as u64 ^ 0x5eed);
    (0..4096).map(|_| rng.f()).collect()
}

/// The light counts to run: all of [`LIGHTS`], or the comma-separated list
/// in `GLT_BENCH_LIGHTS` (scene building and training run outside
/// criterion's filter, so this skips their cost too).
fn light_counts() -> Vec<usize> {
    match std::env::var("GLT_BENCH_LIGHTS") {
        Ok(list) => list
            .split(',')
            .filter_map(|x| x.trim().parse().ok())
            .collect(),
        Err(_) => LIGHTS.to_vec(),
    }
}

fn bench_sampling(c: &mut Criterion) {
    let ctx = ShadingContext::on_surface(POINT, Vec3::Y);
    for n in light_counts() {
        let (lights, tree) = scene(n);
        let power = PowerTreeSampler::new(&tree);
        let u = us(n);
        let mut group = c.benchmark_group(format!("glt/{n}"));
        let mut k = 0usize;
        let mut next = move || {
            k = (k + 1) & 4095;
            k
        };
        group.bench_function("power/sample", |b| {
            b.iter(|| power.sample(black_box(&ctx), black_box(u[next()])))
        });
        let mut emitted: Vec<LightId> = u
            .iter()
            .filter_map(|&x| power.sample(&ctx, x).map(|s| s.light))
            .collect();
        emitted.truncate(4096);
        group.bench_function("power/pmf", |b| {
            b.iter(|| power.pmf(black_box(&ctx), black_box(emitted[next() % emitted.len()])))
        });
        group.bench_function("power/sample+pmf", |b| {
            b.iter(|| {
                let s = power.sample(black_box(&ctx), black_box(u[next()])).unwrap();
                power.pmf(&ctx, s.light)
            })
        });
        // The untrained cut samples exactly the power distribution: the
        // same leaves, so the same path lengths; the ratio to `power` is
        // the rule's own overhead. Trained cuts choose other (often deeper)
        // leaves, which costs more for any sampler.
        let fresh_guide = CutRules::new(&tree, CutConfig::default()).unwrap();
        let fresh = fresh_guide.new_cut();
        group.bench_function("cut-untrained/sample+pmf", |b| {
            b.iter(|| {
                let s = fresh_guide
                    .sample(&fresh, black_box(&ctx), black_box(u[next()]))
                    .unwrap();
                fresh_guide.pmf(&fresh, &ctx, s.light)
            })
        });
        let depth = |light: LightId| match light {
            LightId::Emitter(e) => tree.path(e).map_or(0, |p| p.depth()),
            LightId::Unbounded(_) => 0,
        };
        let mean_depth = |lights: &[LightId]| {
            lights.iter().map(|&l| depth(l)).sum::<usize>() as f64 / lights.len().max(1) as f64
        };
        eprintln!(
            "glt/{n}: tree depth {}, mean sampled depth by power {:.1}",
            tree.depth(),
            mean_depth(&emitted)
        );
        for sigma in SIGMAS {
            let config = CutConfig {
                sigma,
                ..CutConfig::default()
            };
            let guide = CutRules::new(&tree, config).unwrap();
            let cut = trained_cut(&lights, &guide);
            let sampled: Vec<LightId> = u
                .iter()
                .filter_map(|&x| guide.sample(&cut, &ctx, x).map(|s| s.light))
                .collect();
            // Tree-by-power evaluated on the leaves the trained cut picks:
            // the same path lengths as the cut's own pmf.
            eprintln!(
                "glt/{n} sigma={sigma}: mean sampled depth {:.1}",
                mean_depth(&sampled)
            );
            group.bench_function(BenchmarkId::new("power/pmf-of-cut-samples", sigma), |b| {
                b.iter(|| power.pmf(black_box(&ctx), black_box(sampled[next() % sampled.len()])))
            });
            let m = cut.memory();
            eprintln!(
                "glt/{n} sigma={sigma}: {} cut nodes, {} B nodes + {} B sums = {} B per cell, {} B per cut node",
                m.nodes,
                m.node_bytes,
                m.sum_bytes,
                m.total(),
                CutNode::BYTES
            );
            group.bench_function(BenchmarkId::new("cut/sample", sigma), |b| {
                b.iter(|| guide.sample(&cut, black_box(&ctx), black_box(u[next()])))
            });
            group.bench_function(BenchmarkId::new("cut/pmf", sigma), |b| {
                b.iter(|| {
                    guide.pmf(
                        &cut,
                        black_box(&ctx),
                        black_box(sampled[next() % sampled.len()]),
                    )
                })
            });
            group.bench_function(BenchmarkId::new("cut/sample+pmf", sigma), |b| {
                b.iter(|| {
                    let s = guide
                        .sample(&cut, black_box(&ctx), black_box(u[next()]))
                        .unwrap();
                    guide.pmf(&cut, &ctx, s.light)
                })
            });
        }
        if n == 10_000 {
            // Variants at one size: the paper's rules (one distribution per
            // cell, power below the cut and as the prior), without the
            // prior mixture, with importance below the cut only; and the
            // whole Glt (spatial lookup included).
            for (name, config) in [
                (
                    "cut-paper-rules/sample+pmf",
                    CutConfig::default().with_paper_rules(),
                ),
                (
                    "cut-alpha0/sample+pmf",
                    CutConfig {
                        alpha: 0.0,
                        ..CutConfig::default().with_paper_rules()
                    },
                ),
                (
                    "cut-importance/sample+pmf",
                    CutConfig {
                        below_cut: BelowCut::Importance,
                        ..CutConfig::default().with_paper_rules()
                    },
                ),
            ] {
                let guide = CutRules::new(&tree, config).unwrap();
                let cut = trained_cut(&lights, &guide);
                group.bench_function(name, |b| {
                    b.iter(|| {
                        let s = guide
                            .sample(&cut, black_box(&ctx), black_box(u[next()]))
                            .unwrap();
                        guide.pmf(&cut, &ctx, s.light)
                    })
                });
            }
            let glt = trained_glt(&lights, &tree);
            let m = glt.memory();
            eprintln!(
                "glt/{n} Glt: {} cells, {} cut nodes, {} B total, {:.0} B per cell",
                m.cells,
                m.cuts.nodes,
                m.total(),
                m.bytes_per_cell()
            );
            let mut rng = Rand::new(3);
            let points: Vec<Vec3> = (0..4096)
                .map(|_| {
                    Vec3::new(
                        rng.range(-90.0, 90.0),
                        rng.range(-90.0, 90.0),
                        rng.range(-90.0, 90.0),
                    )
                })
                .collect();
            group.bench_function("glt/sample+pmf", |b| {
                b.iter(|| {
                    let i = next();
                    let ctx = ShadingContext::on_surface(points[i], Vec3::Y);
                    let v = glt.vertex(black_box(&ctx)).unwrap();
                    let s = v.sample(black_box(u[i])).unwrap();
                    v.pmf(s.light)
                })
            });
            // The same queries through the GPU snapshot's f32 sampler on
            // the CPU (src/snapshot/): one cell lookup per query, as the
            // GLT's vertex.
            let snapshot = glt.snapshot().unwrap();
            let view = snapshot.view();
            group.bench_function("snapshot/sample+pmf", |b| {
                b.iter(|| {
                    let i = next();
                    let ctx = ShadingContext::on_surface(points[i], Vec3::Y);
                    let v = view.vertex(black_box(&ctx)).unwrap();
                    let s = v.sample(black_box(u[i])).unwrap();
                    v.pmf(s.light)
                })
            });
            group.bench_function("glt/sample", |b| {
                b.iter(|| {
                    let i = next();
                    let ctx = ShadingContext::on_surface(points[i], Vec3::Y);
                    ByPosition(&glt).sample(black_box(&ctx), black_box(u[i]))
                })
            });
            group.bench_function("snapshot/sample", |b| {
                b.iter(|| {
                    let i = next();
                    let ctx = ShadingContext::on_surface(points[i], Vec3::Y);
                    view.vertex(black_box(&ctx))
                        .and_then(|v| v.sample(black_box(u[i])))
                })
            });
            group.bench_function("power/sample+pmf-moving", |b| {
                b.iter(|| {
                    let i = next();
                    let ctx = ShadingContext::on_surface(points[i], Vec3::Y);
                    let s = power.sample(black_box(&ctx), black_box(u[i])).unwrap();
                    power.pmf(&ctx, s.light)
                })
            });
            group.bench_function("glt/record", |b| {
                b.iter(|| {
                    let i = next();
                    glt.record_light_at(
                        black_box(points[i]),
                        LightId::Emitter(i as u32 % n as u32),
                        black_box(1.5),
                    )
                })
            });
            let config = CutConfig::default();
            let guide = CutRules::new(&tree, config).unwrap();
            let cut = trained_cut(&lights, &guide);
            group.bench_function("cut/record", |b| {
                b.iter(|| {
                    let i = next();
                    guide.record(&cut, black_box(LightId::Emitter(i as u32 % n as u32)), 1.5)
                })
            });
        }
        for sigma in SIGMAS {
            if n > 100_000 && sigma < 0.01 {
                continue;
            }
            let config = CutConfig {
                sigma,
                ..CutConfig::default()
            };
            let guide = CutRules::new(&tree, config).unwrap();
            // A trained cut holding one iteration's sums.
            let cut = trained_cut(&lights, &guide);
            let mut rng = Rand::new(5);
            for _ in 0..20_000 {
                if let Some(s) = guide.sample(&cut, &ctx, rng.f()) {
                    let LightId::Emitter(e) = s.light else {
                        continue;
                    };
                    guide.record(&cut, s.light, contribution(&lights, e, POINT) / s.pmf);
                }
            }
            group.bench_function(BenchmarkId::new("cut/refine", sigma), |b| {
                b.iter_batched(
                    || cut.clone(),
                    |mut c| {
                        guide.refine(&mut c);
                        c
                    },
                    BatchSize::SmallInput,
                )
            });
        }
        group.finish();
    }
}

/// A Glt over the scene trained at random points.
fn trained_glt<'a>(lights: &[Emitter], tree: &'a LightTree) -> Glt<&'a LightTree> {
    let bounds = Aabb::new(Vec3::splat(-100.0), Vec3::splat(100.0));
    let mut glt = Glt::new(
        tree,
        bounds,
        GltConfig {
            spatial_threshold: 4000.0,
            ..GltConfig::default()
        },
    )
    .unwrap();
    let mut rng = Rand::new(9);
    for _ in 0..4 {
        for _ in 0..100_000 {
            let p = Vec3::new(
                rng.range(-90.0, 90.0),
                rng.range(-90.0, 90.0),
                rng.range(-90.0, 90.0),
            );
            let ctx = ShadingContext::on_surface(p, Vec3::Y);
            let Some(s) = ByPosition(&glt).sample(&ctx, rng.f()) else {
                continue;
            };
            let LightId::Emitter(e) = s.light else {
                continue;
            };
            glt.record_light_at(p, s.light, contribution(lights, e, p) / s.pmf);
        }
        glt.refine();
    }
    glt
}

criterion_group!(benches, bench_sampling);
criterion_main!(benches);
