//! `city` (the paper's CITY role): a procedural city of box buildings whose
//! lit windows are small quad emitters, with sphere street lamps and roof
//! beacons, under a thick glass dome: over 100k emitters.

use super::{Dice, Size, shapes};
use crate::camera::Camera;
use crate::materials::Material;
use crate::scene::{Effects, Scene, SceneBuilder};
use glam::Vec3;

/// The city seen from above its edge: most of its lights in view.
pub fn build(size: Size) -> Scene {
    build_with(size, View::Overview)
}

/// The city seen from its central street (`city-street`, the paper's own
/// CITY view): the camera a few metres above the street looking down it,
/// so each shading point sees few of the lights.
pub fn build_street(size: Size) -> Scene {
    build_with(size, View::Street)
}

/// The city of [`build`] on a `blocks` x `blocks` grid (20 is `city`'s,
/// about 108k emitters; the emitters grow as `blocks^2`): for measuring how
/// a light sampler's cost grows with the number of lights.
pub fn build_blocks(blocks: usize) -> Scene {
    build_grid(blocks.max(1), View::Overview)
}

/// Where the camera is.
#[derive(Clone, Copy, PartialEq, Eq)]
enum View {
    Overview,
    Street,
}

/// Builds the city: a 20 x 20 grid of buildings (6 x 6 for
/// [`Size::Small`]), seen from `view`.
fn build_with(size: Size, view: View) -> Scene {
    let blocks = match size {
        Size::Full => 20usize,
        Size::Small => 6,
    };
    build_grid(blocks, view)
}

/// The city on a `blocks` x `blocks` grid, seen from `view`.
fn build_grid(blocks: usize, view: View) -> Scene {
    let mut b = SceneBuilder::new();
    let ground = b.material(Material::Diffuse {
        albedo: Vec3::splat(0.25),
    });
    let concrete = b.material(Material::Diffuse {
        albedo: Vec3::new(0.55, 0.52, 0.5),
    });
    let dark = b.material(Material::Diffuse {
        albedo: Vec3::new(0.3, 0.32, 0.36),
    });
    let glass = b.material(Material::Dielectric { ior: 1.5 });
    let spacing = 1.4;
    let extent = 0.5 * spacing * blocks as f32;
    let mut dice = Dice::new(11);
    // Ground.
    let g = extent + 4.0;
    b.quad(
        Vec3::new(-g, 0.0, -g),
        Vec3::Z * 2.0 * g,
        Vec3::X * 2.0 * g,
        ground,
    );
    let warm = [
        Vec3::new(1.0, 0.8, 0.5),
        Vec3::new(1.0, 0.9, 0.75),
        Vec3::new(0.8, 0.9, 1.0),
    ];
    for bx in 0..blocks {
        for bz in 0..blocks {
            let cx = -extent + spacing * (bx as f32 + 0.5);
            let cz = -extent + spacing * (bz as f32 + 0.5);
            let hw = dice.range(0.38, 0.52);
            let hd = dice.range(0.38, 0.52);
            let height = dice.range(0.8, 4.0);
            let lo = Vec3::new(cx - hw, 0.0, cz - hd);
            let hi = Vec3::new(cx + hw, height, cz + hd);
            let m = if dice.chance(0.5) { concrete } else { dark };
            b.cuboid(lo, hi, m);
            // Lit windows on the four facades, 2 mm in front of them.
            let floors = (height / 0.15) as usize;
            let lit = dice.range(0.45, 0.75);
            let facades = [
                (
                    Vec3::new(lo.x, 0.0, lo.z - 0.002),
                    Vec3::X,
                    2.0 * hw,
                    Vec3::NEG_Z,
                ),
                (
                    Vec3::new(hi.x, 0.0, hi.z + 0.002),
                    Vec3::NEG_X,
                    2.0 * hw,
                    Vec3::Z,
                ),
                (
                    Vec3::new(lo.x - 0.002, 0.0, hi.z),
                    Vec3::NEG_Z,
                    2.0 * hd,
                    Vec3::NEG_X,
                ),
                (
                    Vec3::new(hi.x + 0.002, 0.0, lo.z),
                    Vec3::Z,
                    2.0 * hd,
                    Vec3::X,
                ),
            ];
            for (origin, along, width, normal) in facades {
                let cols = 8;
                let cell = width / cols as f32;
                for f in 1..floors {
                    for c in 0..cols {
                        if !dice.chance(lit) {
                            continue;
                        }
                        let corner = origin
                            + along * (cell * (c as f32 + 0.2))
                            + Vec3::Y * (0.15 * f as f32 + 0.03);
                        let e1 = along * (0.6 * cell);
                        let e2 = Vec3::Y * 0.08;
                        let (e1, e2) = if e1.cross(e2).dot(normal) > 0.0 {
                            (e1, e2)
                        } else {
                            (e2, e1)
                        };
                        let tint = warm[(dice.range(0.0, 3.0) as usize).min(2)];
                        b.quad_light(corner, e1, e2, tint * dice.range(4.0, 12.0));
                    }
                }
            }
            // A red beacon on tall roofs.
            if height > 3.0 {
                b.sphere_light(
                    Vec3::new(cx, height + 0.05, cz),
                    0.03,
                    Vec3::new(60.0, 4.0, 2.0),
                );
            }
        }
    }
    // Street lamps at every crossing, two per street segment.
    for ix in 0..=blocks {
        for iz in 0..=blocks {
            let x = -extent + spacing * ix as f32;
            let z = -extent + spacing * iz as f32;
            for (dx, dz) in [(0.0, 0.0), (0.5 * spacing, 0.0), (0.0, 0.5 * spacing)] {
                b.sphere_light(
                    Vec3::new(x + dx, 0.35, z + dz),
                    0.02,
                    Vec3::new(40.0, 34.0, 24.0),
                );
            }
        }
    }
    // The thick glass dome (two hemispherical interfaces, 8 cm apart).
    let dome = extent * 1.45 + 1.0;
    let c = Vec3::ZERO;
    b.mesh(&shapes::hemisphere(c, dome, 96, 32, true), glass);
    b.mesh(&shapes::hemisphere(c, dome - 0.08, 96, 32, false), glass);
    b.hide_emitters_from_camera();
    let effects = Effects {
        diffuse: true,
        dielectric: true,
        quad_lights: true,
        sphere_lights: true,
        max_depth: 6,
        ..Effects::default()
    };
    match view {
        View::Overview => {
            let eye = Vec3::new(-0.62 * extent, 0.22 * extent + 1.5, 1.25 * extent);
            let camera = Camera::look_at(eye, Vec3::new(0.1 * extent, 0.0, 0.0), 50.0);
            b.build("city", effects, camera, Vec::new())
        }
        View::Street => {
            // The street along z at x = 0 (a grid line: lamps stand on
            // it), the eye about 0.1 units (a few metres at this scale)
            // above it near the city's edge.
            let eye = Vec3::new(0.0, 0.12, 0.92 * extent);
            let camera = Camera::look_at(eye, Vec3::new(0.0, 0.1, -extent), 60.0);
            b.build("city-street", effects, camera, Vec::new())
        }
    }
}
