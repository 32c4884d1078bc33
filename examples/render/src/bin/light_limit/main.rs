//! `light_limit`: how far a light sampler is from the best light choice
//! physically possible, measured exactly, without timing noise.
//!
//! At shading points of the render example's scenes (first non-specular
//! hits of camera rays, or the k-th vertex) it computes every light's
//! contribution by brute force with real shadow rays, then the exact
//! per-sample variance of the render example's direct-light estimator (one
//! NEE sample + one BSDF sample, power-heuristic MIS; `variance.rs`) under
//! each light-selection pmf: uniform, power, the light BVH's importance,
//! the Guiding Light Tree as the render example trains it for `pt-glt`
//! (crate defaults, and any variants given with `--glt`), and the
//! clairvoyant pmf (proportional to the square root of each light's second
//! moment, from held-out samples that do not evaluate it).
//!
//! ```text
//! cargo run --release --bin light_limit -- --scene city,ring,torus --points 300 --json out/light_limit.json
//! cargo run --release --bin light_limit -- --scene city --glt "sigma=0.002" --glt "alpha=0.1 below=importance"
//! cargo run --release --bin light_limit -- --scene city --breakdown
//! ```
//!
//! `--breakdown` prints, per GLT variant, where its variance comes from:
//! the share of the worst points, and the share of the next-event second
//! moment on lights whose pmf is 2, 10 or 100 times below the clairvoyant
//! one (and how much of that sits at the defensive prior's floor).
//!
//! The scene, geometry and training code are the render example's own
//! files (`#[path]`), so the GLT measured is exactly the one `pt-glt`
//! renders with.

mod breakdown;
mod brute_force;
mod per_point_m;

mod variance;
use guiding_render::{geometry, methods, rng, run, scene, scenes, shading_points};

use brute_force::PointTerms;
use clap::Parser;
use guiding::{LightChoice, LightId, LightSampler, ShadingContext};
use guiding_render::glt_variant::GltVariant;
use methods::Method;
use rayon::prelude::*;
use std::fmt::Write as _;
use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Instant;

/// The variance at a point from its terms, its pmfs and its lights'
/// visibility factors.
type PointVariance<'a> = dyn Fn(&PointTerms, &[f64], &[f64]) -> f64 + Sync + 'a;

/// A resampling target's visibility factor.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Target {
    /// None (visibility-blind).
    Blind,
    /// The GLT's learned visibility to this exponent.
    Learned(f64),
    /// The held-out visibility at the point.
    Oracle,
}

