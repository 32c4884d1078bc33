//! Rebuilding a cut from what it collected: split where a slot's share is
//! above `sigma`, end (merge) where it is not.

use super::config::{Modulation, SplitPrior};
use super::cut_node::{CutNode, Slot};
use super::cut_rules::CutRules;
use super::guiding_cut::{GuidingCut, sum_count};
use super::importance_table::FastQuery;
use super::tables::Segment;
use super::walk::WalkNode;
use crate::light_sampler::ShadingContext;
use crate::light_tree::LightHierarchy;
use crate::math::Side;
use crate::spatial::Growth;
use alloc::vec;
use alloc::vec::Vec;

/// No parent: the task is the root.
const ROOT: u32 = u32::MAX;

/// A slot still to decide: where it hangs, the light node it stands for, its
/// weight and the old cut node that stood for the same light node (if any).
struct Task<'a> {
    parent: u32,
    side: Side,
    light: u32,
    /// The tables the light node is in (an instance's mesh's, inside one)
    /// and its walk-table entry there (locates its children's pair).
    seg: Segment<'a>,
    walk: WalkNode,
    /// The walk-table entry's depth in the hierarchy (inside an instance,
    /// the top tree's levels and the mesh's, as in the flattened tree).
    depth: u32,
    weight: f64,
    old: Option<u32>,
}

impl<H: LightHierarchy> CutRules<H> {
    /// Rebuilds `cut`'s sampled copy from the accumulated sums, then zeroes them
    /// (swapping the two copies). Returns false when the cell collected
    /// nothing from emitters: then the cut is kept as it was. A cut that
    /// recorded fewer than [`CutConfig::min_records`](super::CutConfig::min_records)
    /// non-zero records since its last rebuild is left entirely alone, sums
    /// included, to go on accumulating (also false).
    ///
    /// Top-down from the root with the cell's total `T`: a slot whose weight
    /// is above `sigma * T` and whose light node is not a leaf becomes a cut
    /// node. A node that existed before takes its children's weights from
    /// their sums; a slot split for the first time shares its weight by the
    /// [`SplitPrior`], and its children are examined in the same pass, so
    /// one pass may split several levels. A slot at or below `sigma * T`
    /// ends the cut, which merges any old subtree under it. The new
    /// `p_left = w_left / (w_left + w_right)` (weights in `f64`, stored as
    /// `f32`). Unbounded light `i`'s fraction becomes `U_i / (U + T)`, `U`
    /// the unbounded lights' total.
    pub fn refine(&self, cut: &mut GuidingCut) -> bool {
        self.refine_within(cut, None)
    }

    /// [`CutRules::refine`] building at most `max_nodes` cut nodes: while
    /// the rebuild would have more, it is redone with `sigma` doubled (the
    /// coarsest cut, at `sigma` 1, has none). Spatial structures use it to
    /// keep their cuts within a memory budget.
    pub(crate) fn refine_within(&self, cut: &mut GuidingCut, max_nodes: Option<usize>) -> bool {
        let config = self.config();
        let Some(plan) = self.plan(cut) else {
            // Too little data: keep the cut, keep accumulating.
            return false;
        };
        cut.recorded.reset();
        let total: f64 = plan.sums.iter().sum();
        let all = total + plan.unbounded.iter().sum::<f64>();
        if all > 0.0 && all.is_finite() {
            for (f, u) in cut.unbounded.iter_mut().zip(&plan.unbounded) {
                *f = (u / all) as f32;
            }
        }
        let rebuilt = total > 0.0 && total.is_finite();
        let mut old_nodes = Vec::new();
        if rebuilt {
            cut.modulated = plan.anchor.is_some();
            let mut sigma = config.sigma;
            let mut nodes = rebuild(self, &cut.nodes, &plan.sums, total, plan.anchor, sigma);
            while let Some(cap) = max_nodes.filter(|&cap| nodes.len() > cap && sigma < 1.0) {
                sigma = if sigma > 0.0 {
                    (2.0 * sigma).min(1.0)
                } else {
                    1.0 / (2 * cap + 2) as f64
                };
                nodes = rebuild(self, &cut.nodes, &plan.sums, total, plan.anchor, sigma);
            }
            old_nodes = core::mem::replace(&mut cut.nodes, nodes);
        }
        cut.sums
            .reset(sum_count(cut.nodes.len(), config.unbounded.count));
        cut.anchor.clear();
        if !cut.visibility.is_empty() {
            if !rebuilt {
                old_nodes = cut.nodes.clone();
            }
            self.relearn_visibility(cut, &old_nodes);
        }
        rebuilt
    }

