//! Runs one method on one scene within a budget: passes of one sample per
//! pixel, parallel over tiles; trained methods follow the crate's iteration
//! schedule (2^k passes, the last taking the rest) and combine their last
//! iterations by inverse variance, as PPG does.

use crate::integrator::{Guides, Recorder, radiance};
use crate::methods::{GuideParams, Method, fixed_sampler, new_field, new_glt, new_sd_tree};
use crate::rng::Sampler;
use crate::scene::Scene;
use glam::Vec3;
use guiding::field::GuidingField;
use guiding::glt::Glt;
use guiding::luminance;
use guiding::schedule::{
    InverseVarianceCombiner, Iteration, PassStats, next_iteration, next_iteration_by_time,
};
use guiding::sd_tree::SdTree;
use guiding::{LightSampler, LightTree};
use indicatif::{ProgressBar, ProgressStyle};
use rayon::prelude::*;
use std::collections::VecDeque;
use std::time::Instant;

/// How long a method may render.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Budget {
    /// This many samples per pixel in all (training included).
    Spp(u64),
    /// This much wall-clock time (training included).
    Seconds(f64),
}

/// What a render is asked to do.
#[derive(Clone, Debug)]
pub struct Settings {
    /// Image width.
    pub width: u32,
    /// Image height.
    pub height: u32,
    /// Budget.
    pub budget: Budget,
    /// Learned-structure parameters.
    pub params: GuideParams,
    /// Seed of all random streams.
    pub seed: u64,
    /// Draw a progress bar.
    pub progress: bool,
    /// Where learned guides are loaded from and saved to.
    pub guide_files: GuideFiles,
}

/// Directories of saved guides (`<scene>-<method>.guide` in each).
#[derive(Clone, Debug, Default)]
pub struct GuideFiles {
    /// Start from the guide saved here.
    pub load: Option<std::path::PathBuf>,
    /// Save the learned guide here.
    pub save: Option<std::path::PathBuf>,
    /// Start the doubling schedule over from a loaded guide (the next
    /// frame of an animation: what was learned is a head start, the frame
    /// still renders its whole budget) instead of going on from the
    /// iteration it reached.
    pub restart: bool,
}

impl GuideFiles {
    fn path(dir: &std::path::Path, scene: &Scene, method: Method) -> std::path::PathBuf {
        dir.join(format!("{}-{}.guide", scene.name, method.name()))
    }

    /// The saved guide's bytes for `method` on `scene`, if asked for and
    /// present.
    fn load(&self, scene: &Scene, method: Method) -> Option<Vec<u8>> {
        if method == Method::PpgAndGlt && self.load.is_some() {
            eprintln!(
                "{}: two guides, not loaded (saved guides hold one)",
                method.name()
            );
            return None;
        }
        let path = Self::path(self.load.as_ref()?, scene, method);
        match std::fs::read(&path) {
            Ok(b) => Some(b),
            Err(e) => {
                eprintln!("{}: {e}; training from scratch", path.display());
                None
            }
        }
    }

    /// Writes `bytes` as the guide of `method` on `scene`, if asked for,
    /// and says how its size on disk compares with its size in memory.
    fn save(&self, scene: &Scene, method: Method, bytes: &[u8], memory: usize) {
        let Some(dir) = &self.save else { return };
        if method == Method::PpgAndGlt {
            eprintln!(
                "{}: two guides, not saved (saved guides hold one)",
                method.name()
            );
            return;
        }
        let path = Self::path(dir, scene, method);
        match std::fs::create_dir_all(dir).and_then(|()| std::fs::write(&path, bytes)) {
            Ok(()) => println!(
                "saved {}: {:.3} MB on disk, {:.3} MB in memory",
                path.display(),
                bytes.len() as f64 / 1e6,
                memory as f64 / 1e6
            ),
            Err(e) => eprintln!("{}: {e}", path.display()),
        }
    }
}

