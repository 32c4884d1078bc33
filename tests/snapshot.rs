//! The GPU snapshot (`guiding::snapshot`): its `f32` sampler over the
//! plain-data arrays is a distribution (sums to 1, draws what its pmf
//! says), chooses as the GLT it was taken from does up to rounding, stays
//! finite on hard scenes, and refuses arrays that are not a snapshot.

mod common;

use common::{Chain, LightsAt, Rand, chi_square_z, contribution, mixed_scene};
use glam::Vec3;
use guiding::cut::{BelowCut, CutConfig, Modulation, Prior};
use guiding::glt::Glt;
use guiding::snapshot::{SnapshotArrays, SnapshotError, SnapshotView};
use guiding::{
    Aabb, BuildHeuristic, Emitter, GltConfig, LightChoice, LightHierarchy, LightId, LightTree,
    ShadingContext, UnboundedLights,
};
use proptest::prelude::*;

/// A draw from a snapshot: the light, its pmf and the learned visibility
/// of the cluster it was chosen from (what the WGSL kernel returns).
#[derive(Clone, Copy, Debug, PartialEq)]
struct Draw {
    light: LightId,
    pmf: f32,
    visibility: f32,
}

/// The context of a point with exactly this normal (the GPU gets the
/// same words).
fn context(p: Vec3, normal: Option<Vec3>) -> ShadingContext {
    ShadingContext {
        normal,
        ..ShadingContext::at(p)
    }
}

/// The snapshot's vertex at `p` and its draw of `u`, with the visibility.
fn draw(view: &SnapshotView, p: Vec3, normal: Option<Vec3>, u: f32) -> Option<Draw> {
    let (s, visibility) = view
        .vertex(&context(p, normal))?
        .sample_with_visibility(u)?;
    Some(Draw {
        light: s.light,
        pmf: s.pmf,
        visibility,
    })
}

/// The snapshot's vertex at `p` and its pmf of `light` (0 with no vertex).
fn pmf(view: &SnapshotView, p: Vec3, normal: Option<Vec3>, light: LightId) -> f32 {
    view.vertex(&context(p, normal))
        .map_or(0.0, |v| v.pmf(light))
}

/// Visibility of light `e` from `p`: a wall at `x = 0` hides lights on
/// the other side.
fn visible(lights: &[Emitter], e: u32, p: Vec3) -> bool {
    (lights[e as usize].bounds.center().x < 0.0) == (p.x < 0.0)
}

/// Trains `glt` on its own choices at random surface points within `half`
/// of the origin: each record the chosen light's contribution over its
/// pmf (behind the wall: 0) and its visibility; unbounded lights get a
/// constant radiance. A refinement after each of `rounds` rounds.
fn train<H: LightHierarchy>(
    glt: &mut Glt<H>,
    lights: &[Emitter],
    half: f32,
    rounds: usize,
    r: &mut Rand,
) {
    for _ in 0..rounds {
        for _ in 0..20_000 {
            let ctx = ShadingContext::on_surface(r.point(half), r.dir());
            let Some(vertex) = glt.vertex(&ctx) else {
                continue;
            };
            let Some(s) = vertex.sample(r.f()) else {
                continue;
            };
            let (unshadowed, seen) = match s.light {
                LightId::Emitter(e) => (
                    contribution(&lights[e as usize], ctx.position),
                    visible(lights, e, ctx.position),
                ),
                LightId::Unbounded(i) => (0.5 + i as f64, r.f() < 0.5),
            };
            let shadowed = if seen { unshadowed } else { 0.0 };
            vertex.record_light(s.light, (shadowed / f64::from(s.pmf)) as f32);
            vertex.record_visibility(s.light, shadowed as f32, unshadowed as f32);
        }
        glt.refine();
    }
}

