//! The Guiding Light Tree over its own spatial tree ([`Glt`]): the
//! light-sampler contract at random points, learning that differs across
//! space, spatial refinement copying cuts, jittered records, bad input
//! counted, threads equal a serial run, and the memory report.

use glam::Vec3;
use guiding::RecordOutcome;
use guiding::cut::CutConfig;
use guiding::glt::{Glt, GltConfig, GltMemory};
use guiding::light_tree::BuildHeuristic;
use guiding::math::Accumulation;
use guiding::spatial::SpatialFilter;
use guiding::spatial::SpatialTree;
use guiding::{
    Emitter, LightHierarchy, LightId, LightSampler, LightTree, ShadingContext, UnboundedLights,
};

mod common;
use common::{ByPosition, LightsAt};
use common::{Rand, scene, two_rooms, value};

/// Trains `glt` for `iterations` iterations of `per_iteration` jittered
/// records, sampling lights from the GLT itself as a renderer would.
fn train<H: LightHierarchy>(
    glt: &mut Glt<H>,
    lights: &[Emitter],
    rng: &mut Rand,
    iterations: usize,
    per_iteration: usize,
) {
    for _ in 0..iterations {
        for _ in 0..per_iteration {
            let p = rng.point(9.5);
            let ctx = ShadingContext::at(p);
            let s = ByPosition(&*glt).sample(&ctx, rng.f()).unwrap();
            let LightId::Emitter(e) = s.light else {
                panic!()
            };
            let v = value(lights, e, p) / s.pmf;
            assert_ne!(glt.record_light_at(p, s.light, v), RecordOutcome::Dropped);
        }
        glt.refine();
    }
}

fn small_config() -> GltConfig {
    GltConfig {
        spatial_threshold: 500.0,
        ..GltConfig::default()
    }
}

/// Spatial cells learn different cuts: after training, a point in the left
/// room puts almost all mass on left lights and vice versa. Every cell's
/// cut is valid, and the light-sampler contract holds at random points.
#[test]
fn learns_per_region_and_keeps_the_contract() {
    let lights = two_rooms();
    let tree = LightTree::build(&lights, BuildHeuristic::Sarh).unwrap();
    let mut glt = Glt::new(&tree, scene(), small_config()).unwrap();
    let mut rng = Rand::new(1);
    train(&mut glt, &lights, &mut rng, 4, 8000);
    assert!(
        glt.spatial().cell_count() >= 4,
        "{}",
        glt.spatial().cell_count()
    );
    assert_eq!(glt.iteration(), 4);
    for cell in glt.spatial().data_slice() {
        cell.cut().check(&tree).unwrap();
    }
    let alpha = glt.config().cut.alpha;
    // Points whose cells' filter boxes do not reach across the wall (cells
    // next to it also learn from the other room through the +-1/2-cell
    // jitter, as PPG's stochastic box filter does).
    for (p, own) in [
        (Vec3::new(-8.0, 0.0, 0.0), 0..40u32),
        (Vec3::new(8.0, 1.0, -2.0), 40..80),
    ] {
        let ctx = ShadingContext::at(p);
        let mass: f64 = own
            .map(|e| ByPosition(&glt).pmf_exact(&ctx, LightId::Emitter(e)))
            .sum();
        // The prior puts about half on each side; the floor alone keeps
        // alpha / 2 on the other.
        assert!(mass > 1.0 - alpha * 0.5 - 0.02, "mass {mass} at {p}");
    }
    for _ in 0..20 {
        let ctx = ShadingContext::at(rng.point(12.0));
        let total: f64 = (0..80)
            .map(|e| ByPosition(&glt).pmf_exact(&ctx, LightId::Emitter(e)))
            .sum();
        assert!((total - 1.0).abs() < 1e-5, "{total}");
        assert_eq!(ByPosition(&glt).pmf(&ctx, LightId::Unbounded(0)), 0.0);
        for _ in 0..50 {
            let s = ByPosition(&glt).sample(&ctx, rng.f()).unwrap();
            assert_eq!(
                s.pmf.to_bits(),
                ByPosition(&glt).pmf(&ctx, s.light).to_bits()
            );
            let (light, p) = ByPosition(&glt).sample_exact(&ctx, rng.f64()).unwrap();
            assert_eq!(
                p.to_bits(),
                ByPosition(&glt).pmf_exact(&ctx, light).to_bits()
            );
        }
    }
    assert!(!ByPosition(&glt).is_empty());
}

