//! The `render` example's integrator gives the same image with every
//! method: per-method image means (whole image and quadrants) agree with an
//! independent reference within their statistical error on `box`, on a small many-light scene (`ring`
//! with 1,536 lights) and on `few-lights` (environment light). And the
//! reference committed for the default job belongs to the default scene as
//! it is. It runs the `render` binary's own library, so it exercises
//! exactly the code the binary runs.

use guiding_render::{methods, metrics, reference, run, scene, scenes, tiles};

use guiding::cut::{BelowCut, CutConfig};
use methods::{GuideParams, Method};
use run::{Budget, Rendered, Settings};

/// Mean luminance of the whole image and of its four quadrants, with the
/// standard error of each (from the per-pixel variance estimates).
fn region_means(r: &Rendered) -> Vec<(f64, f64)> {
    let (w, h) = (r.width as usize, r.height as usize);
    let regions = [
        (0, w, 0, h),
        (0, w / 2, 0, h / 2),
        (w / 2, w, 0, h / 2),
        (0, w / 2, h / 2, h),
        (w / 2, w, h / 2, h),
    ];
    regions
        .iter()
        .map(|&(x0, x1, y0, y1)| {
            let (mut sum, mut var) = (0.0f64, 0.0f64);
            for y in y0..y1 {
                for x in x0..x1 {
                    let i = y * w + x;
                    sum += f64::from(guiding::luminance(r.image[i]));
                    // Variance of a luminance: the channels' variances with
                    // squared weights (their covariance ignored, which only
                    // matters little for a tolerance of several sigma).
                    let v = r.variance[i];
                    var += f64::from(
                        0.2126f32.powi(2) * v.x + 0.7152f32.powi(2) * v.y + 0.0722f32.powi(2) * v.z,
                    );
                }
            }
            let n = ((x1 - x0) * (y1 - y0)) as f64;
            (sum / n, var.sqrt() / n)
        })
        .collect()
}

/// Renders `scene` with every method at `spp` and checks each region mean
/// against an independent reference: `pt-bvh` (no learning; its sampler is
/// chi-square tested on its own) at 16x the samples with another seed.
/// Each method must agree within `k` standard errors of the difference
/// (plus 0.5% for the variance estimates' own noise). A reference rather
/// than the methods' pooled mean, so a bias the guided methods share cannot
/// pull the yardstick with it.
fn methods_agree(name: &str, width: u32, height: u32, spp: u64) {
    methods_agree_with(name, width, height, spp, &Method::ALL, |_| {});
}

/// [`methods_agree`] for `methods`, their parameters changed by `tweak`
/// (the reference keeps the defaults).
fn methods_agree_with(
    name: &str,
    width: u32,
    height: u32,
    spp: u64,
    methods: &[Method],
    tweak: impl Fn(&mut GuideParams),
) {
    let six_percent = 0.06;
    methods_agree_rendered(
        name,
        (width, height, spp),
        methods,
        six_percent,
        tweak,
        run::render,
    );
}

