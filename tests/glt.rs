//! The Guiding Light Tree's per-cell core ([`GuidingCut`]): valid cuts under
//! random record streams and refinements, the sampling rule's contracts
//! (pmf sums to 1, `sample`'s pmf equals `pmf()` bit for bit), learning,
//! unbiasedness with the defensive mixture, numerical stability at depth,
//! across 60 decades and at 1M lights, concurrency and memory.

use glam::Vec3;
use guiding::LightChoice;
use guiding::cut::{
    BelowCut, CutConfig, CutNode, CutRules, GuidingCut, ImportanceBound, Modulation, Prior, Slot,
    SplitPrior,
};
use guiding::light_tree::{BuildHeuristic, EmitterPath, NodeBounds};
use guiding::math::{Aabb, Accumulation, Side};
use guiding::{
    Emitter, LightHierarchy, LightId, LightSampler, LightTree, ShadingContext, UnboundedLights,
};
use proptest::prelude::*;

mod common;
use common::Chain;
use common::LightsAt;
use common::Rand;
use guiding::RecordOutcome;

// ---------------------------------------------------------------------------
// Helpers
// ---------------------------------------------------------------------------

/// Every leaf of `tree` lies below exactly one cluster of the cut (checked
/// by counting leaves, independently of `GuidingCut::check`), the structural
/// check passes, and the clusters' learned probabilities sum to 1.
fn assert_valid_cut<H: LightHierarchy + ?Sized>(tree: &H, cut: &GuidingCut) {
    cut.check(tree).unwrap();
    let mut crossings = vec![0u32; tree.emitter_count()];
    let clusters = cut.clusters(tree);
    for &(node, _) in &clusters {
        let mut stack = vec![node];
        while let Some(n) = stack.pop() {
            match tree.children(n) {
                Some([l, r]) => stack.extend([l, r]),
                None => crossings[tree.emitter(n).unwrap() as usize] += 1,
            }
        }
    }
    assert!(
        crossings.iter().all(|&c| c == 1),
        "a root-to-leaf path crosses the cut {:?} times",
        crossings.iter().find(|&&c| c != 1)
    );
    if !clusters.is_empty() {
        let p: f64 = clusters.iter().map(|c| c.1).sum();
        assert!((p - 1.0).abs() < 1e-5, "cluster probabilities sum to {p}");
    }
    // Slots record the light node they end at.
    let mut stack = vec![];
    if let (Some(root), false) = (tree.root(), cut.nodes().is_empty()) {
        stack.push((0u32, root));
    }
    while let Some((i, light)) = stack.pop() {
        let node = cut.nodes()[i as usize];
        let children = tree.children(light).unwrap();
        for side in [Side::Left, Side::Right] {
            match node.slot(side) {
                Slot::Child(j) => stack.push((j, children[side.index()])),
                Slot::End(n) => assert_eq!(n, children[side.index()]),
            }
        }
    }
}

/// Sum of the exact pmf over every emitter and unbounded light.
fn pmf_total<H: LightHierarchy + ?Sized>(
    guide: &CutRules<&H>,
    cut: &GuidingCut,
    ctx: &ShadingContext,
) -> f64 {
    let unbounded = guide.config().unbounded.count;
    let mut total: f64 = (0..unbounded)
        .map(|i| guide.pmf_exact(cut, ctx, LightId::Unbounded(i)))
        .sum();
    assert_eq!(
        guide.pmf_exact(cut, ctx, LightId::Unbounded(unbounded)),
        0.0
    );
    for e in 0..guide.light_tree().emitter_count() as u32 {
        let p = guide.pmf_exact(cut, ctx, LightId::Emitter(e));
        assert!(p.is_finite() && p >= 0.0, "pmf {p} for {e}");
        total += p;
    }
    total
}

/// What the total pmf must be: 1 when anything can be sampled.
fn expected_total<H: LightHierarchy + ?Sized>(guide: &CutRules<&H>) -> f64 {
    let tree = guide.light_tree();
    let emitters = tree.root().is_some_and(|r| tree.power(r) > 0.0);
    let unbounded = guide.config().unbounded.count > 0;
    if emitters || unbounded { 1.0 } else { 0.0 }
}

/// `sample`'s pmf equals `pmf()` bit for bit, in `f64` and in `f32`, and a
/// sampled light always has a positive pmf.
fn assert_sample_matches_pmf<H: LightHierarchy + ?Sized>(
    guide: &CutRules<&H>,
    cut: &GuidingCut,
    ctx: &ShadingContext,
    rng: &mut Rand,
    draws: usize,
) {
    let sampler = guide.vertex(cut, &ShadingContext::at(Vec3::ZERO));
    for _ in 0..draws {
        let u = rng.f64();
        if let Some((light, p)) = guide.sample_exact(cut, ctx, u) {
            let q = guide.pmf_exact(cut, ctx, light);
            assert_eq!(p.to_bits(), q.to_bits(), "{light:?} u={u}: {p} vs {q}");
            assert!(p > 0.0);
        } else {
            assert_eq!(expected_total(guide), 0.0, "no sample at u={u}");
        }
        let u = rng.f();
        if let Some(s) = sampler.sample(u) {
            let q = sampler.pmf(s.light);
            assert_eq!(s.pmf.to_bits(), q.to_bits(), "{:?} u={u}", s.light);
            assert!(s.pmf > 0.0);
        }
    }
}

fn lights_in_box(rng: &mut Rand, n: usize, r: f32) -> Vec<Emitter> {
    (0..n)
        .map(|_| Emitter::point(rng.point(r), rng.range(0.1, 10.0)))
        .collect()
}

const ALL_CONFIGS: [(BelowCut, SplitPrior); 4] = [
    (BelowCut::Power, SplitPrior::Power),
    (BelowCut::Power, SplitPrior::Half),
    (BelowCut::Importance, SplitPrior::Power),
    (BelowCut::Importance, SplitPrior::Half),
];

// ---------------------------------------------------------------------------
// Property tests
// ---------------------------------------------------------------------------

#[derive(Clone, Debug)]
enum Kind {
    Point,
    Sphere,
    Quad,
    Dark,
}

fn emitter_strategy() -> impl Strategy<Value = (f32, f32, f32, f32, Kind)> {
    (
        -10.0f32..10.0,
        -10.0f32..10.0,
        -10.0f32..10.0,
        prop_oneof![Just(1.0e-3f32), 0.01f32..100.0, Just(1.0e4)],
        prop_oneof![
            Just(Kind::Point),
            Just(Kind::Sphere),
            Just(Kind::Quad),
            Just(Kind::Dark)
        ],
    )
}

fn build_emitter((x, y, z, power, kind): &(f32, f32, f32, f32, Kind)) -> Emitter {
    let p = Vec3::new(*x, *y, *z);
    match kind {
        Kind::Point => Emitter::point(p, *power),
        Kind::Sphere => Emitter::sphere(p, 0.3, *power),
        Kind::Quad => {
            let n = Vec3::new(*y, *z, *x + 0.1).normalize_or(Vec3::Y);
            Emitter::area(Aabb::new(p - 0.2, p + 0.2), n, 0.16, *power)
        }
        Kind::Dark => Emitter::point(p, 0.0),
    }
}

#[derive(Clone, Debug)]
enum Value {
    Normal(f32),
    Tiny,
    Huge,
    Zero,
    Negative,
    Nan,
    Inf,
}

impl Value {
    fn get(&self) -> f32 {
        match self {
            Value::Normal(v) => *v,
            Value::Tiny => 1.0e-30,
            Value::Huge => 1.0e30,
            Value::Zero => 0.0,
            Value::Negative => -1.0,
            Value::Nan => f32::NAN,
            Value::Inf => f32::INFINITY,
        }
    }
    fn is_bad(&self) -> bool {
        matches!(self, Value::Negative | Value::Nan | Value::Inf)
    }
}

fn value_strategy() -> impl Strategy<Value = Value> {
    prop_oneof![
        8 => (0.0f32..100.0).prop_map(Value::Normal),
        1 => Just(Value::Tiny),
        1 => Just(Value::Huge),
        1 => Just(Value::Zero),
        1 => Just(Value::Negative),
        1 => Just(Value::Nan),
        1 => Just(Value::Inf),
    ]
}

fn config_strategy() -> impl Strategy<Value = CutConfig> {
    (
        prop_oneof![
            Just(0.0),
            Just(0.002),
            Just(0.01),
            Just(0.05),
            Just(0.5),
            Just(1.0)
        ],
        prop_oneof![Just(0.0), Just(0.1), Just(0.5), Just(1.0)],
        0usize..4,
        prop_oneof![
            Just(UnboundedLights::NONE),
            Just(UnboundedLights::new(1, 1e-9).unwrap()),
            Just(UnboundedLights::new(1, 0.2).unwrap()),
            Just(UnboundedLights::new(2, 0.2).unwrap()),
            Just(UnboundedLights::new(3, 0.99).unwrap())
        ],
        any::<bool>(),
        prop_oneof![Just(0u32), Just(1), Just(64)],
        any::<bool>(),
        any::<bool>(),
        any::<bool>(),
    )
        .prop_map(
            |(sigma, alpha, variant, unbounded, exact, min_records, modulate, prior_imp, own)| {
                let (below_cut, split_prior) = ALL_CONFIGS[variant];
                CutConfig {
                    sigma,
                    alpha,
                    below_cut,
                    modulation: if modulate {
                        Modulation::Importance
                    } else {
                        Modulation::None
                    },
                    split_prior,
                    importance_bound: if own {
                        ImportanceBound::Children
                    } else {
                        ImportanceBound::Grandchildren
                    },
                    unbounded,
                    accumulation: if exact {
                        Accumulation::Deterministic
                    } else {
                        Accumulation::Fast
                    },
                    min_records,
                    prior: if prior_imp {
                        Prior::Importance
                    } else {
                        Prior::Power
                    },
                    visibility: modulate != exact,
                }
            },
        )
}