/// When a cell splits, both halves start from a copy of its cut and
/// statistics; the halves its records came from trust what it learned
/// (confidence 1), the others, which no record reached, sample as the
/// prior does (confidence 0) until records of their own arrive.
#[test]
fn split_cells_inherit_the_cut_where_its_records_came_from() {
    let lights = two_rooms();
    let tree = LightTree::build(&lights, BuildHeuristic::Sarh).unwrap();
    // The paper's rules: one distribution per cell, so equal cuts and
    // confidences give equal pmfs anywhere.
    let config = GltConfig {
        spatial_threshold: 100.0,
        cut: CutConfig::default().with_paper_rules(),
        ..GltConfig::default()
    };
    let prior = Glt::new(&tree, scene(), config).unwrap();
    let mut glt = prior.clone();
    // All records in one corner, all for light 3: the root cell splits; its
    // halves refine from the same sums.
    let p = Vec3::new(-9.0, -9.0, -9.0);
    let near = ShadingContext::at(p);
    let far = ShadingContext::at(Vec3::new(9.0, 9.0, 9.0));
    for _ in 0..1000 {
        glt.record_light_at(p, LightId::Emitter(3), 2.0);
    }
    glt.refine();
    let cells = glt.spatial().cell_count();
    assert!(cells >= 2, "{cells}");
    let first = glt.spatial().data_slice()[0].cut().nodes().to_vec();
    assert!(first.len() > 1);
    for cell in glt.spatial().data_slice() {
        assert_eq!(cell.cut().nodes(), &first[..]);
        assert_eq!(cell.records(), 0);
    }
    let at = |glt: &Glt<&LightTree>, ctx: &ShadingContext| {
        let cell = glt.locate(ctx.position).unwrap();
        glt.spatial().data(cell).cut().confidence()
    };
    assert_eq!((at(&glt, &near), at(&glt, &far)), (1.0, 0.0));
    let alpha = glt.config().cut.alpha;
    let p3 = ByPosition(&glt).pmf_exact(&near, LightId::Emitter(3));
    let untrained3 = ByPosition(&prior).pmf_exact(&near, LightId::Emitter(3));
    assert!(p3 > 2.0 * untrained3, "{p3} against {untrained3}");
    for e in 0..lights.len() as u32 {
        let l = LightId::Emitter(e);
        let (learned, untrained) = (
            ByPosition(&glt).pmf_exact(&far, l),
            ByPosition(&prior).pmf_exact(&far, l),
        );
        assert!(
            (learned - untrained).abs() <= 1e-12 * untrained,
            "light {e}"
        );
    }
    // A round at the far corner: that cell learns from its own records.
    let q = far.position;
    for _ in 0..1000 {
        glt.record_light_at(q, LightId::Emitter(60), 2.0);
    }
    glt.refine();
    assert_eq!(at(&glt, &far), 1.0);
    let (p60, untrained60) = (
        ByPosition(&glt).pmf_exact(&far, LightId::Emitter(60)),
        ByPosition(&prior).pmf_exact(&far, LightId::Emitter(60)),
    );
    assert!(p60 > untrained60, "{p60} against {untrained60}");
    let room = |glt: &Glt<&LightTree>| -> f64 {
        (40..80)
            .map(|e| ByPosition(glt).pmf_exact(&far, LightId::Emitter(e)))
            .sum()
    };
    assert!(
        room(&glt) > 1.0 - alpha,
        "{} against {}",
        room(&glt),
        room(&prior)
    );
    // The corner cell saw nothing new: it keeps what it learned.
    assert_eq!(
        ByPosition(&glt)
            .pmf_exact(&near, LightId::Emitter(3))
            .to_bits(),
        p3.to_bits()
    );
}

