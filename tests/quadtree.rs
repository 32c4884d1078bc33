//! The directional quadtree: normalisation, sampling against evaluation,
//! refinement invariants, learning, bad input, concurrency, deep trees and
//! the box filter.

use glam::{Vec2, Vec3};
use guiding::math::{Accumulation, canonical_to_dir, dir_to_canonical};
use guiding::quadtree::{
    DirectionalFilter, DirectionalTree, NODE_BYTES, QuadLeaf, QuadtreeConfig, UNIFORM_PDF,
};
use rand_pcg::Pcg64;
use rand_pcg::rand_core::{Rng, SeedableRng};
use std::collections::HashMap;

mod common;
use common::{gamma_q, ln_gamma};

// The design bar: a quadtree node is at most 24 bytes (PPG: 24).
const _: () = assert!(NODE_BYTES <= 24);

const FOUR_PI: f64 = 4.0 * std::f64::consts::PI;
const FILTERS: [DirectionalFilter; 2] = [DirectionalFilter::Nearest, DirectionalFilter::Box];

// ---------------------------------------------------------------- helpers

fn rng(seed: u64) -> Pcg64 {
    Pcg64::seed_from_u64(seed)
}

fn unit(r: &mut Pcg64) -> f32 {
    (r.next_u32() >> 8) as f32 * (1.0 / 16_777_216.0)
}

fn random_dir(r: &mut Pcg64) -> Vec3 {
    canonical_to_dir(Vec2::new(unit(r), unit(r)))
}

/// A radiance field: a few lobes of random width and strength over a dim
/// uniform background.
struct Scene {
    lobes: Vec<(Vec3, f32, f32)>,
    background: f32,
}

impl Scene {
    fn random(r: &mut Pcg64) -> Self {
        let count = 1 + (r.next_u32() % 4) as usize;
        let lobes = (0..count)
            .map(|_| {
                let spread = 0.005 + 0.3 * unit(r) * unit(r);
                (random_dir(r), spread, 0.5 + 5.0 * unit(r))
            })
            .collect();
        Self {
            lobes,
            background: 0.05 + 0.3 * unit(r),
        }
    }

    fn draw(&self, r: &mut Pcg64) -> (Vec3, f32) {
        if unit(r) < self.background {
            return (random_dir(r), 0.2 * unit(r));
        }
        let (centre, spread, weight) = self.lobes[r.next_u32() as usize % self.lobes.len()];
        let dir = (centre + spread * unit(r) * random_dir(r)).normalize();
        (dir, weight * (0.5 + unit(r)))
    }
}

fn train(
    mode: Accumulation,
    filter: DirectionalFilter,
    config: &QuadtreeConfig,
    seed: u64,
    iterations: u32,
    records: usize,
) -> DirectionalTree {
    let mut r = rng(seed);
    let scene = Scene::random(&mut r);
    let mut tree = DirectionalTree::new(mode);
    for k in 0..iterations {
        for _ in 0..records << k.min(3) {
            let (dir, value) = scene.draw(&mut r);
            assert!(tree.record(dir, value, filter));
        }
        tree.refine(config);
    }
    tree
}

/// Midpoint rule over an `n x n` grid of the canonical square, times `4 pi`.
fn quadrature(tree: &DirectionalTree, n: usize) -> f64 {
    let mut sum = 0.0f64;
    for i in 0..n {
        for j in 0..n {
            let c = Vec2::new(
                ((i as f64 + 0.5) / n as f64) as f32,
                ((j as f64 + 0.5) / n as f64) as f32,
            );
            sum += tree.pdf(canonical_to_dir(c)) as f64;
        }
    }
    sum * FOUR_PI / (n * n) as f64
}

/// The probability of each sampling leaf, from `pdf` at its centre.
fn leaf_probabilities(tree: &DirectionalTree, leaves: &[QuadLeaf]) -> Vec<f64> {
    leaves
        .iter()
        .map(|l| tree.pdf(canonical_to_dir(l.center())) as f64 * l.area() * FOUR_PI)
        .collect()
}

fn leaf_key(l: &QuadLeaf) -> (u32, u64, u64) {
    (
        l.depth,
        (l.min[0] / l.size) as u64,
        (l.min[1] / l.size) as u64,
    )
}