    /// What `cut` will hold after [`CutRules::refine`] (which this does
    /// not change): its node count, the heap bytes per node (the node and
    /// its two sums) and those it holds whatever its nodes.
    pub(crate) fn growth(&self, cut: &GuidingCut) -> Growth {
        let per_sum = cut.sums.bytes_per_sum();
        let unbounded = cut.unbounded.len();
        let nodes = match self.plan(cut) {
            Some(plan) => {
                let total: f64 = plan.sums.iter().sum();
                if total > 0.0 && total.is_finite() {
                    let sigma = self.config().sigma;
                    rebuild(self, &cut.nodes, &plan.sums, total, plan.anchor, sigma).len()
                } else {
                    cut.nodes.len()
                }
            }
            None => cut.nodes.len(),
        };
        // A learned visibility per slot: the value and two sums.
        let per_slot = if cut.visibility.is_empty() {
            0
        } else {
            4 + 2 * per_sum
        };
        // Slots: two per node, or the root's one when there is none.
        let root_slot = usize::from(nodes == 0);
        Growth {
            fixed: (root_slot + unbounded) * (per_sum + per_slot)
                + cut.anchor.bytes()
                + 4 * unbounded,
            nodes,
            per_node: CutNode::BYTES + 2 * (per_sum + per_slot),
        }
    }

    /// What a refinement of `cut` starts from; `None` when the cut keeps
    /// accumulating ([`CutConfig::min_records`](super::CutConfig::min_records)).
    fn plan(&self, cut: &GuidingCut) -> Option<Plan> {
        let config = self.config();
        if cut.recorded.get() < u64::from(config.min_records) {
            return None;
        }
        let clusters = cut.first_unbounded_sum();
        // The importances at the anchor come from the same table (and
        // the same function) that sampling modulates with, so at the
        // anchor the modulated cut is exactly the learned one.
        let anchor = match (config.modulation, self.reads_importance()) {
            (Modulation::Importance, true) => {
                cut.anchor().map(|a| FastQuery::new(&ShadingContext::at(a)))
            }
            _ => None,
        };
        Some(Plan {
            sums: (0..clusters).map(|i| cut.sums.get(i)).collect(),
            unbounded: (clusters..cut.sums.len())
                .map(|i| cut.sums.get(i))
                .collect(),
            anchor,
        })
    }
}

/// The sums a refinement reads, and the anchor it modulates with.
struct Plan {
    sums: Vec<f64>,
    unbounded: Vec<f64>,
    anchor: Option<FastQuery>,
}

/// Weight of each old cut node's subtree (children follow parents, so one
/// backward pass suffices).
fn subtree_weights(nodes: &[CutNode], sums: &[f64]) -> Vec<f64> {
    let mut w = vec![0.0f64; nodes.len()];
    for i in (0..nodes.len()).rev() {
        let mut t = 0.0;
        for side in [Side::Left, Side::Right] {
            t += match nodes[i].child(side) {
                Some(j) => w.get(j as usize).copied().unwrap_or(0.0),
                None => sums.get(2 * i + side.index()).copied().unwrap_or(0.0),
            };
        }
        w[i] = t;
    }
    w
}

/// A fresh split's child weights. A dark child (zero power) gets nothing.
fn split_weight<H: LightHierarchy + ?Sized>(
    tree: &H,
    [l, r]: [u32; 2],
    weight: f64,
    prior: SplitPrior,
) -> (f64, f64) {
    let (el, er) = (tree.power(l) as f64, tree.power(r) as f64);
    let (el, er) = (el.max(0.0), er.max(0.0));
    if !(el > 0.0 || er > 0.0) {
        return (0.0, 0.0);
    }
    match prior {
        SplitPrior::Half => match (el > 0.0, er > 0.0) {
            (true, true) => (weight * 0.5, weight * 0.5),
            (true, false) => (weight, 0.0),
            _ => (0.0, weight),
        },
        SplitPrior::Power => {
            let t = el + er;
            (weight * (el / t), weight * (er / t))
        }
    }
}

