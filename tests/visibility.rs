//! The cut clusters' learned visibility (`CutConfig::visibility`): in the
//! two rooms, each room learns that the other room's lights are hidden
//! and its own are seen; it is off (1 everywhere, nothing recorded) by
//! default; bad records are dropped and counted; it survives saving,
//! loading and merging; resampled light choice with it stays unbiased and
//! beats a blind target.

mod common;
use common::{ByPosition, LightsAt};
use guiding::LightChoice;
use guiding::RecordOutcome;

use common::{Rand, scene, two_rooms, unshadowed, value};
use glam::Vec3;
use guiding::cut::CutConfig;
use guiding::glt::{Glt, GltConfig};
use guiding::light_tree::BuildHeuristic;
use guiding::resampling::{Evaluated, resample};
use guiding::{LightId, LightSampler, LightTree, ShadingContext};

fn tree() -> &'static LightTree {
    static TREE: std::sync::OnceLock<LightTree> = std::sync::OnceLock::new();
    TREE.get_or_init(|| LightTree::build(&two_rooms(), BuildHeuristic::Sarh).unwrap())
}

fn config(visibility: bool) -> GltConfig {
    GltConfig {
        cut: CutConfig {
            visibility,
            ..CutConfig::default()
        },
        spatial_threshold: 2000.0,
        ..GltConfig::default()
    }
}

/// Three iterations of NEE from the GLT itself, each sample recording its
/// value and, for the visibility, the value it would have had unoccluded.
fn trained(visibility: bool) -> Glt<&'static LightTree> {
    let lights = two_rooms();
    let mut glt = Glt::new(tree(), scene(), config(visibility)).unwrap();
    let mut rng = Rand::new(31);
    for _ in 0..3 {
        for _ in 0..8000 {
            let p = rng.point(9.5);
            let Some(x) = ByPosition(&glt).sample(&ShadingContext::at(p), rng.f()) else {
                continue;
            };
            let LightId::Emitter(e) = x.light else {
                continue;
            };
            let seen = value(&lights, e, p) / x.pmf;
            glt.record_light_at(p, x.light, seen);
            glt.record_visibility_at(p, x.light, seen, unshadowed(&lights, e, p) / x.pmf);
        }
        glt.refine();
    }
    glt
}

/// Mean learned visibility of each room's lights seen from `p`.
fn room_visibility(glt: &impl LightChoice, p: Vec3) -> (f32, f32) {
    let lights = two_rooms();
    let (mut own, mut other) = (Vec::new(), Vec::new());
    for e in 0..lights.len() as u32 {
        let v = glt.visibility(LightId::Emitter(e));
        assert!((1.0 / 64.0..=1.0).contains(&v), "{v}");
        if (lights[e as usize].bounds.center().x < 0.0) == (p.x < 0.0) {
            own.push(v);
        } else {
            other.push(v);
        }
    }
    let mean = |x: &[f32]| x.iter().sum::<f32>() / x.len() as f32;
    (mean(&own), mean(&other))
}

#[test]
fn each_room_learns_the_other_is_hidden() {
    let glt = trained(true);
    for p in [Vec3::new(-5.0, 1.0, 2.0), Vec3::new(6.0, -3.0, -1.0)] {
        let v = glt.vertex(&ShadingContext::at(p)).unwrap();
        let (own, other) = room_visibility(&v, p);
        assert!(
            own > 0.8 && other < 0.2,
            "at {p}: own room {own}, other {other}"
        );
    }
}

#[test]
fn off_by_default() {
    let glt = trained(false);
    let (own, other) = room_visibility(
        &glt.light_at(Vec3::new(-5.0, 1.0, 2.0)),
        Vec3::new(-5.0, 1.0, 2.0),
    );
    assert_eq!((own, other), (1.0, 1.0));
    assert_eq!(
        glt.record_visibility_at(Vec3::ZERO, LightId::Emitter(0), 0.5, 1.0),
        RecordOutcome::Ignored
    );
    // It costs nothing: 20 bytes per slot only when on.
    let (off, on) = (trained(false).memory(), trained(true).memory());
    assert!(on.cuts.node_bytes > off.cuts.node_bytes);
}