/// A finished render.
#[derive(Clone, Debug)]
pub struct Rendered {
    /// Width.
    pub width: u32,
    /// Height.
    pub height: u32,
    /// Linear RGB, row-major.
    pub image: Vec<Vec3>,
    /// Estimated variance of each pixel's value (per channel).
    pub variance: Vec<Vec3>,
    /// Samples per pixel rendered, training iterations included.
    pub spp: u64,
    /// Samples per pixel of the iterations the image combines.
    pub spp_final: u64,
    /// Wall-clock seconds, training and refinement included.
    pub seconds: f64,
    /// Non-specular path vertices rendered (where a path chooses a
    /// light), training included: `seconds` over these is the wall time
    /// per vertex.
    pub vertices: u64,
    /// Mean luminance of the image.
    pub mean: f64,
    /// Standard error of `mean`.
    pub mean_error: f64,
    /// Training iterations (1 for untrained methods).
    pub iterations: u32,
    /// Bytes of the SD-tree at the end (0 if none).
    pub sd_tree_bytes: usize,
    /// Bytes of the GLT at the end (0 if none).
    pub glt_bytes: usize,
}

const TILE: u32 = 16;

/// Renders one pass (one sample per pixel) into `out` (RGB triples);
/// the non-specular vertices of its paths.
pub fn render_pass(
    scene: &Scene,
    guides: &Guides,
    settings: &Settings,
    pass: u64,
    out: &mut [f32],
) -> u64 {
    let (w, h) = (settings.width, settings.height);
    let tiles: Vec<(u32, u32)> = (0..h.div_ceil(TILE))
        .flat_map(|ty| (0..w.div_ceil(TILE)).map(move |tx| (tx * TILE, ty * TILE)))
        .collect();
    let results: Vec<(Vec<Vec3>, u64)> = tiles
        .par_iter()
        .enumerate()
        .map(|(i, &(x0, y0))| {
            let mut s = Sampler::new(settings.seed, pass, i as u64);
            let mut recorder = Recorder::new();
            let mut vertices = 0u64;
            let mut px = Vec::with_capacity((TILE * TILE) as usize);
            for y in y0..(y0 + TILE).min(h) {
                for x in x0..(x0 + TILE).min(w) {
                    let j = s.next2();
                    let dir = scene.camera.direction(x as f32 + j.x, y as f32 + j.y, w, h);
                    px.push(radiance(
                        scene,
                        guides,
                        scene.camera.eye,
                        dir,
                        &mut s,
                        &mut recorder,
                        &mut vertices,
                    ));
                }
            }
            (px, vertices)
        })
        .collect();
    for (&(x0, y0), (px, _)) in tiles.iter().zip(&results) {
        let mut k = 0;
        for y in y0..(y0 + TILE).min(h) {
            for x in x0..(x0 + TILE).min(w) {
                let o = 3 * (y * w + x) as usize;
                out[o..o + 3].copy_from_slice(&px[k].to_array());
                k += 1;
            }
        }
    }
    results.iter().map(|(_, v)| v).sum()
}

/// Bytes of whichever learned structures a method has.
fn learned_bytes(
    glt: Option<&Glt<&LightTree>>,
    sd_tree: Option<&SdTree>,
    field: Option<&GuidingField<&LightTree>>,
) -> usize {
    glt.map_or(0, |g| g.memory().total())
        + sd_tree.map_or(0, |t| t.memory().total())
        + field.map_or(0, |f| f.memory().total())
}

/// One finished iteration: its statistics and those of its image mean.
struct Done {
    stats: PassStats,
    mean_var: f64,
}

/// The learned structures a render ends with (those its method trains):
/// what its last iteration sampled from.
#[allow(dead_code)] // the `render` example reads none of them; `light_limit` does
pub struct Trained<'a> {
    /// The Guiding Light Tree of `pt-glt`.
    pub glt: Option<Glt<&'a LightTree>>,
    /// The SD-tree of `ppg`.
    pub sd_tree: Option<SdTree>,
    /// The combined field of `ppg-glt`.
    pub field: Option<GuidingField<&'a LightTree>>,
}