const HEURISTICS: [BuildHeuristic; 4] = [
    BuildHeuristic::Balanced,
    BuildHeuristic::Sah,
    BuildHeuristic::Sarh,
    BuildHeuristic::Saoh,
];

proptest! {
    #![proptest_config(ProptestConfig { cases: 48, ..ProptestConfig::default() })]

    /// Random light sets, record streams (bad values and ids included) and
    /// refinement sequences keep every cut valid, the pmf summing to 1 and
    /// sampling agreeing with the pmf bit for bit.
    #[test]
    fn random_streams_keep_cuts_valid(
        emitters in prop::collection::vec(emitter_strategy(), 1..120),
        heuristic in 0usize..4,
        config in config_strategy(),
        rounds in prop::collection::vec(
            prop::collection::vec((0u32..1000, value_strategy()), 0..150),
            1..5,
        ),
        seed in any::<u64>(),
    ) {
        let lights: Vec<Emitter> = emitters.iter().map(build_emitter).collect();
        let tree = LightTree::build(&lights, HEURISTICS[heuristic]).unwrap();
        let guide = CutRules::new(&tree, config).unwrap();
        let n = lights.len() as u32;
        let mut rng = Rand::new(seed);
        let mut cut = guide.new_cut();
        assert_valid_cut(&tree, &cut);
        for round in &rounds {
            for (id, value) in round {
                // Mostly real emitters, some out of range, some unbounded
                // (some of those beyond the configured count).
                let light = match id % 10 {
                    0 => LightId::Unbounded(id % 4),
                    1 => LightId::Emitter(n + id),
                    _ => LightId::Emitter(id % n),
                };
                let outcome = guide.record_from(&cut, rng.point(3.0), light, value.get());
                let dark = match light {
                    LightId::Emitter(e) => e >= n || lights[e as usize].power == 0.0,
                    LightId::Unbounded(i) => i >= config.unbounded.count,
                };
                if value.is_bad() || dark {
                    prop_assert_eq!(outcome, RecordOutcome::Dropped);
                } else if value.get() == 0.0 {
                    prop_assert_eq!(outcome, RecordOutcome::Zero);
                } else {
                    prop_assert_eq!(outcome, RecordOutcome::Recorded);
                }
            }
            guide.refine(&mut cut);
            assert_valid_cut(&tree, &cut);
            for _ in 0..3 {
                let normal = if rng.f() < 0.5 { Some(rng.point(1.0)) } else { None };
                let ctx = ShadingContext {
                    position: rng.point(12.0),
                    normal: normal.and_then(|n| n.try_normalize()),
                    ..ShadingContext::at(Vec3::ZERO)
                };
                let total = pmf_total(&guide, &cut, &ctx);
                let expect = expected_total(&guide);
                prop_assert!((total - expect).abs() < 1e-5, "pmf sums to {} not {}", total, expect);
                assert_sample_matches_pmf(&guide, &cut, &ctx, &mut rng, 40);
            }
        }
    }
}

// ---------------------------------------------------------------------------
// Behaviour of the learned cut
// ---------------------------------------------------------------------------

/// 64 point lights on a ring; only every 8th is visible from the origin.
/// Training as a renderer would (sample from the cut, record
/// contribution / pmf) moves the pmf mass onto the visible subset, up to
/// `1 - alpha * (prior mass outside it)`.
#[test]
fn learns_the_visible_subset() {
    let lights: Vec<Emitter> = (0..64)
        .map(|i| {
            let a = i as f32 / 64.0 * core::f32::consts::TAU;
            Emitter::point(
                Vec3::new(5.0 * a.cos(), 1.0, 5.0 * a.sin()),
                1.0 + (i % 5) as f32,
            )
        })
        .collect();
    let visible = |e: u32| e % 8 == 3;
    let tree = LightTree::build(&lights, BuildHeuristic::Sarh).unwrap();
    let ctx = ShadingContext::on_surface(Vec3::ZERO, Vec3::Y);
    let total_power: f32 = lights.iter().map(|l| l.power).sum();
    let prior_outside: f64 = (0..64)
        .filter(|&e| !visible(e))
        .map(|e| (lights[e as usize].power / total_power) as f64)
        .sum();
    for (below_cut, split_prior) in ALL_CONFIGS {
        for alpha in [0.0, 0.1, 0.3] {
            // The power prior, which `prior_outside` is computed for.
            let config = CutConfig {
                alpha,
                below_cut,
                split_prior,
                ..CutConfig::default().with_paper_rules()
            };
            let guide = CutRules::new(&tree, config).unwrap();
            let mass = |cut: &GuidingCut| -> f64 {
                (0..64)
                    .filter(|&e| visible(e))
                    .map(|e| guide.pmf_exact(cut, &ctx, LightId::Emitter(e)))
                    .sum()
            };
            let mut cut = guide.new_cut();
            let before = mass(&cut);
            let mut rng = Rand::new(7);
            for _ in 0..4 {
                for _ in 0..2000 {
                    let s = guide.sample(&cut, &ctx, rng.f()).unwrap();
                    let LightId::Emitter(e) = s.light else {
                        panic!()
                    };
                    let c = if visible(e) {
                        lights[e as usize].power
                    } else {
                        0.0
                    };
                    guide.record(&cut, s.light, c / s.pmf);
                }
                guide.refine(&mut cut);
            }
            let after = mass(&cut);
            let target = 1.0 - alpha * prior_outside;
            assert!(before < 0.2, "{before}");
            assert!(
                after > target - 1e-4 && after < target + 1e-4,
                "{below_cut:?} {split_prior:?} alpha {alpha}: mass {after}, target {target}"
            );
        }
    }
}

/// With `SplitPrior::Power` a freshly split cluster samples exactly as
/// before the split; with `Half` it does not (the test can tell them apart).
#[test]
fn power_split_prior_preserves_the_distribution() {
    let mut rng = Rand::new(3);
    let lights = lights_in_box(&mut rng, 200, 5.0);
    let tree = LightTree::build(&lights, BuildHeuristic::Sarh).unwrap();
    let ctx = ShadingContext::at(Vec3::ZERO);
    let [l, r] = tree.children(tree.root().unwrap()).unwrap();
    for prior in [SplitPrior::Power, SplitPrior::Half] {
        let config = CutConfig {
            alpha: 0.0,
            split_prior: prior,
            sigma: 0.002,
            // The paper's rules: power below the cut, one distribution per
            // cell, rebuild from any data (here two records).
            min_records: 0,
            ..CutConfig::default().with_paper_rules()
        };
        let guide = CutRules::new(&tree, config).unwrap();
        let mut cut = guide.new_cut();
        let before: Vec<f64> = (0..200)
            .map(|e| guide.pmf_exact(&cut, &ctx, LightId::Emitter(e)))
            .collect();
        // Sums exactly in the ratio of the root's children's powers: the
        // root keeps its p_left, every slot below is split afresh.
        let first_light = |mut n: u32| {
            while let Some([c, _]) = tree.children(n) {
                n = c;
            }
            tree.emitter(n).unwrap()
        };
        guide.record(&cut, LightId::Emitter(first_light(l)), tree.power(l));
        guide.record(&cut, LightId::Emitter(first_light(r)), tree.power(r));
        guide.refine(&mut cut);
        assert!(cut.nodes().len() > 50, "{}", cut.nodes().len());
        assert_valid_cut(&tree, &cut);
        let worst = (0..200)
            .map(|e| {
                let p = guide.pmf_exact(&cut, &ctx, LightId::Emitter(e));
                (p / before[e as usize] - 1.0).abs()
            })
            .fold(0.0, f64::max);
        match prior {
            SplitPrior::Power => assert!(worst < 1e-5, "relative change {worst}"),
            SplitPrior::Half => assert!(worst > 0.1, "relative change {worst}"),
        }
    }
}

/// Below `min_records` non-zero records a refine changes nothing and the
/// sums carry over; the rebuild that follows sees every iteration's data.
#[test]
fn too_few_records_defer_the_rebuild_and_keep_the_data() {
    let mut rng = Rand::new(8);
    let lights = lights_in_box(&mut rng, 300, 5.0);
    let tree = LightTree::build(&lights, BuildHeuristic::Sarh).unwrap();
    let guide = CutRules::new(&tree, CutConfig::default()).unwrap();
    let min = guide.config().min_records;
    assert!(min > 1);
    let mut cut = guide.new_cut();
    let ctx = ShadingContext::at(Vec3::ZERO);
    let pmfs = |cut: &GuidingCut| -> Vec<f64> {
        (0..300)
            .map(|e| guide.pmf_exact(cut, &ctx, LightId::Emitter(e)))
            .collect()
    };
    let before = pmfs(&cut);
    // Zeros (occluded samples) are not data.
    for e in 0..300 {
        assert_eq!(
            guide.record(&cut, LightId::Emitter(e), 0.0),
            RecordOutcome::Zero
        );
    }
    assert!(!guide.refine(&mut cut));
    // Half the floor on emitter 17, then the other half on emitter 42:
    // the first refine keeps everything, the second rebuilds from both.
    for _ in 0..min / 2 {
        guide.record(&cut, LightId::Emitter(17), 1.0);
    }
    assert!(!guide.refine(&mut cut));
    assert_eq!(pmfs(&cut), before);
    for _ in 0..min - min / 2 {
        guide.record(&cut, LightId::Emitter(42), 1.0);
    }
    assert!(guide.refine(&mut cut));
    assert_valid_cut(&tree, &cut);
    let after = pmfs(&cut);
    // Exactly the cut that all of it in one iteration gives.
    let mut once = guide.new_cut();
    for _ in 0..min / 2 {
        guide.record(&once, LightId::Emitter(17), 1.0);
    }
    for _ in 0..min - min / 2 {
        guide.record(&once, LightId::Emitter(42), 1.0);
    }
    assert!(guide.refine(&mut once));
    assert_eq!(once.nodes(), cut.nodes());
    assert_eq!(pmfs(&once), after);
    assert_ne!(after, before);
    // The sums were spent: a refine right after keeps the cut.
    assert!(!guide.refine(&mut cut));
    assert_eq!(pmfs(&cut), after);
}