#[test]
fn bad_records_are_dropped_and_counted() {
    let glt = Glt::new(tree(), scene(), config(true)).unwrap();
    let p = Vec3::new(1.0, 2.0, 3.0);
    let bad = [
        (LightId::Emitter(0), -1.0, 1.0),
        (LightId::Emitter(0), 2.0, 1.0),
        (LightId::Emitter(0), f32::NAN, 1.0),
        (LightId::Emitter(0), 0.5, f32::INFINITY),
        (LightId::Emitter(999), 0.5, 1.0),
        (LightId::Unbounded(0), 0.5, 1.0),
    ];
    for (i, (light, s, u)) in bad.into_iter().enumerate() {
        assert_eq!(
            glt.record_visibility_at(p, light, s, u),
            RecordOutcome::Dropped
        );
        assert_eq!(glt.dropped_records().light, i as u64 + 1);
    }
    assert_eq!(
        glt.record_visibility_at(Vec3::NAN, LightId::Emitter(0), 0.5, 1.0),
        RecordOutcome::Dropped
    );
    assert_eq!(
        glt.record_visibility_at(p, LightId::Emitter(0), 0.0, 0.0),
        RecordOutcome::Zero
    );
    assert_eq!(
        glt.record_visibility_at(p, LightId::Emitter(0), 0.5, 1.0),
        RecordOutcome::Recorded
    );
}

/// Saved and loaded, the visibility and its pending sums come back bit for
/// bit; merged with a copy of itself, its pending sums double (the next
/// refine learns the same ratios).
#[test]
fn visibility_survives_saving_loading_and_merging() {
    let glt = trained(true);
    let lights = two_rooms();
    // Pending records, not yet refined.
    let p = Vec3::new(-4.0, 0.0, 0.0);
    for e in 0..80 {
        glt.record_visibility_at(
            p,
            LightId::Emitter(e),
            value(&lights, e, p),
            unshadowed(&lights, e, p),
        );
    }
    let bytes = glt.to_bytes();
    let back = Glt::from_bytes(&bytes, tree()).unwrap();
    assert_eq!(back.to_bytes(), bytes);
    let mut a = Glt::from_bytes(&bytes, tree()).unwrap();
    assert!(a.merge(&back));
    a.refine();
    let mut b = Glt::from_bytes(&bytes, tree()).unwrap();
    b.refine();
    let q = Vec3::new(-5.0, 1.0, 2.0);
    assert_eq!(
        room_visibility(&a.light_at(q), q),
        room_visibility(&b.light_at(q), q)
    );
}

/// Resampling from the trained GLT with its learned visibility (applied by
/// `resample` itself) is unbiased and has lower variance than with a
/// blind target at the same candidates (where the blind target favours
/// the other room's lights).
#[test]
fn resampling_with_learned_visibility_is_unbiased_and_better() {
    let lights = two_rooms();
    let seeing = trained(true);
    let blind = trained(false);
    let p = Vec3::new(-0.5, 1.0, 2.0);
    let truth: f64 = (0..80).map(|e| f64::from(value(&lights, e, p))).sum();
    let run = |s: &dyn LightChoice| {
        let mut rng = Rand::new(77);
        let n = 100_000;
        let (mut s1, mut s2) = (0.0f64, 0.0f64);
        for _ in 0..n {
            let cands = [
                rng.f(),
                rng.f(),
                rng.f(),
                rng.f(),
                rng.f(),
                rng.f(),
                rng.f(),
                rng.f(),
            ];
            let x = resample(s, &cands, rng.f(), None, |l, _| {
                let LightId::Emitter(e) = l else { return None };
                Some(Evaluated::new(unshadowed(&lights, e, p), e))
            })
            .map_or(0.0, |r| {
                f64::from(value(&lights, r.payload, p)) * f64::from(r.weight)
            });
            s1 += x;
            s2 += x * x;
        }
        let mean = s1 / n as f64;
        let var = s2 / n as f64 - mean * mean;
        (mean, (var / n as f64).sqrt(), var)
    };
    let (m1, se1, v1) = run(&seeing.light_at(p));
    let (m0, se0, v0) = run(&blind.light_at(p));
    assert!((m1 - truth).abs() < 4.5 * se1, "{m1} +- {se1} vs {truth}");
    assert!((m0 - truth).abs() < 4.5 * se0, "{m0} +- {se0} vs {truth}");
    assert!(v1 < 0.8 * v0, "learned visibility {v1}, blind {v0}");
}

