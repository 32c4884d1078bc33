//! A render farm in miniature: N worker processes (each a separate OS
//! process with its own share of the passes) train copies of one guiding
//! field on the render example's scene, exchange their state through
//! files, and the coordinator merges the shares and refines once per
//! iteration. In deterministic mode the merged field is, bit for bit, the
//! field one process rendering every pass learns; the report compares it
//! with what one worker alone learns from its share, by the noise of a
//! final render with each.
//!
//! ```text
//! cargo run --release --bin farm -- --workers 4
//! ```

use guiding_render::{integrator, methods, run, scene, scenes};

use clap::Parser;
use guiding::LightTree;
use guiding::cut::CutConfig;
use guiding::field::{FieldConfig, GuidingField};
use guiding::math::Accumulation;
use guiding::schedule::PassStats;
use guiding::sd_tree::SdTreeConfig;
use integrator::Guides;
use run::{GuideFiles, Settings};
use scene::Scene;
use std::path::PathBuf;
use std::process::{Command, ExitCode};

/// The farm's options (a worker gets the `--worker` ones from the
/// coordinator).
#[derive(Parser, Debug)]
#[command(about = "N worker processes train one guiding field; their states merge through files")]
struct Args {
    /// Scene (as the render example names it).
    #[arg(long, default_value = "ring")]
    scene: String,
    /// Worker processes.
    #[arg(long, default_value_t = 4)]
    workers: u32,
    /// Training iterations.
    #[arg(long, default_value_t = 4)]
    iterations: u32,
    /// Passes (samples per pixel) per training iteration, all workers
    /// together.
    #[arg(long, default_value_t = 8)]
    passes: u64,
    /// Passes of the final render that compares the fields.
    #[arg(long, default_value_t = 16)]
    final_passes: u64,
    /// Image width.
    #[arg(long, default_value_t = 128)]
    width: u32,
    /// Image height.
    #[arg(long, default_value_t = 96)]
    height: u32,
    /// Where the state and share files go.
    #[arg(long, default_value = "out/farm")]
    dir: PathBuf,
    /// Worker mode: this worker's number.
    #[arg(long, hide = true)]
    worker: Option<u32>,
    /// Worker mode: the state file to start from.
    #[arg(long, hide = true)]
    state: Option<PathBuf>,
    /// Worker mode: the file to write the share to.
    #[arg(long, hide = true)]
    share: Option<PathBuf>,
    /// Worker mode: the training iteration.
    #[arg(long, hide = true, default_value_t = 0)]
    iteration: u32,
}

fn settings(args: &Args) -> Settings {
    Settings {
        width: args.width,
        height: args.height,
        budget: run::Budget::Spp(args.passes),
        params: methods::GuideParams::default(),
        seed: 1,
        progress: false,
        guide_files: GuideFiles::default(),
    }
}

/// The field every process builds: deterministic sums, so that merging
/// is exact.
fn new_field(scene: &Scene) -> GuidingField<&LightTree> {
    let mut sd = SdTreeConfig::improved();
    sd.accumulation = Accumulation::Deterministic;
    let config = FieldConfig {
        sd,
        cut: CutConfig {
            accumulation: Accumulation::Deterministic,
            unbounded: scene.unbounded_lights,
            ..CutConfig::default()
        },
        ..FieldConfig::default()
    };
    GuidingField::new(&scene.light_tree, scene.bounds, config).expect("valid scene")
}

/// Renders the passes `first, first + step, ...` below `end` of training
/// iteration `iteration` with `field`, recording into it when `train`;
/// returns their statistics.
fn render_passes(
    scene: &Scene,
    field: &GuidingField<&LightTree>,
    args: &Args,
    iteration: u32,
    (first, step, end): (u64, u64, u64),
    train: bool,
) -> PassStats {
    let guides = Guides {
        lights: None,
        glt: None,
        sd_tree: None,
        field: Some(field),
        train,
        contribution_records: false,
        resample: 0,
        resample_vertices: 1,
        nee_samples: 1,
        nee_samples_vertices: 0,
    };
    let settings = settings(args);
    let len = (3 * args.width * args.height) as usize;
    let mut stats = PassStats::new(len);
    let mut buf = vec![0.0f32; len];
    let mut pass = first;
    while pass < end {
        // Passes are numbered across iterations so every pass draws its
        // own random numbers.
        let global = u64::from(iteration) * 1_000_000 + pass;
        run::render_pass(scene, &guides, &settings, global, &mut buf);
        stats.add_pass(&buf);
        pass += step;
    }
    stats
}

/// The mean over pixels of the relative variance of the image mean.
fn noise(stats: &PassStats) -> f64 {
    let mean = stats.mean();
    let (mut sum, mut n) = (0.0, 0usize);
    for (i, m) in mean.iter().enumerate() {
        if let Some(v) = stats.variance_of_mean(i) {
            sum += v / (m * m + 1e-4);
            n += 1;
        }
    }
    sum / n.max(1) as f64
}

fn scene_of(args: &Args) -> Result<Scene, String> {
    scenes::build(&args.scene, scenes::Size::Full)
        .ok_or_else(|| format!("unknown scene {}", args.scene))
}

