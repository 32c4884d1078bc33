//! Tile order: how pbrt-v3, rs_pbrt and most CPU renderers cover an image.
//! Each 16x16 tile is rendered to completion (every sample of every pixel)
//! before the tiles after it, in Morton order, by a pool of threads; a
//! guided method records into its structures as it goes and refines them
//! by a [`Refinement`] rule between waves of tiles. The image is the mean
//! of each pixel's samples (no iterations to combine).
//!
//! Waves of [`WAVE`] tiles are rendered in parallel; everything a wave
//! records goes in before the next refinement, so the result does not
//! depend on the thread count (deterministic mode) and a refinement sees
//! what a renderer's pool would have finished by then.

use crate::integrator::{Recorder, radiance};
use crate::methods::{Method, fixed_sampler, new_field, new_glt, new_sd_tree};
use crate::rng::Sampler;
use crate::run::{Rendered, Settings, guides, mean_luminance, refine};
use crate::scene::Scene;
use glam::Vec3;
use rayon::prelude::*;
use std::time::Instant;

/// Tiles rendered in parallel between two chances to refine.
pub const WAVE: usize = 8;

/// The tile size in pixels.
const TILE: u32 = 16;

/// When a tile-order render refines what its guided method learned.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Refinement {
    /// Never: the guided method samples from its untrained prior.
    Never,
    /// After 1, 3, 7, 15, 31, ... passes' worth of paths (the whole
    /// image's pixel count times that many samples), as a pass-order
    /// render would: the one-pass recipe rs_pbrt was first wired with.
    Doubling,
    /// After every wave of tiles; the structures decide per cell whether
    /// they have seen enough to change.
    EveryWave,
}

impl Refinement {
    /// Parses `never`, `doubling` or `every-wave`.
    pub fn parse(s: &str) -> Result<Refinement, String> {
        match s {
            "never" => Ok(Refinement::Never),
            "doubling" => Ok(Refinement::Doubling),
            "every-wave" => Ok(Refinement::EveryWave),
            _ => Err(format!(
                "unknown refinement {s:?} (never, doubling, every-wave)"
            )),
        }
    }
}

/// A pixel's samples: sums of the values and their squares (RGB and
/// luminance), in `f64`.
#[derive(Clone, Copy, Debug, Default)]
struct Moments {
    sum: glam::DVec3,
    sum_sq: glam::DVec3,
    lum: f64,
    lum_sq: f64,
}

impl Moments {
    fn add(&mut self, l: Vec3) {
        let l64 = l.as_dvec3();
        self.sum += l64;
        self.sum_sq += l64 * l64;
        let y = f64::from(guiding::luminance(l));
        self.lum += y;
        self.lum_sq += y * y;
    }
}

/// Interleaves the bits of `x` and `y` (x in the even bits).
fn morton(x: u32, y: u32) -> u64 {
    let spread = |v: u32| {
        let mut v = u64::from(v);
        v = (v | (v << 16)) & 0x0000_ffff_0000_ffff;
        v = (v | (v << 8)) & 0x00ff_00ff_00ff_00ff;
        v = (v | (v << 4)) & 0x0f0f_0f0f_0f0f_0f0f;
        v = (v | (v << 2)) & 0x3333_3333_3333_3333;
        (v | (v << 1)) & 0x5555_5555_5555_5555
    };
    spread(x) | (spread(y) << 1)
}

/// The tiles' top-left corners in Morton order.
pub fn tiles_in_morton_order(width: u32, height: u32) -> Vec<(u32, u32)> {
    let mut tiles: Vec<(u32, u32)> = (0..height.div_ceil(TILE))
        .flat_map(|ty| (0..width.div_ceil(TILE)).map(move |tx| (tx, ty)))
        .collect();
    tiles.sort_by_key(|&(tx, ty)| morton(tx, ty));
    tiles
        .into_iter()
        .map(|(tx, ty)| (tx * TILE, ty * TILE))
        .collect()
}

