//! Sums that many threads add to through `&self`, without lost updates and
//! without `f32` accumulation error.
//!
//! Two modes, chosen per structure:
//! - [`Accumulation::Fast`]: one `f64` per sum, added with a compare-and-swap
//!   loop. No update is lost and a sum only loses precision after ~2^53
//!   samples of equal size (an `f32` sum stops growing after 2^24), but the
//!   order in which threads add changes the last bits.
//! - [`Accumulation::Deterministic`]: an exact fixed-point sum of the `f32`
//!   inputs (a Kulisch accumulator spread over atomic words). Integer
//!   addition is associative, so the result is bit-identical whatever the
//!   number of threads or the order of additions. It costs 48 bytes per sum.
//!
//! Targets without 64-bit atomics (e.g. `thumbv7em`) always use the exact
//! accumulator on 32-bit words.

use alloc::vec::Vec;

#[cfg(not(target_has_atomic = "64"))]
use core::sync::atomic::AtomicU32 as Word;
#[cfg(target_has_atomic = "64")]
use core::sync::atomic::AtomicU64 as Word;
use core::sync::atomic::Ordering::Relaxed;

#[cfg(target_has_atomic = "64")]
type Raw = u64;
#[cfg(not(target_has_atomic = "64"))]
type Raw = u32;

const WORD_BITS: u32 = Raw::BITS;
/// An f32 is `m * 2^(s - 149)` with `m < 2^24` and `s <= 253`: 277 bits, plus
/// headroom for 2^64 additions, fits in 384 bits.
const EXACT_BITS: u32 = 384;
const EXACT_WORDS: usize = (EXACT_BITS / WORD_BITS) as usize;

/// How a structure accumulates its training sums.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Accumulation {
    /// `f64` atomic sums: fast, small, exact enough, not bit-reproducible
    /// across thread counts.
    #[default]
    Fast,
    /// Exact sums: bit-identical learned state for the same inputs whatever
    /// the thread count or order. Uses 48 bytes per sum.
    Deterministic,
}

/// The save format's byte for each [`Accumulation`] (its position).
pub(crate) const ACCUMULATION: [Accumulation; 2] =
    [Accumulation::Fast, Accumulation::Deterministic];

/// A fixed number of non-negative sums that can be added to concurrently.
#[derive(Debug)]
pub struct SumBuffer {
    words: Vec<Word>,
    stride: usize,
}

impl SumBuffer {
    /// `len` sums, all zero.
    pub fn new(len: usize, mode: Accumulation) -> Self {
        let stride = Self::stride_of(mode);
        let mut words = Vec::with_capacity(len * stride);
        words.resize_with(len * stride, || Word::new(0));
        Self { words, stride }
    }

    fn stride_of(mode: Accumulation) -> usize {
        match mode {
            #[cfg(target_has_atomic = "64")]
            Accumulation::Fast => 1,
            _ => EXACT_WORDS,
        }
    }

    /// The mode the sums were created with.
    pub fn mode(&self) -> Accumulation {
        if self.stride == 1 {
            Accumulation::Fast
        } else {
            Accumulation::Deterministic
        }
    }

    /// How many sums.
    #[inline]
    pub fn len(&self) -> usize {
        self.words.len() / self.stride
    }

    /// True when there are no sums.
    #[inline]
    pub fn is_empty(&self) -> bool {
        self.words.is_empty()
    }

    /// Bytes of storage.
    pub fn bytes(&self) -> usize {
        self.words.len() * core::mem::size_of::<Word>()
    }

    /// Bytes of storage per sum.
    pub fn bytes_per_sum(&self) -> usize {
        self.stride * core::mem::size_of::<Word>()
    }

    /// Adds `value` to sum `index`. Values that are negative, NaN or infinite
    /// and indices out of range are ignored (callers validate and count bad
    /// input before this point); returns whether it was added.
    #[inline]
    pub fn add(&self, index: usize, value: f32) -> bool {
        if !(value >= 0.0 && value.is_finite()) || index >= self.len() {
            return false;
        }
        if value == 0.0 {
            return true;
        }
        let words = &self.words[index * self.stride..(index + 1) * self.stride];
        #[cfg(target_has_atomic = "64")]
        if self.stride == 1 {
            add_f64(&words[0], value as f64);
            return true;
        }
        add_exact(words, value);
        true
    }

    /// The value of sum `index` (0 out of range). Call it when no thread is
    /// adding (between iterations); a read racing with adds sees some of them.
    #[inline]
    pub fn get(&self, index: usize) -> f64 {
        if index >= self.len() {
            return 0.0;
        }
        let words = &self.words[index * self.stride..(index + 1) * self.stride];
        #[cfg(target_has_atomic = "64")]
        if self.stride == 1 {
            return f64::from_bits(words[0].load(Relaxed));
        }
        exact_value(words)
    }

