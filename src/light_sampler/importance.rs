//! The importance of a light cluster at a shading point: Estevez & Kulla's
//! bound as pbrt-v4's `LightBounds::Importance` computes it, with a
//! scale-invariant distance clamp.

use super::ShadingContext;
use crate::light_tree::NodeBounds;
use crate::math::scalar::sqrt64;
use glam::Vec3;

/// Floor of the squared distance: only reached when the shading point sits
/// exactly on a point cluster, where the true importance is infinite. Keeps
/// every importance finite (power <= f32::MAX) in `f64`.
const MIN_DISTANCE2: f64 = 1e-200;

/// The orientation factor given to a point the cluster reaches at more than
/// 90 degrees from every normal (`cos(theta') <= 0` but within `theta_e`,
/// e.g. a wide spot light's back). pbrt-v4 gives such points zero importance,
/// which would never sample lights that do reach them.
pub(crate) const BACK_FACTOR: f64 = 1e-3;

/// The importance of the lights bounded by `node` at the shading point
/// `ctx`: power x a conservative cosine of the emission angle / clamped
/// squared distance, times the conservative `|cos|` to the surface normal
/// when `ctx.normal` is set. This is pbrt-v4's `LightBounds::Importance`
/// (Estevez & Kulla 2018) with two fixes:
///
/// - the squared distance to the box centre is clamped to the squared radius
///   of the box's bounding sphere, `(|diagonal| / 2)^2` (pbrt compares a
///   squared distance with a length, which is not scale-invariant), and to a
///   tiny floor so a point on a point light stays finite;
/// - a point reached at more than 90 degrees from every normal (possible
///   when `theta_e > pi/2`) keeps a small positive factor instead of zero.
///
/// Inside the bounding sphere every direction is possible and the importance
/// is `power / radius^2`. The result is computed in `f64` and saturates at
/// `f32::MAX`; a positive result never rounds to zero. It is never NaN or
/// negative, and 0 only when the cluster has no power, its box is empty, its
/// emission cone provably misses the point, a point cluster lies exactly in
/// the surface's tangent plane, or the input is not finite.
pub fn importance(ctx: &ShadingContext, node: &NodeBounds) -> f32 {
    let i = Query::new(ctx).importance(node);
    if i > 0.0 {
        (i as f32).clamp(f32::from_bits(1), f32::MAX)
    } else {
        0.0
    }
}

/// A shading point prepared for many importance evaluations: converted to
/// `f64` and its normal normalised once.
#[derive(Clone, Copy)]
pub(crate) struct Query {
    p: D3,
    n: Option<D3>,
    finite: bool,
}

impl Query {
    /// Prepares `ctx`.
    #[inline]
    pub(crate) fn new(ctx: &ShadingContext) -> Self {
        Self {
            p: D3::from(ctx.position),
            n: ctx.normal.and_then(|n| D3::from(n).normalized()),
            finite: ctx.position.is_finite(),
        }
    }

    /// [`importance`] before rounding to `f32`: finite for finite inputs
    /// with `power <= f32::MAX`, never NaN or negative (may be infinite
    /// only for an infinite power).
    #[inline]
    pub(crate) fn importance(&self, node: &NodeBounds) -> f64 {
        importance_f64(self, node)
    }
}

