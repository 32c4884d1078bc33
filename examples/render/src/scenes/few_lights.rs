//! `few-lights` (the paper's SPACESHIP role, the overhead case): a courtyard
//! open to a dim sky and a low sun (two unbounded lights: the sun is a
//! delta light only light sampling finds) with five emitters (three wall
//! panels, two lamps) and,
//! like the spaceship, real geometric detail (a finely tessellated
//! sculpture and a few hundred small boxes, ~45k triangles), so a path
//! costs what it costs in a production-like scene and the guiding
//! overhead is measured against that.

use super::{Dice, Size, shapes};
use crate::camera::Camera;
use crate::lights::{Environment, Sun, Unbounded};
use crate::materials::Material;
use crate::scene::{Effects, Scene, SceneBuilder};
use glam::Vec3;

/// Builds the scene (its size does not depend on `size`).
pub fn build(_size: Size) -> Scene {
    let mut b = SceneBuilder::new();
    let floor = b.material(Material::Diffuse {
        albedo: Vec3::new(0.5, 0.45, 0.4),
    });
    let wall = b.material(Material::Diffuse {
        albedo: Vec3::splat(0.65),
    });
    let metal = b.material(Material::Glossy {
        specular: Vec3::new(0.9, 0.85, 0.8),
        alpha: 0.2,
    });
    let teal = b.material(Material::Diffuse {
        albedo: Vec3::new(0.1, 0.45, 0.45),
    });
    let (r, h) = (4.0, 3.0);
    b.quad(
        Vec3::new(-r, 0.0, -r),
        Vec3::Z * 2.0 * r,
        Vec3::X * 2.0 * r,
        floor,
    );
    b.quad(Vec3::new(-r, 0.0, -r), Vec3::X * 2.0 * r, Vec3::Y * h, wall);
    b.quad(Vec3::new(-r, 0.0, -r), Vec3::Y * h, Vec3::Z * 2.0 * r, wall);
    b.quad(Vec3::new(r, 0.0, -r), Vec3::Z * 2.0 * r, Vec3::Y * h, wall);
    b.sphere(Vec3::new(0.0, 0.8, 0.0), 0.8, metal);
    b.cuboid(Vec3::new(-2.6, 0.0, -1.5), Vec3::new(-1.6, 1.4, -0.5), teal);
    b.cuboid(Vec3::new(1.5, 0.0, 0.8), Vec3::new(2.5, 0.6, 1.8), wall);
    // Detail: a tessellated sculpture and greebles along the walls.
    b.mesh(
        &shapes::torus(
            Vec3::new(1.9, 1.2, -2.4),
            Vec3::new(0.3, 0.2, 1.0),
            0.7,
            0.18,
            192,
            96,
        ),
        metal,
    );
    let mut dice = Dice::new(3);
    for _ in 0..600 {
        let side = dice.range(0.0, 3.0) as u32;
        let (a, y) = (dice.range(-3.8, 3.8), dice.range(0.05, 2.9));
        let s = dice.range(0.02, 0.07);
        let c = match side {
            0 => Vec3::new(a, y, -r + s),
            1 => Vec3::new(-r + s, y, a),
            _ => Vec3::new(r - s, y, a),
        };
        b.cuboid(c - Vec3::splat(s), c + Vec3::splat(s), wall);
    }
    // Three panels on the walls, facing into the courtyard.
    b.quad_light(
        Vec3::new(-1.0, 1.6, -r + 0.01),
        Vec3::X * 2.0,
        Vec3::Y * 0.6,
        Vec3::new(8.0, 7.0, 6.0),
    );
    b.quad_light(
        Vec3::new(-r + 0.01, 1.8, -2.0),
        Vec3::Y * 0.5,
        Vec3::Z * 1.2,
        Vec3::new(4.0, 6.0, 9.0),
    );
    b.quad_light(
        Vec3::new(r - 0.01, 1.8, 0.5),
        Vec3::Z * 1.2,
        Vec3::Y * 0.5,
        Vec3::new(9.0, 5.0, 3.0),
    );
    // Two lamps.
    b.sphere_light(
        Vec3::new(-2.1, 1.7, -1.0),
        0.12,
        Vec3::new(30.0, 26.0, 20.0),
    );
    b.sphere_light(Vec3::new(2.0, 0.9, 1.3), 0.08, Vec3::new(20.0, 30.0, 24.0));
    let effects = Effects {
        diffuse: true,
        glossy: true,
        quad_lights: true,
        sphere_lights: true,
        sky: true,
        sun: true,
        max_depth: 6,
        ..Effects::default()
    };
    let camera = Camera::look_at(Vec3::new(1.5, 2.4, 7.5), Vec3::new(0.0, 0.8, 0.0), 45.0);
    b.build(
        "few-lights",
        effects,
        camera,
        vec![
            Unbounded::Sky(Environment {
                radiance: Vec3::new(0.25, 0.32, 0.45),
            }),
            // Low in the sky: it reaches the courtyard's floor over a wall
            // only in part, so the lamps and panels still matter.
            Unbounded::Sun(Sun {
                direction: Vec3::new(0.55, 0.6, 0.58).normalize(),
                radiance: Vec3::new(1.6, 1.4, 1.1),
            }),
        ],
    )
}