/// Renders `scene` with `method` within `settings.budget`.
pub fn render(scene: &Scene, method: Method, settings: &Settings) -> Rendered {
    render_trained(scene, method, settings).0
}

/// What a render would deliver if it stopped now: the image (the
/// inverse-variance combination of the iterations so far, the current one
/// included), its sample count, the render time so far (without the time
/// spent making these samples) and the bytes of the learned structures.
pub struct CurveSample<'i> {
    /// Seconds of rendering so far.
    pub seconds: f64,
    /// Samples per pixel so far, training included.
    pub spp: u64,
    /// Linear RGB triples, row-major.
    pub image: &'i [f32],
    /// Bytes of the learned structures.
    pub bytes: usize,
}

/// The sample counts at which a curve is recorded: 1, 2, 3, 4, 5, 7, 9,
/// ... (each about 1.25 times the last), so points are log-spaced in
/// samples and, for a steady renderer, in time.
pub fn is_curve_point(spp: u64) -> bool {
    let mut next = 1u64;
    while next < spp {
        next = (next as f64 * 1.25).ceil() as u64;
    }
    next == spp
}

/// Like [`render`], also returning the learned structures as the last
/// iteration used them (the `light_limit` example measures them).
pub fn render_trained<'a>(
    scene: &'a Scene,
    method: Method,
    settings: &Settings,
) -> (Rendered, Trained<'a>) {
    render_observed(scene, method, settings, None)
}

