//! The baseline light samplers: pmf sums, sample/pmf agreement, goodness of
//! fit, exactness of the one-number descent in deep trees, pbrt-v4's
//! importance checks, and the hard cases.

mod common;

use common::{Z_P_1E4, chi_square_z};
use glam::Vec3;
use guiding::light_sampler::{
    ImportanceTreeSampler, PowerSampler, PowerTreeSampler, UnboundedLights, UniformSampler,
    WithUnbounded, importance,
};
use guiding::light_tree::{BuildHeuristic, LightHierarchy, NodeBounds};
use guiding::math::{Aabb, LightCone};
use guiding::{Emitter, LightId, LightSample, LightSampler, LightTree, ShadingContext};
use proptest::prelude::*;
use rand_pcg::Pcg64;
use rand_pcg::rand_core::{Rng, SeedableRng};

// ---------------------------------------------------------------------------
// Random numbers and scenes
// ---------------------------------------------------------------------------

/// A uniform `f64` in `[0, 1)` with 53 random bits.
fn u01(rng: &mut Pcg64) -> f64 {
    (rng.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
}

/// A uniform `f32` drawn at `f64` resolution (fine near 0, where deep
/// leaves live); may round to 1.0, which the samplers clamp.
fn uf32(rng: &mut Pcg64) -> f32 {
    u01(rng) as f32
}

fn range(rng: &mut Pcg64, lo: f32, hi: f32) -> f32 {
    lo + (hi - lo) * u01(rng) as f32
}

fn unit_vector(rng: &mut Pcg64) -> Vec3 {
    let z = range(rng, -1.0, 1.0);
    let phi = range(rng, 0.0, std::f32::consts::TAU);
    let r = (1.0 - z * z).max(0.0).sqrt();
    Vec3::new(r * phi.cos(), r * phi.sin(), z)
}

fn point_in(rng: &mut Pcg64, half: f32) -> Vec3 {
    Vec3::new(
        range(rng, -half, half),
        range(rng, -half, half),
        range(rng, -half, half),
    )
}

/// How a random scene is drawn.
#[derive(Clone, Copy, Debug)]
struct SceneSpec {
    count: usize,
    seed: u64,
    /// Fraction of emitters with zero power.
    zero_fraction: f64,
    /// Put every emitter on one of three shared positions.
    coincident: bool,
}

/// A random mix of point, spot, sphere, one- and two-sided area and
/// random-cone emitters (some with zero-size boxes), with powers
/// log-uniform in 1e-20..1e20.
fn random_emitters(spec: SceneSpec) -> Vec<Emitter> {
    let mut rng = Pcg64::seed_from_u64(spec.seed);
    let shared = [
        Vec3::ZERO,
        Vec3::new(3.0, -1.0, 2.0),
        Vec3::new(-5.0, 4.0, 0.5),
    ];
    (0..spec.count)
        .map(|_| {
            let p = if spec.coincident {
                shared[(rng.next_u32() % 3) as usize]
            } else {
                point_in(&mut rng, 10.0)
            };
            let power = if u01(&mut rng) < spec.zero_fraction {
                0.0
            } else {
                10f32.powf(range(&mut rng, -20.0, 20.0))
            };
            let size = if rng.next_u32() % 4 == 0 {
                0.0
            } else {
                range(&mut rng, 0.0, 1.5)
            };
            let axis = unit_vector(&mut rng);
            match rng.next_u32() % 6 {
                0 => Emitter::point(p, power),
                1 => Emitter::sphere(p, size, power),
                2 => {
                    // A flat box across the normal's dominant axis.
                    let mut ext = Vec3::splat(size);
                    ext[axis.abs().max_position()] = 0.0;
                    Emitter::area(Aabb::new(p - ext, p + ext), axis, 4.0 * size * size, power)
                }
                3 => Emitter {
                    cone: Some(LightCone::spot(axis, range(&mut rng, 0.01, 3.1))),
                    ..Emitter::point(p, power)
                },
                4 => Emitter {
                    cone: Some(LightCone::new(
                        axis,
                        range(&mut rng, 0.0, std::f32::consts::PI),
                        range(&mut rng, 0.0, std::f32::consts::PI),
                    )),
                    two_sided: rng.next_u32() % 2 == 0,
                    ..Emitter::sphere(p, size, power)
                },
                _ => Emitter {
                    two_sided: true,
                    ..Emitter::area(
                        Aabb::new(p, p + Vec3::new(size, size, 0.0)),
                        axis,
                        size * size,
                        power,
                    )
                },
            }
        })
        .collect()
}

/// Shading points: inside the scene, far outside, on an emitter, with and
/// without normals.
fn shading_points(rng: &mut Pcg64, emitters: &[Emitter], count: usize) -> Vec<ShadingContext> {
    (0..count)
        .map(|i| {
            let position = match i % 4 {
                0 => point_in(rng, 12.0),
                1 => point_in(rng, 1e4),
                2 if !emitters.is_empty() => emitters[(rng.next_u32() as usize) % emitters.len()]
                    .bounds
                    .center(),
                _ => point_in(rng, 30.0),
            };
            if i % 2 == 0 {
                ShadingContext::on_surface(position, unit_vector(rng))
            } else {
                ShadingContext::at(position)
            }
        })
        .collect()
}

fn heuristic(i: usize) -> BuildHeuristic {
    [
        BuildHeuristic::Sarh,
        BuildHeuristic::Balanced,
        BuildHeuristic::Sah,
        BuildHeuristic::Saoh,
    ][i % 4]
}

type Dyn<'a> = Box<dyn LightSampler + Sync + 'a>;

/// Every baseline sampler over the same emitters.
fn all_samplers<'a>(
    emitters: &'a [Emitter],
    tree: &'a LightTree,
    unbounded: UnboundedLights,
) -> Vec<(&'static str, Dyn<'a>)> {
    vec![
        ("uniform", Box::new(UniformSampler::new(emitters.len()))),
        ("power", Box::new(PowerSampler::new(emitters))),
        ("power tree", Box::new(PowerTreeSampler::new(tree))),
        (
            "importance tree",
            Box::new(ImportanceTreeSampler::new(tree)),
        ),
        (
            "unbounded + importance tree",
            Box::new(WithUnbounded::new(ImportanceTreeSampler::new(tree), unbounded).unwrap()),
        ),
        (
            "unbounded + power",
            Box::new(WithUnbounded::new(PowerSampler::new(emitters), unbounded).unwrap()),
        ),
    ]
}

/// The most unbounded lights the tests give a sampler.
const UNBOUNDED: usize = 3;