/// A GLT over `n` mixed lights in a 100^3 box, trained.
fn trained(n: usize, cut: CutConfig, seed: u64) -> (Vec<Emitter>, Glt<LightTree>) {
    let lights = mixed_scene(n, seed);
    let tree = LightTree::build(&lights, BuildHeuristic::default()).unwrap();
    let scene = Aabb::new(Vec3::splat(-60.0), Vec3::splat(60.0));
    let config = GltConfig {
        cut,
        ..GltConfig::default()
    };
    let mut glt = Glt::new(tree, scene, config).unwrap();
    train(&mut glt, &lights, 55.0, 3, &mut Rand::new(seed + 1));
    (lights, glt)
}

/// The rules measured: the defaults (importance everywhere), the paper's
/// (power everywhere), each importance rule alone; with two unbounded
/// lights and learned visibility.
fn rule_sets() -> Vec<(&'static str, CutConfig)> {
    let paper = CutConfig::default().with_paper_rules();
    let extra = |c: CutConfig| CutConfig {
        unbounded: UnboundedLights::new(2, 0.1).unwrap(),
        visibility: true,
        ..c
    };
    vec![
        ("default", extra(CutConfig::default())),
        ("paper", extra(paper)),
        (
            "modulation",
            extra(CutConfig {
                modulation: Modulation::Importance,
                ..paper
            }),
        ),
        (
            "below",
            extra(CutConfig {
                below_cut: BelowCut::Importance,
                ..paper
            }),
        ),
        (
            "prior",
            extra(CutConfig {
                prior: Prior::Importance,
                ..paper
            }),
        ),
        ("plain default", CutConfig::default()),
    ]
}

/// What `queries` random queries say about the snapshot against its GLT.
#[derive(Debug, Default)]
struct Agreement {
    /// Queries where both chose the same light (or both nothing).
    same: usize,
    queries: usize,
    /// The largest relative pmf difference for the same choice, and for
    /// any light (emitters and unbounded lights evaluated at random).
    sampled: f64,
    evaluated: f64,
    /// Visibilities of the same choice that differ.
    visibility: usize,
    /// The largest distance from a query's number to one from which the
    /// GLT chooses what the snapshot chose, where they differ.
    boundary: f64,
}

fn relative(a: f32, b: f64) -> f64 {
    if b == 0.0 {
        return if a == 0.0 { 0.0 } else { f64::INFINITY };
    }
    (f64::from(a) / b - 1.0).abs()
}

fn agreement(glt: &Glt<LightTree>, view: &SnapshotView, queries: usize, seed: u64) -> Agreement {
    let mut r = Rand::new(seed);
    let rules = glt.cut_rules();
    let k = rules.config().unbounded.count;
    let n = glt.light_tree().emitter_count() as u32;
    let mut a = Agreement {
        queries,
        ..Agreement::default()
    };
    for _ in 0..queries {
        // The context normalises the normal; the snapshot gets that one
        // (normalising a normal twice may move it by an ulp, and the
        // normal factor amplifies an ulp near grazing angles).
        let ctx = ShadingContext::on_surface(r.point(58.0), r.dir());
        let (p, n_ctx, u) = (ctx.position, ctx.normal, r.f());
        let Some(v) = glt.vertex(&ctx) else {
            panic!("{p} is in the scene")
        };
        let cpu = rules.sample_with_visibility(v.cut(), &ctx, u);
        let snap = draw(view, p, n_ctx, u);
        match (cpu, snap) {
            (Some((c, cv)), Some(s)) if c.light == s.light => {
                a.same += 1;
                a.sampled = a.sampled.max(relative(s.pmf, f64::from(c.pmf)));
                a.visibility += usize::from(cv != s.visibility);
            }
            (None, None) => a.same += 1,
            (_, s) => {
                // The GLT chooses the snapshot's light from a number
                // within `tau` of `u` (searched in steps finer than that
                // light's pmf, up to 1e-5).
                let step = s.map_or(1e-8, |s| (f64::from(s.pmf) / 2.0).clamp(1e-10, 1e-8));
                let chooses =
                    |d: f64| v.sample_exact(f64::from(u) + d).map(|x| x.0) == s.map(|s| s.light);
                let tau = (1..)
                    .map(|k| k as f64 * step)
                    .take_while(|&t| t <= 1e-5)
                    .find(|&t| chooses(-t) || chooses(t));
                a.boundary = a.boundary.max(tau.unwrap_or(f64::INFINITY));
            }
        }
        let light = match r.below(4) {
            0 if k > 0 => LightId::Unbounded(r.below(k)),
            _ => LightId::Emitter(r.below(n)),
        };
        let exact = rules.pmf_exact(v.cut(), &ctx, light);
        if exact > 1e-30 {
            a.evaluated = a.evaluated.max(relative(pmf(view, p, n_ctx, light), exact));
        }
    }
    a
}

