//! The spatial binary tree: lookup, clamping, refinement rules, budgets,
//! overlap queries and depth beyond 64 levels.

use glam::Vec3;
use guiding::math::Aabb;
use guiding::spatial::{BinaryTree, CellId, SpatialError, SpatialFilter, SpatialTree};

fn unit() -> Aabb {
    Aabb::new(Vec3::ZERO, Vec3::ONE)
}

/// A small deterministic point generator (no dependency on an RNG crate).
fn points(n: usize, seed: u64) -> Vec<Vec3> {
    let mut s = seed
        .wrapping_mul(6364136223846793005)
        .wrapping_add(1442695040888963407);
    let mut next = move || {
        s = s
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((s >> 40) as f32) / (1u64 << 24) as f32
    };
    (0..n).map(|_| Vec3::new(next(), next(), next())).collect()
}

/// A tree over `bounds` split uniformly `levels` deep.
fn uniform(bounds: Aabb, levels: u32) -> BinaryTree<u32> {
    let mut t = BinaryTree::new(bounds, 0u32).unwrap();
    let out = t.refine(|_, depth| depth < levels, |_| 0, None);
    assert_eq!(out.splits, (1usize << levels) - 1);
    t
}

#[test]
fn locate_finds_the_cell_that_contains_the_point() {
    let t = uniform(unit(), 6);
    assert_eq!(t.cell_count(), 64);
    assert_eq!(t.node_count(), 127);
    let root = t.root_bounds();
    for p in points(2000, 1) {
        let p = root.min + p * root.diagonal();
        let (cell, bounds) = t.locate_with_bounds(p).unwrap();
        assert_eq!(t.locate(p), Some(cell));
        assert!(bounds.contains(p), "{p} not in {bounds:?}");
        assert_eq!(t.cell_bounds(cell), bounds);
        assert_eq!(t.cell_depth(cell), 6);
    }
    // Depth 6 over cycling axes: every cell is a cube of a quarter side.
    for cell in t.cells() {
        let d = t.cell_bounds(cell).diagonal();
        let side = root.diagonal() / 4.0;
        assert!((d - side).abs().max_element() < 1e-6);
    }
    // The cells tile the root.
    let volume: f32 = t.cells().map(|c| t.cell_bounds(c).volume()).sum();
    assert!((volume - root.volume()).abs() < 1e-5 * root.volume());
}

#[test]
fn first_split_is_along_x_then_y_then_z() {
    let t = uniform(unit(), 1);
    let lo = t.cell_bounds(CellId(0));
    let hi = t.cell_bounds(CellId(1));
    let mid = t.root_bounds().center();
    assert_eq!(lo.max.x, mid.x);
    assert_eq!(hi.min.x, mid.x);
    assert_eq!(lo.max.y, t.root_bounds().max.y);
    let t = uniform(unit(), 2);
    let c = t.locate(Vec3::new(0.1, 0.9, 0.1)).unwrap();
    assert_eq!(t.cell_bounds(c).min.y, mid.y);
    assert_eq!(t.cell_bounds(c).max.z, t.root_bounds().max.z);
}

#[test]
fn points_outside_are_clamped_and_non_finite_rejected() {
    let t = uniform(unit(), 5);
    let root = t.root_bounds();
    for p in points(500, 2) {
        let far = (p - 0.5) * 1.0e6;
        assert_eq!(t.locate(far), t.locate(root.clamp(far)));
    }
    assert_eq!(t.locate(Vec3::splat(f32::MAX)), t.locate(root.max));
    assert_eq!(t.locate(Vec3::splat(-f32::MAX)), t.locate(root.min));
    for bad in [f32::NAN, f32::INFINITY, f32::NEG_INFINITY] {
        assert_eq!(t.locate(Vec3::new(bad, 0.5, 0.5)), None);
        assert_eq!(t.locate(Vec3::new(0.5, 0.5, bad)), None);
        assert!(t.locate_with_bounds(Vec3::splat(bad)).is_none());
    }
}

