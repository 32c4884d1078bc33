//! The SD-tree: normalisation, sample/pdf agreement, learning, refinement
//! rules, memory budget and report, bad input, the learned BSDF fraction
//! and bit-exact concurrency.

mod common;
use common::DirectionsAt;
use glam::{Vec2, Vec3};
use guiding::math::{Aabb, Accumulation, canonical_to_dir};
use guiding::quadtree::{DirectionalFilter, UNIFORM_PDF};
use guiding::sd_tree::{SdTree, SdTreeConfig};
use guiding::spatial::SpatialFilter;
use guiding::spatial::SpatialTree;
use guiding::{RecordOutcome, ShadingContext};
use rand_pcg::Pcg32;
use rand_pcg::rand_core::{Rng, SeedableRng};

fn scene() -> Aabb {
    Aabb::new(Vec3::new(-2.0, -1.0, -1.0), Vec3::new(2.0, 1.0, 1.0))
}

fn unit(rng: &mut Pcg32) -> f32 {
    (rng.next_u32() >> 8) as f32 / (1u32 << 24) as f32
}

fn point_in(rng: &mut Pcg32, b: &Aabb) -> Vec3 {
    b.min + Vec3::new(unit(rng), unit(rng), unit(rng)) * b.diagonal()
}

fn lobes() -> [Vec3; 3] {
    [
        Vec3::new(0.3, 0.2, 0.93).normalize(),
        Vec3::new(-0.8, 0.5, -0.1).normalize(),
        Vec3::new(0.1, -0.9, -0.4).normalize(),
    ]
}

/// A direction near one of the lobes.
fn lobe_dir(rng: &mut Pcg32) -> Vec3 {
    let l = lobes()[(rng.next_u32() % 3) as usize];
    let n = Vec3::new(unit(rng), unit(rng), unit(rng)) - 0.5;
    (l + 0.05 * n).normalize()
}

/// Records `n` lobe directions at random points, radiance 1 sampled
/// uniformly (pdf 1 / 4 pi).
fn train(tree: &SdTree, n: usize, seed: u64) {
    let mut rng = Pcg32::seed_from_u64(seed);
    let b = tree.spatial().root_bounds();
    for _ in 0..n {
        let p = point_in(&mut rng, &b);
        let d = lobe_dir(&mut rng);
        assert_ne!(
            tree.record_radiance_at(p, d, 1.0, UNIFORM_PDF),
            RecordOutcome::Dropped
        );
    }
}

fn config(c: f64) -> SdTreeConfig {
    SdTreeConfig {
        spatial_threshold: c,
        ..SdTreeConfig::default()
    }
}

fn trained(c: f64) -> SdTree {
    let mut t = SdTree::new(scene(), config(c)).unwrap();
    for it in 0..4 {
        train(&t, 4000, it);
        t.refine();
    }
    t
}

#[test]
fn pdf_integrates_to_one_in_every_cell() {
    let t = trained(300.0);
    assert!(t.cell_count() > 4, "{}", t.cell_count());
    let tree = t.spatial();
    for cell in tree.cells() {
        let p = tree.cell_bounds(cell).center();
        let leaves = tree.data(cell).directions().sampling_leaves();
        assert!(leaves.len() > 4);
        // Exact quadrature: the density is constant on each leaf.
        let integral: f64 = leaves
            .iter()
            .map(|l| {
                t.direction_pdf_at(p, canonical_to_dir(l.center())) as f64
                    * l.area()
                    * 4.0
                    * core::f64::consts::PI
            })
            .sum();
        assert!((integral - 1.0).abs() < 1e-4, "cell {cell:?}: {integral}");
    }
    // A blind midpoint rule on a 512^2 grid over the sphere agrees.
    let p = tree.cell_bounds(tree.cells().next().unwrap()).center();
    let n = 512;
    let mut sum = 0.0f64;
    for i in 0..n {
        for j in 0..n {
            let c = Vec2::new((i as f32 + 0.5) / n as f32, (j as f32 + 0.5) / n as f32);
            sum += t.direction_pdf_at(p, canonical_to_dir(c)) as f64;
        }
    }
    let integral = sum * 4.0 * core::f64::consts::PI / (n * n) as f64;
    assert!((integral - 1.0).abs() < 0.02, "{integral}");
}

