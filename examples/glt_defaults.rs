//! The measurement behind the GLT's defaults (`alpha`, `BelowCut`,
//! `SplitPrior`): the exact relative variance of the NEE estimator after
//! training, in a synthetic scene. A measurement, not a check (it was an
//! ignored test that no run executed); run it with
//!
//! ```text
//! cargo run --release --example glt_defaults
//! ```
//!
//! optionally with `GLT_TRAIN=200000` (records per iteration) and
//! `GLT_SEED=2`. Scene: 2000 emitters (a third point lights, the rest small
//! one-sided quads with random normals) above a floor divided into 8x8-unit
//! rooms; a light is visible from the floor in its own room, and from the
//! neighbouring rooms when it hangs low (through a door). Contribution:
//! power x both cosines / distance^2. A [`Glt`] is trained for five
//! iterations, sampling from itself; then at 300 floor points the second
//! moment `sum_l f_l^2 / pmf_l` is summed exactly over all lights, so the
//! printed relative variance `sum (m2 - F^2) / sum F^2` has no Monte Carlo
//! noise of its own (only the training's).

use glam::Vec3;
use guiding::LightChoice;
use guiding::cut::{BelowCut, CutConfig, SplitPrior};
use guiding::glt::{Glt, GltConfig};
use guiding::light_tree::BuildHeuristic;
use guiding::math::Aabb;
use guiding::{Emitter, LightId, LightTree, ShadingContext};

#[path = "../tests/common/mod.rs"]
mod common;
use common::Rand;

fn env(name: &str, default: u64) -> u64 {
    std::env::var(name)
        .ok()
        .and_then(|x| x.parse().ok())
        .unwrap_or(default)
}

fn main() {
    let train = env("GLT_TRAIN", 20_000) as usize;
    let seed = env("GLT_SEED", 1);
    let mut rng = Rand::new(5);
    let lights: Vec<Emitter> = (0..2000)
        .map(|i| {
            let p = Vec3::new(
                rng.f() * 40.0 - 20.0,
                2.0 + rng.f() * 8.0,
                rng.f() * 40.0 - 20.0,
            );
            let power = 0.1 + 10.0 * rng.f().powi(3);
            if i % 3 == 0 {
                Emitter::point(p, power)
            } else {
                let n = Vec3::new(rng.f() - 0.5, rng.f() - 0.5, rng.f() - 0.5)
                    .normalize_or(Vec3::NEG_Y);
                Emitter::area(Aabb::new(p - 0.1, p + 0.1), n, 0.04, power)
            }
        })
        .collect();
    let tree = LightTree::build(&lights, BuildHeuristic::Sarh).unwrap();
    let room =
        |p: Vec3| ((p.x + 20.0) / 8.0).floor() as i32 * 10 + ((p.z + 20.0) / 8.0).floor() as i32;
    let f = |e: usize, p: Vec3| -> f64 {
        let l = &lights[e];
        let c = l.bounds.center();
        let d = c - p;
        let dist2 = d.length_squared().max(0.01);
        let dir = d / dist2.sqrt();
        let cos = dir.y.max(0.0);
        let emit = l.cone.map_or(1.0, |cone| (-dir).dot(cone.axis).max(0.0));
        let visible = room(p) == room(c) || ((room(p) - room(c)).abs() == 1 && c.y < 4.0);
        if visible {
            (l.power * cos * emit / dist2) as f64
        } else {
            0.0
        }
    };
    let bounds = Aabb::new(Vec3::new(-20.0, 0.0, -20.0), Vec3::new(20.0, 10.0, 20.0));
    let points: Vec<Vec3> = (0..300)
        .map(|_| Vec3::new(rng.f() * 40.0 - 20.0, 0.0, rng.f() * 40.0 - 20.0))
        .collect();
    for alpha in [0.05, 0.1, 0.2, 0.3, 0.5, 1.0] {
        for below_cut in [BelowCut::Power, BelowCut::Importance] {
            for split_prior in [SplitPrior::Power, SplitPrior::Half] {
                let config = GltConfig {
                    cut: CutConfig {
                        below_cut,
                        split_prior,
                        alpha,
                        ..CutConfig::default()
                    },
                    spatial_threshold: 2000.0,
                    ..GltConfig::default()
                };
                let mut glt = Glt::new(&tree, bounds, config).unwrap();
                let mut rs = Rand::new(seed);
                for iteration in 0..5 {
                    for _ in 0..train << iteration.min(2) {
                        let p = Vec3::new(rs.f() * 40.0 - 20.0, 0.0, rs.f() * 40.0 - 20.0);
                        let ctx = ShadingContext::on_surface(p, Vec3::Y);
                        let vertex = glt.vertex(&ctx).expect("a finite point");
                        let Some(s) = vertex.sample(rs.f()) else {
                            continue;
                        };
                        let LightId::Emitter(e) = s.light else {
                            continue;
                        };
                        let v = f(e as usize, p) as f32 / s.pmf;
                        vertex.record_light(s.light, v);
                    }
                    glt.refine();
                }
                let (mut variance, mut square, mut missed) = (0.0f64, 0.0f64, 0.0f64);
                for &p in &points {
                    let ctx = ShadingContext::on_surface(p, Vec3::Y);
                    let vertex = glt.vertex(&ctx).expect("a finite point");
                    let (mut m2, mut total) = (0.0, 0.0);
                    for e in 0..lights.len() {
                        let fe = f(e, p);
                        if fe == 0.0 {
                            continue;
                        }
                        total += fe;
                        let pe = vertex.pmf_exact(LightId::Emitter(e as u32));
                        if pe > 0.0 {
                            m2 += fe * fe / pe;
                        } else {
                            missed += fe;
                        }
                    }
                    variance += m2 - total * total;
                    square += total * total;
                }
                let m = glt.memory();
                println!(
                    "alpha {alpha:4} {below_cut:10?} {split_prior:6?}: relative variance {:8.3}, missed {missed:.2e}, {} cells, {} cut nodes",
                    variance / square,
                    m.cells,
                    m.cuts.nodes
                );
                assert!(variance.is_finite());
            }
        }
    }
}