/// Index of the leaf holding canonical point `c`.
fn find_leaf(index: &HashMap<(u32, u64, u64), usize>, max_depth: u32, c: Vec2) -> usize {
    for d in 1..=max_depth {
        let scale = (1u64 << d) as f64;
        let key = (d, (c.x as f64 * scale) as u64, (c.y as f64 * scale) as u64);
        if let Some(&i) = index.get(&key) {
            return i;
        }
    }
    panic!("no leaf holds {c}");
}

/// p-value of a chi-square statistic with `dof` degrees of freedom.
fn chi_square_p(stat: f64, dof: usize) -> f64 {
    gamma_q(dof as f64 / 2.0, stat / 2.0)
}

/// Chi-square p-value of `observed` counts against `expected` probabilities
/// over `n` draws, pooling bins (smallest first) until each expects >= 5.
fn chi_square_test(observed: &[u64], expected: &[f64], n: u64) -> (f64, usize) {
    let mut order: Vec<usize> = (0..expected.len()).collect();
    order.sort_by(|&a, &b| expected[a].total_cmp(&expected[b]));
    let mut bins: Vec<(f64, f64)> = Vec::new();
    let (mut e, mut o) = (0.0, 0.0);
    for i in order {
        e += expected[i] * n as f64;
        o += observed[i] as f64;
        if e >= 5.0 {
            bins.push((e, o));
            e = 0.0;
            o = 0.0;
        }
    }
    if let Some(last) = bins.last_mut() {
        last.0 += e;
        last.1 += o;
    }
    let stat: f64 = bins.iter().map(|(e, o)| (o - e) * (o - e) / e).sum();
    (chi_square_p(stat, bins.len() - 1), bins.len())
}

fn assert_same_leaves(a: &[QuadLeaf], b: &[QuadLeaf]) {
    assert_eq!(a.len(), b.len());
    for (x, y) in a.iter().zip(b) {
        assert_eq!((x.min, x.size, x.depth), (y.min, y.size, y.depth));
    }
}

// ---------------------------------------------------------------- tests

#[test]
fn chi_square_helper_is_right() {
    // Two degrees of freedom: Q = exp(-x / 2).
    for x in [0.5, 2.0, 9.0, 30.0] {
        assert!((chi_square_p(x, 2) - (-x / 2.0f64).exp()).abs() < 1e-10);
    }
    // Median of chi-square with 100 dof is about 99.33.
    assert!((chi_square_p(99.334, 100) - 0.5).abs() < 1e-3);
    assert!((ln_gamma(10.0) - 362_880.0f64.ln()).abs() < 1e-10);
}

#[test]
fn pdf_integrates_to_one_by_quadrature() {
    for (i, filter) in FILTERS.into_iter().enumerate() {
        for seed in 0..3u64 {
            let mut r = rng(100 + seed);
            let config = QuadtreeConfig {
                rho: 0.003 + 0.03 * unit(&mut r),
                // Leaves no smaller than the 1024^2 grid's cells, so the
                // midpoint rule is exact for the piecewise-constant pdf.
                max_depth: 10,
            };
            let mode = [Accumulation::Fast, Accumulation::Deterministic][i];
            let tree = train(mode, filter, &config, seed, 4, 3000);
            assert!(
                tree.depth() >= 4,
                "{filter:?} seed {seed}: depth {}",
                tree.depth()
            );
            let integral = quadrature(&tree, 1024);
            assert!(
                (integral - 1.0).abs() < 1e-4,
                "{filter:?} seed {seed}: integral {integral}"
            );
            // The leaves' probabilities, from `pdf`, add up the same way.
            let leaves = tree.sampling_leaves();
            let total: f64 = leaf_probabilities(&tree, &leaves).iter().sum();
            assert!((total - 1.0).abs() < 1e-4, "{total}");
        }
    }
}

