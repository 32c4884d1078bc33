//! The combined guiding field ([`GuidingField`]): one lookup gives what a
//! separate SD-tree and GLT give, the light-sampler and direction-pdf
//! contracts at random points, spatial splits copying both payloads, bad
//! input counted, threads equal a serial run, and the memory report.

use glam::Vec3;
use guiding::LightChoice;
use guiding::RecordOutcome;
use guiding::cut::{BelowCut, CutConfig, CutRules, GuidingCut};
use guiding::field::{FieldConfig, GuidingField};
use guiding::glt::{Glt, GltConfig};
use guiding::light_tree::BuildHeuristic;
use guiding::math::{Aabb, Accumulation, canonical_to_dir};
use guiding::quadtree::UNIFORM_PDF;
use guiding::sd_tree::{SdCell, SdTree, SdTreeConfig};
use guiding::spatial::SpatialFilter;
use guiding::spatial::{RefineOutcome, SpatialTree};
use guiding::{
    Emitter, LightHierarchy, LightId, LightSampler, LightTree, ShadingContext, UnboundedLights,
};
use proptest::prelude::*;
use rand_pcg::Pcg32;

mod common;
use common::{ByPosition, DirectionsAt, LightsAt};
use common::{scene, two_rooms_with, value};

/// The shared generator over `Pcg32`: these tests were tuned on its streams.
type Rand = common::Rand<Pcg32>;

/// The two rooms drawn from `Pcg32`.
fn two_rooms() -> Vec<Emitter> {
    two_rooms_with::<Pcg32>()
}

/// The two rooms and their light tree.
fn rooms() -> (Vec<Emitter>, LightTree) {
    let lights = two_rooms();
    let tree = LightTree::build(&lights, BuildHeuristic::Sarh).unwrap();
    (lights, tree)
}

/// `sd` with spatial threshold `c`.
fn sd_with(c: f64, sd: SdTreeConfig) -> SdTreeConfig {
    SdTreeConfig {
        spatial_threshold: c,
        ..sd
    }
}

/// Field defaults with the SD-tree's `sd` at spatial threshold `c`.
fn config_with(c: f64, sd: SdTreeConfig) -> FieldConfig {
    FieldConfig {
        sd: sd_with(c, sd),
        ..FieldConfig::default()
    }
}

/// A direction toward one of the lights of `p`'s room, slightly perturbed.
fn light_dir(lights: &[Emitter], p: Vec3, rng: &mut Rand) -> Vec3 {
    let k = (rng.f() * 40.0) as usize + if p.x < 0.0 { 0 } else { 40 };
    let d = lights[k].bounds.center() - p + 0.3 * rng.point(1.0);
    d.normalize()
}

fn emitter(light: LightId) -> u32 {
    match light {
        LightId::Emitter(e) => e,
        LightId::Unbounded(_) => panic!("no unbounded lights in these scenes"),
    }
}

fn cut_bytes(cut: &GuidingCut) -> &[u8] {
    bytemuck::cast_slice(cut.nodes())
}

/// Everything an SD cell learned, as bits.
fn sd_bits(cell: &SdCell) -> Vec<u64> {
    let mut out = vec![
        cell.fraction_logit().to_bits(),
        cell.bsdf_fraction().to_bits() as u64,
        cell.building_weight().to_bits(),
    ];
    for l in cell.directions().sampling_leaves() {
        out.extend([l.min[0], l.min[1], l.size, l.value].map(f64::to_bits));
    }
    for l in cell.directions().building_leaves() {
        out.extend([l.min[0], l.min[1], l.size, l.value].map(f64::to_bits));
    }
    out
}

fn bounds_bits(b: Aabb) -> [u32; 6] {
    let (a, c) = (b.min.to_array(), b.max.to_array());
    [a[0], a[1], a[2], c[0], c[1], c[2]].map(f32::to_bits)
}