    /// Sets every sum to zero.
    pub fn clear(&mut self) {
        for w in &mut self.words {
            *w.get_mut() = 0;
        }
    }

    /// Resizes to `len` sums, all zero.
    pub fn reset(&mut self, len: usize) {
        self.words.clear();
        self.words.resize_with(len * self.stride, || Word::new(0));
    }
}

impl SumBuffer {
    /// Bytes one exact sum takes in the save format: the fixed-point
    /// integer, little-endian, whatever the word size.
    const SAVED_EXACT_BYTES: usize = (EXACT_BITS / 8) as usize;

    /// Writes the mode, the count and every sum (`f64` bits, or the exact
    /// integer's 48 bytes), so a reload holds the same values bit for bit.
    pub(crate) fn write(&self, w: &mut crate::persist::Writer) {
        let exact = self.mode() == Accumulation::Deterministic;
        w.bool(exact);
        w.len(self.len());
        if !exact {
            for i in 0..self.len() {
                w.f64(self.get(i));
            }
            return;
        }
        for word in &self.words {
            w.bytes(&word.load(Relaxed).to_le_bytes());
        }
    }

    /// Reads what [`SumBuffer::write`] wrote: `expected` sums in `mode`
    /// (fast sums must be finite and non-negative; any exact integer is a
    /// valid sum).
    pub(crate) fn read(
        r: &mut crate::persist::Reader<'_>,
        field: &'static str,
        mode: Accumulation,
        expected: usize,
    ) -> Result<Self, crate::persist::LoadError> {
        use crate::persist::Reader;
        let at = r.offset();
        let exact = r.bool(field)?;
        let target = Self::new(0, mode);
        if exact != (target.mode() == Accumulation::Deterministic) {
            return Err(Reader::invalid(field, at));
        }
        let item = if exact { Self::SAVED_EXACT_BYTES } else { 8 };
        let len = r.len(field, item)?;
        if len != expected {
            return Err(Reader::invalid(field, at));
        }
        let mut words = Vec::with_capacity(len * target.stride);
        if exact {
            const BYTES: usize = core::mem::size_of::<Raw>();
            for _ in 0..len * target.stride {
                let b = r.bytes(BYTES, field)?;
                let mut a = [0u8; BYTES];
                a.copy_from_slice(b);
                words.push(Word::new(Raw::from_le_bytes(a)));
            }
        } else {
            #[cfg(target_has_atomic = "64")]
            for _ in 0..len {
                let x = r.check(field, Reader::f64, |x| *x >= 0.0 && x.is_finite())?;
                words.push(Word::new(x.to_bits()));
            }
        }
        Ok(Self {
            words,
            stride: target.stride,
        })
    }

    /// Adds every sum of `other` (same length and mode) to this one's:
    /// exactly in deterministic mode (integer addition with carries), in
    /// `f64` otherwise. False, and nothing changed, when they differ.
    pub(crate) fn merge(&mut self, other: &Self) -> bool {
        if self.words.len() != other.words.len() || self.stride != other.stride {
            return false;
        }
        #[cfg(target_has_atomic = "64")]
        if self.stride == 1 {
            for (a, b) in self.words.iter_mut().zip(&other.words) {
                let sum = f64::from_bits(*a.get_mut()) + f64::from_bits(b.load(Relaxed));
                *a.get_mut() = sum.to_bits();
            }
            return true;
        }
        for i in 0..self.len() {
            let words = &self.words[i * self.stride..(i + 1) * self.stride];
            for k in 0..self.stride {
                add_word(words, k, other.words[i * self.stride + k].load(Relaxed));
            }
        }
        true
    }
}

impl Clone for SumBuffer {
    fn clone(&self) -> Self {
        Self {
            words: self
                .words
                .iter()
                .map(|w| Word::new(w.load(Relaxed)))
                .collect(),
            stride: self.stride,
        }
    }
}

#[cfg(target_has_atomic = "64")]
#[inline]
fn add_f64(word: &Word, value: f64) {
    let mut old = word.load(Relaxed);
    loop {
        let new = (f64::from_bits(old) + value).to_bits();
        match word.compare_exchange_weak(old, new, Relaxed, Relaxed) {
            Ok(_) => return,
            Err(actual) => old = actual,
        }
    }
}

