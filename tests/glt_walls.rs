//! Learning never carries light through walls: a sealed, dim room between
//! two sealed rooms full of bright lights must learn its own lights with
//! the GLT's default record, not the neighbours' (which it cannot see).
//!
//! The scene is analytic: small sphere lights near the ceilings of four
//! rooms side by side along x (the walls lie on the spatial tree's split
//! planes), shading points on the floors, a light reaches a point only in
//! its own room. Training is what a renderer does: at each point one NEE
//! sample from the GLT (record contribution / pmf where the light is
//! visible) and one cosine-distributed "BSDF" direction (record what it
//! hits, radiance x cos / pdf), refine after each iteration of 2^k
//! batches. The variance at the dim room's points is then computed exactly
//! from every light's contribution.

mod common;
use common::{ByPosition, LightsAt};

use common::Rand;
use glam::Vec3;
use guiding::cut::{CutConfig, Modulation};
use guiding::glt::{Glt, GltConfig};
use guiding::light_sampler::PowerSampler;
use guiding::light_tree::BuildHeuristic;
use guiding::math::Aabb;
use guiding::spatial::SpatialFilter;
use guiding::{Emitter, LightId, LightSampler, LightTree, ShadingContext};

/// Room width along x; rooms are `[4k, 4k + 4) x [0, 3) x [0, 4)`.
const ROOM: f32 = 4.0;
/// Number of rooms.
const ROOMS: usize = 4;
/// The dim room.
const DIM: usize = 1;
/// Radius of the sphere lights: the dim room's few lights are larger (a
/// renderer's BSDF samples find them), the bright rooms' many are small.
fn radius(room: usize) -> f32 {
    if room == DIM { 0.25 } else { 0.05 }
}

fn room_of(p: Vec3) -> usize {
    (p.x / ROOM).floor().clamp(0.0, (ROOMS - 1) as f32) as usize
}

/// Four sealed rooms: room `DIM` holds 4 lights of power 1, the others 790
/// lights of power 100 each.
fn rooms() -> Vec<Emitter> {
    let mut rng = Rand::new(7);
    let mut lights = Vec::new();
    for room in 0..ROOMS {
        let (count, power) = if room == DIM { (4, 1.0) } else { (790, 100.0) };
        for _ in 0..count {
            let p = Vec3::new(
                room as f32 * ROOM + rng.range(0.3, ROOM - 0.3),
                rng.range(2.5, 2.9),
                rng.range(0.3, 3.7),
            );
            lights.push(Emitter::sphere(p, radius(room), power));
        }
    }
    lights
}

/// Irradiance from light `e` at floor point `p` (normal +y); 0 from
/// another room.
fn contribution(e: &Emitter, p: Vec3) -> f64 {
    let q = e.bounds.center();
    if room_of(q) != room_of(p) {
        return 0.0;
    }
    let d = q - p;
    let d2 = d.length_squared() as f64;
    let cos = (d.y as f64 / d2.sqrt()).max(0.0);
    e.power as f64 / (4.0 * std::f64::consts::PI * d2) * cos
}

/// A floor point of `room`, 5 cm away from its walls.
fn floor_point(rng: &mut Rand, room: usize) -> Vec3 {
    Vec3::new(
        room as f32 * ROOM + rng.range(0.05, ROOM - 0.05),
        0.0,
        rng.range(0.05, 3.95),
    )
}

/// A cosine-distributed direction around +y and what it hits: the nearest
/// light of the point's own room, with the estimate radiance x cos / pdf
/// (= radiance x pi).
fn bsdf_hit(lights: &[Emitter], p: Vec3, rng: &mut Rand) -> Option<(u32, f64)> {
    let (r, phi) = (rng.f().sqrt(), std::f32::consts::TAU * rng.f());
    let d = Vec3::new(r * phi.cos(), (1.0 - r * r).max(0.0).sqrt(), r * phi.sin());
    let mut best: Option<(f32, u32)> = None;
    for (i, e) in lights.iter().enumerate() {
        let c = e.bounds.center();
        if room_of(c) != room_of(p) {
            continue;
        }
        let oc = c - p;
        let t = oc.dot(d);
        let r = radius(room_of(c));
        if t > 0.0 && (oc - d * t).length_squared() < r * r && best.is_none_or(|b| t < b.0) {
            best = Some((t, i as u32));
        }
    }
    let (_, i) = best?;
    // A sphere of power P and radius r has radiance P / (4 pi^2 r^2).
    let e = &lights[i as usize];
    let r = f64::from(radius(room_of(e.bounds.center())));
    let radiance = e.power as f64 / (4.0 * std::f64::consts::PI.powi(2) * r * r);
    Some((i, radiance * std::f64::consts::PI))
}

