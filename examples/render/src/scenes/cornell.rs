//! `box`: a tiny Cornell-style room for smoke tests, with every material
//! model and two kinds of emitter.

use super::Size;
use crate::camera::Camera;
use crate::materials::Material;
use crate::scene::{Effects, Scene, SceneBuilder};
use glam::Vec3;

/// Builds the box (its size does not depend on `size`).
pub fn build(_size: Size) -> Scene {
    let mut b = SceneBuilder::new();
    let white = b.material(Material::Diffuse {
        albedo: Vec3::splat(0.73),
    });
    let red = b.material(Material::Diffuse {
        albedo: Vec3::new(0.65, 0.05, 0.05),
    });
    let green = b.material(Material::Diffuse {
        albedo: Vec3::new(0.12, 0.45, 0.15),
    });
    let glossy = b.material(Material::Glossy {
        specular: Vec3::new(0.9, 0.8, 0.6),
        alpha: 0.15,
    });
    let glass = b.material(Material::Dielectric { ior: 1.5 });
    // Room: x, y, z in [0, 1], open towards -z where the camera is.
    b.quad(Vec3::ZERO, Vec3::Z, Vec3::X, white); // floor
    b.quad(Vec3::Y, Vec3::X, Vec3::Z, white); // ceiling
    b.quad(Vec3::Z, Vec3::X, Vec3::Y, white); // back
    b.quad(Vec3::ZERO, Vec3::Y, Vec3::Z, red); // left
    b.quad(Vec3::X, Vec3::Z, Vec3::Y, green); // right
    b.cuboid(
        Vec3::new(0.55, 0.0, 0.45),
        Vec3::new(0.85, 0.55, 0.75),
        glossy,
    );
    b.sphere(Vec3::new(0.3, 0.18, 0.35), 0.18, glass);
    // A ceiling panel and a small bulb.
    b.quad_light(
        Vec3::new(0.38, 0.999, 0.38),
        Vec3::new(0.24, 0.0, 0.0),
        Vec3::new(0.0, 0.0, 0.24),
        Vec3::new(12.0, 10.0, 8.0),
    );
    b.sphere_light(Vec3::new(0.15, 0.8, 0.8), 0.03, Vec3::new(20.0, 30.0, 40.0));
    let effects = Effects {
        diffuse: true,
        glossy: true,
        dielectric: true,
        quad_lights: true,
        sphere_lights: true,
        max_depth: 6,
        ..Effects::default()
    };
    let camera = Camera::look_at(Vec3::new(0.5, 0.5, -1.15), Vec3::new(0.5, 0.5, 0.5), 40.0);
    b.build("box", effects, camera, Vec::new())
}