/// Adds an exact positive f32 to the fixed-point words (LSB = 2^-149).
#[inline]
fn add_exact(words: &[Word], value: f32) {
    let bits = value.to_bits();
    let exp = (bits >> 23) & 0xff;
    let frac = bits & 0x7f_ffff;
    let (mantissa, shift) = if exp == 0 {
        (frac as u128, 0u32)
    } else {
        ((frac | 0x80_0000) as u128, exp - 1)
    };
    let word = (shift / WORD_BITS) as usize;
    let wide = mantissa << (shift % WORD_BITS);
    let mut part = wide;
    let mut k = word;
    while part != 0 && k < words.len() {
        add_word(words, k, part as Raw);
        part >>= WORD_BITS;
        k += 1;
    }
}

/// Adds to word `k`, carrying into the words above on overflow. Every step is
/// an atomic add, so the final integer is exact whatever the interleaving.
#[inline]
fn add_word(words: &[Word], mut k: usize, mut x: Raw) {
    while x != 0 && k < words.len() {
        let old = words[k].fetch_add(x, Relaxed);
        x = Raw::from(old.checked_add(x).is_none());
        k += 1;
    }
}

/// The exact sum rounded to f64, the same for the same integer.
fn exact_value(words: &[Word]) -> f64 {
    let mut value = 0.0f64;
    for (k, w) in words.iter().enumerate().rev() {
        let x = w.load(Relaxed);
        if x != 0 {
            let scale = (k as i32) * WORD_BITS as i32 - 149;
            value += x as f64 * pow2(scale);
        }
    }
    value
}

