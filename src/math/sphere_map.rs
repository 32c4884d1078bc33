//! The world-space equal-area cylindrical map of Practical Path Guiding:
//! `cos(theta) = 2u - 1`, `phi = 2 pi v`. Its Jacobian is the constant
//! `4 pi`, so a density over `[0, 1]^2` divided by `4 pi` is a solid-angle pdf.

use super::scalar::{safe_sqrt, sin_cos};
use core::f32::consts::{FRAC_PI_2, PI};
use glam::{Vec2, Vec3};

/// Solid angle per unit of canonical area: `4 pi` steradians.
pub const SPHERE_MAP_JACOBIAN: f32 = 4.0 * PI;

/// The unit direction at canonical coordinates `c` in `[0, 1]^2`.
#[inline]
pub fn canonical_to_dir(c: Vec2) -> Vec3 {
    let cos_theta = 2.0 * c.x - 1.0;
    let sin_theta = safe_sqrt(1.0 - cos_theta * cos_theta);
    let (sin_phi, cos_phi) = sin_cos(2.0 * PI * c.y);
    Vec3::new(sin_theta * cos_phi, sin_theta * sin_phi, cos_theta)
}

/// The canonical coordinates in `[0, 1)^2` of a unit direction. Callers
/// validate directions first; a non-unit input is still mapped without NaN.
/// `v` comes from an inline polynomial `atan2` within 5.5e-7 radians of the
/// exact angle, `f32` arithmetic only: the same bits on every target, with
/// and without `std`.
#[inline]
pub fn dir_to_canonical(d: Vec3) -> Vec2 {
    let cos_theta = d.z.clamp(-1.0, 1.0);
    let phi = azimuth(d.y, d.x);
    let u = ((cos_theta + 1.0) * 0.5).clamp(0.0, ONE_MINUS_EPS);
    let v = (phi / (2.0 * PI)).clamp(0.0, ONE_MINUS_EPS);
    Vec2::new(u, v)
}

const ONE_MINUS_EPS: f32 = 1.0 - f32::EPSILON / 2.0;

/// `atan(a) / a` on `a^2` in `[0, 1]`, from the constant term up: a
/// degree-8 polynomial fitted here (weighted least squares on Chebyshev
/// nodes, reweighted toward the minimax), its `f32` Horner evaluation
/// within 1.4e-7 of `atan` relative (`azimuth_follows_atan2`).
const ATAN: [f32; 9] = [
    1.0,
    -0.333_330_93,
    0.199_930_53,
    -0.142_071_32,
    0.106_546_685,
    -0.075_336_576,
    0.043_039_143,
    -0.016_282_87,
    0.002_903_517_6,
];

/// The angle of `(x, y)` counter-clockwise from the x axis, in
/// `[0, 2 pi]` (`atan2(y, x)`, negative angles taken once around): 0 for
/// `(0, 0)`, NaN and infinities.
///
/// Every pdf and record of a directional distribution maps a direction
/// to the square through this angle. libm's `atan2f` is a call of ~100
/// instructions; this is ~30 inline, `f32` multiplications and additions
/// only, so it gives the same bits with and without `std` and on every
/// target. It is within 5.5e-7 radians of the exact angle (one `f32`
/// step at `2 pi` is 4.8e-7), and within 2e-7 of it relative for small
/// angles (`azimuth_follows_atan2`). `sample` and `pdf` map through the
/// same function, so they agree whatever its error.
#[inline]
pub(crate) fn azimuth(y: f32, x: f32) -> f32 {
    let (ax, ay) = (x.abs(), y.abs());
    let (lo, hi) = (ax.min(ay), ax.max(ay));
    // False for (0, 0), NaN and infinities.
    if !(hi > 0.0 && (ax + ay).is_finite()) {
        return 0.0;
    }
    // `atan` of the smaller ratio, in [0, pi/4].
    let a = lo / hi;
    let t = a * a;
    let mut p = ATAN[8];
    for c in ATAN[..8].iter().rev() {
        p = p * t + c;
    }
    let mut r = a * p;
    if ay > ax {
        r = FRAC_PI_2 - r;
    }
    if x < 0.0 {
        r = PI - r;
    }
    if y < 0.0 {
        r = 2.0 * PI - r;
    }
    r
}