/// A sun and a sky sharing probability `p`.
fn sun_and_sky(p: f64) -> UnboundedLights {
    UnboundedLights::new(2, p).unwrap()
}

/// Every light id a sampler over `n` emitters (and up to [`UNBOUNDED`]
/// unbounded lights) can return, unbounded lights last.
fn lights(n: usize) -> impl Iterator<Item = LightId> {
    (0..n as u32)
        .map(LightId::Emitter)
        .chain((0..UNBOUNDED as u32).map(LightId::Unbounded))
}

fn index(light: LightId, n: usize) -> usize {
    match light {
        LightId::Emitter(i) => i as usize,
        LightId::Unbounded(i) => n + i as usize,
    }
}

// ---------------------------------------------------------------------------
// The contract, checked for one sampler at one point
// ---------------------------------------------------------------------------

/// The pmf sums to 1 (0 when empty), is never NaN or negative, is 0 out of
/// range, and every sample's pmf equals `pmf()` exactly.
fn check_contract(
    name: &str,
    s: &dyn LightSampler,
    n: usize,
    ctx: &ShadingContext,
    us: &[f32],
) -> Result<(), TestCaseError> {
    check_contract_with(name, s, n, ctx, us, &edge_us())
}

/// [`check_contract`] with random `us`, which must all give a light when
/// the sampler is not empty, and `edges`, which may give `None`: an end of
/// `[0, 1)` can fall on a leaf whose pmf underflows `f32`, and that draw is
/// refused (consistently with its pmf of 0).
fn check_contract_with(
    name: &str,
    s: &dyn LightSampler,
    n: usize,
    ctx: &ShadingContext,
    us: &[f32],
    edges: &[f32],
) -> Result<(), TestCaseError> {
    let mut sum = 0.0f64;
    for light in lights(n) {
        let p = s.pmf(ctx, light);
        prop_assert!((0.0..=1.0).contains(&p), "{name}: pmf({light:?}) = {p}");
        sum += p as f64;
    }
    for id in [n as u32, n as u32 + 1, u32::MAX] {
        prop_assert_eq!(s.pmf(ctx, LightId::Emitter(id)), 0.0, "{} id {}", name, id);
    }
    // Nothing is chosen at a non-finite position (tests/edge_semantics.rs).
    let chooses = !s.is_empty() && ctx.is_finite();
    if !chooses {
        prop_assert_eq!(
            sum,
            0.0,
            "{} chooses nothing but its pmf sums to {}",
            name,
            sum
        );
    } else {
        prop_assert!(
            (sum - 1.0).abs() < 1e-5,
            "{name}: pmf sums to {sum} at {ctx:?}"
        );
    }
    for (k, &u) in us.iter().chain(edges).enumerate() {
        match s.sample(ctx, u) {
            Some(x) => {
                prop_assert!(x.pmf > 0.0, "{name}: sampled pmf {}", x.pmf);
                prop_assert!(index(x.light, n) < n + UNBOUNDED, "{name}: {:?}", x.light);
                let p = s.pmf(ctx, x.light);
                prop_assert_eq!(x.pmf, p, "{}: u {} chose {:?}", name, u, x.light);
            }
            None => prop_assert!(
                !chooses || k >= us.len(),
                "{name}: non-empty sampler refused u {u}"
            ),
        }
    }
    Ok(())
}

fn edge_us() -> Vec<f32> {
    vec![
        0.0,
        -0.0,
        1.0,
        f32::from_bits(1.0f32.to_bits() - 1),
        f32::MIN_POSITIVE,
        f32::from_bits(1),
        2.0,
        -1.0,
        f32::NAN,
        f32::INFINITY,
        f32::NEG_INFINITY,
    ]
}

fn check_scene(
    spec: SceneSpec,
    h: BuildHeuristic,
    unbounded: UnboundedLights,
    points: usize,
) -> Result<(), TestCaseError> {
    let emitters = random_emitters(spec);
    let tree = LightTree::build(&emitters, h).expect("valid emitters");
    let mut rng = Pcg64::seed_from_u64(spec.seed ^ 0x5eed);
    let ctxs = shading_points(&mut rng, &emitters, points);
    let us: Vec<f32> = (0..64).map(|_| uf32(&mut rng)).collect();
    for (name, s) in all_samplers(&emitters, &tree, unbounded) {
        for ctx in &ctxs {
            check_contract(name, &s, emitters.len(), ctx, &us)?;
        }
    }
    Ok(())
}

fn scene_spec() -> impl Strategy<Value = SceneSpec> {
    (
        1usize..2000,
        any::<u64>(),
        prop_oneof![Just(0.0), 0.0f64..0.5, Just(1.0)],
        proptest::bool::weighted(0.2),
    )
        .prop_map(|(count, seed, zero_fraction, coincident)| SceneSpec {
            count,
            seed,
            zero_fraction,
            coincident,
        })
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 160, ..ProptestConfig::default() })]

    /// Random scenes, every sampler: sums to 1, sample == pmf exactly.
    #[test]
    fn pmf_sums_to_one_and_matches_sample(
        spec in scene_spec(),
        h in 0usize..4,
        k in 0..=UNBOUNDED as u32,
        p in prop_oneof![Just(1e-6f64), 1e-6f64..1.0, Just(1.0 - 1e-6)],
    ) {
        let probability = if k == 0 { 0.0 } else { p };
        let unbounded = UnboundedLights::new(k, probability).unwrap();
        check_scene(spec, heuristic(h), unbounded, 4)?;
    }

    /// Small scenes, many of them: the corner cases of tiny trees.
    #[test]
    fn small_scenes(
        count in 1usize..8,
        seed in any::<u64>(),
        zero_fraction in prop_oneof![Just(0.0), Just(0.5), Just(1.0)],
        coincident in any::<bool>(),
        h in 0usize..4,
    ) {
        let spec = SceneSpec { count, seed, zero_fraction, coincident };
        check_scene(spec, heuristic(h), sun_and_sky(0.25), 8)?;
    }

    /// The power-tree descent is exactly the inverse CDF of the leaves, in
    /// tree order, and its pmf is exactly the product of the f64 child
    /// probabilities.
    #[test]
    fn power_tree_is_the_inverse_cdf(spec in scene_spec(), h in 0usize..4) {
        let spec = SceneSpec { count: spec.count.min(500), ..spec };
        let emitters = random_emitters(spec);
        let tree = LightTree::build(&emitters, heuristic(h)).unwrap();
        let s = PowerTreeSampler::new(&tree);
        let ctx = ShadingContext::at(Vec3::ONE);
        check_inverse_cdf(&s, &ctx, &power_intervals(&tree));
    }
}