/// Two importances, each at least 1e-6 of their sum; `None` when the sum
/// is zero or not finite.
fn floored((l, r): (f64, f64)) -> Option<(f64, f64)> {
    let t = l + r;
    (t > 0.0 && t.is_finite()).then(|| (l.max(1e-6 * t), r.max(1e-6 * t)))
}

/// A fresh split's child weights in proportion to the (floored)
/// importances at the anchor; a dark child (zero power) gets nothing.
/// `None` when no child can take the weight.
fn split_by_importance<H: LightHierarchy + ?Sized>(
    tree: &H,
    [l, r]: [u32; 2],
    weight: f64,
    (il, ir): (f64, f64),
) -> Option<(f64, f64)> {
    let lit = |n: u32, i: f64| if tree.power(n) > 0.0 { i } else { 0.0 };
    let (il, ir) = (lit(l, il), lit(r, ir));
    let t = il + ir;
    (t > 0.0 && t.is_finite()).then(|| (weight * il / t, weight * ir / t))
}

/// The stored `p_left` from the two sides' weights: their ratio, or with an
/// anchor ([`Modulation::Importance`]) the ratio of the learned factors
/// `weight / importance at the anchor`.
fn stored_p_left(weights: (f64, f64), importances: Option<(f64, f64)>) -> f32 {
    let (wl, wr) = weights;
    let (fl, fr) = match importances {
        Some((il, ir)) => (wl / il, wr / ir),
        None => (wl, wr),
    };
    let f = fl + fr;
    if f > 0.0 && f.is_finite() {
        (fl / f) as f32
    } else {
        (wl / (wl + wr)) as f32
    }
}