/// 2^e for e in the range the accumulator uses (-149..=235), exactly.
fn pow2(e: i32) -> f64 {
    f64::from_bits(((e + 1023) as u64) << 52)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fast_mode_keeps_small_increments() {
        let s = SumBuffer::new(1, Accumulation::Fast);
        s.add(0, 1.0e8);
        for _ in 0..1000 {
            s.add(0, 1.0);
        }
        // An f32 sum would have stayed at 1e8.
        assert_eq!(s.get(0), 1.0e8 + 1000.0);
    }

    #[test]
    fn exact_mode_is_exact_and_order_free() {
        let values = [
            3.0e30f32,
            1.0e-40,
            7.25,
            1.0e-30,
            0.1,
            3.0e30,
            2.0f32.powi(-149),
        ];
        let a = SumBuffer::new(1, Accumulation::Deterministic);
        let b = SumBuffer::new(1, Accumulation::Deterministic);
        for v in values {
            a.add(0, v);
        }
        for v in values.iter().rev() {
            b.add(0, *v);
        }
        assert_eq!(a.get(0).to_bits(), b.get(0).to_bits());
        let expect: f64 = values.iter().map(|&v| v as f64).sum();
        assert!((a.get(0) - expect).abs() <= expect * 1e-15);
    }

    #[test]
    fn exact_mode_carries() {
        let s = SumBuffer::new(1, Accumulation::Deterministic);
        // Largest f32: fills the top of the mantissa range; repeated adds
        // carry into higher words.
        for _ in 0..1000 {
            s.add(0, f32::MAX);
        }
        assert_eq!(s.get(0), f32::MAX as f64 * 1000.0);
        let small = SumBuffer::new(1, Accumulation::Deterministic);
        for _ in 0..(1 << 12) {
            small.add(0, 1.0);
        }
        assert_eq!(small.get(0), 4096.0);
    }

    #[test]
    fn rejects_bad_values_and_indices() {
        for mode in [Accumulation::Fast, Accumulation::Deterministic] {
            let s = SumBuffer::new(2, mode);
            assert!(!s.add(0, -1.0));
            assert!(!s.add(0, f32::NAN));
            assert!(!s.add(0, f32::INFINITY));
            assert!(!s.add(2, 1.0));
            assert!(s.add(1, 2.0));
            assert_eq!(s.get(0), 0.0);
            assert_eq!(s.get(1), 2.0);
            assert_eq!(s.get(9), 0.0);
        }
    }

    #[test]
    fn sizes() {
        let fast = if cfg!(target_has_atomic = "64") {
            8
        } else {
            48
        };
        for (mode, per_sum) in [
            (Accumulation::Fast, fast),
            (Accumulation::Deterministic, 48),
        ] {
            let s = SumBuffer::new(3, mode);
            assert!(!s.is_empty());
            assert_eq!(s.len(), 3);
            assert_eq!(s.bytes_per_sum(), per_sum);
            assert_eq!(s.bytes(), 3 * per_sum);
            assert!(SumBuffer::new(0, mode).is_empty());
        }
    }

    #[test]
    fn merge_adds_and_refuses_mismatches() {
        for mode in [Accumulation::Fast, Accumulation::Deterministic] {
            let mut a = SumBuffer::new(2, mode);
            let b = SumBuffer::new(2, mode);
            a.add(0, 1.5);
            a.add(1, 2.0);
            b.add(0, 0.25);
            b.add(1, 4.0);
            assert!(a.merge(&b));
            assert_eq!((a.get(0), a.get(1)), (1.75, 6.0), "{mode:?}");
            // Merging twice adds twice; the other side is unchanged.
            assert!(a.merge(&b));
            assert_eq!((a.get(0), a.get(1)), (2.0, 10.0), "{mode:?}");
            assert_eq!((b.get(0), b.get(1)), (0.25, 4.0));
            // Another length or another mode: refused, nothing changed.
            let longer = SumBuffer::new(3, mode);
            assert!(!a.merge(&longer));
            let other = match mode {
                Accumulation::Fast => Accumulation::Deterministic,
                Accumulation::Deterministic => Accumulation::Fast,
            };
            let c = SumBuffer::new(2, other);
            if c.mode() != a.mode() {
                c.add(0, 100.0);
                assert!(!a.merge(&c));
            }
            assert_eq!((a.get(0), a.get(1)), (2.0, 10.0));
        }
        // As many words, another mode (6 fast sums, 1 exact one on 64-bit
        // words): refused too.
        if cfg!(target_has_atomic = "64") {
            let mut fast = SumBuffer::new(EXACT_WORDS, Accumulation::Fast);
            let exact = SumBuffer::new(1, Accumulation::Deterministic);
            assert_eq!(fast.words.len(), exact.words.len());
            assert!(!fast.merge(&exact));
        }
    }

    #[test]
    fn saved_sums_round_trip_and_hostile_ones_are_refused() {
        use crate::persist::{Kind, LoadError, Reader, Writer};
        let sealed = |write: &dyn Fn(&mut Writer)| {
            let mut w = Writer::default();
            write(&mut w);
            w.finish(Kind::Glt)
        };
        let read = |bytes: &[u8], mode, n| {
            let mut r = Reader::open(bytes, Kind::Glt).unwrap();
            SumBuffer::read(&mut r, "sums", mode, n)
        };
        for mode in [Accumulation::Fast, Accumulation::Deterministic] {
            let s = SumBuffer::new(3, mode);
            s.add(0, 1.5);
            s.add(2, 1e30);
            let back = read(&sealed(&|w| s.write(w)), mode, 3).unwrap();
            assert_eq!(
                [back.get(0), back.get(1), back.get(2)],
                [s.get(0), 0.0, s.get(2)]
            );
            // Another count than expected, or the other mode: refused.
            assert!(read(&sealed(&|w| s.write(w)), mode, 2).is_err());
        }
        if cfg!(target_has_atomic = "64") {
            // Fast sums must be finite and non-negative.
            for bad in [-1.0, f64::INFINITY, f64::NAN] {
                let bytes = sealed(&|w| {
                    w.bool(false);
                    w.len(2);
                    w.f64(1.0);
                    w.f64(bad);
                });
                let r = read(&bytes, Accumulation::Fast, 2);
                assert!(matches!(r, Err(LoadError::Invalid { .. })), "{bad}: {r:?}");
            }
        }
        // An exact count that the bytes left cannot hold at 48 bytes a sum
        // is refused at the count, before anything is allocated.
        let bytes = sealed(&|w| {
            w.bool(true);
            w.len(40);
            w.bytes(&[0u8; 48]);
        });
        let r = read(&bytes, Accumulation::Deterministic, 40);
        assert!(
            matches!(r, Err(LoadError::Truncated { offset, .. }) if offset == 38 + 1),
            "{r:?}"
        );
    }

    #[test]
    fn clear_and_reset() {
        let mut s = SumBuffer::new(3, Accumulation::Deterministic);
        s.add(2, 5.0);
        s.clear();
        assert_eq!(s.get(2), 0.0);
        s.reset(5);
        assert_eq!(s.len(), 5);
        assert_eq!(s.mode(), Accumulation::Deterministic);
        assert_eq!(s.bytes(), 5 * 48);
    }

    #[cfg(feature = "std")]
    #[test]
    fn threads_lose_no_update() {
        extern crate std;
        for mode in [Accumulation::Fast, Accumulation::Deterministic] {
            let s = SumBuffer::new(4, mode);
            std::thread::scope(|scope| {
                for t in 0..4 {
                    let s = &s;
                    scope.spawn(move || {
                        for i in 0..10_000 {
                            s.add(i % 4, (t + 1) as f32 * 0.5);
                        }
                    });
                }
            });
            let total: f64 = (0..4).map(|i| s.get(i)).sum();
            assert_eq!(total, 10_000.0 * (0.5 + 1.0 + 1.5 + 2.0));
        }
    }
}