#[test]
fn sampled_pdf_equals_pdf() {
    let t = trained(300.0);
    let mut rng = Pcg32::seed_from_u64(9);
    let b = scene();
    for _ in 0..20_000 {
        let p = point_in(&mut rng, &b);
        let (dir, pdf) = t
            .sample_direction_at(p, [unit(&mut rng), unit(&mut rng)])
            .unwrap();
        assert!((dir.length() - 1.0).abs() < 1e-5);
        assert!(pdf > 0.0);
        assert_eq!(pdf, t.direction_pdf_at(p, dir), "at {p} toward {dir}");
        // Any positive length evaluates the same.
        assert_eq!(t.direction_pdf_at(p, dir * 3.0), pdf);
    }
    assert!(t.sample_direction_at(Vec3::NAN, [0.5, 0.5]).is_none());
    assert_eq!(
        t.direction_pdf_at(Vec3::new(f32::INFINITY, 0.0, 0.0), Vec3::Z),
        0.0
    );
    assert_eq!(t.direction_pdf_at(Vec3::ZERO, Vec3::ZERO), 0.0);
    assert_eq!(
        t.direction_pdf_at(Vec3::ZERO, Vec3::new(f32::NAN, 0.0, 1.0)),
        0.0
    );
    // Outside the scene: the clamped point's distribution.
    assert_eq!(
        t.direction_pdf_at(Vec3::splat(100.0), Vec3::Z),
        t.direction_pdf_at(b.max, Vec3::Z)
    );
}

#[test]
fn learning_concentrates_on_the_recorded_directions() {
    let t = trained(1.0e9);
    assert_eq!(t.cell_count(), 1);
    let p = Vec3::ZERO;
    for l in lobes() {
        let ratio = t.direction_pdf_at(p, l) / UNIFORM_PDF;
        assert!(ratio > 20.0, "lobe {l}: {ratio}");
    }
    // Directions away from every lobe lose density.
    let mut rng = Pcg32::seed_from_u64(3);
    let mut away = 0.0;
    let mut count = 0;
    for _ in 0..2000 {
        let d = canonical_to_dir(Vec2::new(unit(&mut rng), unit(&mut rng)));
        if lobes().iter().all(|l| l.dot(d) < 0.7) {
            away += t.direction_pdf_at(p, d);
            count += 1;
        }
    }
    assert!(away / (count as f32) < 0.2 * UNIFORM_PDF);
    // Samples go to the lobes.
    let near = (0..2000)
        .filter(|_| {
            let (d, _) = t
                .sample_direction_at(p, [unit(&mut rng), unit(&mut rng)])
                .unwrap();
            lobes().iter().any(|l| l.dot(d) > 0.95)
        })
        .count();
    assert!(near > 1600, "{near} of 2000");
}

fn record_n(t: &SdTree, p: Vec3, n: usize) {
    for _ in 0..n {
        assert_ne!(
            t.record_radiance_at(p, Vec3::Z, 1.0, 1.0),
            RecordOutcome::Dropped
        );
    }
}

#[test]
fn spatial_split_exactly_above_threshold_copies_and_halves() {
    let p = Vec3::new(0.5, 0.5, 0.5);
    // Iteration 0: threshold c = 100.
    let mut t = SdTree::new(scene(), config(100.0)).unwrap();
    record_n(&t, p, 100);
    assert_eq!(
        t.vertex(&ShadingContext::at(p))
            .unwrap()
            .sd()
            .building_weight(),
        100.0
    );
    assert_eq!(t.refine().splits, 0);
    assert_eq!(t.cell_count(), 1);
    // Iteration 1: threshold 100 sqrt 2 = 141.42.
    record_n(&t, p, 141);
    assert_eq!(t.refine().splits, 0);
    assert_eq!(t.iteration(), 2);
    // Iteration 2: threshold 200; 201 records split once (100.5 each).
    record_n(&t, p, 201);
    assert_eq!(t.refine().splits, 1);
    assert_eq!(t.cell_count(), 2);
    let tree = t.spatial();
    let (a, b) = (
        tree.data_slice()[0].directions(),
        tree.data_slice()[1].directions(),
    );
    assert_eq!(a.sampling_leaves(), b.sampling_leaves());
    assert!(a.pdf(Vec3::Z) > 10.0 * UNIFORM_PDF);
    // Weights were zeroed for the next iteration.
    assert!(tree.data_slice().iter().all(|c| c.building_weight() == 0.0));

    // Recursive in one pass: 450 -> 225 -> 112.5 -> 56.25 against 100.
    let mut t = SdTree::new(scene(), config(100.0)).unwrap();
    record_n(&t, p, 450);
    assert_eq!(t.refine().splits, 7);
    assert_eq!(t.cell_count(), 8);
    // 400 -> 200 -> 100 (not above): two levels.
    let mut t = SdTree::new(scene(), config(100.0)).unwrap();
    record_n(&t, p, 400);
    assert_eq!(t.refine().splits, 3);
    let c = SdTreeConfig::default();
    assert_eq!(c.split_threshold(0), 12000.0);
    assert_eq!(c.split_threshold(4), 48000.0);
    assert!((c.split_threshold(3) - 12000.0 * 8f64.sqrt()).abs() < 1e-9);
    assert_eq!(SdTreeConfig::improved().split_threshold(0), 4000.0);
}

