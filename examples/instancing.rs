//! What an instanced light tree costs in light choice: the light BVH's
//! importance sampling (pbrt-v4's sampler, the GLT's prior) and the GLT,
//! trained the same way, over an `InstancedLightTree` against the same
//! lights in one flat tree, by the exact relative variance per sample at
//! fixed points (every light's pmf against its unshadowed contribution; a
//! clairvoyant pmf has 0).
//!
//! The top tree clusters whole instances, whose boxes overlap where
//! instances crowd; the flat tree clusters triangles across instances. The
//! GLT over the instanced tree reads its tables per mesh, the point moved
//! into mesh space inside an instance. The build time and memory are in
//! `benches/light_tree.rs` (`-- instanced`).
//!
//! ```text
//! cargo run --release --example instancing
//! ROW=3 cargo run --release --example instancing   # one row of the table
//! ```

use glam::{Affine3A, Quat, Vec3};
use guiding::glt::{Glt, GltConfig};
use guiding::light_sampler::ImportanceTreeSampler;
use guiding::light_tree::BuildHeuristic;
use guiding::math::Aabb;
use guiding::{
    Emitter, Instance, InstancedLightTree, LightChoice, LightHierarchy, LightId, LightSampler,
    LightTree, ShadingContext,
};
use rayon::prelude::*;

#[path = "../tests/common/mod.rs"]
mod common;
use common::{Rand, contribution, train_on_own_choices};

const POINTS: usize = 200;

/// The exact relative variance per sample of `s` at `ctx` over `lights`.
fn variance(s: &dyn LightChoice, lights: &[Emitter], ctx: &ShadingContext) -> f64 {
    let f: Vec<f64> = lights
        .iter()
        .map(|e| contribution(e, ctx.position))
        .collect();
    let sum: f64 = f.iter().sum();
    if sum <= 0.0 {
        return 0.0;
    }
    let second: f64 = f
        .iter()
        .enumerate()
        .map(|(i, &f)| {
            let pmf = s.pmf_exact(LightId::Emitter(i as u32));
            let share = f / sum;
            match pmf > 0.0 {
                true => share * share / pmf,
                false if share > 0.0 => f64::INFINITY,
                false => 0.0,
            }
        })
        .sum();
    second - 1.0
}

/// A GLT over `tree` trained as a renderer trains it, without shadows: 4
/// rounds of 50,000 records, each the contribution of a light the GLT
/// chooses at a random point on a random surface, over its pmf.
fn trained<H: LightHierarchy>(tree: H, lights: &[Emitter], spread: f32) -> Glt<H> {
    let scene = Aabb::new(Vec3::splat(-spread - 2.0), Vec3::splat(spread + 2.0));
    let mut glt = Glt::new(tree, scene, GltConfig::default()).unwrap();
    train_on_own_choices(&mut glt, lights, spread, (4, 50_000), &mut Rand::new(11));
    glt
}

/// The mean and the geometric mean of per-point ratios of two variances
/// per point (points where either is 0 left out of the ratio).
fn summary(v: &[(f64, f64)]) -> (f64, f64, f64) {
    let n = v.len() as f64;
    let kept: Vec<&(f64, f64)> = v.iter().filter(|x| x.0 > 0.0 && x.1 > 0.0).collect();
    let ratio = kept.iter().map(|x| (x.1 / x.0).ln()).sum::<f64>() / kept.len() as f64;
    (
        v.iter().map(|x| x.0).sum::<f64>() / n,
        v.iter().map(|x| x.1).sum::<f64>() / n,
        ratio.exp(),
    )
}