/// Splitting goes down to single emitters; a concentrated stream then
/// merges everything else back into few clusters.
#[test]
fn splits_to_leaves_and_merges_back() {
    let mut rng = Rand::new(5);
    let lights = lights_in_box(&mut rng, 300, 5.0);
    let tree = LightTree::build(&lights, BuildHeuristic::Sarh).unwrap();
    // The paper's rule: rebuild from any data (the second phase has ten
    // records per pass).
    let config = CutConfig {
        min_records: 0,
        ..CutConfig::default()
    };
    let guide = CutRules::new(&tree, config).unwrap();
    let mut cut = guide.new_cut();
    // Uniform contributions: every emitter's share 1/300 < sigma, so the cut
    // stops above the leaves but grows large.
    for e in 0..300 {
        guide.record(&cut, LightId::Emitter(e), 1.0);
    }
    guide.refine(&mut cut);
    let wide = cut.nodes().len();
    assert!(wide > 40, "{wide}");
    // One emitter holds everything: the cut becomes its path (single
    // emitter at the end), all else merges. The first pass splits the old
    // cluster of emitter 17 by the power prior; the second learns that its
    // siblings got nothing.
    for _ in 0..2 {
        for _ in 0..10 {
            guide.record(&cut, LightId::Emitter(17), 5.0);
        }
        guide.refine(&mut cut);
    }
    assert_valid_cut(&tree, &cut);
    let path = tree.path(17).unwrap();
    assert_eq!(cut.nodes().len(), path.depth());
    let clusters = cut.clusters(&tree);
    let leaf = clusters.iter().find(|c| c.0 == path.leaf()).unwrap();
    assert!((leaf.1 - 1.0).abs() < 1e-6);
    // A cell that then collects nothing keeps its cut.
    let before = cut.nodes().to_vec();
    assert!(!guide.refine(&mut cut));
    assert_eq!(cut.nodes(), &before[..]);
}

// ---------------------------------------------------------------------------
// Unbiasedness
// ---------------------------------------------------------------------------

/// A wall in the plane x = 0 for 0 < y < 3 blocks the segment between a
/// shading point and a light when the segment crosses it there.
fn visible(p: Vec3, l: Vec3) -> bool {
    if (p.x < 0.0) == (l.x < 0.0) {
        return true;
    }
    let t = p.x / (p.x - l.x);
    let y = p.y + t * (l.y - p.y);
    !(0.0..3.0).contains(&y)
}

/// The direct illumination of light `l` at `p` (normal +Y): power x cosine
/// / (4 pi d^2), times visibility.
fn contribution(light: &Emitter, p: Vec3) -> f64 {
    let c = light.bounds.center();
    let d = c - p;
    let cos = (d.y / d.length()).max(0.0) as f64;
    if !visible(p, c) {
        return 0.0;
    }
    light.power as f64 * cos / (4.0 * core::f64::consts::PI * d.length_squared() as f64)
}

/// The GLT-sampled estimate of direct illumination matches brute force
/// within 4 standard errors, with delta lights that never received a record
/// (a renderer that learns only from BSDF hits). With `alpha = 0` those
/// lights have pmf 0: that estimator would be biased, which this scene
/// detects.
#[test]
fn estimate_is_unbiased_with_the_defensive_mixture() {
    let mut rng = Rand::new(11);
    let lights: Vec<Emitter> = (0..60)
        .map(|i| {
            let p = Vec3::new(
                rng.range(-6.0, 6.0),
                rng.range(1.0, 6.0),
                rng.range(-6.0, 6.0),
            );
            if i % 4 == 0 {
                Emitter::point(p, rng.range(5.0, 50.0))
            } else {
                Emitter::sphere(p, 0.1, rng.range(1.0, 20.0))
            }
        })
        .collect();
    let tree = LightTree::build(&lights, BuildHeuristic::Sarh).unwrap();
    let points = [
        Vec3::new(-2.0, 0.0, 0.5),
        Vec3::new(3.0, 0.0, -1.0),
        Vec3::new(-0.5, 0.0, 4.0),
    ];
    for (below_cut, split_prior) in ALL_CONFIGS {
        let train = CutConfig {
            below_cut,
            split_prior,
            ..CutConfig::default()
        };
        let guide = CutRules::new(&tree, train).unwrap();
        for (k, &p) in points.iter().enumerate() {
            let ctx = ShadingContext::on_surface(p, Vec3::Y);
            let truth: f64 = lights.iter().map(|l| contribution(l, p)).sum();
            // Learn from area lights only, proportional to their
            // contribution (with multiplicative noise).
            let mut cut = guide.new_cut();
            for _ in 0..3 {
                for _ in 0..3000 {
                    let e = rng.below(60);
                    if !lights[e as usize].delta {
                        let v = contribution(&lights[e as usize], p) * (0.5 + rng.f() as f64);
                        guide.record(&cut, LightId::Emitter(e), v as f32);
                    }
                }
                guide.refine(&mut cut);
            }
            let blind = CutConfig {
                alpha: 0.0,
                ..train
            };
            let blind_guide = CutRules::new(&tree, blind).unwrap();
            let biased: f64 = (0..60u32)
                .filter(|&e| blind_guide.pmf_exact(&cut, &ctx, LightId::Emitter(e)) > 0.0)
                .map(|e| contribution(&lights[e as usize], p))
                .sum();
            assert!(
                biased < truth * 0.99,
                "point {k}: alpha = 0 misses nothing ({biased} vs {truth})"
            );
            let n = 100_000;
            let (mut sum, mut sum2) = (0.0f64, 0.0f64);
            for _ in 0..n {
                let s = guide.sample(&cut, &ctx, rng.f()).unwrap();
                let LightId::Emitter(e) = s.light else {
                    panic!()
                };
                let x = contribution(&lights[e as usize], p) / s.pmf as f64;
                sum += x;
                sum2 += x * x;
            }
            let mean = sum / n as f64;
            let se = ((sum2 / n as f64 - mean * mean) / (n - 1) as f64).sqrt();
            assert!(
                (mean - truth).abs() < 4.0 * se,
                "{below_cut:?} {split_prior:?} point {k}: {mean} vs {truth} (se {se})"
            );
        }
    }
}

// ---------------------------------------------------------------------------
// Numerical stability
// ---------------------------------------------------------------------------

/// A chain whose leaf of emitter `hole` names no emitter: a custom
/// hierarchy may have such a leaf.
struct Holed {
    chain: Chain,
    hole: u32,
}

impl LightHierarchy for Holed {
    fn root(&self) -> Option<u32> {
        self.chain.root()
    }
    fn children(&self, node: u32) -> Option<[u32; 2]> {
        self.chain.children(node)
    }
    fn parent(&self, node: u32) -> Option<u32> {
        self.chain.parent(node)
    }
    fn power(&self, node: u32) -> f32 {
        self.chain.power(node)
    }
    fn node_bounds(&self, node: u32) -> NodeBounds {
        self.chain.node_bounds(node)
    }
    fn emitter(&self, node: u32) -> Option<u32> {
        self.chain.emitter(node).filter(|&e| e != self.hole)
    }
    fn leaf(&self, emitter: u32) -> Option<u32> {
        self.chain.leaf(emitter).filter(|_| emitter != self.hole)
    }
    fn node_count(&self) -> usize {
        self.chain.node_count()
    }
    fn emitter_count(&self) -> usize {
        self.chain.emitter_count()
    }
}

/// A walk that reaches a leaf naming no emitter chooses nothing, never a
/// light made up from the leaf's marker (the walk table marks such a leaf
/// `BAD_LEAF`; reading it as an emitter would give `2^31 - 1`). The
/// control: the hole is reached (some draws choose nothing).
#[test]
fn a_leaf_without_an_emitter_is_never_chosen() {
    let holed = Holed {
        chain: Chain::new(vec![1.0, 2.0, 3.0, 4.0, 5.0]),
        hole: 3,
    };
    let guide = CutRules::new(&holed, CutConfig::default()).unwrap();
    let cut = guide.new_cut();
    let ctx = ShadingContext::at(Vec3::new(3.0, 0.0, 0.0));
    let mut nothing = 0;
    for i in 0..4000 {
        let u = (i as f32 + 0.5) / 4000.0;
        let Some(s) = guide.sample(&cut, &ctx, u) else {
            nothing += 1;
            continue;
        };
        let LightId::Emitter(e) = s.light else {
            panic!("{:?}", s.light)
        };
        assert!(e < 5 && e != 3, "chose {e}");
        assert_eq!(s.pmf.to_bits(), guide.pmf(&cut, &ctx, s.light).to_bits());
    }
    assert!(nothing > 0, "the hole was never reached");
    assert_eq!(guide.pmf(&cut, &ctx, LightId::Emitter(3)), 0.0);
}

