//! The GLT's sampling rule and its pmf.
//!
//! For a shading point in a cell with cut `C`, emitter `l` is chosen with
//!
//! ```text
//! pmf(l)   = (1 - alpha) (1 - F) P_cut(l) + alpha (1 - q) P_prior(l)
//! pmf(u_i) = (1 - alpha) f_i + alpha q / k
//! ```
//!
//! with `alpha` the defensive weight raised by the cut's doubt,
//! `1 - (1 - alpha) confidence` ([`GuidingCut::confidence`]: 1
//! for a cut learned from its own cell, so usually `alpha` itself),
//! where `f_i` is the cell's learned fraction of unbounded light `u_i` (of
//! `k`, `F` their sum), `q` the user's prior probability of the unbounded
//! lights together (both 0 without any), `P_prior` the
//! prior's pmf from the light tree's root (tree-by-power, or
//! tree-by-importance at the shading point with [`Prior::Importance`]), and
//! `P_cut` the product of the cut's probabilities down to the slot that ends
//! the cut, then of the light tree's power ratios (the paper) or importance
//! ratios ([`BelowCut::Importance`]) below it. Inside the cut a node's
//! probabilities are its learned `p_left` (the paper: one distribution per
//! cell) or, with [`Modulation::Importance`], its learned factor ratio `r`
//! times the children's importance `I` at the shading point:
//! `r I_l / (r I_l + (1 - r) I_r)`, so the distribution follows the point
//! inside the cell.
//!
//! One uniform number drives everything through one [`Descent`]: first
//! unbounded lights or emitters (then which unbounded light), then which
//! mixture component, then the walk
//! from the light tree's root to a leaf under the chosen component's
//! probabilities. Along that one walk both products (`P_cut` and `P_prior`)
//! are tracked, so the mixture pmf of the chosen emitter is known without a
//! second walk. [`Rule::step`] computes the probabilities at a node and
//! [`Rule::apply`] multiplies them in; the pmf evaluation replays exactly
//! these two functions along the emitter's path, so the pmf `sample` returns
//! equals [`CutRules::pmf_exact`] bit for bit, fallbacks included.

use super::child_weights::Lanes;
use super::config::{BelowCut, CutConfig, Modulation, Prior};
use super::cut_node::CutNode;
use super::cut_rules::CutRules;
use super::guiding_cut::{GuidingCut, sum_count};
use super::importance_table::FastQuery;
use super::instanced_tables::{InstancedTables, mesh_of};
use super::split_table::decode_split;
use super::tables::Segment;
use super::walk::{PathCode, WalkNode};
use crate::light_sampler::ShadingContext;
use crate::light_sampler::{LightId, LightSample, choose_unbounded};
use crate::light_tree::{InstancedLightTree, LightHierarchy};
use crate::math::{Descent, Side, pmf_to_f32};
use smallvec::SmallVec;

/// The probabilities of the top-level choices in one cell.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Mixture {
    /// Probability of the unbounded lights together.
    pub(crate) unbounded: f64,
    /// Unbounded light `i` has probability `learned * f_i + floor` (`f_i`
    /// its learned fraction in the cell).
    learned: f64,
    floor: f64,
    /// Weight of the learned component (`(1 - alpha)(1 - F)`, `F` the
    /// unbounded lights' learned fractions together).
    pub(crate) cut: f64,
    /// Weight of the prior component (`alpha (1 - q)`).
    pub(crate) prior: f64,
}

impl Mixture {
    /// The mixture for `cut` under a validated `config`. Emitters get
    /// nothing when the light tree has no power at all (then the unbounded
    /// lights, if any, share everything in proportion to their weights).
    #[inline]
    pub(crate) fn new(emitters: bool, cut: &GuidingCut, config: &CutConfig) -> Self {
        // Trust what the cut learned only as far as it learned it in its
        // own cell: exactly `alpha` at confidence 1, exactly 1 (the prior
        // alone) at 0.
        let a = if cut.confidence < 1.0 {
            1.0 - (1.0 - config.alpha) * f64::from(cut.confidence)
        } else {
            config.alpha
        };
        let k = cut.unbounded.len();
        if k == 0 {
            return Self {
                unbounded: 0.0,
                learned: 0.0,
                floor: 0.0,
                cut: if emitters { 1.0 - a } else { 0.0 },
                prior: if emitters { a } else { 0.0 },
            };
        }
        let q = config.unbounded.probability;
        // The learned fractions sum to at most 1 up to their f32 rounding;
        // scale them down if they overshoot, so every weight stays >= 0.
        let f: f64 = cut.unbounded.iter().map(|&x| f64::from(x.max(0.0))).sum();
        let scale = if f > 1.0 { 1.0 / f } else { 1.0 };
        let f = f * scale;
        let (learned, floor) = ((1.0 - a) * scale, a * q / k as f64);
        if emitters {
            return Self {
                unbounded: (1.0 - a) * f + a * q,
                learned,
                floor,
                cut: (1.0 - a) * (1.0 - f),
                prior: a * (1.0 - q),
            };
        }
        // Only unbounded lights: normalize their weights (equal shares
        // when none has weight).
        let total = (1.0 - a) * f + a * q;
        let (learned, floor) = if total > 0.0 {
            (learned / total, floor / total)
        } else {
            (0.0, 1.0 / k as f64)
        };
        Self {
            unbounded: 1.0,
            learned,
            floor,
            cut: 0.0,
            prior: 0.0,
        }
    }