/// A GLT learning visibility in the two rooms from its own NEE samples
/// (three refinements of 8,000), with `unbounded` lights (the first
/// hidden half the time).
fn trained_on_two_rooms(
    unbounded: guiding::UnboundedLights,
    lights: &[guiding::Emitter],
    rng: &mut Rand,
) -> Glt<&'static LightTree> {
    let mut cfg = config(true);
    cfg.cut.unbounded = unbounded;
    let mut glt = Glt::new(tree(), scene(), cfg).unwrap();
    for _ in 0..3 {
        for _ in 0..8000 {
            let p = rng.point(9.5);
            let Some(x) = ByPosition(&glt).sample(&ShadingContext::at(p), rng.f()) else {
                continue;
            };
            let (seen, open) = match x.light {
                LightId::Emitter(e) => (value(lights, e, p), unshadowed(lights, e, p)),
                LightId::Unbounded(i) => (if i == 0 && rng.f() < 0.5 { 0.0 } else { 1.0 }, 1.0),
            };
            glt.record_light_at(p, x.light, seen / x.pmf);
            glt.record_visibility_at(p, x.light, seen / x.pmf, open / x.pmf);
        }
        glt.refine();
    }
    glt
}

/// `sample_with_visibility` (the visibility read where the walk leaves the
/// cut) answers exactly as `sample` and then `visibility` (the light's
/// path walked again), for the GLT, its vertex and one cell's cut as a
/// sampler, with and without a sun and a sky whose visibility is learned
/// too. Control: reading the other side's slot differs on most draws.
#[test]
fn sampling_with_visibility_equals_sampling_then_visibility() {
    let lights = two_rooms();
    for unbounded in [
        guiding::UnboundedLights::NONE,
        guiding::UnboundedLights::new(2, 0.2).unwrap(),
    ] {
        let mut rng = Rand::new(77);
        let glt = trained_on_two_rooms(unbounded, &lights, &mut rng);
        let (mut draws, mut learned) = (0, 0);
        for _ in 0..3000 {
            let p = rng.point(9.5);
            let ctx = ShadingContext::on_surface(p, Vec3::Y);
            let u = rng.f();
            let s = glt.vertex(&ctx).unwrap();
            let want = s.sample(u).map(|x| (x, s.visibility(x.light)));
            let got = s.sample_with_visibility(u);
            assert_eq!(
                got.map(|(x, v)| (x, v.to_bits())),
                want.map(|(x, v)| (x, v.to_bits())),
                "at {p} with u = {u}"
            );
            draws += usize::from(got.is_some());
            learned += usize::from(got.is_some_and(|(_, v)| v < 0.99));
        }
        // The check has something to see: most draws answer, and many of
        // them with a visibility learned below 1.
        assert!(
            draws > 2500 && learned > 50,
            "{draws} draws, {learned} learned"
        );
    }
}