#[test]
fn memory_report_and_budget() {
    let t = trained(300.0);
    let m = t.memory();
    assert_eq!(m.cells, t.cell_count());
    assert_eq!(m.spatial_nodes, 2 * m.cells - 1);
    let qn: usize = t
        .spatial()
        .data_slice()
        .iter()
        .map(|c| c.directions().node_count())
        .sum();
    assert_eq!(m.quadtree_nodes, qn);
    assert!(m.quadtree_building_nodes >= m.cells);
    assert!(m.quadtree_bytes >= 24 * m.quadtree_nodes);
    assert!(m.spatial_bytes >= 4 * m.spatial_nodes);
    assert_eq!(
        m.total(),
        m.spatial_bytes + m.quadtree_bytes + m.statistics_bytes
    );
    assert_eq!(SdTree::SPATIAL_NODE_BYTES, 4);

    // The same training under a budget of a third of that.
    let budget = m.total() / 3;
    let mut b = SdTree::new(
        scene(),
        SdTreeConfig {
            max_bytes: Some(budget),
            ..config(300.0)
        },
    )
    .unwrap();
    let mut refused = 0;
    for it in 0..4 {
        train(&b, 4000, it);
        let out = b.refine();
        refused += out.refused_by_budget;
        // Splits never take the total past the budget (quadtrees refined
        // before the splits may, on their own).
        if out.splits > 0 {
            assert!(
                b.memory().total() <= budget,
                "{} > {budget}",
                b.memory().total()
            );
        }
    }
    assert!(refused > 0);
    assert!(b.cell_count() < t.cell_count());
    assert!(b.cell_count() > 1);
}