    /// This mixture among the lights a point is lit by: unbounded light
    /// `i` only where `received(i)`, the emitters only where `emitters`;
    /// the weights left renormalised (equal shares among the received
    /// unbounded lights if none keeps weight), all 0 when nothing is left.
    fn restricted(self, fractions: &[f32], received: impl Fn(u32) -> bool, emitters: bool) -> Self {
        let k = fractions.len() as u32;
        let kept = (0..k).filter(|&i| received(i)).count();
        if kept == k as usize && emitters {
            return self;
        }
        let unbounded: f64 = (0..k)
            .filter(|&i| received(i))
            .map(|i| self.unbounded_pmf(fractions[i as usize]))
            .sum();
        let (cut, prior) = if emitters {
            (self.cut, self.prior)
        } else {
            (0.0, 0.0)
        };
        let total = unbounded + cut + prior;
        if total > 0.0 {
            return Self {
                unbounded: unbounded / total,
                learned: self.learned / total,
                floor: self.floor / total,
                cut: cut / total,
                prior: prior / total,
            };
        }
        Self {
            unbounded: if kept > 0 { 1.0 } else { 0.0 },
            learned: 0.0,
            floor: if kept > 0 { 1.0 / kept as f64 } else { 0.0 },
            cut: 0.0,
            prior: 0.0,
        }
    }

    /// The pmf of an emitter from its two products. Sampling and
    /// evaluation both end here.
    #[inline]
    fn emitter_pmf(&self, p: Products) -> f64 {
        self.cut * p.cut + self.prior * p.prior
    }

    /// The pmf of unbounded light `i`, of fraction `f` in the cell.
    /// Sampling and evaluation both end here.
    #[inline]
    fn unbounded_pmf(&self, f: f32) -> f64 {
        self.learned * f64::from(f.max(0.0)) + self.floor
    }
}

/// What a GPU snapshot (`crate::snapshot`) precomputes of one cell: its
/// [`Mixture`]'s weights and whether its cut is modulated and its prior
/// tracked, exactly as [`Rule::new`] derives them for a point that every
/// light may light.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct CellWeights {
    /// Probability of the unbounded lights together.
    pub(crate) unbounded: f64,
    /// Weight of a learned unbounded fraction.
    pub(crate) learned: f64,
    /// Each unbounded light's floor.
    pub(crate) floor: f64,
    /// Weight of the cut component.
    pub(crate) cut: f64,
    /// Weight of the prior component.
    pub(crate) prior: f64,
    /// [`Modulation::Importance`] applies to this cut.
    pub(crate) modulate: bool,
}

impl<H: LightHierarchy> CutRules<H> {
    /// The weights of `cut`'s mixture for the snapshot.
    pub(crate) fn cell_weights(&self, cut: &GuidingCut) -> CellWeights {
        let config = self.config();
        let m = Mixture::new(self.has_power(), cut, config);
        CellWeights {
            unbounded: m.unbounded,
            learned: m.learned,
            floor: m.floor,
            cut: m.cut,
            prior: m.prior,
            modulate: config.modulation == Modulation::Importance && cut.modulated,
        }
    }
}

/// Where a walk is: a light-tree node's walk-table entry in the walk's
/// current [`Segment`] (which also locates its children in the importance
/// table) and, while inside the cut, the cut node that stands for it.
#[derive(Clone, Copy, Debug)]
struct Cursor {
    node: WalkNode,
    cut: Option<CutNode>,
}

/// A sampling walk's state: where it is, the products so far, and the
/// cut node it is in while it is inside the cut (tracked only when the
/// caller asks for the slot it leaves the cut by).
#[derive(Clone, Copy, Debug)]
struct Walk {
    at: Cursor,
    p: Products,
    in_cut: Option<u32>,
    /// The depth of `at` in the whole hierarchy (inside an instance, the
    /// top tree's levels and the mesh's, as in the flattened tree): the
    /// parity the importance rule weighs by (`child_weights.rs`).
    depth: u32,
}

/// Where a pmf walk is in the hierarchy: its depth (the parity the
/// importance rule weighs by) and the lanes its last level evaluated, with
/// the side it took there.
#[derive(Clone, Copy)]
struct Depth {
    depth: u32,
    carry: Option<(Lanes, usize)>,
}

impl Depth {
    /// At depth `depth`, nothing carried.
    fn at(depth: u32) -> Self {
        Self { depth, carry: None }
    }
}

/// The probabilities at one inner light-tree node.
#[derive(Clone, Copy, Debug)]
struct Step {
    /// Learned component: the cut's `p_left` inside the cut, the below-cut
    /// rule under it. `None` where neither side can be chosen.
    cut: Option<(f64, f64)>,
    /// Prior component: power ratios (`None` when not tracked or both
    /// children are dark).
    prior: Option<(f64, f64)>,
    /// The cut node on each side, `None` where the cut ends.
    next: [Option<u32>; 2],
}

/// Running products of the two components along a walk.
#[derive(Clone, Copy, Debug)]
struct Products {
    cut: f64,
    prior: f64,
}

/// The deepest level a [`StepMemo`] keeps (deeper levels are computed
/// every time).
const MEMO_LEVELS: usize = 16;

/// Where a walk's steps come from: computed at every node ([`NoMemo`],
/// one sample) or remembered across the walks of one point
/// ([`StepMemo`], resampling candidates).
trait Memo {
    /// Whether anything is remembered (else the walk never asks).
    const ACTIVE: bool;

