//! When does a refitted light tree deserve a rebuild? Lights move frame
//! after frame; each frame the tree built at frame 0 is refitted
//! ([`LightTree::refit`], which returns how far the tree drifted) and a new tree is built from the frame's lights. At fixed points
//! the exact per-sample variance of light selection by the light BVH's
//! importance (pbrt-v4's sampler, the GLT's prior and below-cut rule) is
//! computed for both trees by enumerating every light's pmf against an
//! unshadowed contribution; their ratio says what the refit costs in
//! samples, beside the drift the renderer sees (`LightTree::REBUILD_RATIO`
//! was chosen from it).
//!
//! Three motions of 2,000 mixed lights in a box 100 wide: every light on
//! its own random walk (1 per frame), the lights in two halves drifting
//! apart (0.5 per frame each way), and lights that only flicker (power
//! changing 2x either way every frame, nothing moving).
//!
//! ```text
//! cargo run --release --example refit_drift
//! ```

use glam::Vec3;
use guiding::light_sampler::ImportanceTreeSampler;
use guiding::light_tree::BuildHeuristic;
use guiding::math::Aabb;
use guiding::{Emitter, LightId, LightSampler, LightTree, ShadingContext};
use rayon::prelude::*;

#[path = "../tests/common/mod.rs"]
mod common;
use common::{Rand, contribution, mixed_scene};

const LIGHTS: usize = 2000;
const POINTS: usize = 200;
/// Scenes (seeds) each motion is averaged over: one tree's variance
/// differs from another's over the same lights by some 20%.
const SEEDS: u64 = 4;
const FRAMES: [usize; 9] = [0, 1, 2, 4, 8, 16, 32, 64, 128];

/// The exact relative variance per sample of choosing a light with the
/// importance sampler over `tree` and estimating the sum of the lights'
/// contributions at each point, averaged over `points` (0 where nothing
/// contributes).
fn variance(tree: &LightTree, lights: &[Emitter], points: &[Vec3]) -> f64 {
    let sampler = ImportanceTreeSampler::new(tree);
    let per_point: Vec<f64> = points
        .par_iter()
        .map(|&p| {
            let ctx = ShadingContext::at(p);
            let (mut sum, mut second) = (0.0, 0.0);
            for (i, e) in lights.iter().enumerate() {
                let f = contribution(e, p);
                if f <= 0.0 {
                    continue;
                }
                let pmf = sampler.pmf_exact(&ctx, LightId::Emitter(i as u32));
                sum += f;
                second += if pmf > 0.0 {
                    f * f / pmf
                } else {
                    f64::INFINITY
                };
            }
            if sum > 0.0 {
                second / (sum * sum) - 1.0
            } else {
                0.0
            }
        })
        .collect();
    per_point.iter().sum::<f64>() / points.len() as f64
}

fn moved(e: &Emitter, d: Vec3) -> Emitter {
    Emitter {
        bounds: Aabb::new(e.bounds.min + d, e.bounds.max + d),
        ..*e
    }
}

fn main() {
    let mut rng = Rand::new(2);
    let points: Vec<Vec3> = (0..POINTS).map(|_| rng.point(50.0)).collect();
    type Motion = fn(&[Emitter], &[Emitter], &mut Rand) -> Vec<Emitter>;
    let motions: [(&str, Motion); 3] = [
        ("random walk, 1 per frame", |l, _, r| {
            l.iter().map(|e| moved(e, r.dir() * 1.0)).collect()
        }),
        (
            "two halves drifting apart, 0.5 per frame each",
            |l, _, _| {
                l.iter()
                    .enumerate()
                    .map(|(i, e)| {
                        let side = if i % 2 == 0 { 1.0 } else { -1.0 };
                        moved(e, Vec3::X * 0.5 * side)
                    })
                    .collect()
            },
        ),
        (
            "flicker, power 2x either way around the first frame's",
            |l, _, r| {
                l.iter()
                    .zip(mixed_scene(LIGHTS, 1))
                    .map(|(e, first)| Emitter {
                        power: first.power * 2f32.powf(r.range(-1.0, 1.0)),
                        ..*e
                    })
                    .collect()
            },
        ),
    ];
    println!(
        "Refit vs rebuild: exact relative variance per sample of the light BVH's importance \
         sampling, {LIGHTS} mixed lights, {POINTS} points; means over {SEEDS} scenes (the \
         ratio: geometric mean)\n"
    );
    for (name, step) in motions {
        println!("{name}");
        println!(
            "| frame | drift (refit) | variance, refitted | variance, rebuilt | refitted / rebuilt |"
        );
        println!("| ---: | ---: | ---: | ---: | ---: |");
        let mut rows = vec![(0.0f64, 0.0f64, 0.0f64, 0.0f64); FRAMES.len()];
        for seed in 0..SEEDS {
            let start = mixed_scene(LIGHTS, 10 + seed);
            let mut rng = Rand::new(3 + seed);
            let mut lights = start.clone();
            let mut refitted = LightTree::build(lights.as_slice(), BuildHeuristic::Sarh).unwrap();
            let mut frame = 0;
            for (row, &target) in rows.iter_mut().zip(&FRAMES) {
                while frame < target {
                    frame += 1;
                    lights = step(&lights, &start, &mut rng);
                }
                let ratio = refitted.refit(lights.as_slice()).unwrap();
                let rebuilt = LightTree::build(lights.as_slice(), BuildHeuristic::Sarh).unwrap();
                let (a, b) = (
                    variance(&refitted, &lights, &points),
                    variance(&rebuilt, &lights, &points),
                );
                let n = SEEDS as f64;
                row.0 += ratio as f64 / n;
                row.1 += a / n;
                row.2 += b / n;
                row.3 += (a / b).ln() / n;
            }
        }
        for (&frame, r) in FRAMES.iter().zip(&rows) {
            println!(
                "| {frame} | {:.3} | {:.3} | {:.3} | {:.3} |",
                r.0,
                r.1,
                r.2,
                r.3.exp()
            );
        }
        println!();
    }
}