/// The snapshot chooses as its GLT: over 100,000 queries per rule set on
/// 3,000 trained lights, at least 99.95% identical choices (seen: 99.986%
/// to 99.996%), every other one a number within 1e-6 of a boundary away
/// (seen: 7e-8; `f32` rounding moves boundaries by about 1e-7), pmfs
/// within 2e-6 of the GLT's `f64` ones (seen: 8e-7), the same learned
/// visibility for every identical choice.
#[test]
fn the_snapshot_chooses_as_its_glt() {
    for (name, cut) in rule_sets() {
        let (_, glt) = trained(3000, cut, 7);
        let snapshot = glt.snapshot().unwrap();
        let a = agreement(&glt, &snapshot.view(), 100_000, 11);
        eprintln!("{name}: {a:?}");
        assert!(a.same as f64 >= 0.9995 * a.queries as f64, "{name}: {a:?}");
        assert!(a.boundary <= 1e-6, "{name}: {a:?}");
        assert!(a.sampled <= 2e-6, "{name}: {a:?}");
        assert!(a.evaluated <= 2e-6, "{name}: {a:?}");
        assert_eq!(a.visibility, 0, "{name}: {a:?}");
    }
}

/// Checks the snapshot's distribution at `ctx`: the pmf over every light
/// sums to 1 (within `f32` rounding of the terms), `sample` reports the
/// pmf of what it draws bit for bit, and nothing of pmf 0 is drawn.
fn check_distribution(
    view: &SnapshotView,
    ctx: &ShadingContext,
    lights: u32,
    unbounded: u32,
    r: &mut Rand,
) {
    let (p, n) = (ctx.position, ctx.normal);
    let pmfs: Vec<f32> = (0..lights)
        .map(LightId::Emitter)
        .chain((0..unbounded).map(LightId::Unbounded))
        .map(|l| pmf(view, p, n, l))
        .collect();
    assert!(pmfs.iter().all(|x| x.is_finite() && *x >= 0.0), "{pmfs:?}");
    let total: f64 = pmfs.iter().map(|&x| f64::from(x)).sum();
    assert!((total - 1.0).abs() < 1e-5, "sums to {total} at {p}");
    for _ in 0..50 {
        let s = draw(view, p, n, r.f()).expect("a light");
        assert_eq!(s.pmf.to_bits(), pmf(view, p, n, s.light).to_bits(), "{s:?}");
        assert!(s.pmf > 0.0 && (0.0..=1.0).contains(&s.visibility), "{s:?}");
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]

    /// Over random small scenes, rules and training, the snapshot's pmf
    /// sums to 1 at every point and `sample` draws with the pmf it reports.
    #[test]
    fn the_snapshot_is_a_distribution(
        n in 1usize..60,
        rules in 0usize..6,
        unbounded in 0u32..3,
        seed in 0u64..1000,
        rounds in 0usize..3,
    ) {
        let (_, base) = rule_sets()[rules];
        let cut = CutConfig {
            unbounded: UnboundedLights::new(unbounded, if unbounded > 0 { 0.2 } else { 0.0 }).unwrap(),
            ..base
        };
        let lights = mixed_scene(n, seed);
        let tree = LightTree::build(&lights, BuildHeuristic::default()).unwrap();
        let scene = Aabb::new(Vec3::splat(-60.0), Vec3::splat(60.0));
        let mut glt = Glt::new(tree, scene, GltConfig { cut, ..GltConfig::default() }).unwrap();
        let mut r = Rand::new(seed);
        train(&mut glt, &lights, 55.0, rounds, &mut r);
        let snapshot = glt.snapshot().unwrap();
        let view = snapshot.view();
        for _ in 0..20 {
            let ctx = match r.below(3) {
                0 => ShadingContext::at(r.point(70.0)),
                _ => ShadingContext::on_surface(r.point(58.0), r.dir()),
            };
            check_distribution(&view, &ctx, n as u32, unbounded, &mut r);
        }
    }
}

