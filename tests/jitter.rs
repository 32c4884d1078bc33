//! The stochastic box filter draws its offset from a hash of the record
//! (`src/spatial/jitter.rs`), not from a generator the renderer passes:
//! the same records learn the same state in any order, and the filter
//! still moves records into the neighbouring cells.

mod common;

use common::{DirectionsAt, Rand, scene};
use glam::Vec3;
use guiding::RecordOutcome;
use guiding::math::Accumulation;
use guiding::quadtree::UNIFORM_PDF;
use guiding::sd_tree::{SdTree, SdTreeConfig};
use guiding::spatial::SpatialFilter;

/// A tree of a few cells, split by records at scattered points.
fn tree(filter: SpatialFilter) -> SdTree {
    let config = SdTreeConfig {
        spatial_threshold: 50.0,
        spatial_filter: filter,
        accumulation: Accumulation::Deterministic,
        ..SdTreeConfig::default()
    };
    let t = SdTree::new(scene(), config).unwrap();
    let mut rng = Rand::new(1);
    for _ in 0..2000 {
        t.record_radiance_at(rng.point(9.5), Vec3::Y, 1.0, UNIFORM_PDF);
    }
    t
}

/// Every cell's learned pdf along some directions, bit for bit.
fn learned(t: &SdTree) -> Vec<u32> {
    let mut rng = Rand::new(7);
    (0..300)
        .map(|_| t.direction_pdf_at(rng.point(9.5), rng.dir()).to_bits())
        .collect()
}

#[test]
fn the_same_records_in_any_order_learn_the_same_and_the_box_moves_them() {
    let (mut forward, mut backward, mut nearest) = (
        tree(SpatialFilter::StochasticBox),
        tree(SpatialFilter::StochasticBox),
        tree(SpatialFilter::Nearest),
    );
    for t in [&mut forward, &mut backward, &mut nearest] {
        t.refine();
        assert!(t.cell_count() > 4);
    }
    let mut rng = Rand::new(2);
    let records: Vec<(Vec3, Vec3)> = (0..3000).map(|_| (rng.point(9.5), rng.dir())).collect();
    for (p, d) in &records {
        assert_eq!(
            forward.record_radiance_at(*p, *d, 1.0, UNIFORM_PDF),
            RecordOutcome::Recorded
        );
        assert_eq!(
            nearest.record_radiance_at(*p, *d, 1.0, UNIFORM_PDF),
            RecordOutcome::Recorded
        );
    }
    for (p, d) in records.iter().rev() {
        backward.record_radiance_at(*p, *d, 1.0, UNIFORM_PDF);
    }
    for t in [&mut forward, &mut backward, &mut nearest] {
        t.refine();
    }
    // No generator, no order: the jitter is the record's own.
    assert_eq!(learned(&forward), learned(&backward));
    // The control: the box did move records out of their cells (a filter
    // that ignored its offset would learn what the nearest cell learns).
    assert_ne!(learned(&forward), learned(&nearest));
}
