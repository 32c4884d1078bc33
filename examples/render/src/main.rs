//! `render`: a small CPU path tracer that uses only `guiding`'s public API,
//! the way an outside renderer would, to compare light-sampling and
//! guiding methods on code-generated analogues of the paper's scenes.
//!
//! ```text
//! cargo run --release --bin render                     # default job
//! cargo run --release --bin render -- --scene ring --method pt-uniform,ppg-glt --seconds 30 --json out.json
//! ```
//!
//! One concept per file: `cli` (flags), `scenes/` (scene generators),
//! `scene` (scene container, effect declarations), `geometry` + `bvh`
//! (primitives, obvhs ray casting), `materials`, `lights`, `camera`,
//! `integrator` (the path tracer and its training records), `methods` (which
//! crate objects a method uses), `run` (passes, training schedule,
//! combination), `film` (EXR/PNG), `reference` (cache), `metrics`,
//! `report` (JSON, table), `sheet` (comparison sheet).

use guiding_render::{
    cli, crossing, film, frames, methods, metrics, plot, raster, reference, report, rng, run,
    scenes, sheet, tiles,
};

use clap::Parser;
use guiding::spatial::SpatialFilter;
use methods::{GuideParams, Method};
use report::Record;
use run::{Budget, Settings};
use std::path::Path;
use std::process::ExitCode;
use std::time::Instant;

fn main() -> ExitCode {
    let args = cli::Args::parse();
    match run_all(&args) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}

/// Parses the scene and method lists.
fn selection(args: &cli::Args) -> Result<(Vec<String>, Vec<Method>), String> {
    let scenes: Vec<String> = if args.scene.iter().any(|s| s == "all") {
        scenes::NAMES.iter().map(|s| s.to_string()).collect()
    } else {
        args.scene.clone()
    };
    for s in &scenes {
        if !scenes::NAMES.contains(&s.as_str()) {
            return Err(format!(
                "unknown scene {s:?} (known: {})",
                scenes::NAMES.join(", ")
            ));
        }
    }
    let methods = if args.method.is_empty() {
        Method::MAIN.to_vec()
    } else if args.method.iter().any(|m| m == "all") {
        Method::ALL.to_vec()
    } else {
        args.method
            .iter()
            .map(|m| Method::parse(m).ok_or_else(|| format!("unknown method {m:?}")))
            .collect::<Result<_, _>>()?
    };
    Ok((scenes, methods))
}

/// A reference renders this many times a method's seconds by default.
/// Its own relMSE must be a tenth of the best method's; the reference
/// method (`pt-bvh`) needs about 3.2x the best method's time to the same
/// error on `ring` at 20 s (ppg-glt's relMSE 0.11 against pt-bvh's 0.35),
/// so a tenth takes about 32x.
const REFERENCE_TIMES: f64 = 40.0;