fn rebuild<'a, H: LightHierarchy>(
    guide: &'a CutRules<H>,
    old: &[CutNode],
    sums: &[f64],
    total: f64,
    anchor: Option<FastQuery>,
    sigma: f64,
) -> Vec<CutNode> {
    let (tree, config) = (guide.light_tree(), guide.config());
    let top = guide.top_segment(anchor.unwrap_or(FastQuery::unused()));
    let (Some(root), Some(root_walk)) = (tree.root(), top.walk.root()) else {
        return Vec::new();
    };
    // A walk-table entry, moved to its mesh's root at an instance's leaf.
    let place = |seg: Segment<'a>, walk| guide.enter(&seg, walk).unwrap_or((seg, walk));
    let (seg, walk) = place(top, root_walk);
    let threshold = sigma * total;
    let old_weights = subtree_weights(old, sums);
    let mut nodes: Vec<CutNode> = Vec::new();
    let mut stack = vec![Task {
        parent: ROOT,
        side: Side::Left,
        light: root,
        seg,
        walk,
        depth: 0,
        weight: total,
        old: (!old.is_empty()).then_some(0),
    }];
    while let Some(t) = stack.pop() {
        let mut slot = Slot::End(t.light);
        let split = tree.children(t.light).zip(t.walk.children());
        if let Some((children, pair)) = split.filter(|_| t.weight > threshold) {
            // The importances at the anchor come from the table and the
            // function sampling modulates with, the anchor seen as the
            // walk sees the point (in mesh space inside an instance).
            let imp = anchor
                .and_then(|_| guide.child_weights(&t.seg, t.walk, t.depth, None).0)
                .and_then(floored);
            // Each side's weight and the old node that stands for it.
            let sides: [(f64, Option<u32>); 2] = match t.old.and_then(|i| old.get(i as usize)) {
                Some(o) => {
                    let i = t.old.unwrap_or(0) as usize;
                    [Side::Left, Side::Right].map(|s| match o.child(s) {
                        Some(j) => (old_weights.get(j as usize).copied().unwrap_or(0.0), Some(j)),
                        None => (sums.get(2 * i + s.index()).copied().unwrap_or(0.0), None),
                    })
                }
                None => {
                    // A fresh split: with an anchor, in proportion to the
                    // importance there (equal learned factors), else by the
                    // split prior.
                    let (wl, wr) = imp
                        .and_then(|i| split_by_importance(tree, children, t.weight, i))
                        .unwrap_or_else(|| {
                            split_weight(tree, children, t.weight, config.split_prior)
                        });
                    [(wl, None), (wr, None)]
                }
            };
            let sum = sides[0].0 + sides[1].0;
            if sum > 0.0 {
                let index = nodes.len() as u32;
                let p_left = stored_p_left((sides[0].0, sides[1].0), imp);
                nodes.push(CutNode::new(
                    p_left,
                    [Slot::End(children[0]), Slot::End(children[1])],
                ));
                // Right first so the left subtree is numbered first
                // (pre-order).
                let walks = t.seg.walk.pair(pair).0;
                for side in [Side::Right, Side::Left] {
                    let (weight, old) = sides[side.index()];
                    // A mesh's root is as deep as its instance's leaf.
                    let (seg, walk) = place(t.seg, walks[side.index()]);
                    stack.push(Task {
                        parent: index,
                        side,
                        light: children[side.index()],
                        seg,
                        walk,
                        depth: t.depth + 1,
                        weight,
                        old,
                    });
                }
                slot = Slot::Child(index);
            }
        }
        if t.parent != ROOT {
            nodes[t.parent as usize].set_slot(t.side, slot);
        }
    }
    nodes
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cut::CutConfig;
    use crate::emitter::Emitter;
    use crate::light_sampler::{LightId, UnboundedLights};
    use crate::light_tree::{BuildHeuristic, LightTree};
    use crate::record::RecordOutcome;
    use glam::Vec3;

    /// What [`CutRules::growth`] predicts is what the refinement builds:
    /// the refined cut holds exactly `fixed + nodes * per_node` heap bytes,
    /// for a fresh cut and one refined before, with and without unbounded
    /// lights, learned visibility and the anchor (the memory budget splits
    /// what is left between cells by these predictions).
    #[test]
    fn growth_predicts_the_refined_cut_exactly() {
        let lights: Vec<Emitter> = (0..40)
            .map(|i| Emitter::point(Vec3::new(i as f32, (i % 7) as f32, 0.0), 1.0 + i as f32))
            .collect();
        let tree = LightTree::build(&lights, BuildHeuristic::Sarh).unwrap();
        let rich = CutConfig {
            visibility: true,
            unbounded: UnboundedLights::new(2, 0.1).unwrap(),
            ..CutConfig::default()
        };
        for config in [rich, CutConfig::default().with_paper_rules()] {
            let guide = CutRules::new(&tree, config).unwrap();
            let mut cut = guide.new_cut();
            for round in 0..3u32 {
                for k in 0..2000u32 {
                    let e = (k * 7 + round) % 40;
                    let l = LightId::Emitter(e);
                    let p = Vec3::new(e as f32, 0.0, 1.0);
                    guide.record_from(&cut, p, l, 1.0 + (e * e) as f32);
                    guide.record_visibility(&cut, l, (e % 3) as f32 / 2.0, 1.0);
                }
                if config.unbounded.count > 0 {
                    guide.record(&cut, LightId::Unbounded(1), 50.0);
                }
                let g = guide.growth(&cut);
                assert!(guide.refine(&mut cut), "round {round}");
                assert_eq!(
                    cut.heap_bytes(),
                    g.fixed + g.nodes * g.per_node,
                    "round {round}, {config:?}"
                );
                assert_eq!(g.nodes, cut.nodes.len());
            }
            assert!(cut.nodes.len() > 4, "the cut split");
        }
    }

    /// Under a node cap the rebuild is redone with `sigma` doubled (from
    /// `1 / (2 cap + 2)` when it is 0) until the cut fits: the capped cut
    /// is the uncapped one at the first such `sigma` that fits.
    #[test]
    fn a_node_cap_doubles_sigma_until_the_cut_fits() {
        let lights: Vec<Emitter> = (0..64)
            .map(|i| Emitter::point(Vec3::new(i as f32, (i % 5) as f32, 0.0), 1.0))
            .collect();
        let tree = LightTree::build(&lights, BuildHeuristic::Sarh).unwrap();
        for sigma0 in [0.01, 0.0] {
            let config = CutConfig {
                sigma: sigma0,
                ..CutConfig::default()
            };
            let guide = CutRules::new(&tree, config).unwrap();
            let trained = guide.new_cut();
            for k in 0..6000u32 {
                let e = (k * 13) % 64;
                guide.record(&trained, LightId::Emitter(e), 1.0 + ((e * 7) % 11) as f32);
            }
            let refined_at = |sigma: f64| {
                let rules = CutRules::new(&tree, CutConfig { sigma, ..config }).unwrap();
                let mut c = trained.clone();
                rules.refine(&mut c);
                c.nodes
            };
            let uncapped = refined_at(sigma0).len();
            assert!(uncapped > 8, "{uncapped}");
            for cap in [0, 1, 3, 8, uncapped - 1, uncapped, uncapped + 5] {
                let mut capped = trained.clone();
                assert!(guide.refine_within(&mut capped, Some(cap)));
                assert!(
                    capped.nodes.len() <= cap,
                    "cap {cap}: {}",
                    capped.nodes.len()
                );
                let mut sigma = sigma0;
                let expected = loop {
                    let nodes = refined_at(sigma);
                    if nodes.len() <= cap || sigma >= 1.0 {
                        break nodes;
                    }
                    sigma = if sigma > 0.0 {
                        (2.0 * sigma).min(1.0)
                    } else {
                        1.0 / (2 * cap + 2) as f64
                    };
                };
                assert_eq!(capped.nodes, expected, "cap {cap}, sigma {sigma0}");
            }
        }
    }

    /// Two emitters, the first of power `left`, the second `right`, and
    /// the root's children in emitter order (the left child is the
    /// first emitter).
    fn pair(left: f32, right: f32) -> (LightTree, [u32; 2]) {
        let lights = [
            Emitter::point(Vec3::ZERO, left),
            Emitter::point(Vec3::X, right),
        ];
        let tree = LightTree::build(&lights[..], BuildHeuristic::Sarh).unwrap();
        let mut children = tree.children(tree.root().unwrap()).unwrap();
        if tree.power(children[0]) != left {
            children.swap(0, 1);
        }
        (tree, children)
    }

    /// A fresh split shares its weight by the prior: evenly between lit
    /// children (all of it to the one lit child), or by power; a pair
    /// with no power takes nothing, never NaN.
    #[test]
    fn a_fresh_split_shares_its_weight_by_the_prior() {
        use SplitPrior::{Half, Power};
        let weights = |l: f32, r: f32, prior| {
            let (tree, children) = pair(l, r);
            split_weight(&tree, children, 8.0, prior)
        };
        assert_eq!(weights(1.0, 3.0, Half), (4.0, 4.0));
        assert_eq!(weights(1.0, 3.0, Power), (2.0, 6.0));
        assert_eq!(weights(1.0, 0.0, Half), (8.0, 0.0));
        assert_eq!(weights(0.0, 3.0, Half), (0.0, 8.0));
        assert_eq!(weights(0.0, 3.0, Power), (0.0, 8.0));
        assert_eq!(weights(0.0, 0.0, Half), (0.0, 0.0));
        assert_eq!(weights(0.0, 0.0, Power), (0.0, 0.0));
    }

    /// With an anchor a fresh split follows the importances there, a dark
    /// child (no power) getting nothing whatever its importance; no split
    /// weight when neither side can take it. The importances are floored
    /// at 1e-6 of their sum.
    #[test]
    fn a_fresh_split_follows_the_importance_at_the_anchor() {
        let (tree, children) = pair(1.0, 1.0);
        assert_eq!(
            split_by_importance(&tree, children, 8.0, (1.0, 3.0)),
            Some((2.0, 6.0))
        );
        assert_eq!(split_by_importance(&tree, children, 8.0, (0.0, 0.0)), None);
        assert_eq!(
            split_by_importance(&tree, children, 8.0, (f64::INFINITY, 1.0)),
            None
        );
        let (tree, children) = pair(0.0, 1.0);
        assert_eq!(
            split_by_importance(&tree, children, 8.0, (5.0, 3.0)),
            Some((0.0, 8.0))
        );
        assert_eq!(split_by_importance(&tree, children, 8.0, (5.0, 0.0)), None);

        assert_eq!(floored((3.0, 1.0)), Some((3.0, 1.0)));
        assert_eq!(floored((0.0, 2.0)), Some((2e-6, 2.0)));
        assert_eq!(floored((4.0, 0.0)), Some((4.0, 4e-6)));
        assert_eq!(floored((0.0, 0.0)), None);
        assert_eq!(floored((f64::INFINITY, 1.0)), None);
        assert_eq!(floored((f64::NAN, 1.0)), None);
    }

    /// The stored `p_left` is the weights' ratio, or with importances the
    /// ratio of the learned factors `weight / importance`; where those
    /// overflow or underflow, the weights' ratio.
    #[test]
    fn p_left_is_the_ratio_of_the_learned_factors() {
        assert_eq!(stored_p_left((1.0, 3.0), None), 0.25);
        assert_eq!(stored_p_left((1.0, 3.0), Some((1.0, 3.0))), 0.5);
        assert_eq!(stored_p_left((1.0, 3.0), Some((1.0, 1.0))), 0.25);
        assert_eq!(stored_p_left((3.0, 1.0), Some((1.0, 9.0))), 27.0 / 28.0);
        assert_eq!(stored_p_left((1e300, 3e300), Some((1e-300, 1.0))), 0.25);
        // Factors that underflow to 0 (a sum of 0, not NaN): the weights.
        assert_eq!(stored_p_left((1e-300, 3e-300), Some((1e300, 1e300))), 0.25);
    }

    /// [`CutRules::growth`] with nothing learned from emitters (only an
    /// unbounded light recorded): the refinement keeps the cut, and the
    /// prediction keeps its node count.
    #[test]
    fn growth_keeps_the_cut_when_only_unbounded_lights_were_recorded() {
        let lights: Vec<Emitter> = (0..16)
            .map(|i| Emitter::point(Vec3::new(i as f32, 0.0, 0.0), 1.0 + i as f32))
            .collect();
        let tree = LightTree::build(&lights, BuildHeuristic::Sarh).unwrap();
        let config = CutConfig {
            unbounded: UnboundedLights::new(1, 0.1).unwrap(),
            ..CutConfig::default()
        };
        let guide = CutRules::new(&tree, config).unwrap();
        let mut cut = guide.new_cut();
        for k in 0..4000u32 {
            guide.record(&cut, LightId::Emitter(k % 16), 1.0 + (k % 16) as f32);
        }
        assert!(guide.refine(&mut cut));
        let nodes = cut.nodes.len();
        assert!(nodes > 2, "{nodes}");
        for _ in 0..4000 {
            guide.record(&cut, LightId::Unbounded(0), 1.0);
        }
        let g = guide.growth(&cut);
        assert!(!guide.refine(&mut cut));
        assert_eq!((g.nodes, cut.nodes.len()), (nodes, nodes));
    }

    /// Records on lights without power (a renderer's power estimate can
    /// be 0 where its emission is not) are dropped, so a dark cluster never
    /// holds a weight to split (neither child could take it) and no cut
    /// node gets a `p_left` of `0 / 0`. (The rebuild's `sum > 0` guard on
    /// such a split cannot be reached through records: its `>=` mutant is
    /// equivalent.)
    #[test]
    fn records_on_dark_lights_split_nothing_dark() {
        let lights = [
            Emitter::point(Vec3::ZERO, 1.0),
            Emitter::point(Vec3::X, 2.0),
            Emitter::point(Vec3::new(100.0, 0.0, 0.0), 0.0),
            Emitter::point(Vec3::new(101.0, 0.0, 0.0), 0.0),
        ];
        let tree = LightTree::build(&lights[..], BuildHeuristic::Sarh).unwrap();
        let config = CutConfig {
            sigma: 0.0,
            ..CutConfig::default()
        };
        let guide = CutRules::new(&tree, config).unwrap();
        let mut cut = guide.new_cut();
        // The first refinement ends the cut at the dark cluster (the prior
        // gives it nothing); the second finds it holding records.
        for round in 0..2 {
            for k in 0..4000u32 {
                let outcome = guide.record(&cut, LightId::Emitter(k % 4), 1.0);
                let dark = k % 4 >= 2;
                assert_eq!(outcome == RecordOutcome::Dropped, dark, "light {}", k % 4);
            }
            guide.refine(&mut cut);
            assert!(!cut.nodes.is_empty());
            for node in &cut.nodes {
                assert!(
                    (0.0..=1.0).contains(&node.p_left()),
                    "round {round}: {node:?}"
                );
            }
        }
    }
}