#[test]
fn bounds_are_validated_and_degenerate_scenes_padded() {
    assert!(matches!(
        BinaryTree::new(Aabb::EMPTY, ()),
        Err(SpatialError::EmptyBounds)
    ));
    let inf = Aabb::new(Vec3::ZERO, Vec3::splat(f32::INFINITY));
    assert!(matches!(
        BinaryTree::new(inf, ()),
        Err(SpatialError::NonFiniteBounds)
    ));
    // A flat scene (a plane) and a point scene still split on every axis.
    let flat = Aabb::new(Vec3::new(-2.0, 0.0, -2.0), Vec3::new(2.0, 0.0, 2.0));
    let point = Aabb::from_point(Vec3::new(3.0, -1.0, 7.0));
    for scene in [flat, point] {
        let t = uniform(scene, 9);
        assert_eq!(t.cell_count(), 512);
        for c in t.cells() {
            assert!(t.cell_bounds(c).volume() > 0.0);
        }
        let c = t.locate(scene.center()).unwrap();
        assert!(t.cell_bounds(c).contains(scene.center()));
    }
}

#[derive(Clone, Debug, PartialEq)]
struct Payload {
    weight: f64,
    tag: Vec<u8>,
}

fn ppg_refine(t: &mut BinaryTree<Payload>, threshold: f64, budget: Option<usize>) -> usize {
    t.refine(
        |c, _| c.weight > threshold,
        |c| {
            c.weight *= 0.5;
            c.clone()
        },
        budget,
    )
    .splits
}

#[test]
fn splits_exactly_when_weight_exceeds_threshold() {
    let leaf = |w: f64| Payload {
        weight: w,
        tag: vec![7, 8, 9],
    };
    // At the threshold: no split.
    let mut t = BinaryTree::new(unit(), leaf(10.0)).unwrap();
    assert_eq!(ppg_refine(&mut t, 10.0, None), 0);
    assert_eq!(t.cell_count(), 1);
    // Just above: one split, both halves at 5.000..., data copied.
    let mut t = BinaryTree::new(unit(), leaf(10.0 + 1e-9)).unwrap();
    assert_eq!(ppg_refine(&mut t, 10.0, None), 1);
    assert_eq!(t.cell_count(), 2);
    for c in t.cells() {
        assert_eq!(t.data(c).weight, (10.0 + 1e-9) * 0.5);
        assert_eq!(t.data(c).tag, [7, 8, 9]);
    }
    // Recursive in one pass: 40 -> 20 -> 10 (stops at the threshold).
    let mut t = BinaryTree::new(unit(), leaf(40.0)).unwrap();
    assert_eq!(ppg_refine(&mut t, 10.0, None), 3);
    assert_eq!(t.cell_count(), 4);
    assert!(
        t.cells()
            .all(|c| t.data(c).weight == 10.0 && t.cell_depth(c) == 2)
    );
    // 41 -> 20.5 -> 10.25 -> 5.125: three levels, eight cells.
    let mut t = BinaryTree::new(unit(), leaf(41.0)).unwrap();
    assert_eq!(ppg_refine(&mut t, 10.0, None), 7);
    assert!(
        t.cells()
            .all(|c| t.data(c).weight == 5.125 && t.cell_depth(c) == 3)
    );
    // Total weight is preserved by splitting.
    let total: f64 = t.data_slice().iter().map(|c| c.weight).sum();
    assert_eq!(total, 41.0);
    // Only heavy cells split on a later pass.
    t.data_mut(CellId(3)).weight = 100.0;
    let before = t.cell_count();
    let splits = ppg_refine(&mut t, 10.0, None);
    // 100 -> 50 -> 25 -> 12.5 -> 6.25: a full subtree four levels deep.
    assert_eq!(splits, 1 + 2 + 4 + 8);
    assert_eq!(t.cell_count(), before + 15);
    assert_eq!(t.data(CellId(3)).weight, 6.25);
}

#[test]
fn budget_caps_bytes_and_is_spent_breadth_first() {
    let leaf = Payload {
        weight: 1.0e6,
        tag: vec![0; 100],
    };
    let mut probe = BinaryTree::new(unit(), leaf.clone()).unwrap();
    let start = probe.bytes();
    ppg_refine(&mut probe, 1.0e6 / 4.0 - 1.0, None);
    let per_split = (probe.bytes() - start) / probe.cells().len().saturating_sub(1);
    assert!(per_split > 0);

    let budget = start + 5 * per_split;
    let mut t = BinaryTree::new(unit(), leaf.clone()).unwrap();
    let out = t.refine(
        |c, _| c.weight > 1.0,
        |c| {
            c.weight *= 0.5;
            c.clone()
        },
        Some(budget),
    );
    assert_eq!(out.splits, 5);
    assert!(out.refused_by_budget > 0);
    assert!(t.bytes() <= budget, "{} > {budget}", t.bytes());
    // Breadth first: depths differ by at most one.
    let depths: Vec<u32> = t.cells().map(|c| t.cell_depth(c)).collect();
    let (lo, hi) = (depths.iter().min().unwrap(), depths.iter().max().unwrap());
    assert!(hi - lo <= 1, "{depths:?}");

    // Counting the heap bytes of the payload allows fewer splits.
    let heap = |c: &Payload| c.tag.len();
    let mut h = BinaryTree::new(unit(), leaf.clone()).unwrap();
    let budget = start + 100 + 3 * (per_split + 100);
    let out = h.refine_with_heap(
        |c, _| c.weight > 1.0,
        |c| {
            c.weight *= 0.5;
            c.clone()
        },
        heap,
        Some(budget),
    );
    assert_eq!(out.splits, 3);
    let used = h.bytes() + h.data_slice().iter().map(heap).sum::<usize>();
    assert!(used <= budget);
}

