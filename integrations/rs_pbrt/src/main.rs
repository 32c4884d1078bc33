//! Renders the committed scenes with every light strategy rs_pbrt has and
//! with the Guiding Light Tree, at equal samples and at equal time, against
//! a long reference, and prints the table docs/results.md shows.
//!
//! ```sh
//! cargo run --release                      # every scene, every strategy
//! cargo run --release -- --scene two_rooms --spp 16
//! cargo run --release -- --check           # CI: a tiny scene in seconds
//! cargo run --release -- --scene two_rooms --tiles never,waves,auto --seeds 3
//! ```
//!
//! `--tiles` renders the GLT in tile order instead (src/tiles.rs: threads
//! take tiles from a queue, a `SharedGuide` guard per path) with each
//! learning rule, and prints relMSE against the reference.

mod glue;
mod path_tracer;
mod scene_file;
mod tiles;

use guiding::glam::Vec3;
use guiding::luminance;
use path_tracer::{Image, LightStrategy, RsPbrtStrategy, render_pass};
use scene_file::Loaded;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// rs_pbrt's light strategies (pbrt-v3's `lightsamplestrategy`), then ours.
const STRATEGIES: [&str; 4] = ["uniform", "power", "spatial", "glt"];

struct Options {
    scenes: Vec<String>,
    strategies: Vec<String>,
    spp: Option<u32>,
    reference_spp: u32,
    reference_strategy: String,
    seconds: Option<f64>,
    max_seconds: f64,
    check: bool,
    out: PathBuf,
    /// Learning rules to compare in tile order (`--tiles`), if any.
    tiles: Vec<String>,
    seeds: u64,
}

fn options() -> Result<Options, String> {
    let here = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut o = Options {
        scenes: ["two_rooms", "sun_sky", "city"].map(String::from).to_vec(),
        strategies: STRATEGIES.map(String::from).to_vec(),
        spp: None,
        reference_spp: 1024,
        reference_strategy: "glt".into(),
        seconds: None,
        max_seconds: 600.0,
        check: false,
        out: here.join("out"),
        tiles: Vec::new(),
        seeds: 1,
    };
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        let mut value = || args.next().ok_or(format!("{a} needs a value"));
        match a.as_str() {
            "--scene" => o.scenes = value()?.split(',').map(String::from).collect(),
            "--strategy" => o.strategies = value()?.split(',').map(String::from).collect(),
            "--spp" => o.spp = Some(value()?.parse().map_err(|e| format!("--spp: {e}"))?),
            "--reference-spp" => {
                o.reference_spp = value()?
                    .parse()
                    .map_err(|e| format!("--reference-spp: {e}"))?
            }
            "--reference-strategy" => o.reference_strategy = value()?,
            "--seconds" => {
                o.seconds = Some(value()?.parse().map_err(|e| format!("--seconds: {e}"))?)
            }
            "--max-seconds" => {
                o.max_seconds = value()?
                    .parse()
                    .map_err(|e| format!("--max-seconds: {e}"))?
            }
            "--out" => o.out = value()?.into(),
            "--tiles" => {
                o.tiles = match value()?.as_str() {
                    "all" => tiles::LEARNING.map(String::from).to_vec(),
                    v => v.split(',').map(String::from).collect(),
                }
            }
            "--seeds" => o.seeds = value()?.parse().map_err(|e| format!("--seeds: {e}"))?,
            "--check" => o.check = true,
            _ => return Err(format!("unknown argument {a}")),
        }
    }
    Ok(o)
}

/// A render: the image, the seconds it took (the strategy's
/// preprocessing included) and its samples per pixel; `None` when not even
/// the samples asked for fitted in `--max-seconds`.
struct Run {
    pixels: Option<Vec<Vec3>>,
    seconds: f64,
    spp: u32,
}

/// How long a render may run and how many samples it takes.
#[derive(Clone, Copy)]
enum Budget {
    /// These samples per pixel, within `max` seconds.
    Samples { spp: u32, max: f64 },
    /// As many samples as fit in these seconds.
    Seconds(f64),
}

