//! `torus` (the paper's TORUS LIGHT role): a mesh light of 24,576 emitting
//! triangles over a floor with a few objects; no specular chains.

use super::{Size, shapes};
use crate::camera::Camera;
use crate::materials::Material;
use crate::scene::{Effects, Scene, SceneBuilder};
use glam::Vec3;

/// The torus mesh light: 128 x 96 quads = 24,576 triangles (32 x 24 quads =
/// 1,536 for [`Size::Small`]).
pub fn torus_light(b: &mut SceneBuilder, size: Size, center: Vec3, axis: Vec3, radiance: Vec3) {
    let (nu, nv) = match size {
        Size::Full => (128, 96),
        Size::Small => (32, 24),
    };
    for t in shapes::torus(center, axis, 0.8, 0.22, nu, nv) {
        b.triangle_light(t[0], t[1], t[2], radiance);
    }
}

/// Builds the scene.
pub fn build(size: Size) -> Scene {
    let mut b = SceneBuilder::new();
    let floor = b.material(Material::Diffuse {
        albedo: Vec3::splat(0.55),
    });
    let wall = b.material(Material::Diffuse {
        albedo: Vec3::new(0.6, 0.58, 0.55),
    });
    let orange = b.material(Material::Diffuse {
        albedo: Vec3::new(0.7, 0.35, 0.1),
    });
    let r = 5.0;
    b.quad(
        Vec3::new(-r, 0.0, -r),
        Vec3::Z * 2.0 * r,
        Vec3::X * 2.0 * r,
        floor,
    );
    b.quad(
        Vec3::new(-r, 0.0, -2.5),
        Vec3::X * 2.0 * r,
        Vec3::Y * 4.0,
        wall,
    );
    b.quad(
        Vec3::new(-3.0, 0.0, -r),
        Vec3::Y * 4.0,
        Vec3::Z * 2.0 * r,
        wall,
    );
    b.cuboid(Vec3::new(-0.4, 0.0, -0.4), Vec3::new(0.4, 0.5, 0.4), wall);
    b.sphere(Vec3::new(1.4, 0.45, 0.6), 0.45, orange);
    b.cuboid(Vec3::new(-1.9, 0.0, 0.4), Vec3::new(-1.1, 1.2, 1.2), wall);
    torus_light(
        &mut b,
        size,
        Vec3::new(0.0, 1.7, 0.0),
        Vec3::new(0.3, 1.0, 0.4),
        Vec3::new(6.0, 5.0, 3.5),
    );
    let effects = Effects {
        diffuse: true,
        triangle_lights: true,
        max_depth: 5,
        ..Effects::default()
    };
    let camera = Camera::look_at(Vec3::new(0.8, 1.6, 5.5), Vec3::new(0.0, 0.9, 0.0), 45.0);
    b.build("torus", effects, camera, Vec::new())
}