#[test]
fn bad_input_is_dropped_counted_and_never_stored() {
    let mut t = SdTree::new(
        scene(),
        SdTreeConfig {
            learn_bsdf_fraction: true,
            ..config(1.0)
        },
    )
    .unwrap();
    let p = Vec3::ZERO;
    let d = Vec3::Z;
    let nan = f32::NAN;
    let inf = f32::INFINITY;
    let bad_positions = [
        Vec3::new(nan, 0.0, 0.0),
        Vec3::new(0.0, inf, 0.0),
        Vec3::splat(-inf),
    ];
    let bad_dirs = [
        Vec3::ZERO,
        Vec3::new(nan, 0.0, 1.0),
        Vec3::new(0.0, inf, 1.0),
    ];
    for q in bad_positions {
        assert!((t.record_radiance_at(q, d, 1.0, 1.0) == RecordOutcome::Dropped));
    }
    for dir in bad_dirs {
        assert!((t.record_radiance_at(p, dir, 1.0, 1.0) == RecordOutcome::Dropped));
    }
    for r in [nan, inf, -1.0, -0.0 - f32::MIN_POSITIVE] {
        assert!((t.record_radiance_at(p, d, r, 1.0) == RecordOutcome::Dropped));
    }
    for pdf in [0.0, -1.0, nan, inf, -0.0] {
        assert!((t.record_radiance_at(p, d, 1.0, pdf) == RecordOutcome::Dropped));
    }
    assert!((t.record_radiance_at(p, d, 1.0e30, 1.0e-30) == RecordOutcome::Dropped));
    // Every filter drops the same way.
    for f in [SpatialFilter::Box, SpatialFilter::StochasticBox] {
        let filtered = SdTreeConfig {
            spatial_filter: f,
            directional_filter: DirectionalFilter::Box,
            ..config(1.0)
        };
        let other = SdTree::new(scene(), filtered).unwrap();
        assert_eq!(
            other.record_radiance_at(p, d, nan, 1.0),
            RecordOutcome::Dropped
        );
        assert_eq!(other.dropped_records().radiance, 1);
    }
    // Fraction records.
    assert!((t.record_fraction_at(Vec3::NAN, 1.0, 1.0, 1.0) == RecordOutcome::Dropped));
    assert!((t.record_fraction_at(p, 1.0, 1.0, -1.0) == RecordOutcome::Dropped));
    assert!((t.record_fraction_at(p, 0.0, 0.0, 1.0) == RecordOutcome::Dropped));
    assert!((t.record_fraction_at(p, nan, 1.0, 1.0) == RecordOutcome::Dropped));
    let dropped = t.dropped_records();
    assert_eq!(dropped.position, 3 + 1);
    assert_eq!(dropped.direction, 3);
    assert_eq!(dropped.radiance, 4 + 1);
    assert_eq!(dropped.pdf, 5 + 2);
    assert_eq!(dropped.overflow, 1);
    assert_eq!(dropped.total(), 4 + 3 + 5 + 7 + 1);
    // Nothing was stored: no weight, nothing learned, no split, fraction
    // unchanged.
    assert_eq!(
        t.vertex(&ShadingContext::at(p))
            .unwrap()
            .sd()
            .building_weight(),
        0.0
    );
    t.refine();
    assert_eq!(t.cell_count(), 1);
    assert_eq!(t.direction_pdf_at(p, Vec3::X), UNIFORM_PDF);
    assert_eq!(t.bsdf_fraction_at(p), 0.5);
    // Valid zero radiance counts weight, no power.
    assert_ne!(t.record_radiance_at(p, d, 0.0, 1.0), RecordOutcome::Dropped);
    assert_eq!(
        t.vertex(&ShadingContext::at(p))
            .unwrap()
            .sd()
            .building_weight(),
        1.0
    );
    t.reset_dropped_records();
    assert_eq!(t.dropped_records().total(), 0);
    // Learning disabled: valid records are ignored, not counted.
    let off = SdTree::new(scene(), config(1.0)).unwrap();
    assert_eq!(
        off.record_fraction_at(p, 1.0, 1.0, 1.0),
        RecordOutcome::Ignored
    );
    assert_eq!(off.dropped_records().total(), 0);
}

#[test]
fn box_filters_spread_weight_by_overlap() {
    // Four cells: split along x, then y, at the origin (with one cell
    // every filter records the same).
    let four_cells = |spatial_filter| {
        let filtered = SdTreeConfig {
            spatial_filter,
            directional_filter: DirectionalFilter::Nearest,
            ..config(10.0)
        };
        let mut t = SdTree::new(scene(), filtered).unwrap();
        record_n(&t, Vec3::ZERO, 40);
        assert_eq!(t.refine().splits, 3);
        assert_eq!(t.cell_count(), 4);
        t
    };
    let t = four_cells(SpatialFilter::Box);
    // Each cell gets the fraction of the cell-sized box around p it covers.
    let tree = t.spatial();
    let b = tree.root_bounds();
    let p = Vec3::new(b.center().x, 0.3, 0.3);
    let cell = tree.cell_bounds(tree.locate(p).unwrap());
    let half = cell.diagonal() * 0.5;
    let region = Aabb::new(p - half, p + half).intersection(&b);
    let vol = |a: &Aabb| {
        let d = a.diagonal();
        if a.is_empty() {
            0.0
        } else {
            d.x as f64 * d.y as f64 * d.z as f64
        }
    };
    assert_eq!(
        t.record_radiance_at(p, Vec3::Z, 1.0, 1.0),
        RecordOutcome::Recorded
    );
    let mut touched = 0;
    let expected: Vec<f64> = tree
        .cells()
        .map(|c| vol(&tree.cell_bounds(c).intersection(&region)) / vol(&region))
        .collect();
    for c in tree.cells() {
        let expect = expected[c.index()];
        let got = tree.data(c).building_weight();
        assert!((got - expect).abs() < 1e-6, "{c:?}: {got} vs {expect}");
        touched += (got > 0.0) as usize;
    }
    assert!(touched >= 2);
    // At the scene border the box is clipped, so nothing is lost.
    assert_eq!(
        t.record_radiance_at(b.min, Vec3::Z, 1.0, 1.0),
        RecordOutcome::Recorded
    );
    let total: f64 = t
        .spatial()
        .data_slice()
        .iter()
        .map(|c| c.building_weight())
        .sum();
    assert!((total - 2.0).abs() < 1e-6, "{total}");

    // Stochastic box: the same weights in expectation, one cell per
    // record. Its offset is a hash of the record, so these records at one
    // point differ in their direction (at one point along one direction
    // every record would go to the same cell).
    let t = four_cells(SpatialFilter::StochasticBox);
    let before: Vec<f64> = t
        .spatial()
        .data_slice()
        .iter()
        .map(|c| c.building_weight())
        .collect();
    let n = 4000.0;
    for i in 0..n as usize {
        let dir = Vec3::new(i as f32 * 1e-4, 0.0, 1.0);
        assert_eq!(
            t.record_radiance_at(p, dir, 1.0, 1.0),
            RecordOutcome::Recorded
        );
    }
    let gained: Vec<f64> = t
        .spatial()
        .data_slice()
        .iter()
        .zip(&before)
        .map(|(c, b)| c.building_weight() - b)
        .collect();
    assert_eq!(gained.iter().sum::<f64>(), n);
    for (g, w) in gained.iter().zip(&expected) {
        assert_eq!(g.fract(), 0.0);
        let sd = (n * w * (1.0 - w)).sqrt();
        assert!(
            (g - n * w).abs() <= 5.0 * sd + 1.0,
            "{gained:?} vs {expected:?}"
        );
    }
}