/// The field against an [`SdTree`] fed the same radiance records and
/// fraction records (with identically seeded generators) and, per cell of
/// that SD-tree, a cut of its own fed the same light records through the
/// [`CutRules`] (cuts copied to both children when the SD-tree splits a
/// cell). All records and queries go through one [`FieldVertex`] lookup per
/// point; the SD-tree and the cuts are asked by position. Everything is
/// equal bit for bit: spatial decisions, quadtrees, fractions, cuts, pdfs,
/// pmfs and samples.
///
/// [`FieldVertex`]: guiding::field::FieldVertex
#[test]
fn one_lookup_equals_a_separate_sd_tree_and_cuts() {
    let (lights, tree) = rooms();
    let sd_config = sd_with(300.0, SdTreeConfig::improved());
    let config = FieldConfig {
        light_filter: SpatialFilter::Nearest,
        ..config_with(300.0, sd_config)
    };
    let mut field = GuidingField::new(&tree, scene(), config).unwrap();
    let mut sd = SdTree::new(scene(), sd_config).unwrap();
    let guide = CutRules::new(&tree, config.cut).unwrap();
    let mut cuts = vec![guide.new_cut()];
    let mut rng = Rand::seeded(1);
    let (mut learned, mut doubted) = (false, false);
    for it in 0..5 {
        for _ in 0..(3000usize << it.min(2)) {
            // The first pass covers only the half x < 0 (as a renderer
            // that renders tile by tile might): the other half's cells
            // start from the prior.
            let p = match rng.point(9.8) {
                p if it == 0 => Vec3::new(-p.x.abs(), p.y, p.z),
                p => p,
            };
            let ctx = ShadingContext::at(p);
            let v = field.vertex(&ctx).unwrap();
            let cut = &cuts[sd.spatial().locate(p).unwrap().index()];
            // NEE: the vertex's cut and the reference cut agree.
            let u = rng.f();
            let s = v.light.sample(u).unwrap();
            assert_eq!(Some(s), guide.sample(cut, &ctx, u));
            assert_eq!(s.pmf.to_bits(), guide.pmf(cut, &ctx, s.light).to_bits());
            let val = value(&lights, emitter(s.light), p) / s.pmf;
            assert_eq!(
                v.light.record_light(s.light, val),
                guide.record_from(cut, p, s.light, val)
            );
            // Directions: sample, pdf, fraction, mixture.
            let u = [rng.f(), rng.f()];
            let (dir, pdf) = v.direction.sample_direction(u);
            assert_eq!(Some((dir, pdf)), sd.sample_direction_at(p, u));
            assert_eq!(v.direction.direction_pdf(dir).to_bits(), pdf.to_bits());
            assert_eq!(
                v.direction.bsdf_fraction().to_bits(),
                sd.bsdf_fraction_at(p).to_bits()
            );
            assert_eq!(
                v.direction.mixture_pdf(dir, 0.3).to_bits(),
                sd.mixture_pdf_at(p, dir, 0.3).to_bits()
            );
            learned |= v.direction.bsdf_fraction() != 0.5;
            // PPG's record with the stochastic box (its offset hashed from
            // the record: the same for both).
            let d = light_dir(&lights, p, &mut rng);
            let radiance = rng.range(0.0, 4.0);
            assert_ne!(
                v.direction.record_radiance(d, radiance, UNIFORM_PDF),
                RecordOutcome::Dropped
            );
            assert_ne!(
                sd.record_radiance_at(p, d, radiance, UNIFORM_PDF),
                RecordOutcome::Dropped
            );
            let (pb, pg, c) = (rng.f(), pdf, rng.range(0.0, 2.0));
            assert_ne!(
                v.direction.record_fraction(pb, pg, c),
                RecordOutcome::Dropped
            );
            assert_ne!(sd.record_fraction_at(p, pb, pg, c), RecordOutcome::Dropped);
        }
        // The reference's refinement: cuts first, then the SD-tree; a cell
        // born of a split takes its parent's (refined) cut.
        for cut in &mut cuts {
            guide.refine(cut);
        }
        let before = sd.spatial().map_ref(|_| ());
        assert_eq!(field.refine(), sd.refine());
        let after = sd.spatial();
        cuts = after
            .cells()
            .map(|c| {
                let parent = before.locate(after.cell_bounds(c).center()).unwrap();
                cuts[parent.index()].clone()
            })
            .collect();
        assert_eq!(field.iteration(), sd.iteration());
        assert_eq!(field.cell_count(), sd.cell_count());
        let cells = field.spatial();
        for c in cells.cells() {
            let (a, b) = (cells.data(c), after.data(c));
            // How far a split half trusts its copy is the field's to say
            // (tests/glt_field.rs checks it); everything else must agree.
            let confidence = a.cut().confidence();
            doubted |= confidence < 1.0;
            cuts[c.index()].set_confidence(confidence).unwrap();
            assert_eq!(
                bounds_bits(cells.cell_bounds(c)),
                bounds_bits(after.cell_bounds(c))
            );
            assert_eq!(sd_bits(a.sd()), sd_bits(b));
            assert_eq!(cut_bytes(a.cut()), cut_bytes(&cuts[c.index()]));
            a.cut().check(&tree).unwrap();
        }
    }
    assert!(field.cell_count() > 8, "{}", field.cell_count());
    assert!(learned && doubted);
    // Exact pmfs and samples at random points, through the vertex.
    for _ in 0..200 {
        let p = rng.point(11.0);
        let ctx = ShadingContext::at(p);
        let cut = &cuts[sd.spatial().locate(p).unwrap().index()];
        let v = field.vertex(&ctx).unwrap();
        for e in [0, 17, 39, 40, 79] {
            let l = LightId::Emitter(e);
            let x = guide.pmf_exact(cut, &ctx, l).to_bits();
            assert_eq!(v.light.pmf_exact(l).to_bits(), x);
        }
        let u = rng.f64();
        assert_eq!(v.light.sample_exact(u), guide.sample_exact(cut, &ctx, u));
    }
}

