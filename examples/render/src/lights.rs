//! The scene's emitters as the renderer sees them (shapes it can sample a
//! point on) and their description for the crate (`guiding::Emitter`).

use glam::{Vec2, Vec3};
use guiding::Emitter;
use guiding::math::Aabb;
use std::f32::consts::PI;

/// The kinds of emitter a scene can declare.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LightKind {
    /// One-sided parallelogram.
    Quad,
    /// One-sided triangle (mesh lights).
    Triangle,
    /// Sphere emitting outwards.
    Sphere,
}

/// An emitter's shape. Planar ones emit from the side their normal points
/// to.
#[derive(Clone, Copy, Debug)]
pub enum LightShape {
    /// `corner + s e1 + t e2`, `s, t` in `[0, 1]`; normal `e1 x e2`.
    Quad {
        /// Corner.
        corner: Vec3,
        /// First edge.
        e1: Vec3,
        /// Second edge.
        e2: Vec3,
    },
    /// `v0 + s e1 + t e2`, `s + t <= 1`; normal `e1 x e2`.
    Triangle {
        /// First vertex.
        v0: Vec3,
        /// Second vertex minus the first.
        e1: Vec3,
        /// Third vertex minus the first.
        e2: Vec3,
    },
    /// A sphere.
    Sphere {
        /// Centre.
        center: Vec3,
        /// Radius.
        radius: f32,
    },
}

/// A diffuse emitter with constant radiance.
#[derive(Clone, Copy, Debug)]
pub struct Light {
    /// Shape.
    pub shape: LightShape,
    /// Emitted radiance (linear RGB).
    pub radiance: Vec3,
}

/// A point sampled on a light, seen from a shading point.
#[derive(Clone, Copy, Debug)]
pub struct LightPoint {
    /// Unit direction from the shading point to the light point.
    pub wi: Vec3,
    /// Distance to the light point.
    pub dist: f32,
    /// Solid-angle pdf of `wi` (given that this light was chosen).
    pub pdf: f32,
    /// Radiance arriving along `wi` (0 from a planar light's back).
    pub radiance: Vec3,
}

impl Light {
    /// Its kind.
    pub fn kind(&self) -> LightKind {
        match self.shape {
            LightShape::Quad { .. } => LightKind::Quad,
            LightShape::Triangle { .. } => LightKind::Triangle,
            LightShape::Sphere { .. } => LightKind::Sphere,
        }
    }

    /// Surface area.
    pub fn area(&self) -> f32 {
        match self.shape {
            LightShape::Quad { e1, e2, .. } => e1.cross(e2).length(),
            LightShape::Triangle { e1, e2, .. } => 0.5 * e1.cross(e2).length(),
            LightShape::Sphere { radius, .. } => 4.0 * PI * radius * radius,
        }
    }

    /// What the crate needs to know: bounds, power (pi Le A for one-sided
    /// Lambertian planes, 4 pi^2 r^2 Le for spheres, with Le's luminance),
    /// area and emission cone.
    pub fn to_emitter(self) -> Emitter {
        let le = guiding::luminance(self.radiance).max(0.0);
        let power = PI * le * self.area();
        match self.shape {
            LightShape::Quad { corner, e1, e2 } => {
                let b = Aabb::new(corner, corner + e1 + e2)
                    .extend(corner + e1)
                    .extend(corner + e2);
                Emitter::area(b, e1.cross(e2), self.area(), power)
            }
            LightShape::Triangle { v0, e1, e2 } => {
                let b = Aabb::new(v0, v0 + e1).extend(v0 + e2);
                Emitter::area(b, e1.cross(e2), self.area(), power)
            }
            LightShape::Sphere { center, radius } => Emitter::sphere(center, radius, power),
        }
    }

    /// Samples a point of the light as seen from `x` with two uniform
    /// numbers. `None` when the light cannot be reached (behind a planar
    /// light, inside a sphere).
    #[inline]
    pub fn sample(&self, x: Vec3, u: Vec2) -> Option<LightPoint> {
        match self.shape {
            LightShape::Quad { corner, e1, e2 } => {
                self.sample_planar(x, corner + u.x * e1 + u.y * e2, e1.cross(e2))
            }
            LightShape::Triangle { v0, e1, e2 } => {
                let su = u.x.sqrt();
                let (b1, b2) = (1.0 - su, u.y * su);
                self.sample_planar(x, v0 + b1 * e1 + b2 * e2, e1.cross(e2))
            }
            LightShape::Sphere { center, radius } => {
                let to_c = center - x;
                let d2 = to_c.length_squared();
                let r2 = radius * radius;
                if d2 <= r2 {
                    return None;
                }
                let d = d2.sqrt();
                let sin2_max = r2 / d2;
                let cos_max = (1.0 - sin2_max).max(0.0).sqrt();
                let one_minus = one_minus_cos(sin2_max);
                // Uniform in the cone of directions the sphere subtends.
                let uo = u.x * one_minus;
                let cos_t = 1.0 - uo;
                let sin_t = (uo * (2.0 - uo)).max(0.0).sqrt();
                let phi = 2.0 * PI * u.y;
                let frame = crate::geometry::Frame::new(to_c / d);
                let wi = frame
                    .to_world(Vec3::new(sin_t * phi.cos(), sin_t * phi.sin(), cos_t))
                    .normalize();
                let (t0, _) = crate::geometry::sphere_hits(x, wi, center, radius);
                // At the cone's rim rounding can miss: take the tangent point.
                let dist = if t0.is_finite() && t0 > 0.0 {
                    t0
                } else {
                    d * cos_max
                };
                Some(LightPoint {
                    wi,
                    dist,
                    pdf: 1.0 / (2.0 * PI * one_minus),
                    radiance: self.radiance,
                })
            }
        }
    }