#[test]
fn learned_fraction_moves_toward_the_better_technique() {
    // A 1-D stand-in for the directional domain: x in [0, 1], integrand
    // f(x) = 2x. One technique matches it (pdf 2x), the other is uniform.
    // Samples come from the mixture with the cell's current fraction s.
    fn run(bsdf_is_good: bool, seed: u64) -> Vec<f32> {
        let mut t = SdTree::new(
            scene(),
            SdTreeConfig {
                learn_bsdf_fraction: true,
                accumulation: Accumulation::Deterministic,
                ..config(1.0e9)
            },
        )
        .unwrap();
        let mut rng = Pcg32::seed_from_u64(seed);
        let p = Vec3::ZERO;
        let mut history = vec![t.bsdf_fraction_at(p)];
        for _ in 0..6 {
            let s = t.bsdf_fraction_at(p);
            for _ in 0..2000 {
                let pick_bsdf = unit(&mut rng) < s;
                let u = unit(&mut rng).max(1e-7);
                let good = u.sqrt(); // inverse CDF of 2x
                let x = if pick_bsdf == bsdf_is_good { good } else { u };
                let (pg, pu) = (2.0 * x, 1.0);
                let (pb, pguide) = if bsdf_is_good { (pg, pu) } else { (pu, pg) };
                let q = s * pb + (1.0 - s) * pguide;
                assert_ne!(
                    t.record_fraction_at(p, pb, pguide, 2.0 * x / q),
                    RecordOutcome::Dropped
                );
            }
            // Fixed during the iteration.
            assert_eq!(t.bsdf_fraction_at(p), s);
            t.refine();
            history.push(t.bsdf_fraction_at(p));
        }
        history
    }
    let up = run(true, 1);
    assert!(up.windows(2).all(|w| w[1] > w[0]), "{up:?}");
    assert!(*up.last().unwrap() > 0.9, "{up:?}");
    let down = run(false, 2);
    assert!(down.windows(2).all(|w| w[1] < w[0]), "{down:?}");
    assert!(*down.last().unwrap() < 0.1, "{down:?}");
    // Without learning the configured constant stays.
    let mut fixed = SdTree::new(
        scene(),
        SdTreeConfig {
            bsdf_fraction: 0.3,
            ..config(1.0e9)
        },
    )
    .unwrap();
    fixed.refine();
    assert_eq!(fixed.bsdf_fraction_at(Vec3::ZERO), 0.3);
    let m = fixed.mixture_pdf_at(Vec3::ZERO, Vec3::Z, 2.0);
    assert!((m - (0.3 * 2.0 + 0.7 * UNIFORM_PDF)).abs() < 1e-6);
}

/// One training input: position, direction, radiance, pdf and a fraction
/// record.
#[derive(Clone, Copy)]
struct Input {
    p: Vec3,
    dir: Vec3,
    radiance: f32,
    pdf: f32,
    fraction: (f32, f32, f32),
}

