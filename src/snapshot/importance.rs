//! The importance of two sibling clusters at a shading point, in `f32`
//! only: the bound of `src/cut/importance_table.rs` (power x conservative
//! emission cosine / squared distance clamped to the bounding sphere, x
//! the conservative `|cos|` to the normal), term for term, except that it
//! never divides by a squared distance. A GPU has no `f64` to hold
//! `power / distance^2` for a 1e30 W light a millimetre away, and only the
//! ratio between two siblings is ever read, so each importance is kept as
//! a numerator and a squared distance and the pair is cross-multiplied
//! after scaling both distances by the larger: every product stays in
//! `[0, 1]`. The cone arithmetic (`cos_sub_clamped` and its kin, the
//! bfloat16 and 16-bit decoding) is the CPU table's own; the cone bound
//! that combines them is written out again here, over arrays: shared with
//! the table through a closure it cost the GLT's own walk 0.7% more
//! instructions (callgrind, sample + pmf, 11,031 to 11,105). The WGSL
//! kernel (`gpu/src/sample.wgsl`) is this file line for line.

use super::layout::{Bounds, BoundsPair, OMNI, TWO_SIDED};
use crate::cut::{COS_SLACK, cos_sub_clamped, decode, from_bf16, sin_of, sin_sub_clamped};
use crate::light_sampler::BACK_FACTOR;
use crate::math::scalar::sqrt;

/// A shading point as the importance reads it.
#[derive(Clone, Copy, Debug)]
pub(super) struct Point {
    pub(super) p: [f32; 3],
    /// The unit normal, or `None` (no normal factor).
    pub(super) n: Option<[f32; 3]>,
}

impl Point {
    /// `p` with `normal` normalised, `None` for a normal that cannot be
    /// (zero, non-finite): as `Vec3::try_normalize`.
    pub(super) fn new(p: [f32; 3], normal: Option<[f32; 3]>) -> Self {
        let n = normal.and_then(|n| {
            let rcp = 1.0 / sqrt(dot(n, n));
            (rcp.is_finite() && rcp > 0.0).then(|| [n[0] * rcp, n[1] * rcp, n[2] * rcp])
        });
        Self { p, n }
    }
}

#[inline(always)]
fn dot(a: [f32; 3], b: [f32; 3]) -> f32 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// The importance of `e` at `q` as `(numerator, squared distance)`: the
/// importance is their quotient. `(0, 1)` for a cluster that cannot
/// contribute; inside its bounding sphere the distance is the radius
/// (0 for a point: infinitely important, as in the CPU's bound).
#[inline(always)]
fn importance(q: &Point, e: &Bounds) -> (f32, f32) {
    if e.power <= 0.0 || e.power.is_nan() {
        return (0.0, 1.0);
    }
    let to_p = [
        q.p[0] - e.center[0],
        q.p[1] - e.center[1],
        q.p[2] - e.center[2],
    ];
    let dist2 = dot(to_p, to_p);
    let r2 = e.radius2;
    if dist2 <= r2 {
        return (e.power, r2);
    }
    if !dist2.is_finite() {
        return (0.0, 1.0);
    }
    let inv = 1.0 / sqrt(dist2);
    let wi = [to_p[0] * inv, to_p[1] * inv, to_p[2] * inv];
    let sin2_b = r2 / dist2;
    let (sin_b, cos_b) = (sqrt(sin2_b), sqrt((1.0 - sin2_b).max(0.0)));
    let cos_thetap = if e.flags & OMNI == 0 {
        let axis = [decode(e.axis[0]), decode(e.axis[1]), decode(e.axis[2])];
        let mut cos_w = dot(axis, wi).clamp(-1.0, 1.0);
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
    let reaches = cos_thetap >= 1.0 - from_bf16(e.one_minus_cos_e) - COS_SLACK;
    if !reaches {
        return (0.0, 1.0);
    }
    let mut a = e.power * cos_thetap.max(BACK_FACTOR as f32);
    if let Some(n) = q.n {
        let cos_i = dot(wi, n).abs().min(1.0);
        a *= cos_sub_clamped(sin_of(cos_i), cos_i, sin_b, cos_b).max(0.0);
    }
    (a, dist2)
}

/// Weights of the two nodes of `pair` at `q`, in the ratio of their
/// importances, each in `[0, 1]`: `(a_l d_r, a_r d_l)` with the squared
/// distances `d` divided by the larger.
#[inline(always)]
pub(super) fn pair_weights(q: &Point, pair: &BoundsPair) -> (f32, f32) {
    let (al, dl) = importance(q, &pair.nodes[0]);
    let (ar, dr) = importance(q, &pair.nodes[1]);
    let m = dl.max(dr);
    let (dl, dr) = if m > 0.0 {
        (dl / m, dr / m)
    } else {
        (1.0, 1.0)
    };
    (al * dr, ar * dl)
}
