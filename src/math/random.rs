//! Uniform numbers from a renderer's random generator
//! ([`rand_core::Rng`]), for the `*_with` conveniences beside the calls
//! that take numbers: the same mapping everywhere, so a query driven by a
//! generator equals the query driven by the number it drew.

use rand_core::Rng;

/// `2^-24`: the spacing of the numbers [`unit_f32`] returns.
const F32_STEP: f32 = 1.0 / (1u32 << 24) as f32;

/// `2^-53`: the spacing of the numbers [`unit_f64`] returns.
const F64_STEP: f64 = 1.0 / (1u64 << 53) as f64;

/// A uniform number in `[0, 1)` from one `next_u32`: its top 24 bits
/// times `2^-24`, every such number exactly representable (never 1).
#[inline]
pub fn unit_f32<R: Rng + ?Sized>(rng: &mut R) -> f32 {
    (rng.next_u32() >> 8) as f32 * F32_STEP
}

/// A uniform number in `[0, 1)` from one `next_u64`: its top 53 bits
/// times `2^-53` (never 1).
#[inline]
pub fn unit_f64<R: Rng + ?Sized>(rng: &mut R) -> f64 {
    (rng.next_u64() >> 11) as f64 * F64_STEP
}

#[cfg(test)]
mod tests {
    use super::*;
    use core::convert::Infallible;

    /// A generator that returns one fixed word.
    struct Fixed(u64);

    impl rand_core::TryRng for Fixed {
        type Error = Infallible;
        fn try_next_u32(&mut self) -> Result<u32, Infallible> {
            Ok(self.0 as u32)
        }
        fn try_next_u64(&mut self) -> Result<u64, Infallible> {
            Ok(self.0)
        }
        fn try_fill_bytes(&mut self, dst: &mut [u8]) -> Result<(), Infallible> {
            dst.fill(self.0 as u8);
            Ok(())
        }
    }

    /// The extremes map to 0 and to the largest number below 1, and the
    /// top bits decide: a mapping that divided by `u32::MAX` (or kept the
    /// low bits) would return 1 or lose the top.
    #[test]
    fn numbers_stay_below_one() {
        assert_eq!(unit_f32(&mut Fixed(0)), 0.0);
        assert_eq!(unit_f32(&mut Fixed(u64::MAX)), 1.0 - F32_STEP);
        assert!(unit_f32(&mut Fixed(u64::MAX)) < 1.0);
        assert_eq!(unit_f32(&mut Fixed(0x8000_0000)), 0.5);
        assert_eq!(unit_f32(&mut Fixed(0xff)), 0.0);
        assert_eq!(unit_f64(&mut Fixed(0)), 0.0);
        assert_eq!(unit_f64(&mut Fixed(u64::MAX)), 1.0 - F64_STEP);
        assert!(unit_f64(&mut Fixed(u64::MAX)) < 1.0);
        assert_eq!(unit_f64(&mut Fixed(1 << 63)), 0.5);
    }
}