#[test]
fn ten_thousand_emitters() {
    let spec = SceneSpec {
        count: 10_000,
        seed: 10_000,
        zero_fraction: 0.1,
        coincident: false,
    };
    check_scene(spec, BuildHeuristic::Sarh, sun_and_sky(0.1), 4).unwrap();
}

// ---------------------------------------------------------------------------
// Chi-square goodness of fit
// ---------------------------------------------------------------------------

fn assert_fits(what: &str, observed: &[u64], probs: &[f64]) {
    let Some((z, dof)) = chi_square_z(observed, probs) else {
        panic!("{what}: a light with pmf 0 was sampled");
    };
    assert!(z < Z_P_1E4, "{what}: z = {z:.2} with {dof} dof (p < 1e-4)");
}

/// Draws `draws` samples at `ctx` and tests them against `pmf`.
fn fit(what: &str, s: &dyn LightSampler, n: usize, ctx: &ShadingContext, draws: usize, seed: u64) {
    let mut rng = Pcg64::seed_from_u64(seed);
    let mut counts = vec![0u64; n + UNBOUNDED];
    for _ in 0..draws {
        let x = s.sample(ctx, uf32(&mut rng)).expect("non-empty sampler");
        counts[index(x.light, n)] += 1;
    }
    let probs: Vec<f64> = lights(n).map(|l| s.pmf(ctx, l) as f64).collect();
    assert_fits(what, &counts, &probs);
}

/// A scene where every sampler has a spread-out distribution.
fn fit_scene(count: usize, seed: u64) -> Vec<Emitter> {
    let mut rng = Pcg64::seed_from_u64(seed);
    (0..count)
        .map(|i| {
            let p = point_in(&mut rng, 4.0);
            let power = 10f32.powf(range(&mut rng, -2.0, 2.0));
            let n = unit_vector(&mut rng);
            match i % 4 {
                0 => Emitter::point(p, power),
                1 => Emitter::sphere(p, 0.2, power),
                2 => Emitter::area(
                    Aabb::new(p, p + Vec3::new(0.3, 0.3, 0.0)),
                    Vec3::Z,
                    0.09,
                    power,
                ),
                _ => Emitter {
                    cone: Some(LightCone::spot(n, 1.2)),
                    ..Emitter::point(p, power)
                },
            }
        })
        .collect()
}

#[test]
fn chi_square_every_sampler() {
    let emitters = fit_scene(64, 3);
    let tree = LightTree::build(&emitters, BuildHeuristic::Sarh).unwrap();
    let ctxs = [
        ShadingContext::on_surface(Vec3::new(0.5, -4.5, 0.0), Vec3::Y),
        ShadingContext::at(Vec3::new(1.0, 1.0, 1.0)),
        ShadingContext::on_surface(Vec3::new(30.0, 0.0, 2.0), -Vec3::X),
    ];
    for (i, ctx) in ctxs.iter().enumerate() {
        for (j, (name, s)) in all_samplers(&emitters, &tree, sun_and_sky(0.2))
            .into_iter()
            .enumerate()
        {
            let what = format!("{name} at point {i}");
            fit(&what, &s, emitters.len(), ctx, 200_000, (i * 16 + j) as u64);
        }
    }
}

/// Samplers that learn nothing report every light fully visible (the
/// resampling target's factor is then 1), alone and with their sample.
#[test]
fn samplers_that_learn_nothing_see_everything() {
    let emitters = fit_scene(64, 3);
    let tree = LightTree::build(&emitters, BuildHeuristic::Sarh).unwrap();
    let ctx = ShadingContext::on_surface(Vec3::new(0.5, -4.5, 0.0), Vec3::Y);
    for (name, s) in all_samplers(&emitters, &tree, sun_and_sky(0.2)) {
        for l in lights(emitters.len()) {
            assert_eq!(s.visibility(&ctx, l), 1.0, "{name}: {l:?}");
        }
        for k in 0..100 {
            let u = k as f32 / 100.0;
            let with = s.sample_with_visibility(&ctx, u);
            assert_eq!(with, s.sample(&ctx, u).map(|x| (x, 1.0)), "{name}");
        }
    }
}

/// The test above can fail: a distribution 10% off on one light is
/// rejected.
#[test]
fn chi_square_rejects_a_wrong_pmf() {
    let emitters = fit_scene(64, 3);
    let s = PowerSampler::new(&emitters[..]);
    let ctx = ShadingContext::at(Vec3::ZERO);
    let n = emitters.len();
    let mut rng = Pcg64::seed_from_u64(99);
    let mut counts = vec![0u64; n + UNBOUNDED];
    for _ in 0..200_000 {
        counts[index(s.sample(&ctx, uf32(&mut rng)).unwrap().light, n)] += 1;
    }
    let mut probs: Vec<f64> = lights(n).map(|l| s.pmf(&ctx, l) as f64).collect();
    assert!(chi_square_z(&counts, &probs).unwrap().0 < Z_P_1E4);
    let big = (0..n)
        .max_by(|&a, &b| probs[a].total_cmp(&probs[b]))
        .unwrap();
    probs[big] *= 1.1;
    let total: f64 = probs.iter().sum();
    probs.iter_mut().for_each(|p| *p /= total);
    assert!(chi_square_z(&counts, &probs).unwrap().0 > Z_P_1E4);
    // Sampling a light whose pmf is 0 is always a failure.
    probs[big] = 0.0;
    assert!(chi_square_z(&counts, &probs).is_none());
}

// ---------------------------------------------------------------------------
// Exactness in depth
// ---------------------------------------------------------------------------

/// A chain hierarchy of `n` leaves and depth `n - 1`: inner node `k` has
/// children (the rest of the chain, leaf `k`) — or, when `zigzag`, the sides
/// alternate so the walk turns right every other level. All lights sit at
/// the origin and are omnidirectional, so at (1, 0, 0) importance equals
/// power exactly.
struct Chain {
    children: Vec<Option<[u32; 2]>>,
    parent: Vec<Option<u32>>,
    power: Vec<f32>,
    emitter: Vec<Option<u32>>,
    leaf_of: Vec<u32>,
}

