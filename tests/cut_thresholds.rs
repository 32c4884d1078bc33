//! The cut's documented boundaries, pinned: a slot whose weight is at or
//! below `sigma * T` ends the cut and one above it is split
//! (`CutConfig::sigma`, `CutRules::refine`); the coarsest cut, at `sigma`
//! 1, has no node; at `sigma` 0 every slot with weight is split down to
//! single emitters.
//!
//! The scene is four equal point lights in two pairs far apart, so the
//! light tree is a root over two clusters of two leaves. With the paper's
//! rules the learned weights are the recorded sums themselves, exact in
//! `f64`, so the comparison with `sigma * T` is exercised at equality.

use glam::Vec3;
use guiding::cut::{CutConfig, CutRules, GuidingCut};
use guiding::light_tree::BuildHeuristic;
use guiding::{Emitter, LightHierarchy, LightId, LightTree};

/// Emitters 0, 1 at x = -10, -9 (cluster A), 2, 3 at x = 9, 10 (cluster B).
fn tree() -> LightTree {
    let lights: Vec<Emitter> = [-10.0, -9.0, 9.0, 10.0]
        .iter()
        .map(|&x| Emitter::point(Vec3::new(x, 0.0, 0.0), 1.0))
        .collect();
    let tree = LightTree::build(&lights, BuildHeuristic::Sah).unwrap();
    // The topology the tests rely on: root -> {0, 1}, {2, 3}.
    let [a, b] = tree.children(tree.root().unwrap()).unwrap();
    let leaves = |n: u32| {
        let mut e: Vec<u32> = tree
            .children(n)
            .unwrap()
            .iter()
            .map(|&c| tree.emitter(c).unwrap())
            .collect();
        e.sort();
        e
    };
    let mut pairs = [leaves(a), leaves(b)];
    pairs.sort();
    assert_eq!(pairs, [vec![0, 1], vec![2, 3]]);
    tree
}

fn rules(tree: &LightTree, sigma: f64) -> CutRules<&LightTree> {
    let config = CutConfig {
        sigma,
        min_records: 0,
        ..CutConfig::default()
    }
    .with_paper_rules();
    CutRules::new(tree, config).unwrap()
}

/// A cut refined once from records of `values[e]` for emitter `e`.
fn refined(rules: &CutRules<&LightTree>, values: [f32; 4]) -> GuidingCut {
    let mut cut = rules.new_cut();
    for (e, &v) in values.iter().enumerate() {
        if v > 0.0 {
            rules.record(&cut, LightId::Emitter(e as u32), v);
        }
    }
    rules.refine(&mut cut);
    assert!(cut.check(rules.light_tree()).is_ok());
    cut
}

/// The light-tree nodes where the cut ends, as sorted emitter lists.
fn clusters(tree: &LightTree, cut: &GuidingCut) -> Vec<Vec<u32>> {
    let mut out: Vec<Vec<u32>> = cut
        .clusters(tree)
        .iter()
        .map(|&(node, _)| {
            let mut emitters = Vec::new();
            let mut stack = vec![node];
            while let Some(n) = stack.pop() {
                match tree.children(n) {
                    Some(c) => stack.extend(c),
                    None => emitters.push(tree.emitter(n).unwrap()),
                }
            }
            emitters.sort();
            emitters
        })
        .collect();
    out.sort();
    out
}

/// T = 4, sigma = 1/4: cluster A's weight 1 is exactly sigma * T and ends
/// the cut; B's 3 is above and is split into its two emitters.
#[test]
fn a_slot_at_sigma_t_ends_the_cut() {
    let tree = tree();
    let r = rules(&tree, 0.25);
    let cut = refined(&r, [0.5, 0.5, 1.5, 1.5]);
    assert_eq!(clusters(&tree, &cut), [vec![0, 1], vec![2], vec![3]]);
    assert_eq!(cut.nodes().len(), 2, "the root and B");
}

/// The same with A's weight one f32 step above sigma * T (and T adjusted
/// so that sigma * T stays below it): A is split too.
#[test]
fn a_slot_just_above_sigma_t_is_split() {
    let tree = tree();
    let r = rules(&tree, 0.25);
    let a = 0.5f32;
    let a_up = f32::from_bits(a.to_bits() + 1);
    let cut = refined(&r, [a, a_up, 1.5, 1.5]);
    // T = 4 + 2^-24; sigma * T = 1 + 2^-26 < 1 + 2^-24 = A's weight.
    assert_eq!(clusters(&tree, &cut), [vec![0], vec![1], vec![2], vec![3]]);
    assert_eq!(cut.nodes().len(), 3, "the root, A and B");
}

/// At sigma 1 no slot is above the total: the cut has no node and samples
/// the whole tree below its root, whatever was learned.
#[test]
fn the_coarsest_cut_at_sigma_one_has_no_node() {
    let tree = tree();
    let r = rules(&tree, 1.0);
    for values in [
        [1.0, 0.0, 0.0, 0.0],
        [0.5, 0.5, 1.5, 1.5],
        [1e30, 1e-30, 3.0, 0.0],
    ] {
        let cut = refined(&r, values);
        assert!(cut.nodes().is_empty(), "{values:?}: {:?}", cut.nodes());
        assert_eq!(cut.clusters(&tree), [(tree.root().unwrap(), 1.0)]);
    }
    // Just below 1, the root (weight T > sigma * T) is split.
    let r = rules(&tree, 1.0 - 1e-9);
    assert_eq!(refined(&r, [0.5, 0.5, 1.5, 1.5]).nodes().len(), 1);
}

/// At sigma 0 every slot with weight is split down to single emitters; a
/// cluster that received nothing (weight 0, at or below 0 * T) ends the cut.
#[test]
fn sigma_zero_splits_every_slot_with_weight() {
    let tree = tree();
    let r = rules(&tree, 0.0);
    let cut = refined(&r, [0.5, 0.5, 1.5, 1.5]);
    assert_eq!(cut.nodes().len(), 3);
    let cut = refined(&r, [0.5, 0.5, 0.0, 0.0]);
    assert_eq!(clusters(&tree, &cut), [vec![0], vec![1], vec![2, 3]]);
}