/// Candidates drawn together (`sample_candidates`, each step the walks
/// share computed once) are exactly the candidates drawn alone, learned
/// visibility included, at trained cuts with and without unbounded lights
/// and on a 100-level chain (deeper than the walks' memo of 16 levels).
/// Control: a memo that keys its steps by level alone, not by node, gives
/// other lights on most batches (checked by hand when written).
#[test]
fn candidates_drawn_together_are_the_candidates_drawn_alone() {
    let lights = two_rooms();
    let mut rng = Rand::new(78);
    for unbounded in [
        guiding::UnboundedLights::NONE,
        guiding::UnboundedLights::new(2, 0.2).unwrap(),
    ] {
        let glt = trained_on_two_rooms(unbounded, &lights, &mut rng);
        let mut answered = 0;
        for _ in 0..200 {
            let ctx = ShadingContext::on_surface(rng.point(9.5), rng.dir());
            answered += common::candidates_match(&glt.vertex(&ctx).unwrap(), &mut rng);
        }
        assert!(answered > 20_000, "{answered} candidates answered");
        // A point that is not finite answers nothing, together or alone.
        let here = glt.vertex(&ShadingContext::at(Vec3::ZERO)).unwrap();
        let nowhere = ShadingContext::at(Vec3::new(f32::NAN, 0.0, 0.0));
        let lost = glt.cut_rules().vertex(here.cut(), &nowhere);
        assert_eq!(common::candidates_match(&lost, &mut rng), 0);
    }
    let chain = common::Chain::deep();
    let rules = guiding::cut::CutRules::new(&chain, CutConfig::default()).unwrap();
    let mut cut = rules.new_cut();
    for _ in 0..16 {
        for k in 0..chain.n() {
            rules.record(&cut, LightId::Emitter(k), common::Chain::deep_target(k));
        }
        rules.refine(&mut cut);
    }
    let mut answered = 0;
    for _ in 0..50 {
        let ctx = ShadingContext::at(rng.point(5.0));
        answered += common::candidates_match(&rules.vertex(&cut, &ctx), &mut rng);
    }
    assert!(answered > 5_000, "{answered} chain candidates answered");
}

/// The learned visibility is exactly the module's estimate: the shadowed
/// over the unshadowed sum, shrunk towards the slot's previous value by
/// four of the cell's average records, `v = (S + k v0) / (U + k)`, `k = 4
/// U / records` for a cut of one slot. A rebuild without records keeps
/// the old value (the shrinkage's `0 / 0` must not become NaN). Controls:
/// no shrinkage gives 1/8 here, shrinkage by the shadowed sums 1/4.
#[test]
fn the_learned_visibility_is_the_shrunk_ratio() {
    let one = [guiding::Emitter::point(Vec3::ZERO, 1.0)];
    let tree = LightTree::build(one.as_slice(), BuildHeuristic::Sarh).unwrap();
    let guide = guiding::cut::CutRules::new(&tree, learning_visibility()).unwrap();
    let mut cut = guide.new_cut();
    let l = LightId::Emitter(0);
    let round = |records: &[(f32, f32)], cut: &mut guiding::cut::GuidingCut| {
        guide.record(cut, l, 1.0);
        for &(s, u) in records {
            assert_eq!(
                guide.record_visibility(cut, l, s, u),
                RecordOutcome::Recorded
            );
        }
        guide.refine(cut);
        cut.visibility().to_vec()
    };
    assert_eq!(cut.visibility(), &[1.0]);
    // S = 1, U = 8, 3 records: k = 32 / 3, v = (1 + k) / (8 + k) = 5 / 8.
    assert_eq!(
        round(&[(1.0, 2.0), (0.0, 2.0), (0.0, 4.0)], &mut cut),
        [0.625]
    );
    // S = U = 2, one record: k = 8, v = (2 + 8 * 5 / 8) / (2 + 8) = 7 / 10.
    assert_eq!(round(&[(2.0, 2.0)], &mut cut), [0.7]);
    // No records: kept.
    assert_eq!(round(&[], &mut cut), [0.7]);
}