/// Measures the exact per-sample variance of light selection against the
/// clairvoyant pmf at shading points of the render example's scenes.
#[derive(Parser, Debug)]
#[command(name = "light_limit", version)]
struct Args {
    /// Scenes, comma separated (the render example's names).
    #[arg(long, value_delimiter = ',', default_value = "city,ring,torus")]
    scene: Vec<String>,
    /// Shading points per scene.
    #[arg(long, default_value_t = 300)]
    points: usize,
    /// Which non-specular vertex of a camera path to measure at (1 = first
    /// hit).
    #[arg(long, default_value_t = 1)]
    vertex: u32,
    /// Light samples per light in the evaluation set (the domain of the
    /// variances, the same for every pmf).
    #[arg(long, default_value_t = 4)]
    light_samples: usize,
    /// Stratified light samples per light in the held-out set the
    /// clairvoyant pmf is computed from (on city it converges from about
    /// 16; 4 under-reads its variance ratio by ~2x).
    #[arg(long, default_value_t = 16)]
    held_out_samples: usize,
    /// Also report every pmf's variance with the BSDF part estimated from
    /// the BSDF samples themselves (the instrument before the light-domain
    /// integration), to show the difference.
    #[arg(long)]
    bsdf_sampled: bool,
    /// Candidate counts for resampled next-event estimation from each GLT
    /// variant's pmf (comma separated; `variance::resampled_parts`), each
    /// measured with a visibility-blind target and with the held-out
    /// visibility at the point (the best a learned visibility could do).
    #[arg(long, value_delimiter = ',')]
    resample: Vec<usize>,
    /// Exponents of the learned visibility in the resampling target
    /// (comma separated; the crate's `resample` takes 0.5: for a light
    /// seen with probability `v`, `sqrt(v)` minimizes the variance of many
    /// candidates).
    #[arg(long, value_delimiter = ',', default_value = "0.5,1")]
    visibility_exponent: Vec<f64>,
    /// BSDF samples per point.
    #[arg(long, default_value_t = 64)]
    bsdf_samples: usize,
    /// GLT variants besides the defaults: space-separated `key=value`
    /// settings (sigma, alpha, below=power|importance,
    /// modulation=none|importance, prior=power|importance,
    /// bound=children|grandchildren, record=radiance|contribution,
    /// filter=nearest|jitter, rules=paper, min-records, threshold,
    /// train-spp); repeat the flag for several.
    #[arg(long)]
    glt: Vec<String>,
    /// Samples per pixel the GLT trains with (the render example's
    /// schedule; the GLT measured is what its last iteration samples).
    #[arg(long, default_value_t = 128)]
    train_spp: u64,
    /// Image size the GLT trains at and the points are picked from.
    #[arg(long, default_value_t = 256)]
    width: u32,
    /// Image height.
    #[arg(long, default_value_t = 192)]
    height: u32,
    /// Seed of the points, the brute-force samples and the training.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Worker threads [default: all cores].
    #[arg(long)]
    threads: Option<usize>,
    /// Smaller scenes, as the tests use.
    #[arg(long)]
    small: bool,
    /// Write the records as a JSON array here.
    #[arg(long)]
    json: Option<PathBuf>,
    /// Also print, per GLT variant, the bound of choosing the candidate
    /// count per point (`per_point_m.rs`): plain sampling and each
    /// `--resample` count with the BSDF candidate and the first learned
    /// target (blind without learned visibility), at the costs below.
    #[arg(long)]
    per_point_m: bool,
    /// Instructions per path of plain GLT sampling, for `--per-point-m`
    /// (callgrind, `pt-glt` on city: docs/experiments/light-selection.md).
    #[arg(long, default_value_t = 29_429.0)]
    path_cost: f64,
    /// Resampling's instructions per path besides its candidates, for
    /// `--per-point-m` (city: 37,345 / 50,357 / 75,339 at M = 2 / 4 / 8
    /// fit `path + 1,600 + (M - 1) 6,300`).
    #[arg(long, default_value_t = 1_600.0)]
    resample_overhead: f64,
    /// Instructions per resampling candidate after the first, for
    /// `--per-point-m`.
    #[arg(long, default_value_t = 6_300.0)]
    candidate_cost: f64,
    /// Also print, per GLT variant, where its variance comes from (worst
    /// points; lights by how far their pmf is below the clairvoyant's).
    #[arg(long)]
    breakdown: bool,
}

/// One measured method on one scene.
struct Record {
    scene: String,
    method: String,
    rel_variance: f64,
    points: usize,
    glt_bytes: usize,
    train_spp: u64,
}

fn main() -> ExitCode {
    let args = Args::parse();
    match run(&args) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}

fn run(args: &Args) -> Result<(), String> {
    if let Some(n) = args.threads {
        rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build_global()
            .map_err(|e| e.to_string())?;
    }
    let mut variants = vec![GltVariant::defaults(args.train_spp)];
    for spec in &args.glt {
        variants.push(GltVariant::parse(spec, args.train_spp)?);
    }
    let mut all = Vec::new();
    for name in &args.scene {
        let records = measure_scene(args, name, &variants)?;
        print!("{}", table(&records));
        all.extend(records);
    }
    if let Some(path) = &args.json {
        std::fs::write(path, to_json(&all)).map_err(|e| format!("{}: {e}", path.display()))?;
        println!("wrote {}", path.display());
    }
    Ok(())
}

