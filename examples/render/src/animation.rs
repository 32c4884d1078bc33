//! An animated scene (`render --frames N`): frame `f` of a scene has its
//! lights moved along small circles, the lights of one neighbourhood
//! together (as the emitters of one lamp or one car move together), and
//! the camera moved along a line, the geometry otherwise as built.

use crate::bvh::Bvh;
use crate::geometry::{NO_EMITTER, Primitive, Shape};
use crate::lights::{Light, LightShape};
use crate::scene::Scene;
use glam::Vec3;
use guiding::light_tree::BuildHeuristic;
use guiding::math::Aabb;
use guiding::{Emitter, LightTree};

/// Each light circles its place in the horizontal plane with a radius of
/// this share of the scene's diagonal, ...
const LIGHT_RADIUS: f32 = 0.004;
/// ... advancing this many radians per frame, so it moves about 0.2% of
/// the diagonal from frame to frame; ...
const LIGHT_STEP: f32 = 0.5;
/// ... from the phase of its neighbourhood: the cell of a grid of this
/// share of the diagonal its centre lies in, so the triangles of one lamp
/// move as one.
const LIGHT_GROUP: f32 = 0.02;
/// The camera moves this share of the diagonal per frame, sideways.
const CAMERA_STEP: f32 = 0.002;

/// Where a light whose centre was built at `c` is at frame `f`, relative
/// to there, in a scene whose diagonal is `diagonal`.
fn light_offset(c: Vec3, f: u32, diagonal: f32) -> Vec3 {
    let cell = (c / (LIGHT_GROUP * diagonal)).floor().as_ivec3();
    let key = [cell.x, cell.y, cell.z]
        .iter()
        .fold(0x9e37_79b9u64, |h, &x| {
            crate::rng::mix64(h ^ x as u32 as u64)
        });
    let phase = (key >> 40) as f32 / (1u64 << 24) as f32 * core::f32::consts::TAU;
    let radius = LIGHT_RADIUS * diagonal;
    let at = |t: f32| Vec3::new(t.cos(), 0.0, t.sin()) * radius;
    at(phase + LIGHT_STEP * f as f32) - at(phase)
}

fn moved_shape(shape: LightShape, d: Vec3) -> LightShape {
    match shape {
        LightShape::Quad { corner, e1, e2 } => LightShape::Quad {
            corner: corner + d,
            e1,
            e2,
        },
        LightShape::Triangle { v0, e1, e2 } => LightShape::Triangle { v0: v0 + d, e1, e2 },
        LightShape::Sphere { center, radius } => LightShape::Sphere {
            center: center + d,
            radius,
        },
    }
}

fn moved_primitive(p: &Primitive, d: Vec3) -> Primitive {
    let shape = match p.shape {
        Shape::Triangle { v0, e1, e2 } => Shape::Triangle { v0: v0 + d, e1, e2 },
        Shape::Sphere { center, radius } => Shape::Sphere {
            center: center + d,
            radius,
        },
    };
    Primitive { shape, ..*p }
}

/// Frame `f` of `base` (frame 0 is `base` itself, rebuilt): its lights
/// moved, its camera moved, its ray-tracing BVH and light tree built anew
/// (a renderer carrying its guides over replaces the light tree with a
/// refit of the previous frame's).
pub fn frame(base: &Scene, f: u32) -> Scene {
    let diagonal = base.bounds.diagonal().length();
    let offsets: Vec<Vec3> = base
        .emitters
        .iter()
        .map(|e| light_offset(e.bounds.min * 0.5 + e.bounds.max * 0.5, f, diagonal))
        .collect();
    let lights: Vec<Light> = base
        .lights
        .iter()
        .zip(&offsets)
        .map(|(l, &d)| Light {
            shape: moved_shape(l.shape, d),
            ..*l
        })
        .collect();
    let prims: Vec<Primitive> = base
        .bvh
        .primitives()
        .iter()
        .map(|p| match p.emitter {
            NO_EMITTER => *p,
            e => moved_primitive(p, offsets[e as usize]),
        })
        .collect();
    let mut bounds = Aabb::EMPTY;
    for p in &prims {
        let (lo, hi) = p.bounds();
        bounds = bounds.union(&Aabb::new(lo, hi));
    }
    let emitters: Vec<Emitter> = lights.iter().map(|l| l.to_emitter()).collect();
    let light_tree = LightTree::build(emitters.as_slice(), BuildHeuristic::default())
        .expect("the base scene's lights, moved, build");
    let mut camera = base.camera;
    camera.eye += Vec3::X * CAMERA_STEP * base.bounds.diagonal().length() * f as f32;
    Scene {
        name: base.name.clone(),
        effects: base.effects,
        bvh: Bvh::build(prims),
        materials: base.materials.clone(),
        lights,
        emitters,
        light_tree,
        unbounded: base.unbounded.clone(),
        camera,
        bounds,
        unbounded_lights: base.unbounded_lights,
        fingerprint: crate::rng::mix64(base.fingerprint ^ (u64::from(f) << 32) ^ 0xf4a3),
        camera_sees_emitters: base.camera_sees_emitters,
    }
}
