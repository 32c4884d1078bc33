//! The emitter constructors map a renderer's lights one-to-one: their boxes
//! hold every point of the light, their cones every direction it emits
//! into, and importance sampling discounts exactly what they cannot reach.

mod common;

use common::Rand;
use glam::Vec3;
use guiding::light_sampler::ImportanceTreeSampler;
use guiding::light_tree::BuildHeuristic;
use guiding::math::Aabb;
use guiding::{Emitter, LightId, LightSampler, LightTree, ShadingContext};
use std::f32::consts::PI;

fn contains(b: &Aabb, p: Vec3) -> bool {
    let eps = 1e-5 * (1.0 + p.abs().max_element());
    (b.min - Vec3::splat(eps)).cmple(p).all() && p.cmple(b.max + Vec3::splat(eps)).all()
}

/// The pmf of emitter 0 at `p` (normal `n`) beside a dim reference light
/// far away, under importance sampling.
fn importance_pmf(e: Emitter, p: Vec3, n: Vec3) -> f32 {
    let lights = vec![e, Emitter::point(Vec3::new(0.0, 100.0, 0.0), 1e-3)];
    let tree = LightTree::build(&lights, BuildHeuristic::Sarh).unwrap();
    ImportanceTreeSampler::new(&tree).pmf(&ShadingContext::on_surface(p, n), LightId::Emitter(0))
}

#[test]
fn triangles_quads_and_disks_bound_their_surface() {
    let mut rng = Rand::new(5);
    for _ in 0..200 {
        let p = [rng.point(5.0), rng.point(5.0), rng.point(5.0)];
        let t = Emitter::triangle(p, 2.0, false);
        let n = (p[1] - p[0]).cross(p[2] - p[0]);
        assert!((t.area - 0.5 * n.length()).abs() <= 1e-5 * t.area.max(1.0));
        let cone = t.cone.unwrap();
        assert!((cone.axis - n.normalize()).length() < 1e-5);
        assert!(!t.two_sided && !t.delta);
        for _ in 0..20 {
            let (a, b) = (rng.f(), rng.f());
            let (a, b) = if a + b > 1.0 {
                (1.0 - a, 1.0 - b)
            } else {
                (a, b)
            };
            assert!(contains(
                &t.bounds,
                p[0] + a * (p[1] - p[0]) + b * (p[2] - p[0])
            ));
        }
        let (c, u, v) = (rng.point(5.0), rng.point(2.0), rng.point(2.0));
        let q = Emitter::quad(c, u, v, 1.0, true);
        assert!(q.two_sided);
        assert!((q.area - u.cross(v).length()).abs() <= 1e-5 * q.area.max(1.0));
        for _ in 0..20 {
            assert!(contains(&q.bounds, c + rng.f() * u + rng.f() * v));
        }
        let (normal, r) = (rng.dir(), rng.range(0.1, 3.0));
        let d = Emitter::disk(c, normal, r, 1.0, false);
        assert!((d.area - PI * r * r).abs() <= 1e-5 * d.area);
        let (a, b) = normal.any_orthonormal_pair();
        for _ in 0..20 {
            let (rho, phi) = (r * rng.f().sqrt(), 2.0 * PI * rng.f());
            assert!(contains(
                &d.bounds,
                c + rho * (phi.cos() * a + phi.sin() * b)
            ));
        }
    }
    // The disk's box is its own: a disk facing +y is flat in y.
    let d = Emitter::disk(Vec3::ONE, Vec3::Y, 2.0, 1.0, false);
    assert_eq!((d.bounds.min.y, d.bounds.max.y), (1.0, 1.0));
    assert!((d.bounds.max.x - 3.0).abs() < 1e-6);
}

#[test]
fn one_sided_lights_are_dark_behind_two_sided_ones_are_not() {
    let below = Vec3::new(0.3, -2.0, 0.1);
    let above = Vec3::new(0.3, 2.0, 0.1);
    let tri = [Vec3::ZERO, Vec3::new(0.0, 0.0, 1.0), Vec3::X]; // normal +y
    for (e, name) in [
        (Emitter::triangle(tri, 10.0, false), "triangle"),
        (
            Emitter::quad(Vec3::ZERO, Vec3::Z, Vec3::X, 10.0, false),
            "quad",
        ),
        (Emitter::disk(Vec3::ZERO, Vec3::Y, 1.0, 10.0, false), "disk"),
    ] {
        // Shading points facing the light.
        assert!(importance_pmf(e, above, -Vec3::Y) > 0.9, "{name}");
        assert_eq!(importance_pmf(e, below, Vec3::Y), 0.0, "{name}");
        let two = Emitter {
            two_sided: true,
            ..e
        };
        assert!(importance_pmf(two, below, Vec3::Y) > 0.9, "{name}");
    }
}

#[test]
fn spots_reach_their_cone_only() {
    let s = Emitter::spot(Vec3::ZERO, -Vec3::Y, 0.9, 0.7, 50.0);
    assert!(s.delta && s.area == 0.0);
    let cone = s.cone.unwrap();
    assert!((cone.theta_o() - 0.9f32.acos()).abs() < 1e-5);
    assert!((cone.theta_o() + cone.theta_e() - 0.7f32.acos()).abs() < 1e-5);
    // Straight below, at the edge of full intensity, inside the falloff,
    // and beyond its end.
    for (angle, lit) in [
        (0.0f32, true),
        (0.44, true),
        (0.75, true),
        (0.85, false),
        (2.0, false),
    ] {
        let p = Vec3::new(angle.sin(), -angle.cos(), 0.0) * 3.0;
        let pmf = importance_pmf(s, p, -p);
        assert_eq!(pmf > 0.0, lit, "angle {angle}: {pmf}");
    }
}

#[test]
fn light_bounds_map_one_to_one() {
    let b = Aabb::new(Vec3::ZERO, Vec3::ONE);
    let e =
        Emitter::from_light_bounds(b, Vec3::new(0.0, 0.0, 2.0), 7.0, 0.5, 0.2, true, 3.0, false);
    let cone = e.cone.unwrap();
    assert_eq!(e.bounds, b);
    assert_eq!(e.power, 7.0);
    assert_eq!(cone.axis, Vec3::Z);
    assert!((cone.cos_theta_o - 0.5).abs() < 1e-6);
    assert!((cone.cos_theta_e - 0.2).abs() < 1e-6);
    assert!(e.two_sided && !e.delta && e.area == 3.0);
}

#[test]
fn degenerate_shapes_are_conservative() {
    // A triangle with zero area, a disk with a zero normal: they emit
    // everywhere (never discounted by orientation), and a tree builds.
    let t = Emitter::triangle([Vec3::ZERO, Vec3::X, 2.0 * Vec3::X], 1.0, false);
    assert_eq!(t.area, 0.0);
    assert!(t.cone.unwrap().is_sphere());
    let d = Emitter::disk(Vec3::ZERO, Vec3::ZERO, 1.0, 1.0, false);
    assert!(d.cone.unwrap().is_sphere());
    assert!(contains(&d.bounds, Vec3::new(0.0, 1.0, 0.0)));
    for e in [t, d] {
        assert!(importance_pmf(e, Vec3::new(0.5, -3.0, 0.0), Vec3::Y) > 0.5);
    }
}
