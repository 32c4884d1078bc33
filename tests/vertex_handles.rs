//! One front shape: the SD-tree, the GLT and the field each locate a path
//! vertex once (`vertex(p)`), and the handle answers and records exactly as
//! the structure does by position.

mod common;

use common::{Rand, scene, two_rooms, value};
use glam::Vec3;
use guiding::glt::{Glt, GltConfig};
use guiding::light_tree::BuildHeuristic;
use guiding::quadtree::UNIFORM_PDF;
use guiding::sd_tree::{SdTree, SdTreeConfig};
use guiding::spatial::SpatialFilter;
use guiding::spatial::SpatialTree;
use guiding::{LightId, LightSampler, LightTree, ShadingContext};
use rand_pcg::Pcg32;
use rand_pcg::rand_core::{Rng, SeedableRng};

#[test]
fn sd_vertex_equals_the_tree_by_position() {
    let config = SdTreeConfig {
        spatial_threshold: 300.0,
        spatial_filter: SpatialFilter::StochasticBox,
        learn_bsdf_fraction: true,
        ..SdTreeConfig::default()
    };
    let (mut by_pos, mut by_vertex) = (
        SdTree::new(scene(), config).unwrap(),
        SdTree::new(scene(), config).unwrap(),
    );
    let mut rng = Rand::new(2);
    for _ in 0..4 {
        for _ in 0..4000 {
            let p = rng.point(9.5);
            let d = (Vec3::Y + 0.3 * rng.dir()).normalize();
            let (radiance, c) = (rng.range(0.0, 3.0), rng.range(0.0, 1.0));
            let seed = rng.0.next_u64();
            let v = by_vertex.vertex(p).unwrap();
            assert_eq!(v.position(), p);
            assert!(by_pos.splat(p, d, radiance, UNIFORM_PDF, &mut Pcg32::seed_from_u64(seed)));
            assert!(v.splat_radiance(d, radiance, UNIFORM_PDF, &mut Pcg32::seed_from_u64(seed)));
            assert!(by_pos.record_fraction(p, 0.3, 0.5, c));
            assert!(v.record_fraction(0.3, 0.5, c));
        }
        assert_eq!(by_pos.refine(), by_vertex.refine());
    }
    assert!(by_pos.cell_count() > 1);
    for _ in 0..500 {
        let p = rng.point(9.5);
        let v = by_vertex.vertex(p).unwrap();
        let u = [rng.f(), rng.f()];
        let (d, pdf) = v.sample_direction(u);
        assert_eq!(by_pos.sample(p, u), Some((d, pdf)));
        assert_eq!(by_pos.pdf(p, d).to_bits(), v.direction_pdf(d).to_bits());
        assert_eq!(
            by_pos.bsdf_fraction(p).to_bits(),
            v.bsdf_fraction().to_bits()
        );
        assert_eq!(
            by_pos.mixture_pdf(p, d, 0.2).to_bits(),
            v.mixture_pdf(d, 0.2).to_bits()
        );
    }
    assert!(by_pos.vertex(Vec3::NAN).is_none());
}

#[test]
fn glt_vertex_equals_the_glt_by_position() {
    let lights = two_rooms();
    let tree = LightTree::build(&lights, BuildHeuristic::Sarh).unwrap();
    let config = GltConfig {
        spatial_threshold: 300.0,
        filter: SpatialFilter::StochasticBox,
        ..GltConfig::default()
    };
    let mut by_pos = Glt::new(&tree, scene(), config).unwrap();
    let mut by_vertex = Glt::new(&tree, scene(), config).unwrap();
    let mut rng = Rand::new(4);
    for _ in 0..4 {
        for _ in 0..4000 {
            let p = rng.point(9.5);
            let ctx = ShadingContext::at(p);
            let u = rng.f();
            let v = by_vertex.vertex(p).unwrap();
            let s = by_pos.sample(&ctx, u).unwrap();
            assert_eq!(v.sample(&ctx, u), Some(s));
            let LightId::Emitter(e) = s.light else {
                panic!()
            };
            let x = value(&lights, e, p) / s.pmf;
            let seed = rng.0.next_u64();
            assert_eq!(
                by_pos.splat(p, s.light, x, &mut Pcg32::seed_from_u64(seed)),
                v.splat_light(s.light, x, &mut Pcg32::seed_from_u64(seed))
            );
        }
        assert_eq!(by_pos.refine(), by_vertex.refine());
    }
    assert!(by_pos.spatial().cell_count() > 1);
    for _ in 0..500 {
        let p = rng.point(9.5);
        let ctx = ShadingContext::on_surface(p, rng.dir());
        let v = by_vertex.vertex(p).unwrap();
        for e in 0..lights.len() as u32 {
            let l = LightId::Emitter(e);
            assert_eq!(
                by_pos.pmf_exact(&ctx, l).to_bits(),
                v.pmf_exact(&ctx, l).to_bits()
            );
        }
        let u = rng.f64();
        assert_eq!(by_pos.sample_exact(&ctx, u), v.sample_exact(&ctx, u));
    }
    assert!(by_pos.vertex(Vec3::INFINITY).is_none());
}

