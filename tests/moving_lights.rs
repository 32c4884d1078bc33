//! Lights that move between frames: a guide handed its light tree after a
//! refit keeps what it learned and every contract, samples as one that
//! learned the same records over the refitted tree, reaches every light
//! that shines now, and refuses a tree of another shape.

use glam::Vec3;
use guiding::cut::CutConfig;
use guiding::field::{FieldConfig, GuidingField};
use guiding::glt::{Glt, GltConfig};
use guiding::light_tree::BuildHeuristic;
use guiding::math::Aabb;
use guiding::spatial::SpatialTree;
use guiding::{Emitter, Error, LightHierarchy, LightId, LightSampler, LightTree, ShadingContext};

mod common;
use common::{ByPosition, LightsAt, Rand, mixed_scene, value};

/// How many of the scene's lights are dark in the first frame and shine in
/// the second.
const RELIT: usize = 10;

fn bounds() -> Aabb {
    Aabb::new(Vec3::splat(-60.0), Vec3::splat(60.0))
}

/// Two frames of one scene: 300 mixed lights, then every light moved by
/// up to 1 (the box is 100 wide) and its power scaled by up to `scale`
/// either way. With `relit`, the first [`RELIT`] lights (points) are dark
/// in the first frame and shine in the second.
fn frames(step: f32, scale: f32, relit: bool) -> (Vec<Emitter>, Vec<Emitter>) {
    let mut first = mixed_scene(300, 81);
    if relit {
        for e in &mut first[..RELIT] {
            *e = Emitter::point(e.bounds.center(), 0.0);
        }
    }
    let mut r = Rand::new(82);
    let second = first
        .iter()
        .map(|e| {
            let d = r.point(step);
            let mut m = *e;
            m.bounds = Aabb::new(e.bounds.min + d, e.bounds.max + d);
            m.power = match e.power {
                0.0 => 50.0,
                p => p * scale.powf(r.range(-1.0, 1.0)),
            };
            m
        })
        .collect();
    (first, second)
}

/// Four iterations of records: points in the box and lights drawn
/// uniformly, the same for every guide they train; each light's
/// contribution at the point (with a wall at x = 0) over its probability,
/// in `lights`' frame.
fn records_of(lights: &[Emitter]) -> Vec<Vec<(Vec3, u32, f32)>> {
    let mut r = Rand::new(83);
    let n = lights.len() as u32;
    (0..4)
        .map(|_| {
            (0..6000)
                .map(|_| {
                    let p = r.point(50.0);
                    let e = r.below(n);
                    (p, e, value(lights, e, p) * n as f32)
                })
                .collect()
        })
        .collect()
}

fn train<G: LightsAt>(guide: &mut G, records: &[Vec<(Vec3, u32, f32)>], refine: fn(&mut G)) {
    for iteration in records {
        for &(p, e, v) in iteration {
            guide.record_light_at(p, LightId::Emitter(e), v);
        }
        refine(guide);
    }
}

fn glt_config() -> GltConfig {
    GltConfig {
        spatial_threshold: 1000.0,
        ..GltConfig::default()
    }
}

/// Total variation between two guides' light choices at `p`.
fn total_variation<A: LightsAt, B: LightsAt>(a: &A, b: &B, p: Vec3, n: u32) -> f64 {
    let ctx = ShadingContext::at(p);
    (0..n)
        .map(|e| {
            let l = LightId::Emitter(e);
            (ByPosition(a).pmf_exact(&ctx, l) - ByPosition(b).pmf_exact(&ctx, l)).abs()
        })
        .sum::<f64>()
        * 0.5
}

/// The light-sampler contract at random points (pmfs sum to 1, a sample
/// reports exactly its pmf), and every light that reaches a point now is
/// chosen there with a positive probability.
fn check_contract<G: LightsAt>(guide: &G, lights: &[Emitter], r: &mut Rand) {
    let n = lights.len() as u32;
    for _ in 0..40 {
        let p = r.point(50.0);
        let ctx = ShadingContext::at(p);
        let g = ByPosition(guide);
        let total: f64 = (0..n).map(|e| g.pmf_exact(&ctx, LightId::Emitter(e))).sum();
        assert!((total - 1.0).abs() < 1e-6, "{total} at {p}");
        for _ in 0..20 {
            let s = g.sample(&ctx, r.f()).unwrap();
            assert_eq!(s.pmf.to_bits(), g.pmf(&ctx, s.light).to_bits());
        }
        // Points and spheres (the lights `value` describes fully: it knows
        // no cones) that reach the point.
        for e in 0..n {
            if lights[e as usize].cone.is_none() && value(lights, e, p) > 0.0 {
                let pmf = g.pmf(&ctx, LightId::Emitter(e));
                assert!(pmf > 0.0, "light {e} reaches {p} but has pmf 0");
            }
        }
    }
}