/// `dir` scaled to unit length; `None` when it has a NaN or infinite
/// component or is zero. Tiny and huge directions are rescaled before
/// normalising, so any finite non-zero vector works.
#[inline]
pub(crate) fn unit_direction(dir: Vec3) -> Option<Vec3> {
    if !dir.is_finite() {
        return None;
    }
    let m = dir.abs().max_element();
    if m == 0.0 {
        return None;
    }
    let d = dir / m;
    Some(d / d.length())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trip() {
        for i in 0..50 {
            for j in 0..50 {
                let c = Vec2::new((i as f32 + 0.5) / 50.0, (j as f32 + 0.5) / 50.0);
                let d = canonical_to_dir(c);
                assert!((d.length() - 1.0).abs() < 1e-5);
                let back = dir_to_canonical(d);
                assert!(
                    (back - c).abs().max_element() < 1e-4,
                    "{c} -> {d} -> {back}"
                );
            }
        }
    }

    /// The azimuth is `atan2` (taken into `[0, 2 pi)`) to 5.5e-7 radians
    /// over a dense sweep of every octant (seen: 5.0e-7, where `2 pi - r`
    /// rounds near `2 pi`; libm's `atan2f` plus `2 pi`, the map before,
    /// 5.3e-7 in the same sweep), and to 2e-7 relative just above the x
    /// axis, where the angle is small; zero, NaN and infinite
    /// inputs give 0. Control: the degree-6 fit (8.4e-7 relative) fails
    /// it, and so does a mirror left out.
    #[test]
    fn azimuth_follows_atan2() {
        let mut worst = (0.0f64, 0.0f64);
        let n = 200_000;
        for i in 0..n {
            let angle = (i as f64 + 0.5) / n as f64 * core::f64::consts::TAU;
            for r in [1.0f64, 1e-30, 3e20] {
                let (x, y) = ((angle.cos() * r) as f32, (angle.sin() * r) as f32);
                let exact = f64::from(y)
                    .atan2(f64::from(x))
                    .rem_euclid(core::f64::consts::TAU);
                let got = f64::from(azimuth(y, x));
                assert!(
                    (0.0..=core::f64::consts::TAU).contains(&got),
                    "{x} {y}: {got}"
                );
                // Across the seam, 2 pi and 0 are the same direction.
                let err = (got - exact)
                    .abs()
                    .min(core::f64::consts::TAU - (got - exact).abs());
                worst.0 = worst.0.max(err);
            }
        }
        // Small angles above the x axis, down to 1e-12: relative accuracy
        // (elsewhere an angle is near a multiple of pi/2 and only its
        // absolute error means anything, checked above).
        for k in 1..2000 {
            let e = (k as f64 * 1e-3).powi(4);
            let (x, y) = (1.0f32, e as f32);
            let exact = f64::from(y).atan2(f64::from(x));
            let got = f64::from(azimuth(y, x));
            worst.1 = worst.1.max((got - exact).abs() / exact);
        }
        assert!(worst.0 <= 5.5e-7, "{} radians", worst.0);
        assert!(worst.1 <= 2e-7, "{} relative", worst.1);
        for (x, y) in [
            (0.0, 0.0),
            (-0.0, 0.0),
            (f32::NAN, 1.0),
            (1.0, f32::NAN),
            (f32::INFINITY, 1.0),
        ] {
            assert_eq!(azimuth(y, x), 0.0, "{x} {y}");
        }
    }

    #[test]
    fn poles_and_seam_stay_in_range() {
        for d in [Vec3::Z, -Vec3::Z, Vec3::X, Vec3::new(1.0, -1e-9, 0.0)] {
            let c = dir_to_canonical(d);
            assert!(
                c.x >= 0.0 && c.x < 1.0 && c.y >= 0.0 && c.y < 1.0,
                "{d} -> {c}"
            );
        }
    }
}