/// The stochastic box: records near a cell border land on both sides, in
/// proportion to the overlap of the +-1/2-cell box with each; the
/// deterministic variant never crosses.
#[test]
fn jitter_spreads_over_neighbouring_cells() {
    let lights = two_rooms();
    let tree = LightTree::build(&lights, BuildHeuristic::Sarh).unwrap();
    let config = GltConfig {
        spatial_threshold: 10.0,
        light_filter: SpatialFilter::StochasticBox,
        ..GltConfig::default()
    };
    let mut glt = Glt::new(&tree, scene(), config).unwrap();
    // Split the root once: cells meet at x = 0 (the cube is about [-10, 10]).
    for _ in 0..15 {
        glt.record_light_at(Vec3::ZERO, LightId::Emitter(0), 1.0);
    }
    glt.refine();
    assert_eq!(glt.spatial().cell_count(), 2);
    let side = glt
        .spatial()
        .cell_bounds(glt.locate(Vec3::new(-1.0, 0.0, 0.0)).unwrap())
        .diagonal()
        .x;
    let p = Vec3::new(-0.25 * side, 0.0, 0.0);
    let here = glt.locate(p).unwrap();
    // The offset is a hash of the record: records at points apart by a
    // hair (along z, which does not move the box across the x border).
    for k in 0..4000 {
        let q = p + Vec3::new(0.0, 0.0, k as f32 * 1e-4);
        glt.record_light_at(q, LightId::Emitter(1), 1.0);
    }
    let counts: Vec<u64> = glt
        .spatial()
        .data_slice()
        .iter()
        .map(|c| c.records())
        .collect();
    let other = 1 - here.index();
    // A box of one cell width centred a quarter cell from the border
    // overlaps the neighbour by a quarter.
    let share = counts[other] as f64 / 4000.0;
    assert!((share - 0.25).abs() < 0.03, "{counts:?}");
}

/// Bad input is dropped and counted, never recorded: non-finite or
/// negative values, non-finite positions, emitters out of range or with
/// zero power, unbounded lights when none is configured.
#[test]
fn bad_records_are_counted() {
    let mut lights = two_rooms();
    lights[5].power = 0.0;
    let tree = LightTree::build(&lights, BuildHeuristic::Sarh).unwrap();
    let mut glt = Glt::new(&tree, scene(), GltConfig::default()).unwrap();
    let p = Vec3::ONE;
    let bad = [
        (p, LightId::Emitter(1), f32::NAN),
        (p, LightId::Emitter(1), -2.0),
        (p, LightId::Emitter(1), f32::INFINITY),
        (Vec3::new(f32::NAN, 0.0, 0.0), LightId::Emitter(1), 1.0),
        (p, LightId::Emitter(80), 1.0),
        (p, LightId::Emitter(u32::MAX), 1.0),
        (p, LightId::Emitter(5), 1.0),
        (p, LightId::Unbounded(0), 1.0),
    ];
    for &(q, light, v) in &bad {
        let before = glt.dropped_records();
        assert_eq!(glt.record_light_at(q, light, v), RecordOutcome::Dropped);
        assert_eq!(glt.record_light_at(q, light, v), RecordOutcome::Dropped);
        // A non-finite point has no vertex: counted as a position.
        let (light, position) = if q.is_finite() { (2, 0) } else { (0, 2) };
        assert_eq!(glt.dropped_records().light, before.light + light);
        assert_eq!(glt.dropped_records().position, before.position + position);
    }
    assert_eq!(
        glt.record_light_at(p, LightId::Emitter(1), 0.0),
        RecordOutcome::Zero
    );
    assert_eq!(
        glt.record_light_at(p, LightId::Emitter(1), 1.0),
        RecordOutcome::Recorded
    );
    assert_eq!(glt.dropped_records().light, 14);
    assert_eq!(glt.dropped_records().total(), 16);
    glt.reset_dropped_records();
    assert_eq!(glt.dropped_records().total(), 0);
    let (emitters, env) = glt
        .vertex(&ShadingContext::at(p))
        .unwrap()
        .cut()
        .accumulated();
    assert_eq!((emitters, env), (1.0, 0.0));
    assert_eq!(glt.spatial().data_slice()[0].records(), 2);
    // Queries at non-finite points: nothing, consistently.
    let nan = ShadingContext::at(Vec3::splat(f32::NAN));
    assert!(ByPosition(&glt).sample(&nan, 0.5).is_none());
    assert_eq!(ByPosition(&glt).pmf(&nan, LightId::Emitter(0)), 0.0);
}