/// A GLT trained over the first frame and handed the refitted tree, the
/// same GLT left over the first frame's tree, and one trained from scratch
/// over the refitted tree with the same records made in the second frame:
/// the mean total variation between the carried-over and the fresh one's
/// light choices, and between the stale and the fresh one's.
fn carried_and_stale(step: f32, scale: f32) -> (f64, f64) {
    let (first, second) = frames(step, scale, false);
    let tree = LightTree::build(first.as_slice(), BuildHeuristic::Sarh).unwrap();
    let mut carried = Glt::new(tree.clone(), bounds(), glt_config()).unwrap();
    train(&mut carried, &records_of(&first), |g| {
        g.refine();
    });
    let stale = carried.clone();
    let cells = carried.spatial().cell_count();
    assert!(cells > 4, "{cells} cells");
    let mut refitted = tree.clone();
    let drift = refitted.refit(second.as_slice()).unwrap();
    assert!(drift < LightTree::REBUILD_RATIO, "{drift}");
    let old = carried.set_light_tree(refitted.clone()).unwrap();
    assert_eq!(old.to_bytes(), tree.to_bytes());
    assert_eq!(carried.spatial().cell_count(), cells);
    assert_eq!(carried.iteration(), 4);
    for cell in carried.spatial().data_slice() {
        cell.cut().check(carried.light_tree()).unwrap();
    }
    let mut fresh = Glt::new(refitted, bounds(), glt_config()).unwrap();
    train(&mut fresh, &records_of(&second), |g| {
        g.refine();
    });
    let mut r = Rand::new(84);
    let points: Vec<Vec3> = (0..100).map(|_| r.point(50.0)).collect();
    let n = second.len() as u32;
    let mean = |a: &Glt<LightTree>| {
        points
            .iter()
            .map(|&p| total_variation(a, &fresh, p, n))
            .sum::<f64>()
            / points.len() as f64
    };
    check_contract(&carried, &second, &mut r);
    (mean(&carried), mean(&stale))
}

#[test]
fn a_refitted_glt_samples_as_one_that_learned_over_the_refitted_tree() {
    // A small move: every light up to 0.25 in a box 100 wide, its power
    // within 10%.
    let (tv, stale) = carried_and_stale(0.25, 1.1);
    assert!(
        tv < 0.05,
        "carried over: total variation {tv} (stale: {stale})"
    );
    // Powers that change up to 4x: the refitted tree's powers and bounds
    // take the learned state most of the way; the control, the same state
    // over the first frame's tree, stays far.
    let (tv, stale) = carried_and_stale(0.25, 4.0);
    assert!(tv < stale / 2.0, "carried over {tv}, stale {stale}");
}

#[test]
fn a_refitted_glt_reaches_every_light_that_shines_now() {
    // Powers change up to 4x, and ten lights that were dark (so learned
    // nothing) shine.
    let (first, second) = frames(1.0, 4.0, true);
    let tree = LightTree::build(first.as_slice(), BuildHeuristic::Sarh).unwrap();
    let mut glt = Glt::new(tree.clone(), bounds(), glt_config()).unwrap();
    train(&mut glt, &records_of(&first), |g| {
        g.refine();
    });
    let mut refitted = tree;
    refitted.refit(second.as_slice()).unwrap();
    glt.set_light_tree(refitted).unwrap();
    check_contract(&glt, &second, &mut Rand::new(86));
    // The control: over the old tree, a light dark in the first frame is
    // never chosen.
    let (first, second) = frames(1.0, 4.0, true);
    let tree = LightTree::build(first.as_slice(), BuildHeuristic::Sarh).unwrap();
    let glt = Glt::new(tree, bounds(), glt_config()).unwrap();
    let ctx = ShadingContext::at(second[0].bounds.center() + Vec3::X);
    assert_eq!(ByPosition(&glt).pmf(&ctx, LightId::Emitter(0)), 0.0);
}