impl Chain {
    fn new(leaf_power: &[f32], zigzag: bool) -> Self {
        let n = leaf_power.len();
        assert!(n >= 2);
        let inner = n - 1;
        let total = inner + n;
        let leaf = |k: usize| (inner + k) as u32;
        let mut c = Chain {
            children: vec![None; total],
            parent: vec![None; total],
            power: vec![0.0; total],
            emitter: vec![None; total],
            leaf_of: (0..n).map(leaf).collect(),
        };
        for (k, &e) in leaf_power.iter().enumerate() {
            c.emitter[leaf(k) as usize] = Some(k as u32);
            c.power[leaf(k) as usize] = e;
        }
        for k in 0..inner {
            let deeper = if k + 1 < inner {
                (k + 1) as u32
            } else {
                leaf(n - 1)
            };
            let pair = if zigzag && k % 2 == 1 {
                [leaf(k), deeper]
            } else {
                [deeper, leaf(k)]
            };
            c.children[k] = Some(pair);
            c.parent[pair[0] as usize] = Some(k as u32);
            c.parent[pair[1] as usize] = Some(k as u32);
        }
        let mut below = leaf_power[n - 1] as f64;
        for k in (0..inner).rev() {
            below += leaf_power[k] as f64;
            c.power[k] = below as f32;
        }
        c
    }
}

impl LightHierarchy for Chain {
    fn root(&self) -> Option<u32> {
        Some(0)
    }
    fn children(&self, node: u32) -> Option<[u32; 2]> {
        *self.children.get(node as usize)?
    }
    fn parent(&self, node: u32) -> Option<u32> {
        *self.parent.get(node as usize)?
    }
    fn power(&self, node: u32) -> f32 {
        self.power.get(node as usize).copied().unwrap_or(0.0)
    }
    fn node_bounds(&self, node: u32) -> NodeBounds {
        NodeBounds {
            bounds: Aabb::from_point(Vec3::ZERO),
            cone: LightCone::SPHERE,
            two_sided: false,
            power: self.power(node),
        }
    }
    fn emitter(&self, node: u32) -> Option<u32> {
        *self.emitter.get(node as usize)?
    }
    fn leaf(&self, emitter: u32) -> Option<u32> {
        self.leaf_of.get(emitter as usize).copied()
    }
    fn node_count(&self) -> usize {
        self.children.len()
    }
    fn emitter_count(&self) -> usize {
        self.leaf_of.len()
    }
}

/// (emitter, C, p) of every leaf in the descent's left-to-right order, with
/// p multiplied root-down exactly as the descent does (`w / (wl + wr)` in
/// f64 from the `f32` subtree powers) and C the running sum of the p's.
fn power_intervals<H: LightHierarchy>(t: &H) -> Vec<(u32, f64, f64)> {
    let mut out = Vec::new();
    let Some(root) = t.root() else {
        return out;
    };
    let mut c = 0.0;
    let mut stack = vec![(root, if t.power(root) > 0.0 { 1.0 } else { 0.0 })];
    while let Some((node, p)) = stack.pop() {
        match t.children(node) {
            None => {
                out.push((t.emitter(node).unwrap(), c, p));
                c += p;
            }
            Some([l, r]) => {
                let (wl, wr) = (t.power(l) as f64, t.power(r) as f64);
                let total = wl + wr;
                let (pl, pr) = if total > 0.0 {
                    (wl / total, wr / total)
                } else {
                    (0.0, 0.0)
                };
                stack.push((r, p * pr));
                stack.push((l, p * pl));
            }
        }
    }
    out
}

fn next_up(x: f32) -> f32 {
    if x <= 0.0 {
        f32::from_bits(1)
    } else {
        f32::from_bits(x.to_bits() + 1)
    }
}

fn next_down(x: f32) -> f32 {
    if x <= f32::from_bits(1) {
        0.0
    } else {
        f32::from_bits(x.to_bits() - 1)
    }
}

/// For every leaf, its pmf is exactly the f64 product converted to f32, and
/// wherever an `f32` u lies strictly inside its CDF interval (beyond the
/// ~1e-13 relative rounding of the f64 rescaling), `sample` picks it: the
/// lowest, middle and highest such `u` are tried. Returns how many leaves
/// were checked and the smallest pmf among them.
fn check_inverse_cdf(
    s: &dyn LightSampler,
    ctx: &ShadingContext,
    intervals: &[(u32, f64, f64)],
) -> (usize, f64) {
    let mut checked = 0;
    let mut smallest = f64::INFINITY;
    for &(e, c, p) in intervals {
        let light = LightId::Emitter(e);
        let expect = match p as f32 {
            q if q > 0.0 && q.is_finite() => q,
            _ => 0.0,
        };
        assert_eq!(s.pmf(ctx, light), expect, "pmf of emitter {e}");
        let margin = 1e-13 * (c + p);
        let (lo, hi) = (c + margin, c + p - margin);
        if hi <= lo || expect == 0.0 {
            continue;
        }
        let first = {
            let u = lo as f32;
            if u as f64 <= lo { next_up(u) } else { u }
        };
        let last = {
            let u = hi as f32;
            if u as f64 >= hi { next_down(u) } else { u }
        };
        let mid = (c + 0.5 * p) as f32;
        let mut any = false;
        for u in [first, mid, last] {
            if (u as f64) > lo && (u as f64) < hi && u < 1.0 {
                let x = s.sample(ctx, u).expect("leaf with positive pmf");
                assert_eq!(
                    x.light,
                    light,
                    "u = {u:e} in [{c:e}, {:e}) chose {:?}",
                    c + p,
                    x.light
                );
                assert_eq!(x.pmf, expect);
                any = true;
            }
        }
        if any {
            checked += 1;
            smallest = smallest.min(p);
        }
    }
    (checked, smallest)
}

/// Leaf powers 2^-k: leaf k has pmf ~2^-(k+1), down to ~4e-31 at depth 100.
fn halving_powers(n: usize) -> Vec<f32> {
    (0..n).map(|k| 2f32.powi(-(k as i32))).collect()
}

#[test]
fn deep_chain_is_the_exact_inverse_cdf() {
    let ctx = ShadingContext::at(Vec3::X);
    for zigzag in [false, true] {
        let chain = Chain::new(&halving_powers(101), zigzag);
        let intervals = power_intervals(&chain);
        assert_eq!(intervals.len(), 101);
        let samplers: [(&str, &dyn LightSampler); 2] = [
            ("power", &PowerTreeSampler::new(&chain)),
            ("importance", &ImportanceTreeSampler::new(&chain)),
        ];
        for (name, s) in samplers {
            let (checked, smallest) = check_inverse_cdf(s, &ctx, &intervals);
            if zigzag {
                // Deep leaves sit near u = 1/3: an f32 resolves ~24 levels.
                assert!(checked >= 20, "{name}: {checked}");
            } else {
                // Every leaf sits near u = 0, where an f32 resolves 1e-30.
                assert_eq!(checked, 101, "{name}");
                assert!(smallest < 1e-30, "{name}: {smallest:e}");
            }
        }
    }
}