    /// The step remembered at level `level` of the top segment for the
    /// node whose children are walk-table pair `key`.
    fn get(&self, level: usize, key: u32) -> Option<Step>;

    /// Remembers `step`, computed at that node.
    fn put(&mut self, level: usize, key: u32, step: Step);
}

/// Every step computed where it is needed.
struct NoMemo;

impl Memo for NoMemo {
    const ACTIVE: bool = false;

    #[inline(always)]
    fn get(&self, _: usize, _: u32) -> Option<Step> {
        None
    }

    #[inline(always)]
    fn put(&mut self, _: usize, _: u32, _: Step) {}
}

/// The last step computed at each level of the top segment, by the node it
/// was computed at. The candidates of one point pass through the same
/// nodes near the root (and, where the learned choice is sharp, further
/// down), and a node's step depends only on the node and the point, so a
/// walk that reaches the node a level's entry holds takes it instead of
/// evaluating the children's importance again: the same bits for less
/// work. The key names the node (its children's walk-table pair is unique
/// in the segment), so an entry is never wrong, only replaced. A walk
/// reaches level `l` only through levels `0..l`, so the levels fill in
/// order (nothing is initialised ahead).
struct StepMemo {
    levels: SmallVec<[(u32, Step); MEMO_LEVELS]>,
}

impl StepMemo {
    fn new() -> Self {
        Self {
            levels: SmallVec::new(),
        }
    }
}

impl Memo for StepMemo {
    const ACTIVE: bool = true;

    #[inline(always)]
    fn get(&self, level: usize, key: u32) -> Option<Step> {
        self.levels
            .get(level)
            .and_then(|&(k, step)| (k == key).then_some(step))
    }

    #[inline(always)]
    fn put(&mut self, level: usize, key: u32, step: Step) {
        let filled = self.levels.len();
        if level < filled {
            self.levels[level] = (key, step);
        } else if level == filled && level < MEMO_LEVELS {
            // Never past the inline capacity: no allocation.
            self.levels.push((key, step));
        }
    }
}

/// `pair` with each side times its factor in `seen`, renormalised; `None`
/// where neither side keeps any probability.
#[inline(always)]
fn restrict(pair: Option<(f64, f64)>, (sl, sr): (f64, f64)) -> Option<(f64, f64)> {
    let (l, r) = pair?;
    Descent::probabilities(l * sl, r * sr)
}

/// The probability of `side` in a pair.
#[inline]
fn pick((pl, pr): (f64, f64), side: Side) -> f64 {
    match side {
        Side::Left => pl,
        Side::Right => pr,
    }
}

/// Everything one query needs: the cut rules, the cell's cut nodes, the
/// rule below the cut and the shading point.
struct Rule<'b, H: LightHierarchy, R: Restriction> {
    guide: &'b CutRules<H>,
    tree: &'b H,
    /// The tables at the root, with the shading point prepared for the
    /// decoded nodes (only the importance rules read it).
    top: Segment<'b>,
    nodes: &'b [CutNode],
    below: BelowCut,
    /// Whether the cut's probabilities follow the importance at the
    /// shading point ([`Modulation::Importance`]).
    modulate: bool,
    /// Whether the prior component follows the importance ([`Prior`]).
    prior_importance: bool,
    /// Whether the prior component has weight (else its product is not
    /// tracked and stays 1, multiplied by a zero weight).
    prior: bool,
    mixture: Mixture,
    /// The cell's learned fractions of the unbounded lights.
    unbounded: &'b [f32],
    /// The emitters the point may be lit by.
    restriction: R,
}

/// Which emitters a point may be lit by: every one ([`Unrestricted`], a
/// type of no size, so a walk without light sets reads none) or those in
/// the light sets it receives ([`Receives`]).
trait Restriction: Copy {
    /// Whether any step reads a light set.
    const LINKED: bool;

    /// `step` at a node whose split-table entry is `split` and whose
    /// children have the light sets `sets` returns: each component
    /// restricted to the sides that may light the point and renormalised.
    fn restrict(self, step: Step, split: f32, sets: impl FnOnce() -> Option<[u64; 2]>) -> Step;

    /// Whether emitters with light sets `sets` may light the point.
    fn reaches(self, sets: u64) -> bool;

    /// Whether unbounded light `i` may light the point.
    fn unbounded(self, i: u32) -> bool;
}

/// Every emitter may light the point.
#[derive(Clone, Copy)]
struct Unrestricted;

impl Restriction for Unrestricted {
    const LINKED: bool = false;

    #[inline(always)]
    fn restrict(self, step: Step, _: f32, _: impl FnOnce() -> Option<[u64; 2]>) -> Step {
        step
    }

    #[inline(always)]
    fn reaches(self, _: u64) -> bool {
        true
    }

    #[inline(always)]
    fn unbounded(self, _: u32) -> bool {
        true
    }
}

/// Only emitters in one of these light sets (one bit per set) and the
/// unbounded lights of the second mask may light the point
/// ([`ShadingContext::receives`], [`ShadingContext::receives_unbounded`]).
#[derive(Clone, Copy)]
struct Receives(u64, u64);

impl Restriction for Receives {
    const LINKED: bool = true;

