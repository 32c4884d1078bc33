//! The GLT's sampling rule over a snapshot's arrays, in `f32`: the rule of
//! `src/cut/sampling.rs` (mixture, cut, importance modulation, the rule
//! below the cut, the prior) step for step, with the descent's number and
//! the running products in `f32` as a GPU keeps them. The WGSL kernel
//! (`gpu/src/sample.wgsl`) is this file line for line.

use super::importance::{Point, child_weights};
use super::layout::{
    BELOW_IMPORTANCE, Cell, GRANDCHILDREN, LEAF, MODULATED, NO_EMITTER, PRIOR, PRIOR_IMPORTANCE,
    TreeEntry,
};
use super::view::SnapshotView;
use crate::cut::{CutNode, Slot};
use crate::light_sampler::{LightChoice, LightId, LightSample, ShadingContext};
use crate::math::Side;
use glam::Vec3;

/// The largest `f32` below one: where rescaled numbers are clamped.
const ONE_MINUS_EPS: f32 = 1.0 - f32::EPSILON / 2.0;

/// `left` and `right` normalised; `None` unless they are non-negative with
/// a positive finite sum.
#[inline(always)]
fn probabilities(left: f32, right: f32) -> Option<(f32, f32)> {
    let total = left + right;
    if !(total > 0.0 && total < f32::INFINITY && left >= 0.0 && right >= 0.0) {
        return None;
    }
    Some((left / total, right / total))
}

/// A power split entry as `(p_left, p_right)`: the smaller side's
/// probability as stored, the larger `1 - |s|`; `None` for NaN (both
/// children dark).
#[inline(always)]
fn decode_split(s: f32) -> Option<(f32, f32)> {
    if s.is_nan() {
        return None;
    }
    let small = s.abs();
    let large = 1.0 - small;
    Some(if s.is_sign_negative() {
        (large, small)
    } else {
        (small, large)
    })
}

/// The one-number descent in `f32` (`src/math/descent.rs` in `f64`).
#[derive(Clone, Copy, Debug)]
struct Descent {
    u: f32,
}

impl Descent {
    fn new(u: f32) -> Self {
        Self {
            u: if u >= 0.0 { u.min(ONE_MINUS_EPS) } else { 0.0 },
        }
    }

    #[inline(always)]
    fn choose(&mut self, (pl, pr): (f32, f32)) -> Side {
        if self.u < pl {
            self.u = (self.u / pl).min(ONE_MINUS_EPS);
            Side::Left
        } else {
            self.u = if pr > 0.0 {
                ((self.u - pl) / pr).clamp(0.0, ONE_MINUS_EPS)
            } else {
                0.0
            };
            Side::Right
        }
    }
}

#[inline(always)]
fn pick((pl, pr): (f32, f32), side: Side) -> f32 {
    match side {
        Side::Left => pl,
        Side::Right => pr,
    }
}

/// The probabilities of both components at one inner node, and the cut
/// node on the chosen side's way (`None` where the cut ends).
#[derive(Clone, Copy, Debug)]
struct Step {
    cut: Option<(f32, f32)>,
    prior: Option<(f32, f32)>,
    next: [Option<u32>; 2],
}

/// One query's fixed parts.
#[derive(Clone, Copy)]
struct Rule<'v, 'a> {
    view: &'v SnapshotView<'a>,
    q: Point,
    /// The point's cell and its index.
    cell: Cell,
    cell_index: u32,
    below_importance: bool,
    prior_importance: bool,
    /// Importance weighs children by their children at even depths.
    grandchildren: bool,
    modulate: bool,
    prior: bool,
}

impl<'v, 'a> Rule<'v, 'a> {
    fn new(view: &'v SnapshotView<'a>, p: Vec3, normal: Option<Vec3>) -> Option<Self> {
        if !p.is_finite() {
            return None;
        }
        let a = &view.a;
        let cell_index = locate(view, p)?;
        let cell = *a.cells.get(cell_index as usize)?;
        let flags = a.header.flags;
        Some(Self {
            view,
            q: Point::new(p.to_array(), normal.map(|n| n.to_array())),
            cell,
            cell_index,
            below_importance: flags & BELOW_IMPORTANCE != 0,
            prior_importance: flags & PRIOR_IMPORTANCE != 0,
            grandchildren: flags & GRANDCHILDREN != 0,
            modulate: cell.flags & MODULATED != 0,
            prior: cell.flags & PRIOR != 0,
        })
    }

