//! The direction bound of a node while aggregating, which always bounds its
//! children.

use crate::math::LightCone;
use crate::math::cone_angle_between;
use core::f32::consts::PI;
use glam::{Quat, Vec3};

/// A node's direction bound while aggregating: pbrt-v4's cone union, but
/// with `theta_o` kept as an angle. [`LightCone`] stores `cos(theta_o)` in
/// `f32`, whose spacing near 1 hides angles up to ~3e-4 rad, so repeated
/// unions through it can end up narrower than their children; here every
/// union is widened by its own rounding error instead, so the result always
/// bounds the children.
#[derive(Clone, Copy, Debug)]
pub(super) struct ConeBound {
    pub(super) axis: Vec3,
    /// Half-angle of the normal cone; `>= pi` is the whole sphere.
    pub(super) theta_o: f32,
    pub(super) cos_theta_e: f32,
}

/// Covers the float error of one angle computation or rotation (a few
/// ulps of pi, with room to spare).
const ANGLE_SLACK: f32 = 2e-6;

impl ConeBound {
    pub(super) fn sphere(cos_theta_e: f32) -> Self {
        Self {
            axis: Vec3::Z,
            theta_o: PI,
            cos_theta_e,
        }
    }

    pub(super) fn of(c: &LightCone) -> Self {
        if c.is_sphere() {
            return Self::sphere(c.cos_theta_e);
        }
        Self {
            axis: c.axis,
            // Rounded to nearest; the node encoder's margin covers the
            // half ulp.
            theta_o: libm::acos(c.cos_theta_o.clamp(-1.0, 1.0) as f64) as f32,
            cos_theta_e: c.cos_theta_e,
        }
    }

    fn is_sphere(&self) -> bool {
        self.theta_o.partial_cmp(&PI) != Some(core::cmp::Ordering::Less)
    }

    pub(super) fn union(&self, o: &Self) -> Self {
        let cos_theta_e = self.cos_theta_e.min(o.cos_theta_e);
        if self.is_sphere() || o.is_sphere() {
            return Self::sphere(cos_theta_e);
        }
        if self.axis == o.axis {
            return Self {
                theta_o: self.theta_o.max(o.theta_o),
                cos_theta_e,
                ..*self
            };
        }
        let d = cone_angle_between(self.axis, o.axis) + ANGLE_SLACK;
        if d + o.theta_o <= self.theta_o {
            return Self {
                cos_theta_e,
                ..*self
            };
        }
        if d + self.theta_o <= o.theta_o {
            return Self { cos_theta_e, ..*o };
        }
        let theta_o = (self.theta_o + d + o.theta_o) * 0.5;
        if theta_o + ANGLE_SLACK >= PI {
            return Self::sphere(cos_theta_e);
        }
        let Some(wr) = self.axis.cross(o.axis).try_normalize() else {
            return Self::sphere(cos_theta_e);
        };
        let Some(axis) =
            (Quat::from_axis_angle(wr, theta_o - self.theta_o) * self.axis).try_normalize()
        else {
            return Self::sphere(cos_theta_e);
        };
        Self {
            axis,
            theta_o: theta_o + ANGLE_SLACK,
            cos_theta_e,
        }
    }
}
