//! The light tree's nodes decoded once for fast importance evaluation: the
//! Estevez-Kulla importance of [`crate::light_sampler::importance`] computed in `f32` from
//! precomputed bounding spheres, without decoding the quantised nodes on
//! every visit. Entries are 32 bytes and stored as sibling pairs in the
//! order of the GLT's walk table, so one 64-byte cache line holds both
//! children a walk step compares.

use super::child_weights::{Lanes, lanes};
use super::config::ImportanceBound;
use super::entry::{COS_SLACK, Entry, OMNI, TWO_SIDED, decode, from_bf16};
use crate::light_sampler::BACK_FACTOR;
use crate::light_sampler::ShadingContext;
use crate::light_tree::{LightHierarchy, NodeBounds};
use crate::math::scalar::sqrt;
use alloc::vec::Vec;
use glam::{Mat3A, Vec3, Vec3A};

/// Both children of a light-tree node: one cache line.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[repr(C, align(64))]
struct Pair([Entry; 2]);

/// Every inner node's children decoded for [`ImportanceTable::pair_importance`],
/// indexed like the GLT's walk table.
#[derive(Clone, Debug, Default)]
pub(crate) struct ImportanceTable {
    pairs: Vec<Pair>,
    /// The bound the rules weigh children by.
    pub(crate) bound: ImportanceBound,
}

/// A shading point prepared for many evaluations.
#[derive(Clone, Copy, Debug)]
pub(crate) struct FastQuery {
    p: Vec3,
    n: Option<Vec3>,
    finite: bool,
}

impl FastQuery {
    /// Prepares `ctx` (its normal normalised once).
    #[inline]
    pub(crate) fn new(ctx: &ShadingContext) -> Self {
        Self {
            p: ctx.position,
            n: ctx.normal.and_then(Vec3::try_normalize),
            finite: ctx.position.is_finite(),
        }
    }

    /// This point seen from an instance's mesh space: the position
    /// `to_mesh (p - origin)` (the world offset first, so a point near an
    /// instance far from the world's origin keeps its precision), the
    /// normal `normal_to_mesh n` renormalised (`M^T` for an instance's
    /// linear part `M`: normals are covectors). An unused query stays
    /// unused.
    #[inline]
    pub(crate) fn moved(&self, to_mesh: &Mat3A, origin: Vec3A, normal_to_mesh: &Mat3A) -> Self {
        if !self.finite {
            return *self;
        }
        let p = Vec3::from(*to_mesh * (Vec3A::from(self.p) - origin));
        Self {
            p,
            n: self
                .n
                .and_then(|n| Vec3::from(*normal_to_mesh * Vec3A::from(n)).try_normalize()),
            finite: p.is_finite(),
        }
    }

    /// A placeholder for walks that evaluate no importance (every
    /// importance it gives is 0).
    #[inline]
    pub(crate) fn unused() -> Self {
        Self {
            p: Vec3::ZERO,
            n: None,
            finite: false,
        }
    }
}

#[inline(always)]
pub(crate) fn sin_of(cos: f32) -> f32 {
    sqrt((1.0 - cos * cos).max(0.0))
}

/// `cos(max(0, a - b))` from the sines and cosines of `a` and `b`.
#[inline(always)]
pub(crate) fn cos_sub_clamped(sin_a: f32, cos_a: f32, sin_b: f32, cos_b: f32) -> f32 {
    if cos_a > cos_b {
        1.0
    } else {
        cos_a * cos_b + sin_a * sin_b
    }
}

/// `sin(max(0, a - b))` from the sines and cosines of `a` and `b`.
#[inline(always)]
pub(crate) fn sin_sub_clamped(sin_a: f32, cos_a: f32, sin_b: f32, cos_b: f32) -> f32 {
    if cos_a > cos_b {
        0.0
    } else {
        sin_a * cos_b - cos_a * sin_b
    }
}

impl ImportanceTable {
    /// Decodes the children of every inner node of `tree`; `pairs` lists
    /// each walk-table pair's two light-tree nodes in the walk table's
    /// order (`None` for the root's placeholder pair).
    pub(crate) fn new<H: LightHierarchy + ?Sized>(
        tree: &H,
        pairs: impl Iterator<Item = Option<[u32; 2]>>,
        bound: ImportanceBound,
    ) -> Self {
        Self::from_bounds(pairs, |n| tree.node_bounds(n), bound)
    }