fn importance_f64(q: &Query, node: &NodeBounds) -> f64 {
    let phi = node.power as f64;
    let b = &node.bounds;
    let valid = phi > 0.0 && q.finite && b.min.is_finite() && b.max.is_finite();
    if !valid || b.is_empty() {
        return 0.0;
    }
    let (p, lo, hi) = (q.p, D3::from(b.min), D3::from(b.max));
    let center = lo.add(hi).scale(0.5);
    let r2 = hi.sub(lo).scale(0.5).length_squared();
    let to_p = p.sub(center);
    let dist2 = to_p.length_squared();
    let d2 = dist2.max(r2).max(MIN_DISTANCE2);
    if dist2 <= r2 {
        // Inside the bounding sphere: theta_b = pi, every factor is 1.
        return phi / d2;
    }
    let wi = to_p.scale(1.0 / sqrt64(dist2));
    // The cone of directions from the point to the bounding sphere.
    let sin2_b = r2 / dist2;
    let (sin_b, cos_b) = (sqrt64(sin2_b), sqrt64((1.0f64 - sin2_b).max(0.0)));

    // theta' = max(0, theta_w - theta_o - theta_b): the smallest angle
    // between the emission direction towards p and any normal in the cone.
    let cone = &node.cone;
    let cos_o = (cone.cos_theta_o as f64).clamp(-1.0, 1.0);
    let cos_thetap = match D3::from(cone.axis).unit() {
        Some(axis) if cos_o > -1.0 => {
            let mut cos_w = axis.dot(wi).clamp(-1.0, 1.0);
            if node.two_sided {
                cos_w = cos_w.abs();
            }
            let sin_w = sin_of(cos_w);
            let sin_o = sin_of(cos_o);
            let cos_x = cos_sub_clamped(sin_w, cos_w, sin_o, cos_o);
            let sin_x = sin_sub_clamped(sin_w, cos_w, sin_o, cos_o);
            cos_sub_clamped(sin_x, cos_x, sin_b, cos_b)
        }
        _ => 1.0,
    };
    let cos_e = (cone.cos_theta_e as f64).clamp(-1.0, 1.0);
    // Written so that a NaN (from a NaN cone) also gives 0.
    let reaches = cos_thetap >= cos_e;
    if !reaches {
        return 0.0;
    }
    let mut imp = phi * cos_thetap.max(BACK_FACTOR) / d2;
    if let Some(n) = q.n {
        imp *= normal_factor(wi, n, sin_b, cos_b);
    }
    if imp >= 0.0 { imp } else { 0.0 }
}

/// `cos(max(0, theta_i - theta_b))` for the angle `theta_i` between the
/// direction and the (two-sided) normal.
#[inline]
fn normal_factor(wi: D3, n: D3, sin_b: f64, cos_b: f64) -> f64 {
    let cos_i = wi.dot(n).abs().min(1.0);
    cos_sub_clamped(sin_of(cos_i), cos_i, sin_b, cos_b)
}

/// A minimal `f64` 3-vector (glam's `f64` types are not enabled).
#[derive(Clone, Copy)]
struct D3([f64; 3]);

impl From<Vec3> for D3 {
    #[inline]
    fn from(v: Vec3) -> Self {
        Self([v.x as f64, v.y as f64, v.z as f64])
    }
}

impl D3 {
    #[inline]
    fn add(self, o: Self) -> Self {
        Self([self.0[0] + o.0[0], self.0[1] + o.0[1], self.0[2] + o.0[2]])
    }
    #[inline]
    fn sub(self, o: Self) -> Self {
        Self([self.0[0] - o.0[0], self.0[1] - o.0[1], self.0[2] - o.0[2]])
    }
    #[inline]
    fn scale(self, s: f64) -> Self {
        Self([self.0[0] * s, self.0[1] * s, self.0[2] * s])
    }
    #[inline]
    fn dot(self, o: Self) -> f64 {
        self.0[0] * o.0[0] + self.0[1] * o.0[1] + self.0[2] * o.0[2]
    }
    #[inline]
    fn length_squared(self) -> f64 {
        self.dot(self)
    }
    /// `self` when already unit length (to 1e-6, as decoded axes are),
    /// else [`D3::normalized`].
    #[inline]
    fn unit(self) -> Option<Self> {
        if (self.length_squared() - 1.0).abs() < 1e-6 {
            Some(self)
        } else {
            self.normalized()
        }
    }
    /// The unit vector along `self`; `None` when zero or not finite.
    #[inline]
    fn normalized(self) -> Option<Self> {
        let l2 = self.length_squared();
        (l2 > 0.0 && l2.is_finite()).then(|| self.scale(1.0 / sqrt64(l2)))
    }
}

#[inline]
fn sin_of(cos: f64) -> f64 {
    sqrt64((1.0 - cos * cos).max(0.0))
}

/// `cos(max(0, a - b))` from the sines and cosines of `a` and `b`.
#[inline]
fn cos_sub_clamped(sin_a: f64, cos_a: f64, sin_b: f64, cos_b: f64) -> f64 {
    if cos_a > cos_b {
        1.0
    } else {
        cos_a * cos_b + sin_a * sin_b
    }
}

