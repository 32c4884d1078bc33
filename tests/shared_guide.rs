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
use guiding::shared_guide::{RefineSchedule, SharedGuide};
use guiding::{LightChoice, LightId, LightSampler, LightTree, ShadingContext};
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
    keeps_the_contracts(&shared.read(), &tree);
}

/// Every cut valid; at 50 points the pmf over the 80 lights sums to 1 and
/// a sample's pmf is the pmf of its light.
fn keeps_the_contracts(glt: &Glt<&LightTree>, tree: &LightTree) {
    for cell in glt.spatial().data_slice() {
        assert!(cell.cut().check(tree).is_ok());
    }
    let mut rng = Rand::new(7);
    for _ in 0..50 {
        let ctx = ShadingContext::at(rng.point(9.0));
        let total: f64 = (0..80)
            .map(|e| ByPosition(glt).pmf_exact(&ctx, LightId::Emitter(e)))
            .sum();
        assert!((total - 1.0).abs() < 1e-6);
        let x = ByPosition(glt).sample(&ctx, rng.f()).unwrap();
        assert_eq!(x.pmf, ByPosition(glt).pmf(&ctx, x.light));
    }
}

/// PPG's doubling through `refine_when_due`: the refinements run after
/// exactly `first`, `3 first`, `7 first` paths, counted however the calls
/// group them. Control: a schedule that doubled the total instead (after
/// `first`, `2 first`, `4 first`) refines at 200 paths and fails here.
#[test]
fn doubling_refines_after_first_three_and_seven_times_first() {
    let tree = LightTree::build(&two_rooms(), BuildHeuristic::Sarh).unwrap();
    let glt = Glt::new(&tree, scene(), config()).unwrap();
    let schedule = RefineSchedule::Doubling { first: 100 };
    let shared = SharedGuide::with_schedule(glt, schedule).unwrap();
    assert_eq!(shared.schedule(), schedule);
    let mut ran = Vec::new();
    for path in 1..=800u64 {
        // A tile of 4 paths every 50 paths, single paths between.
        let n = if path % 50 == 0 { 4 } else { 1 };
        if shared.refine_when_due(n).is_some() {
            ran.push(path);
        }
    }
    let counted: Vec<u64> = ran.iter().map(|&p| p + 3 * (p / 50)).collect();
    assert_eq!(counted, [100, 300, 700], "paths counted at each refinement");
    assert_eq!(shared.refinements(), 3);
}

/// The amortized schedule refines at the first call (nothing took any
/// time yet), then waits `ratio` times what that refinement took. Control:
/// with the clock not updated after a refinement, the second call refines
/// again and this fails.
#[test]
fn amortized_waits_ratio_times_the_last_refinement() {
    let tree = LightTree::build(&two_rooms(), BuildHeuristic::Sarh).unwrap();
    let glt = Glt::new(&tree, scene(), config()).unwrap();
    let lazy = RefineSchedule::Amortized { ratio: u32::MAX };
    let shared = SharedGuide::with_schedule(glt, lazy).unwrap();
    assert!(shared.refine_when_due(1).is_some());
    for _ in 0..1000 {
        assert!(shared.refine_when_due(1).is_none());
    }
    assert_eq!(shared.refinements(), 1);
    // The GLT's own default, and the others' doubling from their threshold.
    let glt = Glt::new(&tree, scene(), config()).unwrap();
    assert_eq!(SharedGuide::new(glt).schedule(), RefineSchedule::GLT);
    let sd = guiding::SdTree::new(scene(), Default::default()).unwrap();
    assert_eq!(
        SharedGuide::new(sd).schedule(),
        RefineSchedule::Doubling { first: 12_000 }
    );
}