/// Draws follow the pmf: chi-square over 200,000 draws at five points of a
/// trained 300-light scene (z below 4 means p > 3e-5).
#[test]
fn draws_follow_the_snapshots_pmf() {
    let (lights, glt) = trained(300, rule_sets()[0].1, 3);
    let snapshot = glt.snapshot().unwrap();
    let view = snapshot.view();
    let mut r = Rand::new(8);
    for _ in 0..5 {
        let ctx = ShadingContext::on_surface(r.point(50.0), r.dir());
        let sampler = view.vertex(&ctx).unwrap();
        let mut counts = vec![0u64; lights.len() + 2];
        for _ in 0..200_000 {
            let s = sampler.sample(r.f()).unwrap();
            let i = match s.light {
                LightId::Emitter(e) => e as usize,
                LightId::Unbounded(i) => lights.len() + i as usize,
            };
            counts[i] += 1;
        }
        let probs: Vec<f64> = (0..lights.len() as u32)
            .map(LightId::Emitter)
            .chain((0..2).map(LightId::Unbounded))
            .map(|l| f64::from(sampler.pmf(l)))
            .collect();
        let (z, _) = chi_square_z(&counts, &probs).expect("no draw of pmf 0");
        assert!(z < common::Z_P_1E4, "z = {z} at {}", ctx.position);
    }
}

/// Hard scenes keep the snapshot a distribution: one light, coincident
/// lights of 1e30 W beside a dark one and a 1e-30 W one, degenerate boxes
/// (points), all lights dark but for the unbounded lights; points outside
/// the scene, far from the origin, not finite.
#[test]
fn hard_scenes_stay_distributions() {
    let scene = Aabb::new(Vec3::splat(-10.0), Vec3::splat(10.0));
    let mut r = Rand::new(21);
    let points = [
        Vec3::ZERO,
        Vec3::new(3.0, -2.0, 1.0),
        Vec3::new(500.0, 0.0, 0.0),
        Vec3::new(-1e20, 3e19, 1e18),
        Vec3::new(1e30, 1e30, -1e30),
    ];
    let cases: Vec<(&str, Vec<Emitter>, u32)> = vec![
        ("one light", vec![Emitter::point(Vec3::ONE, 2.0)], 0),
        (
            "extremes",
            vec![
                Emitter::point(Vec3::new(1.0, 1.0, 0.0), 1e30),
                Emitter::point(Vec3::new(1.0, 1.0, 0.0), 1e30),
                Emitter::point(Vec3::new(-1.0, 1.0, 0.0), 0.0),
                Emitter::sphere(Vec3::new(2.0, -1.0, 0.0), 0.0, 1e-30),
                common::quad(Vec3::new(0.0, 4.0, 0.0), -Vec3::Y, 0.0, 3.0),
            ],
            1,
        ),
        ("all dark, sky", vec![Emitter::point(Vec3::ONE, 0.0); 3], 2),
    ];
    for (name, lights, unbounded) in cases {
        let tree = LightTree::build(&lights, BuildHeuristic::default()).unwrap();
        for rules in [
            CutConfig::default(),
            CutConfig::default().with_paper_rules(),
        ] {
            let cut = CutConfig {
                unbounded: UnboundedLights::new(unbounded, if unbounded > 0 { 0.3 } else { 0.0 })
                    .unwrap(),
                ..rules
            };
            let config = GltConfig {
                cut,
                ..GltConfig::default()
            };
            let mut glt = Glt::new(&tree, scene, config).unwrap();
            train(&mut glt, &lights, 9.0, 2, &mut r);
            let snapshot = glt.snapshot().unwrap();
            let view = snapshot.view();
            for p in points {
                for ctx in [
                    ShadingContext::at(p),
                    ShadingContext::on_surface(p, Vec3::Y),
                ] {
                    check_distribution(&view, &ctx, lights.len() as u32, unbounded, &mut r);
                }
            }
            for bad in [Vec3::NAN, Vec3::new(0.0, f32::INFINITY, 0.0)] {
                assert_eq!(draw(&view, bad, None, 0.5), None, "{name}");
                assert_eq!(pmf(&view, bad, None, LightId::Emitter(0)), 0.0, "{name}");
            }
            if name == "one light" {
                let s = draw(&view, Vec3::ZERO, None, 0.99).unwrap();
                assert_eq!((s.light, s.pmf), (LightId::Emitter(0), 1.0));
            }
        }
    }
}