/// The field's vertex answers as the field by position: its cell is the
/// field's `locate`, light choice, pmfs and the learned visibility (which
/// differs from 1 once learned) are bit for bit the same, light and
/// visibility records made through either learn the same; an empty field
/// says so through both.
#[test]
fn field_vertex_equals_the_field_by_position() {
    use guiding::field::{FieldConfig, GuidingField};
    use guiding::glt::CutConfig;
    let lights = two_rooms();
    let tree = LightTree::build(&lights, BuildHeuristic::Sarh).unwrap();
    let mut config = FieldConfig {
        cut: CutConfig {
            visibility: true,
            ..CutConfig::default()
        },
        ..FieldConfig::default()
    };
    config.sd.spatial_threshold = 300.0;
    let mut by_pos = GuidingField::new(&tree, scene(), config).unwrap();
    let mut by_vertex = GuidingField::new(&tree, scene(), config).unwrap();
    let mut rng = Rand::new(6);
    for _ in 0..4 {
        for _ in 0..4000 {
            let p = rng.point(9.5);
            let ctx = ShadingContext::at(p);
            let u = rng.f();
            let v = by_vertex.vertex(p).unwrap();
            assert_eq!(by_pos.locate(p), Some(v.cell()));
            let s = by_pos.sample(&ctx, u).unwrap();
            assert_eq!(v.sample(&ctx, u), Some(s));
            let LightId::Emitter(e) = s.light else {
                panic!()
            };
            let x = value(&lights, e, p) / s.pmf;
            let seed = rng.0.next_u64();
            assert_eq!(
                by_pos.splat_light(p, s.light, x, &mut Pcg32::seed_from_u64(seed)),
                v.splat_light(s.light, x, &mut Pcg32::seed_from_u64(seed))
            );
            let d = (Vec3::Y + 0.3 * rng.dir()).normalize();
            let radiance = rng.range(0.0, 3.0);
            let seed = rng.0.next_u64();
            assert_eq!(
                by_pos.splat_radiance(p, d, radiance, UNIFORM_PDF, &mut Pcg32::seed_from_u64(seed)),
                v.splat_radiance(d, radiance, UNIFORM_PDF, &mut Pcg32::seed_from_u64(seed))
            );
            // Half the unshadowed records arrive (a wall of sorts).
            let unshadowed = 1.0 + rng.f();
            let seen = if rng.f() < 0.5 { unshadowed } else { 0.0 };
            assert_eq!(
                by_pos.splat_visibility(p, s.light, seen, unshadowed),
                v.splat_visibility(s.light, seen, unshadowed)
            );
        }
        by_pos.refine();
        by_vertex.refine();
    }
    assert!(by_pos.cell_count() > 1);
    let mut learned = 0;
    for _ in 0..500 {
        let p = rng.point(9.5);
        let ctx = ShadingContext::on_surface(p, rng.dir());
        let v = by_vertex.vertex(p).unwrap();
        assert_eq!(by_pos.locate(p), Some(v.cell()));
        for e in 0..lights.len() as u32 {
            let l = LightId::Emitter(e);
            assert_eq!(
                by_pos.pmf_exact(&ctx, l).to_bits(),
                v.pmf_exact(&ctx, l).to_bits()
            );
            let vis = by_pos.visibility(&ctx, l);
            assert_eq!(vis.to_bits(), v.visibility(&ctx, l).to_bits());
            learned += usize::from(vis < 0.9);
        }
        let u = rng.f64();
        assert_eq!(by_pos.sample_exact(&ctx, u), v.sample_exact(&ctx, u));
        // Sampling with the visibility read on the way equals sampling,
        // then asking the visibility, through either.
        let u = u as f32;
        let samplers: [&dyn LightSampler; 2] = [&by_pos, &v];
        for s in samplers {
            let want = s
                .sample(&ctx, u)
                .map(|x| (x, s.visibility(&ctx, x.light).to_bits()));
            let got = s
                .sample_with_visibility(&ctx, u)
                .map(|(x, vis)| (x, vis.to_bits()));
            assert!(want.is_some());
            assert_eq!(got, want);
        }
    }
    assert!(learned > 0, "no visibility learned");
    assert!(by_pos.locate(Vec3::NAN).is_none());
    assert!(!by_pos.is_empty() && !by_vertex.vertex(Vec3::ZERO).unwrap().is_empty());
    let dark = [guiding::Emitter::point(Vec3::ZERO, 0.0)];
    let dark_tree = LightTree::build(&dark[..], BuildHeuristic::Sarh).unwrap();
    let empty = GuidingField::new(&dark_tree, scene(), config).unwrap();
    assert!(empty.is_empty() && empty.vertex(Vec3::ZERO).unwrap().is_empty());
}

