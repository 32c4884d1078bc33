//! How the importance rules weigh a node's two children: each child by
//! the importance of its own two children (a leaf child by its own), the
//! four bounds evaluated side by side.
//!
//! A child's bound (power x conservative emission cosine / squared
//! distance, x the conservative `|cos|` to the normal, over the child's
//! whole box and cone) is loose where the box is large or the cone wide;
//! its two children's bounds together are tighter. Weighing each side by
//! their sum cut the exact relative variance of the GLT's light choice by
//! 13% on `city`, 8% on `ring` and 18% on `torus` (`light_limit`, 300
//! points, docs/benchmarks.md), and the four evaluations share every
//! instruction: one pass of 4-wide arithmetic over `glam::Vec4` lanes
//! without branches (SSE on x86-64, four scalar lanes where the target
//! has no vector unit: glam's own fallback).
//!
//! Each lane's importance is a numerator and a squared distance, as the
//! GPU snapshot's (`src/snapshot/sampling.rs`, `gpu/src/sample.wgsl`),
//! which weighs with this same function: `f32` only, never dividing a
//! power by a squared distance (a 1e30 W light a millimetre away stays
//! finite). The four are brought to one scale by the smallest squared
//! distance among the lanes that contribute, so every weight lies in
//! `[0, power]` and only their ratio is read.

use super::entry::{COS_SLACK, Entry, OMNI, TWO_SIDED, decode, from_bf16};
use crate::light_sampler::BACK_FACTOR;
use glam::{BVec4A, Vec4};

/// Four bounds records as lanes, decoded.
struct Records {
    cx: Vec4,
    cy: Vec4,
    cz: Vec4,
    r2: Vec4,
    ax: Vec4,
    ay: Vec4,
    az: Vec4,
    /// `1 - cos theta_o`, decoded from its bfloat16.
    one_minus_cos_o: Vec4,
    /// `1 - cos theta_e`, decoded from its bfloat16.
    one_minus_cos_e: Vec4,
    power: Vec4,
    omni: BVec4A,
    two_sided: BVec4A,
}

/// The records as lanes, field by field.
#[inline(always)]
fn load(e: [&Entry; 4]) -> Records {
    let f = |g: &dyn Fn(&Entry) -> f32| Vec4::new(g(e[0]), g(e[1]), g(e[2]), g(e[3]));
    let flag = |bit: u16| {
        let set = |x: &Entry| x.flags & bit != 0;
        BVec4A::new(set(e[0]), set(e[1]), set(e[2]), set(e[3]))
    };
    Records {
        cx: f(&|x| x.center[0]),
        cy: f(&|x| x.center[1]),
        cz: f(&|x| x.center[2]),
        r2: f(&|x| x.radius2),
        ax: f(&|x| decode(x.axis[0])),
        ay: f(&|x| decode(x.axis[1])),
        az: f(&|x| decode(x.axis[2])),
        one_minus_cos_o: f(&|x| from_bf16(x.one_minus_cos_o)),
        one_minus_cos_e: f(&|x| from_bf16(x.one_minus_cos_e)),
        power: f(&|x| x.power),
        omni: flag(OMNI),
        two_sided: flag(TWO_SIDED),
    }
}

/// The lanes' square roots, each the crate's scalar `sqrt` (with `std`,
/// LLVM's intrinsic, which the four lanes fuse into one `sqrtps`; glam's
/// own `Vec4::sqrt` goes through libm).
#[inline(always)]
fn sqrt(v: Vec4) -> Vec4 {
    use crate::math::scalar::sqrt;
    Vec4::new(sqrt(v.x), sqrt(v.y), sqrt(v.z), sqrt(v.w))
}

/// `sin` from `cos`, per lane.
#[inline(always)]
fn sin_of(cos: Vec4) -> Vec4 {
    sqrt((Vec4::ONE - cos * cos).max(Vec4::ZERO))
}

/// `cos(max(0, a - b))` from the sines and cosines, per lane.
#[inline(always)]
fn cos_sub_clamped(sin_a: Vec4, cos_a: Vec4, sin_b: Vec4, cos_b: Vec4) -> Vec4 {
    Vec4::select(cos_a.cmpgt(cos_b), Vec4::ONE, cos_a * cos_b + sin_a * sin_b)
}

/// `sin(max(0, a - b))` from the sines and cosines, per lane.
#[inline(always)]
fn sin_sub_clamped(sin_a: Vec4, cos_a: Vec4, sin_b: Vec4, cos_b: Vec4) -> Vec4 {
    Vec4::select(
        cos_a.cmpgt(cos_b),
        Vec4::ZERO,
        sin_a * cos_b - cos_a * sin_b,
    )
}

/// Four bounds' importances at one point, raw: each lane's numerator
/// and squared distance (the importance is their quotient), before any
/// scaling. A lane's two numbers are the same whichever lane holds it and
/// whatever the other lanes hold: lanes never mix before
/// [`Lanes::sides`] or [`Lanes::side`].
#[derive(Clone, Copy, Debug)]
pub(crate) struct Lanes {
    a: Vec4,
    d: Vec4,
}

impl Lanes {
    /// Lane `i`'s importance, `numerator / squared distance`, in `f64`.
    #[cfg(test)]
    pub(crate) fn importance(&self, i: usize) -> f64 {
        let (a, d) = (self.a.to_array()[i], self.d.to_array()[i]);
        f64::from(a) / f64::from(d).max(1e-200)
    }