/// All lights dark and no unbounded light: nothing to choose, every pmf 0.
#[test]
fn a_dark_scene_chooses_nothing() {
    let lights = vec![Emitter::point(Vec3::ONE, 0.0); 4];
    let tree = LightTree::build(&lights, BuildHeuristic::default()).unwrap();
    let scene = Aabb::new(Vec3::splat(-10.0), Vec3::splat(10.0));
    let glt = Glt::new(&tree, scene, GltConfig::default()).unwrap();
    let snapshot = glt.snapshot().unwrap();
    let view = snapshot.view();
    assert_eq!(draw(&view, Vec3::ZERO, Some(Vec3::Y), 0.5), None);
    for e in 0..4 {
        assert_eq!(pmf(&view, Vec3::ZERO, None, LightId::Emitter(e)), 0.0);
    }
}

/// A million lights: the snapshot is built, is about 88 bytes per light
/// (tree, bounds, leaf order), and its pmf sums to 1.
#[test]
fn a_million_lights() {
    let lights = mixed_scene(1_000_000, 5);
    let tree = LightTree::build(&lights, BuildHeuristic::default()).unwrap();
    let scene = Aabb::new(Vec3::splat(-60.0), Vec3::splat(60.0));
    let glt = Glt::new(&tree, scene, GltConfig::default()).unwrap();
    let snapshot = glt.snapshot().unwrap();
    let per_light = snapshot.bytes() as f64 / 1e6;
    assert!(
        (88.0..89.0).contains(&per_light),
        "{per_light} bytes per light"
    );
    let view = snapshot.view();
    let mut r = Rand::new(2);
    check_distribution(
        &view,
        &ShadingContext::on_surface(r.point(40.0), r.dir()),
        1_000_000,
        0,
        &mut r,
    );
}

/// The snapshot's arrays as owned words, to corrupt.
struct Owned {
    words: [Vec<u32>; 10],
}

impl Owned {
    fn new(a: &SnapshotArrays) -> Self {
        let w = |s: &[u32]| s.to_vec();
        Self {
            words: [
                w(bytemuck::cast_slice(core::slice::from_ref(a.header))),
                w(a.spatial),
                w(bytemuck::cast_slice(a.cells)),
                w(bytemuck::cast_slice(a.cut_nodes)),
                w(bytemuck::cast_slice(a.fractions)),
                w(bytemuck::cast_slice(a.visibility)),
                w(bytemuck::cast_slice(a.tree)),
                w(a.first_right),
                w(bytemuck::cast_slice(a.bounds)),
                w(a.leaf_position),
            ],
        }
    }