    /// [`ImportanceTable::new`] with each node's bounds from `bounds`.
    pub(crate) fn from_bounds(
        pairs: impl Iterator<Item = Option<[u32; 2]>>,
        bounds: impl Fn(u32) -> NodeBounds,
        bound: ImportanceBound,
    ) -> Self {
        let pairs = pairs
            .map(|p| match p {
                Some(nodes) => Pair(nodes.map(|n| Entry::new(&bounds(n)))),
                None => Pair::default(),
            })
            .collect();
        Self { pairs, bound }
    }

    /// The two entries of walk-table pair `pair` as stored (32 bytes each:
    /// centre, squared radius, 16-bit axis, flags, two bfloat16 cone
    /// terms, power), for the GPU snapshot, which declares the same record.
    pub(crate) fn entry_bytes(&self, pair: usize) -> Option<[[u8; 32]; 2]> {
        let Pair(entries) = self.pairs.get(pair)?;
        Some(entries.map(|e| {
            let mut bytes = [0u8; 32];
            bytes.copy_from_slice(bytemuck::bytes_of(&e));
            bytes
        }))
    }

    /// Bytes of the table.
    pub(crate) fn bytes(&self) -> usize {
        self.pairs.len() * core::mem::size_of::<Pair>()
    }

    /// The raw lanes at `q` of the four grandchildren of the node whose
    /// children are walk-table pair `pair` and whose children's children
    /// are the pairs `children` (`None` for a leaf child: itself, then an
    /// empty lane); `None` out of range and at a point that is not finite.
    #[inline(always)]
    pub(crate) fn grandchild_lanes(
        &self,
        q: &FastQuery,
        pair: u32,
        children: [Option<u32>; 2],
    ) -> Option<Lanes> {
        if !q.finite {
            return None;
        }
        let side = |s: usize| -> Option<[&Entry; 2]> {
            match children[s] {
                Some(k) => self.pairs.get(k as usize).map(|Pair([l, r])| [l, r]),
                None => Some([&self.pairs.get(pair as usize)?.0[s], &Entry::EMPTY]),
            }
        };
        let ([a, b], [c, d]) = (side(0)?, side(1)?);
        Some(lanes(
            q.p.to_array(),
            q.n.map(|n| n.to_array()),
            [a, b, c, d],
        ))
    }

    /// The importances at `q` of the two nodes of walk-table pair `pair`
    /// (0 for pairs out of range).
    ///
    /// Always inlined: callgrind, one GLT sample and pmf on 20,000 lights
    /// (`docs/experiments/light-sets.md`), 11,303 instructions when the
    /// compiler chose, 11,054 inlined.
    #[inline(always)]
    pub(crate) fn pair_importance(&self, q: &FastQuery, pair: u32) -> (f64, f64) {
        match self.pairs.get(pair as usize) {
            // The point's finiteness is tested once for both.
            Some(Pair([l, r])) if q.finite => (importance(q, l), importance(q, r)),
            _ => (0.0, 0.0),
        }
    }

    /// The raw lanes at `q` of the two nodes of walk-table pair `pair`, in
    /// lanes 0 and 1 (side 0 of [`Lanes::side`]); `None` out of range and
    /// at a point that is not finite.
    #[inline(always)]
    pub(crate) fn child_lanes(&self, q: &FastQuery, pair: u32) -> Option<Lanes> {
        let Pair([l, r]) = self.pairs.get(pair as usize).filter(|_| q.finite)?;
        Some(lanes(
            q.p.to_array(),
            q.n.map(|n| n.to_array()),
            [l, r, &Entry::EMPTY, &Entry::EMPTY],
        ))
    }
}

