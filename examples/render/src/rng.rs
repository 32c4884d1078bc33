//! Random numbers: one PCG stream per (seed, pass, tile), so a render is
//! reproducible whatever the thread count.

use glam::Vec2;
use rand_pcg::Pcg32;
use rand_pcg::rand_core::Rng;

/// SplitMix64's finaliser: spreads nearby integers over all 64 bits.
pub fn mix64(mut x: u64) -> u64 {
    x = x.wrapping_add(0x9e37_79b9_7f4a_7c15);
    x = (x ^ (x >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    x = (x ^ (x >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    x ^ (x >> 31)
}

/// Uniform numbers for one tile of one pass.
pub struct Sampler {
    rng: Pcg32,
}

impl Sampler {
    /// The stream for `seed`, `pass` and `tile`.
    pub fn new(seed: u64, pass: u64, tile: u64) -> Self {
        let state = mix64(seed ^ mix64(pass.wrapping_mul(0x1000_0000_01b3) ^ mix64(tile)));
        Self {
            rng: Pcg32::new(state, mix64(tile ^ 0x5851_f42d_4c95_7f2d)),
        }
    }

    /// A number in `[0, 1)` with 24 random bits.
    #[inline]
    // A sampler's next number, not an iterator's next item.
    #[allow(clippy::should_implement_trait)]
    pub fn next(&mut self) -> f32 {
        (self.rng.next_u32() >> 8) as f32 * (1.0 / 16_777_216.0)
    }

    /// Two numbers in `[0, 1)`.
    #[inline]
    pub fn next2(&mut self) -> Vec2 {
        Vec2::new(self.next(), self.next())
    }
}