/// A sun and a sky (two unbounded lights): each one's share is learned per
/// cell beside the cut, each keeps its prior floor `alpha q / 2`, the pmf
/// still sums to one and sampling follows it.
#[test]
fn unbounded_shares_are_learned() {
    let lights = two_rooms();
    let tree = LightTree::build(&lights, BuildHeuristic::Sarh).unwrap();
    let config = GltConfig {
        cut: CutConfig {
            unbounded: UnboundedLights::new(2, 0.3).unwrap(),
            ..CutConfig::default()
        },
        ..GltConfig::default()
    };
    let mut glt = Glt::new(&tree, scene(), config).unwrap();
    let ctx = ShadingContext::at(Vec3::ZERO);
    let (sky, sun) = (LightId::Unbounded(0), LightId::Unbounded(1));
    for light in [sky, sun] {
        assert!((ByPosition(&glt).pmf_exact(&ctx, light) - 0.15).abs() < 1e-7);
    }
    assert_eq!(ByPosition(&glt).pmf(&ctx, LightId::Unbounded(2)), 0.0);
    for _ in 0..100 {
        glt.record_light_at(Vec3::ZERO, sky, 3.0);
        glt.record_light_at(Vec3::ZERO, LightId::Emitter(7), 1.0);
    }
    glt.refine();
    // The sky took 3/4 of what the cell saw; the sun nothing, so it keeps
    // only its floor (a delta light BSDF sampling never finds: without the
    // floor its light would be lost, a bias).
    let alpha = glt.config().cut.alpha;
    let expect = [(1.0 - alpha) * 0.75 + alpha * 0.15, alpha * 0.15];
    let got = [
        ByPosition(&glt).pmf_exact(&ctx, sky),
        ByPosition(&glt).pmf_exact(&ctx, sun),
    ];
    for (g, e) in got.iter().zip(expect) {
        assert!((g - e).abs() < 1e-6, "{got:?} vs {expect:?}");
    }
    assert!(got[1] > 0.0);
    let total: f64 = got.iter().sum::<f64>()
        + (0..80)
            .map(|e| ByPosition(&glt).pmf_exact(&ctx, LightId::Emitter(e)))
            .sum::<f64>();
    assert!((total - 1.0).abs() < 1e-6);
    // Sampling: each unbounded light is chosen at its pmf (3-sigma bounds
    // of 40,000 draws), with the pmf it reports.
    let mut rng = Rand::new(9);
    let mut hits = [0u32; 2];
    const N: u32 = 40_000;
    for _ in 0..N {
        let s = ByPosition(&glt).sample(&ctx, rng.f()).unwrap();
        assert_eq!(s.pmf, ByPosition(&glt).pmf(&ctx, s.light));
        match s.light {
            LightId::Unbounded(i) => hits[i as usize] += 1,
            LightId::Emitter(_) => {}
        }
    }
    for (h, e) in hits.iter().zip(expect) {
        let sd = (e * (1.0 - e) / f64::from(N)).sqrt();
        assert!(
            (f64::from(*h) / f64::from(N) - e).abs() < 3.0 * sd + 1e-4,
            "{hits:?}"
        );
    }
    // The sun gets its own learned share once it is seen (twice the
    // records of the first round: the cell takes part again).
    for _ in 0..200 {
        glt.record_light_at(Vec3::ZERO, sun, 2.0);
        glt.record_light_at(Vec3::ZERO, sky, 2.0);
    }
    glt.refine();
    let (a, b) = (
        ByPosition(&glt).pmf_exact(&ctx, sky),
        ByPosition(&glt).pmf_exact(&ctx, sun),
    );
    assert!((a - b).abs() < 1e-6 && a > 0.4, "{a} {b}");
}

