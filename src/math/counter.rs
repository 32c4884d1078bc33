//! An event counter many threads bump through `&self`.

#[cfg(not(target_has_atomic = "64"))]
use core::sync::atomic::AtomicU32 as Atomic;
#[cfg(target_has_atomic = "64")]
use core::sync::atomic::AtomicU64 as Atomic;
use core::sync::atomic::Ordering::Relaxed;

/// A lock-free event counter: 64-bit where the target has 64-bit atomics,
/// 32-bit (wrapping after 2^32 events) elsewhere, e.g. on `thumbv7em`.
#[derive(Debug, Default)]
pub struct Counter(Atomic);

impl Counter {
    /// A counter at zero.
    pub const fn new() -> Self {
        Self(Atomic::new(0))
    }

    /// Adds one.
    #[inline]
    pub fn bump(&self) {
        self.0.fetch_add(1, Relaxed);
    }

    /// Adds `n` (wrapped to 32 bits where the counter is).
    #[inline]
    pub fn add(&self, n: u64) {
        #[allow(clippy::useless_conversion, clippy::unnecessary_cast)]
        self.0.fetch_add(n as _, Relaxed);
    }

    /// The count so far.
    #[inline]
    pub fn get(&self) -> u64 {
        #[allow(clippy::useless_conversion)]
        u64::from(self.0.load(Relaxed))
    }

    /// Back to zero.
    pub fn reset(&mut self) {
        *self.0.get_mut() = 0;
    }

    /// A counter at `n` (wrapped to 32 bits where the counter is).
    pub(crate) fn with(n: u64) -> Self {
        #[allow(clippy::useless_conversion, clippy::unnecessary_cast)]
        Self(Atomic::new(n as _))
    }

    /// Adds `other`'s count (merging two structures' statistics).
    pub(crate) fn merge(&mut self, other: &Self) {
        #[allow(clippy::useless_conversion, clippy::unnecessary_cast)]
        let n = other.0.load(Relaxed) as _;
        let c = self.0.get_mut();
        *c = c.wrapping_add(n);
    }
}

impl Clone for Counter {
    fn clone(&self) -> Self {
        Self(Atomic::new(self.0.load(Relaxed)))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn counts_and_resets() {
        let mut c = Counter::new();
        for _ in 0..42 {
            c.bump();
        }
        assert_eq!(c.get(), 42);
        assert_eq!(c.clone().get(), 42);
        c.reset();
        assert_eq!(c.get(), 0);
    }
}
