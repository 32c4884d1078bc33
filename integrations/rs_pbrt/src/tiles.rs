//! Tile order, as rs_pbrt's own integrators render: threads take 16x16
//! tiles from a queue and render each to completion (all its samples per
//! pixel), and the GLT is shared through a `SharedGuide` whose read guard
//! each path holds. How the guide learns is the `learning` rule.

use crate::glue::GltRef;
use crate::path_tracer::{Image, Rng, sample_pixel};
use crate::scene_file::Loaded;
use guiding::glam::Vec3;
use guiding::{Glt, LightTree, RefineSchedule, SharedGuide};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::Instant;

/// The tile's side in pixels (pbrt-v3's and rs_pbrt's).
const TILE: usize = 16;

/// The rules compared: when the shared guide refines.
pub const LEARNING: [&str; 5] = ["never", "waves", "auto", "amortized:20", "doubling:4096"];

/// When to refine.
enum Rule {
    /// Never: the prior all along.
    Never,
    /// After every wave of as many tiles as there are threads (the recipe
    /// that needs a tile hook and the thread count).
    Waves(usize),
    /// When the guide's schedule says so (`SharedGuide::refine_when_due`
    /// after every path): `auto` is the GLT's own schedule.
    WhenDue,
}

/// The shared GLT for rule `name`: `auto`, `never` and `waves` with the
/// GLT's schedule, `amortized:K` and `doubling:N` with that one.
pub fn guide(glt: Glt<LightTree>, name: &str) -> Result<SharedGuide<Glt<LightTree>>, String> {
    let schedule = match name.split_once(':') {
        Some(("amortized", k)) => RefineSchedule::Amortized {
            ratio: k.parse().map_err(|e| format!("{name}: {e}"))?,
        },
        Some(("doubling", n)) => RefineSchedule::Doubling {
            first: n.parse().map_err(|e| format!("{name}: {e}"))?,
        },
        _ => return Ok(SharedGuide::new(glt)),
    };
    SharedGuide::with_schedule(glt, schedule).map_err(|e| e.to_string())
}

/// What a render in tile order did.
pub struct TileRun {
    /// The image.
    pub image: Image,
    /// Refinements run.
    pub refinements: u64,
    /// Seconds.
    pub seconds: f64,
}

/// Renders `spp` samples per pixel in tile order on the rayon pool's
/// thread count, learning by `learning`.
pub fn render_tiles(
    loaded: &Loaded,
    guide: &SharedGuide<Glt<LightTree>>,
    emitters: u32,
    spp: u32,
    seed: u64,
    learning: &str,
) -> Result<TileRun, String> {
    let threads = rayon::current_num_threads();
    let rule = match learning {
        "never" => Rule::Never,
        "waves" => Rule::Waves(threads),
        _ => Rule::WhenDue,
    };
    let (w, h) = loaded.resolution;
    let (tx, ty) = (w.div_ceil(TILE), h.div_ceil(TILE));
    let next_tile = AtomicUsize::new(0);
    let tiles_done = AtomicUsize::new(0);
    let start = Instant::now();
    let refinements0 = guide.refinements();
    let tiles: Vec<Vec<(usize, Vec3)>> = std::thread::scope(|s| {
        let workers: Vec<_> = (0..threads)
            .map(|_| {
                s.spawn(|| {
                    let mut out = Vec::new();
                    loop {
                        let t = next_tile.fetch_add(1, Ordering::Relaxed);
                        if t >= tx * ty {
                            break;
                        }
                        let (x0, y0) = (t % tx * TILE, t / tx * TILE);
                        for y in y0..(y0 + TILE).min(h) {
                            for x in x0..(x0 + TILE).min(w) {
                                let pixel = y * w + x;
                                let mut rng = Rng::new(pixel as u64, seed);
                                let mut sum = Vec3::ZERO;
                                for _ in 0..spp {
                                    let g = guide.read();
                                    sum += sample_pixel(
                                        loaded,
                                        &GltRef(&g, emitters),
                                        (x, y),
                                        &mut rng,
                                    );
                                    drop(g);
                                    if let Rule::WhenDue = rule {
                                        guide.refine_when_due(1);
                                    }
                                }
                                out.push((pixel, sum));
                            }
                        }
                        let done = tiles_done.fetch_add(1, Ordering::Relaxed) + 1;
                        if let Rule::Waves(n) = rule
                            && done.is_multiple_of(n)
                        {
                            guide.refine();
                        }
                    }
                    out
                })
            })
            .collect();
        workers.into_iter().map(|w| w.join().unwrap()).collect()
    });
    let mut image = Image::new(loaded.resolution);
    for (pixel, sum) in tiles.into_iter().flatten() {
        image.sum[pixel] = sum;
    }
    image.spp = spp;
    Ok(TileRun {
        image,
        refinements: guide.refinements() - refinements0,
        seconds: start.elapsed().as_secs_f64(),
    })
}
