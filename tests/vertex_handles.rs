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