/// Renders with strategy `name` in passes of 1, 1, 2, 4, ... samples per
/// pixel (the GLT refines after each; under a time budget each pass is cut
/// to what the time left holds, at the rate measured so far); `seed`
/// chooses the random numbers.
fn render(loaded: &Loaded, name: &str, budget: Budget, seed: u64) -> Result<Run, String> {
    let start = Instant::now();
    match name {
        "glt" => passes(
            loaded,
            glue::GltStrategy::new(&loaded.scene).map_err(|e| e.to_string())?,
            budget,
            start,
            seed,
        ),
        _ if STRATEGIES.contains(&name) => passes(
            loaded,
            RsPbrtStrategy::new(name, loaded),
            budget,
            start,
            seed,
        ),
        _ => Err(format!("unknown strategy {name}")),
    }
}

fn passes(
    loaded: &Loaded,
    mut strategy: impl LightStrategy,
    budget: Budget,
    start: Instant,
    seed: u64,
) -> Result<Run, String> {
    let mut image = Image::new(loaded.resolution);
    let mut pass = seed << 32;
    let seconds = |s: f64| start + std::time::Duration::from_secs_f64(s.min(1e9));
    let (deadline, spp) = match budget {
        Budget::Samples { spp, max } => (seconds(max), spp),
        Budget::Seconds(s) => (seconds(s), u32::MAX),
    };
    let mut rendering = 0.0; // seconds spent in passes
    while image.spp < spp {
        let mut n = image.spp.max(1).min(spp - image.spp);
        if let Budget::Seconds(s) = budget {
            let left = s - start.elapsed().as_secs_f64();
            if left <= 0.0 {
                break;
            }
            if image.spp > 0 {
                n = n.min(((left / (rendering / image.spp as f64)) as u32).max(1));
            }
        }
        // Under a time budget a pass sized to fit may still end a little
        // late (the machine is shared); only the first, which no rate
        // sizes, must end within the budget.
        let deadline = match budget {
            Budget::Seconds(s) if image.spp > 0 => seconds(1.5 * s),
            _ => deadline,
        };
        let t = Instant::now();
        if !render_pass(loaded, &strategy, &mut image, n, pass, deadline) {
            break;
        }
        rendering += t.elapsed().as_secs_f64();
        strategy.refine();
        pass += 1;
    }
    let done = image.spp > 0 && (matches!(budget, Budget::Seconds(_)) || image.spp >= spp);
    Ok(Run {
        pixels: done.then(|| image.pixels()),
        seconds: start.elapsed().as_secs_f64(),
        spp: image.spp,
    })
}

/// Relative MSE against the reference, as the render example measures it
/// (docs/results.md): the mean over pixels and channels of
/// `(x - r)^2 / (r^2 + 0.01 mean(r)^2)`.
fn rel_mse(pixels: &[Vec3], reference: &[Vec3]) -> f64 {
    let n = 3.0 * pixels.len() as f64;
    let m: f64 = reference
        .iter()
        .flat_map(|r| r.to_array())
        .map(f64::from)
        .sum::<f64>()
        / n;
    let sum: f64 = pixels
        .iter()
        .zip(reference)
        .flat_map(|(p, r)| p.to_array().into_iter().zip(r.to_array()))
        .map(|(x, r)| {
            let (x, r) = (f64::from(x), f64::from(r));
            (x - r) * (x - r) / (r * r + 0.01 * m * m)
        })
        .sum();
    sum / n
}

/// Writes `pixels` as an sRGB PNG (clamped at 1) for a look.
fn save_png(pixels: &[Vec3], (w, h): (usize, usize), path: &Path) -> Result<(), String> {
    let srgb = |c: f32| {
        let c = c.clamp(0.0, 1.0);
        let v = if c <= 0.003_130_8 {
            12.92 * c
        } else {
            1.055 * c.powf(1.0 / 2.4) - 0.055
        };
        (v * 255.0 + 0.5) as u8
    };
    let bytes: Vec<u8> = pixels.iter().flat_map(|p| p.to_array().map(srgb)).collect();
    image::save_buffer(path, &bytes, w as u32, h as u32, image::ColorType::Rgb8)
        .map_err(|e| e.to_string())
}