    #[inline(always)]
    fn restrict(self, step: Step, split: f32, sets: impl FnOnce() -> Option<[u64; 2]>) -> Step {
        let Some(sets) = sets() else {
            return step;
        };
        let f = |s: u64| f64::from(u8::from(self.reaches(s)));
        let seen = (f(sets[0]), f(sets[1]));
        // Where the learned choice had no mass on the sides that may light
        // the point, the prior's power split takes over, so each component
        // stays a distribution over the lights the point receives.
        Step {
            cut: restrict(step.cut, seen).or_else(|| restrict(decode_split(split), seen)),
            prior: restrict(step.prior, seen).or_else(|| restrict(decode_split(split), seen)),
            next: step.next,
        }
    }

    #[inline(always)]
    fn reaches(self, sets: u64) -> bool {
        sets & self.0 != 0
    }

    #[inline(always)]
    fn unbounded(self, i: u32) -> bool {
        i >= 64 || self.1 & (1 << i) != 0
    }
}

impl<'b, H: LightHierarchy, R: Restriction> Rule<'b, H, R> {
    /// The rule for `cut` at `ctx`, choosing among the emitters
    /// `restriction` lets light it.
    #[inline]
    pub(crate) fn new(
        guide: &'b CutRules<H>,
        cut: &'b GuidingCut,
        ctx: &'b ShadingContext,
        restriction: R,
    ) -> Self {
        let config = guide.config();
        // Emitters take part when some has power and, under light linking,
        // some is in a set the point receives.
        let emitters = guide.has_power()
            && (!R::LINKED || {
                let tree = guide.light_tree();
                tree.root()
                    .is_some_and(|n| restriction.reaches(tree.light_sets(n)))
            });
        let mut mixture = Mixture::new(emitters, cut, config);
        if R::LINKED {
            mixture = mixture.restricted(&cut.unbounded, |i| restriction.unbounded(i), emitters);
        }
        let modulate = config.modulation == Modulation::Importance && cut.modulated;
        let prior_importance = config.prior == Prior::Importance;
        Self {
            guide,
            tree: guide.light_tree(),
            top: guide.top_segment(match guide.reads_importance() {
                true => FastQuery::new(ctx),
                false => FastQuery::unused(),
            }),
            nodes: &cut.nodes,
            below: config.below_cut,
            modulate,
            prior_importance,
            prior: mixture.prior > 0.0,
            mixture,
            unbounded: &cut.unbounded,
            restriction,
        }
    }

    #[inline(always)]
    fn root(&self) -> Option<Cursor> {
        Some(Cursor {
            node: self.top.walk.root()?,
            cut: self.nodes.first().copied(),
        })
    }

    /// The cut nodes on both sides below a step (`None` where the cut
    /// ends), read before the walk chooses a side so the next level's load
    /// overlaps with this one's arithmetic.
    #[inline(always)]
    fn cut_children(&self, step: &Step) -> [Option<CutNode>; 2] {
        step.next
            .map(|c| c.and_then(|i| self.nodes.get(i as usize).copied()))
    }

    /// Whether a rule reads the importance at `at`.
    #[inline(always)]
    fn needs_importance(&self, at: &Cursor) -> bool {
        self.prior_importance
            || match at.cut {
                Some(_) => self.modulate,
                None => self.below == BelowCut::Importance,
            }
    }

    /// The importance weights of the children at `at`, at depth `depth` of
    /// segment `seg`, from the lanes `carried` from its parent
    /// ([`Segment::child_weights`]), when a rule reads them; and the lanes
    /// for the level below.
    #[inline(always)]
    fn weights(
        &self,
        seg: &Segment,
        at: &Cursor,
        depth: u32,
        carried: Option<(Lanes, usize)>,
    ) -> (Option<(f64, f64)>, Option<Lanes>) {
        match self.needs_importance(at) {
            true => self.guide.child_weights(seg, at.node, depth, carried),
            false => (None, None),
        }
    }

    /// The probabilities of both components at the inner node `at` of
    /// segment `seg`, whose split-table entry is `split`.
    ///
    /// - Inside the cut the learned component takes the cut node's
    ///   `p_left`, or with [`Modulation::Importance`] the learned factor
    ///   ratio times the children's importance at the shading point (the
    ///   learned `p_left` where both importances vanish).
    /// - Below the cut it takes the [`BelowCut`] rule (power where both
    ///   importances vanish, so the component stays a distribution).
    /// - The prior component takes the [`Prior`] rule (likewise).
    ///
    /// The children's importances are evaluated at most once per node.
    ///
    /// Light sets restrict it afterwards ([`Restriction::restrict`]).
    #[inline(always)]
    fn step(&self, at: Cursor, split: f32, imp: Option<(f64, f64)>) -> Step {
        let needs_importance = self.needs_importance(&at);
        // The power split is decoded only where a rule falls back to it
        // (callgrind on trained city cuts: 436 instructions a sample when
        // decoded at every level, docs/benchmarks.md).
        let power = || decode_split(split);
        // The importance ratio, the prior's and the below-cut rule's alike,
        // computed once.
        let by_importance = match needs_importance {
            true => imp
                .and_then(|(l, r)| Descent::probabilities(l, r))
                .or_else(power),
            false => None,
        };
        let prior = match (self.prior, self.prior_importance) {
            (false, _) => None,
            (true, false) => power(),
            (true, true) => by_importance,
        };
        match at.cut {
            Some(node) => {
                let learned = node.probabilities();
                let cut = match imp.filter(|_| self.modulate) {
                    Some((il, ir)) => {
                        Descent::probabilities(learned.0 * il, learned.1 * ir).unwrap_or(learned)
                    }
                    None => learned,
                };
                Step {
                    cut: Some(cut),
                    prior,
                    next: [node.child(Side::Left), node.child(Side::Right)],
                }
            }
            None => Step {
                cut: match self.below {
                    BelowCut::Power => power(),
                    BelowCut::Importance => by_importance,
                },
                prior,
                next: [None, None],
            },
        }
    }