/// The importance of `e` at `q`: the bound of [`crate::light_sampler::importance()`] (power
/// x conservative emission cosine / squared distance clamped to the
/// bounding sphere, x the conservative `|cos|` to the normal), evaluated in
/// `f32` up to the final quotient, at a finite point `q`. Finite, never
/// negative.
#[inline(always)]
fn importance(q: &FastQuery, e: &Entry) -> f64 {
    // An entry's power is finite: 0 marks one that cannot contribute.
    if e.power <= 0.0 {
        return 0.0;
    }
    let to_p = q.p - Vec3::from_array(e.center);
    let dist2 = to_p.length_squared();
    let r2 = e.radius2;
    let phi = f64::from(e.power);
    if dist2 <= r2 {
        // Inside the bounding sphere every direction is possible.
        return phi / f64::from(r2).max(1e-200);
    }
    let wi = to_p * (1.0 / sqrt(dist2));
    let sin2_b = r2 / dist2;
    let (sin_b, cos_b) = (sqrt(sin2_b), sqrt((1.0 - sin2_b).max(0.0)));
    let cos_thetap = if e.flags & OMNI == 0 {
        let axis = Vec3::new(decode(e.axis[0]), decode(e.axis[1]), decode(e.axis[2]));
        let mut cos_w = axis.dot(wi).clamp(-1.0, 1.0);
        if e.flags & TWO_SIDED != 0 {
            cos_w = cos_w.abs();
        }
        let x = from_bf16(e.one_minus_cos_o);
        let (cos_o, sin_o) = (1.0 - x, sqrt((x * (2.0 - x)).max(0.0)));
        let sin_w = sin_of(cos_w);
        let cos_x = cos_sub_clamped(sin_w, cos_w, sin_o, cos_o);
        let sin_x = sin_sub_clamped(sin_w, cos_w, sin_o, cos_o);
        cos_sub_clamped(sin_x, cos_x, sin_b, cos_b)
    } else {
        1.0
    };
    // Written so that a NaN also gives 0.
    let reaches = cos_thetap >= 1.0 - from_bf16(e.one_minus_cos_e) - COS_SLACK;
    if !reaches {
        return 0.0;
    }
    let mut imp = f64::from(cos_thetap.max(BACK_FACTOR as f32)) / f64::from(dist2);
    if let Some(n) = q.n {
        let cos_i = wi.dot(n).abs().min(1.0);
        imp *= f64::from(cos_sub_clamped(sin_of(cos_i), cos_i, sin_b, cos_b).max(0.0));
    }
    let imp = phi * imp;
    // Finite and not negative, NaN excluded: two comparisons (`is_finite`
    // compiles to integer masking, 2 x 12 instructions a level).
    if (0.0..f64::INFINITY).contains(&imp) {
        imp
    } else {
        0.0
    }
}

#[cfg(test)]
mod tests {
    use super::super::entry::bf16_up;
    use super::*;
    use crate::emitter::Emitter;
    use crate::light_sampler::importance as exact;
    use crate::light_tree::{BuildHeuristic, LightTree};

    /// A one-sided emitter contributes nothing behind its plane, in the
    /// table as in the exact bound (a threshold that let every node reach
    /// every point would give it the back factor's share); in front it
    /// does. The table takes 64 bytes per walk-table pair.
    #[test]
    fn nothing_behind_a_one_sided_emitter() {
        let b = crate::math::Aabb::new(Vec3::new(-0.5, 0.0, -0.5), Vec3::new(0.5, 0.0, 0.5));
        let lights = [
            Emitter::area(b, Vec3::Y, 1.0, 2.0),
            Emitter::area(
                crate::math::Aabb::new(b.min + Vec3::X * 3.0, b.max + Vec3::X * 3.0),
                Vec3::Y,
                1.0,
                2.0,
            ),
        ];
        let tree = LightTree::build(&lights[..], BuildHeuristic::Saoh).unwrap();
        let pairs: Vec<Option<[u32; 2]>> = (0..tree.node_count() as u32)
            .map(|n| tree.children(n))
            .collect();
        let table = ImportanceTable::new(&tree, pairs.iter().copied(), ImportanceBound::Children);
        assert_eq!(table.bytes(), pairs.len() * 64);
        let k = pairs.iter().position(Option::is_some).unwrap() as u32;
        let at = |p: Vec3| table.pair_importance(&FastQuery::new(&ShadingContext::at(p)), k);
        let (l, r) = at(Vec3::new(1.5, -4.0, 0.0));
        assert_eq!((l, r), (0.0, 0.0));
        let (l, r) = at(Vec3::new(1.5, 4.0, 0.0));
        assert!(l > 0.0 && r > 0.0);
    }

    /// Numbers in `[0, 1)` from a xorshift generator seeded with `seed`.
    fn uniform(mut s: u32) -> impl FnMut() -> f32 {
        move || {
            s ^= s << 13;
            s ^= s >> 17;
            s ^= s << 5;
            (s >> 8) as f32 / (1u32 << 24) as f32
        }
    }