/// The field against a [`Glt`] over its own spatial tree. The two split
/// cells by different counts (the field by radiance-record weight, halved
/// exactly; the GLT by its number of light records, halved as an integer),
/// so their spatial decisions agree when every light record comes with a
/// radiance record at the same point, both go to the cell holding it (the
/// nearest filter: a jittered light record may land in a neighbour the
/// radiance record does not reach) and counts stay multiples of 16 (no
/// cascade here halves more than 3 times). Then cells, cuts, pmfs and
/// samples are equal bit for bit.
#[test]
fn equals_a_glt_fed_the_same_light_records() {
    let (lights, tree) = rooms();
    let cut = CutConfig {
        accumulation: Accumulation::Deterministic,
        ..CutConfig::default()
    };
    let mut glt = Glt::new(
        &tree,
        scene(),
        GltConfig {
            cut,
            spatial_threshold: 200.0,
            max_bytes: None,
            light_filter: SpatialFilter::Nearest,
        },
    )
    .unwrap();
    let config = FieldConfig {
        cut,
        light_filter: SpatialFilter::Nearest,
        ..config_with(200.0, SdTreeConfig::default())
    };
    let mut field = GuidingField::new(&tree, scene(), config).unwrap();
    let mut rng = Rand::seeded(4);
    let compare = |field: &GuidingField<&LightTree>, glt: &Glt<&LightTree>, rng: &mut Rand| {
        assert_eq!(field.cell_count(), glt.spatial().cell_count());
        for c in field.spatial().cells() {
            let b = field.spatial().cell_bounds(c);
            assert_eq!(bounds_bits(b), bounds_bits(glt.spatial().cell_bounds(c)));
            let (x, y) = (field.spatial().data(c).cut(), glt.spatial().data(c).cut());
            assert_eq!(cut_bytes(x), cut_bytes(y));
            let (xa, ya) = (x.accumulated(), y.accumulated());
            assert_eq!(
                (xa.0.to_bits(), xa.1.to_bits()),
                (ya.0.to_bits(), ya.1.to_bits())
            );
        }
        for _ in 0..100 {
            let ctx = ShadingContext::at(rng.point(10.5));
            let u = rng.f();
            assert_eq!(
                ByPosition(field).sample(&ctx, u),
                ByPosition(glt).sample(&ctx, u)
            );
            let v = field.vertex(&ctx).unwrap();
            assert_eq!(v.light.sample(u), ByPosition(glt).sample(&ctx, u));
            for e in [3, 44, 71] {
                let l = LightId::Emitter(e);
                assert_eq!(
                    ByPosition(field).pmf(&ctx, l).to_bits(),
                    ByPosition(glt).pmf(&ctx, l).to_bits()
                );
                assert_eq!(
                    v.light.pmf_exact(l).to_bits(),
                    ByPosition(glt).pmf_exact(&ctx, l).to_bits()
                );
            }
        }
    };
    for round in 0..4 {
        // Growing batches: every cell of the GLT holds 3/2 of what its last
        // refinement used, so it takes part in every refinement as each
        // cell of the field does.
        for _ in 0..(150 << (2 * round)) {
            let p = rng.point(9.8);
            let e = (rng.f() * 80.0) as u32;
            let v = value(&lights, e, p) * rng.range(0.5, 1.5);
            let d = light_dir(&lights, p, &mut rng);
            for _ in 0..16 {
                let l = LightId::Emitter(e);
                assert_eq!(field.record_light_at(p, l, v), glt.record_light_at(p, l, v));
                assert_ne!(
                    field.record_radiance_at(p, d, 1.0, UNIFORM_PDF),
                    RecordOutcome::Dropped
                );
            }
        }
        compare(&field, &glt, &mut rng);
        field.refine();
        glt.refine();
        compare(&field, &glt, &mut rng);
    }
    assert!(field.cell_count() > 8, "{}", field.cell_count());
    // More records, fewer than any cell of the GLT needs to split: the
    // cells stay, the cuts learn the same.
    for _ in 0..300 {
        let p = rng.point(9.8);
        let e = (rng.f() * 80.0) as u32;
        let v = value(&lights, e, p);
        let l = LightId::Emitter(e);
        assert_eq!(field.record_light_at(p, l, v), glt.record_light_at(p, l, v));
    }
    compare(&field, &glt, &mut rng);
    let cells = field.cell_count();
    field.refine();
    glt.refine();
    assert_eq!(field.cell_count(), cells);
    compare(&field, &glt, &mut rng);
}

/// Random lights with some dark ones, random environment probability and
/// below-cut rule.
fn random_lights(rng: &mut Rand, n: usize, dark: usize) -> Vec<Emitter> {
    (0..n)
        .map(|i| {
            let power = if i < dark { 0.0 } else { rng.range(0.01, 5.0) };
            Emitter::point(rng.point(9.0), power)
        })
        .collect()
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 16, ..ProptestConfig::default() })]

    /// After random records and refinements, at random points: every cut is
    /// valid, the pmf sums to 1 (emitters and environment), sampling's pmf
    /// equals `pmf` bit for bit (through the vertex, `f32` and
    /// `f64`), and sampled directions' pdfs equal `direction_pdf`.
    #[test]
    fn contract_at_random_points(
        seed in any::<u64>(),
        n in 1usize..40,
        dark in 0usize..3,
        unbounded in 0u32..3,
        share in 1e-6f64..0.6,
        importance in any::<bool>(),
        iterations in 0usize..4,
    ) {
        let mut rng = Rand::seeded(seed);
        let dark = dark.min(n - 1);
        let lights = random_lights(&mut rng, n, dark);
        let tree = LightTree::build(&lights, BuildHeuristic::Sarh).unwrap();
        let config = FieldConfig {
            cut: CutConfig {
                unbounded: match unbounded {
                    0 => UnboundedLights::NONE,
                    k => UnboundedLights::new(k, share).unwrap(),
                },
                below_cut: if importance { BelowCut::Importance } else { BelowCut::Power },
                ..CutConfig::default()
            },
            ..config_with(60.0, SdTreeConfig::improved())
        };
        let mut field = GuidingField::new(&tree, scene(), config).unwrap();
        for _ in 0..iterations {
            for _ in 0..(200 + (rng.f() * 600.0) as usize) {
                let p = rng.point(10.5);
                let v = field.vertex(&ShadingContext::at(p)).unwrap();
                if let Some(s) = v.light.sample(rng.f()) {
                    let val = if rng.f() < 0.3 { 0.0 } else { rng.range(0.0, 3.0) / s.pmf };
                    prop_assert_ne!(v.light.record_light(s.light, val), RecordOutcome::Dropped);
                }
                let (d, _) = v.direction.sample_direction([rng.f(), rng.f()]);
                prop_assert_ne!(v.direction.record_radiance(d, rng.range(0.0, 2.0), 0.5), RecordOutcome::Dropped);
            }
            field.refine();
        }
        for cell in field.spatial().data_slice() {
            prop_assert!(cell.cut().check(&tree).is_ok());
        }
        for _ in 0..25 {
            let p = rng.point(11.0);
            let ctx = ShadingContext::on_surface(p, rng.point(1.0).normalize_or(Vec3::Z));
            let v = field.vertex(&ctx).unwrap();
            let mut total: f64 = (0..n as u32)
                .map(|e| v.light.pmf_exact(LightId::Emitter(e)))
                .sum();
            total += (0..unbounded).map(|i| v.light.pmf_exact(LightId::Unbounded(i))).sum::<f64>();
            prop_assert!((total - 1.0).abs() < 1e-5, "pmf sums to {}", total);
            for _ in 0..20 {
                let u = rng.f();
                let s = v.light.sample(u).unwrap();
                prop_assert_eq!(s.pmf.to_bits(), v.light.pmf(s.light).to_bits());
                prop_assert_eq!(s.pmf.to_bits(), ByPosition(&field).pmf(&ctx, s.light).to_bits());
                let (l, q) = v.light.sample_exact(rng.f64()).unwrap();
                prop_assert_eq!(q.to_bits(), v.light.pmf_exact(l).to_bits());
                let (d, pdf) = v.direction.sample_direction([rng.f(), rng.f()]);
                prop_assert!(pdf > 0.0);
                prop_assert_eq!(pdf.to_bits(), v.direction.direction_pdf(d).to_bits());
            }
        }
    }
}