/// A schedule that could never refine, or would refine at every call
/// forever, is a configuration error.
#[test]
fn invalid_schedules_are_errors() {
    let tree = LightTree::build(&two_rooms(), BuildHeuristic::Sarh).unwrap();
    for bad in [
        RefineSchedule::Amortized { ratio: 0 },
        RefineSchedule::Doubling { first: 0 },
    ] {
        let glt = Glt::new(&tree, scene(), config()).unwrap();
        let e = SharedGuide::with_schedule(glt, bad).unwrap_err();
        assert!(matches!(e, guiding::Error::Config(_)), "{e}");
        assert!(e.to_string().contains("at least 1"), "{e}");
    }
}

/// Four threads hold the guard per path and call `refine_when_due` after
/// each, as a renderer with tiles from a queue does: no deadlock, the GLT
/// refines, and its distributions keep their contracts.
#[test]
fn refining_when_due_from_every_path() {
    let lights = two_rooms();
    let tree = LightTree::build(&lights, BuildHeuristic::Sarh).unwrap();
    let shared = SharedGuide::new(Glt::new(&tree, scene(), config()).unwrap());
    std::thread::scope(|s| {
        for t in 0..4u64 {
            let (shared, lights) = (&shared, &lights);
            s.spawn(move || {
                let mut rng = Rand::new(300 + t);
                for _ in 0..3000 {
                    let glt = shared.read();
                    let p = rng.point(9.5);
                    let ctx = ShadingContext::at(p);
                    let v = glt.vertex(&ctx).unwrap();
                    let x = v.sample(rng.f()).unwrap();
                    let LightId::Emitter(e) = x.light else {
                        panic!("no unbounded lights")
                    };
                    v.record_light(x.light, value(lights, e, p) / x.pmf);
                    drop(glt);
                    shared.refine_when_due(1);
                }
            });
        }
    });
    assert!(shared.refinements() >= 2, "{}", shared.refinements());
    keeps_the_contracts(&shared.read(), &tree);
}

/// The SD-tree and the field refine through a `SharedGuide` as they do on
/// their own: the same records give the same outcome, splits included.
/// Control: a `Refine` impl that skipped the refinement returns no splits.
#[test]
fn the_sd_tree_and_the_field_refine_through_the_shared_guide() {
    use guiding::{FieldConfig, GuidingField, SdTree, SdTreeConfig};
    let sd_config = SdTreeConfig {
        spatial_threshold: 100.0,
        ..SdTreeConfig::default()
    };
    let record = |f: &dyn Fn(&ShadingContext)| {
        let mut rng = Rand::new(5);
        for _ in 0..4000 {
            f(&ShadingContext::at(rng.point(9.5)));
        }
    };
    let dir = Vec3::Y;
    let mut alone = SdTree::new(scene(), sd_config).unwrap();
    record(&|ctx| {
        let _ = alone.vertex(ctx).unwrap().record_radiance(dir, 1.0, 1.0);
    });
    let shared = SharedGuide::new(SdTree::new(scene(), sd_config).unwrap());
    record(&|ctx| {
        let _ = shared
            .read()
            .vertex(ctx)
            .unwrap()
            .record_radiance(dir, 1.0, 1.0);
    });
    let expected = alone.refine();
    assert!(expected.splits > 0);
    assert_eq!(shared.refine(), expected);

    let tree = LightTree::build(&two_rooms(), BuildHeuristic::Sarh).unwrap();
    let config = FieldConfig {
        sd: sd_config,
        ..FieldConfig::default()
    };
    let mut alone = GuidingField::new(&tree, scene(), config).unwrap();
    let field_record = |f: &GuidingField<&LightTree>, ctx: &ShadingContext| {
        let _ = f
            .vertex(ctx)
            .unwrap()
            .direction
            .record_radiance(dir, 1.0, 1.0);
    };
    record(&|ctx| field_record(&alone, ctx));
    let shared = SharedGuide::new(GuidingField::new(&tree, scene(), config).unwrap());
    record(&|ctx| field_record(&shared.read(), ctx));
    let expected = alone.refine();
    assert!(expected.splits > 0);
    assert_eq!(shared.refine(), expected);
}