/// Exact variance of one-sample NEE with `pmf` at `p`: `sum c^2 / P - I^2`.
fn variance(lights: &[Emitter], p: Vec3, pmf: impl Fn(LightId) -> f64) -> f64 {
    let (mut m2, mut mean) = (0.0, 0.0);
    for (i, e) in lights.iter().enumerate() {
        let c = contribution(e, p);
        if c > 0.0 {
            let q = pmf(LightId::Emitter(i as u32));
            assert!(q > 0.0, "a visible light has pmf 0");
            m2 += c * c / q;
            mean += c;
        }
    }
    m2 - mean * mean
}

/// Trains a GLT with `config` and `filter` on the three rooms, recording
/// through `LightVertex::record_light`; the dim room's variance relative to power
/// sampling's.
fn dim_room_ratio(config: CutConfig, filter: SpatialFilter) -> f64 {
    let lights = rooms();
    let tree = LightTree::build(&lights, BuildHeuristic::default()).unwrap();
    let scene = Aabb::new(Vec3::ZERO, Vec3::new(ROOMS as f32 * ROOM, 3.0, 4.0));
    let mut glt = Glt::new(
        &tree,
        scene,
        GltConfig {
            cut: config,
            spatial_threshold: 400.0,
            max_bytes: None,
            light_filter: filter,
        },
    )
    .unwrap();
    let mut rng = Rand::new(11);
    for k in 0..7 {
        for _ in 0..(1500 << k) {
            let room = rng.below(ROOMS as u32) as usize;
            let p = floor_point(&mut rng, room);
            let ctx = ShadingContext::on_surface(p, Vec3::Y);
            if let Some((light, value)) = bsdf_hit(&lights, p, &mut rng) {
                glt.record_light_at(p, LightId::Emitter(light), value as f32);
            }
            let Some(s) = ByPosition(&glt).sample(&ctx, rng.f()) else {
                continue;
            };
            let LightId::Emitter(e) = s.light else {
                continue;
            };
            let c = contribution(&lights[e as usize], p);
            if c > 0.0 {
                glt.record_light_at(p, s.light, (c / s.pmf as f64) as f32);
            }
        }
        glt.refine();
    }
    let power = PowerSampler::new(&lights);
    let (mut v_glt, mut v_power) = (0.0, 0.0);
    for _ in 0..200 {
        let p = floor_point(&mut rng, DIM);
        let ctx = ShadingContext::on_surface(p, Vec3::Y);
        v_glt += variance(&lights, p, |l| ByPosition(&glt).pmf_exact(&ctx, l));
        v_power += variance(&lights, p, |l| f64::from(power.pmf(&ctx, l)));
    }
    v_glt / v_power
}

/// The dim room learns its own lights with the default record: its
/// variance is at most 2e-5 of power sampling's (the bar was 1/10;
/// nearest records give 6.3e-6 without modulation and 3.9e-6 with it, so
/// a change that triples either fails here), with and without modulation.
#[test]
fn dim_room_beside_bright_rooms_learns_its_own_lights() {
    let filter = GltConfig::default().light_filter;
    for modulation in [Modulation::None, Modulation::Importance] {
        let config = CutConfig {
            modulation,
            ..CutConfig::default()
        };
        let ratio = dim_room_ratio(config, filter);
        assert!(
            ratio <= 2e-5,
            "{modulation:?}: GLT / power variance {ratio}"
        );
    }
}

/// The control that shows the test above can fail: jittered records
/// (PPG's stochastic box) carry the bright rooms' lights through the walls
/// into the dim room's cells by the walls, whose variance then dominates
/// (about 0.08 of power's here, 10,000x the nearest filter's).
#[test]
fn jittered_records_leak_through_walls() {
    let ratio = dim_room_ratio(CutConfig::default(), SpatialFilter::StochasticBox);
    assert!(ratio > 1e-2, "stochastic box: GLT / power variance {ratio}");
}