/// A field trained on the two rooms for four iterations (vertex API, the
/// default stochastic-box light records).
/// `after_refine` sees the field and each refinement's outcome.
fn trained_field<'a>(
    tree: &'a LightTree,
    lights: &[Emitter],
    config: FieldConfig,
    mut after_refine: impl FnMut(&GuidingField<&'a LightTree>, RefineOutcome),
) -> GuidingField<&'a LightTree> {
    let mut field = GuidingField::new(tree, scene(), config).unwrap();
    let mut rng = Rand::seeded(8);
    for it in 0..4 {
        for _ in 0..(3000usize << it.min(2)) {
            // The first pass covers only the half x < 0 (as a renderer
            // that renders tile by tile might): the other half's cells
            // start from the prior.
            let p = match rng.point(9.8) {
                p if it == 0 => Vec3::new(-p.x.abs(), p.y, p.z),
                p => p,
            };
            let v = field.vertex(&ShadingContext::at(p)).unwrap();
            let s = v.light.sample(rng.f()).unwrap();
            let val = value(lights, emitter(s.light), p) / s.pmf;
            assert_ne!(v.light.record_light(s.light, val), RecordOutcome::Dropped);
            let d = light_dir(lights, p, &mut rng);
            assert_ne!(
                v.direction.record_radiance(d, 1.0, UNIFORM_PDF),
                RecordOutcome::Dropped
            );
        }
        let outcome = field.refine();
        after_refine(&field, outcome);
    }
    field
}

/// In every cell the learned directional density integrates to 1 (exact
/// quadrature: it is constant on each quadtree leaf), is concentrated, and
/// the light selection learned its room.
#[test]
fn direction_pdf_integrates_to_one_in_every_cell() {
    let (lights, tree) = rooms();
    let config = config_with(400.0, SdTreeConfig::default());
    let field = trained_field(&tree, &lights, config, |_, _| {});
    assert!(field.cell_count() > 8, "{}", field.cell_count());
    let mut deep = 0;
    for c in field.spatial().cells() {
        let p = field.spatial().cell_bounds(c).center();
        let v = field.vertex(&ShadingContext::at(p)).unwrap();
        assert_eq!(v.direction.cell(), c);
        let leaves = v.direction.sd().directions().sampling_leaves();
        deep += (leaves.len() > 16) as usize;
        let integral: f64 = leaves
            .iter()
            .map(|l| {
                v.direction.direction_pdf(canonical_to_dir(l.center())) as f64
                    * l.area()
                    * 4.0
                    * core::f64::consts::PI
            })
            .sum();
        assert!((integral - 1.0).abs() < 1e-4, "cell {c:?}: {integral}");
    }
    assert!(
        deep * 2 > field.cell_count(),
        "{deep} of {}",
        field.cell_count()
    );
    let alpha = field.config().cut.alpha;
    let ctx = ShadingContext::at(Vec3::new(-8.0, 0.0, 0.0));
    let mass: f64 = (0..40)
        .map(|e| ByPosition(&field).pmf_exact(&ctx, LightId::Emitter(e)))
        .sum();
    assert!(mass > 1.0 - alpha * 0.5 - 0.02, "{mass}");
}

