//! Light linking: should a GLT learn one state for every light set (each
//! point's query masked to the sets it receives) or one state per set?
//!
//! Lights are put in `S` light sets; shading points each receive one set.
//! Both ways get the same records: a renderer's loop that samples a light
//! with the GLT at the point (lit by its set), records what it brought
//! (unshadowed contribution over pmf) and refines, `ITERATIONS` times.
//! **Masked**: one GLT gets every record and answers every point through
//! `ShadingContext::lit_by`. **Per set**: one GLT per set, each fed only
//! its own points' records (the same total), answering its own points.
//! Judged by the exact relative variance per sample at fresh points
//! (every light's pmf against its contribution, which a clairvoyant pmf
//! would have at 0), beside the light BVH's importance sampling restricted
//! the same way, and by memory.
//!
//! The box has walls: four rooms along z, a light lighting only its own
//! (without them the importance alone is near the best choice and there is
//! nothing to learn). Two ways lights fall in sets: **interleaved** (each light in a random
//! set: the worst case for a shared state, every cluster mixes sets) and
//! **regional** (a light's set by where it is: slabs along x, as when an
//! object's rig lights stand around it). Points receive a random set in
//! both, so every cell of a shared state sees every set.
//!
//! ```text
//! cargo run --release --example light_sets
//! ```

use glam::Vec3;
use guiding::LightChoice;
use guiding::glt::{Glt, GltConfig};
use guiding::light_sampler::ImportanceTreeSampler;
use guiding::light_tree::BuildHeuristic;
use guiding::math::Aabb;
use guiding::{Emitter, LightId, LightSampler, LightTree, ShadingContext};
use rayon::prelude::*;

#[path = "../tests/common/mod.rs"]
mod common;
use common::{Rand, mixed_scene};

/// Walls split the box into `ROOMS` rooms along z: a light lights only its
/// own room (so there is something to learn beyond the importance).
const ROOMS: f32 = 4.0;

fn room(p: Vec3) -> i32 {
    ((p.z + 60.0) / 120.0 * ROOMS).floor() as i32
}

/// The contribution of `e` at `p`: the unshadowed one in its own room, 0
/// through a wall.
fn contribution(e: &Emitter, p: Vec3) -> f64 {
    match room(e.bounds.center()) == room(p) {
        true => common::contribution(e, p),
        false => 0.0,
    }
}

const LIGHTS: usize = 4000;
const RECORDS: usize = 400_000;
const ITERATIONS: usize = 4;
const POINTS: usize = 400;
const SEEDS: u64 = 4;

fn bounds() -> Aabb {
    Aabb::new(Vec3::splat(-60.0), Vec3::splat(60.0))
}

/// The lights' sets: interleaved (random) or regional (slabs along x).
fn assign(lights: &[Emitter], sets: u32, regional: bool, r: &mut Rand) -> Vec<Emitter> {
    lights
        .iter()
        .map(|e| {
            let set = if regional {
                let x = (e.bounds.center().x + 50.0) / 100.0;
                ((x * sets as f32) as u32).min(sets - 1)
            } else {
                r.below(sets)
            };
            e.in_light_sets(1 << set)
        })
        .collect()
}

/// One iteration of a renderer's loop at `n` points of `set`'s receivers
/// (or of random sets when `set` is `None`): sample with the GLT, record
/// contribution over pmf.
fn train(
    glt: &mut Glt<&LightTree>,
    lights: &[Emitter],
    sets: u32,
    set: Option<u32>,
    n: usize,
    r: &mut Rand,
) {
    for _ in 0..n {
        let p = r.point(50.0);
        let s = set.unwrap_or_else(|| r.below(sets));
        let ctx = ShadingContext::at(p).lit_by(1 << s);
        let Some(v) = glt.vertex(&ctx) else { continue };
        let Some(x) = v.sample(r.f()) else {
            continue;
        };
        let LightId::Emitter(e) = x.light else {
            continue;
        };
        let f = contribution(&lights[e as usize], p) as f32;
        v.record_light(x.light, f / x.pmf);
    }
    glt.refine();
}