fn run_all(args: &cli::Args) -> Result<(), String> {
    if let Some(path) = &args.replot {
        return replot(path, &args.out);
    }
    if let Some(n) = args.threads {
        rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build_global()
            .map_err(|e| e.to_string())?;
    }
    let (scene_names, methods) = selection(args)?;
    if args.nee_samples == 0 || (args.nee_samples > 1 && args.resample > 0) {
        return Err("--nee-samples takes at least 1, and only without --resample".into());
    }
    let reference_method = Method::parse(&args.reference_method)
        .ok_or_else(|| format!("unknown reference method {:?}", args.reference_method))?;
    let budget = match (args.spp, args.seconds) {
        (Some(n), _) => Budget::Spp(n.max(1)),
        (None, Some(s)) => Budget::Seconds(s),
        (None, None) => Budget::Seconds(20.0),
    };
    let reference_budget = match (args.reference_spp, args.reference_seconds, budget) {
        (Some(n), _, _) => Budget::Spp(n),
        (None, Some(s), _) => Budget::Seconds(s),
        (None, None, Budget::Seconds(s)) => Budget::Seconds(REFERENCE_TIMES * s),
        (None, None, Budget::Spp(_)) => Budget::Seconds(80.0),
    };
    std::fs::create_dir_all(&args.out).map_err(|e| format!("{}: {e}", args.out.display()))?;
    let size = if args.small {
        scenes::Size::Small
    } else {
        scenes::Size::Full
    };
    let mut params = GuideParams {
        sigma: args.sigma[0],
        spatial_threshold: args.spatial_threshold,
        glt_spatial_threshold: args.glt_spatial_threshold,
        below_cut: args.below_cut,
        min_records: args.min_records,
        alpha: args.alpha,
        modulation: args.modulation,
        importance_bound: args.importance_bound,
        contribution_records: args.contribution_records,
        glt_filter: if args.glt_jitter {
            SpatialFilter::StochasticBox
        } else {
            SpatialFilter::Nearest
        },
        prior: args.prior,
        visibility: args.visibility,
        resample: args.resample,
        resample_vertices: args.resample_vertices,
        nee_samples: args.nee_samples,
        nee_samples_vertices: args.nee_samples_vertices,
    };
    if args.paper_rules {
        params = params.paper_rules();
    }
    let settings = Settings {
        width: args.width,
        height: args.height,
        budget,
        params,
        seed: args.seed,
        progress: !args.quiet,
        guide_files: run::GuideFiles {
            load: args.load_guide.clone(),
            save: args.save_guide.clone(),
            restart: false,
        },
    };
    if args.frames > 1 {
        for name in &scene_names {
            let table = frames::run(
                args,
                name,
                size,
                &methods,
                &settings,
                reference_method,
                reference_budget,
            )?;
            println!("{table}");
        }
        return Ok(());
    }
    let mut all = Vec::new();
    for name in &scene_names {
        let (records, trust) = run_scene(
            args,
            name,
            size,
            &methods,
            &settings,
            reference_method,
            reference_budget,
        )?;
        if !records.is_empty() {
            println!("{}", report::table(&records));
            print!("{}", report::work_table(&records));
            print!("{}", report::curve_table(&records));
        }
        println!("{trust}\n");
        all.extend(records);
    }
    if let Some(path) = &args.json {
        std::fs::write(path, report::to_json(&all))
            .map_err(|e| format!("{}: {e}", path.display()))?;
        println!("wrote {}", path.display());
    }
    Ok(())
}

/// Redraws the plots of the records in the JSON file `path` under
/// `out/<scene>/` and prints their tables.
fn replot(path: &Path, out: &Path) -> Result<(), String> {
    let text = std::fs::read_to_string(path).map_err(|e| format!("{}: {e}", path.display()))?;
    let all = report::from_json(&text)?;
    let mut scenes: Vec<&str> = all.iter().map(|r| r.scene.as_str()).collect();
    scenes.dedup();
    for name in scenes {
        let records: Vec<Record> = all.iter().filter(|r| r.scene == name).cloned().collect();
        println!("{}", report::table(&records));
        print!("{}", report::work_table(&records));
        print!("{}", report::curve_table(&records));
        let dir = out.join(name);
        std::fs::create_dir_all(&dir).map_err(|e| format!("{}: {e}", dir.display()))?;
        if records.iter().any(|r| !r.curve.is_empty()) {
            let [svg, png] = plot::convergence(&dir.join("convergence"), name, &records)?;
            println!("{name}: {} and {}", svg.display(), png.display());
        }
        if records.iter().any(|r| r.method.contains(" s=")) {
            let [svg, png] = plot::sigma_study(&dir.join("sigma"), name, &records)?;
            println!("{name}: {} and {}", svg.display(), png.display());
        }
        println!("{}", crossing::describe(&crossing::crossings(&records)));
    }
    Ok(())
}