fn main() {
    println!(
        "Light choice over an instanced light tree vs the flat tree of the same triangles: \
         exact relative variance per sample, mean over {POINTS} points on random surfaces in \
         the scene (instanced / flat: geometric mean of per-point ratios); the light BVH's \
         importance sampling, then the GLT trained alike\n"
    );
    println!(
        "| instances | triangles each | mesh, placement | spread | BVH flat | BVH instanced | instanced / flat | GLT flat | GLT instanced | instanced / flat |"
    );
    println!("| ---: | ---: | --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: |");
    let rows = [
        (200, 500, false, 50.0),
        (200, 500, false, 200.0),
        (1000, 100, false, 50.0),
        (200, 500, true, 50.0),
    ];
    let only: Option<usize> = std::env::var("ROW").ok().and_then(|v| v.parse().ok());
    for (row, (count, triangles, panels, spread)) in rows.into_iter().enumerate() {
        if only.is_some_and(|o| o != row) {
            continue;
        }
        let mut r = Rand::new(3);
        // Scattered small triangles facing every way, or a lamp panel: a
        // flat grid of triangles facing +z (one tight cone).
        let mesh: Vec<[Vec3; 3]> = (0..triangles)
            .map(|i| match panels {
                false => {
                    let c = r.point(1.0);
                    [c, c + r.dir() * 0.05, c + r.dir() * 0.05]
                }
                true => {
                    let c = Vec3::new(
                        (i % 25) as f32 * 0.08 - 1.0,
                        (i / 25) as f32 * 0.1 - 1.0,
                        0.0,
                    );
                    [c, c + Vec3::X * 0.07, c + Vec3::Y * 0.09]
                }
            })
            .collect();
        let instances: Vec<Instance> = (0..count)
            .map(|_| {
                let turn = Quat::from_axis_angle(r.dir(), r.range(0.0, 6.0));
                // Panels stretched: a non-uniform scale (no angle kept).
                let scale = match panels {
                    false => Vec3::splat(r.range(0.5, 2.0)),
                    true => Vec3::new(r.range(0.5, 3.0), r.range(0.5, 3.0), r.range(0.5, 3.0)),
                };
                let t = Affine3A::from_scale_rotation_translation(scale, turn, r.point(spread));
                Instance::new(0, t)
            })
            .collect();
        let local: Vec<Emitter> = mesh
            .iter()
            .map(|&p| Emitter::triangle(p, 1.0, false))
            .collect();
        let flat: Vec<Emitter> = instances
            .iter()
            .flat_map(|i| {
                mesh.iter().map(move |p| {
                    let p = p.map(|c| i.transform.transform_point3(c));
                    Emitter::triangle(p, i.power_scale, false)
                })
            })
            .collect();
        let mesh_tree = LightTree::build(local.as_slice(), BuildHeuristic::Sarh).unwrap();
        let instanced =
            InstancedLightTree::build(vec![mesh_tree], &instances, BuildHeuristic::Sarh).unwrap();
        let flat_tree = LightTree::build(flat.as_slice(), BuildHeuristic::Sarh).unwrap();
        let (a, b) = (
            ImportanceTreeSampler::new(&flat_tree),
            ImportanceTreeSampler::new(&instanced),
        );
        let points: Vec<ShadingContext> = (0..POINTS)
            .map(|_| ShadingContext::on_surface(r.point(spread), r.dir()))
            .collect();
        let v: Vec<(f64, f64)> = points
            .par_iter()
            .map(|ctx| {
                (
                    variance(&a.at(ctx), &flat, ctx),
                    variance(&b.at(ctx), &flat, ctx),
                )
            })
            .collect();
        let (glt_flat, glt_instanced) = (
            trained(&flat_tree, &flat, spread),
            trained(&instanced, &flat, spread),
        );
        let g: Vec<(f64, f64)> = points
            .par_iter()
            .map(|ctx| {
                let (Some(a), Some(b)) = (glt_flat.vertex(ctx), glt_instanced.vertex(ctx)) else {
                    return (0.0, 0.0);
                };
                (variance(&a, &flat, ctx), variance(&b, &flat, ctx))
            })
            .collect();
        let (bf, bi, br) = summary(&v);
        let (gf, gi, gr) = summary(&g);
        let kind = match panels {
            false => "scattered, turned and scaled",
            true => "panel, turned and stretched",
        };
        println!(
            "| {count} | {triangles} | {kind} | {spread} | {bf:.3} | {bi:.3} | {br:.2} | {gf:.3} | {gi:.3} | {gr:.2} |"
        );
    }
}