#[test]
fn untrained_tree_is_uniform() {
    let mut tree = DirectionalTree::new(Accumulation::Fast);
    assert!((quadrature(&tree, 64) - 1.0).abs() < 1e-6);
    assert_eq!(tree.pdf(Vec3::new(0.3, -0.2, 0.9)), UNIFORM_PDF);
    let (dir, pdf) = tree.sample([0.25, 0.5]);
    assert_eq!(dir, canonical_to_dir(Vec2::new(0.25, 0.5)));
    assert_eq!(pdf, UNIFORM_PDF);
    // Refining with nothing collected keeps it uniform.
    tree.refine(&QuadtreeConfig::default());
    assert!(tree.is_uniform());
    assert_eq!(tree.pdf(Vec3::X), UNIFORM_PDF);
    assert_eq!(tree.building_node_count(), 1);
}

#[test]
fn sample_pdf_matches_pdf_and_chi_square() {
    for (i, filter) in FILTERS.into_iter().enumerate() {
        let config = QuadtreeConfig::default();
        let tree = train(
            Accumulation::Deterministic,
            filter,
            &config,
            7 + i as u64,
            4,
            4000,
        );
        let leaves = tree.sampling_leaves();
        assert!(leaves.len() > 100, "{}", leaves.len());
        let expected = leaf_probabilities(&tree, &leaves);
        let index: HashMap<_, _> = leaves
            .iter()
            .enumerate()
            .map(|(i, l)| (leaf_key(l), i))
            .collect();
        let mut observed = vec![0u64; leaves.len()];
        let mut r = rng(1000 + i as u64);
        let n = 200_000u64;
        let mut worst = 0.0f64;
        for _ in 0..n {
            let (dir, pdf) = tree.sample([unit(&mut r), unit(&mut r)]);
            assert!((dir.length() - 1.0).abs() < 1e-5);
            assert!(pdf > 0.0 && pdf.is_finite());
            let eval = tree.pdf(dir);
            worst = worst.max(((pdf - eval) / eval).abs() as f64);
            let c = dir_to_canonical(dir.normalize());
            observed[find_leaf(&index, tree.depth() as u32, c)] += 1;
        }
        assert!(worst <= 1e-4, "{filter:?}: sample pdf vs pdf(): {worst}");
        let (p, bins) = chi_square_test(&observed, &expected, n);
        assert!(bins > 50, "{bins}");
        assert!(p > 1e-4, "{filter:?}: chi-square p = {p} over {bins} bins");
    }
}

#[test]
fn chi_square_detects_a_wrong_distribution() {
    // The same machinery must reject samples from another tree.
    let config = QuadtreeConfig::default();
    let tree = train(
        Accumulation::Fast,
        DirectionalFilter::Nearest,
        &config,
        3,
        3,
        3000,
    );
    let other = train(
        Accumulation::Fast,
        DirectionalFilter::Nearest,
        &config,
        4,
        3,
        3000,
    );
    let leaves = tree.sampling_leaves();
    let expected = leaf_probabilities(&tree, &leaves);
    let index: HashMap<_, _> = leaves
        .iter()
        .enumerate()
        .map(|(i, l)| (leaf_key(l), i))
        .collect();
    let mut observed = vec![0u64; leaves.len()];
    let mut r = rng(5);
    for _ in 0..20_000 {
        let (dir, _) = other.sample([unit(&mut r), unit(&mut r)]);
        observed[find_leaf(&index, tree.depth() as u32, dir_to_canonical(dir))] += 1;
    }
    assert!(chi_square_test(&observed, &expected, 20_000).0 < 1e-4);
}