#[test]
fn overlap_visits_exactly_the_intersecting_cells() {
    let mut t = uniform(unit(), 4);
    // Refine one corner deeper, so cells differ in size.
    let corner = t.locate(Vec3::splat(0.1)).unwrap();
    *t.data_mut(corner) = 1;
    t.refine(|w, d| *w == 1 && d < 10, |w| *w, None);
    assert_eq!(t.cell_count(), 16 + 63);
    let root = t.root_bounds();
    for (i, q) in points(50, 3).into_iter().enumerate() {
        let half = Vec3::splat(0.02 + 0.005 * (i % 7) as f32);
        let region = Aabb::new(
            root.min + q * root.diagonal() - half,
            root.min + q * root.diagonal() + half,
        );
        let mut seen = Vec::new();
        let mut overlap = 0.0f64;
        t.for_each_overlapping(&region, |cell, b| {
            assert_eq!(*b, t.cell_bounds(cell));
            seen.push(cell);
            let i = b.intersection(&region);
            if !i.is_empty() {
                overlap += i.volume() as f64;
            }
        });
        seen.sort();
        let mut expect: Vec<CellId> = t
            .cells()
            .filter(|&c| {
                let b = t.cell_bounds(c);
                b.min.cmple(region.max).all() && region.min.cmple(b.max).all()
            })
            .collect();
        expect.sort();
        assert_eq!(seen, expect);
        let clipped = region.intersection(&root).volume() as f64;
        assert!(
            (overlap - clipped).abs() < 1e-4 * clipped,
            "{overlap} vs {clipped}"
        );
        // The trait method visits the same cells.
        let mut via_trait = Vec::new();
        let dynamic: &dyn SpatialTree<Data = u32> = &t;
        dynamic.visit_overlapping(&region, &mut |c| via_trait.push(c));
        via_trait.sort();
        assert_eq!(via_trait, expect);
    }
    let mut none = 0;
    t.for_each_overlapping(&Aabb::EMPTY, |_, _| none += 1);
    t.for_each_overlapping(&Aabb::new(Vec3::splat(5.0), Vec3::splat(6.0)), |_, _| {
        none += 1
    });
    assert_eq!(none, 0);
}

#[test]
fn deeper_than_64_levels_at_a_point_cluster() {
    // Twenty points at one spot near the origin of [-1, 1]^3; each pass
    // recounts them per cell and splits cells holding more than 2.5 / 4 of
    // them, i.e. two levels per pass around the cluster.
    let cluster = Vec3::new(1.0e-20, 2.0e-20, 3.0e-20);
    let scene = Aabb::new(Vec3::splat(-1.0), Vec3::splat(1.0));
    let mut t = BinaryTree::new(scene, 0.0f64).unwrap();
    let n = 20.0;
    let mut passes = 0;
    let mut refused = 0;
    while refused == 0 && passes < 400 {
        for w in t.data_slice_mut() {
            *w = 0.0;
        }
        let c = t.locate(cluster).unwrap();
        *t.data_mut(c) = n;
        let out = t.refine(
            |w, _| *w > n / 2.5,
            |w| {
                *w *= 0.5;
                *w
            },
            None,
        );
        refused = out.refused_by_precision;
        passes += 1;
        if passes == 40 {
            let c = t.locate(cluster).unwrap();
            assert!(t.cell_depth(c) >= 80, "depth {}", t.cell_depth(c));
            assert!(t.cell_bounds(c).contains(cluster));
        }
    }
    // It stops at f32 precision, not at some fixed depth, and never panics.
    assert!(
        refused > 0,
        "never hit the precision limit in {passes} passes"
    );
    let c = t.locate(cluster).unwrap();
    let depth = t.cell_depth(c);
    assert!(depth > 200, "depth {depth}");
    assert_eq!(t.max_depth(), depth);
    let b = t.cell_bounds(c);
    assert!(b.contains(cluster) && b.volume() < 1.0e-60_f64 as f32 + f32::MIN_POSITIVE);
    // Lookups and overlap queries everywhere else still work.
    for p in points(200, 4) {
        let p = p * 2.0 - 1.0;
        let (cell, bounds) = t.locate_with_bounds(p).unwrap();
        assert!(bounds.contains(p));
        let mut hit = false;
        t.for_each_overlapping(&Aabb::from_point(p), |c, _| hit |= c == cell);
        assert!(hit);
    }
    let mut count = 0;
    t.for_each_overlapping(&Aabb::from_point(cluster), |_, _| count += 1);
    assert!(count >= 1);
}

