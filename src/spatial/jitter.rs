//! Where the stochastic box filter's offset comes from: a hash of the
//! record itself.
//!
//! PPG jitters each record's position with three random numbers. Here the
//! numbers are a hash of what the record is (the position's bits and a
//! salt: the sampled direction's bits, or the light's id), so a record
//! takes no random-number argument, the default nearest filter costs
//! nothing for it, and the same records learn the same state whatever the
//! thread count and order. The records of a path tracer are made at
//! continuously distributed points, so their hashes are as good as
//! independent uniform numbers (`tests/jitter.rs` tests the offsets'
//! distribution and that the filter equals the box filter in expectation).

use glam::Vec3;

/// SplitMix64's finaliser: every input bit moves every output bit.
#[inline(always)]
fn mix(mut z: u64) -> u64 {
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

/// The stochastic box's offset for a record made at `p` with `salt` (what
/// else tells records at one point apart), each coordinate in
/// `[-1/2, 1/2)` (21 bits each).
#[inline]
pub(crate) fn record_offset(p: Vec3, salt: [u32; 3]) -> Vec3 {
    let word = |a: u32, b: u32| u64::from(a) | (u64::from(b) << 32);
    let mut h = mix(word(p.x.to_bits(), p.y.to_bits()) ^ 0x9e37_79b9_7f4a_7c15);
    h = mix(h ^ word(p.z.to_bits(), salt[0]));
    h = mix(h ^ word(salt[1], salt[2]));
    let unit = |k: u32| ((h >> (k * 21)) & 0x1f_ffff) as f32 * (1.0 / 2_097_152.0) - 0.5;
    Vec3::new(unit(0), unit(1), unit(2))
}

/// The salt of a record along `dir` (a radiance record).
#[inline]
pub(crate) fn direction_salt(dir: Vec3) -> [u32; 3] {
    [dir.x.to_bits(), dir.y.to_bits(), dir.z.to_bits()]
}

#[cfg(test)]
mod tests {
    use super::*;
    use alloc::vec::Vec;

    /// The offsets of records at nearby points, or at one point with other
    /// salts, are uniform in the box: 8 bins per axis, chi-square with 7
    /// degrees of freedom, well below its 0.1% point (24.3). A hash that
    /// ignored the salt, or used only some of the position's bits, fails.
    #[test]
    fn offsets_are_uniform_per_axis() {
        let worst = |offsets: &[Vec3]| {
            let mut worst = 0f64;
            for axis in 0..3 {
                let mut bins = [0f64; 8];
                for o in offsets {
                    assert!((-0.5..0.5).contains(&o[axis]));
                    bins[((o[axis] + 0.5) * 8.0) as usize] += 1.0;
                }
                let e = offsets.len() as f64 / 8.0;
                let chi2: f64 = bins.iter().map(|b| (b - e) * (b - e) / e).sum();
                worst = worst.max(chi2);
            }
            worst
        };
        let check = |offsets: &[Vec3]| {
            let chi2 = worst(offsets);
            assert!(chi2 < 24.3, "chi2 {chi2}");
        };
        // Points one f32 step apart along x.
        let near: Vec<Vec3> = (0..8000u32)
            .map(|i| record_offset(Vec3::new(f32::from_bits(0x3f80_0000 + i), 2.0, 3.0), [0; 3]))
            .collect();
        check(&near);
        // One point, light ids as salt.
        let salted: Vec<Vec3> = (0..8000u32)
            .map(|i| record_offset(Vec3::splat(0.25), [i, 1, 0]))
            .collect();
        check(&salted);
        // Directions as salt.
        let dirs: Vec<Vec3> = (0..8000u32)
            .map(|i| {
                let t = i as f32 * 0.37;
                let d = Vec3::new(libm::sinf(t), libm::cosf(0.3 * t), 0.5);
                record_offset(Vec3::ONE, direction_salt(d))
            })
            .collect();
        check(&dirs);
        // The control: the offsets of a hash that saw only the high bits of
        // the position (the cell, not the point) fail.
        let coarse: Vec<Vec3> = (0..8000u32)
            .map(|i| {
                let x = f32::from_bits((0x3f80_0000 + i) & !0xfff);
                record_offset(Vec3::new(x, 2.0, 3.0), [0; 3])
            })
            .collect();
        assert!(worst(&coarse) > 24.3);
    }
}