#[test]
fn refinement_preserves_power_merges_and_bounds_depth() {
    for (i, filter) in FILTERS.into_iter().enumerate() {
        for seed in 0..3u64 {
            let mut r = rng(200 + seed);
            let config = QuadtreeConfig {
                rho: 0.004 + 0.04 * unit(&mut r),
                max_depth: 6 + r.next_u32() % 10,
            };
            let mode = [Accumulation::Deterministic, Accumulation::Fast][i];
            let mut tree = train(mode, filter, &config, 300 + seed, 2, 3000);
            // One more iteration, inspected before and after the refine.
            let scene = Scene::random(&mut r);
            for _ in 0..20_000 {
                let (dir, value) = scene.draw(&mut r);
                tree.record(dir, value, filter);
            }
            let before = tree.building_leaves();
            let total = tree.building_total();
            let before_depth = tree.building_depth();
            tree.refine(&config);

            // Power: the sampling copy is what was collected, leaf by leaf.
            assert_eq!(tree.sampling_total().to_bits(), total.to_bits());
            assert_eq!(tree.depth(), before_depth);
            let sampling = tree.sampling_leaves();
            assert_same_leaves(&before, &sampling);
            let mut sum = 0.0;
            for (b, s) in before.iter().zip(&sampling) {
                assert!((s.value * total - b.value).abs() <= 1e-6 * b.value + 1e-12 * total);
                sum += s.value;
            }
            assert!((sum - 1.0).abs() < 1e-9);
            let leaf_sum: f64 = before.iter().map(|l| l.value).sum();
            assert!((leaf_sum - total).abs() <= 1e-9 * total);

            // The new building topology: shares from the statistics, with a
            // leaf's share split by area (quarter initialisation).
            let share = |min: [f64; 2], size: f64| -> f64 {
                sampling
                    .iter()
                    .map(|l| {
                        let w = (l.min[0] + l.size).min(min[0] + size) - l.min[0].max(min[0]);
                        let h = (l.min[1] + l.size).min(min[1] + size) - l.min[1].max(min[1]);
                        if w > 0.0 && h > 0.0 {
                            l.value * w * h / l.area()
                        } else {
                            0.0
                        }
                    })
                    .sum()
            };
            let rho = config.rho as f64;
            let after = tree.building_leaves();
            assert!(after.iter().all(|l| l.value == 0.0), "sums are zeroed");
            assert!(tree.building_depth() <= config.max_depth as usize);
            let mut split_deeper = false;
            for l in &after {
                assert!(l.depth <= config.max_depth);
                if l.depth < config.max_depth {
                    // Not split: its share is at most rho.
                    let s = share(l.min, l.size);
                    assert!(s <= rho * (1.0 + 1e-5), "leaf {l:?} share {s} > rho {rho}");
                }
                if l.depth > 1 {
                    // Its parent node exists: the parent's share exceeds rho,
                    // so every subtree at or below rho was merged.
                    let size = 2.0 * l.size;
                    let min = l.min.map(|m| (m / size).floor() * size);
                    let s = share(min, size);
                    assert!(
                        s > rho * (1.0 - 1e-5),
                        "parent of {l:?} share {s} <= rho {rho}"
                    );
                }
                let holder = sampling.iter().find(|s| s.contains(l.center())).unwrap();
                split_deeper |= l.depth > holder.depth;
            }
            assert!(split_deeper, "some old leaf was split");
        }
    }
}

#[test]
fn quarter_initialisation_splits_a_bright_leaf_several_levels() {
    for mode in [Accumulation::Fast, Accumulation::Deterministic] {
        let mut tree = DirectionalTree::new(mode);
        for _ in 0..10 {
            tree.record(Vec3::new(0.2, 0.1, 0.97), 3.0, DirectionalFilter::Nearest);
        }
        let mut capped = tree.clone();
        tree.refine(&QuadtreeConfig::default());
        // Share 1 -> 1/4 -> 1/16 -> 1/64 (> 0.01) -> 1/256: nodes at levels
        // 1, 2, 3, 4, 5 under the bright quadrant.
        assert_eq!(tree.building_node_count(), 1 + 1 + 4 + 16 + 64);
        assert_eq!(tree.building_depth(), 5);
        assert_eq!(tree.node_count(), 1);
        assert_eq!(tree.depth(), 1);
        assert_eq!(tree.sampling_total(), 30.0);
        capped.refine(&QuadtreeConfig {
            rho: 0.01,
            max_depth: 3,
        });
        assert_eq!(capped.building_node_count(), 1 + 1 + 4);
        assert_eq!(capped.building_depth(), 3);
    }
}

#[test]
fn old_subtrees_merge_when_their_light_goes() {
    let config = QuadtreeConfig::default();
    let mut tree = DirectionalTree::new(Accumulation::Fast);
    let up = Vec3::new(0.1, 0.2, 0.97).normalize();
    let down = Vec3::new(-0.3, 0.1, -0.9).normalize();
    for _ in 0..3 {
        for _ in 0..100 {
            tree.record(up, 1.0, DirectionalFilter::Nearest);
        }
        tree.refine(&config);
    }
    let holder = |t: &DirectionalTree, d: Vec3| {
        let c = dir_to_canonical(d);
        t.building_leaves()
            .into_iter()
            .find(|l| l.contains(c))
            .unwrap()
            .depth
    };
    assert!(holder(&tree, up) > 10);
    for _ in 0..100 {
        tree.record(down, 1.0, DirectionalFilter::Nearest);
    }
    tree.refine(&config);
    // The upper hemisphere's quadrants got nothing: merged to one level.
    assert_eq!(holder(&tree, up), 1);
    assert!(holder(&tree, down) >= 5);
}