/// Worker mode: start from the state file with its records cleared (the
/// coordinator keeps those), render this worker's passes of the iteration
/// while recording, write the share.
fn worker(args: &Args, w: u32) -> Result<(), String> {
    let scene = scene_of(args)?;
    let state = std::fs::read(args.state.as_ref().ok_or("--state")?).map_err(|e| e.to_string())?;
    let mut field =
        GuidingField::from_bytes(&state, &scene.light_tree).map_err(|e| e.to_string())?;
    field.clear_records();
    let n = u64::from(args.workers);
    render_passes(
        &scene,
        &field,
        args,
        args.iteration,
        (u64::from(w), n, args.passes),
        true,
    );
    std::fs::write(args.share.as_ref().ok_or("--share")?, field.to_bytes())
        .map_err(|e| e.to_string())
}

/// Trains a field in this process on passes `first, first + step, ...` of
/// every iteration.
fn train_here<'a>(
    scene: &'a Scene,
    args: &Args,
    first: u64,
    step: u64,
) -> GuidingField<&'a LightTree> {
    let mut field = new_field(scene);
    for it in 0..args.iterations {
        render_passes(scene, &field, args, it, (first, step, args.passes), true);
        field.refine();
    }
    field
}

fn coordinator(args: &Args) -> Result<(), String> {
    let scene = scene_of(args)?;
    std::fs::create_dir_all(&args.dir).map_err(|e| e.to_string())?;
    let exe = std::env::current_exe().map_err(|e| e.to_string())?;
    let file = |name: String| -> PathBuf { args.dir.join(name) };
    let mut state = new_field(&scene);
    let start = std::time::Instant::now();
    for it in 0..args.iterations {
        let state_path = file(format!("state-{it}.guide"));
        std::fs::write(&state_path, state.to_bytes()).map_err(|e| e.to_string())?;
        let children: Vec<_> = (0..args.workers)
            .map(|w| {
                Command::new(&exe)
                    .args(["--scene", &args.scene])
                    .args(["--workers", &args.workers.to_string()])
                    .args(["--passes", &args.passes.to_string()])
                    .args(["--width", &args.width.to_string()])
                    .args(["--height", &args.height.to_string()])
                    .args(["--iteration", &it.to_string()])
                    .args(["--worker", &w.to_string()])
                    .arg("--state")
                    .arg(&state_path)
                    .arg("--share")
                    .arg(file(format!("share-{it}-{w}.guide")))
                    .spawn()
                    .map_err(|e| e.to_string())
            })
            .collect::<Result<_, _>>()?;
        for mut c in children {
            let status = c.wait().map_err(|e| e.to_string())?;
            if !status.success() {
                return Err(format!("a worker failed: {status}"));
            }
        }
        let load = |w: u32| -> Result<GuidingField<&LightTree>, String> {
            let bytes =
                std::fs::read(file(format!("share-{it}-{w}.guide"))).map_err(|e| e.to_string())?;
            GuidingField::from_bytes(&bytes, &scene.light_tree).map_err(|e| e.to_string())
        };
        for w in 0..args.workers {
            if !state.merge(&load(w)?) {
                return Err("shares of different fields".into());
            }
        }
        state.refine();
        println!(
            "iteration {it}: {} workers x {} passes merged, {} cells, {:.1} MB on disk, {:.1} MB in memory",
            args.workers,
            args.passes.div_ceil(u64::from(args.workers)),
            state.cell_count(),
            state.to_bytes().len() as f64 / 1e6,
            state.memory().total() as f64 / 1e6
        );
    }
    let farm_seconds = start.elapsed().as_secs_f64();
    let farm = state;
    // The same passes in one process, and one worker's share alone.
    let one_process = train_here(&scene, args, 0, 1);
    let one_worker = train_here(&scene, args, 0, u64::from(args.workers));
    let identical = one_process.to_bytes() == farm.to_bytes();
    let final_range = (0, 1, args.final_passes);
    let final_it = args.iterations + 1;
    let report = |name: &str, f: &GuidingField<&LightTree>| {
        let stats = render_passes(&scene, f, args, final_it, final_range, false);
        println!(
            "{name:<28} {:>6} cells  relative variance of the final image {:.4e}",
            f.cell_count(),
            noise(&stats)
        );
    };
    println!(
        "\nppg-glt on {}: {} iterations of {} passes ({:.1} s with {} worker processes); final render {} passes",
        args.scene, args.iterations, args.passes, farm_seconds, args.workers, args.final_passes
    );
    report("farm (merged shares)", &farm);
    report("one process, every pass", &one_process);
    report("one worker, its share only", &one_worker);
    println!("merged farm state identical to the one-process state: {identical}");
    if identical {
        Ok(())
    } else {
        Err("merged state differs from the one-process state".into())
    }
}

fn main() -> ExitCode {
    let args = Args::parse();
    let result = match args.worker {
        Some(w) => worker(&args, w),
        None => coordinator(&args),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("farm: {e}");
            ExitCode::FAILURE
        }
    }
}