/// [`methods_agree_with`], the methods rendered by `render` (the
/// reference always in pass order), the check shown to see a trained GLT
/// method `off` (a fraction) off.
fn methods_agree_rendered(
    name: &str,
    (width, height, spp): (u32, u32, u64),
    methods: &[Method],
    off: f64,
    tweak: impl Fn(&mut GuideParams),
    render: impl Fn(&scene::Scene, Method, &Settings) -> Rendered,
) {
    let scene = scenes::build(name, scenes::Size::Small).expect("known scene");
    let mut settings = Settings {
        width,
        height,
        budget: Budget::Spp(spp),
        params: GuideParams {
            sigma: 0.01,
            spatial_threshold: 250.0,
            glt_spatial_threshold: 250.0,
            below_cut: BelowCut::Power,
            min_records: CutConfig::default().min_records,
            alpha: CutConfig::default().alpha,
            modulation: CutConfig::default().modulation,
            importance_bound: CutConfig::default().importance_bound,
            contribution_records: false,
            glt_filter: guiding::spatial::SpatialFilter::Nearest,
            prior: CutConfig::default().prior,
            visibility: false,
            resample: 0,
            resample_vertices: 1,
            nee_samples: 1,
            nee_samples_vertices: 0,
        },
        seed: 1001,
        progress: false,
        guide_files: Default::default(),
    };
    settings.budget = Budget::Spp(16 * spp);
    let reference = region_means(&run::render(&scene, Method::PtBvh, &settings));
    settings.budget = Budget::Spp(spp);
    settings.seed = 3;
    tweak(&mut settings.params);
    // Each method's region means, and whether it refined.
    type Means = Vec<(f64, f64)>;
    let results: Vec<(Method, Means, bool)> = methods
        .iter()
        .map(|&m| {
            let r = render(&scene, m, &settings);
            assert_eq!(r.spp, spp, "{name} {}: spp", m.name());
            assert!(
                r.image.iter().all(|p| p.is_finite()),
                "{name} {}: non-finite pixels",
                m.name()
            );
            (m, region_means(&r), r.iterations > 1)
        })
        .collect();
    let k = 4.5;
    for (region, &(truth, truth_e)) in reference.iter().enumerate() {
        assert!(truth > 0.0 && truth_e > 0.0, "{name}: black reference");
        for (method, rm, trained) in &results {
            let (m, e) = rm[region];
            assert!(
                e > 0.0,
                "{name}: {} reports no error estimate",
                method.name()
            );
            let tolerance = k * (e * e + truth_e * truth_e).sqrt() + 0.005 * truth;
            assert!(
                (m - truth).abs() <= tolerance,
                "{name} region {region}: {} mean {m:.5} +- {e:.5} vs reference {truth:.5} +- {truth_e:.5} (tolerance {tolerance:.5})",
                method.name()
            );
            // The control: on the whole image the check has the power to
            // see a trained GLT method `off` off (in pass order 6%: a pmf
            // reported 6% too high everywhere it matters, say). The
            // unguided uniform and power samplers, and a GLT that never
            // refined, are too noisy on ring at this spp to see that much.
            if region == 0 && method.name().ends_with("glt") && *trained {
                assert!(
                    (m * (1.0 - off) - truth).abs() > tolerance,
                    "{name}: {} would pass {:.0}% low (tolerance {:.1}%)",
                    method.name(),
                    100.0 * off,
                    100.0 * tolerance / truth
                );
            }
        }
    }
}

#[test]
fn box_every_method_converges_to_the_same_image() {
    methods_agree("box", 48, 36, 64);
}

#[test]
fn many_lights_every_method_converges_to_the_same_image() {
    methods_agree("ring", 48, 36, 64);
}

/// Resampled NEE (8 candidates of the GLT, with its learned visibility)
/// inside the full integrator, MIS and training included, against the
/// same reference, on the many-light scene and with a sun and a sky.
#[test]
fn resampled_glt_methods_converge_to_the_same_image() {
    let tweak = |p: &mut GuideParams| {
        p.resample = 8;
        p.visibility = true;
    };
    let glt = [Method::PtGlt, Method::PpgGlt];
    methods_agree_with("ring", 48, 36, 64, &glt, tweak);
    methods_agree_with("few-lights", 48, 36, 128, &glt, tweak);
}

/// Several light samples per vertex (`--nee-samples`, the instrument that
/// measures what no light choice can remove), MIS counting them all: the
/// same image, with and without a sun and a sky.
#[test]
fn several_light_samples_per_vertex_converge_to_the_same_image() {
    let tweak = |p: &mut GuideParams| p.nee_samples = 4;
    let methods = [Method::PtBvh, Method::PtGlt, Method::PpgGlt];
    methods_agree_with("ring", 48, 36, 32, &methods, tweak);
    methods_agree_with("few-lights", 48, 36, 64, &methods, tweak);
}

/// Tile order (`render --tiles`): each tile rendered to completion, the
/// guided methods learning and refining between waves of tiles by every
/// rule, gives the same image. (Of this small image's 9 tiles, 8 render
/// before the first refinement: the GLT methods are nearly untrained and
/// as noisy as the prior, so the check is shown to see them 10% off.)
#[test]
fn tile_order_converges_to_the_same_image_whatever_the_refinement() {
    use tiles::Refinement;
    let methods = [Method::PtBvh, Method::PtGlt, Method::Ppg, Method::PpgGlt];
    let ten_percent = 0.1;
    for rule in [
        Refinement::Never,
        Refinement::Doubling,
        Refinement::EveryWave,
    ] {
        let render = |scene: &scene::Scene, m: Method, s: &Settings| {
            let r = tiles::render_tiles(scene, m, s, 64, rule);
            let refined = rule != Refinement::Never && m.is_trained();
            assert_eq!(r.iterations > 1, refined, "{} {rule:?}", m.name());
            r
        };
        methods_agree_rendered("ring", (48, 36, 64), &methods, ten_percent, |_| {}, render);
    }
}

#[test]
fn environment_every_method_converges_to_the_same_image() {
    methods_agree("few-lights", 48, 36, 128);
}

