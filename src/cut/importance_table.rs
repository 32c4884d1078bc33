//! The light tree's nodes decoded once for fast importance evaluation: the
//! Estevez-Kulla importance of [`crate::light_sampler::importance`] computed in `f32` from
//! precomputed bounding spheres, without decoding the quantised nodes on
//! every visit. Entries are 32 bytes and stored as sibling pairs in the
//! order of the GLT's walk table, so one 64-byte cache line holds both
//! children a walk step compares.

use crate::light_sampler::BACK_FACTOR;
use crate::light_sampler::ShadingContext;
use crate::light_tree::{LightHierarchy, NodeBounds};
use crate::math::scalar::{acos, sqrt};
use alloc::vec::Vec;
use bytemuck::{Pod, Zeroable};
use glam::{Mat3A, Vec3, Vec3A};

/// Slack on the emission-angle test, beyond the widening of the stored
/// cones: `f32` rounding must never decide that a cluster cannot reach a
/// point that the exact bound says it reaches (the importance is then 0
/// and, with an importance prior, so is the pmf).
pub(crate) const COS_SLACK: f32 = 1e-4;

/// The angle by which stored normal cones are widened, covering the error
/// of the 16-bit axis (at most ~3e-5 rad) with margin.
const AXIS_WIDENING: f32 = 1e-4;

/// Scale of the 16-bit signed-normalised codes.
const SNORM: f32 = 32767.0;

/// The cone covers every direction (no orientation factor).
const OMNI: u16 = 1;
/// An emitter below is two-sided.
const TWO_SIDED: u16 = 2;

/// One node, as the importance needs it: 32 bytes.
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
#[repr(C)]
struct Entry {
    center: [f32; 3],
    /// Squared radius of the box's bounding sphere.
    radius2: f32,
    /// The cone axis, signed-normalised.
    axis: [i16; 3],
    flags: u16,
    /// `1 - cos theta_o` of the widened cone as a bfloat16, rounded up
    /// (relative precision 2^-8 in the angle's square, so narrow cones
    /// keep their angle to ~0.2%).
    one_minus_cos_o: u16,
    /// `1 - cos theta_e` as a bfloat16, rounded up.
    one_minus_cos_e: u16,
    /// Total power; 0 for a node that cannot contribute (no power, empty
    /// or non-finite box) or that does not exist.
    power: f32,
}

const _: () = assert!(core::mem::size_of::<Entry>() == 32);

/// Both children of a light-tree node: one cache line.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[repr(C, align(64))]
struct Pair([Entry; 2]);

/// `x` in `[0, 2]` as a bfloat16 (the high half of its `f32` bits),
/// rounded up.
fn bf16_up(x: f32) -> u16 {
    let bits = x.clamp(0.0, 2.0).to_bits();
    let high = (bits >> 16) as u16;
    if bits & 0xffff != 0 { high + 1 } else { high }
}

#[inline(always)]
pub(crate) fn from_bf16(b: u16) -> f32 {
    f32::from_bits(u32::from(b) << 16)
}

/// The nearest code of `c` in `[-1, 1]`.
fn snorm(c: f32) -> i16 {
    libm::roundf(c.clamp(-1.0, 1.0) * SNORM) as i16
}

#[inline(always)]
pub(crate) fn decode(q: i16) -> f32 {
    q as f32 * (1.0 / SNORM)
}

impl Entry {
    fn new(b: &NodeBounds) -> Self {
        let (lo, hi) = (b.bounds.min, b.bounds.max);
        let valid = b.power > 0.0
            && b.power.is_finite()
            && lo.is_finite()
            && hi.is_finite()
            && !b.bounds.is_empty();
        if !valid {
            return Self::default();
        }
        let axis = b.cone.axis.try_normalize();
        let cos_o = b.cone.cos_theta_o.clamp(-1.0, 1.0);
        let theta_o = acos(cos_o) + AXIS_WIDENING;
        let mut flags = if b.two_sided { TWO_SIDED } else { 0 };
        let (axis, one_minus_cos_o) = match axis {
            Some(a) if theta_o < core::f32::consts::PI => (
                [snorm(a.x), snorm(a.y), snorm(a.z)],
                // 1 - cos = 2 sin^2(theta / 2), exact for small angles.
                bf16_up(2.0 * libm::powf(libm::sinf(0.5 * theta_o), 2.0)),
            ),
            _ => {
                flags |= OMNI;
                ([0; 3], bf16_up(2.0))
            }
        };
        Self {
            center: (lo * 0.5 + hi * 0.5).to_array(),
            radius2: (0.5 * (hi - lo)).length_squared(),
            axis,
            flags,
            one_minus_cos_o,
            one_minus_cos_e: bf16_up(1.0 - b.cone.cos_theta_e.clamp(-1.0, 1.0)),
            power: b.power,
        }
    }
}

/// Every inner node's children decoded for [`ImportanceTable::pair_importance`],
/// indexed like the GLT's walk table.
#[derive(Clone, Debug, Default)]
pub(crate) struct ImportanceTable {
    pairs: Vec<Pair>,
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
    ) -> Self {
        Self::from_bounds(pairs, |n| tree.node_bounds(n))
    }

    /// [`ImportanceTable::new`] with each node's bounds from `bounds`.
    pub(crate) fn from_bounds(
        pairs: impl Iterator<Item = Option<[u32; 2]>>,
        bounds: impl Fn(u32) -> NodeBounds,
    ) -> Self {
        let pairs = pairs
            .map(|p| match p {
                Some(nodes) => Pair(nodes.map(|n| Entry::new(&bounds(n)))),
                None => Pair::default(),
            })
            .collect();
        Self { pairs }
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
        let table = ImportanceTable::new(&tree, pairs.iter().copied());
        assert_eq!(table.bytes(), pairs.len() * 64);
        let k = pairs.iter().position(Option::is_some).unwrap() as u32;
        let at = |p: Vec3| table.pair_importance(&FastQuery::new(&ShadingContext::at(p)), k);
        let (l, r) = at(Vec3::new(1.5, -4.0, 0.0));
        assert_eq!((l, r), (0.0, 0.0));
        let (l, r) = at(Vec3::new(1.5, 4.0, 0.0));
        assert!(l > 0.0 && r > 0.0);
    }

    /// Rounding up to bfloat16 keeps values it can represent exactly and
    /// moves every other one to the next code above: the stored cones are
    /// never narrower than the tree's, and no wider than they must be.
    #[test]
    fn bf16_rounds_up_only_what_it_cannot_hold() {
        for x in [0.0f32, 0.5, 1.0, 1.5, 2.0, 0.25, 0.0078125] {
            assert_eq!(from_bf16(bf16_up(x)), x, "{x} is a bfloat16");
        }
        for x in [1.0f32 + f32::EPSILON, 0.3, 1.999, 1e-7] {
            let up = from_bf16(bf16_up(x));
            let below = f32::from_bits(up.to_bits() - (1 << 16));
            assert!(up > x && below < x, "{x} rounds up to {up}");
        }
        // Out of range is clamped to [0, 2].
        assert_eq!(from_bf16(bf16_up(-1.0)), 0.0);
        assert_eq!(from_bf16(bf16_up(7.0)), 2.0);
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
        let mut s = 0x2545_f491_u32;
        let mut next = move || {
            s ^= s << 13;
            s ^= s >> 17;
            s ^= s << 5;
            (s >> 8) as f32 / (1u32 << 24) as f32
        };
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
        let table = ImportanceTable::new(&tree, pairs.iter().copied());
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
}
