//! A [`SharedGuide`] refined through `&self` by one of the threads that
//! render with it: the learned state equals a serial run bit for bit in
//! deterministic mode; `try_refine` never waits; refinements from workers
//! in the middle of a render keep every contract.

mod common;
use common::ByPosition;
use common::LightsAt;

use common::{Rand, scene, two_rooms, value};
use glam::Vec3;
use guiding::cut::CutConfig;
use guiding::glt::{Glt, GltConfig};
use guiding::light_tree::BuildHeuristic;
use guiding::math::Accumulation;
use guiding::shared_guide::SharedGuide;
use guiding::{LightId, LightSampler, LightTree, ShadingContext};
use std::sync::Barrier;

fn config() -> GltConfig {
    GltConfig {
        cut: CutConfig {
            accumulation: Accumulation::Deterministic,
            ..CutConfig::default()
        },
        spatial_threshold: 300.0,
        ..GltConfig::default()
    }
}

/// Four workers record tiles of a stream; after each round one of them
/// refines through `&self`. A serial run of the same records with
/// `refine(&mut self)` between rounds learns the same cuts, bit for bit.
#[test]
fn refining_from_a_worker_equals_serial() {
    let lights = two_rooms();
    let tree = LightTree::build(&lights, BuildHeuristic::Sarh).unwrap();
    let mut rng = Rand::new(31);
    let stream: Vec<(Vec3, u32, f32)> = (0..24_000)
        .map(|_| {
            let p = rng.point(9.5);
            let e = rng.below(80);
            (p, e, value(&lights, e, p) * rng.range(0.5, 1.5))
        })
        .collect();
    let rounds: Vec<&[(Vec3, u32, f32)]> = stream.chunks(8000).collect();
    let mut serial = Glt::new(&tree, scene(), config()).unwrap();
    for round in &rounds {
        for &(p, e, v) in *round {
            serial.record_light_at(p, LightId::Emitter(e), v);
        }
        serial.refine();
    }
    let shared = SharedGuide::new(Glt::new(&tree, scene(), config()).unwrap());
    let barrier = Barrier::new(4);
    std::thread::scope(|s| {
        for t in 0..4 {
            let (shared, barrier, rounds) = (&shared, &barrier, &rounds);
            s.spawn(move || {
                for round in rounds {
                    // Tiles of 100 records, one guard each.
                    for tile in round.chunks(100).skip(t).step_by(4) {
                        let glt = shared.read();
                        for &(p, e, v) in tile {
                            glt.record_light_at(p, LightId::Emitter(e), v);
                        }
                    }
                    if barrier.wait().is_leader() {
                        shared.refine();
                    }
                    barrier.wait();
                }
            });
        }
    });
    assert_eq!(shared.refinements(), 3);
    let shared = shared.into_inner();
    let (a, b) = (serial.spatial().data_slice(), shared.spatial().data_slice());
    assert!(a.len() > 4);
    assert_eq!(a.len(), b.len());
    for (x, y) in a.iter().zip(b) {
        let x: &[u8] = bytemuck::cast_slice(x.cut().nodes());
        let y: &[u8] = bytemuck::cast_slice(y.cut().nodes());
        assert_eq!(x, y);
    }
}

/// `try_refine` refuses at once while another thread holds a guard, and
/// refines once it is dropped.
#[test]
fn try_refine_never_waits() {
    let tree = LightTree::build(&two_rooms(), BuildHeuristic::Sarh).unwrap();
    let shared = SharedGuide::new(Glt::new(tree, scene(), config()).unwrap());
    let held = Barrier::new(2);
    let tried = Barrier::new(2);
    std::thread::scope(|s| {
        s.spawn(|| {
            let _glt = shared.read();
            held.wait();
            tried.wait();
        });
        held.wait();
        assert!(shared.try_refine().is_none());
        tried.wait();
    });
    assert!(shared.try_refine().is_some());
    assert_eq!(shared.refinements(), 1);
}

/// Workers render and record while two of them refine whenever they like
/// (one waiting, one only when nothing is in flight): no deadlock, every
/// cut stays valid, the pmf sums to 1 and sampling matches it.
#[test]
fn refinements_in_the_middle_of_a_render_keep_the_contracts() {
    let lights = two_rooms();
    let tree = LightTree::build(&lights, BuildHeuristic::Sarh).unwrap();
    let fast = GltConfig {
        spatial_threshold: 200.0,
        ..GltConfig::default()
    };
    let shared = SharedGuide::new(Glt::new(&tree, scene(), fast).unwrap());
    std::thread::scope(|s| {
        for t in 0..4u64 {
            let (shared, lights) = (&shared, &lights);
            s.spawn(move || {
                let mut rng = Rand::new(100 + t);
                for tile in 0..60 {
                    {
                        let glt = shared.read();
                        for _ in 0..50 {
                            let p = rng.point(9.5);
                            let x = ByPosition(&*glt)
                                .sample(&ShadingContext::at(p), rng.f())
                                .unwrap();
                            let LightId::Emitter(e) = x.light else {
                                panic!("no unbounded lights")
                            };
                            glt.record_light_at(p, x.light, value(lights, e, p) / x.pmf);
                        }
                    }
                    match t {
                        0 if tile % 10 == 9 => {
                            shared.refine();
                        }
                        1 => {
                            shared.try_refine();
                        }
                        _ => {}
                    }
                }
            });
        }
    });
    assert!(shared.refinements() >= 6);
    let glt = shared.read();
    for cell in glt.spatial().data_slice() {
        assert!(cell.cut().check(&tree).is_ok());
    }
    let mut rng = Rand::new(7);
    for _ in 0..50 {
        let ctx = ShadingContext::at(rng.point(9.0));
        let total: f64 = (0..80)
            .map(|e| ByPosition(&*glt).pmf_exact(&ctx, LightId::Emitter(e)))
            .sum();
        assert!((total - 1.0).abs() < 1e-6);
        let x = ByPosition(&*glt).sample(&ctx, rng.f()).unwrap();
        assert_eq!(x.pmf, ByPosition(&*glt).pmf(&ctx, x.light));
    }
}