    fn arrays(&self) -> Option<SnapshotArrays<'_>> {
        let [h, s, c, n, f, v, t, r, b, l] = &self.words;
        Some(SnapshotArrays {
            header: bytemuck::try_from_bytes(bytemuck::cast_slice(h)).ok()?,
            spatial: s,
            cells: bytemuck::try_cast_slice(c).ok()?,
            cut_nodes: bytemuck::try_cast_slice(n).ok()?,
            fractions: bytemuck::cast_slice(f),
            visibility: bytemuck::cast_slice(v),
            tree: bytemuck::try_cast_slice(t).ok()?,
            first_right: r,
            bounds: bytemuck::try_cast_slice(b).ok()?,
            leaf_position: l,
        })
    }
}

/// The snapshot of a small trained GLT with unbounded lights and
/// visibility.
fn small_snapshot() -> guiding::snapshot::Snapshot {
    let (_, glt) = trained(40, rule_sets()[0].1, 9);
    glt.snapshot().unwrap()
}

/// Plainly broken arrays get the error that names what is wrong.
#[test]
fn broken_arrays_are_named() {
    let snapshot = small_snapshot();
    let good = Owned::new(&snapshot.arrays());
    assert!(SnapshotView::new(good.arrays().unwrap()).is_ok());
    let broken = |array: usize, f: &dyn Fn(&mut Vec<u32>)| {
        let mut o = Owned::new(&snapshot.arrays());
        f(&mut o.words[array]);
        SnapshotView::new(o.arrays().unwrap()).err()
    };
    assert_eq!(broken(0, &|h| h[0] ^= 1), Some(SnapshotError::Magic));
    assert_eq!(broken(0, &|h| h[1] = 3), Some(SnapshotError::Version(3)));
    assert_eq!(
        broken(1, &|s| s[0] = 0),
        Some(SnapshotError::Invalid("spatial"))
    );
    assert_eq!(
        broken(1, &|s| {
            s.pop();
        }),
        Some(SnapshotError::Invalid("spatial"))
    );
    // A tree link pointing back at the root's pair: a walk would loop.
    assert_eq!(
        broken(6, &|t| t[5] = 0),
        Some(SnapshotError::Invalid("tree"))
    );
    assert_eq!(
        broken(6, &|t| t[4] = f32::to_bits(0.7)),
        Some(SnapshotError::Invalid("tree"))
    );
    assert_eq!(
        broken(7, &|r| {
            r.pop();
        }),
        Some(SnapshotError::Invalid("first right"))
    );
    assert_eq!(
        broken(2, &|c| c[7] = f32::to_bits(f32::NAN)),
        Some(SnapshotError::Invalid("cells"))
    );
    assert_eq!(
        broken(4, &|f| f[0] = f32::to_bits(-1.0)),
        Some(SnapshotError::Invalid("fractions"))
    );
    assert_eq!(
        broken(8, &|b| b[0] = f32::to_bits(f32::INFINITY)),
        Some(SnapshotError::Invalid("bounds"))
    );
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    /// Any corruption of the arrays (a few words set to anything) is
    /// refused, or sampled without panic, loop or NaN: every answer a pmf
    /// in [0, 1].
    #[test]
    fn corrupted_arrays_never_panic(
        edits in prop::collection::vec((0usize..10, any::<prop::sample::Index>(), any::<u32>()), 1..4),
        seed in 0u64..100,
    ) {
        let snapshot = small_snapshot();
        let mut o = Owned::new(&snapshot.arrays());
        for (array, at, value) in edits {
            let words = &mut o.words[array];
            if !words.is_empty() {
                let i = at.index(words.len());
                words[i] = value;
            }
        }
        let Some(arrays) = o.arrays() else { return Ok(()); };
        let Ok(view) = SnapshotView::new(arrays) else { return Ok(()); };
        let mut r = Rand::new(seed);
        for _ in 0..20 {
            let (p, n) = (r.point(70.0), r.dir());
            if let Some(s) = draw(&view, p, Some(n), r.f()) {
                prop_assert!(s.pmf > 0.0 && s.pmf <= 1.0001, "{s:?}");
            }
            for e in 0..45 {
                let light = if e < 40 { LightId::Emitter(e) } else { LightId::Unbounded(e - 40) };
                let pmf = pmf(&view, p, Some(n), light);
                prop_assert!((0.0..=1.0001).contains(&pmf), "{pmf}");
            }
        }
    }
}