fn inputs(n: usize, seed: u64) -> Vec<Input> {
    let mut rng = Pcg32::seed_from_u64(seed);
    let b = scene();
    (0..n)
        .map(|_| Input {
            p: point_in(&mut rng, &b),
            dir: lobe_dir(&mut rng),
            radiance: -(1.0 - unit(&mut rng)).ln() * 3.0,
            pdf: 0.05 + 2.0 * unit(&mut rng),
            fraction: (unit(&mut rng) * 2.0, unit(&mut rng) * 2.0, unit(&mut rng)),
        })
        .collect()
}

fn apply(t: &SdTree, input: &Input) {
    assert_ne!(
        t.record_radiance_at(input.p, input.dir, input.radiance, input.pdf),
        RecordOutcome::Dropped
    );
    let (pb, pg, c) = input.fraction;
    assert_ne!(
        t.record_fraction_at(input.p, pb, pg, c),
        RecordOutcome::Dropped
    );
}

/// Feeds a batch with `threads` threads (0 = the calling thread, in
/// reverse order).
fn feed(t: &SdTree, batch: &[Input], threads: usize) {
    if threads == 0 {
        for input in batch.iter().rev() {
            apply(t, input);
        }
        return;
    }
    std::thread::scope(|s| {
        for k in 0..threads {
            s.spawn(move || {
                for input in batch.iter().skip(k).step_by(threads) {
                    apply(t, input);
                }
            });
        }
    });
}

/// Trains on every batch but the last with a refine after each, then feeds
/// the last without refining (so the building sums are compared too).
fn train_threaded(config: SdTreeConfig, data: &[Vec<Input>], threads: usize) -> SdTree {
    let mut t = SdTree::new(scene(), config).unwrap();
    let (last, refined) = data.split_last().unwrap();
    for batch in refined {
        feed(&t, batch, threads);
        t.refine();
    }
    feed(&t, last, threads);
    t
}

/// Everything learned, as bits.
fn fingerprint(t: &SdTree) -> Vec<u64> {
    let mut out = vec![t.cell_count() as u64];
    let tree = t.spatial();
    for c in tree.cells() {
        let b = tree.cell_bounds(c);
        out.extend(
            b.min
                .to_array()
                .iter()
                .chain(&b.max.to_array())
                .map(|x| x.to_bits() as u64),
        );
        let cell = tree.data(c);
        out.push(cell.fraction_logit().to_bits());
        out.push(cell.bsdf_fraction().to_bits() as u64);
        out.push(cell.building_weight().to_bits());
        for l in cell.directions().sampling_leaves() {
            out.extend([
                l.min[0].to_bits(),
                l.min[1].to_bits(),
                l.size.to_bits(),
                l.value.to_bits(),
            ]);
        }
        for l in cell.directions().building_leaves() {
            out.extend([l.min[0].to_bits(), l.size.to_bits(), l.value.to_bits()]);
        }
    }
    out
}

#[test]
fn threads_learn_exactly_what_one_thread_learns() {
    let config = SdTreeConfig {
        accumulation: Accumulation::Deterministic,
        spatial_filter: SpatialFilter::StochasticBox,
        directional_filter: DirectionalFilter::Box,
        learn_bsdf_fraction: true,
        ..config(400.0)
    };
    let data: Vec<Vec<Input>> = (0..3).map(|k| inputs(5000, k)).collect();
    let reference = train_threaded(config, &data, 0);
    assert!(reference.cell_count() > 4, "{}", reference.cell_count());
    let expect = fingerprint(&reference);
    for threads in [1, 3, 4] {
        let t = train_threaded(config, &data, threads);
        assert_eq!(fingerprint(&t), expect, "{threads} threads");
    }
    // The box spatial filter too.
    let boxed = SdTreeConfig {
        spatial_filter: SpatialFilter::Box,
        ..config
    };
    assert_eq!(
        fingerprint(&train_threaded(boxed, &data, 0)),
        fingerprint(&train_threaded(boxed, &data, 4))
    );

    // Fast mode loses no update: the weights of unit records add exactly.
    let fast = SdTreeConfig {
        accumulation: Accumulation::Fast,
        spatial_filter: SpatialFilter::Nearest,
        ..config
    };
    let weights = |t: &SdTree| {
        t.spatial()
            .data_slice()
            .iter()
            .map(|c| c.building_weight())
            .collect::<Vec<_>>()
    };
    let a = train_threaded(fast, &data[..2], 0);
    let b = train_threaded(fast, &data[..2], 4);
    assert_eq!(a.cell_count(), b.cell_count());
    assert_eq!(weights(&a), weights(&b));
    assert_eq!(weights(&b).iter().sum::<f64>(), data[1].len() as f64);
}
