//! Counting the bad input that records drop: one [`DroppedRecords`]
//! report for the SD-tree, the GLT and the field.

#[cfg(not(target_has_atomic = "64"))]
use core::sync::atomic::AtomicU32 as AtomicCount;
#[cfg(target_has_atomic = "64")]
use core::sync::atomic::AtomicU64 as AtomicCount;
use core::sync::atomic::Ordering::Relaxed;

/// Why a record was dropped.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub(crate) enum DropReason {
    /// A vertex was asked for at a position with a NaN or infinite
    /// coordinate (nothing can be recorded there).
    Position,
    /// The direction is NaN, infinite or of zero length.
    Direction,
    /// The radiance (or a fraction record's contribution) is NaN, infinite
    /// or negative.
    Radiance,
    /// A pdf is zero, negative, NaN or infinite (for a fraction record: a
    /// pdf is negative or non-finite, or both are zero).
    Pdf,
    /// `radiance / pdf` overflowed `f32`.
    Overflow,
    /// A light record: a negative or non-finite
    /// value, an emitter out of range or without power, or an unbounded
    /// light beyond the configured count.
    Light,
}

const REASONS: usize = 6;

/// Snapshot of how many records were dropped, per reason. Dropped input
/// is never stored.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct DroppedRecords {
    /// Vertices asked for at non-finite positions (`vertex` returned
    /// `None`: nothing can be recorded there).
    pub position: u64,
    /// NaN, infinite or zero-length directions.
    pub direction: u64,
    /// NaN, infinite or negative radiance or contribution.
    pub radiance: u64,
    /// Zero, negative or non-finite pdfs.
    pub pdf: u64,
    /// `radiance / pdf` not representable in `f32`.
    pub overflow: u64,
    /// Light and visibility records (of the GLT or the field's cuts), every
    /// reason together: a negative or non-finite value, an
    /// emitter out of range or without power, or an unbounded light beyond
    /// the configured count.
    pub light: u64,
}

impl DroppedRecords {
    /// All dropped inputs.
    pub fn total(&self) -> u64 {
        self.position + self.direction + self.radiance + self.pdf + self.overflow + self.light
    }
}

/// Lock-free per-reason counters (wrap around only after 2^64 drops, 2^32
/// on targets without 64-bit atomics).
#[derive(Debug, Default)]
pub(crate) struct DropCounters {
    counts: [AtomicCount; REASONS],
}

impl DropCounters {
    #[inline]
    pub(crate) fn count(&self, reason: DropReason) {
        self.counts[reason as usize].fetch_add(1, Relaxed);
    }

    pub(crate) fn snapshot(&self) -> DroppedRecords {
        // A no-op cast where the counters are 64-bit, a widening elsewhere.
        #[allow(clippy::unnecessary_cast)]
        let get = |r: DropReason| self.counts[r as usize].load(Relaxed) as u64;
        DroppedRecords {
            position: get(DropReason::Position),
            direction: get(DropReason::Direction),
            radiance: get(DropReason::Radiance),
            pdf: get(DropReason::Pdf),
            overflow: get(DropReason::Overflow),
            light: get(DropReason::Light),
        }
    }

    pub(crate) fn reset(&mut self) {
        for c in &mut self.counts {
            *c.get_mut() = 0;
        }
    }

    /// Writes the six counts.
    pub(crate) fn write(&self, w: &mut crate::persist::Writer) {
        for c in &self.counts {
            #[allow(clippy::useless_conversion, clippy::unnecessary_cast)]
            w.u64(c.load(Relaxed) as u64);
        }
    }

    /// Reads what [`DropCounters::write`] wrote.
    pub(crate) fn read(
        r: &mut crate::persist::Reader<'_>,
    ) -> Result<Self, crate::persist::LoadError> {
        let s = Self::default();
        for c in &s.counts {
            #[allow(clippy::useless_conversion, clippy::unnecessary_cast)]
            c.store(r.u64("dropped records")? as _, Relaxed);
        }
        Ok(s)
    }

    /// Adds `other`'s counts.
    pub(crate) fn merge(&mut self, other: &Self) {
        for (a, b) in self.counts.iter_mut().zip(&other.counts) {
            let c = a.get_mut();
            *c = c.wrapping_add(b.load(Relaxed));
        }
    }
}

impl Clone for DropCounters {
    fn clone(&self) -> Self {
        let s = Self::default();
        for (a, b) in s.counts.iter().zip(&self.counts) {
            a.store(b.load(Relaxed), Relaxed);
        }
        s
    }
}