#[test]
fn empty_iteration_keeps_the_learned_distribution() {
    let config = QuadtreeConfig::default();
    let mut tree = train(
        Accumulation::Deterministic,
        DirectionalFilter::Box,
        &config,
        9,
        3,
        2000,
    );
    let mut r = rng(10);
    let probes: Vec<Vec3> = (0..500).map(|_| random_dir(&mut r)).collect();
    let pdfs: Vec<u32> = probes.iter().map(|&d| tree.pdf(d).to_bits()).collect();
    let sampling = tree.sampling_leaves();
    let building = tree.building_leaves();
    let total = tree.sampling_total();
    // Zero-valued records are accepted but carry nothing.
    assert!(tree.record(Vec3::X, 0.0, DirectionalFilter::Nearest));
    tree.refine(&config);
    assert_eq!(tree.sampling_total(), total);
    assert_eq!(tree.sampling_leaves(), sampling);
    assert_same_leaves(&tree.building_leaves(), &building);
    let again: Vec<u32> = probes.iter().map(|&d| tree.pdf(d).to_bits()).collect();
    assert_eq!(pdfs, again);
}

#[test]
fn learns_three_directions() {
    let dirs = [
        Vec3::new(0.3, 0.5, 0.8).normalize(),
        Vec3::new(-0.7, 0.1, -0.2).normalize(),
        Vec3::new(0.05, -0.9, -0.4).normalize(),
    ];
    for filter in FILTERS {
        let mut tree = DirectionalTree::new(Accumulation::Fast);
        let mut r = rng(11);
        for _ in 0..5 {
            for _ in 0..3000 {
                let k = r.next_u32() as usize % 3;
                let jitter = 0.01 * unit(&mut r) * random_dir(&mut r);
                tree.record((dirs[k] + jitter).normalize(), (k + 1) as f32, filter);
                // A dim background: 1% of the power.
                if r.next_u32() % 10 == 0 {
                    tree.record(random_dir(&mut r), 0.2, filter);
                }
            }
            tree.refine(&QuadtreeConfig::default());
        }
        for d in dirs {
            let ratio = tree.pdf(d) / UNIFORM_PDF;
            assert!(ratio > 50.0, "{filter:?}: pdf ratio {ratio} at {d}");
        }
        let cos_max = 0.05f32.cos();
        let n = 20_000;
        let near = (0..n)
            .filter(|_| {
                let (s, _) = tree.sample([unit(&mut r), unit(&mut r)]);
                dirs.iter().any(|d| d.dot(s) > cos_max)
            })
            .count();
        let mass = near as f64 / n as f64;
        assert!(mass > 0.9, "{filter:?}: mass near the lights {mass}");
    }
}