/// One number per descent stays exact in distribution 100 levels deep in
/// `f32` too: a chain (leaf `k` at depth `k + 1`) whose learned cut covers
/// the first 70 levels; chi-square of 200,000 draws over the 100 leaves
/// against the snapshot's pmf, and the two deepest leaves are drawn.
#[test]
fn a_deep_chain_is_sampled_in_distribution() {
    let chain = Chain::deep();
    let n = chain.n();
    let scene = Aabb::new(Vec3::splat(-1.0), Vec3::splat(1.0));
    for cut in [
        CutConfig::default(),
        CutConfig::default().with_paper_rules(),
    ] {
        let config = GltConfig {
            cut: CutConfig {
                min_records: 0,
                ..cut
            },
            ..GltConfig::default()
        };
        let mut glt = Glt::new(&chain, scene, config).unwrap();
        let p = Vec3::new(0.5, 0.0, 0.0);
        for _ in 0..16 {
            for k in 0..n {
                glt.record_light_at(p, LightId::Emitter(k), Chain::deep_target(k));
            }
            glt.refine();
        }
        let snapshot = glt.snapshot().unwrap();
        let view = snapshot.view();
        let pmf: Vec<f64> = (0..n)
            .map(|k| f64::from(pmf(&view, p, None, LightId::Emitter(k))))
            .collect();
        assert!((pmf.iter().sum::<f64>() - 1.0).abs() < 1e-5);
        assert!(pmf[99] > 1e-4, "{}", pmf[99]);
        let mut counts = vec![0u64; n as usize];
        let mut r = Rand::new(99);
        for _ in 0..200_000 {
            let s = draw(&view, p, None, r.f()).unwrap();
            let LightId::Emitter(e) = s.light else {
                panic!()
            };
            counts[e as usize] += 1;
        }
        let (z, _) = chi_square_z(&counts, &pmf).unwrap();
        assert!(z < common::Z_P_1E4, "z = {z}");
        assert!(counts[99] > 0 && counts[98] > 0);
    }
}

/// A guiding field's snapshot chooses as the field's light vertex does
/// (the field keeps its cuts in the same spatial tree as its quadtrees).
#[test]
fn a_fields_snapshot_chooses_as_the_field() {
    use guiding::{FieldConfig, GuidingField};
    let lights = mixed_scene(2000, 13);
    let tree = LightTree::build(&lights, BuildHeuristic::default()).unwrap();
    let scene = Aabb::new(Vec3::splat(-60.0), Vec3::splat(60.0));
    let mut field = GuidingField::new(&tree, scene, FieldConfig::default()).unwrap();
    let mut r = Rand::new(14);
    for _ in 0..3 {
        for _ in 0..20_000 {
            let ctx = ShadingContext::on_surface(r.point(55.0), r.dir());
            let Some(v) = field.vertex(&ctx) else {
                continue;
            };
            let Some(s) = v.light.sample(r.f()) else {
                continue;
            };
            if let LightId::Emitter(e) = s.light {
                let value = contribution(&lights[e as usize], ctx.position) / f64::from(s.pmf);
                v.light.record_light(s.light, value as f32);
            }
        }
        field.refine();
    }
    let snapshot = field.snapshot().unwrap();
    let view = snapshot.view();
    let (mut same, mut worst, queries) = (0usize, 0f64, 50_000);
    for _ in 0..queries {
        let ctx = ShadingContext::on_surface(r.point(58.0), r.dir());
        let u = r.f();
        let cpu = field.vertex(&ctx).and_then(|v| v.light.sample(u));
        let snap = draw(&view, ctx.position, ctx.normal, u);
        match (cpu, snap) {
            (Some(c), Some(s)) if c.light == s.light => {
                same += 1;
                worst = worst.max(relative(s.pmf, f64::from(c.pmf)));
            }
            (None, None) => same += 1,
            _ => {}
        }
    }
    assert!(
        same as f64 >= 0.9995 * queries as f64,
        "{same} of {queries}"
    );
    assert!(worst <= 2e-6, "{worst}");
}