    /// Both sides' weights from all four lanes (the left child's two
    /// children, then the right child's): each side the sum of its two,
    /// all four scaled by one positive factor.
    #[inline(always)]
    pub(crate) fn sides(&self) -> (f32, f32) {
        // The smallest squared distance among the lanes that contribute
        // (a lane at that distance keeps its numerator, which is also the
        // limit at distance 0).
        let (a, d) = (self.a, self.d);
        let m = Vec4::select(a.cmpgt(Vec4::ZERO), d, Vec4::MAX).min_element();
        let w = Vec4::select(d.cmple(Vec4::splat(m)), a, a * (Vec4::splat(m) / d));
        (w.x + w.y, w.z + w.w)
    }

    /// The weights of lanes `2 s` and `2 s + 1` alone (side `s`'s two
    /// children, weighed against each other one level down), scaled by
    /// the smaller squared distance of the two: the same arithmetic as
    /// [`Lanes::sides`] on two lanes.
    #[inline(always)]
    pub(crate) fn side(&self, s: usize) -> (f32, f32) {
        let (a, d) = (self.a.to_array(), self.d.to_array());
        let (i, j) = (2 * s, 2 * s + 1);
        let far = |k: usize| if a[k] > 0.0 { d[k] } else { f32::MAX };
        let m = far(i).min(far(j));
        let w = |k: usize| if d[k] <= m { a[k] } else { a[k] * (m / d[k]) };
        (w(i), w(j))
    }
}

impl Lanes {
    /// These lanes with lanes `2 s` and `2 s + 1` replaced by lanes 0 and 1
    /// of `other`, brought to this space: numerators times `power`,
    /// squared distances times `distance2` (an instance's power scale and
    /// the square of its linear scale, for a mesh's lanes seen from the
    /// top tree), each kept finite.
    #[inline(always)]
    pub(crate) fn with_side(self, s: usize, other: Lanes, power: f32, distance2: f32) -> Lanes {
        let (mut a, mut d) = (self.a.to_array(), self.d.to_array());
        let (oa, od) = (other.a.to_array(), other.d.to_array());
        for j in 0..2 {
            a[2 * s + j] = (oa[j] * power).min(f32::MAX);
            d[2 * s + j] = (od[j] * distance2).min(f32::MAX);
        }
        Lanes {
            a: Vec4::from_array(a),
            d: Vec4::from_array(d),
        }
    }
}

/// The raw importances at the point `p` (unit normal `n`, or `None` for
/// no normal factor) of the four bounds `e`. A lane is `(0, d)` where its
/// bound has no power, cannot reach the point or is too far to measure;
/// `(power, r^2)` inside its bounding sphere (every direction possible
/// there). Finite for a finite `p` and entries whose power is finite (0
/// marks one that cannot contribute).
#[inline(always)]
pub(crate) fn lanes(p: [f32; 3], n: Option<[f32; 3]>, e: [&Entry; 4]) -> Lanes {
    let l = load(e);
    let (tx, ty, tz) = (
        Vec4::splat(p[0]) - l.cx,
        Vec4::splat(p[1]) - l.cy,
        Vec4::splat(p[2]) - l.cz,
    );
    let dist2 = tx * tx + ty * ty + tz * tz;
    let inv = Vec4::ONE / sqrt(dist2);
    let (wx, wy, wz) = (tx * inv, ty * inv, tz * inv);
    let sin2_b = l.r2 / dist2;
    let (sin_b, cos_b) = (sqrt(sin2_b), sqrt((Vec4::ONE - sin2_b).max(Vec4::ZERO)));
    // The emission cone: the angle to its axis less the cone's half
    // angle, less the angle the bounding sphere subtends.
    let dot_w = (l.ax * wx + l.ay * wy + l.az * wz).clamp(-Vec4::ONE, Vec4::ONE);
    let cos_w = Vec4::select(l.two_sided, dot_w.abs(), dot_w);
    let x = l.one_minus_cos_o;
    let (cos_o, sin_o) = (
        Vec4::ONE - x,
        sqrt((x * (Vec4::splat(2.0) - x)).max(Vec4::ZERO)),
    );
    let sin_w = sin_of(cos_w);
    let cos_x = cos_sub_clamped(sin_w, cos_w, sin_o, cos_o);
    let sin_x = sin_sub_clamped(sin_w, cos_w, sin_o, cos_o);
    let cos_t = Vec4::select(
        l.omni,
        Vec4::ONE,
        cos_sub_clamped(sin_x, cos_x, sin_b, cos_b),
    );
    let mut num = l.power * cos_t.max(Vec4::splat(BACK_FACTOR as f32));
    if let Some(n) = n {
        let cos_i = (wx * n[0] + wy * n[1] + wz * n[2]).abs().min(Vec4::ONE);
        num *= cos_sub_clamped(sin_of(cos_i), cos_i, sin_b, cos_b).max(Vec4::ZERO);
    }
    // Written so that a NaN cone also gives nothing.
    let lit = l.power.cmpgt(Vec4::ZERO);
    let inside = dist2.cmple(l.r2);
    let threshold = Vec4::ONE - l.one_minus_cos_e - Vec4::splat(COS_SLACK);
    let reaches = cos_t.cmpge(threshold) & dist2.cmplt(Vec4::INFINITY);
    Lanes {
        a: Vec4::select(
            lit & inside,
            l.power,
            Vec4::select(lit & reaches, num, Vec4::ZERO),
        ),
        d: Vec4::select(inside, l.r2, dist2),
    }
}