/// A spatial split gives both children copies of the quadtree and of the
/// cut: before new data their directions answer identically, and the cut
/// is trusted only in the cells its light records came from. The next round
/// changes only the cell that gets data.
#[test]
fn spatial_split_copies_both_payloads() {
    let (_, tree) = rooms();
    let config = config_with(100.0, SdTreeConfig::default());
    let mut field = GuidingField::new(&tree, scene(), config).unwrap();
    let p = Vec3::new(-9.0, -9.0, -9.0);
    let dir = Vec3::new(0.2, 1.0, 0.1);
    let round = |field: &GuidingField<&LightTree>| {
        let v = field.vertex(&ShadingContext::at(p)).unwrap();
        for _ in 0..1000 {
            assert_ne!(
                v.direction.record_radiance(dir, 1.0, 1.0),
                RecordOutcome::Dropped
            );
            assert_eq!(
                field.record_light_at(p, LightId::Emitter(3), 2.0),
                RecordOutcome::Recorded
            );
        }
    };
    round(&field);
    // 1000 -> 500 -> 250 -> 125 -> 62.5 against 100: four levels, everywhere.
    let out = field.refine();
    assert_eq!(out.splits, 15);
    assert_eq!(field.cell_count(), 16);
    let cells = field.spatial().data_slice();
    let (q0, c0) = (
        cells[0].sd().directions().sampling_leaves(),
        cut_bytes(cells[0].cut()),
    );
    assert!(c0.len() > 12);
    for cell in cells {
        assert_eq!(cell.sd().directions().sampling_leaves(), q0);
        assert_eq!(cut_bytes(cell.cut()), c0);
        assert_eq!(cell.sd().building_weight(), 0.0);
        assert_eq!(cell.cut().accumulated(), (0.0, 0.0));
    }
    let far = Vec3::new(9.0, 9.0, 9.0);
    let (vn, vf) = (
        field.vertex(&ShadingContext::at(p)).unwrap(),
        field.vertex(&ShadingContext::at(far)).unwrap(),
    );
    assert_ne!(vn.direction.cell(), vf.direction.cell());
    // One refinement from the uniform tree: the root level learned (about 4x).
    assert!(vn.direction.direction_pdf(dir) > 3.0 * UNIFORM_PDF);
    assert_eq!(
        vn.direction.direction_pdf(dir).to_bits(),
        vf.direction.direction_pdf(dir).to_bits()
    );
    // The same learned cut in both cells, but the far cell got none of the
    // light records it learned from: there it samples as the prior does,
    // near p as learned.
    assert_eq!(vn.light.cut().confidence(), 1.0);
    assert_eq!(vf.light.cut().confidence(), 0.0);
    let l3 = LightId::Emitter(3);
    // The far cell's cut asked at p (its vertex answers at its own point).
    let near_ctx = ShadingContext::at(p);
    let far_at_p = |vf: &guiding::FieldVertex<&LightTree>| {
        CutRules::new(&tree, config.cut)
            .unwrap()
            .pmf_exact(vf.light.cut(), &near_ctx, l3)
    };
    let prior = GuidingField::new(&tree, scene(), config).unwrap();
    let untrained = prior
        .vertex(&ShadingContext::at(p))
        .unwrap()
        .light
        .pmf_exact(l3);
    assert_eq!(far_at_p(&vf).to_bits(), untrained.to_bits());
    let learned = vn.light.pmf_exact(l3);
    assert!(learned > 1.2 * untrained, "{learned} against {untrained}");
    // A second round near p, another direction and light: only that cell
    // learns it; the far one keeps its copies.
    let dir2 = Vec3::new(1.0, -0.3, 0.0);
    let v = field.vertex(&ShadingContext::at(p)).unwrap();
    for _ in 0..200 {
        assert_ne!(
            v.direction.record_radiance(dir2, 1.0, 1.0),
            RecordOutcome::Dropped
        );
        v.light.record_light(LightId::Emitter(30), 5.0);
    }
    let far_pdf = field
        .vertex(&ShadingContext::at(far))
        .unwrap()
        .direction
        .direction_pdf(dir2);
    field.refine();
    let (vn, vf) = (
        field.vertex(&ShadingContext::at(p)).unwrap(),
        field.vertex(&ShadingContext::at(far)).unwrap(),
    );
    assert!(vn.direction.direction_pdf(dir2) > 10.0 * vf.direction.direction_pdf(dir2));
    assert_eq!(
        vf.direction.direction_pdf(dir2).to_bits(),
        far_pdf.to_bits()
    );
    assert_eq!(far_at_p(&vf).to_bits(), untrained.to_bits());
    assert!(vn.light.pmf_exact(LightId::Emitter(30)) > 0.5);
}

/// Bad input is dropped, counted per kind and never stored, through the
/// field and through a vertex; queries at non-finite points answer nothing.
/// A split shares the cut's trust by where its light records fell: a half
/// with 2% of them (below the 5% a half needs for full trust) gets
/// confidence 0.4, the other 1; each half counts its own octants' records.
#[test]
fn a_split_shares_trust_by_where_the_light_records_fell() {
    let (_, tree) = rooms();
    // 1000 radiance records: above 600, one split; its halves (500) are
    // below the next level's threshold.
    let config = config_with(600.0, SdTreeConfig::default());
    let mut field = GuidingField::new(&tree, scene(), config).unwrap();
    // Apart along every axis: in different halves whichever axis splits.
    let (lower, upper) = (Vec3::splat(-5.0), Vec3::splat(5.0));
    let dir = Vec3::new(0.2, 1.0, 0.1);
    for (p, light_records) in [(lower, 20), (upper, 980)] {
        let v = field.vertex(&ShadingContext::at(p)).unwrap();
        for _ in 0..500 {
            v.direction.record_radiance(dir, 1.0, 1.0);
        }
        for _ in 0..light_records {
            field.record_light_at(p, LightId::Emitter(3), 2.0);
        }
    }
    // Before the refinement, one cell counts every record in the octants
    // they fell in.
    let counts = field.spatial().data_slice()[0].octant_records();
    assert_eq!(counts.iter().sum::<u64>(), 1000);
    assert_eq!(counts.iter().filter(|&&c| c > 0).count(), 2, "{counts:?}");
    assert!(counts.contains(&20) && counts.contains(&980), "{counts:?}");
    let out = field.refine();
    assert_eq!(out.splits, 1);
    let confidence = |p: Vec3| {
        field
            .vertex(&ShadingContext::at(p))
            .unwrap()
            .light
            .cut()
            .confidence()
    };
    assert!(
        (confidence(lower) - 0.4).abs() < 1e-6,
        "{}",
        confidence(lower)
    );
    assert_eq!(confidence(upper), 1.0);
    for cell in field.spatial().data_slice() {
        assert_eq!(cell.octant_records(), [0; 8], "counts restart");
    }
}