/// Jitter-free records from four threads equal a serial run: bit for bit in
/// deterministic mode, including the spatial splits and cell counts.
#[test]
fn threads_equal_serial() {
    let lights = two_rooms();
    let tree = LightTree::build(&lights, BuildHeuristic::Sarh).unwrap();
    let config = GltConfig {
        cut: CutConfig {
            accumulation: Accumulation::Deterministic,
            ..CutConfig::default()
        },
        spatial_threshold: 300.0,
        ..GltConfig::default()
    };
    let mut rng = Rand::new(12);
    let stream: Vec<(Vec3, u32, f32)> = (0..24_000)
        .map(|_| {
            let p = rng.point(9.5);
            let e = (rng.f() * 80.0) as u32;
            (p, e, value(&lights, e, p) * rng.range(0.5, 1.5))
        })
        .collect();
    let mut serial = Glt::new(&tree, scene(), config).unwrap();
    let mut parallel = Glt::new(&tree, scene(), config).unwrap();
    for chunk in stream.chunks(8000) {
        for &(p, e, v) in chunk {
            serial.record_light_at(p, LightId::Emitter(e), v);
        }
        std::thread::scope(|s| {
            for t in 0..4 {
                let glt = &parallel;
                s.spawn(move || {
                    for &(p, e, v) in chunk.iter().skip(t).step_by(4) {
                        glt.record_light_at(p, LightId::Emitter(e), v);
                    }
                });
            }
        });
        serial.refine();
        parallel.refine();
        let (a, b) = (
            serial.spatial().data_slice(),
            parallel.spatial().data_slice(),
        );
        assert_eq!(a.len(), b.len());
        for (x, y) in a.iter().zip(b) {
            let (x, y): (&[u8], &[u8]) = (
                bytemuck::cast_slice(x.cut().nodes()),
                bytemuck::cast_slice(y.cut().nodes()),
            );
            assert_eq!(x, y);
        }
    }
    assert!(serial.spatial().cell_count() > 4);
}

/// The memory report: 12 bytes per cut node, parts add up to the total.
#[test]
fn memory_report_adds_up() {
    let lights = two_rooms();
    let tree = LightTree::build(&lights, BuildHeuristic::Sarh).unwrap();
    let mut glt = Glt::new(&tree, scene(), small_config()).unwrap();
    let mut rng = Rand::new(2);
    train(&mut glt, &lights, &mut rng, 3, 4000);
    let m = glt.memory();
    assert_eq!(GltMemory::BYTES_PER_CUT_NODE, 12);
    assert_eq!(m.cells, glt.spatial().cell_count());
    let nodes: usize = glt
        .spatial()
        .data_slice()
        .iter()
        .map(|c| c.cut().nodes().len())
        .sum();
    assert_eq!(m.cuts.nodes, nodes);
    assert_eq!(m.cuts.node_bytes, 12 * nodes);
    // One sum per slot (no unbounded light here), and the default
    // modulation's 7 anchor sums, per cell.
    assert_eq!(m.cuts.sum_bytes, 8 * (2 * nodes + 7 * m.cells));
    assert_eq!(m.spatial_bytes, glt.spatial().bytes());
    // Split table 4 B per node; walk table one 16-B pair per inner node +
    // root and an 8-B path code per emitter; the default importance rules'
    // table one 64-B pair beside it.
    assert_eq!(
        m.shared_bytes,
        4 * tree.node_count() + (8 + 32) * (tree.node_count() + 1) + 8 * tree.emitter_count()
    );
    assert_eq!(
        m.total(),
        m.spatial_bytes + m.shared_bytes + m.cuts.node_bytes + m.cuts.sum_bytes
    );
    let per_cell = (m.total() - m.shared_bytes) as f64 / m.cells as f64;
    assert_eq!(m.bytes_per_cell(), per_cell);
    assert!(per_cell > 12.0 * m.cuts.nodes as f64 / m.cells as f64);
}