fn mean(pixels: &[Vec3]) -> f64 {
    pixels.iter().map(|p| luminance(*p) as f64).sum::<f64>() / pixels.len() as f64
}

/// The reference image of `scene`: read from `out/` when a render with the
/// same strategy and samples exists, else rendered (with random numbers of
/// its own, independent of the compared renders') and saved (raw
/// little-endian `f32` RGB). Every strategy is unbiased, so any converges
/// to the same image; the table's mean column checks them against it.
fn reference(loaded: &Loaded, scene: &str, o: &Options) -> Result<Vec<Vec3>, String> {
    let path = o.out.join(format!(
        "{scene}-reference-{}-{}spp.f32",
        o.reference_strategy, o.reference_spp
    ));
    if let Ok(bytes) = std::fs::read(&path) {
        let f: Vec<f32> = bytes
            .chunks_exact(4)
            .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
            .collect();
        if f.len() == 3 * loaded.resolution.0 * loaded.resolution.1 {
            println!("  reference: {} (reused)", path.display());
            return Ok(f
                .chunks_exact(3)
                .map(|c| Vec3::new(c[0], c[1], c[2]))
                .collect());
        }
    }
    let budget = Budget::Samples {
        spp: o.reference_spp,
        max: f64::INFINITY,
    };
    let run = render(loaded, &o.reference_strategy, budget, 1)?;
    let pixels = run.pixels.ok_or("the reference did not finish")?;
    println!(
        "  reference: {}, {} spp, {:.0} s, saved to {}",
        o.reference_strategy,
        o.reference_spp,
        run.seconds,
        path.display()
    );
    std::fs::create_dir_all(&o.out).map_err(|e| e.to_string())?;
    let bytes: Vec<u8> = pixels
        .iter()
        .flat_map(|p| p.to_array())
        .flat_map(f32::to_le_bytes)
        .collect();
    std::fs::write(&path, bytes).map_err(|e| e.to_string())?;
    save_png(&pixels, loaded.resolution, &path.with_extension("png"))?;
    Ok(pixels)
}

/// The GLT in tile order with each learning rule of `--tiles`, against
/// the reference: relMSE at equal samples, seconds, refinements.
fn compare_tiles(loaded: &Loaded, reference: &[Vec3], spp: u32, o: &Options) -> Result<(), String> {
    println!("\n| learning (tile order) | seeds | relMSE | vs never | seconds | refinements |");
    println!("|---|---:|---:|---:|---:|---:|");
    let mut never = None;
    for rule in &o.tiles {
        let (mut err, mut secs, mut refs) = (0.0, 0.0, 0);
        for seed in 0..o.seeds {
            let (glt, emitters) = glue::GltStrategy::new(&loaded.scene)
                .map_err(|e| e.to_string())?
                .into_parts();
            let guide = tiles::guide(glt, rule)?;
            let run = tiles::render_tiles(loaded, &guide, emitters, spp, 7 + seed, rule)?;
            err += rel_mse(&run.image.pixels(), reference) / o.seeds as f64;
            secs += run.seconds / o.seeds as f64;
            refs += run.refinements;
        }
        if rule == "never" {
            never = Some(err);
        }
        let ratio = never.map_or("-".into(), |n| format!("{:.2}x", n / err));
        println!(
            "| {rule} | {} | {err:.4} | {ratio} | {secs:.2} | {:.1} |",
            o.seeds,
            refs as f64 / o.seeds as f64
        );
    }
    Ok(())
}