/// Chi-square over the leaves in `intervals`, with u at f64 resolution scaled into
/// `[0, top)` (so the conditional distribution of the leaves inside is
/// tested).
fn deep_fit(what: &str, s: &dyn LightSampler, intervals: &[(u32, f64, f64)], top: f64, seed: u64) {
    let ctx = ShadingContext::at(Vec3::X);
    let n = intervals.len();
    let mut rng = Pcg64::seed_from_u64(seed);
    let mut counts = vec![0u64; n + UNBOUNDED];
    for _ in 0..400_000 {
        let u = (u01(&mut rng) * top) as f32;
        counts[index(s.sample(&ctx, u).unwrap().light, n)] += 1;
    }
    let mut probs = vec![0.0; n + UNBOUNDED];
    for &(e, c, p) in intervals {
        // The part of the leaf's interval inside [0, top), renormalised.
        probs[e as usize] = ((c + p).min(top) - c.min(top)) / top;
    }
    assert_fits(what, &counts, &probs);
}

#[test]
fn deep_chain_chi_square() {
    let chain = Chain::new(&halving_powers(101), false);
    let intervals = power_intervals(&chain);
    // [0, top) holds exactly the leaves at depth >= 60.
    let top: f64 = intervals
        .iter()
        .filter(|&&(e, _, _)| e >= 60)
        .map(|&(_, _, p)| p)
        .sum();
    assert!(top > 0.0 && top < 1e-17);
    let samplers: [(&str, &dyn LightSampler); 2] = [
        ("power", &PowerTreeSampler::new(&chain)),
        ("importance", &ImportanceTreeSampler::new(&chain)),
    ];
    for (i, (name, s)) in samplers.into_iter().enumerate() {
        deep_fit(
            &format!("{name}, all leaves"),
            s,
            &intervals,
            1.0,
            40 + i as u64,
        );
        deep_fit(
            &format!("{name}, depth >= 60"),
            s,
            &intervals,
            top,
            50 + i as u64,
        );
    }
}

/// Emitters at x = 2^-k with power 2^-k: the SARH light tree gets deeper
/// than 64 levels, with the faintest (deepest) leaves leftmost.
fn skewed_emitters(n: usize) -> Vec<Emitter> {
    (0..n as i32)
        .map(|k| {
            let s = 2f32.powi(-k);
            let x = s;
            let b = Aabb::new(
                Vec3::new(x, 0.0, 0.0),
                Vec3::new(x + 0.1 * s, 0.1 * s, 0.1 * s),
            );
            Emitter::area(b, Vec3::Z, 0.01 * s * s, s)
        })
        .collect()
}

#[test]
fn deep_light_tree_is_exact() {
    let emitters = skewed_emitters(100);
    let tree = LightTree::build(&emitters, BuildHeuristic::Sarh).unwrap();
    assert!(tree.depth() > 64, "depth {}", tree.depth());
    let intervals = power_intervals(&tree);
    let s = PowerTreeSampler::new(&tree);
    let ctx = ShadingContext::at(Vec3::X);
    let (checked, smallest) = check_inverse_cdf(&s, &ctx, &intervals);
    assert!(checked >= 40, "{checked}");
    assert!(smallest < 1e-15, "{smallest:e}");
    // Sorted by emitter for the chi-square's probability vector.
    deep_fit("power, skewed light tree", &s, &intervals, 1.0, 7);
    let imp = ImportanceTreeSampler::new(&tree);
    let ctxs = [
        ShadingContext::at(Vec3::X),
        ShadingContext::on_surface(Vec3::new(-0.3, 0.0, 0.2), Vec3::Z),
    ];
    for (i, ctx) in ctxs.iter().enumerate() {
        fit(
            &format!("importance, skewed tree, point {i}"),
            &imp,
            emitters.len(),
            ctx,
            200_000,
            70 + i as u64,
        );
    }
}

// ---------------------------------------------------------------------------
// pbrt-v4's importance checks
// ---------------------------------------------------------------------------

#[test]
fn far_away_importance_is_proportional_to_power() {
    let mut rng = Pcg64::seed_from_u64(11);
    let emitters: Vec<Emitter> = (0..300)
        .map(|i| {
            let p = point_in(&mut rng, 1.0);
            let power = 10f32.powf(range(&mut rng, -3.0, 3.0));
            if i % 2 == 0 {
                Emitter::point(p, power)
            } else {
                Emitter::sphere(p, 0.05, power)
            }
        })
        .collect();
    let total: f64 = emitters.iter().map(|e| e.power as f64).sum();
    for h in [BuildHeuristic::Sarh, BuildHeuristic::Saoh] {
        let tree = LightTree::build(&emitters, h).unwrap();
        let s = ImportanceTreeSampler::new(&tree);
        for _ in 0..6 {
            let dir = unit_vector(&mut rng);
            let position = dir * 2e6; // 1e6 x the scene's size
            let tilted = (-dir + 0.5 * unit_vector(&mut rng)).normalize();
            for ctx in [
                ShadingContext::at(position),
                ShadingContext::on_surface(position, -dir),
                ShadingContext::on_surface(position, tilted),
            ] {
                for (i, e) in emitters.iter().enumerate() {
                    let pmf = s.pmf(&ctx, LightId::Emitter(i as u32)) as f64;
                    let expect = e.power as f64 / total;
                    assert!(
                        (pmf / expect - 1.0).abs() < 0.01,
                        "{h:?} light {i}: {pmf:e} vs {expect:e}"
                    );
                }
            }
        }
    }
}

/// Sum over N draws of 1/(pmf N) per light is ~1: the estimator a renderer
/// builds is unbiased for every light the sampler can choose.
#[test]
fn inverse_pmf_estimates_one() {
    let emitters = fit_scene(12, 5);
    let tree = LightTree::build(&emitters, BuildHeuristic::Sarh).unwrap();
    let n = emitters.len();
    let ctx = ShadingContext::on_surface(Vec3::new(0.0, -3.0, 0.5), Vec3::new(0.2, 1.0, 0.1));
    const DRAWS: usize = 1_000_000;
    for (j, (name, s)) in all_samplers(&emitters, &tree, sun_and_sky(0.2))
        .into_iter()
        .enumerate()
    {
        let mut rng = Pcg64::seed_from_u64(1000 + j as u64);
        let mut sums = vec![0.0f64; n + UNBOUNDED];
        for _ in 0..DRAWS {
            let x = s.sample(&ctx, uf32(&mut rng)).unwrap();
            sums[index(x.light, n)] += 1.0 / (x.pmf as f64 * DRAWS as f64);
        }
        for light in lights(n) {
            let p = s.pmf(&ctx, light);
            let est = sums[index(light, n)];
            if p == 0.0 {
                assert_eq!(est, 0.0, "{name}: {light:?} has pmf 0 but was drawn");
            } else if p >= 5e-3 {
                assert!(
                    (est - 1.0).abs() < 0.05,
                    "{name}: {light:?} (pmf {p}) estimates {est}"
                );
            }
        }
    }
}

