//! What the C API adds to a light choice: `guiding_glt_sample` and
//! `guiding_glt_pmf` against the Rust front's `glt.vertex(&ctx)` then
//! `sample(u)` / `pmf(light)`, on one trained GLT (10,000 quads over a
//! street, four training iterations), the same 1,024 shading points and
//! random numbers per iteration of the benchmark. The C handle is loaded
//! from the Rust guide's bytes, so both choose identically (checked).
//!
//! ```text
//! cargo bench -p guiding-c --bench call_cost
//! ```

use criterion::{Criterion, criterion_group, criterion_main};
use guiding::glam::Vec3;
use guiding::{LightChoice, LightId, ShadingContext};
use guiding_c::*;
use std::hint::black_box;

#[path = "common/scene.rs"]
mod scene;
use scene::{Lcg, scene};

fn bench(c: &mut Criterion) {
    let (tree, glt) = scene();
    let mut r = Lcg(9);
    let points: Vec<(ShadingContext, GuidingShadingContext, f32)> = (0..1024)
        .map(|_| {
            let p = [200.0 * r.next(), 0.0, 200.0 * r.next()];
            let rust = ShadingContext::on_surface(Vec3::from(p), Vec3::Y);
            let c = GuidingShadingContext {
                position: p,
                normal: [0.0, 1.0, 0.0],
                light_sets: GUIDING_ALL_LIGHTS,
                unbounded_lights: GUIDING_ALL_LIGHTS,
            };
            (rust, c, r.next().min(0.999_999))
        })
        .collect();
    // The C handle: the same guide, through its bytes.
    let tree_bytes = tree.to_bytes();
    let glt_bytes = glt.to_bytes();
    let mut c_tree = std::ptr::null_mut();
    let mut c_glt = std::ptr::null_mut();
    // SAFETY: valid pointers and lengths; the handles are freed below.
    unsafe {
        assert_eq!(
            guiding_light_tree_load(tree_bytes.as_ptr(), tree_bytes.len(), &mut c_tree),
            GuidingStatus::Ok
        );
        assert_eq!(
            guiding_glt_load(c_tree, glt_bytes.as_ptr(), glt_bytes.len(), &mut c_glt),
            GuidingStatus::Ok
        );
    }
    // A renderer builds its context at each vertex: the Rust call does too.
    let rust_sample = |ctx: &ShadingContext, u: f32| {
        let ctx = ShadingContext::on_surface(ctx.position, Vec3::Y);
        glt.vertex(&ctx).and_then(|v| v.sample(u))
    };
    let c_sample = |ctx: &GuidingShadingContext, u: f32| {
        let mut out = GuidingLightSample { light: 0, pmf: 0.0 };
        // SAFETY: a live handle and valid pointers.
        let status = unsafe { guiding_glt_sample(c_glt, ctx, u, &mut out) };
        (status, out)
    };
    for (rust, c, u) in &points {
        let a = rust_sample(rust, *u).expect("a light");
        let (status, b) = c_sample(c, *u);
        assert!(status == GuidingStatus::Ok && a.light.index(10_000) == b.light && a.pmf == b.pmf);
    }
    let mut group = c.benchmark_group("call_cost/1024 samples");
    group.bench_function("rust vertex + sample", |b| {
        b.iter(|| {
            for (ctx, _, u) in &points {
                black_box(rust_sample(black_box(ctx), *u));
            }
        })
    });
    group.bench_function("c guiding_glt_sample", |b| {
        b.iter(|| {
            for (_, ctx, u) in &points {
                black_box(c_sample(black_box(ctx), *u));
            }
        })
    });
    group.bench_function("rust vertex + pmf", |b| {
        b.iter(|| {
            for (i, (ctx, _, _)) in points.iter().enumerate() {
                black_box(
                    glt.vertex(black_box(ctx))
                        .map(|v| v.pmf(LightId::Emitter(i as u32 * 7))),
                );
            }
        })
    });
    group.bench_function("c guiding_glt_pmf", |b| {
        b.iter(|| {
            for (i, (_, ctx, _)) in points.iter().enumerate() {
                let mut p = 0.0;
                // SAFETY: a live handle and valid pointers.
                black_box(unsafe { guiding_glt_pmf(c_glt, black_box(ctx), i as u32 * 7, &mut p) });
                black_box(p);
            }
        })
    });
    let (contexts, us): (Vec<GuidingShadingContext>, Vec<f32>) =
        points.iter().map(|(_, c, u)| (*c, *u)).unzip();
    let mut out = vec![GuidingLightSample { light: 0, pmf: 0.0 }; points.len()];
    group.bench_function("c guiding_glt_sample_batch", |b| {
        b.iter(|| {
            // SAFETY: a live handle; arrays of `points.len()` elements.
            let s = unsafe {
                guiding_glt_sample_batch(
                    c_glt,
                    black_box(contexts.as_ptr()),
                    us.as_ptr(),
                    us.len(),
                    out.as_mut_ptr(),
                )
            };
            black_box((s, &out));
        })
    });
    let lights: Vec<u32> = (0..points.len() as u32).map(|i| i * 7).collect();
    let mut pmfs = vec![0.0f32; points.len()];
    group.bench_function("c guiding_glt_pmf_batch", |b| {
        b.iter(|| {
            // SAFETY: as above.
            let s = unsafe {
                guiding_glt_pmf_batch(
                    c_glt,
                    black_box(contexts.as_ptr()),
                    lights.as_ptr(),
                    lights.len(),
                    pmfs.as_mut_ptr(),
                )
            };
            black_box((s, &pmfs));
        })
    });
    group.finish();
    // SAFETY: the handles from the loads above, freed once.
    unsafe {
        guiding_glt_free(c_glt);
        guiding_light_tree_free(c_tree);
    }
}

criterion_group!(benches, bench);
criterion_main!(benches);
