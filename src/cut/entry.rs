//! [`Entry`]: one light-tree node's bounds as the importance rules read
//! them, 32 bytes (centre and squared radius of the box's bounding sphere,
//! a 16-bit cone axis, bfloat16 cone angles, the power), and the codes it
//! is stored in. The importance table (`importance_table.rs`) holds them
//! in sibling pairs; `child_weights.rs` evaluates four at a time; the GPU
//! snapshot's `Bounds` is the same record.

use crate::light_tree::NodeBounds;
use crate::math::scalar::acos;
use bytemuck::{Pod, Zeroable};

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
pub(crate) const OMNI: u16 = 1;
/// An emitter below is two-sided.
pub(crate) const TWO_SIDED: u16 = 2;

/// One node, as the importance needs it: 32 bytes (the GPU snapshot's
/// `Bounds` is the same record).
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
#[repr(C)]
pub(crate) struct Entry {
    pub(crate) center: [f32; 3],
    /// Squared radius of the box's bounding sphere.
    pub(crate) radius2: f32,
    /// The cone axis, signed-normalised.
    pub(crate) axis: [i16; 3],
    pub(crate) flags: u16,
    /// `1 - cos theta_o` of the widened cone as a bfloat16, rounded up
    /// (relative precision 2^-8 in the angle's square, so narrow cones
    /// keep their angle to ~0.2%).
    pub(crate) one_minus_cos_o: u16,
    /// `1 - cos theta_e` as a bfloat16, rounded up.
    pub(crate) one_minus_cos_e: u16,
    /// Total power; 0 for a node that cannot contribute (no power, empty
    /// or non-finite box) or that does not exist.
    pub(crate) power: f32,
}

impl Entry {
    /// A node under which no emitter is (power 0): the empty lane beside
    /// a leaf in [`crate::cut::child_weights`].
    pub(crate) const EMPTY: Self = Self {
        center: [0.0; 3],
        radius2: 0.0,
        axis: [0; 3],
        flags: 0,
        one_minus_cos_o: 0,
        one_minus_cos_e: 0,
        power: 0.0,
    };
}

const _: () = assert!(core::mem::size_of::<Entry>() == 32);

/// `x` in `[0, 2]` as a bfloat16 (the high half of its `f32` bits),
/// rounded up.
pub(crate) fn bf16_up(x: f32) -> u16 {
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
    /// The entry of a node with bounds `b`.
    pub(crate) fn new(b: &NodeBounds) -> Self {
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

#[cfg(test)]
mod tests {
    use super::*;

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
}