/// `clear_records` zeroes what was recorded since the last refinement
/// (light sums, octant counts, radiance sums, drop counts) and keeps what
/// was learned: the field samples as before.
#[test]
fn clearing_records_keeps_what_was_learned() {
    let (_, tree) = rooms();
    let config = config_with(600.0, SdTreeConfig::default());
    let mut field = GuidingField::new(&tree, scene(), config).unwrap();
    let p = Vec3::new(-5.0, 2.0, 1.0);
    let dir = Vec3::new(0.2, 1.0, 0.1);
    let record = |field: &GuidingField<&LightTree>| {
        let v = field.vertex(&ShadingContext::at(p)).unwrap();
        for _ in 0..300 {
            v.direction.record_radiance(dir, 1.0, 1.0);
            field.record_light_at(p, LightId::Emitter(3), 2.0);
        }
        field.record_light_at(p, LightId::Emitter(3), f32::NAN);
    };
    record(&field);
    field.refine();
    record(&field);
    let before = field
        .vertex(&ShadingContext::at(p))
        .unwrap()
        .light
        .pmf(LightId::Emitter(3));
    assert!(field.dropped_records().total() > 0);
    field.clear_records();
    assert_eq!(field.dropped_records().total(), 0);
    for cell in field.spatial().data_slice() {
        assert_eq!(cell.cut().accumulated(), (0.0, 0.0));
        assert_eq!(cell.octant_records(), [0; 8]);
        assert_eq!(cell.sd().building_weight(), 0.0);
    }
    let after = field
        .vertex(&ShadingContext::at(p))
        .unwrap()
        .light
        .pmf(LightId::Emitter(3));
    assert_eq!(before.to_bits(), after.to_bits());
}

#[test]
fn bad_input_is_dropped_and_counted() {
    let mut lights = two_rooms();
    lights[5].power = 0.0;
    let tree = LightTree::build(&lights, BuildHeuristic::Sarh).unwrap();
    let config = FieldConfig {
        sd: SdTreeConfig {
            learn_bsdf_fraction: true,
            ..SdTreeConfig::default()
        },
        ..FieldConfig::default()
    };
    let mut field = GuidingField::new(&tree, scene(), config).unwrap();
    let p = Vec3::ONE;
    let nan = Vec3::new(f32::NAN, 0.0, 0.0);
    let v = field.vertex(&ShadingContext::at(p)).unwrap();
    // Radiance records: position, direction, radiance, pdf, overflow.
    let bad = [
        (nan, Vec3::Z, 1.0, 1.0),
        (Vec3::splat(f32::INFINITY), Vec3::Z, 1.0, 1.0),
        (p, Vec3::ZERO, 1.0, 1.0),
        (p, Vec3::new(f32::NAN, 1.0, 0.0), 1.0, 1.0),
        (p, Vec3::Z, -1.0, 1.0),
        (p, Vec3::Z, f32::NAN, 1.0),
        (p, Vec3::Z, 1.0, 0.0),
        (p, Vec3::Z, 1.0, f32::INFINITY),
        (p, Vec3::Z, 1.0e30, 1.0e-30),
    ];
    for &(q, d, r, pdf) in &bad {
        assert!((field.record_radiance_at(q, d, r, pdf) == RecordOutcome::Dropped));
        if q == p {
            assert!((v.direction.record_radiance(d, r, pdf) == RecordOutcome::Dropped));
        }
    }
    let dropped = field.dropped_records();
    assert_eq!(
        (
            dropped.position,
            dropped.direction,
            dropped.radiance,
            dropped.pdf,
            dropped.overflow
        ),
        (2, 4, 4, 4, 2)
    );
    // Fraction records.
    assert!((field.record_fraction_at(nan, 1.0, 1.0, 1.0) == RecordOutcome::Dropped));
    assert!((v.direction.record_fraction(1.0, 1.0, f32::NAN) == RecordOutcome::Dropped));
    assert!((v.direction.record_fraction(-1.0, 1.0, 1.0) == RecordOutcome::Dropped));
    assert!((v.direction.record_fraction(0.0, 0.0, 1.0) == RecordOutcome::Dropped));
    assert_eq!(field.dropped_records().total(), 16 + 4);
    // Light records: values, positions, emitters out of range or dark, the
    // environment without one.
    let lbad = [
        (p, LightId::Emitter(1), f32::NAN),
        (p, LightId::Emitter(1), -2.0),
        (p, LightId::Emitter(1), f32::INFINITY),
        (nan, LightId::Emitter(1), 1.0),
        (p, LightId::Emitter(80), 1.0),
        (p, LightId::Emitter(5), 1.0),
        (p, LightId::Unbounded(0), 1.0),
    ];
    for (i, &(q, l, x)) in lbad.iter().enumerate() {
        assert_eq!(field.record_light_at(q, l, x), RecordOutcome::Dropped);
        assert_eq!(field.record_light_at(q, l, x), RecordOutcome::Dropped);
        if q == p {
            assert_eq!(v.light.record_light(l, x), RecordOutcome::Dropped);
        }
        assert!(field.dropped_records().light >= 2 * (i as u64 + 1));
    }
    // The records at a non-finite point find no vertex: two positions.
    assert_eq!(field.dropped_records().light, 2 * 6 + 6);
    assert_eq!(field.dropped_records().position, 2 + 1 + 2);
    // Nothing was stored.
    let cell = field.spatial().data_slice()[0].clone();
    assert_eq!(cell.sd().building_weight(), 0.0);
    assert_eq!(cell.sd().directions().building_total(), 0.0);
    assert_eq!(cell.cut().accumulated(), (0.0, 0.0));
    // Valid zeros are valid.
    assert_ne!(
        v.direction.record_radiance(Vec3::Z, 0.0, 1.0),
        RecordOutcome::Dropped
    );
    assert_eq!(
        v.light.record_light(LightId::Emitter(1), 0.0),
        RecordOutcome::Zero
    );
    // One report: 20 radiance and fraction records, 20 light records.
    assert_eq!(field.dropped_records().total(), 20 + 20);
    // Queries at non-finite points.
    assert!(field.vertex(&ShadingContext::at(nan)).is_none());
    let ctx = ShadingContext::at(nan);
    assert!(ByPosition(&field).sample(&ctx, 0.5).is_none());
    assert_eq!(ByPosition(&field).pmf(&ctx, LightId::Emitter(0)), 0.0);
    assert_eq!(ByPosition(&field).pmf_exact(&ctx, LightId::Emitter(0)), 0.0);
    assert!(ByPosition(&field).sample_exact(&ctx, 0.5).is_none());
    // A refinement with nothing valid learned changes nothing.
    field.refine();
    assert_eq!(field.cell_count(), 1);
    field.reset_dropped_records();
    assert_eq!(field.dropped_records().total(), 0);
    assert_eq!(field.dropped_records().light, 0);
}