fn run_scene(
    args: &cli::Args,
    name: &str,
    size: scenes::Size,
    methods: &[Method],
    settings: &Settings,
    reference_method: Method,
    reference_budget: Budget,
) -> Result<(Vec<Record>, String), String> {
    let t = Instant::now();
    let mut scene = scenes::build(name, size).ok_or_else(|| format!("unknown scene {name}"))?;
    if let Some(d) = args.max_depth {
        scene.effects.max_depth = d;
        scene.fingerprint = rng::mix64(scene.fingerprint ^ u64::from(d));
    }
    if let Some(s) = &args.camera_shift {
        let [x, y, z] = s[..] else {
            return Err("--camera-shift takes three numbers: x,y,z".into());
        };
        let shift = glam::Vec3::new(x, y, z);
        scene.camera.eye += shift;
        for x in shift.to_array() {
            scene.fingerprint = rng::mix64(scene.fingerprint ^ u64::from(x.to_bits()));
        }
    }
    println!(
        "scene {name}: {} primitives, {} emitters, light tree {:.1} MB; effects: {}; built in {:.1} s",
        scene.bvh.primitives().len(),
        scene.lights.len(),
        scene.light_tree.bytes() as f64 / 1e6,
        scene.effects.describe(),
        t.elapsed().as_secs_f64()
    );
    let reference = reference::load_or_render(
        &scene,
        &args.out,
        settings,
        reference_method,
        reference_budget,
        args.rebuild_reference,
    )?;
    let (w, h) = (settings.width, settings.height);
    let stem = match reference.origin {
        reference::Origin::Committed => reference::stem_in(
            std::path::Path::new(reference::COMMITTED),
            &scene,
            w,
            h,
            reference_method,
        ),
        _ => reference::cache_stem(&args.out, &scene, w, h, reference_method),
    };
    println!(
        "reference: {} ({}){}",
        reference.provenance,
        stem.display(),
        match reference.origin {
            reference::Origin::Cached => ", cached".to_string(),
            reference::Origin::Committed => ", committed to the repository".to_string(),
            reference::Origin::Rendered => String::new(),
            reference::Origin::Extended(spp) => format!(", extended from the {spp} spp it had"),
        }
    );
    if let Some(dir) = &args.export_reference {
        let note = format!(
            "scene {name} (fingerprint {:016x}), {w}x{h}, exported by `render --export-reference`",
            scene.fingerprint
        );
        let stem = reference::export(&reference, dir, &scene, (w, h), reference_method, &note)?;
        println!("reference exported to {}", stem.display());
    }
    if args.reference_only {
        let floor = metrics::errors(&reference.image, &reference).relmse_floor;
        return Ok((Vec::new(), format!("reference: own relMSE {floor:.2e}")));
    }
    let exposure = film::auto_exposure(reference.mean);
    let dir = args.out.join(name);
    std::fs::create_dir_all(&dir).map_err(|e| e.to_string())?;
    let mut records = Vec::new();
    let mut rendered = Vec::new();
    // Tile order renders no curves.
    let no_curve = args.no_curve || args.tiles.is_some();
    // The sigma study: GLT methods once per sigma.
    let study = args.sigma.len() > 1;
    let runs: Vec<(Method, Option<f64>)> = methods
        .iter()
        .flat_map(|&m| {
            let sigmas: Vec<Option<f64>> = if study && (m.uses_glt() || m.uses_field()) {
                args.sigma.iter().map(|&s| Some(s)).collect()
            } else {
                vec![None]
            };
            sigmas.into_iter().map(move |s| (m, s))
        })
        .collect();
    for (method, sigma) in runs {
        let mut run_settings = settings.clone();
        if let Some(s) = sigma {
            run_settings.params.sigma = s;
        }
        let settings = &run_settings;
        let label = match sigma {
            Some(s) => format!("{} s={s}", method.name()),
            None => method.name().to_string(),
        };
        let mut curve = Vec::new();
        let mut observe = |c: run::CurveSample<'_>| {
            curve.push(report::CurvePoint {
                seconds: c.seconds,
                spp: c.spp,
                relmse: metrics::relmse_of_rgb(c.image, &reference),
                bytes: c.bytes,
            });
        };
        let observer: Option<&mut dyn FnMut(run::CurveSample<'_>)> =
            if no_curve { None } else { Some(&mut observe) };
        let r = match (args.tiles, settings.budget) {
            (None, _) => run::render_observed(&scene, method, settings, observer).0,
            (Some(rule), Budget::Spp(spp)) => {
                tiles::render_tiles(&scene, method, settings, spp, rule)
            }
            (Some(_), Budget::Seconds(_)) => return Err("--tiles renders --spp samples".into()),
        };
        let e = metrics::errors(&r.image, &reference);
        write_outputs(&dir, &label.replace(' ', "-"), &r, exposure)?;
        records.push(Record {
            scene: name.to_string(),
            method: label.clone(),
            sigma: settings.params.sigma,
            width: r.width,
            height: r.height,
            spp: r.spp,
            spp_final: r.spp_final,
            seconds: r.seconds,
            rmse: e.rmse,
            relmse: e.relmse,
            efficiency: metrics::efficiency(e.relmse, r.seconds),
            rmse_raw: e.rmse_raw,
            relmse_raw: e.relmse_raw,
            reference_relmse: e.relmse_floor,
            mean: r.mean,
            mean_error: r.mean_error,
            reference_mean: reference.mean,
            sdtree_bytes: r.sd_tree_bytes,
            glt_bytes: r.glt_bytes,
            emitters: scene.lights.len(),
            iterations: r.iterations,
            vertices: r.vertices,
            curve,
        });
        rendered.push((label, r, e));
    }
    let mut panels = vec![sheet::Panel {
        image: &reference.image,
        lines: vec!["reference".into(), reference.provenance.clone()],
    }];
    for (method, r, e) in &rendered {
        panels.push(sheet::Panel {
            image: &r.image,
            lines: vec![
                method.clone(),
                format!("RMSE {:.4}", e.rmse),
                format!("{} spp, {:.0} s", r.spp, r.seconds),
            ],
        });
    }
    let sheet_path = dir.join("comparison.png");
    let chart = |v: raster::Viewport<'_>| plot::convergence_into(v, name, &records);
    sheet::write_sheet(
        &sheet_path,
        settings.width,
        settings.height,
        exposure,
        &panels,
        (!no_curve).then_some(&chart as sheet::Chart<'_>),
    )?;
    film::write_png(
        &dir.join("reference.png"),
        settings.width,
        settings.height,
        &film::tone_map(&reference.image, exposure),
    )?;
    println!(
        "{name}: images in {}, comparison sheet {}",
        dir.display(),
        sheet_path.display()
    );
    if !no_curve {
        let [svg, png] = plot::convergence(&dir.join("convergence"), name, &records)?;
        println!(
            "{name}: convergence plot (relMSE over time) {} and {}",
            svg.display(),
            png.display()
        );
    }
    if study {
        let [svg, png] = plot::sigma_study(&dir.join("sigma"), name, &records)?;
        println!(
            "{name}: sigma study (relMSE and memory against sigma) {} and {}",
            svg.display(),
            png.display()
        );
    }
    let best = records
        .iter()
        .filter(|r| r.relmse > 0.0)
        .min_by(|a, b| a.relmse.total_cmp(&b.relmse));
    let trust = match best {
        Some(b) => reference::trust_line(b, reference::seconds_of(&reference)),
        None => "reference: no method to compare it with".to_string(),
    };
    let trust = format!(
        "{}{trust}",
        crossing::describe(&crossing::crossings(&records))
    );
    Ok((records, trust))
}

fn write_outputs(dir: &Path, name: &str, r: &run::Rendered, exposure: f32) -> Result<(), String> {
    film::write_exr(
        &dir.join(format!("{name}.exr")),
        r.width,
        r.height,
        &r.image,
    )?;
    film::write_png(
        &dir.join(format!("{name}.png")),
        r.width,
        r.height,
        &film::tone_map(&r.image, exposure),
    )
}
