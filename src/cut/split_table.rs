//! The split table: each inner node's power split, one `f32` per node.
//!
//! The table is why the GLT's walk is cheaper per level than a plain power
//! descent: the prior probabilities of a node's children come from one
//! 4-byte load instead of two 32-byte node loads (the right child lies far
//! from its parent in memory) and a division. Each entry stores the
//! probability of the *smaller* side in `f32`, its sign telling which side
//! that is, so both sides keep 24 bits of relative precision: a child with
//! 1e-9 of its parent's power keeps its 1e-9 (a plain `f32` `p_left` would
//! round the pair to 1 and 0 and lose the child's prior floor). A child
//! with any positive power gets a positive probability (at least the
//! smallest `f32`); both children dark is NaN (neither can be chosen).
//! `tables.rs` writes the table, `sampling.rs` reads it.

use crate::math::Descent;

/// Encodes the split of a node with child powers `el`, `er`.
pub(crate) fn encode_split(el: f32, er: f32) -> f32 {
    let (l, r) = (el as f64, er as f64);
    let Some((pl, pr)) = Descent::probabilities(l, r) else {
        return f32::NAN;
    };
    let tiny = f32::from_bits(1);
    if pl <= pr {
        let q = pl as f32;
        if l > 0.0 { q.max(tiny) } else { 0.0 }
    } else {
        let q = pr as f32;
        -(if r > 0.0 { q.max(tiny) } else { 0.0 })
    }
}

/// Decodes a split entry into `(p_left, p_right)`; `None` for a dark node.
///
/// Branch-free in the sign: which side is the smaller one is a coin flip
/// per level, and a mispredicted branch there would cost more than the
/// rest of the level.
#[inline(always)]
pub(crate) fn decode_split(s: f32) -> Option<(f64, f64)> {
    if s.is_nan() {
        return None;
    }
    let small = s.abs() as f64;
    let large = 1.0 - small;
    // All ones when the right side is the smaller one (sign bit set).
    let mask = ((s.to_bits() >> 31) as u64).wrapping_neg();
    let (a, b) = (small.to_bits(), large.to_bits());
    let left = f64::from_bits((a & !mask) | (b & mask));
    let right = f64::from_bits((b & !mask) | (a & mask));
    Some((left, right))
}
