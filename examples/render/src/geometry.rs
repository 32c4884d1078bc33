//! Ray-traceable primitives (triangles and spheres) and their
//! intersection routines.

use glam::{Vec3, Vec3A};
use obvhs::Boundable;
use obvhs::aabb::Aabb as BvhAabb;

/// Marks a primitive that belongs to no emitter.
pub const NO_EMITTER: u32 = u32::MAX;

/// The shape of a primitive.
#[derive(Clone, Copy, Debug)]
pub enum Shape {
    /// A triangle `v0, v0 + e1, v0 + e2`; its geometric normal is
    /// `normalize(e1 x e2)`.
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

/// A shape with its material and, for emissive shapes, its emitter.
#[derive(Clone, Copy, Debug)]
pub struct Primitive {
    /// The geometry.
    pub shape: Shape,
    /// Index into the scene's materials.
    pub material: u32,
    /// Index into the scene's lights, or [`NO_EMITTER`].
    pub emitter: u32,
}

impl Primitive {
    /// A triangle from its three vertices.
    pub fn triangle(a: Vec3, b: Vec3, c: Vec3, material: u32, emitter: u32) -> Self {
        Self {
            shape: Shape::Triangle {
                v0: a,
                e1: b - a,
                e2: c - a,
            },
            material,
            emitter,
        }
    }

    /// A sphere.
    pub fn sphere(center: Vec3, radius: f32, material: u32, emitter: u32) -> Self {
        Self {
            shape: Shape::Sphere { center, radius },
            material,
            emitter,
        }
    }

    /// Distance along the ray (`dir` unit length) to the first intersection
    /// in `(tmin, tmax)`, or infinity.
    #[inline]
    pub fn intersect(&self, origin: Vec3, dir: Vec3, tmin: f32, tmax: f32) -> f32 {
        match self.shape {
            Shape::Triangle { v0, e1, e2 } => {
                // Möller-Trumbore.
                let p = dir.cross(e2);
                let det = e1.dot(p);
                if det.abs() < 1e-12 {
                    return f32::INFINITY;
                }
                let inv = 1.0 / det;
                let s = origin - v0;
                let u = s.dot(p) * inv;
                if !(0.0..=1.0).contains(&u) {
                    return f32::INFINITY;
                }
                let q = s.cross(e1);
                let v = dir.dot(q) * inv;
                if v < 0.0 || u + v > 1.0 {
                    return f32::INFINITY;
                }
                let t = e2.dot(q) * inv;
                if t > tmin && t < tmax {
                    t
                } else {
                    f32::INFINITY
                }
            }
            Shape::Sphere { center, radius } => {
                let (t0, t1) = sphere_hits(origin, dir, center, radius);
                if t0 > tmin && t0 < tmax {
                    t0
                } else if t1 > tmin && t1 < tmax {
                    t1
                } else {
                    f32::INFINITY
                }
            }
        }
    }

    /// The unit geometric normal at a point `p` on the primitive (outward for
    /// spheres, `e1 x e2` for triangles).
    #[inline]
    pub fn normal(&self, p: Vec3) -> Vec3 {
        match self.shape {
            Shape::Triangle { e1, e2, .. } => e1.cross(e2).normalize_or_zero(),
            Shape::Sphere { center, .. } => (p - center).normalize_or_zero(),
        }
    }

    /// Bounding box as `(min, max)`.
    pub fn bounds(&self) -> (Vec3, Vec3) {
        match self.shape {
            Shape::Triangle { v0, e1, e2 } => {
                let (a, b, c) = (v0, v0 + e1, v0 + e2);
                (a.min(b).min(c), a.max(b).max(c))
            }
            Shape::Sphere { center, radius } => {
                (center - Vec3::splat(radius), center + Vec3::splat(radius))
            }
        }
    }
}

impl Boundable for Primitive {
    fn aabb(&self) -> BvhAabb {
        let (lo, hi) = self.bounds();
        BvhAabb::new(Vec3A::from(lo), Vec3A::from(hi))
    }
}

/// Both ray parameters where a ray (`dir` unit) meets a sphere, near first;
/// infinities on a miss. Uses the numerically stable form of pbrt-v4 /
/// Ray Tracing Gems ch. 7, so tiny far spheres intersect reliably.
#[inline]
pub fn sphere_hits(origin: Vec3, dir: Vec3, center: Vec3, radius: f32) -> (f32, f32) {
    let f = origin - center;
    let b = -f.dot(dir);
    let perp = f + b * dir;
    let disc = radius * radius - perp.length_squared();
    if disc < 0.0 {
        return (f32::INFINITY, f32::INFINITY);
    }
    let c = f.length_squared() - radius * radius;
    let q = b + b.signum() * disc.sqrt();
    if q == 0.0 {
        return (0.0, 0.0);
    }
    let (t0, t1) = (c / q, q);
    if t0 < t1 { (t0, t1) } else { (t1, t0) }
}

/// A unit-length orthonormal frame around a normal (Duff et al. 2017).
#[derive(Clone, Copy, Debug)]
pub struct Frame {
    /// First tangent.
    pub s: Vec3,
    /// Second tangent.
    pub t: Vec3,
    /// The normal.
    pub n: Vec3,
}

impl Frame {
    /// The frame with `n` as its z axis.
    #[inline]
    pub fn new(n: Vec3) -> Self {
        let sign = 1.0f32.copysign(n.z);
        let a = -1.0 / (sign + n.z);
        let b = n.x * n.y * a;
        Self {
            s: Vec3::new(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x),
            t: Vec3::new(b, sign + n.y * n.y * a, -n.y),
            n,
        }
    }

    /// World to local.
    #[inline]
    pub fn to_local(self, v: Vec3) -> Vec3 {
        Vec3::new(v.dot(self.s), v.dot(self.t), v.dot(self.n))
    }

    /// Local to world.
    #[inline]
    pub fn to_world(self, v: Vec3) -> Vec3 {
        self.s * v.x + self.t * v.y + self.n * v.z
    }
}

/// Offsets a ray origin off a surface along its normal, towards `dir`, far
/// enough to escape the surface's own f32 rounding.
#[inline]
pub fn offset_origin(p: Vec3, n: Vec3, dir: Vec3) -> Vec3 {
    let eps = 1e-4 * (1.0 + p.abs().max_element());
    if n.dot(dir) >= 0.0 {
        p + n * eps
    } else {
        p - n * eps
    }
}
