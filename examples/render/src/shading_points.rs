//! The shading points the instrument measures at: the first (or k-th)
//! non-specular vertex of camera paths, as the render example's integrator
//! reaches them.

use crate::geometry::{NO_EMITTER, offset_origin};
use crate::materials::Material;
use crate::rng::Sampler;
use crate::scene::Scene;
use glam::Vec3;

/// A non-specular path vertex: where next-event estimation happens.
#[derive(Clone, Copy, Debug)]
pub struct ShadingPoint {
    /// Position.
    pub p: Vec3,
    /// Shading normal, turned towards `wo`.
    pub n: Vec3,
    /// Direction back along the incoming ray.
    pub wo: Vec3,
    /// The surface's material (never delta, never black).
    pub material: Material,
}

/// `count` shading points of `scene`: camera rays through uniformly random
/// pixels of a `width` x `height` image, followed through specular
/// (delta) vertices, and then by BSDF sampling until the `vertex`-th
/// non-specular vertex (1 = first hit). Paths that leave the scene, hit an
/// emitter or die are dropped and another pixel is tried, up to `100
/// count` paths.
pub fn pick(
    scene: &Scene,
    count: usize,
    vertex: u32,
    (width, height): (u32, u32),
    seed: u64,
) -> Vec<ShadingPoint> {
    let mut s = Sampler::new(seed, 0x5a5a, 0);
    let mut out = Vec::with_capacity(count);
    let mut tries = 0usize;
    while out.len() < count && tries < 100 * count.max(1) {
        tries += 1;
        let px = s.next2() * glam::Vec2::new(width as f32, height as f32);
        let dir = scene.camera.direction(px.x, px.y, width, height);
        if let Some(v) = follow(scene, scene.camera.eye, dir, vertex, &mut s) {
            out.push(v);
        }
    }
    out
}

/// Follows a path from `origin` to its `vertex`-th non-specular vertex.
fn follow(
    scene: &Scene,
    mut origin: Vec3,
    mut dir: Vec3,
    vertex: u32,
    s: &mut Sampler,
) -> Option<ShadingPoint> {
    let mut seen = 0u32;
    for _ in 0..scene.effects.max_depth.max(1) + 8 {
        let hit = scene.intersect(origin, dir)?;
        let prim = *scene.primitive(&hit);
        if prim.emitter != NO_EMITTER {
            return None;
        }
        let p = origin + dir * hit.t;
        let ng = prim.normal(p);
        let mat = scene.materials[prim.material as usize];
        if mat.is_black() {
            return None;
        }
        let wo = -dir;
        if mat.is_delta() {
            let bs = mat.sample(ng, wo, s.next2(), s.next())?;
            origin = offset_origin(p, ng, bs.wi);
            dir = bs.wi;
            continue;
        }
        let n = if ng.dot(wo) < 0.0 { -ng } else { ng };
        seen += 1;
        if seen >= vertex {
            return Some(ShadingPoint {
                p,
                n,
                wo,
                material: mat,
            });
        }
        let bs = mat.sample(n, wo, s.next2(), s.next())?;
        origin = offset_origin(p, n, bs.wi);
        dir = bs.wi;
    }
    None
}