/// The snapshot's estimate of the direct light (contribution over pmf)
/// is unbiased: its mean over 400,000 draws at each of four points is the
/// exact sum over every light within four standard errors.
#[test]
fn the_snapshots_estimates_are_unbiased() {
    let (lights, glt) = trained(500, CutConfig::default(), 17);
    let snapshot = glt.snapshot().unwrap();
    let view = snapshot.view();
    let mut r = Rand::new(18);
    for _ in 0..4 {
        let ctx = ShadingContext::on_surface(r.point(50.0), r.dir());
        let exact: f64 = lights.iter().map(|e| contribution(e, ctx.position)).sum();
        let draws = 400_000;
        let (mut sum, mut sum2) = (0.0f64, 0.0f64);
        for _ in 0..draws {
            let s = draw(&view, ctx.position, ctx.normal, r.f()).unwrap();
            let LightId::Emitter(e) = s.light else {
                panic!("no unbounded light")
            };
            let x = contribution(&lights[e as usize], ctx.position) / f64::from(s.pmf);
            sum += x;
            sum2 += x * x;
        }
        let mean = sum / draws as f64;
        let se = ((sum2 / draws as f64 - mean * mean) / draws as f64).sqrt();
        assert!(
            (mean - exact).abs() <= 4.0 * se,
            "mean {mean}, exact {exact}, se {se}"
        );
    }
}

/// `Debug` names the header and the arrays' lengths, not every entry.
#[test]
fn debug_prints_a_summary() {
    let snapshot = small_snapshot();
    let text = format!("{:?} {:?}", snapshot, snapshot.view());
    assert!(
        text.contains("magic") && text.contains("cut_nodes"),
        "{text}"
    );
    assert!(text.len() < 2000, "{} bytes of Debug", text.len());
}

/// The number's edges, as every sampler's (`tests/edge_semantics.rs`):
/// below 0 and NaN count as 0, 1 and above as the largest `f32` below 1;
/// `u = 0` never takes a side of probability 0 (a dark light on the
/// left), nor does the largest number (a dark light on the right).
#[test]
fn the_numbers_edges() {
    let below_one = 1.0 - f32::EPSILON / 2.0;
    let scene = Aabb::new(Vec3::splat(-10.0), Vec3::splat(10.0));
    // Two leaves under the root, the dark one left, then right.
    for dark in [0u32, 1] {
        let tree = Chain::new(if dark == 0 {
            vec![0.0, 1.0]
        } else {
            vec![1.0, 0.0]
        });
        for rules in [
            CutConfig::default(),
            CutConfig::default().with_paper_rules(),
        ] {
            let config = GltConfig {
                cut: rules,
                ..GltConfig::default()
            };
            let glt = Glt::new(&tree, scene, config).unwrap();
            let snapshot = glt.snapshot().unwrap();
            let view = snapshot.view();
            let p = Vec3::new(0.0, 2.0, 0.0);
            let at = |u: f32| draw(&view, p, Some(Vec3::Y), u);
            for u in [f32::NAN, -1.0, -0.0, f32::NEG_INFINITY] {
                assert_eq!(at(u), at(0.0), "u = {u}");
            }
            for u in [1.0, 7.5, f32::INFINITY] {
                assert_eq!(at(u), at(below_one), "u = {u}");
            }
            // The dark light is on the side the extreme number walks to.
            let extreme = if dark == 0 { 0.0 } else { below_one };
            let s = at(extreme).expect("the lit light");
            assert_eq!(
                (s.light, s.pmf),
                (LightId::Emitter(1 - dark), 1.0),
                "u = {extreme}"
            );
        }
    }
}