// ---------------------------------------------------------------------------
// Hard cases
// ---------------------------------------------------------------------------

fn some_points() -> Vec<ShadingContext> {
    vec![
        ShadingContext::at(Vec3::ZERO),
        ShadingContext::on_surface(Vec3::new(0.5, 2.0, -1.0), Vec3::Y),
        ShadingContext::on_surface(Vec3::new(0.0, -1e30, 0.0), Vec3::Y),
        ShadingContext::at(Vec3::splat(1e20)),
        ShadingContext::at(Vec3::NAN),
        ShadingContext::at(Vec3::INFINITY),
        ShadingContext {
            position: Vec3::ONE,
            normal: Some(Vec3::ZERO),
            ..ShadingContext::at(Vec3::ZERO)
        },
        ShadingContext {
            position: Vec3::ONE,
            normal: Some(Vec3::NAN),
            ..ShadingContext::at(Vec3::ZERO)
        },
    ]
}

/// The full contract at many points, with edge `u`s.
fn check_all(emitters: &[Emitter], extra_points: &[ShadingContext]) {
    let mut rng = Pcg64::seed_from_u64(emitters.len() as u64);
    let us: Vec<f32> = (0..32).map(|_| uf32(&mut rng)).collect();
    let mut ctxs = some_points();
    ctxs.extend_from_slice(extra_points);
    ctxs.extend(shading_points(&mut rng, emitters, 8));
    for h in 0..4 {
        let tree = LightTree::build(emitters, heuristic(h)).unwrap();
        for (name, s) in all_samplers(emitters, &tree, sun_and_sky(0.3)) {
            for ctx in &ctxs {
                check_contract(name, &s, emitters.len(), ctx, &us).unwrap();
            }
        }
    }
}

#[test]
fn no_emitters() {
    let tree = LightTree::build(&Vec::<Emitter>::new(), BuildHeuristic::Sarh).unwrap();
    let ctx = ShadingContext::at(Vec3::ZERO);
    let samplers: [Dyn; 4] = [
        Box::new(UniformSampler::new(0)),
        Box::new(PowerSampler::from_powers([])),
        Box::new(PowerTreeSampler::new(&tree)),
        Box::new(ImportanceTreeSampler::new(&tree)),
    ];
    for s in &samplers {
        assert!(s.is_empty());
        for u in edge_us() {
            assert_eq!(s.sample(&ctx, u), None);
        }
        assert_eq!(s.pmf(&ctx, LightId::Emitter(0)), 0.0);
        assert_eq!(s.pmf(&ctx, LightId::Unbounded(0)), 0.0);
    }
    // The unbounded lights alone share probability 1.
    let env = WithUnbounded::new(ImportanceTreeSampler::new(&tree), sun_and_sky(0.1)).unwrap();
    assert_eq!(env.sample(&ctx, 0.7).unwrap().light, LightId::Unbounded(1));
    assert_eq!(env.pmf(&ctx, LightId::Unbounded(0)), 0.5);
    assert_eq!(env.pmf(&ctx, LightId::Unbounded(1)), 0.5);
    check_all(&[], &[]);
}

#[test]
fn one_emitter() {
    let quad = Emitter::area(
        Aabb::new(Vec3::new(-1.0, -1.0, 0.0), Vec3::new(1.0, 1.0, 0.0)),
        Vec3::Z,
        4.0,
        5.0,
    );
    let tree = LightTree::build(&[quad][..], BuildHeuristic::Sarh).unwrap();
    let behind = ShadingContext::on_surface(Vec3::new(0.0, 0.0, -2.0), -Vec3::Z);
    let inside = ShadingContext::at(Vec3::new(0.2, 0.3, 0.0));
    for ctx in [behind, inside] {
        for s in [
            &PowerTreeSampler::new(&tree) as &dyn LightSampler,
            &ImportanceTreeSampler::new(&tree),
            &PowerSampler::new(&[quad][..]),
        ] {
            assert_eq!(s.pmf(&ctx, LightId::Emitter(0)), 1.0);
            assert_eq!(s.sample(&ctx, 0.99).unwrap().pmf, 1.0);
        }
    }
    check_all(&[quad], &[behind, inside]);
    check_all(
        &[Emitter::point(Vec3::ONE, 1e-30)],
        &[ShadingContext::at(Vec3::ONE)],
    );
}

#[test]
fn two_emitters() {
    let emitters = vec![
        Emitter::point(Vec3::new(1.0, 0.0, 0.0), 1.0),
        Emitter::point(Vec3::new(-2.0, 0.0, 0.0), 3.0),
    ];
    let tree = LightTree::build(&emitters, BuildHeuristic::Sarh).unwrap();
    let ctx = ShadingContext::at(Vec3::ZERO);
    let pick = |s: &dyn LightSampler, i: u32| s.pmf(&ctx, LightId::Emitter(i));
    let power = PowerSampler::new(&emitters[..]);
    let tree_sampler = PowerTreeSampler::new(&tree);
    let imp = ImportanceTreeSampler::new(&tree);
    for s in [&power as &dyn LightSampler, &tree_sampler] {
        assert_eq!((pick(s, 0), pick(s, 1)), (0.25, 0.75));
    }
    // Importance: 1/1^2 against 3/2^2.
    assert!((pick(&imp, 0) - 4.0 / 7.0).abs() < 1e-6);
    assert!((pick(&imp, 1) - 3.0 / 7.0).abs() < 1e-6);
    check_all(&emitters, &[]);
}

#[test]
fn all_zero_power() {
    let emitters: Vec<Emitter> = (0..20)
        .map(|i| Emitter::point(Vec3::new(i as f32, 0.0, 0.0), 0.0))
        .collect();
    for h in 0..4 {
        let tree = LightTree::build(&emitters, heuristic(h)).unwrap();
        let samplers: [Dyn; 3] = [
            Box::new(PowerSampler::new(&emitters[..])),
            Box::new(PowerTreeSampler::new(&tree)),
            Box::new(ImportanceTreeSampler::new(&tree)),
        ];
        for s in &samplers {
            assert!(s.is_empty());
            for ctx in some_points() {
                assert_eq!(s.sample(&ctx, 0.5), None);
                assert!(lights(20).all(|l| s.pmf(&ctx, l) == 0.0));
            }
        }
    }
    // The uniform sampler ignores power by definition.
    assert!(!UniformSampler::new(20).is_empty());
    check_all(&emitters, &[]);
}