    /// The cut node `i` of this cell.
    #[inline(always)]
    fn cut_node(&self, i: u32) -> Option<CutNode> {
        let at = (self.cell.first_node as usize).checked_add(i as usize)?;
        self.view.a.cut_nodes.get(at).copied()
    }

    /// The root: its tree entry and cut node (none for an empty cut).
    fn root(&self) -> Option<(TreeEntry, Option<u32>)> {
        let root = self.view.a.tree.first()?.nodes[0];
        Some((root, (self.cell.nodes > 0).then_some(0)))
    }

    /// The probabilities at the inner entry `at` (children pair `k`),
    /// inside the cut at cut node `cut`.
    #[inline(always)]
    fn step(&self, at: TreeEntry, k: u32, cut: Option<u32>, depth: u32) -> Option<Step> {
        let power = decode_split(at.split);
        let needs_importance = self.prior_importance
            || match cut {
                Some(_) => self.modulate,
                None => self.below_importance,
            };
        let imp = match needs_importance {
            true => {
                // Without the grandchildren's bound every level weighs as
                // an odd one does: by the children's own bounds.
                let depth = if self.grandchildren { depth } else { 1 };
                child_weights(&self.q, self.view.a.tree, self.view.a.bounds, k, depth)
            }
            false => None,
        };
        let by_importance = imp.and_then(|(l, r)| probabilities(l, r)).or(power);
        let prior = match (self.prior, self.prior_importance) {
            (false, _) => None,
            (true, false) => power,
            (true, true) => by_importance,
        };
        Some(match cut {
            Some(i) => {
                let node = self.cut_node(i)?;
                let p = node.p_left();
                let learned = (p, 1.0 - p);
                let cut = match imp.filter(|_| self.modulate) {
                    Some((il, ir)) => probabilities(p * il, (1.0 - p) * ir).unwrap_or(learned),
                    None => learned,
                };
                Step {
                    cut: Some(cut),
                    prior,
                    next: [Side::Left, Side::Right].map(|s| match node.slot(s) {
                        Slot::Child(j) => Some(j),
                        Slot::End(_) => None,
                    }),
                }
            }
            None => Step {
                cut: match self.below_importance {
                    true => by_importance,
                    false => power,
                },
                prior,
                next: [None, None],
            },
        })
    }

    /// Multiplies the probabilities of `side` into the products.
    #[inline(always)]
    fn apply(&self, p: &mut (f32, f32), step: &Step, side: Side) {
        p.0 = step.cut.map_or(0.0, |pair| p.0 * pick(pair, side));
        if self.prior {
            p.1 = step.prior.map_or(0.0, |pair| p.1 * pick(pair, side));
        }
    }

    /// The pmf of an emitter from its two products.
    #[inline(always)]
    fn emitter_pmf(&self, (cut, prior): (f32, f32)) -> f32 {
        self.cell.cut * cut + self.cell.prior * prior
    }

    /// Unbounded light `i`'s pmf (0 for one out of range).
    #[inline(always)]
    fn unbounded_pmf(&self, i: u32) -> f32 {
        let k = self.view.a.header.unbounded;
        let at = self.cell_index as usize * k as usize + i as usize;
        match self.view.a.fractions.get(at) {
            Some(&f) if i < k => self.cell.learned * f.max(0.0) + self.cell.floor,
            _ => 0.0,
        }
    }

    /// The learned visibility of slot `slot` of this cell's cut (1 without
    /// any).
    fn visibility(&self, slot: usize) -> f32 {
        let v = self.view.a.visibility;
        if v.is_empty() {
            return 1.0;
        }
        v.get(self.cell.first_visibility as usize + slot)
            .copied()
            .unwrap_or(1.0)
    }