struct Input {
    p: Vec3,
    dir: Vec3,
    radiance: f32,
    light: (u32, f32),
    fraction: (f32, f32, f32),
}

fn inputs(lights: &[Emitter], n: usize, seed: u64) -> Vec<Input> {
    let mut rng = Rand::seeded(seed);
    (0..n)
        .map(|_| {
            let p = rng.point(9.8);
            let e = (rng.f() * 80.0) as u32;
            Input {
                p,
                dir: light_dir(lights, p, &mut rng),
                // Values over 50 octaves, so that sums in another order
                // would round differently.
                radiance: rng.range(0.0, 3.0) * rng.range(-25.0, 25.0).exp2(),
                light: (e, value(lights, e, p) * rng.range(-25.0, 25.0).exp2()),
                fraction: (rng.range(0.0, 2.0), rng.range(0.0, 2.0), rng.f()),
            }
        })
        .collect()
}

fn apply(field: &GuidingField<&LightTree>, input: &Input) {
    let v = field.vertex(&ShadingContext::at(input.p)).unwrap();
    assert_ne!(
        v.direction
            .record_radiance(input.dir, input.radiance, UNIFORM_PDF),
        RecordOutcome::Dropped
    );
    let (e, x) = input.light;
    assert_ne!(
        v.light.record_light(LightId::Emitter(e), x),
        RecordOutcome::Dropped
    );
    let (pb, pg, c) = input.fraction;
    assert_ne!(
        v.direction.record_fraction(pb, pg, c),
        RecordOutcome::Dropped
    );
}

/// Feeds a batch from `threads` threads (0: the calling thread, in reverse
/// order).
fn feed(field: &GuidingField<&LightTree>, batch: &[Input], threads: usize) {
    if threads == 0 {
        batch.iter().rev().for_each(|i| apply(field, i));
        return;
    }
    std::thread::scope(|s| {
        for k in 0..threads {
            s.spawn(move || {
                batch
                    .iter()
                    .skip(k)
                    .step_by(threads)
                    .for_each(|i| apply(field, i))
            });
        }
    });
}

/// Everything learned, as bits: cells, quadtrees, fractions, weights,
/// cuts and their sums.
fn fingerprint(field: &GuidingField<&LightTree>) -> Vec<u64> {
    let cells = field.spatial();
    let mut out = vec![cells.cell_count() as u64];
    for c in cells.cells() {
        out.extend(bounds_bits(cells.cell_bounds(c)).map(u64::from));
        let cell = cells.data(c);
        out.extend(sd_bits(cell.sd()));
        out.extend(cut_bytes(cell.cut()).iter().map(|&b| b as u64));
        let (e, env) = cell.cut().accumulated();
        out.extend([e.to_bits(), env.to_bits()]);
    }
    out
}

/// Records from several threads (stochastic filters, learned fraction, every
/// record through a vertex) equal a serial run in reverse order bit for bit
/// in deterministic mode: spatial splits, quadtrees, fractions and cuts,
/// and the sums of an iteration not yet refined.
#[test]
fn threads_equal_serial() {
    let (lights, tree) = rooms();
    let config =
        config_with(400.0, SdTreeConfig::improved()).with_accumulation(Accumulation::Deterministic);
    let data: Vec<Vec<Input>> = (0..3).map(|k| inputs(&lights, 5000, k)).collect();
    let run = |threads: usize| {
        let mut field = GuidingField::new(&tree, scene(), config).unwrap();
        let (last, refined) = data.split_last().unwrap();
        for batch in refined {
            feed(&field, batch, threads);
            field.refine();
        }
        feed(&field, last, threads);
        fingerprint(&field)
    };
    let serial = run(0);
    assert!(serial[0] > 4, "{} cells", serial[0]);
    for threads in [1, 4] {
        assert!(run(threads) == serial, "{threads} threads differ");
    }
}