#[test]
fn zero_power_subtree_is_never_chosen() {
    let mut emitters: Vec<Emitter> = (0..50)
        .map(|i| Emitter::sphere(Vec3::new(i as f32 * 0.02, 0.0, 0.0), 0.01, 0.0))
        .collect();
    emitters.extend((0..50).map(|i| {
        Emitter::sphere(
            Vec3::new(10.0 + i as f32 * 0.02, 0.0, 0.0),
            0.01,
            1.0 + i as f32,
        )
    }));
    let near_dark = [
        ShadingContext::at(Vec3::new(0.5, 0.1, 0.0)),
        ShadingContext::at(Vec3::new(0.3, 0.0, 0.0)),
    ];
    for h in 0..4 {
        let tree = LightTree::build(&emitters, heuristic(h)).unwrap();
        for s in [
            &PowerTreeSampler::new(&tree) as &dyn LightSampler,
            &ImportanceTreeSampler::new(&tree),
            &PowerSampler::new(&emitters[..]),
        ] {
            for ctx in &near_dark {
                for i in 0..50 {
                    assert_eq!(s.pmf(ctx, LightId::Emitter(i)), 0.0);
                }
                for k in 0..1000 {
                    let x = s.sample(ctx, k as f32 / 1000.0).unwrap();
                    assert!(matches!(x.light, LightId::Emitter(50..)), "{x:?}");
                }
            }
        }
    }
    check_all(&emitters, &near_dark);
}

/// Behind every (one-sided) light, every importance is zero: each node falls
/// back to its children's powers, so the importance sampler becomes the
/// power sampler, bit for bit, and zero-power lights stay at pmf 0.
#[test]
fn behind_every_light_falls_back_to_power() {
    let mut rng = Pcg64::seed_from_u64(21);
    let emitters: Vec<Emitter> = (0..300)
        .map(|i| {
            let p = point_in(&mut rng, 5.0) * Vec3::new(1.0, 1.0, 0.0);
            let power = if i % 7 == 0 {
                0.0
            } else {
                range(&mut rng, 0.1, 10.0)
            };
            Emitter::area(
                Aabb::new(p, p + Vec3::new(0.2, 0.2, 0.0)),
                Vec3::Z,
                0.04,
                power,
            )
        })
        .collect();
    for h in 0..4 {
        let tree = LightTree::build(&emitters, heuristic(h)).unwrap();
        let imp = ImportanceTreeSampler::new(&tree);
        let tree_sampler = PowerTreeSampler::new(&tree);
        for ctx in [
            // Far enough that even the root's bounds are all in front.
            ShadingContext::at(Vec3::new(0.5, 0.5, -1000.0)),
            ShadingContext::on_surface(Vec3::new(40.0, -9.0, -500.0), Vec3::Y),
        ] {
            for i in 0..emitters.len() as u32 {
                let p = imp.pmf(&ctx, LightId::Emitter(i));
                assert_eq!(p, tree_sampler.pmf(&ctx, LightId::Emitter(i)));
                assert_eq!(p == 0.0, emitters[i as usize].power == 0.0);
            }
            for k in 0..100 {
                let u = k as f32 / 100.0;
                assert_eq!(imp.sample(&ctx, u), tree_sampler.sample(&ctx, u));
            }
        }
    }
}

#[test]
fn huge_and_tiny_powers() {
    let mut emitters: Vec<Emitter> = (0..10)
        .map(|i| Emitter::point(Vec3::new(i as f32, 1.0, 0.0), 1e30))
        .collect();
    emitters.extend((0..10).map(|i| Emitter::point(Vec3::new(i as f32, -1.0, 0.0), 1e-30)));
    emitters.push(Emitter::sphere(Vec3::new(3.0, 1.0, 0.0), 0.5, 3e37));
    let on_top = ShadingContext::at(Vec3::new(2.0, 1.0, 0.0));
    check_all(&emitters, &[on_top]);
    // The tiny ones are ~1e-61 of the total: pmf 0, never sampled.
    let tree = LightTree::build(&emitters, BuildHeuristic::Sarh).unwrap();
    let s = PowerTreeSampler::new(&tree);
    assert_eq!(s.pmf(&on_top, LightId::Emitter(15)), 0.0);
    assert!(s.pmf(&on_top, LightId::Emitter(5)) > 0.0);
}

#[test]
fn coincident_emitters_split_by_power() {
    let p = Vec3::new(1.0, 2.0, 3.0);
    let emitters: Vec<Emitter> = (0..40).map(|i| Emitter::point(p, 1.0 + i as f32)).collect();
    let total: f32 = emitters.iter().map(|e| e.power).sum();
    for h in 0..4 {
        let tree = LightTree::build(&emitters, heuristic(h)).unwrap();
        let s = ImportanceTreeSampler::new(&tree);
        // On the lights themselves (the distance floor) and away from them.
        for ctx in [
            ShadingContext::at(p),
            ShadingContext::on_surface(p + Vec3::X, Vec3::X),
        ] {
            for (i, e) in emitters.iter().enumerate() {
                let pmf = s.pmf(&ctx, LightId::Emitter(i as u32));
                assert!((pmf / (e.power / total) - 1.0).abs() < 1e-5, "{i}: {pmf}");
            }
        }
    }
    check_all(&emitters, &[ShadingContext::at(p)]);
}

#[test]
fn degenerate_boxes_and_points_inside_lights() {
    let flat = Aabb::new(Vec3::new(-1.0, 0.0, -1.0), Vec3::new(1.0, 0.0, 1.0));
    let emitters = vec![
        Emitter::area(flat, Vec3::Y, 4.0, 2.0),
        Emitter::area(
            Aabb::from_point(Vec3::new(0.0, 1.0, 0.0)),
            -Vec3::Y,
            0.0,
            1.0,
        ),
        Emitter::sphere(Vec3::new(0.0, 0.5, 0.0), 0.0, 1.0),
        Emitter::sphere(Vec3::new(2.0, 0.5, 0.0), 3.0, 1.0),
        Emitter {
            two_sided: true,
            ..Emitter::area(
                Aabb::new(Vec3::new(5.0, 0.0, 0.0), Vec3::new(5.0, 1.0, 1.0)),
                Vec3::X,
                1.0,
                1.0,
            )
        },
    ];
    let inside = [
        // On the flat light, facing away and along it.
        ShadingContext::on_surface(Vec3::new(0.3, 0.0, 0.2), -Vec3::Y),
        ShadingContext::on_surface(Vec3::new(0.3, 0.0, 0.2), Vec3::X),
        // Exactly on the zero-size lights, and inside the big sphere.
        ShadingContext::at(Vec3::new(0.0, 1.0, 0.0)),
        ShadingContext::at(Vec3::new(0.0, 0.5, 0.0)),
        ShadingContext::on_surface(Vec3::new(2.0, 0.5, 0.0), Vec3::Z),
        ShadingContext::at(Vec3::new(5.0, 0.5, 0.5)),
    ];
    check_all(&emitters, &inside);
}

