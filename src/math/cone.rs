use super::scalar::{cos, safe_acos};
use core::f32::consts::PI;
use glam::{Quat, Vec3};

/// The directions a light (or a cluster of lights) emits into, as in pbrt-v4's
/// `LightBounds`: normals lie within `theta_o` of `axis`, and each normal emits
/// up to `theta_e` away from itself.
///
/// Angles are stored as cosines. The entire sphere is `cos_theta_o = -1`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LightCone {
    /// Unit axis of the normal cone.
    pub axis: Vec3,
    /// Cosine of the normal cone's half-angle `theta_o`.
    pub cos_theta_o: f32,
    /// Cosine of the emission falloff angle `theta_e` (pi/2 for a Lambertian
    /// surface: `0`).
    pub cos_theta_e: f32,
}

impl LightCone {
    /// Emission in every direction: a point light or a cluster with
    /// omnidirectional members.
    pub const SPHERE: Self = Self {
        axis: Vec3::Z,
        cos_theta_o: -1.0,
        cos_theta_e: 0.0,
    };

    /// A cone from its axis (normalised here; a zero or non-finite axis gives
    /// [`LightCone::SPHERE`]) and its two angles in radians.
    pub fn new(axis: Vec3, theta_o: f32, theta_e: f32) -> Self {
        let Some(axis) = axis.try_normalize() else {
            return Self::SPHERE;
        };
        Self {
            axis,
            cos_theta_o: cos(theta_o.clamp(0.0, PI)),
            cos_theta_e: cos(theta_e.clamp(0.0, PI)),
        }
    }

    /// A one-sided Lambertian emitter with the given normal (theta_o = 0,
    /// theta_e = pi/2).
    pub fn lambertian(normal: Vec3) -> Self {
        Self::new(normal, 0.0, core::f32::consts::FRAC_PI_2)
    }

    /// A spot light along `axis` whose emission ends `angle` radians off it.
    pub fn spot(axis: Vec3, angle: f32) -> Self {
        Self::new(axis, 0.0, angle)
    }

    /// `theta_o` in radians.
    #[inline]
    pub fn theta_o(&self) -> f32 {
        safe_acos(self.cos_theta_o)
    }

    /// `theta_e` in radians.
    #[inline]
    pub fn theta_e(&self) -> f32 {
        safe_acos(self.cos_theta_e)
    }

    /// True when the normal cone covers every direction.
    #[inline]
    pub fn is_sphere(&self) -> bool {
        self.cos_theta_o <= -1.0
    }

    /// The smallest cone (in pbrt-v4's construction) that bounds both: the
    /// normal cones are merged and the larger `theta_e` is kept.
    pub fn union(&self, other: &Self) -> Self {
        self.union_with_angles(self.theta_o(), other, other.theta_o())
            .0
    }

    /// [`LightCone::union`] (the same operations, the same result bits)
    /// with each cone's [`LightCone::theta_o`] passed in rather than
    /// recomputed; returns the union and its `theta_o`. The light tree's
    /// builder merges a cone per emitter and axis, mostly equal or nested
    /// ones, and keeping the angles beside the cones saves every `acos`.
    #[inline]
    pub(crate) fn union_with_angles(
        &self,
        theta_a: f32,
        other: &Self,
        theta_b: f32,
    ) -> (Self, f32) {
        if self.is_sphere() || other.is_sphere() {
            let cos_theta_e = self.cos_theta_e.min(other.cos_theta_e);
            // A sphere's angle is `safe_acos(-1)`, as `theta_o()` computes
            // it; pass it on rather than assume it equals `PI`.
            let theta = if self.is_sphere() { theta_a } else { theta_b };
            return (
                Self {
                    cos_theta_e,
                    ..Self::SPHERE
                },
                theta,
            );
        }
        if self == other {
            // angle_between(x, x) == 0, so the union is `self`.
            return (*self, theta_a);
        }
        self.union_general(theta_a, other, theta_b)
    }