#[test]
fn bad_input_is_rejected_and_changes_nothing() {
    let bad_values = [
        f32::NAN,
        f32::INFINITY,
        f32::NEG_INFINITY,
        -1.0,
        -f32::MIN_POSITIVE,
    ];
    let bad_dirs = [
        Vec3::ZERO,
        Vec3::new(f32::NAN, 0.0, 1.0),
        Vec3::new(0.0, f32::INFINITY, 0.0),
        Vec3::NAN,
    ];
    let config = QuadtreeConfig::default();
    for mode in [Accumulation::Fast, Accumulation::Deterministic] {
        for filter in FILTERS {
            let mut tree = train(mode, filter, &config, 12, 2, 2000);
            tree.record(Vec3::Y, 2.0, filter);
            let leaves = tree.building_leaves();
            let total = tree.building_total();
            for v in bad_values {
                assert!(!tree.record(Vec3::Y, v, filter), "value {v}");
            }
            for d in bad_dirs {
                assert!(!tree.record(d, 1.0, filter), "dir {d}");
                assert_eq!(tree.pdf(d), 0.0);
            }
            assert_eq!(tree.building_total().to_bits(), total.to_bits());
            assert_eq!(tree.building_leaves(), leaves);
            // A direction of any length is normalised.
            assert_eq!(tree.pdf(Vec3::new(0.0, 5.0, 0.0)), tree.pdf(Vec3::Y));
            // Random numbers outside [0, 1) are clamped.
            for u in [
                [0.0, 0.0],
                [1.0, 1.0],
                [-5.0, 7.0],
                [f32::NAN, f32::NAN],
                [f32::INFINITY, f32::NEG_INFINITY],
                [0.999_999_94, 0.999_999_94],
            ] {
                let (dir, pdf) = tree.sample(u);
                assert!(
                    dir.is_finite() && (dir.length() - 1.0).abs() < 1e-5,
                    "{u:?}"
                );
                assert!(pdf > 0.0 && pdf == tree.pdf(dir), "{u:?}: {pdf}");
            }
            // Only rejected input this iteration: refining it is an empty
            // iteration apart from the one good record.
            tree.refine(&config);
            assert_eq!(tree.sampling_total(), total);
        }
    }
}

#[test]
fn pdf_is_positive_where_nothing_was_learned() {
    let mut tree = DirectionalTree::new(Accumulation::Fast);
    for _ in 0..4 {
        for _ in 0..100 {
            tree.record(Vec3::Z, 1.0, DirectionalFilter::Nearest);
        }
        tree.refine(&QuadtreeConfig::default());
    }
    let floor = DirectionalTree::DEFAULT_UNIFORM_FRACTION * UNIFORM_PDF;
    let dark = tree.pdf(-Vec3::Z);
    assert!((dark - floor).abs() <= 1e-6 * floor, "{dark} vs {floor}");
    tree.set_uniform_fraction(1.0);
    assert!((tree.pdf(-Vec3::Z) - UNIFORM_PDF).abs() < 1e-7);
    assert!((tree.pdf(Vec3::Z) - UNIFORM_PDF).abs() < 1e-7);
}

/// The record stream the concurrency test replays: values over many orders of
/// magnitude, both filters.
fn record_stream(seed: u64, n: usize) -> Vec<(Vec3, f32, DirectionalFilter)> {
    let mut r = rng(seed);
    let scene = Scene::random(&mut r);
    (0..n)
        .map(|_| {
            let (dir, value) = scene.draw(&mut r);
            let scale = 10f32.powi((r.next_u32() % 13) as i32 - 6);
            (dir, value * scale, FILTERS[(r.next_u32() % 2) as usize])
        })
        .collect()
}

fn record_threaded(
    tree: &DirectionalTree,
    stream: &[(Vec3, f32, DirectionalFilter)],
    threads: usize,
) {
    std::thread::scope(|s| {
        for t in 0..threads {
            s.spawn(move || {
                // Each thread walks its share backwards, so the global order
                // differs from the single-threaded one.
                for i in (0..stream.len()).rev().filter(|i| i % threads == t) {
                    let (d, v, f) = stream[i];
                    assert!(tree.record(d, v, f));
                }
            });
        }
    });
}

#[test]
fn threads_give_the_same_state_as_one_thread() {
    let config = QuadtreeConfig::default();
    let stream = record_stream(13, 40_000);
    for mode in [Accumulation::Deterministic, Accumulation::Fast] {
        let base = train(mode, DirectionalFilter::Nearest, &config, 14, 3, 3000);
        let single = base.clone();
        for &(d, v, f) in &stream {
            single.record(d, v, f);
        }
        let multi = base.clone();
        record_threaded(&multi, &stream, 4);
        let (a, b) = (single.building_leaves(), multi.building_leaves());
        assert_same_leaves(&a, &b);
        let (ta, tb) = (single.building_total(), multi.building_total());
        match mode {
            Accumulation::Deterministic => {
                assert_eq!(ta.to_bits(), tb.to_bits());
                for (x, y) in a.iter().zip(&b) {
                    assert_eq!(x.value.to_bits(), y.value.to_bits());
                }
                let (mut single, mut multi) = (single, multi);
                single.refine(&config);
                multi.refine(&config);
                assert_eq!(single.sampling_leaves(), multi.sampling_leaves());
                assert_same_leaves(&single.building_leaves(), &multi.building_leaves());
                let mut r = rng(15);
                for _ in 0..1000 {
                    let u = [unit(&mut r), unit(&mut r)];
                    let (da, pa) = single.sample(u);
                    let (db, pb) = multi.sample(u);
                    assert_eq!((da, pa.to_bits()), (db, pb.to_bits()));
                }
            }
            Accumulation::Fast => {
                assert!((ta - tb).abs() <= 1e-12 * ta);
                for (x, y) in a.iter().zip(&b) {
                    assert!((x.value - y.value).abs() <= 1e-12 * x.value.max(y.value));
                }
            }
        }
    }
}