/// [`render_trained`], calling `curve` at every [`is_curve_point`] and
/// at the end with what the render would deliver then; the time `curve`
/// takes is not counted as rendering time.
pub fn render_observed<'a>(
    scene: &'a Scene,
    method: Method,
    settings: &Settings,
    mut curve: Option<&mut dyn FnMut(CurveSample<'_>)>,
) -> (Rendered, Trained<'a>) {
    let start = Instant::now();
    // Time spent observing the render, taken off its clock.
    let mut paused = 0.0f64;
    let (w, h) = (settings.width, settings.height);
    let len = (3 * w * h) as usize;
    let fixed = fixed_sampler(scene, method);
    let mut glt = new_glt(scene, method, &settings.params);
    let mut sd_tree = new_sd_tree(scene, method, &settings.params);
    let mut field = new_field(scene, method, &settings.params);
    let trained = method.is_trained();
    // A saved guide replaces the fresh one; the schedule goes on from the
    // iteration it reached.
    let mut k = 0u32;
    if let Some(bytes) = settings.guide_files.load(scene, method) {
        let tree = &scene.light_tree;
        let loaded = if glt.is_some() {
            Glt::from_bytes(&bytes, tree).map(|g| {
                k = g.iteration();
                glt = Some(g);
            })
        } else if sd_tree.is_some() {
            SdTree::from_bytes(&bytes).map(|t| {
                k = t.iteration();
                sd_tree = Some(t);
            })
        } else {
            GuidingField::from_bytes(&bytes, tree).map(|f| {
                k = f.iteration();
                field = Some(f);
            })
        };
        if let Err(e) = loaded {
            eprintln!(
                "{} on {}: saved guide not loaded ({e}); training from scratch",
                method.name(),
                scene.name
            );
        }
        if settings.guide_files.restart {
            k = 0;
            if let Some(g) = &mut glt {
                g.restart();
            }
        }
    }
    let bar = progress_bar(settings, method);
    let mut combiner = InverseVarianceCombiner::new();
    let mut history: VecDeque<Done> = VecDeque::new();
    let mut pass_buf = vec![0.0f32; len];
    let (mut spp, mut sec_per_pass) = (0u64, 0.0f64);
    let mut vertices = 0u64;
    loop {
        let elapsed = start.elapsed().as_secs_f64() - paused;
        let it = match (trained, settings.budget) {
            (true, Budget::Spp(n)) => next_iteration(k, n - spp),
            (true, Budget::Seconds(s)) => next_iteration_by_time(k, s - elapsed, sec_per_pass),
            (false, Budget::Spp(n)) => (spp < n).then_some(Iteration {
                index: 0,
                passes: n,
                is_last: true,
            }),
            (false, Budget::Seconds(_)) => Some(Iteration {
                index: 0,
                passes: u64::MAX,
                is_last: true,
            }),
        };
        let Some(it) = it else { break };
        // Under a time budget the last iteration renders until time is up.
        let passes = match settings.budget {
            Budget::Seconds(_) if it.is_last => u64::MAX,
            _ => it.passes,
        };
        let mut stats = PassStats::new(len);
        let (mut m_sum, mut m_sq) = (0.0f64, 0.0f64);
        let it_start = Instant::now();
        let paused_before = paused;
        for pass in 0..passes {
            if let Budget::Seconds(s) = settings.budget {
                let done = start.elapsed().as_secs_f64() - paused;
                let per = if pass > 0 {
                    (it_start.elapsed().as_secs_f64() - (paused - paused_before)) / pass as f64
                } else {
                    0.0
                };
                if pass > 0 && it.is_last && done + 0.5 * per > s {
                    break;
                }
                bar.set_position((done * 1000.0) as u64);
            }
            let train = trained && !it.is_last;
            let guides = guides(&fixed, &glt, &sd_tree, &field, &settings.params, train);
            vertices += render_pass(scene, &guides, settings, spp, &mut pass_buf);
            stats.add_pass(&pass_buf);
            let m = mean_luminance(&pass_buf);
            m_sum += m;
            m_sq += m * m;
            spp += 1;
            if let Budget::Spp(_) = settings.budget {
                bar.set_position(spp);
            }
            if let Some(observe) = curve.as_mut()
                && is_curve_point(spp)
            {
                let t = Instant::now();
                let seconds = start.elapsed().as_secs_f64() - paused;
                let mut now = combiner.clone();
                now.push_stats(&stats);
                let image = now.combine();
                let bytes = learned_bytes(glt.as_ref(), sd_tree.as_ref(), field.as_ref());
                observe(CurveSample {
                    seconds,
                    spp,
                    image: &image,
                    bytes,
                });
                paused += t.elapsed().as_secs_f64();
            }
        }
        let n = stats.passes();
        if n == 0 {
            break;
        }
        sec_per_pass = (it_start.elapsed().as_secs_f64() - (paused - paused_before)) / n as f64;
        let mean = m_sum / n as f64;
        let mean_var = if n > 1 {
            ((m_sq - n as f64 * mean * mean) / ((n - 1) as f64 * n as f64)).max(0.0)
        } else {
            f64::NAN
        };
        combiner.push_stats(&stats);
        if history.len() == InverseVarianceCombiner::MAX_COMBINED {
            history.pop_front();
        }
        history.push_back(Done { stats, mean_var });
        if it.is_last {
            break;
        }
        refine(&mut glt, &mut sd_tree, &mut field);
        k += 1;
    }
    bar.finish_and_clear();
    let seconds = start.elapsed().as_secs_f64() - paused;
    let flat = combiner.combine();
    if let Some(observe) = curve.as_mut()
        && !is_curve_point(spp)
    {
        observe(CurveSample {
            seconds,
            spp,
            image: &flat,
            bytes: learned_bytes(glt.as_ref(), sd_tree.as_ref(), field.as_ref()),
        });
    }
    let weights = combiner.weights();
    let mut variance = vec![Vec3::ZERO; (w * h) as usize];
    let (mut mean_error2, mut spp_final) = (0.0f64, 0u64);
    for (done, &wt) in history.iter().zip(&weights) {
        if wt <= 0.0 {
            continue;
        }
        spp_final += done.stats.passes();
        mean_error2 += wt * wt * done.mean_var;
        for (i, v) in variance.iter_mut().enumerate() {
            for c in 0..3 {
                let var = done.stats.variance_of_mean(3 * i + c).unwrap_or(0.0);
                v[c] += (wt * wt * var) as f32;
            }
        }
    }
    let image: Vec<Vec3> = flat.chunks_exact(3).map(Vec3::from_slice).collect();
    let rendered = Rendered {
        width: w,
        height: h,
        mean: mean_luminance(&flat),
        image,
        variance,
        spp,
        spp_final,
        seconds,
        vertices,
        mean_error: mean_error2.sqrt(),
        iterations: k + 1,
        // For the field: the cuts are the GLT's share, the rest (spatial
        // tree, quadtrees, statistics) the SD-tree's.
        sd_tree_bytes: sd_tree.as_ref().map_or(0, |t| t.memory().total())
            + field.as_ref().map_or(0, |f| {
                let m = f.memory();
                m.total() - m.cut_bytes()
            }),
        glt_bytes: glt.as_ref().map_or(0, |g| g.memory().total())
            + field.as_ref().map_or(0, |f| f.memory().cut_bytes()),
    };
    let files = &settings.guide_files;
    if let Some(g) = &glt {
        files.save(scene, method, &g.to_bytes(), g.memory().total());
    }
    if let Some(t) = &sd_tree {
        files.save(scene, method, &t.to_bytes(), t.memory().total());
    }
    if let Some(f) = &field {
        files.save(scene, method, &f.to_bytes(), f.memory().total());
    }
    let learned = Trained {
        glt,
        sd_tree,
        field,
    };
    (rendered, learned)
}

