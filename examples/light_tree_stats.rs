//! Builds a light tree over a generated scene of 100k emitters (quads,
//! spheres, point and spot lights with powers over five decades), prints its
//! shape, memory and build time, then checks the tree-by-energy sampler:
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
use guiding::light_sampler::EnergyTreeSampler;
use guiding::light_tree::BuildHeuristic;
use guiding::math::{Aabb, LightCone};
use guiding::{Emitter, LightHierarchy, LightId, LightSampler, LightTree, ShadingContext};
use rand_pcg::Pcg64Mcg;
use rand_pcg::rand_core::{Rng, SeedableRng};
use std::process::ExitCode;
use std::time::Instant;

const EMITTERS: usize = 100_000;
const SAMPLES: usize = 2_000_000;
const SEED: u64 = 2023;
/// Power classes: half-decade bins over the generated range 1e-2..1e3.
const CLASSES: usize = 10;
/// The chi-square test fails below this p-value (a correct sampler fails
/// one run in a thousand; the seed is fixed, so a run is reproducible).
const MIN_P: f64 = 1e-3;

struct Rand(Pcg64Mcg);

impl Rand {
    /// Uniform in [0, 1) with 24 random bits: every value an f32 can hold.
    fn f(&mut self) -> f32 {
        (self.0.next_u32() >> 8) as f32 * (1.0 / (1u32 << 24) as f32)
    }
    fn range(&mut self, lo: f32, hi: f32) -> f32 {
        lo + (hi - lo) * self.f()
    }
    fn dir(&mut self) -> Vec3 {
        loop {
            let v = Vec3::new(
                self.range(-1.0, 1.0),
                self.range(-1.0, 1.0),
                self.range(-1.0, 1.0),
            );
            if let Some(d) = v.try_normalize() {
                return d;
            }
        }
    }
}

/// A quad of half-size `s` centred at `c` facing `n`.
fn quad(c: Vec3, n: Vec3, s: f32, power: f32) -> Emitter {
    let (t, b) = n.any_orthonormal_pair();
    let mut bounds = Aabb::EMPTY;
    for (u, v) in [(-1.0, -1.0), (-1.0, 1.0), (1.0, -1.0), (1.0, 1.0)] {
        bounds = bounds.extend(c + (t * u + b * v) * s);
    }
    Emitter::area(bounds, n, 4.0 * s * s, power)
}

/// 40% quads (half facing down, a tenth of them two-sided), 30% spheres,
/// 20% point and 10% spot lights in a 100^3 box; power log-uniform over
/// 1e-2..1e3.
fn mixed_scene(n: usize, r: &mut Rand) -> Vec<Emitter> {
    (0..n)
        .map(|_| {
            let c = Vec3::new(
                r.range(-50.0, 50.0),
                r.range(-50.0, 50.0),
                r.range(-50.0, 50.0),
            );
            let power = 10f32.powf(r.range(-2.0, 3.0));
            let kind = r.f();
            if kind < 0.4 {
                let normal = if r.f() < 0.5 { -Vec3::Y } else { r.dir() };
                let mut e = quad(c, normal, r.range(0.05, 2.0), power);
                e.two_sided = r.f() < 0.1;
                e
            } else if kind < 0.7 {
                Emitter::sphere(c, r.range(0.05, 1.0), power)
            } else if kind < 0.9 {
                Emitter::point(c, power)
            } else {
                let mut e = Emitter::point(c, power);
                e.cone = Some(LightCone::spot(r.dir(), r.range(0.1, 1.2)));
                e
            }
        })
        .collect()
}

fn power_class(power: f32) -> usize {
    let x = (power.log10() + 2.0) * 2.0;
    (x.max(0.0) as usize).min(CLASSES - 1)
}

/// ln Gamma(x) for x > 0 (Lanczos, g = 7, 9 terms; ~1e-15 relative).
fn ln_gamma(x: f64) -> f64 {
    const G: [f64; 9] = [
        0.999_999_999_999_809_9,
        676.520_368_121_885_1,
        -1_259.139_216_722_402_8,
        771.323_428_777_653_1,
        -176.615_029_162_140_6,
        12.507_343_278_686_905,
        -0.138_571_095_265_720_12,
        9.984_369_578_019_572e-6,
        1.505_632_735_149_311_6e-7,
    ];
    if x < 0.5 {
        // Reflection.
        let pi = std::f64::consts::PI;
        return (pi / (pi * x).sin()).ln() - ln_gamma(1.0 - x);
    }
    let x = x - 1.0;
    let mut a = G[0];
    let t = x + 7.5;
    for (i, g) in G.iter().enumerate().skip(1) {
        a += g / (x + i as f64);
    }
    0.5 * (2.0 * std::f64::consts::PI).ln() + (x + 0.5) * t.ln() - t + a.ln()
}

/// The regularised upper incomplete gamma function Q(a, x).
fn gamma_q(a: f64, x: f64) -> f64 {
    if x <= 0.0 {
        return 1.0;
    }
    let front = (-x + a * x.ln() - ln_gamma(a)).exp();
    if x < a + 1.0 {
        // Series for P(a, x).
        let (mut sum, mut term, mut n) = (1.0 / a, 1.0 / a, a);
        for _ in 0..10_000 {
            n += 1.0;
            term *= x / n;
            sum += term;
            if term.abs() < sum.abs() * 1e-16 {
                break;
            }
        }
        1.0 - sum * front
    } else {
        // Continued fraction for Q(a, x) (modified Lentz).
        let tiny = 1e-300;
        let mut b = x + 1.0 - a;
        let mut c = 1.0 / tiny;
        let mut d = 1.0 / b;
        let mut h = d;
        for i in 1..10_000 {
            let an = -(i as f64) * (i as f64 - a);
            b += 2.0;
            d = an * d + b;
            if d.abs() < tiny {
                d = tiny;
            }
            c = b + an / c;
            if c.abs() < tiny {
                c = tiny;
            }
            d = 1.0 / d;
            let delta = d * c;
            h *= delta;
            if (delta - 1.0).abs() < 1e-16 {
                break;
            }
        }
        front * h
    }
}

fn main() -> ExitCode {
    let mut rng = Rand(Pcg64Mcg::seed_from_u64(SEED));
    let scene = mixed_scene(EMITTERS, &mut rng);
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

    // The tree-by-energy sampler: the probability of each emitter should be
    // its share of the total power, whatever the shading point.
    let sampler = EnergyTreeSampler::new(&tree);
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
        "tree-by-energy sampler, {SAMPLES} samples ({:.0} ns per sample + pmf)",
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