/// `sin(max(0, a - b))` from the sines and cosines of `a` and `b`.
#[inline]
fn sin_sub_clamped(sin_a: f64, cos_a: f64, sin_b: f64, cos_b: f64) -> f64 {
    if cos_a > cos_b {
        0.0
    } else {
        sin_a * cos_b - cos_a * sin_b
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::{Aabb, LightCone};

    fn node(bounds: Aabb, cone: LightCone, power: f32) -> NodeBounds {
        NodeBounds {
            bounds,
            cone,
            two_sided: false,
            power,
        }
    }

    fn point(p: Vec3, power: f32) -> NodeBounds {
        node(Aabb::from_point(p), LightCone::SPHERE, power)
    }

    /// The documented edges, each against what it must equal: no
    /// importance at a non-finite point (even from a cluster that emits
    /// everywhere, whose bound would otherwise not look at the point), a
    /// cone axis of any length or none at all (zero or infinite: every
    /// direction, as an omnidirectional cluster), a normal of any length or
    /// a zero one (no normal).
    #[test]
    fn degenerate_inputs_are_handled_as_documented() {
        let at = ShadingContext::at(Vec3::new(0.3, -8.0, 0.5));
        let b = Aabb::new(Vec3::new(-0.5, 0.0, -0.5), Vec3::new(0.5, 0.2, 0.5));
        let omni = importance(&at, &node(b, LightCone::SPHERE, 3.0));
        assert!(omni > 0.0);
        for p in [Vec3::NAN, Vec3::new(f32::INFINITY, 0.0, 0.0)] {
            let bad = ShadingContext::at(p);
            assert_eq!(importance(&bad, &node(b, LightCone::SPHERE, 3.0)), 0.0);
            assert_eq!(importance(&bad, &point(Vec3::ZERO, 3.0)), 0.0);
        }
        let cone = |axis: Vec3| LightCone {
            axis,
            cos_theta_o: 0.99,
            cos_theta_e: 0.0,
        };
        for axis in [Vec3::ZERO, Vec3::new(f32::INFINITY, 0.0, 0.0)] {
            assert_eq!(importance(&at, &node(b, cone(axis), 3.0)), omni);
        }
        // An axis the point lies outside the normal cone of.
        let axis = Vec3::new(1.0, -1.0, 0.0).normalize();
        let unit = importance(&at, &node(b, cone(axis), 3.0));
        let long = importance(&at, &node(b, cone(3.0 * axis), 3.0));
        assert!(unit > 0.0 && unit < omni, "{unit} {omni}");
        assert!((long - unit).abs() <= 1e-6 * unit, "{long} {unit}");
        let with = |n: Option<Vec3>| {
            let ctx = ShadingContext {
                position: at.position,
                normal: n,
                ..ShadingContext::at(Vec3::ZERO)
            };
            importance(&ctx, &node(b, LightCone::SPHERE, 3.0))
        };
        let tilted = Vec3::new(1.0, 0.2, 0.0);
        assert_eq!(with(Some(Vec3::ZERO)), with(None));
        let (n1, n2) = (with(Some(tilted.normalize())), with(Some(2.0 * tilted)));
        assert!(n1 < omni && (n1 - n2).abs() <= 1e-6 * n1, "{n1} {n2}");
    }

    #[test]
    fn point_light_is_inverse_square() {
        let ctx = ShadingContext::at(Vec3::ZERO);
        let a = importance(&ctx, &point(Vec3::new(2.0, 0.0, 0.0), 8.0));
        assert!((a - 2.0).abs() < 1e-6, "{a}");
        let b = importance(&ctx, &point(Vec3::new(0.0, 0.0, 4.0), 8.0));
        assert!((b - 0.5).abs() < 1e-6, "{b}");
    }

    #[test]
    fn distance_clamp_is_scale_invariant() {
        // The same configuration at two scales: importance scales by 1/s^2,
        // both when inside the box and outside it.
        for p in [Vec3::new(0.1, 0.2, 0.0), Vec3::new(3.0, 1.0, 2.0)] {
            let unit = Aabb::new(Vec3::splat(-1.0), Vec3::splat(1.0));
            let ctx = ShadingContext::at(p);
            let a = importance(&ctx, &node(unit, LightCone::SPHERE, 1.0));
            for s in [1e-3f32, 1e3] {
                let scaled = Aabb::new(unit.min * s, unit.max * s);
                let ctx = ShadingContext::at(p * s);
                let b = importance(&ctx, &node(scaled, LightCone::SPHERE, 1.0));
                let ratio = b * s * s / a;
                assert!((ratio - 1.0).abs() < 1e-4, "{p} {s}: {ratio}");
            }
        }
        // Inside: power / radius^2 with radius = |diagonal| / 2 = sqrt(3).
        let ctx = ShadingContext::at(Vec3::ZERO);
        let unit = Aabb::new(Vec3::splat(-1.0), Vec3::splat(1.0));
        let i = importance(&ctx, &node(unit, LightCone::SPHERE, 3.0));
        assert!((i - 1.0).abs() < 1e-6);
    }

    #[test]
    fn backfacing_emitter_is_zero_front_is_not() {
        let quad = Aabb::new(Vec3::new(-1.0, -1.0, 0.0), Vec3::new(1.0, 1.0, 0.0));
        let n = node(quad, LightCone::lambertian(Vec3::Z), 1.0);
        let front = ShadingContext::at(Vec3::new(0.0, 0.0, 5.0));
        let back = ShadingContext::at(Vec3::new(0.0, 0.0, -5.0));
        assert!(importance(&front, &n) > 0.0);
        assert_eq!(importance(&back, &n), 0.0);
        let two = NodeBounds {
            two_sided: true,
            ..n
        };
        assert_eq!(importance(&back, &two), importance(&front, &two));
    }

    #[test]
    fn wide_spot_reaches_behind_its_normal() {
        let spot = node(
            Aabb::from_point(Vec3::ZERO),
            LightCone::spot(Vec3::Z, 2.0),
            1.0,
        );
        // 100 degrees off the axis, inside the 2-radian (115 degree) spot.
        let a = 100f32.to_radians();
        let inside = ShadingContext::at(Vec3::new(a.sin(), 0.0, a.cos()));
        assert!(importance(&inside, &spot) > 0.0);
        let b = 130f32.to_radians();
        let outside = ShadingContext::at(Vec3::new(b.sin(), 0.0, b.cos()));
        assert_eq!(importance(&outside, &spot), 0.0);
    }

    #[test]
    fn normal_discounts_grazing_lights() {
        let light = point(Vec3::new(1.0, 0.0, 1.0), 1.0);
        let up = ShadingContext::on_surface(Vec3::ZERO, Vec3::Z);
        let none = ShadingContext::at(Vec3::ZERO);
        let ratio = importance(&up, &light) / importance(&none, &light);
        assert!((ratio - core::f32::consts::FRAC_1_SQRT_2).abs() < 1e-6);
        // |cos|: a light below the surface counts too (transmission).
        let below = point(Vec3::new(1.0, 0.0, -1.0), 1.0);
        assert_eq!(importance(&up, &below), importance(&up, &light));
    }

    #[test]
    fn never_nan_or_negative() {
        let bad = [
            ShadingContext::at(Vec3::ZERO),
            ShadingContext::at(Vec3::NAN),
            ShadingContext::at(Vec3::INFINITY),
            ShadingContext {
                position: Vec3::ONE,
                normal: Some(Vec3::ZERO),
                ..ShadingContext::at(Vec3::ZERO)
            },
            ShadingContext {
                position: Vec3::ONE,
                normal: Some(Vec3::NAN),
                ..ShadingContext::at(Vec3::ZERO)
            },
        ];
        let nodes = [
            point(Vec3::ZERO, 1.0),
            point(Vec3::ZERO, f32::MAX),
            point(Vec3::ZERO, f32::INFINITY),
            point(Vec3::ZERO, f32::NAN),
            point(Vec3::ZERO, -1.0),
            node(Aabb::EMPTY, LightCone::SPHERE, 1.0),
            node(
                Aabb::new(Vec3::splat(-f32::MAX), Vec3::splat(f32::MAX)),
                LightCone::SPHERE,
                1.0,
            ),
            node(
                Aabb::from_point(Vec3::X),
                LightCone {
                    axis: Vec3::NAN,
                    cos_theta_o: f32::NAN,
                    cos_theta_e: f32::NAN,
                },
                1.0,
            ),
        ];
        for c in &bad {
            for n in &nodes {
                let i = importance(c, n);
                assert!(i >= 0.0 && i.is_finite(), "{c:?} {n:?}: {i}");
            }
        }
        // On top of a point light: huge but finite, and proportional to power.
        let q = Query::new(&bad[0]);
        let a = q.importance(&point(Vec3::ZERO, 1.0));
        let b = q.importance(&point(Vec3::ZERO, 2.0));
        assert!(a.is_finite() && b == 2.0 * a);
    }
}
