//! `occlusion` (the paper's OCCLUSION role): the torus mesh light hidden
//! behind a wall, a glossy reflector under the ceiling that bounces its
//! light down onto a diffuse statue, and hundreds of small dark occluders
//! between them, blocking both the light and the statue.

use super::{Dice, Size, torus::torus_light};
use crate::camera::Camera;
use crate::materials::Material;
use crate::scene::{Effects, Scene, SceneBuilder};
use glam::Vec3;

/// Builds the scene: 400 occluders (100 for [`Size::Small`]).
pub fn build(size: Size) -> Scene {
    let occluders = match size {
        Size::Full => 400,
        Size::Small => 100,
    };
    let mut b = SceneBuilder::new();
    let floor = b.material(Material::Diffuse {
        albedo: Vec3::splat(0.45),
    });
    let wall = b.material(Material::Diffuse {
        albedo: Vec3::splat(0.5),
    });
    let statue = b.material(Material::Diffuse {
        albedo: Vec3::new(0.8, 0.78, 0.72),
    });
    let mirror = b.material(Material::Glossy {
        specular: Vec3::new(0.95, 0.93, 0.88),
        alpha: 0.08,
    });
    let soot = b.material(Material::Diffuse {
        albedo: Vec3::splat(0.03),
    });
    // Room 10 x 4.5 x 8.
    let (x0, x1, h, z) = (-5.0, 5.0, 4.5, 4.0);
    b.quad(
        Vec3::new(x0, 0.0, -z),
        Vec3::Z * 2.0 * z,
        Vec3::X * (x1 - x0),
        floor,
    );
    b.quad(
        Vec3::new(x0, h, -z),
        Vec3::X * (x1 - x0),
        Vec3::Z * 2.0 * z,
        wall,
    );
    b.quad(
        Vec3::new(x0, 0.0, -z),
        Vec3::X * (x1 - x0),
        Vec3::Y * h,
        wall,
    );
    b.quad(
        Vec3::new(x0, 0.0, z),
        Vec3::Y * h,
        Vec3::X * (x1 - x0),
        wall,
    );
    b.quad(Vec3::new(x0, 0.0, -z), Vec3::Y * h, Vec3::Z * 2.0 * z, wall);
    b.quad(Vec3::new(x1, 0.0, -z), Vec3::Z * 2.0 * z, Vec3::Y * h, wall);
    // The wall that hides the light from the statue.
    b.cuboid(Vec3::new(-1.6, 0.0, -z), Vec3::new(-1.4, 2.4, z), wall);
    torus_light(
        &mut b,
        size,
        Vec3::new(-3.3, 1.2, 0.0),
        Vec3::new(0.5, 1.0, 0.0),
        Vec3::new(14.0, 12.0, 9.0),
    );
    // The glossy reflector, tilted towards the statue.
    let c = Vec3::new(-0.5, 4.2, 0.0);
    let e1 = Vec3::new(3.6, -0.7, 0.0);
    let e2 = Vec3::new(0.0, 0.0, 3.2);
    b.quad(c - 0.5 * e1 - 0.5 * e2, e1, e2, mirror);
    // The statue: a stack of spheres on a plinth.
    b.cuboid(Vec3::new(1.6, 0.0, -0.5), Vec3::new(2.6, 0.4, 0.5), statue);
    b.sphere(Vec3::new(2.1, 0.8, 0.0), 0.42, statue);
    b.sphere(Vec3::new(2.1, 1.42, 0.0), 0.3, statue);
    b.sphere(Vec3::new(2.1, 1.88, 0.0), 0.2, statue);
    b.sphere(Vec3::new(2.42, 1.4, 0.12), 0.1, statue);
    b.sphere(Vec3::new(1.78, 1.4, -0.12), 0.1, statue);
    // Small dark occluders under the reflector.
    let mut dice = Dice::new(31);
    for _ in 0..occluders {
        let p = Vec3::new(
            dice.range(-2.6, 2.0),
            dice.range(2.6, 3.9),
            dice.range(-1.8, 1.8),
        );
        let s = dice.range(0.04, 0.09);
        b.cuboid(p - Vec3::splat(s), p + Vec3::splat(s), soot);
    }
    let effects = Effects {
        diffuse: true,
        glossy: true,
        triangle_lights: true,
        max_depth: 6,
        ..Effects::default()
    };
    let camera = Camera::look_at(Vec3::new(4.6, 1.7, 3.6), Vec3::new(1.5, 1.1, 0.0), 50.0);
    b.build("occlusion", effects, camera, Vec::new())
}