/// One refinement splits a cell as many levels deep as its count allows,
/// each half taken to have half its parent's records (PPG's rule): 1,000
/// records at threshold 100 split the root while the count is above it
/// (1,000, 500, 250, 125; not 62), 4 levels, 1 + 2 + 4 + 8 = 15 splits.
#[test]
fn one_refinement_splits_as_deep_as_the_count_allows() {
    let lights = two_rooms();
    let tree = LightTree::build(&lights, BuildHeuristic::Sarh).unwrap();
    let config = GltConfig {
        spatial_threshold: 100.0,
        ..GltConfig::default()
    };
    let mut glt = Glt::new(&tree, scene(), config).unwrap();
    for _ in 0..1000 {
        glt.record_light_at(Vec3::new(-9.0, -9.0, -9.0), LightId::Emitter(3), 2.0);
    }
    let out = glt.refine();
    assert_eq!((out.splits, out.refused_by_budget), (15, 0));
    assert_eq!(glt.spatial().cell_count(), 16);
    // Every cell took part, so its next threshold is 100 sqrt(2) = 141.4:
    // 142 records in the far corner's cell (none of the first 1,000 fell
    // there, so any number makes it take part) split it once more, its
    // halves' 71 do not split them.
    for _ in 0..142 {
        glt.record_light_at(Vec3::new(9.0, 9.0, 9.0), LightId::Emitter(3), 2.0);
    }
    assert_eq!(glt.refine().splits, 1);
    // The first corner's cell holds its share of the first 1,000: all of
    // them for three splits (x, y, z: its octants tell), half at the
    // fourth (along x again, where its octants no longer tell): 500. So
    // 749 more records do not make it take part, 750 do.
    let corner = Vec3::new(-9.0, -9.0, -9.0);
    for _ in 0..749 {
        glt.record_light_at(corner, LightId::Emitter(3), 2.0);
    }
    assert_eq!(glt.refine().splits, 0);
    glt.record_light_at(corner, LightId::Emitter(3), 2.0);
    assert!(glt.refine().splits > 0);
}

/// A renderer keeps its lights and its guiding state in one struct: the GLT
/// owns its light tree or shares it through `Arc`, and samples exactly as a
/// GLT borrowing the same tree does.
#[test]
fn owns_or_shares_its_light_tree() {
    use std::sync::Arc;
    struct Renderer {
        lights: Arc<LightTree>,
        guide: Glt<Arc<LightTree>>,
        owned: Glt<LightTree>,
    }
    fn assert_send_sync<T: Send + Sync>() {}
    assert_send_sync::<Renderer>();
    let lights = two_rooms();
    let tree = LightTree::build(&lights, BuildHeuristic::Sarh).unwrap();
    let shared = Arc::new(tree.clone());
    let mut r = Renderer {
        lights: shared.clone(),
        guide: Glt::new(shared, scene(), small_config()).unwrap(),
        owned: Glt::new(tree.clone(), scene(), small_config()).unwrap(),
    };
    let mut borrowed = Glt::new(&tree, scene(), small_config()).unwrap();
    let (mut a, mut b, mut c) = (Rand::new(3), Rand::new(3), Rand::new(3));
    train(&mut r.guide, &lights, &mut a, 3, 2000);
    train(&mut r.owned, &lights, &mut b, 3, 2000);
    train(&mut borrowed, &lights, &mut c, 3, 2000);
    assert_eq!(r.lights.emitter_count(), lights.len());
    let mut rng = Rand::new(9);
    for _ in 0..200 {
        let ctx = ShadingContext::at(rng.point(9.5));
        let u = rng.f();
        let s = ByPosition(&borrowed).sample(&ctx, u);
        assert_eq!(ByPosition(&r.guide).sample(&ctx, u), s);
        assert_eq!(ByPosition(&r.owned).sample(&ctx, u), s);
    }
}