/// The guided methods really learn: after a few training iterations their
/// structures have grown well past the one-cell, uniform start (catches a
/// method whose training records never arrive, which no mean would show).
#[test]
fn guided_methods_train_their_structures() {
    let scene = scenes::build("box", scenes::Size::Small).expect("known scene");
    let settings = Settings {
        width: 48,
        height: 36,
        budget: Budget::Spp(64),
        params: GuideParams {
            sigma: 0.01,
            spatial_threshold: 250.0,
            glt_spatial_threshold: 250.0,
            below_cut: BelowCut::Power,
            min_records: CutConfig::default().min_records,
            alpha: CutConfig::default().alpha,
            modulation: CutConfig::default().modulation,
            importance_bound: CutConfig::default().importance_bound,
            contribution_records: false,
            glt_filter: guiding::spatial::SpatialFilter::Nearest,
            prior: CutConfig::default().prior,
            visibility: false,
            resample: 0,
            resample_vertices: 1,
            nee_samples: 1,
            nee_samples_vertices: 0,
        },
        seed: 5,
        progress: false,
        guide_files: Default::default(),
    };
    let fresh = |m: Method| {
        let mut s = settings.clone();
        s.budget = Budget::Spp(1);
        run::render(&scene, m, &s)
    };
    for m in [
        Method::PtGlt,
        Method::Ppg,
        Method::PpgGlt,
        Method::PpgAndGlt,
    ] {
        let (start, trained) = (fresh(m), run::render(&scene, m, &settings));
        assert!(
            trained.iterations >= 5,
            "{}: {} iterations",
            m.name(),
            trained.iterations
        );
        if m.uses_glt() || m.uses_field() {
            assert!(
                trained.glt_bytes > 4 * start.glt_bytes,
                "{}: cuts did not grow ({} -> {} bytes)",
                m.name(),
                start.glt_bytes,
                trained.glt_bytes
            );
        }
        if m.uses_sd_tree() || m.uses_field() {
            assert!(
                trained.sd_tree_bytes > 4 * start.sd_tree_bytes,
                "{}: SD-tree did not grow ({} -> {} bytes)",
                m.name(),
                start.sd_tree_bytes,
                trained.sd_tree_bytes
            );
        }
    }
}

/// The convergence curve is recorded right: for an unbiased, unguided
/// method on `box`, the relMSE of what the render would deliver falls as
/// `1 / spp` (slope -1 +- 0.2 on log-log over more than a decade of
/// samples; samples stand in for time, which they are proportional to for
/// an unguided method, so the test does not depend on the machine's
/// speed). The reference is a 2048-spp render of the same method.
#[test]
fn convergence_curve_falls_as_one_over_samples() {
    let scene = scenes::build("box", scenes::Size::Small).expect("known scene");
    let settings = |spp, seed| Settings {
        width: 48,
        height: 36,
        budget: Budget::Spp(spp),
        params: GuideParams::default(),
        seed,
        progress: false,
        guide_files: Default::default(),
    };
    let r = run::render(&scene, Method::PtUniform, &settings(2048, 99));
    let reference = reference::Reference {
        mean: r.mean,
        image: r.image,
        variance: r.variance,
        provenance: "pt-uniform 2048 spp".into(),
        origin: reference::Origin::Rendered,
    };
    let mut curve: Vec<(u64, f64)> = Vec::new();
    let mut observe = |c: run::CurveSample<'_>| {
        curve.push((c.spp, metrics::relmse_of_rgb(c.image, &reference)));
    };
    run::render_observed(
        &scene,
        Method::PtUniform,
        &settings(256, 5),
        Some(&mut observe),
    );
    assert!(curve.windows(2).all(|w| w[0].0 < w[1].0));
    assert_eq!(curve.last().map(|c| c.0), Some(256));
    let pts: Vec<(f64, f64)> = curve
        .iter()
        .filter(|&&(spp, _)| spp >= 16)
        .map(|&(spp, e)| ((spp as f64).ln(), e.ln()))
        .collect();
    assert!(pts.len() >= 8, "{curve:?}");
    let n = pts.len() as f64;
    let (mx, my) = (
        pts.iter().map(|p| p.0).sum::<f64>() / n,
        pts.iter().map(|p| p.1).sum::<f64>() / n,
    );
    let slope = pts.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum::<f64>()
        / pts.iter().map(|p| (p.0 - mx).powi(2)).sum::<f64>();
    assert!((slope + 1.0).abs() <= 0.2, "slope {slope}: {curve:?}");
}