/// One uniform number per descent stays exact in distribution through the
/// cut and the tree together, 100 levels deep: the cut covers the first 70
/// levels, power descent the last 30. Chi-square over the 100 leaves
/// against `pmf()`, with f32 and f64 numbers. (An f32 rescaling, as in the
/// paper's code, never reaches leaves past depth ~24 and fails this.)
#[test]
fn deep_chain_is_exact_in_distribution() {
    let chain = Chain::deep();
    let n = chain.n();
    for (below_cut, split_prior) in ALL_CONFIGS {
        let config = CutConfig {
            below_cut,
            split_prior,
            ..CutConfig::default()
        };
        let guide = CutRules::new(&chain, config).unwrap();
        let mut cut = guide.new_cut();
        for _ in 0..16 {
            for k in 0..n {
                guide.record(&cut, LightId::Emitter(k), Chain::deep_target(k));
            }
            guide.refine(&mut cut);
        }
        assert_valid_cut(&chain, &cut);
        assert_eq!(cut.nodes().len(), 70, "the cut ends at depth 70");
        let ctx = ShadingContext::at(Vec3::new(3.0, 0.0, 0.0));
        let pmf: Vec<f64> = (0..n)
            .map(|k| guide.pmf_exact(&cut, &ctx, LightId::Emitter(k)))
            .collect();
        assert!((pmf.iter().sum::<f64>() - 1.0).abs() < 1e-12);
        assert!(pmf[99] > 1e-4, "{}", pmf[99]);
        let draws = 200_000;
        let mut rng = Rand::new(99);
        for exact in [false, true] {
            let mut counts = vec![0u64; n as usize];
            for _ in 0..draws {
                let light = if exact {
                    guide.sample_exact(&cut, &ctx, rng.f64()).unwrap().0
                } else {
                    guide.sample(&cut, &ctx, rng.f()).unwrap().light
                };
                let LightId::Emitter(e) = light else { panic!() };
                counts[e as usize] += 1;
            }
            let chi2: f64 = (0..n as usize)
                .map(|k| {
                    let expect = pmf[k] * draws as f64;
                    (counts[k] as f64 - expect).powi(2) / expect
                })
                .sum();
            // 99 degrees of freedom: mean 99, sd 14; 200 is > 7 sd.
            assert!(
                chi2 < 200.0,
                "{below_cut:?} {split_prior:?} exact={exact}: chi2 {chi2}"
            );
            assert!(counts[99] > 0 && counts[98] > 0);
        }
    }
}

/// Sums spanning 1e-30..1e30 in one cell: no NaN, valid cut, pmf sums to 1,
/// sample and pmf agree; the tiny ones keep their prior floor.
#[test]
fn sums_across_sixty_decades() {
    let mut rng = Rand::new(21);
    let lights = lights_in_box(&mut rng, 500, 8.0);
    let tree = LightTree::build(&lights, BuildHeuristic::Sarh).unwrap();
    for accumulation in [Accumulation::Fast, Accumulation::Deterministic] {
        let config = CutConfig {
            accumulation,
            unbounded: UnboundedLights::new(2, 0.1).unwrap(),
            ..CutConfig::default()
        };
        let guide = CutRules::new(&tree, config).unwrap();
        let mut cut = guide.new_cut();
        for round in 0..3 {
            for e in 0..500u32 {
                let decade = (e * 7 + round) % 61;
                let v = 10f32.powi(decade as i32 - 30);
                guide.record(&cut, LightId::Emitter(e), v);
            }
            guide.record(&cut, LightId::Unbounded(0), 1.0e-30);
            guide.record(&cut, LightId::Unbounded(1), 1.0e30);
            guide.refine(&mut cut);
            assert_valid_cut(&tree, &cut);
            for _ in 0..3 {
                let ctx = ShadingContext::on_surface(rng.point(9.0), Vec3::Y);
                let total = pmf_total(&guide, &cut, &ctx);
                assert!((total - 1.0).abs() < 1e-5, "{total}");
                for e in 0..500 {
                    let p = guide.pmf_exact(&cut, &ctx, LightId::Emitter(e));
                    assert!(p > 0.0, "emitter {e} lost its floor");
                }
                assert_sample_matches_pmf(&guide, &cut, &ctx, &mut rng, 300);
            }
        }
    }
}

/// Empty, single-light and two-light scenes, with and without unbounded
/// lights (a sun and a sky) and the mixture.
#[test]
fn tiny_scenes() {
    let one = vec![Emitter::point(Vec3::ONE, 2.0)];
    let two = vec![
        Emitter::point(Vec3::ONE, 2.0),
        Emitter::point(Vec3::ZERO, 6.0),
    ];
    let none: Vec<Emitter> = Vec::new();
    let dark = vec![
        Emitter::point(Vec3::ONE, 0.0),
        Emitter::point(Vec3::ZERO, 0.0),
    ];
    let mut rng = Rand::new(1);
    for lights in [&none, &one, &two, &dark] {
        let tree = LightTree::build(lights, BuildHeuristic::Sarh).unwrap();
        for unbounded in [
            UnboundedLights::NONE,
            UnboundedLights::new(2, 0.25).unwrap(),
        ] {
            for alpha in [0.0, 0.1] {
                let config = CutConfig {
                    alpha,
                    unbounded,
                    ..CutConfig::default()
                };
                let guide = CutRules::new(&tree, config).unwrap();
                let mut cut = guide.new_cut();
                let ctx = ShadingContext::at(Vec3::splat(0.5));
                for round in 0..3 {
                    assert_valid_cut(&tree, &cut);
                    let total = pmf_total(&guide, &cut, &ctx);
                    assert!((total - expected_total(&guide)).abs() < 1e-6);
                    assert_sample_matches_pmf(&guide, &cut, &ctx, &mut rng, 50);
                    for e in 0..lights.len() as u32 {
                        guide.record(&cut, LightId::Emitter(e), 1.0 + e as f32);
                    }
                    if round == 1 {
                        guide.record(&cut, LightId::Unbounded(0), 3.0);
                    }
                    if round == 2 {
                        guide.record(&cut, LightId::Unbounded(1), 0.5);
                    }
                    guide.refine(&mut cut);
                }
            }
        }
        if lights.len() == 1 {
            let config = CutConfig::default();
            let guide = CutRules::new(&tree, config).unwrap();
            let cut = guide.new_cut();
            assert!(cut.nodes().is_empty());
            let s = guide.sample(&cut, &ShadingContext::at(Vec3::ZERO), 0.7);
            assert_eq!(
                s.map(|s| (s.light, s.pmf)),
                Some((LightId::Emitter(0), 1.0))
            );
        }
    }
}

/// Subtrees whose emitters all have zero power: never sampled, records to
/// them dropped, the rest sums to 1 under both split priors.
#[test]
fn zero_power_subtrees() {
    let mut rng = Rand::new(8);
    // Dark lights on one side of the scene so whole subtrees are dark.
    let lights: Vec<Emitter> = (0..200)
        .map(|i| {
            let mut p = rng.point(5.0);
            if i < 100 {
                p.x = -10.0 - p.x.abs();
                Emitter::point(p, 0.0)
            } else {
                Emitter::point(p, rng.range(0.5, 2.0))
            }
        })
        .collect();
    let tree = LightTree::build(&lights, BuildHeuristic::Balanced).unwrap();
    let [l, r] = tree.children(tree.root().unwrap()).unwrap();
    assert!(tree.power(l) == 0.0 || tree.power(r) == 0.0);
    for (below_cut, split_prior) in ALL_CONFIGS {
        let config = CutConfig {
            below_cut,
            split_prior,
            sigma: 0.0,
            ..CutConfig::default()
        };
        let guide = CutRules::new(&tree, config).unwrap();
        let mut cut = guide.new_cut();
        for _ in 0..3 {
            for e in 0..200u32 {
                let o = guide.record(&cut, LightId::Emitter(e), 1.0);
                assert_eq!(o == RecordOutcome::Dropped, e < 100);
            }
            guide.refine(&mut cut);
            assert_valid_cut(&tree, &cut);
            let ctx = ShadingContext::on_surface(rng.point(5.0), Vec3::X);
            assert!((pmf_total(&guide, &cut, &ctx) - 1.0).abs() < 1e-6);
            for e in 0..100 {
                assert_eq!(guide.pmf(&cut, &ctx, LightId::Emitter(e)), 0.0);
            }
            assert_sample_matches_pmf(&guide, &cut, &ctx, &mut rng, 300);
        }
    }
}

/// The power prior keeps `f32` relative precision on both sides of every
/// split: lights with 1e-12 and 3e-10 of the total power keep their floor
/// `alpha * power / total` after the cut learned only the bright one (a
/// plain `f32` `p_left` would round their side to 0).
#[test]
fn prior_floor_survives_extreme_ratios() {
    let lights = vec![
        Emitter::point(Vec3::ZERO, 3.0e9),
        Emitter::point(Vec3::X, 3.0e-3),
        Emitter::point(Vec3::Y, 1.0),
    ];
    let tree = LightTree::build(&lights, BuildHeuristic::Sarh).unwrap();
    // The paper's rules (the power prior), rebuilding from any data (one
    // record per pass).
    let config = CutConfig {
        min_records: 0,
        ..CutConfig::default().with_paper_rules()
    };
    let guide = CutRules::new(&tree, config).unwrap();
    let alpha = guide.config().alpha;
    let mut cut = guide.new_cut();
    for _ in 0..3 {
        guide.record(&cut, LightId::Emitter(0), 1.0);
        guide.refine(&mut cut);
    }
    let ctx = ShadingContext::at(Vec3::ONE);
    let total: f64 = lights.iter().map(|l| l.power as f64).sum();
    for e in 1..3u32 {
        let p = guide.pmf_exact(&cut, &ctx, LightId::Emitter(e));
        let expect = alpha * lights[e as usize].power as f64 / total;
        assert!(
            (p / expect - 1.0).abs() < 1e-5,
            "light {e}: {p} vs {expect}"
        );
    }
    assert!((pmf_total(&guide, &cut, &ctx) - 1.0).abs() < 1e-12);
}