    /// The table's importance follows the exact `f64` bound: never below
    /// it by more than f32 rounding (it stays conservative, so a node the
    /// exact bound lets contribute is never dropped), within 1% for 99% of
    /// the evaluations, and above it by at most 2% plus 5e-3 of the
    /// unoriented `power / distance^2` (the stored cones are widened by
    /// 1e-4 rad and rounded outward to bfloat16, which matters only where
    /// the emission cosine is near zero).
    #[test]
    fn matches_the_exact_importance_and_stays_conservative() {
        let mut next = uniform(0x2545_f491);
        let mut lights = Vec::new();
        for i in 0..300 {
            let p = Vec3::new(next(), next(), next()) * 20.0 - 10.0;
            let n = Vec3::new(next() - 0.5, next() - 0.5, next() - 0.5);
            let e = match i % 3 {
                0 => Emitter::point(p, 1.0 + next()),
                1 => Emitter::sphere(p, 0.2, 1.0 + next()),
                _ => Emitter::area(
                    crate::math::Aabb::new(p, p + Vec3::splat(0.3)),
                    n,
                    0.09,
                    1.0 + next(),
                ),
            };
            lights.push(e);
        }
        let tree = LightTree::build(&lights, BuildHeuristic::Saoh).unwrap();
        let pairs: Vec<Option<[u32; 2]>> = (0..tree.node_count() as u32)
            .map(|n| tree.children(n))
            .collect();
        let table = ImportanceTable::new(&tree, pairs.iter().copied(), ImportanceBound::Children);
        let (mut close, mut total) = (0usize, 0usize);
        for _ in 0..200 {
            let p = Vec3::new(next(), next(), next()) * 30.0 - 15.0;
            let n = Vec3::new(next() - 0.5, next() - 0.5, next() - 0.5);
            let ctx = ShadingContext::on_surface(p, n);
            let q = FastQuery::new(&ctx);
            for (k, c) in pairs.iter().enumerate() {
                let Some([l, r]) = c else { continue };
                let (il, ir) = table.pair_importance(&q, k as u32);
                for (node, fast) in [(*l, il), (*r, ir)] {
                    let b = tree.node_bounds(node);
                    let e = f64::from(exact(&ctx, &b));
                    // The importance without its two cosines.
                    let r2 = (0.5 * (b.bounds.max - b.bounds.min)).length_squared();
                    let d2 = (p - b.bounds.center()).length_squared().max(r2);
                    let scale = f64::from(b.power / d2);
                    if e > 0.0 {
                        assert!(fast >= 0.998 * e, "node {node}: exact {e}, table {fast}");
                        let slack = 1.02 * e + 5e-3 * scale;
                        assert!(fast <= slack, "node {node}: exact {e}, table {fast}");
                        total += 1;
                        close += usize::from((fast - e).abs() <= 0.01 * e);
                    }
                }
            }
        }
        assert!(
            close as f64 >= 0.99 * total as f64,
            "{close} of {total} within 1%"
        );
    }

    /// Random entries of every kind (points, spheres, one- and two-sided
    /// areas), powers from 1e-3 to 1e30, and points near, far and inside.
    fn lane_cases() -> (Vec<Entry>, Vec<FastQuery>) {
        let mut next = uniform(0x9e37_79b9);
        let mut lights = Vec::new();
        for i in 0..64 {
            let p = Vec3::new(next(), next(), next()) * 20.0 - 10.0;
            let n = Vec3::new(next() - 0.5, next() - 0.5, next() - 0.5);
            let power = [1e-3, 1.0, 7.5, 1e30][i % 4];
            let mut e = match i % 4 {
                0 => Emitter::point(p, power),
                1 => Emitter::sphere(p, 0.5, power),
                _ => Emitter::area(
                    crate::math::Aabb::new(p, p + Vec3::splat(0.3)),
                    n,
                    0.09,
                    power,
                ),
            };
            e.two_sided = i % 8 == 3;
            lights.push(e);
        }
        // Every node: leaves, and clusters with wide boxes and cones.
        let tree = LightTree::build(&lights, BuildHeuristic::Saoh).unwrap();
        let mut entries: Vec<Entry> = (0..tree.node_count() as u32)
            .map(|n| Entry::new(&tree.node_bounds(n)))
            .collect();
        // Points of radius exactly 0 (the tree pads its leaves' boxes), at
        // which a shading point can sit.
        for i in 0..8 {
            entries.insert(
                8 * i + 1,
                Entry {
                    center: [i as f32, 1.0, -2.0],
                    flags: OMNI,
                    one_minus_cos_o: bf16_up(2.0),
                    one_minus_cos_e: bf16_up(1.0),
                    power: 5.0,
                    ..Entry::EMPTY
                },
            );
        }
        let mut points = Vec::new();
        for i in 0..64 {
            let p = match i % 4 {
                0 => Vec3::new(next(), next(), next()) * 30.0 - 15.0,
                1 => Vec3::new(next(), next(), next()) * 2e4,
                // Inside a bounding sphere: at a cluster's centre, or at a
                // point light itself (distance 0 to a sphere of radius 0).
                2 => {
                    let points: Vec<&Entry> = entries
                        .iter()
                        .filter(|e| e.radius2 == 0.0 && e.power > 0.0)
                        .collect();
                    match i % 8 {
                        2 => Vec3::from_array(points[i % points.len()].center),
                        _ => Vec3::from_array(entries[i % entries.len()].center),
                    }
                }
                _ => Vec3::new(next(), next(), next()) * 4.0 - 2.0,
            };
            let n = Vec3::new(next() - 0.5, next() - 0.5, next() - 0.5);
            let ctx = match i % 3 {
                0 => ShadingContext::at(p),
                _ => ShadingContext::on_surface(p, n),
            };
            points.push(FastQuery::new(&ctx));
        }
        (entries, points)
    }

