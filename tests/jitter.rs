//! Jittered splats take their random numbers from any `rand_core`
//! generator or from three numbers the renderer drew itself.

mod common;

use common::{Rand, scene};
use glam::Vec3;
use guiding::quadtree::UNIFORM_PDF;
use guiding::sd_tree::{SdTree, SdTreeConfig};
use guiding::spatial::{JitterNumbers, SpatialFilter};

fn tree(filter: SpatialFilter) -> SdTree {
    let config = SdTreeConfig {
        spatial_threshold: 50.0,
        spatial_filter: filter,
        ..SdTreeConfig::default()
    };
    let mut t = SdTree::new(scene(), config).unwrap();
    // Split the scene into a few cells first (centred jitter: the same
    // cells whatever the filter).
    let mut rng = Rand::new(1);
    for _ in 0..2000 {
        let centre = &mut JitterNumbers([0.5; 3]);
        t.splat(rng.point(9.5), Vec3::Y, 1.0, UNIFORM_PDF, centre);
    }
    t.refine();
    t
}

#[test]
fn centred_numbers_splat_like_nearest_and_others_move() {
    let (mut a, mut b, mut c) = (
        tree(SpatialFilter::StochasticBox),
        tree(SpatialFilter::Nearest),
        tree(SpatialFilter::StochasticBox),
    );
    assert!(a.cell_count() > 4);
    assert_eq!(a.cell_count(), b.cell_count());
    // And any rand_core generator drives it too.
    assert!(c.splat(
        Vec3::ZERO,
        Vec3::Y,
        0.0,
        UNIFORM_PDF,
        &mut rand_pcg::Pcg32::new(1, 1)
    ));
    let mut rng = Rand::new(2);
    for _ in 0..2000 {
        let p = rng.point(9.5);
        let d = rng.dir();
        // The box's centre is the point itself: the nearest cell.
        assert!(a.splat(p, d, 1.0, UNIFORM_PDF, &mut JitterNumbers([0.5; 3])));
        assert!(b.splat(p, d, 1.0, UNIFORM_PDF, &mut JitterNumbers([0.0; 3])));
        // A corner of the box: a neighbouring cell near the cell's faces.
        let nan = JitterNumbers([f32::NAN, 7.0, -1.0]);
        assert!(c.splat(p, d, 1.0, UNIFORM_PDF, &mut { nan }));
    }
    a.refine();
    b.refine();
    c.refine();
    let mut same_ab = true;
    let mut same_ac = true;
    for _ in 0..300 {
        let p = rng.point(9.5);
        let d = rng.dir();
        same_ab &= a.pdf(p, d).to_bits() == b.pdf(p, d).to_bits();
        same_ac &= a.pdf(p, d).to_bits() == c.pdf(p, d).to_bits();
    }
    assert!(same_ab, "centred jitter must equal the nearest cell");
    assert!(!same_ac, "a corner jitter must reach other cells");
}