/// The exact relative variance per sample of `sampler` at `ctx` over the
/// lights it is lit by (0 where none contributes).
fn variance(sampler: &dyn LightChoice, lights: &[Emitter], ctx: &ShadingContext) -> f64 {
    let lit: Vec<(u32, f64)> = (0..lights.len() as u32)
        .filter(|&i| lights[i as usize].light_sets & ctx.receives != 0)
        .map(|i| (i, contribution(&lights[i as usize], ctx.position)))
        .collect();
    let sum: f64 = lit.iter().map(|x| x.1).sum();
    if sum <= 0.0 {
        return 0.0;
    }
    // In shares of the sum: the squares of powers near 1e30 overflow.
    let second: f64 = lit
        .iter()
        .map(|&(i, f)| {
            let pmf = sampler.pmf_exact(LightId::Emitter(i));
            let s = f / sum;
            if pmf > 0.0 {
                s * s / pmf
            } else if s > 0.0 {
                f64::INFINITY
            } else {
                0.0
            }
        })
        .sum();
    second - 1.0
}

fn glt(tree: &LightTree) -> Glt<&LightTree> {
    Glt::new(tree, bounds(), GltConfig::default()).unwrap()
}

fn main() {
    println!(
        "Light linking: one GLT masked per query vs one GLT per set; {LIGHTS} mixed lights, \
         {RECORDS} records x {ITERATIONS} iterations in all, exact relative variance per sample \
         at {POINTS} fresh points each receiving one random set, over {SEEDS} scenes: the BVH's \
         mean, the others as geometric means of per-point ratios (1 set: two GLTs alike, the \
         noise)\n"
    );
    println!(
        "| lights in sets | sets | BVH variance | masked / BVH | per-set / BVH | per-set / masked | memory masked | memory per set |"
    );
    println!("| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: |");
    for regional in [false, true] {
        for sets in [1u32, 2, 4, 8, 16] {
            let mut row = [0.0f64; 5];
            let mut memory = (0usize, 0usize);
            for seed in 0..SEEDS {
                let mut r = Rand::new(40 + seed);
                let lights = assign(&mixed_scene(LIGHTS, 20 + seed), sets, regional, &mut r);
                let tree = LightTree::build(lights.as_slice(), BuildHeuristic::Sarh).unwrap();
                let mut masked = glt(&tree);
                let mut per_set: Vec<_> = (0..sets).map(|_| glt(&tree)).collect();
                for _ in 0..ITERATIONS {
                    train(
                        &mut masked,
                        &lights,
                        sets,
                        None,
                        RECORDS / ITERATIONS,
                        &mut r,
                    );
                    for (s, g) in per_set.iter_mut().enumerate() {
                        let n = RECORDS / ITERATIONS / sets as usize;
                        train(g, &lights, sets, Some(s as u32), n, &mut r);
                    }
                }
                memory.0 += masked.memory().total() / SEEDS as usize;
                memory.1 +=
                    per_set.iter().map(|g| g.memory().total()).sum::<usize>() / SEEDS as usize;
                let bvh = ImportanceTreeSampler::new(&tree);
                let points: Vec<(Vec3, u32)> = (0..POINTS)
                    .map(|_| (r.point(50.0), r.below(sets)))
                    .collect();
                let v: Vec<[f64; 3]> = points
                    .par_iter()
                    .map(|&(p, s)| {
                        let ctx = ShadingContext::at(p).lit_by(1 << s);
                        let m = masked.vertex(&ctx).unwrap();
                        let q = per_set[s as usize].vertex(&ctx).unwrap();
                        [
                            variance(&bvh.at(&ctx), &lights, &ctx),
                            variance(&m, &lights, &ctx),
                            variance(&q, &lights, &ctx),
                        ]
                    })
                    .collect();
                // Geometric means of per-point ratios: the mean variance
                // is ruled by a few points (two identical GLTs fed
                // different records differ by 30% in it).
                let kept: Vec<&[f64; 3]> =
                    v.iter().filter(|x| x.iter().all(|&y| y > 0.0)).collect();
                let log_ratio = |a: usize, b: usize| {
                    kept.iter().map(|x| (x[a] / x[b]).ln()).sum::<f64>() / kept.len() as f64
                };
                let n = SEEDS as f64;
                row[0] += v.iter().map(|x| x[0]).sum::<f64>() / POINTS as f64 / n;
                row[1] += log_ratio(1, 0) / n;
                row[2] += log_ratio(2, 0) / n;
                row[3] += log_ratio(2, 1) / n;
            }
            println!(
                "| {} | {sets} | {:.3} | {:.3} | {:.3} | {:.2} | {:.1} MB | {:.1} MB |",
                if regional { "regional" } else { "interleaved" },
                row[0],
                row[1].exp(),
                row[2].exp(),
                row[3].exp(),
                memory.0 as f64 / 1e6,
                memory.1 as f64 / 1e6,
            );
        }
    }
}