    fn sample_planar(&self, x: Vec3, y: Vec3, cross: Vec3) -> Option<LightPoint> {
        let area = self.area();
        let n = cross.normalize_or_zero();
        let v = y - x;
        let d2 = v.length_squared();
        if d2 <= 0.0 {
            return None;
        }
        let dist = d2.sqrt();
        let wi = v / dist;
        let cos_l = -n.dot(wi);
        if cos_l <= 0.0 {
            return None;
        }
        Some(LightPoint {
            wi,
            dist,
            pdf: d2 / (cos_l * area),
            radiance: self.radiance,
        })
    }

    /// Solid-angle pdf with which [`Light::sample`] from `x` gives the point
    /// `y` (normal `n_y`) that a ray along `wi` hit at distance `dist`.
    #[inline]
    pub fn pdf(&self, x: Vec3, wi: Vec3, dist: f32, n_y: Vec3) -> f32 {
        match self.shape {
            LightShape::Quad { .. } | LightShape::Triangle { .. } => {
                let cos_l = -n_y.dot(wi);
                if cos_l <= 0.0 {
                    0.0
                } else {
                    dist * dist / (cos_l * self.area())
                }
            }
            LightShape::Sphere { center, radius } => {
                let d2 = (center - x).length_squared();
                let r2 = radius * radius;
                if d2 <= r2 {
                    return 0.0;
                }
                1.0 / (2.0 * PI * one_minus_cos(r2 / d2))
            }
        }
    }

    /// Radiance leaving the light's surface (normal `n_y`) towards `-wi`.
    #[inline]
    pub fn emitted(&self, wi: Vec3, n_y: Vec3) -> Vec3 {
        match self.shape {
            LightShape::Sphere { .. } => self.radiance,
            _ if n_y.dot(wi) < 0.0 => self.radiance,
            _ => Vec3::ZERO,
        }
    }
}

/// `1 - cos(theta_max)` from `sin^2(theta_max)`, accurate for tiny cones.
#[inline]
fn one_minus_cos(sin2: f32) -> f32 {
    if sin2 < 1e-3 {
        // 1 - sqrt(1 - s) = s/2 + s^2/8 + ...
        0.5 * sin2 + 0.125 * sin2 * sin2
    } else {
        1.0 - (1.0 - sin2).max(0.0).sqrt()
    }
}

/// A constant environment light, sampled cosine-weighted around the shading
/// normal for next-event estimation.
#[derive(Clone, Copy, Debug)]
pub struct Environment {
    /// Radiance arriving from every direction.
    pub radiance: Vec3,
}

impl Environment {
    /// A direction from the hemisphere around `n` and its pdf.
    #[inline]
    pub fn sample(&self, n: Vec3, u: Vec2) -> Option<LightPoint> {
        let local = crate::materials::cosine_hemisphere(u);
        if local.z <= 0.0 {
            return None;
        }
        Some(LightPoint {
            wi: crate::geometry::Frame::new(n).to_world(local),
            dist: f32::INFINITY,
            pdf: local.z / PI,
            radiance: self.radiance,
        })
    }

    /// The pdf of [`Environment::sample`] for `wi` at a point with normal
    /// `n`.
    #[inline]
    pub fn pdf(&self, n: Vec3, wi: Vec3) -> f32 {
        n.dot(wi).max(0.0) / PI
    }
}

/// A sun: a distant light of irradiance `radiance` (on a surface facing
/// it) arriving from the fixed direction `direction`. A delta light: BSDF
/// sampling never finds it, so only light sampling can, and a light
/// sampler that never chose it would be biased.
#[derive(Clone, Copy, Debug)]
pub struct Sun {
    /// Unit direction from the scene towards the sun.
    pub direction: Vec3,
    /// Irradiance on a surface facing the sun.
    pub radiance: Vec3,
}

/// A light without position, outside the light tree: the crate's
/// `LightId::Unbounded(i)` is the scene's `unbounded[i]`.
#[derive(Clone, Copy, Debug)]
pub enum Unbounded {
    /// A constant environment light (a sky).
    Sky(Environment),
    /// A distant light (a sun).
    Sun(Sun),
}

impl Unbounded {
    /// A light sample towards it from a point with normal `n`. For the
    /// sun, `pdf` is 1 (a delta: no BSDF sample competes with it).
    #[inline]
    pub fn sample(&self, n: Vec3, u: Vec2) -> Option<LightPoint> {
        match self {
            Self::Sky(sky) => sky.sample(n, u),
            Self::Sun(sun) => Some(LightPoint {
                wi: sun.direction,
                dist: f32::INFINITY,
                pdf: 1.0,
                radiance: sun.radiance,
            }),
        }
    }

    /// Whether it is a delta light (BSDF sampling never hits it).
    #[inline]
    pub fn is_delta(&self) -> bool {
        matches!(self, Self::Sun(_))
    }
}