/// A cached reference only grows: asking for more samples than the cache
/// holds renders the rest with fresh streams and averages it in, so the
/// extended reference has the samples asked for, about half the variance,
/// and about half the error against an independent long render; asking
/// for fewer loads the cache as it is.
#[test]
fn references_are_extended_not_rerendered() {
    let scene = scenes::build("box", scenes::Size::Small).expect("known scene");
    let out = std::env::temp_dir().join(format!("guiding-ref-{}", std::process::id()));
    let settings = Settings {
        width: 32,
        height: 24,
        budget: Budget::Spp(1),
        params: GuideParams::default(),
        seed: 3,
        progress: false,
        guide_files: Default::default(),
    };
    let get = |spp| {
        reference::load_or_render(
            &scene,
            &out,
            &settings,
            Method::PtUniform,
            Budget::Spp(spp),
            false,
        )
        .expect("reference")
    };
    let variance = |r: &reference::Reference| {
        r.variance
            .iter()
            .map(|v| f64::from(v.x + v.y + v.z))
            .sum::<f64>()
    };
    let truth = run::render(
        &scene,
        Method::PtUniform,
        &Settings {
            budget: Budget::Spp(4096),
            seed: 77,
            ..settings.clone()
        },
    );
    let truth = reference::Reference {
        mean: truth.mean,
        image: truth.image,
        variance: truth.variance,
        provenance: String::new(),
        origin: reference::Origin::Rendered,
    };
    let short = get(64);
    assert_eq!(short.origin, reference::Origin::Rendered);
    let long = get(128);
    assert_eq!(long.origin, reference::Origin::Extended(64));
    assert!(
        long.provenance.starts_with("pt-uniform 128 spp"),
        "{}",
        long.provenance
    );
    let ratio = variance(&long) / variance(&short);
    assert!((0.4..0.6).contains(&ratio), "variance ratio {ratio}");
    let (e_short, e_long) = (
        metrics::errors(&short.image, &truth).relmse_raw,
        metrics::errors(&long.image, &truth).relmse_raw,
    );
    assert!(
        (0.35..0.7).contains(&(e_long / e_short)),
        "relMSE {e_short} -> {e_long}"
    );
    let again = get(100);
    assert_eq!(again.origin, reference::Origin::Cached);
    assert_eq!(again.image, long.image);
    std::fs::remove_dir_all(&out).ok();
}

/// The reference committed for the README's main job is the default
/// scene's at the default size, as the scene is now: a change of the scene
/// (its fingerprint) without a new committed reference fails here, so the
/// main job never silently renders its reference again or compares against
/// another scene's. It loads as the job loads it, holds a long render, and
/// an extension of it is written to the cache, never to the repository.
#[test]
fn the_committed_reference_is_the_default_scenes() {
    let scene = scenes::build(scenes::DEFAULT, scenes::Size::Full).unwrap();
    let (w, h) = scenes::DEFAULT_SIZE;
    let committed = std::path::Path::new(reference::COMMITTED);
    let stem = reference::stem_in(committed, &scene, w, h, Method::PtBvh);
    let (img, var, meta) = reference::paths(&stem);
    for f in [&img, &var, &meta] {
        assert!(
            f.exists(),
            "no committed reference {} for the default scene {} (fingerprint {:016x}): render one \
             with `cargo run --release --bin render -- --reference-only --reference-spp 4096 \
             --export-reference examples/render/references` (examples/render/references/README.md)",
            f.display(),
            scenes::DEFAULT,
            scene.fingerprint
        );
    }
    let out = std::env::temp_dir().join(format!("guiding-committed-{}", std::process::id()));
    let settings = Settings {
        width: w,
        height: h,
        budget: Budget::Spp(1),
        params: GuideParams::default(),
        seed: 1,
        progress: false,
        guide_files: Default::default(),
    };
    let r = reference::load_or_render(
        &scene,
        &out,
        &settings,
        Method::PtBvh,
        Budget::Spp(1),
        false,
    )
    .unwrap();
    assert_eq!(r.origin, reference::Origin::Committed);
    assert_eq!(r.image.len(), (w * h) as usize);
    assert!(r.mean > 0.0 && r.mean.is_finite());
    let spp: u64 = r
        .provenance
        .split_whitespace()
        .nth(1)
        .unwrap()
        .parse()
        .unwrap();
    assert!(spp >= 4096, "{}", r.provenance);
    // Nothing was written to the cache: the budget was met.
    assert!(!out.exists());
    // Control: another scene's fingerprint finds nothing committed.
    let mut other = scene;
    other.fingerprint ^= 1;
    let stem = reference::stem_in(committed, &other, w, h, Method::PtBvh);
    assert!(!reference::paths(&stem).0.exists());
}