    /// Multiplies the probabilities of `side` at `step` into `p`.
    #[inline(always)]
    fn apply(&self, p: &mut Products, step: &Step, side: Side) {
        p.cut = match step.cut {
            Some(pair) => p.cut * pick(pair, side),
            None => 0.0,
        };
        if self.prior {
            p.prior = match step.prior {
                Some(pair) => p.prior * pick(pair, side),
                None => 0.0,
            };
        }
    }

    /// Samples a light with the descent `d`; the light, its `f64` pmf and
    /// the index of its sum in the cut (the slot where the walk left the
    /// cut, or its unbounded light's: [`CutRules::sum_of`] of the light,
    /// found without a second walk) when `SUM` (else 0: the walk that does
    /// not need it does not track it).
    /// Steps come from `memo` (the walks of one point's candidates share
    /// it).
    fn sample<const SUM: bool>(
        &self,
        mut d: Descent,
        sum: &mut usize,
        memo: &mut impl Memo,
    ) -> Option<(LightId, f64)> {
        let m = self.mixture;
        if m.unbounded > 0.0 {
            let (pu, pe) = Descent::probabilities(m.unbounded, m.cut + m.prior)?;
            if d.choose_with(pu, pe) == Side::Left {
                let f = self.unbounded;
                let weight = |i: u32| match self.restriction.unbounded(i) {
                    true => m.unbounded_pmf(f[i as usize]),
                    false => 0.0,
                };
                let i = choose_unbounded(&mut d, f.len() as u32, weight)?;
                if SUM {
                    // After the cluster sums (`GuidingCut::first_unbounded_sum`).
                    *sum = sum_count(self.nodes.len(), 0) + i as usize;
                }
                return Some((LightId::Unbounded(i), weight(i)));
            }
        }
        let use_cut = match (m.cut > 0.0, self.prior) {
            (true, true) => {
                let (pc, pp) = Descent::probabilities(m.cut, m.prior)?;
                d.choose_with(pc, pp) == Side::Left
            }
            (true, false) => true,
            (false, true) => false,
            (false, false) => return None,
        };
        let at = self.root()?;
        let mut w = Walk {
            at,
            p: Products {
                cut: 1.0,
                prior: 1.0,
            },
            // The cut node the walk is in (the root's only slot when the
            // cut has no nodes).
            in_cut: at.cut.filter(|_| SUM).map(|_| 0u32),
            depth: 0,
        };
        if SUM {
            *sum = 0;
        }
        self.descend::<SUM, _>(&self.top, &mut w, &mut d, use_cut, sum, memo)?;
        let leaf = w.at.node.emitter()?;
        let emitter = match self.guide.instanced() {
            None => leaf,
            Some((tables, _)) => {
                self.descend_instance::<SUM>(tables, leaf, &mut w, d, use_cut, sum)?
            }
        };
        Some((LightId::Emitter(emitter), m.emitter_pmf(w.p)))
    }

    /// Walks `w` down segment `seg` to a leaf with the descent `d`, under
    /// the cut's probabilities when `use_cut` (else the prior's), writing
    /// the slot the walk leaves the cut by to `sum` when `SUM`, its steps
    /// from `memo`. `None` where neither side can be chosen.
    #[inline(always)]
    fn descend<const SUM: bool, M: Memo>(
        &self,
        seg: &Segment,
        w: &mut Walk,
        d: &mut Descent,
        use_cut: bool,
        sum: &mut usize,
        memo: &mut M,
    ) -> Option<()> {
        let walk = seg.walk;
        // A copy the loop keeps in registers, written back at the end.
        let (mut at, mut p, mut in_cut, mut depth) = (w.at, w.p, w.in_cut, w.depth);
        let mut children = at.node.children().map(|k| walk.pair(k));
        // The lanes the last level evaluated and the side taken there.
        let mut carry: Option<(Lanes, usize)> = None;
        while let Some(pair) = children {
            // Load the next level for both sides before choosing: these
            // loads do not depend on `u`, so they overlap with this level's
            // choice instead of waiting for it (the walk is latency-bound).
            let grand = walk.grandchildren(pair);
            let split = at.node.split;
            let compute = || {
                let (imp, lanes) = self.weights(seg, &at, depth, carry);
                let step = self
                    .restriction
                    .restrict(self.step(at, split, imp), split, || {
                        at.node.children().map(|k| seg.pair_sets(k))
                    });
                (step, lanes)
            };
            let (step, lanes) = match M::ACTIVE {
                // One sample: the loop as if there were no memo.
                false => compute(),
                true => {
                    // A remembered step comes without its lanes: the level
                    // below evaluates its own (the same bits).
                    let key = at.node.children().unwrap_or(u32::MAX);
                    match memo.get(depth as usize, key) {
                        Some(step) => (step, None),
                        None => {
                            let (step, lanes) = compute();
                            memo.put(depth as usize, key, step);
                            (step, lanes)
                        }
                    }
                }
            };
            let cuts = self.cut_children(&step);
            let (pl, pr) = if use_cut { step.cut } else { step.prior }?;
            let side = d.choose_with(pl, pr);
            self.apply(&mut p, &step, side);
            let k = side.index();
            carry = lanes.map(|l| (l, k));
            depth += 1;
            if let Some(i) = in_cut {
                in_cut = step.next[k];
                if in_cut.is_none() {
                    *sum = 2 * i as usize + k;
                }
            }
            at = Cursor {
                node: pair.0[k],
                cut: cuts[k],
            };
            children = at.node.children().map(|_| grand[k]);
        }
        *w = Walk {
            at,
            p,
            in_cut,
            depth,
        };
        Some(())
    }