/// Renders `scene` with `method` in tile order, `spp` samples per pixel,
/// refining by `rule`.
pub fn render_tiles(
    scene: &Scene,
    method: Method,
    settings: &Settings,
    spp: u64,
    rule: Refinement,
) -> Rendered {
    let start = Instant::now();
    let (w, h) = (settings.width, settings.height);
    let pixels = u64::from(w) * u64::from(h);
    let fixed = fixed_sampler(scene, method);
    let mut glt = new_glt(scene, method, &settings.params);
    let mut sd_tree = new_sd_tree(scene, method, &settings.params);
    let mut field = new_field(scene, method, &settings.params);
    let learns = method.is_trained() && rule != Refinement::Never;
    let mut moments = vec![Moments::default(); pixels as usize];
    let tiles = tiles_in_morton_order(w, h);
    // Samples rendered so far, and the pass count whose worth of samples
    // triggers the next `Doubling` refinement.
    let (mut samples, mut next_worth, mut refinements) = (0u64, 1u64, 0u32);
    let mut vertices = 0u64;
    for chunk in tiles.chunks(WAVE) {
        let guides = guides(&fixed, &glt, &sd_tree, &field, &settings.params, learns);
        let rendered: Vec<(Vec<Moments>, u64)> = chunk
            .par_iter()
            .map(|&(x0, y0)| {
                let mut recorder = Recorder::new();
                let mut tile_vertices = 0u64;
                let mut out = Vec::with_capacity((TILE * TILE) as usize);
                for y in y0..(y0 + TILE).min(h) {
                    for x in x0..(x0 + TILE).min(w) {
                        let mut m = Moments::default();
                        // One stream per pixel, whatever the tile's wave.
                        let mut s = Sampler::new(settings.seed, u64::from(y * w + x), u64::MAX);
                        for _ in 0..spp {
                            let j = s.next2();
                            let dir = scene.camera.direction(x as f32 + j.x, y as f32 + j.y, w, h);
                            let l = radiance(
                                scene,
                                &guides,
                                scene.camera.eye,
                                dir,
                                &mut s,
                                &mut recorder,
                                &mut tile_vertices,
                            );
                            m.add(l);
                        }
                        out.push(m);
                    }
                }
                (out, tile_vertices)
            })
            .collect();
        for (&(x0, y0), (px, tile_vertices)) in chunk.iter().zip(&rendered) {
            vertices += tile_vertices;
            let mut k = 0;
            for y in y0..(y0 + TILE).min(h) {
                for x in x0..(x0 + TILE).min(w) {
                    moments[(y * w + x) as usize] = px[k];
                    k += 1;
                }
            }
            samples += px.len() as u64 * spp;
        }
        if !learns {
            continue;
        }
        let refine_now = match rule {
            Refinement::Never => false,
            Refinement::EveryWave => true,
            Refinement::Doubling => {
                let due = samples >= next_worth * pixels;
                while samples >= next_worth * pixels {
                    next_worth = 2 * next_worth + 1;
                }
                due
            }
        };
        if refine_now {
            refine(&mut glt, &mut sd_tree, &mut field);
            refinements += 1;
        }
    }
    let n = spp as f64;
    let image: Vec<Vec3> = moments.iter().map(|m| (m.sum / n).as_vec3()).collect();
    // Each pixel's variance of its mean: the sample variance over n.
    let variance_of_mean = |s: f64, q: f64| ((q - s * s / n) / (n - 1.0).max(1.0) / n).max(0.0);
    let variance: Vec<Vec3> = moments
        .iter()
        .map(|m| {
            let v = m.sum.to_array();
            let q = m.sum_sq.to_array();
            Vec3::new(
                variance_of_mean(v[0], q[0]) as f32,
                variance_of_mean(v[1], q[1]) as f32,
                variance_of_mean(v[2], q[2]) as f32,
            )
        })
        .collect();
    let flat: Vec<f32> = image.iter().flat_map(|v| v.to_array()).collect();
    let mean = mean_luminance(&flat);
    let mean_error = moments
        .iter()
        .map(|m| variance_of_mean(m.lum, m.lum_sq))
        .sum::<f64>()
        .sqrt()
        / pixels as f64;
    Rendered {
        width: w,
        height: h,
        image,
        variance,
        spp,
        spp_final: spp,
        seconds: start.elapsed().as_secs_f64(),
        vertices,
        mean,
        mean_error,
        iterations: refinements + 1,
        sd_tree_bytes: sd_tree.as_ref().map_or(0, |t| t.memory().total())
            + field.as_ref().map_or(0, |f| {
                let m = f.memory();
                m.total() - m.cut_bytes()
            }),
        glt_bytes: glt.as_ref().map_or(0, |g| g.memory().total())
            + field.as_ref().map_or(0, |f| f.memory().cut_bytes()),
    }
}
