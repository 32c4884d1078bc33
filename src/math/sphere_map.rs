//! The world-space equal-area cylindrical map of Practical Path Guiding:
//! `cos(theta) = 2u - 1`, `phi = 2 pi v`. Its Jacobian is the constant
//! `4 pi`, so a density over `[0, 1]^2` divided by `4 pi` is a solid-angle pdf.

use super::scalar::{atan2, safe_sqrt, sin_cos};
use core::f32::consts::PI;
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
#[inline]
pub fn dir_to_canonical(d: Vec3) -> Vec2 {
    let cos_theta = d.z.clamp(-1.0, 1.0);
    let mut phi = atan2(d.y, d.x);
    if phi < 0.0 {
        phi += 2.0 * PI;
    }
    let u = ((cos_theta + 1.0) * 0.5).clamp(0.0, ONE_MINUS_EPS);
    let v = (phi / (2.0 * PI)).clamp(0.0, ONE_MINUS_EPS);
    Vec2::new(u, v)
}

const ONE_MINUS_EPS: f32 = 1.0 - f32::EPSILON / 2.0;

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