/// The memory report: the SD part equals an SD-tree's trained the same way,
/// 12 bytes per cut node, the parts add up, the budget holds, and the cuts'
/// bytes are set beside the quadtrees' (printed).
#[test]
fn memory_report_adds_up_and_compares_cuts_with_quadtrees() {
    let (lights, tree) = rooms();
    let sd_config = sd_with(400.0, SdTreeConfig::default());
    let config = FieldConfig {
        light_filter: SpatialFilter::Nearest,
        ..config_with(400.0, sd_config)
    };
    let field = trained_field(&tree, &lights, config, |_, _| {});
    // An SD-tree fed the same radiance records: same random stream, and the
    // light records (nearest) draw nothing from it.
    let mut sd = SdTree::new(scene(), sd_config).unwrap();
    let mut rng = Rand::seeded(8);
    for it in 0..4 {
        for _ in 0..(3000usize << it.min(2)) {
            // The first pass covers only the half x < 0 (as a renderer
            // that renders tile by tile might): the other half's cells
            // start from the prior.
            let p = match rng.point(9.8) {
                p if it == 0 => Vec3::new(-p.x.abs(), p.y, p.z),
                p => p,
            };
            rng.f(); // the number the field's light sample took
            let d = light_dir(&lights, p, &mut rng);
            assert_ne!(
                sd.record_radiance_at(p, d, 1.0, UNIFORM_PDF),
                RecordOutcome::Dropped
            );
        }
        sd.refine();
    }
    let m = field.memory();
    let s = sd.memory();
    assert_eq!(m.sd.cells, field.cell_count());
    assert_eq!(
        (
            m.sd.spatial_nodes,
            m.sd.quadtree_nodes,
            m.sd.quadtree_building_nodes
        ),
        (s.spatial_nodes, s.quadtree_nodes, s.quadtree_building_nodes)
    );
    assert_eq!(
        (m.sd.quadtree_bytes, m.sd.statistics_bytes),
        (s.quadtree_bytes, s.statistics_bytes)
    );
    assert_eq!(m.sd.spatial_bytes, field.spatial().bytes());
    let nodes: usize = field
        .spatial()
        .data_slice()
        .iter()
        .map(|c| c.cut().nodes().len())
        .sum();
    assert_eq!(m.cuts.nodes, nodes);
    assert_eq!(m.cuts.node_bytes, 12 * nodes);
    // One sum per slot (no unbounded light here), and the default
    // modulation's 7 anchor sums, per cell.
    assert_eq!(m.cuts.sum_bytes, 8 * (2 * nodes + 7 * m.sd.cells));
    // Split table 4 B per node; walk table one 16-B pair per inner node +
    // root and an 8-B path code per emitter; the default importance rules'
    // table one 64-B pair beside it.
    assert_eq!(
        m.shared_bytes,
        4 * tree.node_count() + (8 + 32) * (tree.node_count() + 1) + 8 * tree.emitter_count()
    );
    assert_eq!(m.cut_bytes(), m.cuts.node_bytes + m.cuts.sum_bytes);
    assert_eq!(m.quadtree_bytes(), m.sd.quadtree_bytes);
    assert_eq!(m.capped(), m.sd.total() + m.cut_bytes());
    assert_eq!(
        m.total(),
        m.sd.spatial_bytes
            + m.sd.quadtree_bytes
            + m.sd.statistics_bytes
            + m.cuts.node_bytes
            + m.cuts.sum_bytes
            + m.shared_bytes
    );
    let ratio = m.cut_to_quadtree();
    assert_eq!(ratio, m.cut_bytes() as f64 / m.quadtree_bytes() as f64);
    assert!(ratio > 0.0);
    // Cut nodes are 12 bytes, sampling quadtree nodes 24.
    assert_eq!(
        m.sampled_cut_to_quadtree(),
        (12 * m.cuts.nodes) as f64 / (24 * m.sd.quadtree_nodes) as f64
    );
    println!(
        "{} cells: cuts {} B ({} nodes) vs quadtrees {} B ({} sampling nodes): {:.2}x \
         (sampled copies {:.2}x); total {} B",
        m.sd.cells,
        m.cut_bytes(),
        m.cuts.nodes,
        m.quadtree_bytes(),
        m.sd.quadtree_nodes,
        ratio,
        m.sampled_cut_to_quadtree(),
        m.total()
    );

    // The same training under a budget of a third: splits never take the
    // capped total past it.
    let budget = m.capped() / 3;
    let budgeted = FieldConfig {
        sd: SdTreeConfig {
            max_bytes: Some(budget),
            ..sd_config
        },
        ..config
    };
    let mut refused = 0;
    let capped = trained_field(&tree, &lights, budgeted, |field, out| {
        refused += out.refused_by_budget;
        if out.splits > 0 {
            let bytes = field.memory().capped();
            assert!(bytes <= budget, "{bytes} > {budget}");
        }
    });
    assert!(refused > 0);
    assert!(capped.cell_count() > 1 && capped.cell_count() < field.cell_count());
}