    /// The walk on from the top tree's leaf of instance `i`: into its
    /// mesh's tables, the point seen from mesh space, down to an emitter;
    /// its id.
    #[inline(always)]
    fn descend_instance<const SUM: bool>(
        &self,
        tables: &InstancedTables,
        i: u32,
        w: &mut Walk,
        mut d: Descent,
        use_cut: bool,
        sum: &mut usize,
    ) -> Option<u32> {
        let seg = tables.segment(i, &self.top.fast)?;
        w.at.node = seg.walk.root()?;
        // Keys name nodes of the top segment only, at its depths.
        self.descend::<SUM, _>(&seg, w, &mut d, use_cut, sum, &mut NoMemo)?;
        tables.emitter_id(i, w.at.node.emitter()?)
    }

    /// The `f64` pmf of `light`: the same steps along its path.
    pub(crate) fn pmf(&self, light: LightId) -> f64 {
        let emitter = match light {
            LightId::Unbounded(i) => {
                return self
                    .unbounded
                    .get(i as usize)
                    .filter(|_| self.restriction.unbounded(i))
                    .map_or(0.0, |&f| self.mixture.unbounded_pmf(f));
            }
            LightId::Emitter(e) => e,
        };
        if self.mixture.cut <= 0.0 && !self.prior {
            return 0.0;
        }
        let Some(mut at) = self.root() else {
            return 0.0;
        };
        let mut p = Products {
            cut: 1.0,
            prior: 1.0,
        };
        let found = match (self.guide.instanced(), self.top.walk.code(emitter)) {
            (None, Some(code)) => self.pmf_coded(&self.top, &mut at, &mut p, code),
            // Deeper than a code holds.
            (None, None) => self
                .tree
                .path(emitter)
                .is_some_and(|path| self.pmf_along(&self.top, &mut at, &mut p, path.steps(), 0)),
            (Some((tables, tree)), _) => self.pmf_instanced(tables, tree, emitter, &mut at, &mut p),
        };
        match found {
            true => self.mixture.emitter_pmf(p),
            false => 0.0,
        }
    }

    /// [`Rule::pmf_along`] the path of `emitter` over an instanced tree:
    /// the top tree's path to its instance, then its mesh's path to it in
    /// the mesh's tables, the point seen from mesh space.
    #[inline(always)]
    fn pmf_instanced(
        &self,
        tables: &InstancedTables,
        tree: &InstancedLightTree,
        emitter: u32,
        at: &mut Cursor,
        p: &mut Products,
    ) -> bool {
        let Some((i, t)) = tree.locate(emitter) else {
            return false;
        };
        let (Some(top), Some(inner)) =
            (tree.top().path(i), mesh_of(tree, i).and_then(|m| m.path(t)))
        else {
            return false;
        };
        if !self.pmf_along(&self.top, at, p, top.steps(), 0) {
            return false;
        }
        let Some(seg) = tables.segment(i, &self.top.fast) else {
            return false;
        };
        let Some(root) = seg.walk.root() else {
            return false;
        };
        at.node = root;
        // The mesh's root is as deep as the instance's leaf above it.
        let depth = top.steps().len() as u32;
        self.pmf_along(&seg, at, p, inner.steps(), depth)
    }

    /// [`Rule::pmf_along`] the path `code` gives, down the walk table from
    /// `at` (each node's split read from its walk entry, the same `f32` the
    /// split table holds, so the products are the ones `sample` forms).
    #[inline(always)]
    fn pmf_coded(&self, seg: &Segment, at: &mut Cursor, p: &mut Products, code: PathCode) -> bool {
        let mut depth = Depth::at(0);
        for level in 0..code.depth() {
            let Some(k) = at.node.children() else {
                return false;
            };
            let side = code.side(level);
            if !self.pmf_step(seg, at, p, at.node.split, side, &mut depth) {
                return false;
            }
            at.node = seg.walk.pair(k).0[side.index()];
        }
        at.node.children().is_none()
    }

    /// One level of a pmf walk at `at`, whose node's split-table entry is
    /// `split`, at `depth`: multiplies the probabilities of `side` into `p`
    /// and moves `at`'s cut node and `depth` to that side (the caller moves
    /// its walk-table entry); false once both products are 0.
    #[inline(always)]
    fn pmf_step(
        &self,
        seg: &Segment,
        at: &mut Cursor,
        p: &mut Products,
        split: f32,
        side: Side,
        depth: &mut Depth,
    ) -> bool {
        let pair = at.node.children();
        let (imp, lanes) = self.weights(seg, at, depth.depth, depth.carry);
        *depth = Depth {
            depth: depth.depth + 1,
            carry: lanes.map(|l| (l, side.index())),
        };
        let step = self
            .restriction
            .restrict(self.step(*at, split, imp), split, || {
                pair.map(|k| seg.pair_sets(k))
            });
        self.apply(p, &step, side);
        if p.cut == 0.0 && (!self.prior || p.prior == 0.0) {
            return false;
        }
        at.cut = step.next[side.index()].and_then(|i| self.nodes.get(i as usize).copied());
        true
    }

