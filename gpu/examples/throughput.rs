//! Samples per second of the GLT's light choice on the CPU (the GLT
//! itself, and the snapshot's `f32` sampler) and on the GPU (the WGSL
//! kernel through wgpu, on whatever adapter it finds), over a million
//! queries on the city trained as the light-selection instrument trains it
//! (256 x 192, 128 spp); how the three agree; and what the snapshot
//! weighs.
//!
//! `cargo run --release -p guiding-gpu --example throughput`
//!
//! Times are medians of five runs on one thread (CPU) or of five
//! dispatches (GPU: submission to completion, without the upload and the
//! read-back). On lavapipe the "GPU" is the CPU running Vulkan in
//! software: that figure is a correctness run, not a speed claim.

#[path = "../tests/common/mod.rs"]
mod common;

use guiding::glam::Vec3;
use guiding::{LightChoice, ShadingContext};
use guiding_gpu::{Gpu, GpuSampler};
use std::time::{Duration, Instant};

/// The median of five timings of `f`.
fn median(mut f: impl FnMut()) -> Duration {
    let mut t: Vec<Duration> = (0..5)
        .map(|_| {
            let s = Instant::now();
            f();
            s.elapsed()
        })
        .collect();
    t.sort();
    t[2]
}

fn per_second(n: usize, t: Duration) -> String {
    format!(
        "{:.2} M/s ({:.0} ns each)",
        n as f64 / t.as_secs_f64() / 1e6,
        t.as_nanos() as f64 / n as f64
    )
}

fn main() {
    let scene = common::city();
    let t = Instant::now();
    let glt = common::trained(&scene, (256, 192), 128);
    println!("trained in {:.1} s", t.elapsed().as_secs_f64());
    let snapshot = glt.snapshot().expect("a snapshot");
    let queries = common::queries(&scene, 50_000, 20);
    let n = queries.len();

    let a = snapshot.arrays();
    let lights = a.leaf_position.len();
    let light_bytes = std::mem::size_of_val(a.tree)
        + std::mem::size_of_val(a.first_right)
        + std::mem::size_of_val(a.bounds)
        + std::mem::size_of_val(a.leaf_position);
    let cut_bytes = std::mem::size_of_val(a.cut_nodes);
    let cell_bytes = snapshot.bytes() - light_bytes - cut_bytes;
    println!(
        "city: {lights} lights, {} cells, {} cut nodes",
        a.cells.len(),
        a.cut_nodes.len()
    );
    println!(
        "snapshot: {:.2} MiB: {:.1} B per light (tree, bounds, leaf order), {} B per cut node, {:.1} KiB of cells, spatial tree, fractions, visibilities",
        snapshot.bytes() as f64 / (1 << 20) as f64,
        light_bytes as f64 / lights as f64,
        cut_bytes / a.cut_nodes.len().max(1),
        cell_bytes as f64 / 1024.0
    );
    println!(
        "the GLT in memory: {:.2} MiB",
        glt.memory().total() as f64 / (1 << 20) as f64
    );

    let cpu_glt = median(|| {
        let mut sum = 0.0f32;
        for q in &queries {
            let ctx = ShadingContext {
                normal: Some(Vec3::from_array(q.n)),
                ..ShadingContext::at(Vec3::from_array(q.p))
            };
            if let Some(s) = glt.vertex(&ctx).and_then(|v| v.sample(q.u)) {
                sum += s.pmf;
            }
        }
        std::hint::black_box(sum);
    });
    println!(
        "CPU, the GLT (f64 descent), one thread: {}",
        per_second(n, cpu_glt)
    );
    let view = snapshot.view();
    let cpu_snap = median(|| {
        let mut sum = 0.0f32;
        for q in &queries {
            let ctx = ShadingContext {
                normal: Some(Vec3::from_array(q.n)),
                ..ShadingContext::at(Vec3::from_array(q.p))
            };
            if let Some(s) = view.vertex(&ctx).and_then(|v| v.sample(q.u)) {
                sum += s.pmf;
            }
        }
        std::hint::black_box(sum);
    });
    println!(
        "CPU, the snapshot (f32), one thread: {}",
        per_second(n, cpu_snap)
    );

    let snap = common::cpu_answers(&snapshot, &queries);
    let cpu = common::glt_answers(&glt, &queries);
    println!("snapshot (CPU) vs GLT: {:?}", common::compare(&snap, &cpu));

    let Some(gpu) = Gpu::new() else {
        println!("GPU: no wgpu adapter (not even lavapipe); skipped");
        return;
    };
    let sampler = GpuSampler::new(&gpu, &snapshot);
    let (answers, t) = sampler.sample_timed(&queries, 5);
    println!(
        "GPU vs snapshot (CPU): {:?}",
        common::compare(&answers, &snap)
    );
    println!(
        "GPU, {} ({:?}, {:?}): {}; snapshot buffer {:.2} MiB",
        gpu.info.name,
        gpu.info.device_type,
        gpu.info.backend,
        per_second(n, t),
        sampler.bytes() as f64 / (1 << 20) as f64
    );
}