    fn sample(&self, u: f32) -> Option<(LightSample, f32)> {
        let c = self.cell;
        let mut d = Descent::new(u);
        if c.unbounded > 0.0 {
            let split = probabilities(c.unbounded, c.cut + c.prior)?;
            if d.choose(split) == Side::Left {
                let k = self.view.a.header.unbounded;
                for i in 0..k {
                    let rest: f32 = (i + 1..k).map(|j| self.unbounded_pmf(j)).sum();
                    let pair = probabilities(self.unbounded_pmf(i), rest)?;
                    if d.choose(pair) == Side::Left {
                        let slots = (2 * c.nodes as usize).max(1) + i as usize;
                        return finish(
                            LightId::Unbounded(i),
                            self.unbounded_pmf(i),
                            self.visibility(slots),
                        );
                    }
                }
                return None;
            }
        }
        let use_cut = match (c.cut > 0.0, self.prior) {
            (true, true) => d.choose(probabilities(c.cut, c.prior)?) == Side::Left,
            (true, false) => true,
            (false, true) => false,
            (false, false) => return None,
        };
        let (mut at, mut cut) = self.root()?;
        let mut p = (1.0f32, 1.0f32);
        // The slot the walk leaves the cut by (0: the root's only one).
        let mut slot = 0usize;
        let mut depth = 0;
        while at.link & LEAF == 0 {
            let k = at.link;
            let step = self.step(at, k, cut, depth)?;
            depth += 1;
            let side = d.choose(if use_cut { step.cut } else { step.prior }?);
            self.apply(&mut p, &step, side);
            if let Some(i) = cut {
                cut = step.next[side.index()];
                if cut.is_none() {
                    slot = 2 * i as usize + side.index();
                }
            }
            at = self.view.a.tree.get(k as usize)?.nodes[side.index()];
        }
        if at.link == NO_EMITTER {
            return None;
        }
        finish(
            LightId::Emitter(at.link & !LEAF),
            self.emitter_pmf(p),
            self.visibility(slot),
        )
    }

    /// The learned visibility of the cluster `light` leaves the cut by
    /// (1 without any, or for a light out of range): the slot
    /// [`Rule::sample`] reads when it chooses `light`.
    fn visibility_of(&self, light: LightId) -> f32 {
        let a = &self.view.a;
        let e = match light {
            LightId::Unbounded(i) if i < a.header.unbounded => {
                return self.visibility((2 * self.cell.nodes as usize).max(1) + i as usize);
            }
            LightId::Unbounded(_) => return 1.0,
            LightId::Emitter(e) => e,
        };
        let (Some(&position), Some((mut at, mut cut))) =
            (a.leaf_position.get(e as usize), self.root())
        else {
            return 1.0;
        };
        let mut slot = 0usize;
        while let Some(i) = cut {
            if at.link & LEAF != 0 {
                break;
            }
            let (Some(&first), Some(node), Some(pair)) = (
                a.first_right.get(at.link as usize),
                self.cut_node(i),
                a.tree.get(at.link as usize),
            ) else {
                return 1.0;
            };
            let side = if position >= first {
                Side::Right
            } else {
                Side::Left
            };
            cut = match node.slot(side) {
                Slot::Child(j) => Some(j),
                Slot::End(_) => None,
            };
            if cut.is_none() {
                slot = 2 * i as usize + side.index();
            }
            at = pair.nodes[side.index()];
        }
        self.visibility(slot)
    }

    fn pmf(&self, light: LightId) -> f32 {
        let e = match light {
            LightId::Unbounded(i) => return positive(self.unbounded_pmf(i)),
            LightId::Emitter(e) => e,
        };
        let a = &self.view.a;
        let Some(&position) = a.leaf_position.get(e as usize) else {
            return 0.0;
        };
        if self.cell.cut <= 0.0 && !self.prior {
            return 0.0;
        }
        let Some((mut at, mut cut)) = self.root() else {
            return 0.0;
        };
        let mut p = (1.0f32, 1.0f32);
        let mut depth = 0;
        while at.link & LEAF == 0 {
            let k = at.link;
            let Some(step) = self.step(at, k, cut, depth) else {
                return 0.0;
            };
            depth += 1;
            let side = match a.first_right.get(k as usize) {
                Some(&first) if position >= first => Side::Right,
                Some(_) => Side::Left,
                None => return 0.0,
            };
            self.apply(&mut p, &step, side);
            if cut.is_some() {
                cut = step.next[side.index()];
            }
            match a.tree.get(k as usize) {
                Some(pair) => at = pair.nodes[side.index()],
                None => return 0.0,
            }
        }
        match at.link == LEAF | e {
            true => positive(self.emitter_pmf(p)),
            false => 0.0,
        }
    }
}

