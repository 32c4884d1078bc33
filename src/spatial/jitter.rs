//! [`Jitter`]: where a stochastic spatial filter gets its random numbers.

use rand_core::Rng;

/// The random numbers of one jittered splat (PPG's stochastic box): any
/// `rand_core` generator (one `next_u64` per splat, 21 bits per axis), or
/// three numbers the renderer drew from its own sampler
/// ([`JitterNumbers`]), so a renderer on another `rand_core` version, or
/// with a QMC sampler, implements nothing. Filters that do not jitter draw
/// nothing.
pub trait Jitter {
    /// Three numbers in `[0, 1)`, one per axis.
    fn jitter(&mut self) -> [f32; 3];
}

impl<R: Rng + ?Sized> Jitter for R {
    #[inline]
    fn jitter(&mut self) -> [f32; 3] {
        let bits = self.next_u64();
        let unit = |k: u32| ((bits >> (k * 21)) & 0x1f_ffff) as f32 * (1.0 / 2_097_152.0);
        [unit(0), unit(1), unit(2)]
    }
}

/// Three numbers in `[0, 1)` from the renderer's own sampler (values
/// outside are clamped into it, NaN counts as 0).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct JitterNumbers(pub [f32; 3]);

impl Jitter for JitterNumbers {
    #[inline]
    fn jitter(&mut self) -> [f32; 3] {
        const BELOW_ONE: f32 = 1.0 - f32::EPSILON / 2.0;
        self.0.map(|x| {
            if x.is_nan() {
                0.0
            } else {
                x.clamp(0.0, BELOW_ONE)
            }
        })
    }
}

/// The stochastic box's offset, each coordinate in `[-1/2, 1/2)`.
#[inline]
pub(crate) fn jitter_offset<J: Jitter + ?Sized>(jitter: &mut J) -> glam::Vec3 {
    glam::Vec3::from(jitter.jitter()) - 0.5
}