/// A million lights (Balanced build for speed): no NaN, pmf sums to 1,
/// sample and pmf agree after training.
#[test]
fn a_million_lights() {
    let mut rng = Rand::new(1_000_000);
    let lights: Vec<Emitter> = (0..1_000_000)
        .map(|_| Emitter::point(rng.point(100.0), rng.range(0.0, 1.0).powi(4)))
        .collect();
    let tree = LightTree::build(&lights, BuildHeuristic::Balanced).unwrap();
    let config = CutConfig::default();
    let guide = CutRules::new(&tree, config).unwrap();
    let mut cut = guide.new_cut();
    let ctx = ShadingContext::on_surface(Vec3::new(10.0, -3.0, 5.0), Vec3::Y);
    for _ in 0..2 {
        for _ in 0..100_000 {
            let s = guide.sample(&cut, &ctx, rng.f()).unwrap();
            let LightId::Emitter(e) = s.light else {
                panic!()
            };
            // Only lights in one octant contribute.
            let c = lights[e as usize].bounds.min;
            let v = if c.x > 0.0 && c.y > 0.0 && c.z > 0.0 {
                lights[e as usize].power
            } else {
                0.0
            };
            guide.record(&cut, s.light, v / s.pmf);
        }
        guide.refine(&mut cut);
    }
    assert_valid_cut(&tree, &cut);
    assert!(cut.nodes().len() > 30);
    let total = pmf_total(&guide, &cut, &ctx);
    assert!((total - 1.0).abs() < 1e-5, "{total}");
    assert_sample_matches_pmf(&guide, &cut, &ctx, &mut rng, 20_000);
}

// ---------------------------------------------------------------------------
// Concurrency and memory
// ---------------------------------------------------------------------------

/// Records from four threads give the same learned cut as a serial run: bit
/// for bit in deterministic mode, to f32 rounding in fast mode.
#[test]
fn threads_equal_serial() {
    let mut rng = Rand::new(4);
    let lights = lights_in_box(&mut rng, 400, 5.0);
    let tree = LightTree::build(&lights, BuildHeuristic::Sarh).unwrap();
    let stream: Vec<(LightId, f32)> = (0..40_000)
        .map(|i| {
            let light = if i % 97 == 0 {
                LightId::Unbounded(i % 2)
            } else {
                LightId::Emitter(rng.below(400) % (rng.below(400) + 1))
            };
            (light, rng.range(0.0, 1.0).powi(3) * 1.0e3 + 1.0e-7)
        })
        .collect();
    for accumulation in [Accumulation::Deterministic, Accumulation::Fast] {
        let config = CutConfig {
            accumulation,
            unbounded: UnboundedLights::new(2, 0.05).unwrap(),
            sigma: 0.002,
            ..CutConfig::default()
        };
        let guide = CutRules::new(&tree, config).unwrap();
        let mut serial = guide.new_cut();
        let mut parallel = serial.clone();
        for round in 0..3 {
            let chunk = &stream[round * 10_000..(round + 1) * 10_000];
            for &(light, v) in chunk {
                guide.record(&serial, light, v);
            }
            std::thread::scope(|s| {
                for t in 0..4 {
                    let (cut, guide) = (&parallel, &guide);
                    s.spawn(move || {
                        for &(light, v) in chunk.iter().skip(t).step_by(4) {
                            guide.record(cut, light, v);
                        }
                    });
                }
            });
            if accumulation == Accumulation::Deterministic {
                assert_eq!(serial.accumulated(), parallel.accumulated());
            }
            guide.refine(&mut serial);
            guide.refine(&mut parallel);
            let (a, b) = (serial.nodes(), parallel.nodes());
            match accumulation {
                Accumulation::Deterministic => {
                    let bytes_a: &[u8] = bytemuck::cast_slice(a);
                    let bytes_b: &[u8] = bytemuck::cast_slice(b);
                    assert_eq!(bytes_a, bytes_b);
                    let bits = |c: &GuidingCut| {
                        c.unbounded_fractions()
                            .iter()
                            .map(|f| f.to_bits())
                            .collect::<Vec<_>>()
                    };
                    assert_eq!(bits(&serial), bits(&parallel));
                }
                Accumulation::Fast => {
                    assert_eq!(a.len(), b.len());
                    for (x, y) in a.iter().zip(b) {
                        assert_eq!(x.slot(Side::Left), y.slot(Side::Left));
                        assert_eq!(x.slot(Side::Right), y.slot(Side::Right));
                        assert!((x.p_left() - y.p_left()).abs() <= 1e-6);
                    }
                }
            }
        }
    }
}

/// A cut node is 12 bytes, and the memory report counts them so.
#[test]
fn cut_node_is_twelve_bytes() {
    assert_eq!(CutNode::BYTES, 12);
    assert_eq!(std::mem::size_of::<CutNode>(), 12);
    let mut rng = Rand::new(2);
    let lights = lights_in_box(&mut rng, 100, 5.0);
    let tree = LightTree::build(&lights, BuildHeuristic::Sarh).unwrap();
    for (accumulation, per_sum) in [(Accumulation::Fast, 8), (Accumulation::Deterministic, 48)] {
        let config = CutConfig {
            accumulation,
            ..CutConfig::default()
        };
        let guide = CutRules::new(&tree, config).unwrap();
        let mut cut = guide.new_cut();
        for e in 0..100 {
            guide.record(&cut, LightId::Emitter(e), 1.0 + (e % 3) as f32);
        }
        guide.refine(&mut cut);
        let m = cut.memory();
        assert_eq!(m.nodes, cut.nodes().len());
        assert_eq!(m.node_bytes, 12 * m.nodes);
        // One sum per slot (no unbounded light here), plus the default
        // modulation's 7 anchor sums.
        assert_eq!(m.sum_bytes, per_sum * (2 * m.nodes + 7));
        assert_eq!(cut.heap_bytes(), m.node_bytes + m.sum_bytes);
    }
}

/// The test hierarchy itself: leaf `k` at depth `k + 1`, parents and
/// children agree, powers add up.
#[test]
fn chain_hierarchy_is_consistent() {
    let chain = Chain::new((0..80).map(|k| k as f32).collect());
    for k in 0..79u32 {
        let path: EmitterPath = chain.path(k).unwrap();
        assert_eq!(path.depth(), k as usize + 1);
        assert_eq!(chain.emitter(path.leaf()), Some(k));
    }
    assert_eq!(chain.path(79).unwrap().depth(), 79);
    assert_eq!(chain.power(0), (0..80).sum::<u32>() as f32);
    for node in 1..chain.node_count() as u32 {
        let parent = chain.parent(node).unwrap();
        assert!(chain.children(parent).unwrap().contains(&node));
    }
}

// ---------------------------------------------------------------------------
// Modulation by importance inside a cell
// ---------------------------------------------------------------------------

/// With [`Modulation::Importance`] the learned distribution is reproduced
/// at the cell's anchor (the mean record position) and follows the
/// importance away from it: at the anchor every emitter's pmf equals the
/// unmodulated cut's (to f32 rounding); near one end of a row of lights the
/// near lights gain and the second moment of sampling the contributions
/// there falls; the pmf still sums to 1 with sample == pmf bit for bit.
#[test]
fn modulation_reproduces_the_learned_cut_at_the_anchor_and_follows_importance() {
    // 32 equal point lights on a row along x, 1 above the floor.
    let lights: Vec<Emitter> = (0..32)
        .map(|i| Emitter::point(Vec3::new(i as f32, 1.0, 0.0), 1.0))
        .collect();
    let tree = LightTree::build(&lights, BuildHeuristic::Sah).unwrap();
    let make = |modulation| {
        CutRules::new(
            &tree,
            CutConfig {
                modulation,
                min_records: 0,
                sigma: 0.001,
                ..CutConfig::default()
            },
        )
        .unwrap()
    };
    let (plain, modulated) = (make(Modulation::None), make(Modulation::Importance));
    let (mut a, mut b) = (plain.new_cut(), modulated.new_cut());
    // Every record is made at the anchor (the middle of the row), with the
    // inverse-square contribution there.
    let anchor = Vec3::new(15.5, 0.0, 0.0);
    for _ in 0..3 {
        for (i, e) in lights.iter().enumerate() {
            let v = 1.0 / (e.bounds.center() - anchor).length_squared();
            plain.record_from(&a, anchor, LightId::Emitter(i as u32), v);
            modulated.record_from(&b, anchor, LightId::Emitter(i as u32), v);
        }
        plain.refine(&mut a);
        modulated.refine(&mut b);
    }
    // Records without a position leave no anchor: that cut is sampled
    // exactly like the unmodulated one.
    let mut c = modulated.new_cut();
    for _ in 0..3 {
        for (i, e) in lights.iter().enumerate() {
            let v = 1.0 / (e.bounds.center() - anchor).length_squared();
            modulated.record(&c, LightId::Emitter(i as u32), v);
        }
        modulated.refine(&mut c);
    }
    let far = ShadingContext::at(Vec3::new(-3.0, 0.0, 0.0));
    for i in 0..32 {
        assert_eq!(
            plain.pmf_exact(&a, &far, LightId::Emitter(i)),
            modulated.pmf_exact(&c, &far, LightId::Emitter(i)),
            "light {i}: a cut without anchor is not modulated"
        );
    }
    let at = ShadingContext::at(anchor);
    for i in 0..32 {
        let (p, q) = (
            plain.pmf_exact(&a, &at, LightId::Emitter(i)),
            modulated.pmf_exact(&b, &at, LightId::Emitter(i)),
        );
        assert!(
            (p - q).abs() <= 1e-5 * p,
            "light {i} at the anchor: {p} vs {q}"
        );
    }
    // Near the row's start the first lights matter far more than at the
    // anchor; the plain cut cannot know.
    let near = ShadingContext::at(Vec3::new(0.0, 0.0, 0.0));
    let first = |g: &CutRules<&LightTree>, c| g.pmf_exact(c, &near, LightId::Emitter(0));
    assert!(
        first(&modulated, &b) > 3.0 * first(&plain, &a),
        "near light: {} vs {}",
        first(&modulated, &b),
        first(&plain, &a)
    );
    // And it samples the near point's inverse-square contributions with a
    // lower second moment, sum c^2 / p.
    let m2 = |g: &CutRules<&LightTree>, c| {
        (0..32u32)
            .map(|i| {
                let d2 = (lights[i as usize].bounds.center() - near.position).length_squared();
                let c2 = 1.0 / (d2 as f64 * d2 as f64);
                c2 / g.pmf_exact(c, &near, LightId::Emitter(i))
            })
            .sum::<f64>()
    };
    let (m_plain, m_mod) = (m2(&plain, &a), m2(&modulated, &b));
    assert!(m_mod < 0.5 * m_plain, "second moment {m_mod} vs {m_plain}");
    let total = pmf_total(&modulated, &b, &near);
    assert!((total - 1.0).abs() < 1e-9, "pmf sums to {total}");
    let mut rng = Rand::new(5);
    assert_sample_matches_pmf(&modulated, &b, &near, &mut rng, 200);
}

