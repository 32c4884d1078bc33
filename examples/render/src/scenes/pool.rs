//! `pool` (the paper's POOL role): 1,700 small sphere lights near the bottom
//! of a pool under a bumpy, specular (smooth dielectric) water surface; the
//! deck and a wall above catch the caustics.

use super::{Dice, Size, shapes};
use crate::camera::Camera;
use crate::materials::Material;
use crate::scene::{Effects, Scene, SceneBuilder};
use glam::Vec3;

/// Builds the pool (425 lights for [`Size::Small`]).
pub fn build(size: Size) -> Scene {
    let (lights, grid) = match size {
        Size::Full => (1_700usize, (96usize, 64usize)),
        Size::Small => (425, (48, 32)),
    };
    let mut b = SceneBuilder::new();
    let tiles = b.material(Material::Diffuse {
        albedo: Vec3::new(0.55, 0.72, 0.8),
    });
    let deck = b.material(Material::Diffuse {
        albedo: Vec3::new(0.7, 0.66, 0.6),
    });
    let wall = b.material(Material::Diffuse {
        albedo: Vec3::splat(0.75),
    });
    let water = b.material(Material::Dielectric { ior: 1.33 });
    let (px, pz, depth) = (3.0f32, 2.0f32, 1.5f32);
    // Basin: floor and four walls.
    b.quad(
        Vec3::new(-px, -depth, -pz),
        Vec3::Z * 2.0 * pz,
        Vec3::X * 2.0 * px,
        tiles,
    );
    b.quad(
        Vec3::new(-px, -depth, -pz),
        Vec3::X * 2.0 * px,
        Vec3::Y * depth,
        tiles,
    );
    b.quad(
        Vec3::new(-px, -depth, pz),
        Vec3::Y * depth,
        Vec3::X * 2.0 * px,
        tiles,
    );
    b.quad(
        Vec3::new(-px, -depth, -pz),
        Vec3::Y * depth,
        Vec3::Z * 2.0 * pz,
        tiles,
    );
    b.quad(
        Vec3::new(px, -depth, -pz),
        Vec3::Z * 2.0 * pz,
        Vec3::Y * depth,
        tiles,
    );
    // Deck around the pool, out to 8 m.
    let r = 8.0;
    b.quad(
        Vec3::new(-r, 0.0, -r),
        Vec3::Z * (r - pz),
        Vec3::X * 2.0 * r,
        deck,
    );
    b.quad(
        Vec3::new(-r, 0.0, pz),
        Vec3::Z * (r - pz),
        Vec3::X * 2.0 * r,
        deck,
    );
    b.quad(
        Vec3::new(-r, 0.0, -pz),
        Vec3::Z * 2.0 * pz,
        Vec3::X * (r - px),
        deck,
    );
    b.quad(
        Vec3::new(px, 0.0, -pz),
        Vec3::Z * 2.0 * pz,
        Vec3::X * (r - px),
        deck,
    );
    // A wall behind the pool and two loungers.
    b.quad(
        Vec3::new(-r, 0.0, -4.0),
        Vec3::X * 2.0 * r,
        Vec3::Y * 4.0,
        wall,
    );
    b.cuboid(Vec3::new(-2.5, 0.0, 2.6), Vec3::new(-1.7, 0.35, 4.4), wall);
    b.cuboid(Vec3::new(1.2, 0.0, 2.6), Vec3::new(2.0, 0.35, 4.4), wall);
    // Bumpy water 10 cm below the deck; flat at the rim so it meets the
    // walls without gaps.
    let surface = shapes::height_field((-px, px), (-pz, pz), grid.0, grid.1, |x, z| {
        let rim = ((px - x.abs()) * (pz - z.abs())).clamp(0.0, 0.25) * 4.0;
        let waves = (3.1 * x + 1.3 * z).sin() * 0.5
            + (2.3 * z - 1.7 * x).sin() * 0.35
            + (5.3 * x + 4.1 * z).sin() * 0.15;
        -0.1 + 0.03 * rim * waves
    });
    b.mesh(&surface, water);
    // The lights: small spheres 10-20 cm above the pool floor.
    let mut dice = Dice::new(23);
    let palette = [
        Vec3::new(1.0, 0.9, 0.7),
        Vec3::new(0.5, 0.8, 1.0),
        Vec3::new(0.9, 0.5, 1.0),
    ];
    let scale = (1_700.0 / lights as f32).sqrt();
    for i in 0..lights {
        let c = Vec3::new(
            dice.range(-px + 0.1, px - 0.1),
            -depth + dice.range(0.1, 0.2),
            dice.range(-pz + 0.1, pz - 0.1),
        );
        b.sphere_light(c, 0.012 * scale, palette[i % 3] * 400.0);
    }
    b.hide_emitters_from_camera();
    let effects = Effects {
        diffuse: true,
        dielectric: true,
        sphere_lights: true,
        max_depth: 8,
        ..Effects::default()
    };
    let camera = Camera::look_at(Vec3::new(0.5, 3.2, 6.5), Vec3::new(0.0, -0.9, -0.5), 50.0);
    b.build("pool", effects, camera, Vec::new())
}