    /// Multiplies into `p` the steps along `path` in segment `seg`, from
    /// `at` at depth `depth` of the hierarchy; false as soon as both
    /// products are 0 (or the walk table does not follow the path).
    ///
    /// The path names every node, so the split loads are independent of
    /// each other (unlike the walk table's chain, which `sample` follows
    /// because it does not know the path in advance).
    #[inline(always)]
    fn pmf_along(
        &self,
        seg: &Segment,
        at: &mut Cursor,
        p: &mut Products,
        path: &[(u32, Side)],
        depth: u32,
    ) -> bool {
        // Follow the walk table too (the importance table and the light
        // sets are laid out like it), only when they are read.
        let follow = seg.importance.is_some() || R::LINKED;
        let mut depth = Depth::at(depth);
        for &(node, side) in path {
            if !self.pmf_step(seg, at, p, seg.raw_split(node), side, &mut depth) {
                return false;
            }
            if follow {
                match at.node.children() {
                    Some(k) => at.node = seg.walk.pair(k).0[side.index()],
                    None => return false,
                }
            }
        }
        true
    }
}

/// How many candidates [`CutRules::sample_candidates`] sorts at a time.
const ORDERED: usize = 64;

/// A sample converted for the [`crate::LightSampler`] interface.
#[inline]
pub(crate) fn to_light_sample(s: Option<(LightId, f64)>) -> Option<LightSample> {
    let (light, pmf) = s?;
    let pmf = pmf_to_f32(pmf);
    (pmf > 0.0).then_some(LightSample { light, pmf })
}

impl<H: LightHierarchy> CutRules<H> {
    /// Chooses a light for a shading point `ctx` in the cell of `cut` from
    /// one uniform number `u` in `[0, 1)`, by the GLT's sampling rule:
    ///
    /// ```text
    /// pmf(l)   = (1 - alpha) (1 - F) P_cut(l) + alpha (1 - q) P_prior(l)
    /// pmf(u_i) = (1 - alpha) f_i + alpha q / k
    /// ```
    ///
    /// (`f_i` the cell's learned fraction of unbounded light `i` of `k`, `F`
    /// their sum, `q` their configured prior together, `P_prior` the [`Prior`] rule from the root, `P_cut` the
    /// cut's learned probabilities, [`Modulation`] applied, down to the cut,
    /// then the [`BelowCut`] rule; the full description is at the top of
    /// `src/cut/sampling.rs`). `None` when
    /// nothing can be chosen or the pmf rounds to zero in `f32`.
    #[inline]
    pub fn sample(&self, cut: &GuidingCut, ctx: &ShadingContext, u: f32) -> Option<LightSample> {
        to_light_sample(self.sample_exact_from(cut, ctx, Descent::new(u)))
    }

    /// [`CutRules::sample`] and the chosen light's learned
    /// [`CutRules::visibility`] in `cut`, read where the walk leaves the
    /// cut instead of walking the light's path again.
    #[inline]
    pub fn sample_with_visibility(
        &self,
        cut: &GuidingCut,
        ctx: &ShadingContext,
        u: f32,
    ) -> Option<(LightSample, f32)> {
        let mut sum = 0;
        let s = to_light_sample(self.sample_at::<true>(cut, ctx, Descent::new(u), &mut sum))?;
        Some((s, self.visibility_at(cut, Some(sum))))
    }

    /// Resampling candidates at `ctx` with `cut`: `out[j]` becomes
    /// [`CutRules::sample_with_visibility`]`(u[j])` for every `j` (up to
    /// the shorter slice), bit for bit, but each step the walks share is
    /// computed once (a memo of each level's last step, by node), and the walks go in increasing order
    /// of their numbers, so consecutive walks share the longest prefixes
    /// (a descent keeps the numbers' order). The mixture and the prepared
    /// point are computed once for all of them.
    pub fn sample_candidates(
        &self,
        cut: &GuidingCut,
        ctx: &ShadingContext,
        u: &[f32],
        out: &mut [Option<(LightSample, f32)>],
    ) {
        let n = u.len().min(out.len());
        let (u, out) = (&u[..n], &mut out[..n]);
        if !ctx.is_finite() {
            out.fill(None);
            return;
        }
        match self.receives(ctx) {
            None => self.candidates_by(&Rule::new(self, cut, ctx, Unrestricted), cut, u, out),
            Some(r) => self.candidates_by(&Rule::new(self, cut, ctx, r), cut, u, out),
        }
    }