/// Below the cut, `BelowCut::Importance` is the light BVH's importance walk
/// restricted to the slot's subtree: for the initial cut (its root split by
/// power), no defensive prior and unmodulated probabilities, the pmf of
/// light `l` on side `s` is `p_s * bvh(l) / bvh(subtree s)`, where `bvh`
/// is the `ImportanceTreeSampler`'s pmf. With `BelowCut::Power` it is not
/// (the control). Importance is evaluated whatever the prior rule (a
/// mutant that evaluated it only for an importance prior went unseen).
/// The light BVH weighs each child by its own bound, so the cut does too
/// here (`ImportanceBound::Children`, not the default; the default's
/// grandchildren are `child_weights_follow_the_grandchildren`'s).
#[test]
fn below_cut_importance_is_the_importance_walk() {
    let mut rng = Rand::new(41);
    let lights = lights_in_box(&mut rng, 300, 10.0);
    let tree = LightTree::build(&lights, BuildHeuristic::Sarh).unwrap();
    let bvh = guiding::light_sampler::ImportanceTreeSampler::new(&tree);
    let [left, right] = tree.children(tree.root().unwrap()).unwrap();
    let under = |n: u32| {
        let mut out = Vec::new();
        let mut stack = vec![n];
        while let Some(k) = stack.pop() {
            match tree.children(k) {
                Some(c) => stack.extend(c),
                None => out.push(tree.emitter(k).unwrap()),
            }
        }
        out
    };
    let sides = [under(left), under(right)];
    let (pl, pr) = {
        let (l, r) = (f64::from(tree.power(left)), f64::from(tree.power(right)));
        (l / (l + r), r / (l + r))
    };
    for below_cut in [BelowCut::Importance, BelowCut::Power] {
        for prior in [Prior::Power, Prior::Importance] {
            let config = CutConfig {
                alpha: 0.0,
                below_cut,
                modulation: Modulation::None,
                prior,
                importance_bound: ImportanceBound::Children,
                ..CutConfig::default()
            };
            let guide = CutRules::new(&tree, config).unwrap();
            let cut = guide.new_cut();
            let mut worst = 0.0f64;
            let mut rng = Rand::new(42);
            for _ in 0..20 {
                let ctx = ShadingContext::on_surface(rng.point(12.0), rng.dir());
                for (s, side) in sides.iter().enumerate() {
                    let p_side = if s == 0 { pl } else { pr };
                    let sub: f64 = side
                        .iter()
                        .map(|&e| bvh.pmf_exact(&ctx, LightId::Emitter(e)))
                        .sum();
                    for &e in side {
                        let want = p_side * bvh.pmf_exact(&ctx, LightId::Emitter(e)) / sub;
                        let got = guide.pmf_exact(&cut, &ctx, LightId::Emitter(e));
                        worst = worst.max((got - want).abs() / want.max(1e-12));
                    }
                }
            }
            match below_cut {
                // The GLT reads importance from its decoded f32 table, the
                // BVH computes it in f64: a few 1e-4 apart at some points.
                BelowCut::Importance => assert!(worst < 5e-3, "{prior:?}: off by {worst}"),
                BelowCut::Power => assert!(worst > 0.1, "{prior:?}: the control, {worst}"),
            }
        }
    }
}

/// `CutRules::vertex` is the cut as a `LightChoice` at a point: the same
/// draws, pmfs and visibility as the rules' own calls at that point, and
/// not empty.
#[test]
fn a_cut_as_a_light_sampler_answers_as_its_rules() {
    let mut rng = Rand::new(51);
    let lights = lights_in_box(&mut rng, 200, 10.0);
    let tree = LightTree::build(&lights, BuildHeuristic::Sarh).unwrap();
    let config = CutConfig {
        visibility: true,
        ..CutConfig::default()
    };
    let guide = CutRules::new(&tree, config).unwrap();
    let mut cut = guide.new_cut();
    for _ in 0..2000 {
        let e = rng.below(200);
        guide.record_from(&cut, rng.point(5.0), LightId::Emitter(e), rng.f());
        guide.record_visibility(&cut, LightId::Emitter(e), 0.25, 1.0);
    }
    guide.refine(&mut cut);
    assert!(
        !guide
            .vertex(&cut, &ShadingContext::at(Vec3::ZERO))
            .is_empty()
    );
    for _ in 0..500 {
        let ctx = ShadingContext::on_surface(rng.point(8.0), rng.dir());
        let s = guide.vertex(&cut, &ctx);
        assert_eq!(s.context(), &ctx);
        let (u, u64) = (rng.f(), rng.f64());
        assert_eq!(s.sample(u), guide.sample(&cut, &ctx, u));
        assert_eq!(s.sample_exact(u64), guide.sample_exact(&cut, &ctx, u64));
        let l = LightId::Emitter(rng.below(200));
        assert_eq!(s.pmf(l), guide.pmf(&cut, &ctx, l));
        assert_eq!(s.pmf_exact(l), guide.pmf_exact(&cut, &ctx, l));
        assert_eq!(s.visibility(l), guide.visibility(&cut, l));
        assert!(s.visibility(l) < 0.5, "learned from 1/4 records");
        let with = guide.sample_with_visibility(&cut, &ctx, u);
        assert_eq!(s.sample_with_visibility(u), with);
        assert_eq!(
            with,
            guide
                .sample(&cut, &ctx, u)
                .map(|x| (x, guide.visibility(&cut, x.light)))
        );
    }
    // Lights without power and no unbounded light: empty, and says so.
    let dark: Vec<Emitter> = lights
        .iter()
        .map(|e| Emitter { power: 0.0, ..*e })
        .collect();
    let dark_tree = LightTree::build(&dark, BuildHeuristic::Sarh).unwrap();
    let dark_rules = CutRules::new(&dark_tree, CutConfig::default()).unwrap();
    let dark_cut = dark_rules.new_cut();
    assert!(
        dark_rules.is_empty()
            && dark_rules
                .vertex(&dark_cut, &ShadingContext::at(Vec3::ZERO))
                .is_empty()
    );
    assert_eq!(
        dark_rules
            .vertex(&dark_cut, &ShadingContext::at(Vec3::ZERO))
            .sample(0.5),
        None
    );
}

/// A light whose pmf rounds to 0 in `f32` is never returned, even by the
/// number that walks straight to it (`u = 0` takes every left branch): a
/// sample's pmf is in `(0, 1]`, as `LightSample` promises.
#[test]
fn a_pmf_that_rounds_to_zero_is_never_sampled() {
    let lights = [
        Emitter::point(Vec3::new(-1.0, 0.0, 0.0), 1e-30),
        Emitter::point(Vec3::new(1.0, 0.0, 0.0), 1e30),
    ];
    let tree = LightTree::build(&lights[..], BuildHeuristic::Sarh).unwrap();
    let [left, _] = tree.children(tree.root().unwrap()).unwrap();
    assert_eq!(tree.emitter(left), Some(0), "the dim light is on the left");
    for config in [
        CutConfig::default(),
        CutConfig::default().with_paper_rules(),
    ] {
        let guide = CutRules::new(&tree, config).unwrap();
        let cut = guide.new_cut();
        let ctx = ShadingContext::at(Vec3::new(0.0, 1.0, 0.0));
        assert!(guide.pmf_exact(&cut, &ctx, LightId::Emitter(0)) < 1e-45);
        assert_eq!(guide.pmf(&cut, &ctx, LightId::Emitter(0)), 0.0);
        for u in [0.0f32, f32::from_bits(1), 1e-30] {
            if let Some(s) = guide.sample(&cut, &ctx, u) {
                assert!(s.pmf > 0.0, "{config:?} u = {u}: {s:?}");
            }
        }
    }
}