/// What a path consults and trains with a method's samplers: its fixed
/// light sampler, or the structures it trains (recording if `train`).
pub fn guides<'r, 's: 'r>(
    fixed: &'r Option<Box<dyn LightSampler + Sync + 's>>,
    glt: &'r Option<Glt<&'s LightTree>>,
    sd_tree: &'r Option<SdTree>,
    field: &'r Option<GuidingField<&'s LightTree>>,
    params: &GuideParams,
    train: bool,
) -> Guides<'r> {
    assert!(
        fixed.is_some() || glt.is_some() || field.is_some(),
        "every method has a light sampler"
    );
    Guides {
        lights: fixed.as_deref(),
        glt: glt.as_ref(),
        sd_tree: sd_tree.as_ref(),
        field: field.as_ref(),
        train,
        contribution_records: params.contribution_records,
        resample_vertices: params.resample_vertices,
        nee_samples: params.nee_samples.max(1),
        nee_samples_vertices: params.nee_samples_vertices,
        resample: if fixed.is_none() { params.resample } else { 0 },
    }
}

/// Refines whichever structures a method trains.
pub fn refine(
    glt: &mut Option<Glt<&LightTree>>,
    sd_tree: &mut Option<SdTree>,
    field: &mut Option<GuidingField<&LightTree>>,
) {
    if let Some(g) = glt.as_mut() {
        g.refine();
    }
    if let Some(t) = sd_tree.as_mut() {
        t.refine();
    }
    if let Some(f) = field.as_mut() {
        f.refine();
    }
}

/// Mean luminance of an RGB buffer.
pub fn mean_luminance(rgb: &[f32]) -> f64 {
    let n = (rgb.len() / 3).max(1) as f64;
    rgb.chunks_exact(3)
        .map(|c| f64::from(luminance(Vec3::from_slice(c))))
        .sum::<f64>()
        / n
}

fn progress_bar(settings: &Settings, method: Method) -> ProgressBar {
    if !settings.progress {
        return ProgressBar::hidden();
    }
    let (len, unit) = match settings.budget {
        Budget::Spp(n) => (n, "spp"),
        Budget::Seconds(s) => ((s * 1000.0) as u64, "ms"),
    };
    let bar = ProgressBar::new(len);
    let template = format!("{{msg:>10}} [{{bar:40}}] {{pos}}/{{len}} {unit}");
    if let Ok(style) = ProgressStyle::with_template(&template) {
        bar.set_style(style.progress_chars("=> "));
    }
    bar.set_message(method.name());
    bar
}
