//! `ring` (the paper's Figure 1 role): ~24.6k small sphere lights along a
//! ring inside a closed channel (a solid drum, a lid and a slatted fence),
//! in a closed room: light leaves only through the gaps between the slats. Most lights are hidden from most points, and which ones are
//! visible changes quickly with position: distance and orientation alone
//! (the light BVH's importance) cannot know it, visibility learned per
//! region can.

use super::{Dice, Size, shapes};
use crate::camera::Camera;
use crate::materials::Material;
use crate::scene::{Effects, Scene, SceneBuilder};
use glam::Vec3;
use std::f32::consts::TAU;

/// Builds the scene: 24,576 lights (1,536 for [`Size::Small`]).
pub fn build(size: Size) -> Scene {
    let (lights, slats) = match size {
        Size::Full => (24_576usize, 96usize),
        Size::Small => (1_536, 48),
    };
    let mut b = SceneBuilder::new();
    let floor = b.material(Material::Diffuse {
        albedo: Vec3::new(0.5, 0.48, 0.45),
    });
    let wall = b.material(Material::Diffuse {
        albedo: Vec3::splat(0.3),
    });
    let wood = b.material(Material::Diffuse {
        albedo: Vec3::new(0.45, 0.3, 0.18),
    });
    let drum = b.material(Material::Diffuse {
        albedo: Vec3::splat(0.3),
    });
    let blue = b.material(Material::Diffuse {
        albedo: Vec3::new(0.2, 0.3, 0.6),
    });
    // Room 16 x 5 x 16.
    let (h, r) = (5.0, 8.0);
    b.quad(
        Vec3::new(-r, 0.0, -r),
        Vec3::Z * 2.0 * r,
        Vec3::X * 2.0 * r,
        floor,
    );
    b.quad(
        Vec3::new(-r, h, -r),
        Vec3::X * 2.0 * r,
        Vec3::Z * 2.0 * r,
        wall,
    );
    for (c, e1, e2) in [
        (Vec3::new(-r, 0.0, -r), Vec3::X, Vec3::Y),
        (Vec3::new(-r, 0.0, r), Vec3::Y, Vec3::X),
        (Vec3::new(-r, 0.0, -r), Vec3::Y, Vec3::Z),
        (Vec3::new(r, 0.0, -r), Vec3::Z, Vec3::Y),
    ] {
        let (e1, e2) = (
            if e1 == Vec3::Y { e1 * h } else { e1 * 2.0 * r },
            if e2 == Vec3::Y { e2 * h } else { e2 * 2.0 * r },
        );
        b.quad(c, e1, e2, wall);
    }
    // The drum inside the ring hides its far side.
    b.mesh(&shapes::cylinder(Vec3::ZERO, 1.5, 1.6, 64), drum);
    b.mesh(&shapes::disk(Vec3::Y * 1.6, 1.5, 64), drum);
    // A lid over the channel between drum and fence: light leaves only
    // through the gaps between the slats.
    b.mesh(&shapes::annulus(Vec3::Y * 1.6, 1.45, 2.5, 96), drum);
    // The slatted fence: each slat covers 70% of its angular period.
    let fence_r = 2.4;
    let period = TAU / slats as f32;
    let half_width = 0.35 * period * fence_r;
    for i in 0..slats {
        let a = (i as f32 + 0.5) * period;
        let radial = Vec3::new(a.cos(), 0.0, a.sin());
        let tangent = Vec3::new(-a.sin(), 0.0, a.cos());
        let c = radial * fence_r + Vec3::Y * 0.8;
        b.oriented_box(c, radial * 0.03, Vec3::Y * 0.8, tangent * half_width, wood);
    }
    // The ring of lights: 512 columns x 48 rows of 4 mm spheres on a
    // cylinder of radius 2 m (24,576 lights, 2.5 x 1.7 cm apart, none
    // touching), with a little jitter.
    let mut dice = Dice::new(7);
    let (cols, rows) = match size {
        Size::Full => (512usize, lights / 512),
        Size::Small => (128, lights / 128),
    };
    let radius = 0.004 * (24_576.0 / lights as f32).sqrt();
    for c in 0..cols {
        for r in 0..rows {
            let a = TAU * (c as f32 + dice.range(0.3, 0.7)) / cols as f32;
            let y = 0.35 + 0.8 * (r as f32 + dice.range(0.3, 0.7)) / rows as f32;
            let rr = 2.0 + dice.range(-0.03, 0.03);
            let hue = 0.5 + 0.5 * (a * 3.0).cos();
            let le = Vec3::new(1.0, 0.75 + 0.2 * hue, 0.5 + 0.45 * hue) * 400.0;
            b.sphere_light(Vec3::new(rr * a.cos(), y, rr * a.sin()), radius, le);
        }
    }
    // Things outside the fence to be lit through the gaps.
    b.sphere(Vec3::new(-1.6, 0.5, 3.4), 0.5, blue);
    b.cuboid(Vec3::new(1.2, 0.0, 3.0), Vec3::new(2.0, 0.9, 3.8), wall);
    b.cuboid(Vec3::new(-4.0, 0.0, -1.0), Vec3::new(-3.2, 1.8, 0.2), wall);
    b.hide_emitters_from_camera();
    let effects = Effects {
        diffuse: true,
        sphere_lights: true,
        max_depth: 5,
        ..Effects::default()
    };
    let camera = Camera::look_at(Vec3::new(0.6, 2.2, 6.6), Vec3::new(0.0, 0.2, 0.0), 50.0);
    b.build("ring", effects, camera, Vec::new())
}