/// What a cut reports of itself: the unbounded lights' fractions start at
/// their prior shares and become `U_i / (U + T)` after a refine; its memory
/// parts add up to its total, and adding memories adds every part.
#[test]
fn a_cut_reports_its_fractions_and_memory() {
    let mut rng = Rand::new(5);
    let lights = lights_in_box(&mut rng, 40, 4.0);
    let tree = LightTree::build(&lights, BuildHeuristic::Sarh).unwrap();
    let config = CutConfig {
        min_records: 0,
        unbounded: UnboundedLights::new(2, 0.1).unwrap(),
        ..CutConfig::default()
    };
    let guide = CutRules::new(&tree, config).unwrap();
    let mut cut = guide.new_cut();
    assert_eq!(cut.unbounded_fractions(), &[0.05f32, 0.05]);
    // Emitters 1.0 in all, the first unbounded light 3.0, the second none.
    for e in 0..40u32 {
        guide.record(&cut, LightId::Emitter(e), 1.0 / 40.0);
    }
    guide.record(&cut, LightId::Unbounded(0), 3.0);
    assert!(guide.refine(&mut cut));
    let f = cut.unbounded_fractions();
    assert_eq!(f.len(), 2);
    assert!((f[0] - 0.75).abs() < 1e-6, "{f:?}");
    assert_eq!(f[1], 0.0);

    let m = cut.memory();
    // (none of them 2, where doubling and squaring agree)
    assert!(
        [m.nodes, m.node_bytes, m.sum_bytes, m.inline_bytes]
            .iter()
            .all(|&x| x > 2),
        "{m:?}"
    );
    assert!(m.nodes > 0 && m.node_bytes > 0 && m.sum_bytes > 0 && m.inline_bytes > 0);
    assert_eq!(m.total(), m.node_bytes + m.sum_bytes + m.inline_bytes);
    let mut twice = m;
    twice += m;
    assert_eq!(
        (
            twice.nodes,
            twice.node_bytes,
            twice.sum_bytes,
            twice.inline_bytes
        ),
        (
            2 * m.nodes,
            2 * m.node_bytes,
            2 * m.sum_bytes,
            2 * m.inline_bytes
        )
    );
    assert_eq!(twice.total(), 2 * m.total());
}

/// A cut that learns visibility counts its parts exactly: its nodes, the
/// unbounded lights' fractions and every slot's learned visibility (4
/// bytes each) in the node bytes, the three kinds of sums in the sum bytes;
/// the heap is both. Its visibility has one entry per slot and unbounded
/// light, and slots seen a quarter of the time learn about a quarter.
#[test]
fn a_cut_with_visibility_counts_every_part() {
    let mut rng = Rand::new(8);
    let lights = lights_in_box(&mut rng, 60, 4.0);
    let tree = LightTree::build(&lights, BuildHeuristic::Sarh).unwrap();
    let config = CutConfig {
        min_records: 0,
        visibility: true,
        unbounded: UnboundedLights::new(3, 0.1).unwrap(),
        ..CutConfig::default()
    };
    let guide = CutRules::new(&tree, config).unwrap();
    let mut cut = guide.new_cut();
    for round in 0..2 {
        for e in 0..60u32 {
            let l = LightId::Emitter(e);
            guide.record_from(&cut, rng.point(3.0), l, 1.0 + e as f32);
            for k in 0..4 {
                let seen = if k == 0 { 1.0 } else { 0.0 };
                guide.record_visibility(&cut, l, seen, 1.0);
            }
        }
        guide.record(&cut, LightId::Unbounded(1), 30.0);
        assert!(guide.refine(&mut cut), "round {round}");
    }
    let n = cut.nodes().len();
    assert!(n > 3, "{n} nodes");
    let vis = cut.visibility();
    assert_eq!(vis.len(), 2 * n + 3);
    // (slots split in the last refine start from the prior, 1)
    let low = vis[..2 * n].iter().filter(|&&v| v < 0.3).count();
    assert!(low > n / 2 && vis.iter().all(|&v| v <= 1.0), "{vis:?}");
    let m = cut.memory();
    assert_eq!(m.nodes, n);
    assert_eq!(m.node_bytes, n * CutNode::BYTES + (3 + vis.len()) * 4);
    assert_eq!(cut.heap_bytes(), m.node_bytes + m.sum_bytes);
    assert!(m.sum_bytes > 2 * n * 8, "{m:?}");
}

/// The anchor (the mean position a cell's records came from) ignores
/// records from non-finite positions entirely: their weight does not
/// dilute the mean of the others.
#[test]
fn the_anchor_ignores_non_finite_positions() {
    let mut rng = Rand::new(9);
    let lights = lights_in_box(&mut rng, 30, 4.0);
    let tree = LightTree::build(&lights, BuildHeuristic::Sarh).unwrap();
    let guide = CutRules::new(&tree, CutConfig::default()).unwrap();
    let cut = guide.new_cut();
    assert_eq!(cut.anchor(), None);
    let at = Vec3::new(2.0, -4.0, 6.0);
    for p in [at, Vec3::NAN, at, Vec3::new(f32::INFINITY, 0.0, 0.0), at] {
        guide.record_from(&cut, p, LightId::Emitter(3), 1.0);
    }
    // Records that record nothing (a zero value, a dropped one) do not
    // move it either.
    let elsewhere = Vec3::new(-5.0, 5.0, -5.0);
    assert_eq!(
        guide.record_from(&cut, elsewhere, LightId::Emitter(3), 0.0),
        RecordOutcome::Zero
    );
    assert_eq!(
        guide.record_from(&cut, elsewhere, LightId::Emitter(3), -1.0),
        RecordOutcome::Dropped
    );
    assert_eq!(cut.anchor(), Some(at));
}

/// A GLT over `tree` (30 lights) whose light records use the box filter,
/// trained for three iterations of uniform records into several cells.
fn box_filter_glt<'a>(tree: &'a LightTree, rng: &mut Rand) -> guiding::glt::Glt<&'a LightTree> {
    use guiding::glt::{Glt, GltConfig};
    use guiding::spatial::SpatialFilter;
    let config = GltConfig {
        light_filter: SpatialFilter::Box,
        spatial_threshold: 200.0,
        ..GltConfig::default()
    };
    let mut glt = Glt::new(tree, common::scene(), config).unwrap();
    for _ in 0..3 {
        for _ in 0..3000 {
            let p = rng.point(9.0);
            glt.record_light_at(p, LightId::Emitter(rng.below(30)), 1.0);
        }
        glt.refine();
    }
    glt
}

/// With the box filter a record is shared among the cells its box overlaps,
/// each taking a fraction of its weight; the anchor of each is still the
/// position the records came from (the position weighted by its share, over
/// the shares), whatever the shares.
#[test]
fn shared_records_anchor_where_they_came_from() {
    let mut rng = Rand::new(12);
    let tree = LightTree::build(&lights_in_box(&mut rng, 30, 8.0), BuildHeuristic::Sarh).unwrap();
    let glt = box_filter_glt(&tree, &mut rng);
    let p = Vec3::new(0.013, -0.021, 0.017);
    for _ in 0..10 {
        glt.record_light_at(p, LightId::Emitter(4), 1.0);
    }
    let mut anchored = 0;
    for d in [-0.4f32, 0.0, 0.4] {
        for axis in [Vec3::X, Vec3::Y, Vec3::Z] {
            let cut = glt.vertex(&ShadingContext::at(p + d * axis)).unwrap().cut();
            if let Some(a) = cut.anchor() {
                assert!((a - p).length() < 1e-5, "anchor {a} for records from {p}");
                anchored += 1;
            }
        }
    }
    assert!(
        glt.memory().cells > 8 && anchored > 3,
        "{anchored} anchored"
    );
}

/// With the box filter a record's value is shared among the cells its box
/// overlaps by the fraction each covers: the cells' sums add up to the
/// value. A value so small that some cells' parts round to zero is still
/// `Recorded` when any cell took a part.
#[test]
fn box_filter_shares_a_records_value_by_volume() {
    use guiding::RecordOutcome;
    use guiding::glt::Glt;
    let mut rng = Rand::new(13);
    let tree = LightTree::build(&lights_in_box(&mut rng, 30, 8.0), BuildHeuristic::Sarh).unwrap();
    let mut glt = box_filter_glt(&tree, &mut rng);
    assert!(glt.memory().cells > 8);
    let collected = |glt: &Glt<&LightTree>| -> (f64, usize) {
        let sums = glt
            .spatial()
            .data_slice()
            .iter()
            .map(|c| c.cut().accumulated().0);
        (sums.clone().sum(), sums.filter(|&s| s > 0.0).count())
    };
    let (mut shared, mut mixed) = (0, 0);
    for _ in 0..300 {
        let p = rng.point(9.0);
        glt.clear_records();
        glt.record_light_at(p, LightId::Emitter(4), 3.0);
        let (total, overlapped) = collected(&glt);
        assert!((total - 3.0).abs() < 1e-5, "{total} at {p}");
        shared += usize::from(overlapped > 1);
        glt.clear_records();
        let tiny = f32::from_bits(1);
        let outcome = glt.record_light_at(p, LightId::Emitter(4), tiny);
        let (total, cells) = collected(&glt);
        mixed += usize::from(cells > 0 && cells < overlapped);
        let expected = match total > 0.0 {
            true => RecordOutcome::Recorded,
            false => RecordOutcome::Zero,
        };
        assert_eq!(outcome, expected, "at {p}");
    }
    assert!(shared > 100 && mixed > 20, "{shared} shared, {mixed} mixed");
}

/// A light without power is never chosen, under the paper's rules (power
/// ratios all the way down) and the defaults: its pmf is exactly 0 wherever
/// it sits in the tree, left or right of a lit sibling.
#[test]
fn a_light_without_power_has_pmf_zero() {
    let mut rng = Rand::new(14);
    let mut lights = lights_in_box(&mut rng, 24, 5.0);
    let dark = [0usize, 5, 11, 17, 23];
    for &d in &dark {
        lights[d].power = 0.0;
    }
    let tree = LightTree::build(&lights, BuildHeuristic::Sarh).unwrap();
    // Both sides occur: some dark leaf is a left child, some a right one.
    let sides: Vec<Side> = dark
        .iter()
        .map(|&d| {
            *tree
                .path(d as u32)
                .unwrap()
                .steps()
                .last()
                .map(|(_, s)| s)
                .unwrap()
        })
        .collect();
    assert!(
        sides.contains(&Side::Left) && sides.contains(&Side::Right),
        "{sides:?}"
    );
    for config in [
        CutConfig::default(),
        CutConfig::default().with_paper_rules(),
    ] {
        let guide = CutRules::new(&tree, config).unwrap();
        let cut = guide.new_cut();
        for _ in 0..20 {
            let ctx = ShadingContext::on_surface(rng.point(6.0), rng.dir());
            for &d in &dark {
                assert_eq!(guide.pmf_exact(&cut, &ctx, LightId::Emitter(d as u32)), 0.0);
            }
        }
    }
}