/// Where a rebuilt cut is coarser than the old one, a new slot takes the
/// mean visibility of the old slots below it: lights learned hidden stay
/// hidden when the cut stops resolving them (the records moved elsewhere).
/// Control: taking 1 for such a slot (forgetting what was learned).
#[test]
fn a_coarser_cut_keeps_what_its_finer_slots_learned() {
    let tree = row_of_lights();
    let guide = guiding::cut::CutRules::new(&tree, learning_visibility()).unwrap();
    let mut cut = guide.new_cut();
    let round = |lit: std::ops::Range<u32>, cut: &mut guiding::cut::GuidingCut| {
        for e in lit {
            let l = LightId::Emitter(e);
            for _ in 0..8 {
                guide.record(cut, l, 100.0);
                // The left half is hidden, the right half seen.
                let seen = if e < 8 { 0.0 } else { 1.0 };
                guide.record_visibility(cut, l, seen, 1.0);
            }
        }
        guide.refine(cut);
    };
    // Three rounds resolving every light, then one whose records are all on
    // the right: the cut no longer splits the left half.
    for _ in 0..3 {
        round(0..16, &mut cut);
    }
    let fine = cut.nodes().len();
    let hidden = guide.visibility(&cut, LightId::Emitter(2));
    assert!(hidden < 0.2, "{hidden}");
    round(8..16, &mut cut);
    assert!(
        cut.nodes().len() < fine,
        "{} nodes, {fine} before",
        cut.nodes().len()
    );
    let kept = guide.visibility(&cut, LightId::Emitter(2));
    // Every old slot below it learned the floor: their mean is the floor.
    assert_eq!(kept, hidden, "the left half's visibility");
    assert!(guide.visibility(&cut, LightId::Emitter(12)) > 0.8);
}

/// The mean over the old slots below a coarser slot weighs each by its
/// unshadowed records: a hidden quarter that still sends records outweighs
/// a seen quarter that sends none (the plain mean would be about 1/2).
#[test]
fn a_coarser_slot_weighs_its_old_slots_by_their_records() {
    let tree = row_of_lights();
    let guide = guiding::cut::CutRules::new(&tree, learning_visibility()).unwrap();
    let mut cut = guide.new_cut();
    // Lights 0-3 hidden, 4-15 seen; `record` says which lights the cut
    // resolves, `records` which send visibility records.
    let round = |record: std::ops::Range<u32>,
                 records: std::ops::Range<u32>,
                 cut: &mut guiding::cut::GuidingCut| {
        for e in record {
            guide.record(cut, LightId::Emitter(e), 100.0);
        }
        for e in records {
            let seen = if e < 4 { 0.0 } else { 1.0 };
            for _ in 0..8 {
                guide.record_visibility(cut, LightId::Emitter(e), seen, 1.0);
            }
        }
        guide.refine(cut);
    };
    for _ in 0..3 {
        round(0..16, 0..16, &mut cut);
    }
    let (hidden, seen) = (
        guide.visibility(&cut, LightId::Emitter(1)),
        guide.visibility(&cut, LightId::Emitter(6)),
    );
    assert!(hidden < 0.1 && seen > 0.9, "{hidden} {seen}");
    let fine = cut.nodes().len();
    // The cut stops resolving the left half; only the hidden quarter
    // still sends records.
    round(8..16, 0..4, &mut cut);
    assert!(cut.nodes().len() < fine);
    let merged = guide.visibility(&cut, LightId::Emitter(1));
    assert_eq!(
        merged,
        guide.visibility(&cut, LightId::Emitter(6)),
        "one slot"
    );
    assert!(merged > 0.0 && merged < 0.2, "{merged}");
}

/// A cut that learns visibility and rebuilds from any data.
fn learning_visibility() -> CutConfig {
    CutConfig {
        min_records: 0,
        visibility: true,
        ..CutConfig::default()
    }
}

/// 16 point lights of power 1 in a row along x.
fn row_of_lights() -> LightTree {
    let lights: Vec<guiding::Emitter> = (0..16)
        .map(|i| guiding::Emitter::point(Vec3::new(i as f32, 0.0, 0.0), 1.0))
        .collect();
    LightTree::build(lights.as_slice(), BuildHeuristic::Sarh).unwrap()
}