#[test]
fn importance_is_never_nan_negative_or_spuriously_zero() {
    let mut rng = Pcg64::seed_from_u64(17);
    let emitters = random_emitters(SceneSpec {
        count: 500,
        seed: 17,
        zero_fraction: 0.1,
        coincident: false,
    });
    let tree = LightTree::build(&emitters, BuildHeuristic::Saoh).unwrap();
    let mut ctxs = shading_points(&mut rng, &emitters, 16);
    ctxs.extend(some_points());
    for ctx in &ctxs {
        for node in 0..tree.node_count() as u32 {
            let b = tree.node_bounds(node);
            let i = importance(ctx, &b);
            assert!(i >= 0.0 && i.is_finite(), "{ctx:?} {b:?}: {i}");
            // Omnidirectional lights with power reach every finite point.
            if b.power > 0.0
                && b.cone.is_sphere()
                && ctx.normal.is_none()
                && ctx.position.is_finite()
            {
                assert!(i > 0.0, "{ctx:?} {b:?}");
            }
        }
    }
}

#[test]
fn samplers_are_sync_and_work_across_threads() {
    fn assert_sync<T: Sync + Send>() {}
    assert_sync::<UniformSampler>();
    assert_sync::<PowerSampler>();
    assert_sync::<PowerTreeSampler<&'static LightTree>>();
    assert_sync::<ImportanceTreeSampler<&'static LightTree>>();
    assert_sync::<WithUnbounded<PowerSampler>>();

    // Two threads answer the interleaved halves of 2000 queries; together
    // they give what one thread gives alone, for every sampler.
    let emitters = fit_scene(200, 8);
    let tree = LightTree::build(&emitters, BuildHeuristic::Sarh).unwrap();
    let ctx = ShadingContext::at(Vec3::new(0.0, 5.0, 0.0));
    for (name, s) in all_samplers(&emitters, &tree, sun_and_sky(0.2)) {
        let query = |k: usize| {
            let x = s.sample(&ctx, k as f32 / 2000.0);
            (x, x.map(|x| s.pmf(&ctx, x.light)))
        };
        let serial: Vec<_> = (0..2000).map(query).collect();
        let halves: Vec<Vec<_>> = std::thread::scope(|scope| {
            let handles: Vec<_> = (0..2)
                .map(|t| scope.spawn(move || (t..2000).step_by(2).map(query).collect()))
                .collect();
            handles.into_iter().map(|h| h.join().unwrap()).collect()
        });
        for (k, want) in serial.iter().enumerate() {
            assert_eq!(halves[k % 2][k / 2], *want, "{name}: query {k}");
        }
    }
}

// ---------------------------------------------------------------------------
// One million emitters
// ---------------------------------------------------------------------------

#[test]
fn one_million_emitters() {
    const N: usize = 1_000_000;
    let mut rng = Pcg64::seed_from_u64(1_000_000);
    let emitters: Vec<Emitter> = (0..N)
        .map(|i| {
            let p = point_in(&mut rng, 100.0);
            let power = 10f32.powf(range(&mut rng, -3.0, 3.0));
            if i % 2 == 0 {
                Emitter::point(p, power)
            } else {
                Emitter::area(
                    Aabb::new(p, p + Vec3::new(0.1, 0.1, 0.0)),
                    unit_vector(&mut rng),
                    0.01,
                    power,
                )
            }
        })
        .collect();
    let tree = LightTree::build(&emitters, BuildHeuristic::Balanced).unwrap();
    let ctxs = [
        ShadingContext::on_surface(Vec3::ZERO, Vec3::Y),
        ShadingContext::at(Vec3::new(50.0, -20.0, 10.0)),
        ShadingContext::on_surface(Vec3::splat(500.0), -Vec3::ONE),
    ];
    let samplers = all_samplers(&emitters, &tree, sun_and_sky(0.1));
    for (name, s) in &samplers {
        for ctx in &ctxs {
            for _ in 0..500 {
                let u = uf32(&mut rng);
                let x = s.sample(ctx, u).unwrap();
                assert_eq!(x.pmf, s.pmf(ctx, x.light), "{name}");
            }
        }
    }
    // The full sum at one point (power and power tree: the importance
    // tree's sums are covered by the smaller scenes).
    for (name, s) in &samplers[1..3] {
        let sum: f64 = (0..N as u32)
            .map(|i| s.pmf(&ctxs[0], LightId::Emitter(i)) as f64)
            .sum();
        assert!((sum - 1.0).abs() < 1e-5, "{name}: {sum}");
    }
}

/// A renderer's own sampler that knows nothing of light linking: empty
/// when it holds no light.
struct Own(Option<LightSample>);

impl LightSampler for Own {
    fn sample(&self, ctx: &ShadingContext, _: f32) -> Option<LightSample> {
        self.0.filter(|_| ctx.is_finite())
    }
    fn pmf(&self, ctx: &ShadingContext, light: LightId) -> f32 {
        match self.0 {
            Some(s) if s.light == light && ctx.is_finite() => s.pmf,
            _ => 0.0,
        }
    }
    fn is_empty(&self) -> bool {
        self.0.is_none()
    }
}

/// `is_empty_at`'s default answers `is_empty` at every finite point and
/// true elsewhere, so `WithUnbounded` around a sampler of the renderer's
/// own gives the sun everything when that sampler is empty, and shares
/// as set when it is not.
#[test]
fn is_empty_at_defaults_to_is_empty_at_finite_points() {
    let lamp = Some(LightSample {
        light: LightId::Emitter(0),
        pmf: 1.0,
    });
    let here = ShadingContext::at(Vec3::ONE);
    let nowhere = ShadingContext::at(Vec3::NAN);
    assert!(Own(None).is_empty_at(&here));
    assert!(!Own(lamp).is_empty_at(&here));
    assert!(Own(lamp).is_empty_at(&nowhere));
    let sun = UnboundedLights::new(1, 0.3).unwrap();
    let dark = WithUnbounded::new(Own(None), sun).unwrap();
    assert_eq!(dark.pmf(&here, LightId::Unbounded(0)), 1.0);
    let lit = WithUnbounded::new(Own(lamp), sun).unwrap();
    assert_eq!(lit.pmf(&here, LightId::Unbounded(0)), 0.3);
    assert_eq!(lit.pmf(&here, LightId::Emitter(0)), 0.7);
}