#[test]
fn a_refitted_field_keeps_its_contract_and_its_directions() {
    let (first, second) = frames(1.0, 4.0, true);
    let records = records_of(&first);
    let tree = LightTree::build(first.as_slice(), BuildHeuristic::Sarh).unwrap();
    let config = FieldConfig {
        cut: CutConfig::default(),
        ..FieldConfig::default()
    };
    let mut field = GuidingField::new(tree.clone(), bounds(), config).unwrap();
    train(&mut field, &records, |f| {
        f.refine();
    });
    let cells = field.cell_count();
    let mut refitted = tree;
    refitted.refit(second.as_slice()).unwrap();
    field.set_light_tree(refitted).unwrap();
    assert_eq!(field.cell_count(), cells);
    check_contract(&field, &second, &mut Rand::new(85));
}

#[test]
fn a_tree_of_another_shape_is_refused_and_nothing_changes() {
    let (first, second) = frames(1.0, 1.1, false);
    let tree = LightTree::build(first.as_slice(), BuildHeuristic::Sarh).unwrap();
    let mut glt = Glt::new(tree.clone(), bounds(), glt_config()).unwrap();
    train(&mut glt, &records_of(&first)[..2], |g| {
        g.refine();
    });
    let saved = glt.to_bytes();
    let others = [
        LightTree::build(second.as_slice(), BuildHeuristic::Balanced).unwrap(),
        LightTree::build(&second[..299], BuildHeuristic::Sarh).unwrap(),
        LightTree::build(&[] as &[Emitter], BuildHeuristic::Sarh).unwrap(),
    ];
    for other in others {
        assert_eq!(glt.set_light_tree(other).err(), Some(Error::LightTreeShape));
        assert_eq!(glt.to_bytes(), saved);
    }
    let mut field = GuidingField::new(tree, bounds(), FieldConfig::default()).unwrap();
    let other = LightTree::build(second.as_slice(), BuildHeuristic::Balanced).unwrap();
    assert_eq!(
        field.set_light_tree(other).err(),
        Some(Error::LightTreeShape)
    );
    assert!(Error::LightTreeShape.to_string().contains("refit"));
    // Any hierarchy a guide can hold: a borrowed one, refitted.
    let mut owned = LightTree::build(first.as_slice(), BuildHeuristic::Sarh).unwrap();
    let before = owned.clone();
    let mut borrowed = Glt::new(&before, bounds(), glt_config()).unwrap();
    owned.refit(second.as_slice()).unwrap();
    assert!(borrowed.set_light_tree(&owned).is_ok());
    assert_eq!(borrowed.light_tree().node_count(), before.node_count());
}

/// A guide carried into a new frame re-learns from the new frame's records
/// at once: after `restart` (which `set_light_tree` does) every cell with
/// records takes part in the next refinement; without it, a cell waits for
/// 3/2 of what it refined on last.
#[test]
fn a_restarted_glt_refines_every_cell_on_the_next_records() {
    let (first, second) = frames(0.25, 1.1, false);
    let tree = LightTree::build(first.as_slice(), BuildHeuristic::Sarh).unwrap();
    let mut glt = Glt::new(tree.clone(), bounds(), glt_config()).unwrap();
    // A long last iteration: many records per cell.
    let mut records = records_of(&first);
    records[3] = records[3].repeat(8);
    train(&mut glt, &records, |g| {
        g.refine();
    });
    let generations = |g: &Glt<LightTree>| -> Vec<u32> {
        g.spatial()
            .data_slice()
            .iter()
            .map(|c| c.generation())
            .collect()
    };
    let few = &records_of(&second)[0][..3000];
    let refined = |mut g: Glt<LightTree>| {
        let before = generations(&g);
        train(&mut g, &[few.to_vec()], |g| {
            g.refine();
        });
        let after = generations(&g);
        let took_part = before.iter().zip(&after).filter(|(b, a)| a > b).count();
        (took_part, after.len())
    };
    let (waiting, cells) = refined(glt.clone());
    assert_eq!(
        waiting, 0,
        "without a restart no cell has 3/2 of its last count"
    );
    let mut restarted = glt.clone();
    restarted.restart();
    let (taking_part, _) = refined(restarted);
    assert!(
        taking_part * 10 >= cells * 9,
        "{taking_part} of {cells} cells refined"
    );
    let mut refitted = tree;
    refitted.refit(second.as_slice()).unwrap();
    glt.set_light_tree(refitted).unwrap();
    let (after_refit, _) = refined(glt);
    assert_eq!(after_refit, taking_part);
}