/// Each importance rule alone changes the light choice, and a configuration
/// with none of them pays for no importance table: the table is built only
/// when `CutConfig::uses_importance` says a rule needs it, so a rule left
/// without it would fall back to power silently. And the two rule
/// builders set all three rules.
#[test]
fn each_importance_rule_works_alone_and_only_they_pay_for_the_table() {
    let at = |i: u32| Vec3::new(2.0 * i as f32, 1.0, 0.0);
    let lights: Vec<Emitter> = (0..16)
        .map(|i| Emitter::point(at(i), 1.0 + (i % 3) as f32))
        .collect();
    let tree = LightTree::build(&lights, BuildHeuristic::Sarh).unwrap();
    // A coarse cut (sigma 0.3), so that below it matters too.
    let paper = CutConfig {
        sigma: 0.3,
        ..CutConfig::default().with_paper_rules()
    };
    let rules = |c: CutConfig| (c.modulation, c.below_cut, c.prior);
    assert_eq!(
        rules(paper),
        (Modulation::None, BelowCut::Power, Prior::Power)
    );
    let all = paper.with_importance();
    let importance = (
        Modulation::Importance,
        BelowCut::Importance,
        Prior::Importance,
    );
    assert_eq!(rules(all), importance);
    assert_eq!(rules(CutConfig::default()), importance);
    // Trained from the left end (x = 0), evaluated at the right end.
    let learned = |config: CutConfig| {
        let guide = CutRules::new(&tree, config).unwrap();
        let cut = guide.new_cut();
        for k in 0..4000u32 {
            let e = k % 16;
            let value = 1.0 / (1.0 + at(e).length_squared());
            guide.record_from(&cut, Vec3::ZERO, LightId::Emitter(e), value);
        }
        let mut cut = cut;
        assert!(guide.refine(&mut cut));
        let ctx = ShadingContext::at(Vec3::new(30.0, 0.0, 0.0));
        let pmf: Vec<f64> = (0..16)
            .map(|e| guide.pmf_exact(&cut, &ctx, LightId::Emitter(e)))
            .collect();
        (pmf, guide.bytes())
    };
    let (base, base_bytes) = learned(paper);
    for one in [
        CutConfig {
            modulation: Modulation::Importance,
            ..paper
        },
        CutConfig {
            below_cut: BelowCut::Importance,
            ..paper
        },
        CutConfig {
            prior: Prior::Importance,
            ..paper
        },
        all,
    ] {
        let (pmf, bytes) = learned(one);
        let moved: f64 = pmf.iter().zip(&base).map(|(a, b)| (a - b).abs()).sum();
        assert!(moved > 0.01, "{:?} moves the pmf by {moved}", rules(one));
        assert!(
            bytes > base_bytes,
            "{:?}: {bytes} bytes, paper {base_bytes}",
            rules(one)
        );
    }
}

/// A refinement from records that carry nothing from emitters (only
/// zeros, or only the unbounded lights') keeps the cut's nodes and says so
/// (`false`); the unbounded lights' fractions follow what was collected
/// (unchanged after zeros, all the sky's after only sky).
#[test]
fn a_cut_that_collected_nothing_from_emitters_keeps_its_nodes() {
    let lights: Vec<Emitter> = (0..16)
        .map(|i| Emitter::point(Vec3::new(i as f32, 0.0, 0.0), 1.0 + i as f32))
        .collect();
    let tree = LightTree::build(&lights, BuildHeuristic::Sarh).unwrap();
    let config = CutConfig {
        min_records: 0,
        unbounded: UnboundedLights::new(1, 0.1).unwrap(),
        ..CutConfig::default()
    };
    let guide = CutRules::new(&tree, config).unwrap();
    let mut cut = guide.new_cut();
    for k in 0..800u32 {
        guide.record(&cut, LightId::Emitter(k % 16), 1.0 + (k % 16) as f32);
    }
    guide.record(&cut, LightId::Unbounded(0), 40.0);
    assert!(guide.refine(&mut cut));
    let (nodes, fractions) = (cut.nodes().to_vec(), cut.unbounded_fractions().to_vec());
    assert!(nodes.len() > 2 && fractions[0] > 0.0 && fractions[0] < 0.1);
    for e in 0..16 {
        guide.record(&cut, LightId::Emitter(e), 0.0);
    }
    guide.record(&cut, LightId::Unbounded(0), 0.0);
    assert!(!guide.refine(&mut cut));
    assert_eq!(
        (cut.nodes(), cut.unbounded_fractions()),
        (&nodes[..], &fractions[..])
    );
    for _ in 0..100 {
        guide.record(&cut, LightId::Unbounded(0), 2.0);
    }
    assert!(!guide.refine(&mut cut));
    assert_eq!(
        (cut.nodes(), cut.unbounded_fractions()),
        (&nodes[..], &[1.0f32][..])
    );
}

/// The choice does not depend on the unit of power, up to the largest
/// powers a tree holds: every power (and every recorded value) times
/// 2^118, which `f32` and `f64` multiply exactly, puts the tree's total
/// near `f32::MAX` and changes no pmf, untrained or trained, at points a
/// millimetre from a light (where power over squared distance is far
/// beyond `f32::MAX`), far away and in between, under both importance
/// bounds. A rule that divided a power by a squared distance, or summed
/// such weights, in `f32` would overflow there and fall back to the
/// power split (the control in the comment below).
#[test]
fn the_choice_does_not_depend_on_the_unit_of_power() {
    const SCALE: f32 = (1u128 << 118) as f32;
    let mut rng = Rand::new(118);
    let base: Vec<Emitter> = (0..40)
        .map(|i| {
            let p = rng.point(4.0);
            let power = rng.range(0.1, 10.0);
            match i % 2 {
                0 => Emitter::point(p, power),
                _ => Emitter::area(
                    Aabb::new(p, p + Vec3::new(0.3, 0.0, 0.3)),
                    Vec3::new(rng.range(-1.0, 1.0), 1.0, rng.range(-1.0, 1.0)),
                    0.09,
                    power,
                ),
            }
        })
        .collect();
    let scaled: Vec<Emitter> = base
        .iter()
        .map(|e| Emitter {
            power: e.power * SCALE,
            ..*e
        })
        .collect();
    let trees = [&base, &scaled].map(|l| LightTree::build(&l[..], BuildHeuristic::Saoh).unwrap());
    assert!(trees[1].total_power() > 1e37 && trees[1].total_power().is_finite());
    // Points near lights (1 mm), far away and in the box; with and
    // without a normal.
    let mut points = Vec::new();
    for (i, e) in base.iter().enumerate() {
        let c = e.bounds.center();
        let near = c + Vec3::new(1e-3, 1e-3, 0.0);
        let far = c * 1e4 + Vec3::splat(1e4);
        let inside = rng.point(5.0);
        for p in [near, far, inside] {
            points.push(match i % 3 {
                0 => ShadingContext::at(p),
                _ => ShadingContext::on_surface(p, Vec3::new(0.3, 1.0, -0.2)),
            });
        }
    }
    for bound in [ImportanceBound::Children, ImportanceBound::Grandchildren] {
        let config = CutConfig {
            importance_bound: bound,
            min_records: 0,
            ..CutConfig::default()
        };
        let guides = [0, 1].map(|t| CutRules::new(&trees[t], config).unwrap());
        let mut cuts = [0, 1].map(|t| guides[t].new_cut());
        for round in 0..3 {
            let mut worst = 0.0f64;
            for ctx in &points {
                let pmfs = [0, 1].map(|t| {
                    (0..40u32)
                        .map(|e| guides[t].pmf_exact(&cuts[t], ctx, LightId::Emitter(e)))
                        .collect::<Vec<f64>>()
                });
                for (a, b) in pmfs[0].iter().zip(&pmfs[1]) {
                    assert!(b.is_finite(), "{bound:?} round {round}: {b}");
                    worst = worst.max((a - b).abs() / a.max(1e-300));
                }
                let total: f64 = pmfs[1].iter().sum();
                assert!((total - 1.0).abs() < 1e-9, "{bound:?}: sums to {total}");
                for u in [0.0f32, 0.3, 0.999] {
                    let s = guides[1].sample(&cuts[1], ctx, u).unwrap();
                    assert_eq!(Some(s.pmf), Some(guides[1].pmf(&cuts[1], ctx, s.light)));
                }
            }
            assert!(
                worst <= 1e-9,
                "{bound:?} round {round}: relative difference {worst}"
            );
            // Train both alike: light e at point k records the same value,
            // times the scale for the scaled tree.
            for (k, ctx) in points.iter().enumerate() {
                let e = (k * 7 + round) as u32 % 40;
                let v = 1.0
                    / (1.0
                        + ctx
                            .position
                            .distance_squared(base[e as usize].bounds.center()));
                guides[0].record(&cuts[0], LightId::Emitter(e), v);
                guides[1].record(&cuts[1], LightId::Emitter(e), v * SCALE);
            }
            for t in 0..2 {
                guides[t].refine(&mut cuts[t]);
            }
        }
        // The cuts learned (and alike: the pmfs above agree).
        assert!(
            cuts[1].nodes().len() > 3,
            "{bound:?}: {}",
            cuts[1].nodes().len()
        );
        assert_eq!(cuts[0].nodes().len(), cuts[1].nodes().len());
        // Control (run by hand): `Lanes::sides` weighing by `a / d` in
        // `f32` instead of scaling by the nearest lane fails this test.
    }
}