fn compare(scene: &str, o: &Options) -> Result<(), String> {
    let file = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("scenes")
        .join(format!("{scene}.pbrt"));
    let t = Instant::now();
    let loaded = scene_file::load(&file)?;
    let spp = o.spp.unwrap_or(loaded.spp);
    println!(
        "\n{scene}: {} lights ({} unbounded), {}x{}, read in {:.1} s",
        loaded.scene.lights.len(),
        loaded.scene.infinite_lights.len()
            + loaded
                .scene
                .lights
                .iter()
                .filter(|l| matches!(***l, rs_pbrt::core::light::Light::Distant(_)))
                .count(),
        loaded.resolution.0,
        loaded.resolution.1,
        t.elapsed().as_secs_f64()
    );
    let reference = reference(&loaded, scene, o)?;
    let reference_mean = mean(&reference);
    if !o.tiles.is_empty() {
        return compare_tiles(&loaded, &reference, spp, o);
    }
    let mut runs = Vec::new();
    for s in &o.strategies {
        let run = render(
            &loaded,
            s,
            Budget::Samples {
                spp,
                max: o.max_seconds,
            },
            0,
        )?;
        if let Some(p) = &run.pixels {
            save_png(
                p,
                loaded.resolution,
                &o.out.join(format!("{scene}-{s}-{spp}spp.png")),
            )?;
        }
        runs.push((s.clone(), run));
    }
    // Equal time: the GLT's time at equal samples (or --seconds).
    let budget = o
        .seconds
        .or_else(|| {
            runs.iter()
                .find(|(s, _)| s == "glt")
                .map(|(_, r)| r.seconds)
        })
        .unwrap_or(1.0);
    println!(
        "\n| strategy | {spp} spp: seconds | relMSE | mean (reference {reference_mean:.4}) | {budget:.1} s: spp | relMSE |"
    );
    println!("|---|---:|---:|---:|---:|---:|");
    for (s, run) in &runs {
        let equal_samples = match &run.pixels {
            Some(p) => {
                let m = mean(p);
                let off = 100.0 * (m / reference_mean - 1.0);
                format!(
                    "{:.2} | {:.4} | {m:.4} ({off:+.2}%)",
                    run.seconds,
                    rel_mse(p, &reference)
                )
            }
            None => format!("not done in {:.0} | - | -", o.max_seconds),
        };
        let timed = render(&loaded, s, Budget::Seconds(budget), 2)?;
        let equal_time = match &timed.pixels {
            Some(p) => format!(
                "{} in {:.1} s | {:.4}",
                timed.spp,
                timed.seconds,
                rel_mse(p, &reference)
            ),
            None => "none | -".into(),
        };
        println!("| {s} | {equal_samples} | {equal_time} |");
    }
    Ok(())
}

/// CI's check: the tiny scene read, rendered with every strategy at a few
/// samples, each image finite and its mean within 5% of the others'.
fn check(spp: u32) -> Result<(), String> {
    let file = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/tiny.pbrt");
    let loaded = scene_file::load(&file)?;
    let means: Vec<(&str, f64)> = STRATEGIES
        .iter()
        .map(|s| {
            let r = render(&loaded, s, Budget::Samples { spp, max: 60.0 }, 0)?;
            Ok((*s, r.pixels.as_deref().map_or(f64::NAN, mean)))
        })
        .collect::<Result<_, String>>()?;
    // The GLT in tile order, refining when due (src/tiles.rs).
    let (glt, emitters) = glue::GltStrategy::new(&loaded.scene)
        .map_err(|e| e.to_string())?
        .into_parts();
    let guide = tiles::guide(glt, "auto")?;
    let run = tiles::render_tiles(&loaded, &guide, emitters, spp, 0, "auto")?;
    if run.refinements == 0 {
        return Err("tile order: the GLT never refined".into());
    }
    let mut means = means;
    means.push(("glt in tile order", mean(&run.image.pixels())));
    let all = means.iter().map(|m| m.1).sum::<f64>() / means.len() as f64;
    for (s, m) in &means {
        println!("{s}: mean {m:.4}");
        if !(m.is_finite() && (m / all - 1.0).abs() < 0.05) {
            return Err(format!("{s}: mean {m} against {all} for all strategies"));
        }
    }
    println!(
        "check passed: {} lights, every strategy agrees",
        loaded.scene.lights.len()
    );
    Ok(())
}

fn main() {
    let result = options().and_then(|o| {
        if o.check {
            return check(o.spp.unwrap_or(128));
        }
        o.scenes.iter().try_for_each(|s| compare(s, &o))
    });
    if let Err(e) = result {
        eprintln!("error: {e}");
        std::process::exit(1);
    }
}
