//! Directions as points of the canonical square, in the fixed-point form the
//! trees descend with: `x = floor(u * 2^32)`, so the quadrant at every level
//! is one bit and a cell's membership test is a shift, exact at any depth.

use crate::math::{dir_to_canonical, unit_direction};
use glam::{Vec2, Vec3};

/// The canonical point of a direction of any positive length; `None` for a
/// zero, NaN or infinite vector. The vector is scaled then normalised (see
/// [`unit_direction`]), so tiny vectors do not underflow.
#[inline]
pub(crate) fn canonical_of(dir: Vec3) -> Option<Vec2> {
    unit_direction(dir).map(dir_to_canonical)
}

/// A canonical point in 32-bit fixed point per axis.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Fixed {
    x: u32,
    y: u32,
}

impl Fixed {
    /// The fixed-point form of `c` (coordinates clamped into `[0, 1)`).
    #[inline]
    pub(crate) fn from_canonical(c: Vec2) -> Self {
        Self {
            x: to_fixed(c.x),
            y: to_fixed(c.y),
        }
    }

    /// The quadrant `ix + 2 iy` holding the point in a node at `level`
    /// (`1..=32`).
    #[inline]
    pub(crate) fn quadrant(self, level: u32) -> usize {
        let s = 32 - level;
        (((self.x >> s) & 1) | (((self.y >> s) & 1) << 1)) as usize
    }

    /// The integer coordinates of the cell of side `2^-level` (`1..=32`)
    /// holding the point.
    #[inline]
    pub(crate) fn cell(self, level: u32) -> (u32, u32) {
        let s = 32 - level;
        (self.x >> s, self.y >> s)
    }
}

#[inline]
fn to_fixed(v: f32) -> u32 {
    // Exact for any f32 in [0, 1); `as` saturates and maps NaN to 0.
    (v as f64 * 4_294_967_296.0) as u32
}

/// `2^-level` exactly.
#[inline]
pub(crate) fn cell_size(level: u32) -> f64 {
    1.0 / (1u64 << level) as f64
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quadrants_follow_bits() {
        let p = Fixed::from_canonical(Vec2::new(0.75, 0.25));
        assert_eq!(p.quadrant(1), 1);
        assert_eq!(p.quadrant(2), 3);
        assert_eq!(p.cell(2), (3, 1));
        let edge = Fixed::from_canonical(Vec2::new(0.5, 1.0 - f32::EPSILON / 2.0));
        assert_eq!(edge.quadrant(1), 3);
        assert_eq!(edge.cell(24), (1 << 23, (1 << 24) - 1));
        let bad = Fixed::from_canonical(Vec2::new(f32::NAN, -1.0));
        assert_eq!(bad.cell(3), (0, 0));
    }

    #[test]
    fn directions_are_validated_and_normalised() {
        assert!(canonical_of(Vec3::ZERO).is_none());
        assert!(canonical_of(Vec3::new(f32::NAN, 0.0, 1.0)).is_none());
        assert!(canonical_of(Vec3::new(f32::INFINITY, 0.0, 0.0)).is_none());
        let a = canonical_of(Vec3::new(1e-42, 0.0, 1e-42)).unwrap();
        let b = canonical_of(Vec3::new(3.0, 0.0, 3.0)).unwrap();
        assert!((a - b).abs().max_element() < 1e-6);
        assert_eq!(cell_size(3), 0.125);
    }
}