/// A pmf as reported: positive and finite, else 0.
#[inline(always)]
fn positive(pmf: f32) -> f32 {
    if pmf > 0.0 && pmf < f32::INFINITY {
        pmf
    } else {
        0.0
    }
}

/// The sample and its cluster's learned visibility, or `None` when its
/// pmf is not positive (so sample and pmf agree).
#[inline(always)]
fn finish(light: LightId, pmf: f32, visibility: f32) -> Option<(LightSample, f32)> {
    let pmf = positive(pmf);
    (pmf > 0.0).then_some((LightSample { light, pmf }, visibility))
}

/// The cell of `p` (clamped into the root cube): the spatial tree's walk,
/// splitting each box at its midpoint on x, y, z in turn.
fn locate(view: &SnapshotView, p: Vec3) -> Option<u32> {
    let a = &view.a;
    let (mut lo, mut hi) = (a.header.root_min, a.header.root_max);
    let p = [
        p.x.clamp(lo[0], hi[0]),
        p.y.clamp(lo[1], hi[1]),
        p.z.clamp(lo[2], hi[2]),
    ];
    let (mut node, mut axis) = (0usize, 0usize);
    loop {
        let word = *a.spatial.get(node)?;
        if word & LEAF != 0 {
            return Some(word & !LEAF);
        }
        let mid = lo[axis] * 0.5 + hi[axis] * 0.5;
        if p[axis] < mid {
            hi[axis] = mid;
            node = word as usize;
        } else {
            lo[axis] = mid;
            node = word as usize + 1;
        }
        axis = if axis == 2 { 0 } else { axis + 1 };
    }
}

/// A shading point's light choice over a snapshot
/// ([`SnapshotView::vertex`]): the GLT's sampling rule
/// (`src/cut/sampling.rs`) in `f32` over the arrays, the point's cell
/// located once. The same [`LightChoice`] as the CPU guide's
/// [`LightVertex`](crate::LightVertex): `sample(u)` returns a
/// [`LightSample`] whose pmf equals `pmf` of its light bit for bit, and
/// `sample_with_visibility` the learned visibility of the cluster it came
/// from (what the WGSL kernel returns beside it).
#[derive(Clone, Copy)]
pub struct SnapshotVertex<'v, 'a> {
    rule: Rule<'v, 'a>,
}

impl core::fmt::Debug for SnapshotVertex<'_, '_> {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.debug_struct("SnapshotVertex")
            .field("cell", &self.rule.cell_index)
            .finish_non_exhaustive()
    }
}

impl<'a> SnapshotView<'a> {
    /// The light choice at `ctx` (its position and normal; the snapshot
    /// has no light linking): the cell holding the position (clamped onto
    /// the root cube), through which `sample` and `pmf` answer. `None` for
    /// a non-finite position, and for a context that restricts the lights
    /// (`ShadingContext::lit_by`, `lit_by_unbounded`) that a snapshot
    /// cannot honour: its guide had no light sets, so only a point lit by
    /// none of them ([`ShadingContext::receives`] 0, where nothing is
    /// chosen) or by fewer of its unbounded lights is restricted.
    pub fn vertex(&self, ctx: &ShadingContext) -> Option<SnapshotVertex<'_, 'a>> {
        let k = self.a.header.unbounded;
        if ctx.receives == 0 || ctx.unbounded_received(k) < k {
            return None;
        }
        Some(SnapshotVertex {
            rule: Rule::new(self, ctx.position, ctx.normal)?,
        })
    }
}

impl LightChoice for SnapshotVertex<'_, '_> {
    #[inline]
    fn sample(&self, u: f32) -> Option<LightSample> {
        self.rule.sample(u).map(|(s, _)| s)
    }

    #[inline]
    fn pmf(&self, light: LightId) -> f32 {
        self.rule.pmf(light)
    }

    fn is_empty(&self) -> bool {
        let c = self.rule.cell;
        !(c.unbounded > 0.0 || c.cut > 0.0 || self.rule.prior)
    }

    fn visibility(&self, light: LightId) -> f32 {
        self.rule.visibility_of(light)
    }

    #[inline]
    fn sample_with_visibility(&self, u: f32) -> Option<(LightSample, f32)> {
        self.rule.sample(u)
    }
}