    /// [`LightCone::union_with_angles`] of two different cones, neither the
    /// sphere (kept out of line: the builder's hot loop mostly takes the
    /// two shortcuts).
    #[inline(never)]
    fn union_general(&self, theta_a: f32, other: &Self, theta_b: f32) -> (Self, f32) {
        let cos_theta_e = self.cos_theta_e.min(other.cos_theta_e);
        let sphere = || {
            let c = Self {
                cos_theta_e,
                ..Self::SPHERE
            };
            (c, safe_acos(c.cos_theta_o))
        };
        let theta_d = angle_between(self.axis, other.axis);
        if (theta_d + theta_b).min(PI) <= theta_a {
            return (
                Self {
                    cos_theta_e,
                    ..*self
                },
                theta_a,
            );
        }
        if (theta_d + theta_a).min(PI) <= theta_b {
            return (
                Self {
                    cos_theta_e,
                    ..*other
                },
                theta_b,
            );
        }
        let theta_o = (theta_a + theta_d + theta_b) * 0.5;
        if theta_o >= PI {
            return sphere();
        }
        let Some(wr) = self.axis.cross(other.axis).try_normalize() else {
            return sphere();
        };
        let axis = Quat::from_axis_angle(wr, theta_o - theta_a) * self.axis;
        let c = Self {
            axis: axis.normalize_or(Vec3::Z),
            cos_theta_o: cos(theta_o),
            cos_theta_e,
        };
        (c, safe_acos(c.cos_theta_o))
    }
}

/// The angle between two unit vectors, accurate near 0 and pi:
/// `2 atan2(|a - b|, |a + b|)` (an `acos` of the dot product loses all
/// precision below ~3e-4 rad).
#[inline]
pub(crate) fn angle_between(a: Vec3, b: Vec3) -> f32 {
    2.0 * super::scalar::atan2((a - b).length(), (a + b).length())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn covers(c: &LightCone, d: Vec3) -> bool {
        c.is_sphere() || angle_between(c.axis, d) <= c.theta_o() + 1e-4
    }

    #[test]
    fn union_covers_both_axes() {
        let a = LightCone::lambertian(Vec3::X);
        let b = LightCone::lambertian(Vec3::Y);
        let u = a.union(&b);
        assert!(covers(&u, Vec3::X) && covers(&u, Vec3::Y));
        assert!((u.theta_o() - core::f32::consts::FRAC_PI_4).abs() < 1e-5);
        assert_eq!(u.cos_theta_e, a.cos_theta_e);
    }

    #[test]
    fn opposite_axes_give_sphere() {
        let u = LightCone::lambertian(Vec3::Z).union(&LightCone::lambertian(-Vec3::Z));
        assert!(u.is_sphere());
    }

    #[test]
    fn nested_cone_is_absorbed() {
        let wide = LightCone::new(Vec3::Z, 1.0, 0.1);
        let narrow = LightCone::new(Vec3::new(0.1, 0.0, 1.0), 0.05, 0.5);
        let u = wide.union(&narrow);
        assert_eq!(u.axis, wide.axis);
        assert_eq!(u.cos_theta_o, wide.cos_theta_o);
        assert_eq!(u.cos_theta_e, narrow.cos_theta_e);
    }

    #[test]
    fn degenerate_axis_is_sphere() {
        assert!(LightCone::new(Vec3::ZERO, 0.0, 1.0).is_sphere());
        assert!(LightCone::new(Vec3::NAN, 0.0, 1.0).is_sphere());
    }

    #[test]
    fn angle_between_is_accurate_at_extremes() {
        assert_eq!(angle_between(Vec3::Z, Vec3::Z), 0.0);
        assert!((angle_between(Vec3::Z, -Vec3::Z) - PI).abs() < 1e-6);
        let tiny = Vec3::new(1e-4, 0.0, 1.0).normalize();
        assert!((angle_between(Vec3::Z, tiny) - 1e-4).abs() < 1e-7);
    }
}