/// The variance at every point under `pmf`: with the BSDF part integrated
/// in the light-sample domain, and with it estimated from the BSDF samples
/// (the instrument before).
fn pmfs_of(
    points: &[PointTerms],
    pmf: impl Fn(&ShadingContext, LightId) -> f64 + Sync,
) -> (Vec<f64>, Vec<f64>) {
    points
        .par_iter()
        .map(|t| {
            let ctx = ShadingContext::on_surface(t.at.p, t.at.n);
            let pmfs: Vec<f64> = t.lights.iter().map(|l| pmf(&ctx, l.light)).collect();
            (
                variance::variance(t, &pmfs),
                variance::variance_bsdf_sampled(t, &pmfs),
            )
        })
        .unzip()
}

fn measure_scene(args: &Args, name: &str, variants: &[GltVariant]) -> Result<Vec<Record>, String> {
    let size = if args.small {
        scenes::Size::Small
    } else {
        scenes::Size::Full
    };
    let scene = scenes::build(name, size).ok_or_else(|| format!("unknown scene {name:?}"))?;
    let t = Instant::now();
    let at = shading_points::pick(
        &scene,
        args.points,
        args.vertex,
        (args.width, args.height),
        args.seed,
    );
    let points: Vec<PointTerms> = at
        .par_iter()
        .enumerate()
        .map(|(i, &p)| {
            brute_force::measure(
                &scene,
                p,
                (args.light_samples, args.held_out_samples),
                args.bsdf_samples,
                rng::mix64(args.seed ^ i as u64),
            )
        })
        .collect();
    let contributing: usize = points.iter().map(|t| t.lights.len()).sum();
    println!(
        "scene {name}: {} emitters, {} points, {:.0} contributing lights per point on average; brute force {:.1} s",
        scene.lights.len(),
        points.len(),
        contributing as f64 / points.len().max(1) as f64,
        t.elapsed().as_secs_f64()
    );
    let record = |method: &str, variances: &[f64], glt_bytes: usize, train_spp: u64| Record {
        scene: name.to_string(),
        method: method.to_string(),
        rel_variance: variance::relative(&points, variances),
        points: points.len(),
        glt_bytes,
        train_spp,
    };
    let mut records = Vec::new();
    for (label, method) in [
        ("uniform", Method::PtUniform),
        ("power", Method::PtPower),
        ("bvh", Method::PtBvh),
    ] {
        let sampler = methods::fixed_sampler(&scene, method).ok_or("a fixed sampler")?;
        let (v, vb) = pmfs_of(&points, |ctx, l| f64::from(sampler.pmf(ctx, l)));
        records.push(record(label, &v, 0, 0));
        if args.bsdf_sampled {
            records.push(record(&format!("{label} [bsdf-sampled]"), &vb, 0, 0));
        }
    }
    for variant in variants {
        let t = Instant::now();
        let settings = run::Settings {
            width: args.width,
            height: args.height,
            budget: run::Budget::Spp(variant.train_spp),
            params: variant.params,
            seed: args.seed,
            progress: false,
            guide_files: Default::default(),
        };
        let (_, trained) = run::render_trained(&scene, Method::PtGlt, &settings);
        let glt = trained.glt.ok_or("pt-glt trains a GLT")?;
        let (v, vb) = pmfs_of(&points, |ctx, l| f64::from(pmf_at(&glt, ctx, l)));
        if args.breakdown {
            let pmf_vectors =
                |f: &(dyn Fn(&ShadingContext, LightId) -> f64 + Sync)| -> Vec<Vec<f64>> {
                    points
                        .par_iter()
                        .map(|t| {
                            let ctx = ShadingContext::on_surface(t.at.p, t.at.n);
                            t.lights.iter().map(|l| f(&ctx, l.light)).collect()
                        })
                        .collect()
                };
            let pmfs = pmf_vectors(&|ctx, l| f64::from(pmf_at(&glt, ctx, l)));
            let bvh = methods::fixed_sampler(&scene, Method::PtBvh).ok_or("bvh")?;
            let prior = pmf_vectors(&|ctx, l| f64::from(bvh.pmf(ctx, l)));
            let clair: Vec<f64> = points
                .par_iter()
                .map(|t| variance::variance(t, &variance::clairvoyant(t)))
                .collect();
            print!(
                "{}",
                breakdown::report(&points, &v, &clair, &pmfs, &prior, variant.params.alpha)
            );
        }
        records.push(record(
            &variant.name,
            &v,
            glt.memory().total(),
            variant.train_spp,
        ));
        if args.bsdf_sampled {
            let name = format!("{} [bsdf-sampled]", variant.name);
            records.push(record(&name, &vb, 0, variant.train_spp));
        }
        // The shading context of a point and the trained GLT's pmf of each
        // of its lights.
        let glt_pmfs = |t: &PointTerms| {
            let ctx = ShadingContext::on_surface(t.at.p, t.at.n);
            let pmfs: Vec<f64> = t
                .lights
                .iter()
                .map(|l| f64::from(pmf_at(&glt, &ctx, l.light)))
                .collect();
            (ctx, pmfs)
        };
        // Each light's visibility factor in a target (below).
        let visibility_of = |t: &PointTerms, ctx: &ShadingContext, target: Target| -> Vec<f64> {
            match target {
                Target::Learned(e) => t
                    .lights
                    .iter()
                    .map(|l| {
                        let v = glt.vertex(ctx).map_or(1.0, |v| v.visibility(l.light));
                        f64::from(v).powf(e)
                    })
                    .collect(),
                k => variance::visibilities(t, k == Target::Oracle, 0.05),
            }
        };
        // Targets: blind, the GLT's learned visibility to each exponent
        // (when it learns one; `resample` takes the square root), the
        // visibility at the point (the best a learned one could do).
        let mut targets = vec![("unshadowed".to_string(), Target::Blind)];
        if variant.params.visibility {
            for &e in &args.visibility_exponent {
                let name = if e == 1.0 {
                    "x learned visibility".to_string()
                } else {
                    format!("x learned visibility^{e}")
                };
                targets.push((name, Target::Learned(e)));
            }
        }
        targets.push(("x visibility".to_string(), Target::Oracle));
        // Proxies of the MIS weights: the candidate density, and the
        // resampled density's approximation with the exact integral of the
        // target at the point (the bound of any proxy of that form; not for
        // the blind target).
        // `variance(point, pmfs, visibilities)` at every point, the
        // visibilities those of `target`.
        let per_point = |target: Target, variance: &PointVariance<'_>| -> Vec<f64> {
            points
                .par_iter()
                .map(|t| {
                    let (ctx, pmfs) = glt_pmfs(t);
                    variance(t, &pmfs, &visibility_of(t, &ctx, target))
                })
                .collect()
        };
        let proxies = [
            (variance::Proxy::Candidate, ""),
            (
                variance::Proxy::Resampled(None),
                ", MIS by the resampled density",
            ),
        ];
        // The per-point bound's choices: plain sampling, then each count
        // with the BSDF candidate and the first learned target.
        let chosen_target = targets
            .iter()
            .map(|t| t.1)
            .find(|t| matches!(t, Target::Learned(_)))
            .unwrap_or(Target::Blind);
        let mut choices = vec![per_point_m::Choice {
            name: variant.name.clone(),
            candidates: 0,
            shares: variance::shares(&points, &v),
        }];
        for &m in &args.resample {
            for &(proxy, proxy_name) in &proxies {
                for (target, kind) in &targets {
                    let kind = *kind;
                    if kind == Target::Blind && proxy != variance::Proxy::Candidate {
                        continue;
                    }
                    let v = per_point(kind, &|t, pmfs, vis| {
                        let (nee, bsdf) = variance::resampled_parts_with(t, pmfs, vis, m, proxy);
                        nee + bsdf
                    });
                    let name = format!("{} resampled M={m} ({target}{proxy_name})", variant.name);
                    records.push(record(&name, &v, 0, variant.train_spp));
                }
            }
            // The BSDF sample resampled with the light candidates: one
            // sample, no MIS weights.
            for seen in [false, true] {
                for (target, kind) in &targets {
                    let kind = *kind;
                    if seen && kind == Target::Blind {
                        continue;
                    }
                    let v = per_point(kind, &|t, pmfs, vis| {
                        variance::bsdf_candidate_variance(t, pmfs, vis, m, seen)
                    });
                    let name = format!(
                        "{} resampled M={m} + BSDF candidate ({target}{})",
                        variant.name,
                        if seen { ", the BSDF's seen" } else { "" }
                    );
                    if !seen && kind == chosen_target {
                        choices.push(per_point_m::Choice {
                            name: name.clone(),
                            candidates: m,
                            shares: variance::shares(&points, &v),
                        });
                    }
                    records.push(record(&name, &v, 0, variant.train_spp));
                }
            }
        }
        if args.per_point_m && choices.len() > 1 {
            println!(
                "  {}: candidates chosen per point (the bound):",
                variant.name
            );
            print!(
                "{}",
                per_point_m::report(
                    &choices,
                    per_point_m::Costs {
                        path: args.path_cost,
                        overhead: args.resample_overhead,
                        candidate: args.candidate_cost,
                    }
                )
            );
        }
        // How much of the variance is the BSDF sample's (which a better
        // light choice alone cannot remove), in the relMSE normalisation.
        let bsdf_only: Vec<f64> = points
            .par_iter()
            .map(|t| variance::parts(t, &glt_pmfs(t).1).1)
            .collect();
        println!(
            "  {}: trained {} spp in {:.1} s; the BSDF sample's part of its variance: {:.1}%",
            variant.name,
            variant.train_spp,
            t.elapsed().as_secs_f64(),
            100.0 * variance::relative(&points, &bsdf_only) / variance::relative(&points, &v)
        );
    }
    let (v, vb): (Vec<f64>, Vec<f64>) = points
        .par_iter()
        .map(|t| {
            let c = variance::clairvoyant(t);
            (
                variance::variance(t, &c),
                variance::variance_bsdf_sampled(t, &c),
            )
        })
        .unzip();
    records.push(record("clairvoyant", &v, 0, 0));
    if args.bsdf_sampled {
        records.push(record("clairvoyant [bsdf-sampled]", &vb, 0, 0));
    }
    Ok(records)
}