    /// Each lane's importance is the scalar bound's (the same `f32` cone
    /// arithmetic, the quotient kept apart) to 1e-5 relative, for every
    /// kind of entry and point; every lane is finite and not negative,
    /// 1e30 W and far points included.
    #[test]
    fn each_lane_is_the_scalar_bound() {
        let (entries, points) = lane_cases();
        let mut checked = 0;
        for q in &points {
            for four in entries.chunks_exact(4) {
                let l = lanes(
                    q.p.to_array(),
                    q.n.map(|n| n.to_array()),
                    [&four[0], &four[1], &four[2], &four[3]],
                );
                for (i, e) in four.iter().enumerate() {
                    let (got, want) = (l.importance(i), importance(q, e));
                    assert!(got.is_finite() && got >= 0.0, "lane {i}: {got}");
                    assert!(
                        (got - want).abs() <= 1e-5 * want,
                        "lane {i}: {got}, the scalar bound {want}"
                    );
                    checked += usize::from(want > 0.0);
                }
            }
        }
        assert!(checked > 1000, "only {checked} lanes contribute");
    }

    /// A lane's two numbers do not depend on which lane holds the entry or
    /// on the other lanes (what lets a walk carry its parent's lanes to the
    /// level below instead of evaluating them again), and the two scalings
    /// give the bounds' ratios: `sides` the sums of two against two,
    /// `side` one against one.
    #[test]
    fn lanes_are_independent_and_scale_to_the_bounds_ratios() {
        let (entries, points) = lane_cases();
        // Ratios lie in [0, 1]: a point light at distance 0 takes all of
        // the lanes' weight, and nearly all (1e200 to 1) of the scalar's.
        let close = |got: f64, want: f64| (got - want).abs() <= 1e-5 * want + 1e-12;
        for q in &points {
            let (p, n) = (q.p.to_array(), q.n.map(|n| n.to_array()));
            for k in 0..entries.len() - 3 {
                let e = [
                    &entries[k],
                    &entries[k + 1],
                    &entries[k + 2],
                    &entries[k + 3],
                ];
                let l = lanes(p, n, e);
                // The same entries, rotated by one lane.
                let r = lanes(p, n, [e[1], e[2], e[3], e[0]]);
                for i in 0..4 {
                    assert_eq!(
                        l.importance(i).to_bits(),
                        r.importance((i + 3) % 4).to_bits(),
                        "entry {} moved lanes",
                        k + i
                    );
                }
                let imp: Vec<f64> = (0..4).map(|i| importance(q, e[i])).collect();
                let (a, b) = l.sides();
                let (a, b) = (f64::from(a), f64::from(b));
                assert!(
                    a.is_finite() && b.is_finite() && a >= 0.0 && b >= 0.0,
                    "{a} {b}"
                );
                if a + b > 0.0 {
                    let want = (imp[0] + imp[1]) / imp.iter().sum::<f64>();
                    assert!(close(a / (a + b), want), "{a} {b} against {imp:?}");
                }
                for s in 0..2 {
                    let (x, y) = l.side(s);
                    let (x, y) = (f64::from(x), f64::from(y));
                    assert!(
                        x.is_finite() && y.is_finite() && x >= 0.0 && y >= 0.0,
                        "{x} {y}"
                    );
                    let (ix, iy) = (imp[2 * s], imp[2 * s + 1]);
                    if ix + iy > 0.0 {
                        assert!(
                            close(x / (x + y), ix / (ix + iy)),
                            "{x} {y} against {ix} {iy}"
                        );
                    }
                }
            }
        }
    }
}