#[test]
fn deep_trees_with_more_than_65535_nodes() {
    let config = QuadtreeConfig {
        rho: 5e-6,
        max_depth: 20,
    };
    let spikes = [
        Vec3::new(0.31, 0.52, 0.8).normalize(),
        Vec3::new(-0.62, 0.11, -0.33).normalize(),
        Vec3::new(0.01, -0.97, 0.2).normalize(),
    ];
    let mut tree = DirectionalTree::new(Accumulation::Fast);
    let grid = 512;
    for _ in 0..5 {
        // An even background: one record per cell of a 512^2 grid, so every
        // level-8 cell holds 4 (share > rho) and every level-9 cell 1 (< rho).
        for i in 0..grid {
            for j in 0..grid {
                let c = Vec2::new(
                    (i as f32 + 0.5) / grid as f32,
                    (j as f32 + 0.5) / grid as f32,
                );
                tree.record(canonical_to_dir(c), 1.0, DirectionalFilter::Nearest);
            }
        }
        for s in spikes {
            tree.record(s, 0.05 * (grid * grid) as f32, DirectionalFilter::Nearest);
        }
        tree.refine(&config);
    }
    assert!(tree.node_count() > 65_535, "{}", tree.node_count());
    assert!(tree.building_node_count() > 65_535);
    assert_eq!(tree.depth(), 20);
    assert!(tree.bytes() >= tree.node_count() * NODE_BYTES);

    // Normalised, exactly over the leaves.
    let leaves = tree.sampling_leaves();
    let total: f64 = leaf_probabilities(&tree, &leaves).iter().sum();
    assert!((total - 1.0).abs() < 1e-4, "{total}");
    // Spikes are learned down to depth 20 cells.
    for s in spikes {
        let c = dir_to_canonical(s);
        let leaf = leaves.iter().find(|l| l.contains(c)).unwrap();
        assert_eq!(leaf.depth, 20);
        assert!(tree.pdf(s) > 1e6 * UNIFORM_PDF, "{}", tree.pdf(s));
    }
    // Sampling agrees with evaluation, deep leaves included.
    let mut r = rng(16);
    let mut deep = 0;
    for _ in 0..50_000 {
        let (dir, pdf) = tree.sample([unit(&mut r), unit(&mut r)]);
        let eval = tree.pdf(dir);
        assert!(
            pdf > 0.0 && ((pdf - eval) / eval).abs() <= 1e-4,
            "{pdf} vs {eval}"
        );
        deep += (pdf > 1e6 * UNIFORM_PDF) as usize;
    }
    assert!(deep > 5_000, "{deep}");
    assert!(tree.record(spikes[0], 1.0, DirectionalFilter::Box));
    assert!(tree.building_total() > 0.0);
}

/// What the box filter should give each building leaf: `value` times the
/// leaf's overlap with a square as wide as the leaf holding `c`, wrapped in
/// v, clipped in u, divided by the square's area inside the domain.
fn box_expectation(leaves: &[QuadLeaf], c: Vec2, value: f64) -> Vec<f64> {
    let holder = leaves.iter().find(|l| l.contains(c)).unwrap();
    let (cx, cy, h) = (c.x as f64, c.y as f64, holder.size);
    let (x0, x1) = ((cx - h / 2.0).max(0.0), (cx + h / 2.0).min(1.0));
    let (y0, y1) = (cy - h / 2.0, cy + h / 2.0);
    let pieces = if y0 < 0.0 {
        vec![(y0 + 1.0, 1.0), (0.0, y1)]
    } else if y1 > 1.0 {
        vec![(y0, 1.0), (0.0, y1 - 1.0)]
    } else {
        vec![(y0, y1)]
    };
    let area = (x1 - x0) * h;
    leaves
        .iter()
        .map(|l| {
            let w = (l.min[0] + l.size).min(x1) - l.min[0].max(x0);
            pieces
                .iter()
                .map(|&(a, b)| {
                    let hh = (l.min[1] + l.size).min(b) - l.min[1].max(a);
                    if w > 0.0 && hh > 0.0 { w * hh } else { 0.0 }
                })
                .sum::<f64>()
                * value
                / area
        })
        .collect()
}