    /// [`CutRules::sample_candidates`] by `rule`, in batches of
    /// [`ORDERED`] numbers sorted once each.
    fn candidates_by<R: Restriction>(
        &self,
        rule: &Rule<'_, H, R>,
        cut: &GuidingCut,
        u: &[f32],
        out: &mut [Option<(LightSample, f32)>],
    ) {
        let mut memo = StepMemo::new();
        for (u, out) in u.chunks(ORDERED).zip(out.chunks_mut(ORDERED)) {
            let mut order = [0u8; ORDERED];
            let order = &mut order[..u.len()];
            for (i, o) in order.iter_mut().enumerate() {
                *o = i as u8;
            }
            // Only the speed depends on the order (a NaN sorts anywhere).
            order.sort_unstable_by(|&a, &b| u[a as usize].total_cmp(&u[b as usize]));
            for &j in order.iter() {
                let j = j as usize;
                let mut sum = 0;
                let s = rule.sample::<true>(Descent::new(u[j]), &mut sum, &mut memo);
                out[j] = to_light_sample(s).map(|s| (s, self.visibility_at(cut, Some(sum))));
            }
        }
    }

    /// Like [`CutRules::sample`] from an `f64` number (53 bits),
    /// returning the unrounded `f64` pmf: equal, bit for bit, to
    /// [`CutRules::pmf_exact`] for the chosen light.
    #[inline]
    pub fn sample_exact(
        &self,
        cut: &GuidingCut,
        ctx: &ShadingContext,
        u: f64,
    ) -> Option<(LightId, f64)> {
        self.sample_exact_from(cut, ctx, Descent::from_f64(u))
    }

    /// The walk from descent `d`; nothing at a non-finite position.
    #[inline(always)]
    fn sample_exact_from(
        &self,
        cut: &GuidingCut,
        ctx: &ShadingContext,
        d: Descent,
    ) -> Option<(LightId, f64)> {
        self.sample_at::<false>(cut, ctx, d, &mut 0)
    }

    /// [`Rule::sample`] at `ctx` (nothing at a non-finite position),
    /// writing the chosen light's sum index to `sum` when `SUM`.
    #[inline(always)]
    fn sample_at<const SUM: bool>(
        &self,
        cut: &GuidingCut,
        ctx: &ShadingContext,
        d: Descent,
        sum: &mut usize,
    ) -> Option<(LightId, f64)> {
        if !ctx.is_finite() {
            return None;
        }
        match self.receives(ctx) {
            None => Rule::new(self, cut, ctx, Unrestricted).sample::<SUM>(d, sum, &mut NoMemo),
            Some(r) => self.sample_linked::<SUM>(cut, ctx, d, sum, r),
        }
    }

    /// [`CutRules::sample_at`] at a point lit by some light sets: its own
    /// copy of the walk, so the walk without sets reads none.
    #[inline(never)]
    fn sample_linked<const SUM: bool>(
        &self,
        cut: &GuidingCut,
        ctx: &ShadingContext,
        d: Descent,
        sum: &mut usize,
        receives: Receives,
    ) -> Option<(LightId, f64)> {
        Rule::new(self, cut, ctx, receives).sample::<SUM>(d, sum, &mut NoMemo)
    }

    /// The light sets `ctx` receives, when they restrict this tree's
    /// emitters (light linking).
    #[inline(always)]
    fn receives(&self, ctx: &ShadingContext) -> Option<Receives> {
        let sets = ctx.restricts(self.light_tree().has_light_sets());
        let k = self.config().unbounded.count;
        let unbounded = ctx.receives_unbounded != u64::MAX && ctx.unbounded_received(k) < k;
        (sets || unbounded).then_some(Receives(ctx.receives, ctx.receives_unbounded))
    }

    /// The probability that [`CutRules::sample`] chooses `light` at `ctx`
    /// with `cut` (0 for lights it never chooses and ids out of range).
    #[inline]
    pub fn pmf(&self, cut: &GuidingCut, ctx: &ShadingContext, light: LightId) -> f32 {
        pmf_to_f32(self.pmf_exact(cut, ctx, light))
    }

    /// The `f64` pmf before rounding to `f32`.
    #[inline]
    pub fn pmf_exact(&self, cut: &GuidingCut, ctx: &ShadingContext, light: LightId) -> f64 {
        if !ctx.is_finite() {
            return 0.0;
        }
        match self.receives(ctx) {
            None => Rule::new(self, cut, ctx, Unrestricted).pmf(light),
            Some(r) => self.pmf_linked(cut, ctx, light, r),
        }
    }

    /// [`CutRules::pmf_exact`] at a point lit by some light sets: its own
    /// copy of the walk.
    #[inline(never)]
    fn pmf_linked(
        &self,
        cut: &GuidingCut,
        ctx: &ShadingContext,
        light: LightId,
        receives: Receives,
    ) -> f64 {
        Rule::new(self, cut, ctx, receives).pmf(light)
    }
}

impl<H: LightHierarchy> CutRules<H> {
    /// True when nothing can ever be sampled: no emitter has power and
    /// there is no unbounded light.
    pub fn is_empty(&self) -> bool {
        !self.has_power() && self.config().unbounded.count == 0
    }

    /// True when [`CutRules::sample`] chooses nothing at `ctx` (with any
    /// cut): a position that is not finite, or no emitter with power in
    /// the sets it receives and no unbounded light it receives.
    pub fn is_empty_at(&self, ctx: &ShadingContext) -> bool {
        let tree = self.light_tree();
        let emitters = self.has_power()
            && (!ctx.restricts(tree.has_light_sets())
                || tree
                    .root()
                    .is_some_and(|n| tree.light_sets(n) & ctx.receives != 0));
        !ctx.is_finite()
            || (!emitters && ctx.unbounded_received(self.config().unbounded.count) == 0)
    }
}
