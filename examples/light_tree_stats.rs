//! Builds a light tree over a generated scene of 100k emitters (quads,
//! spheres, point and spot lights with powers over five decades), prints its
//! shape, memory and build time, then checks the tree-by-power sampler:
//! draws light samples, compares how often each power class is chosen with
//! the probability `pmf` assigns it (chi-square test), checks that `sample`
//! and `pmf` agree exactly and that the pmf sums to one.
//!
//! Exits with status 1 when a check fails.
//!
//! ```text
//! cargo run --release --example light_tree_stats
//! ```

use glam::Vec3;
use guiding::light_sampler::PowerTreeSampler;
use guiding::light_tree::BuildHeuristic;
use guiding::{LightHierarchy, LightId, LightSampler, LightTree, ShadingContext};
use std::process::ExitCode;
use std::time::Instant;

#[path = "../tests/common/mod.rs"]
mod common;
use common::{Rand, gamma_q, mixed_scene_from};

const EMITTERS: usize = 100_000;
const SAMPLES: usize = 2_000_000;
const SEED: u64 = 2023;
/// Power classes: half-decade bins over the generated range 1e-2..1e3.
const CLASSES: usize = 10;
/// The chi-square test fails below this p-value (a correct sampler fails
/// one run in a thousand; the seed is fixed, so a run is reproducible).
const MIN_P: f64 = 1e-3;

fn power_class(power: f32) -> usize {
    let x = (power.log10() + 2.0) * 2.0;
    (x.max(0.0) as usize).min(CLASSES - 1)
}

fn main() -> ExitCode {
    let mut rng = Rand::new(SEED);
    let scene = mixed_scene_from(EMITTERS, &mut rng);
    let heuristic = BuildHeuristic::default();

    let start = Instant::now();
    let tree = match LightTree::build(&scene, heuristic) {
        Ok(tree) => tree,
        Err(err) => {
            eprintln!("build failed: {err}");
            return ExitCode::FAILURE;
        }
    };
    let build_time = start.elapsed();

    let nodes = tree.node_count();
    let node_bytes = size_of::<guiding::light_tree::LightNode>();
    println!("light tree over {EMITTERS} emitters (heuristic {heuristic:?})");
    println!(
        "  build time        {:>10.1} ms",
        build_time.as_secs_f64() * 1e3
    );
    println!("  depth             {:>10}", tree.depth());
    println!("  nodes             {:>10}", nodes);
    println!("  bytes per node    {:>10}", node_bytes);
    println!(
        "  bytes per emitter {:>10.2}   (nodes + 4-byte leaf index)",
        tree.bytes() as f64 / EMITTERS as f64
    );
    println!(
        "  total             {:>10.2} MiB",
        tree.bytes() as f64 / (1u64 << 20) as f64
    );

    // The tree-by-power sampler: the probability of each emitter should be
    // its share of the total power, whatever the shading point.
    let sampler = PowerTreeSampler::new(&tree);
    let ctx = ShadingContext::on_surface(Vec3::new(1.0, -3.0, 2.0), Vec3::Y);
    let mut failures = Vec::new();

    let total_power: f64 = scene.iter().map(|e| e.power as f64).sum();
    let mut expected = [0.0f64; CLASSES];
    let mut ideal = [0.0f64; CLASSES];
    let mut members = [0usize; CLASSES];
    let mut pmf_sum = 0.0f64;
    let mut worst_rel = 0.0f64;
    for (i, e) in scene.iter().enumerate() {
        let p = sampler.pmf(&ctx, LightId::Emitter(i as u32)) as f64;
        let k = power_class(e.power);
        expected[k] += p;
        ideal[k] += e.power as f64 / total_power;
        members[k] += 1;
        pmf_sum += p;
        let share = e.power as f64 / total_power;
        worst_rel = worst_rel.max((p - share).abs() / share);
    }

    let start = Instant::now();
    let mut observed = [0u64; CLASSES];
    let mut mismatches = 0usize;
    let mut misses = 0usize;
    for _ in 0..SAMPLES {
        let u = rng.f();
        match sampler.sample(&ctx, u) {
            Some(s) => {
                let LightId::Emitter(i) = s.light else {
                    misses += 1;
                    continue;
                };
                if s.pmf != sampler.pmf(&ctx, s.light) {
                    mismatches += 1;
                }
                observed[power_class(scene[i as usize].power)] += 1;
            }
            None => misses += 1,
        }
    }
    let sample_time = start.elapsed();

    println!();
    println!(
        "tree-by-power sampler, {SAMPLES} samples ({:.0} ns per sample + pmf)",
        sample_time.as_secs_f64() * 1e9 / SAMPLES as f64
    );
    println!(
        "  {:<16} {:>8} {:>12} {:>12} {:>12} {:>8}",
        "power class", "emitters", "pmf() sum", "power share", "observed", "obs/exp"
    );
    let mut chi2 = 0.0;
    let mut dof = 0usize;
    for k in 0..CLASSES {
        let lo = 10f64.powf(k as f64 / 2.0 - 2.0);
        let hi = 10f64.powf((k + 1) as f64 / 2.0 - 2.0);
        let exp_count = expected[k] * SAMPLES as f64;
        let obs = observed[k] as f64;
        if exp_count > 0.0 {
            chi2 += (obs - exp_count).powi(2) / exp_count;
            dof += 1;
        } else if obs > 0.0 {
            chi2 = f64::INFINITY;
        }
        println!(
            "  {:<16} {:>8} {:>12.6} {:>12.6} {:>12.6} {:>8.4}",
            format!("{lo:.3}..{hi:.3}"),
            members[k],
            expected[k],
            ideal[k],
            obs / SAMPLES as f64,
            if exp_count > 0.0 {
                obs / exp_count
            } else {
                f64::NAN
            },
        );
    }
    let dof = dof.saturating_sub(1).max(1);
    let p_value = gamma_q(dof as f64 / 2.0, chi2 / 2.0);
    println!("  chi-square {chi2:.2} with {dof} degrees of freedom: p = {p_value:.4}");
    println!("  sum of pmf over all emitters: {pmf_sum:.9}");
    println!("  largest |pmf - power share| / share: {worst_rel:.2e}");
    println!("  sample pmf != pmf(): {mismatches} of {SAMPLES}; no light chosen: {misses}");

    if p_value.is_nan() || p_value < MIN_P {
        failures.push(format!("chi-square p = {p_value:.2e} < {MIN_P}"));
    }
    let pmf_error = (pmf_sum - 1.0).abs();
    if pmf_error.is_nan() || pmf_error > 1e-5 {
        failures.push(format!("pmf sums to {pmf_sum}"));
    }
    if worst_rel.is_nan() || worst_rel > 1e-4 {
        failures.push(format!("pmf deviates from power share by {worst_rel:.2e}"));
    }
    if mismatches > 0 {
        failures.push(format!("{mismatches} sampled pmfs differ from pmf()"));
    }
    if misses > 0 {
        failures.push(format!("{misses} samples chose no emitter"));
    }
    println!();
    if failures.is_empty() {
        println!("check passed");
        ExitCode::SUCCESS
    } else {
        for f in &failures {
            println!("check FAILED: {f}");
        }
        ExitCode::FAILURE
    }
}
