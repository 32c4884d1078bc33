//! [`OctantRecords`]: the records a cell took, counted per octant, so that
//! when the cell splits each half knows its share of the records its
//! parent's cut learned from (the GLT's cells and the field's).

use crate::math::{Aabb, Counter};
use crate::persist::{LoadError, Reader, Writer};
use glam::Vec3;

/// The octant of a cell with `bounds` that `p` falls in: bit 0 set for
/// `x` at or above the centre, bit 1 for `y`, bit 2 for `z` (a point
/// outside counts in the nearest).
#[inline]
pub(crate) fn octant_of(p: Vec3, bounds: &Aabb) -> usize {
    let c = bounds.center();
    usize::from(p.x >= c.x) | usize::from(p.y >= c.y) << 1 | usize::from(p.z >= c.z) << 2
}

/// A half of a split cell that holds at least this share of the records
/// its parent's cut learned from keeps the cut's confidence; below it the
/// confidence falls in proportion, to 0 for a half no record came from.
/// Small: a cut a twentieth of whose records came from a half still serves
/// it better than the prior, and in pass order the halves split by the
/// last refinement sample with what they inherit for the longest
/// iteration (at 0.25 the GLT's variance on `city` rose by up to 10%; at
/// 0.05 it is main's; docs/experiments/tile-order.md). What it guards
/// against is a half that got nothing: a region not rendered yet.
pub(crate) const TRUSTED_SHARE: f64 = 0.05;

/// Records since a cell's last refinement, per octant of the cell (index
/// as [`octant_of`]).
#[derive(Clone, Debug, Default)]
pub(crate) struct OctantRecords([Counter; 8]);

impl OctantRecords {
    /// The given counts.
    pub(crate) fn with(counts: [u64; 8]) -> Self {
        Self(counts.map(Counter::with))
    }

    /// `total` records of unknown octants spread as evenly as counts can
    /// be: each octant `total / 8`, the first `total % 8` one more (what
    /// saves of format versions 1 and 2, which kept one count per cell,
    /// load as).
    pub(crate) fn spread(total: u64) -> Self {
        Self::with(core::array::from_fn(|o| {
            total / 8 + u64::from((o as u64) < total % 8)
        }))
    }

    /// Counts a record from `octant`.
    #[inline]
    pub(crate) fn count(&self, octant: usize) {
        self.0[octant & 7].bump();
    }

    /// The counts.
    pub(crate) fn get(&self) -> [u64; 8] {
        core::array::from_fn(|o| self.0[o].get())
    }

    /// Their sum.
    pub(crate) fn total(&self) -> u64 {
        self.get().iter().sum()
    }

    /// Back to zero.
    pub(crate) fn reset(&mut self) {
        for c in &mut self.0 {
            c.reset();
        }
    }

    /// Adds `other`'s counts (merging two structures' statistics).
    pub(crate) fn merge(&mut self, other: &Self) {
        for (x, y) in self.0.iter_mut().zip(&other.0) {
            x.merge(y);
        }
    }

    /// Splits the counts of a cell halved along `axis` (0, 1, 2): these
    /// become the lower half's and the upper half's are returned (along
    /// `axis` a half's own octants are not known: its count is shared
    /// evenly), with each half's confidence factor, `min(1, share /
    /// TRUSTED_SHARE)` of the records (1 when there are none): `(upper,
    /// lower factor, upper factor)`.
    pub(crate) fn split(&mut self, axis: usize) -> (Self, f32, f32) {
        let counts = self.get();
        let bit = 1usize << axis;
        let total: u64 = counts.iter().sum();
        let mut halves = [[0u64; 8]; 2];
        for (o, &n) in counts.iter().enumerate() {
            let half = &mut halves[usize::from(o & bit != 0)];
            half[o & !bit] += n / 2;
            half[o | bit] += n - n / 2;
        }
        let factor = |half: &[u64; 8]| {
            if total == 0 {
                1.0
            } else {
                let share = half.iter().sum::<u64>() as f64 / total as f64;
                (share / TRUSTED_SHARE).min(1.0) as f32
            }
        };
        let (lower, upper) = (factor(&halves[0]), factor(&halves[1]));
        *self = Self::with(halves[0]);
        (Self::with(halves[1]), lower, upper)
    }

    /// Writes the eight counts.
    pub(crate) fn write(&self, w: &mut Writer) {
        for n in self.get() {
            w.u64(n);
        }
    }

    /// Reads what [`OctantRecords::write`] wrote.
    pub(crate) fn read(r: &mut Reader<'_>, field: &'static str) -> Result<Self, LoadError> {
        let mut counts = [0u64; 8];
        for n in &mut counts {
            *n = r.u64(field)?;
        }
        Ok(Self::with(counts))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A total spreads evenly, the remainder to the first octants, and
    /// nothing is lost or made up.
    #[test]
    fn a_total_spreads_evenly() {
        assert_eq!(OctantRecords::spread(20).get(), [3, 3, 3, 3, 2, 2, 2, 2]);
        assert_eq!(OctantRecords::spread(7).get(), [1, 1, 1, 1, 1, 1, 1, 0]);
        assert_eq!(OctantRecords::spread(16).get(), [2; 8]);
        assert_eq!(OctantRecords::spread(0).get(), [0; 8]);
        for total in [1u64, 9, 1001, u64::MAX] {
            let counts = OctantRecords::spread(total).get();
            assert_eq!(
                counts.iter().map(|&c| c as u128).sum::<u128>(),
                total as u128
            );
        }
    }

    #[test]
    fn a_point_counts_in_its_octant() {
        let b = Aabb::new(Vec3::ZERO, Vec3::splat(2.0));
        assert_eq!(octant_of(Vec3::splat(0.5), &b), 0);
        assert_eq!(octant_of(Vec3::new(1.5, 0.5, 0.5), &b), 1);
        assert_eq!(octant_of(Vec3::new(0.5, 1.5, 0.5), &b), 2);
        assert_eq!(octant_of(Vec3::new(0.5, 0.5, 1.5), &b), 4);
        assert_eq!(
            octant_of(Vec3::splat(1.0), &b),
            7,
            "the centre counts above"
        );
        assert_eq!(octant_of(Vec3::splat(-5.0), &b), 0, "outside: the nearest");
    }
}