/// The printed table of one scene.
fn table(records: &[Record]) -> String {
    let clair_of = |method: &str| {
        let name = if method.ends_with("[bsdf-sampled]") {
            "clairvoyant [bsdf-sampled]"
        } else {
            "clairvoyant"
        };
        records
            .iter()
            .find(|r| r.method == name)
            .map_or(f64::NAN, |r| r.rel_variance)
    };
    let mut s = String::new();
    let _ = writeln!(
        s,
        "| scene | method | rel. variance | / clairvoyant | GLT MB |"
    );
    let _ = writeln!(s, "|---|---|---:|---:|---:|");
    for r in records {
        let _ = writeln!(
            s,
            "| {} | {} | {:.4} | {:.1}x | {:.2} |",
            r.scene,
            r.method,
            r.rel_variance,
            r.rel_variance / clair_of(&r.method),
            r.glt_bytes as f64 / 1e6
        );
    }
    s
}

/// The records as a JSON array.
fn to_json(records: &[Record]) -> String {
    let num = |x: f64| {
        if x.is_finite() {
            format!("{x}")
        } else {
            "null".into()
        }
    };
    let items: Vec<String> = records
        .iter()
        .map(|r| {
            format!(
                "  {{\"scene\": \"{}\", \"method\": \"{}\", \"rel_variance\": {}, \"points\": {}, \"glt_bytes\": {}, \"train_spp\": {}}}",
                r.scene,
                r.method.replace('"', "'"),
                num(r.rel_variance),
                r.points,
                r.glt_bytes,
                r.train_spp
            )
        })
        .collect();
    format!("[\n{}\n]\n", items.join(",\n"))
}

/// The GLT's pmf of `light` at `ctx`, through the vertex there (0 where
/// there is none).
fn pmf_at(
    glt: &guiding::glt::Glt<&guiding::LightTree>,
    ctx: &ShadingContext,
    light: LightId,
) -> f32 {
    glt.vertex(ctx).map_or(0.0, |v| v.pmf(light))
}