#[test]
fn map_keeps_topology() {
    let mut t = BinaryTree::new(unit(), 3u32).unwrap();
    t.refine(|w, d| *w > 0 && d < 3, |w| *w, None);
    let m = t.map_ref(|w| *w as f64 * 2.0);
    assert_eq!(m.cell_count(), t.cell_count());
    for p in points(100, 5) {
        let c = t.locate(p).unwrap();
        assert_eq!(m.locate(p), Some(c));
        assert_eq!(*m.data(c), 6.0);
    }
    let owned = t.map(|w| w + 1);
    assert!(owned.data_slice().iter().all(|w| *w == 4));
}

/// The stochastic box skips the second lookup when the jittered point stays
/// in its cell; it must pick exactly the cell a lookup of that point picks,
/// on split planes, root faces and deep cells included.
#[test]
fn stochastic_box_picks_the_cell_a_lookup_of_the_jittered_point_picks() {
    let scene = Aabb::new(Vec3::splat(-1.0), Vec3::splat(3.0));
    let mut t = BinaryTree::new(scene, 0.0f64).unwrap();
    t.refine(|_, depth| depth < 4, |w| *w, None);
    // Uneven refinement: two more levels per pass around one point (as in
    // `deeper_than_64_levels_at_a_point_cluster`), 30 passes.
    let corner = Vec3::new(-0.7, 2.2, 0.3);
    for _ in 0..30 {
        for w in t.data_slice_mut() {
            *w = 0.0;
        }
        let c = t.locate(corner).unwrap();
        *t.data_mut(c) = 20.0;
        t.refine(
            |w, _| *w > 8.0,
            |w| {
                *w *= 0.5;
                *w
            },
            None,
        );
    }
    assert!(t.max_depth() > 60, "{}", t.max_depth());
    let root = t.root_bounds();
    let mut checked = 0;
    let mut stayed = 0;
    let ps = points(3000, 9);
    let js = points(3000, 10);
    for (i, (u, j)) in ps.iter().zip(&js).enumerate() {
        let mut p = root.min + *u * root.diagonal();
        let (cell, b) = t.locate_with_bounds(p).unwrap();
        // Every third point sits on a face of its cell (split planes and
        // the root's faces).
        match i % 3 {
            1 => p.x = b.min.x,
            2 => p.y = b.max.y,
            _ => {}
        }
        let mut jitter = *j - 0.5;
        if i % 7 == 0 {
            jitter = Vec3::new(0.5 - f32::EPSILON, -0.5, 0.0);
        }
        if i % 5 == 0 {
            // Exactly onto the cell's upper corner (dyadic cells: exact), which
            // belongs to the neighbours unless it is the root's.
            p = b.max - 0.25 * b.diagonal();
            jitter = Vec3::splat(0.25);
        }
        let (cell, b) = t.locate_with_bounds(p).unwrap_or((cell, b));
        let q = root.clamp(p) + jitter * b.diagonal();
        let mut got = None;
        t.spread(
            p,
            SpatialFilter::StochasticBox,
            || jitter,
            |c, w| {
                assert_eq!(w, 1.0);
                got = Some(c);
            },
        );
        assert_eq!(got, t.locate(q), "point {p}, jitter {jitter}");
        stayed += (got == Some(cell)) as usize;
        checked += 1;
    }
    assert_eq!(checked, 3000);
    // Both branches ran.
    assert!(stayed > 300 && stayed < 2700, "{stayed}");
}