/// The records [`glt_vertex_drops_and_counts_bad_records_as_the_glt_does`]
/// and its field twin make: `(light, value, unshadowed)`, good and bad.
fn mixed_records(n: u32) -> [(LightId, f32, f32); 7] {
    [
        (LightId::Emitter(3), 1.0, 2.0),
        (LightId::Emitter(3), f32::NAN, 2.0),
        (LightId::Emitter(n + 5), 1.0, 2.0),
        (LightId::Emitter(4), -1.0, 2.0),
        (LightId::Emitter(4), 0.0, 2.0),
        (LightId::Emitter(5), 3.0, 2.0),
        (LightId::Unbounded(0), 1.0, 1.0),
    ]
}

/// Of [`mixed_records`], dropped as splats: the NaN, the light out of
/// range, the negative value, the sky the configuration does not have;
/// as visibility records the same but the NaN (its record is
/// `min(NaN, 2) = 2` of 2).
const MIXED_DROPPED: u64 = 4 + 3;

/// Bad records made through a GLT vertex are dropped and counted exactly as
/// through the GLT by position, and good ones are not counted: light
/// splats and visibility records alike.
#[test]
fn glt_vertex_drops_and_counts_bad_records_as_the_glt_does() {
    let lights = two_rooms();
    let tree = LightTree::build(&lights, BuildHeuristic::Sarh).unwrap();
    let config = GltConfig {
        cut: guiding::glt::CutConfig {
            visibility: true,
            ..Default::default()
        },
        ..GltConfig::default()
    };
    let (by_pos, by_vertex) = (
        Glt::new(&tree, scene(), config).unwrap(),
        Glt::new(&tree, scene(), config).unwrap(),
    );
    let p = Vec3::new(-3.0, 1.0, 2.0);
    let v = by_vertex.vertex(p).unwrap();
    let records = mixed_records(lights.len() as u32);
    let mut rng = Pcg32::seed_from_u64(1);
    for (k, &(light, value, unshadowed)) in records.iter().enumerate() {
        let a = by_pos.splat(p, light, value, &mut rng);
        assert_eq!(a, v.splat_light(light, value, &mut rng), "record {k}");
        let seen = value.min(unshadowed);
        let b = by_pos.splat_visibility(p, light, seen, unshadowed);
        assert_eq!(b, v.splat_visibility(light, seen, unshadowed), "record {k}");
        assert_eq!(
            by_pos.dropped_splats(),
            by_vertex.dropped_splats(),
            "record {k}"
        );
    }
    assert_eq!(by_pos.dropped_splats().light, MIXED_DROPPED);
}

/// The field's twin of [`glt_vertex_drops_and_counts_bad_records_as_the_glt_does`].
#[test]
fn field_vertex_drops_and_counts_bad_records_as_the_field_does() {
    use guiding::field::{FieldConfig, GuidingField};
    let lights = two_rooms();
    let tree = LightTree::build(&lights, BuildHeuristic::Sarh).unwrap();
    let config = FieldConfig {
        cut: guiding::glt::CutConfig {
            visibility: true,
            ..Default::default()
        },
        ..FieldConfig::default()
    };
    let (by_pos, by_vertex) = (
        GuidingField::new(&tree, scene(), config).unwrap(),
        GuidingField::new(&tree, scene(), config).unwrap(),
    );
    let p = Vec3::new(-3.0, 1.0, 2.0);
    let v = by_vertex.vertex(p).unwrap();
    let mut rng = Pcg32::seed_from_u64(1);
    for (k, &(light, value, unshadowed)) in mixed_records(lights.len() as u32).iter().enumerate() {
        let a = by_pos.splat_light(p, light, value, &mut rng);
        assert_eq!(a, v.splat_light(light, value, &mut rng), "record {k}");
        let seen = value.min(unshadowed);
        let b = by_pos.splat_visibility(p, light, seen, unshadowed);
        assert_eq!(b, v.splat_visibility(light, seen, unshadowed), "record {k}");
        assert_eq!(
            by_pos.dropped_splats(),
            by_vertex.dropped_splats(),
            "record {k}"
        );
    }
    assert_eq!(by_pos.dropped_splats().light, MIXED_DROPPED);
}
