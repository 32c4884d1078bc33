//! What a renderer that holds a [`SharedGuide`]'s guard per path pays for
//! it: `read` + drop + `refine_when_due(1)` (not due) on one thread, and
//! the same while a second thread does it in a loop (the lock's cache line
//! shared), beside one GLT `vertex` + `sample` for scale. Short run:
//! `cargo bench --bench shared_guide -- --warm-up-time 0.3
//! --measurement-time 1 --sample-size 20`.

use criterion::{Criterion, criterion_group, criterion_main};
use glam::Vec3;
use guiding::{Aabb, Emitter, Glt, GltConfig, LightChoice, LightTree};
use guiding::{RefineSchedule, ShadingContext, SharedGuide};
use std::hint::black_box;
use std::sync::atomic::{AtomicBool, Ordering};

fn guide() -> SharedGuide<Glt<LightTree>> {
    let lights: Vec<Emitter> = (0..1000)
        .map(|i| {
            Emitter::point(
                Vec3::new((i % 10) as f32, (i / 10 % 10) as f32, (i / 100) as f32),
                1.0,
            )
        })
        .collect();
    let tree = LightTree::build(&lights, Default::default()).unwrap();
    let scene = Aabb::new(Vec3::splat(-1.0), Vec3::splat(11.0));
    let glt = Glt::new(tree, scene, GltConfig::default()).unwrap();
    // Never due during the run: what every path but a few pays.
    let schedule = RefineSchedule::Doubling { first: u64::MAX };
    SharedGuide::with_schedule(glt, schedule).unwrap()
}

fn per_path(guide: &SharedGuide<Glt<LightTree>>) {
    let g = guide.read();
    black_box(&*g);
    drop(g);
    black_box(guide.refine_when_due(1));
}

fn bench(c: &mut Criterion) {
    let guide = guide();
    let mut group = c.benchmark_group("shared_guide");
    group.bench_function("per_path/1_thread", |b| b.iter(|| per_path(&guide)));
    let stop = AtomicBool::new(false);
    std::thread::scope(|s| {
        s.spawn(|| {
            while !stop.load(Ordering::Relaxed) {
                per_path(&guide);
            }
        });
        group.bench_function("per_path/2_threads", |b| b.iter(|| per_path(&guide)));
        stop.store(true, Ordering::Relaxed);
    });
    let ctx = ShadingContext::at(Vec3::new(4.5, 4.5, 4.5));
    group.bench_function("vertex+sample", |b| {
        b.iter(|| {
            let g = guide.read();
            let v = g.vertex(black_box(&ctx)).unwrap();
            black_box(v.sample(black_box(0.37)))
        })
    });
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