#[test]
fn box_filter_spreads_by_overlap_and_keeps_the_mass() {
    let config = QuadtreeConfig::default();
    let tree = train(
        Accumulation::Deterministic,
        DirectionalFilter::Nearest,
        &config,
        17,
        3,
        3000,
    );
    let empty = tree.building_leaves();
    assert!(empty.len() > 50);
    let mut r = rng(18);
    let edges = [1e-4f32, 0.9999];
    let mut spread = 0;
    for k in 0..300 {
        let mut c = Vec2::new(unit(&mut r), unit(&mut r));
        if k % 3 == 1 {
            c.x = edges[k % 2];
        }
        if k % 5 == 2 {
            c.y = edges[(k / 5) % 2];
        }
        let dir = canonical_to_dir(c);
        let c = dir_to_canonical(dir);
        let value = 0.5 + 10.0 * unit(&mut r);
        let t = tree.clone();
        assert!(t.record(dir, value, DirectionalFilter::Box));
        let total = t.building_total();
        assert!(
            (total - value as f64).abs() <= 1e-6 * value as f64,
            "{total} vs {value}"
        );
        let got = t.building_leaves();
        let expect = box_expectation(&empty, c, value as f64);
        for (g, e) in got.iter().zip(&expect) {
            assert!(
                (g.value - e).abs() <= 1e-5 * value as f64,
                "at {c}: {g:?} vs {e}"
            );
        }
        spread += (got.iter().filter(|l| l.value > 0.0).count() > 1) as usize;
    }
    assert!(spread > 100, "{spread}");
}

#[test]
fn clone_copies_both_copies() {
    let config = QuadtreeConfig::default();
    let tree = train(
        Accumulation::Deterministic,
        DirectionalFilter::Box,
        &config,
        19,
        3,
        2000,
    );
    let mut r = rng(20);
    let scene = Scene::random(&mut r);
    let stream: Vec<_> = (0..5000).map(|_| scene.draw(&mut r)).collect();
    for &(d, v) in &stream[..2500] {
        tree.record(d, v, DirectionalFilter::Box);
    }
    let mut a = tree.clone();
    let mut b = tree.clone();
    assert_eq!(a.sampling_leaves(), tree.sampling_leaves());
    assert_eq!(a.building_leaves(), tree.building_leaves());
    // The clones are independent of the original.
    let before = tree.building_leaves();
    for &(d, v) in &stream[2500..] {
        a.record(d, v, DirectionalFilter::Box);
        b.record(d, v, DirectionalFilter::Box);
    }
    assert_eq!(tree.building_leaves(), before);
    a.refine(&config);
    b.refine(&config);
    assert_eq!(a.sampling_leaves(), b.sampling_leaves());
    assert_eq!(a.building_leaves(), b.building_leaves());
    assert_ne!(a.sampling_leaves(), tree.sampling_leaves());
}

#[test]
fn memory_is_reported() {
    let config = QuadtreeConfig::default();
    let fast = train(
        Accumulation::Fast,
        DirectionalFilter::Nearest,
        &config,
        21,
        3,
        2000,
    );
    let exact = train(
        Accumulation::Deterministic,
        DirectionalFilter::Nearest,
        &config,
        21,
        3,
        2000,
    );
    assert_eq!(fast.node_count(), exact.node_count());
    let sampling = fast.node_count() * NODE_BYTES;
    let building = fast.building_node_count() * 8;
    assert!(fast.bytes() >= sampling + building + fast.building_node_count() * 4 * 8);
    assert!(exact.bytes() >= sampling + building + exact.building_node_count() * 4 * 48);
}
