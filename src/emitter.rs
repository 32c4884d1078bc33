//! How a renderer describes its lights to the crate.

use crate::math::{Aabb, LightCone};
use glam::Vec3;

/// The lights of a scene as the crate sees them: the renderer implements this
/// for its own light list (or uses `[Emitter]`).
///
/// Emitters are identified by their index `0..len()`. Unbounded lights
/// (distant and infinite) are not emitters: the samplers handle them beside
/// the tree ([`crate::UnboundedLights`]).
pub trait Emitters {
    /// How many emitters.
    fn len(&self) -> usize;

    /// True when there are none.
    fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// World-space bounds of emitter `i` (a point light is a point box).
    fn bounds(&self, i: usize) -> Aabb;

    /// Emitted power (flux) of emitter `i`, in any consistent unit. Must be
    /// finite and non-negative.
    fn power(&self, i: usize) -> f32;

    /// Surface area of emitter `i` (0 for point and directional lights).
    fn area(&self, i: usize) -> f32;

    /// Directions emitter `i` emits into; `None` for omnidirectional lights.
    fn cone(&self, i: usize) -> Option<LightCone>;

    /// Whether emitter `i` emits from both sides of its surface.
    fn two_sided(&self, _i: usize) -> bool {
        false
    }

    /// Whether emitter `i` is a delta light (point or spot): it cannot be hit
    /// by BSDF sampling, so only light sampling reaches it.
    fn is_delta(&self, _i: usize) -> bool {
        false
    }

    /// The renderer's multiplier on how often emitter `i` is chosen (a light
    /// the artist knows matters, or one to sample less): every sampler
    /// chooses by power times weight where it chooses by power (the power
    /// sampler, the light tree's samplers, the GLT's prior and its choice
    /// below the cut), and in proportion to the weight where it ignores
    /// power (the uniform sampler). Estimates stay unbiased: the pmfs say
    /// exactly what was done, and the renderer divides by them. What a GLT
    /// learns from records is not weighted (records say what arrives). 1 by
    /// default; must be finite and non-negative. A weight of 0 means the
    /// light is never chosen: only BSDF sampling can then find it, so give
    /// it only to lights BSDF sampling can hit, or that may be left out.
    fn weight(&self, _i: usize) -> f32 {
        1.0
    }

    /// The light sets emitter `i` belongs to, one bit per set (up to 64;
    /// light linking): a shading point that receives only some sets
    /// ([`ShadingContext::receives`](crate::ShadingContext)) is lit only by
    /// the emitters of those sets. Every set by default (`u64::MAX`); 0
    /// lights no point that receives a set.
    fn light_sets(&self, _i: usize) -> u64 {
        u64::MAX
    }
}

/// A plain description of one emitter, for renderers that would rather hand
/// over a list than implement [`Emitters`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Emitter {
    /// World-space bounds.
    pub bounds: Aabb,
    /// Emitted power (flux).
    pub power: f32,
    /// Surface area.
    pub area: f32,
    /// Emission directions; `None` for omnidirectional.
    pub cone: Option<LightCone>,
    /// Emits from both sides.
    pub two_sided: bool,
    /// Point or spot light.
    pub delta: bool,
    /// The multiplier on how often it is chosen ([`Emitters::weight`]); 1
    /// from every constructor.
    pub weight: f32,
    /// The light sets it belongs to ([`Emitters::light_sets`]); every set
    /// from every constructor.
    pub light_sets: u64,
}

impl Emitter {
    /// An isotropic point light.
    pub fn point(position: Vec3, power: f32) -> Self {
        Self {
            bounds: Aabb::from_point(position),
            power,
            area: 0.0,
            cone: None,
            two_sided: false,
            delta: true,
            weight: 1.0,
            light_sets: u64::MAX,
        }
    }

    /// A one-sided Lambertian planar emitter with the given bounds, normal
    /// and area; prefer [`Emitter::triangle`], [`Emitter::quad`] or
    /// [`Emitter::disk`], which compute them. A zero or non-finite `normal`
    /// gives an omnidirectional emitter (a conservative bound: it is never
    /// discounted by orientation).
    pub fn area(bounds: Aabb, normal: Vec3, area: f32, power: f32) -> Self {
        Self {
            bounds,
            power,
            area,
            cone: Some(LightCone::lambertian(normal)),
            two_sided: false,
            delta: false,
            weight: 1.0,
            light_sets: u64::MAX,
        }
    }

    /// A Lambertian triangle emitting on the side of
    /// `(p1 - p0) x (p2 - p0)` (both sides when `two_sided`). A degenerate
    /// triangle (zero area) is omnidirectional with area 0.
    pub fn triangle(p: [Vec3; 3], power: f32, two_sided: bool) -> Self {
        let n = (p[1] - p[0]).cross(p[2] - p[0]);
        let bounds = Aabb::new(p[0], p[1]).union(&Aabb::from_point(p[2]));
        Self {
            two_sided,
            ..Self::area(bounds, n, 0.5 * n.length(), power)
        }
    }

    /// A Lambertian parallelogram `corner + s edge_u + t edge_v`
    /// (`s, t` in `[0, 1]`), emitting on the side of `edge_u x edge_v`
    /// (both sides when `two_sided`).
    pub fn quad(corner: Vec3, edge_u: Vec3, edge_v: Vec3, power: f32, two_sided: bool) -> Self {
        let n = edge_u.cross(edge_v);
        let bounds = Aabb::new(corner, corner + edge_u + edge_v)
            .union(&Aabb::new(corner + edge_u, corner + edge_v));
        Self {
            two_sided,
            ..Self::area(bounds, n, n.length(), power)
        }
    }

    /// A Lambertian disk of `radius` around `center`, emitting on the side
    /// of `normal` (both sides when `two_sided`). Its box is the disk's own
    /// (`radius * sqrt(1 - n_i^2)` along axis `i`), not the sphere's.
    pub fn disk(center: Vec3, normal: Vec3, radius: f32, power: f32, two_sided: bool) -> Self {
        let n = normal.try_normalize().unwrap_or(Vec3::ZERO);
        let half = if n == Vec3::ZERO {
            Vec3::splat(radius)
        } else {
            (Vec3::ONE - n * n)
                .max(Vec3::ZERO)
                .map(crate::math::scalar::sqrt)
                * radius
        };
        Self {
            two_sided,
            ..Self::area(
                Aabb::new(center - half, center + half),
                n,
                core::f32::consts::PI * radius * radius,
                power,
            )
        }
    }

    /// A spot light at `position` shining along `direction`, at full
    /// intensity within the angle whose cosine is `cos_falloff_start` and
    /// dark beyond `cos_falloff_end` (pbrt's spot light). Its cone is
    /// pbrt-v4's: the normal cone spans the full-intensity angle and the
    /// emission falloff the rest.
    pub fn spot(
        position: Vec3,
        direction: Vec3,
        cos_falloff_start: f32,
        cos_falloff_end: f32,
        power: f32,
    ) -> Self {
        let start = crate::math::scalar::acos(cos_falloff_start.clamp(-1.0, 1.0));
        let end = crate::math::scalar::acos(cos_falloff_end.clamp(-1.0, 1.0)).max(start);
        Self {
            cone: Some(LightCone::new(direction, start, end - start)),
            ..Self::point(position, power)
        }
    }

    /// pbrt-v4's `LightBounds` one-to-one: `bounds`, the normal-cone axis
    /// `w`, the power `phi`, `cos_theta_o`, `cos_theta_e` and `two_sided`.
    /// `area` and `delta` are what the renderer's light is (they only
    /// matter to the renderer's own bookkeeping and to
    /// [`Emitters::is_delta`]).
    #[allow(clippy::too_many_arguments)]
    pub fn from_light_bounds(
        bounds: Aabb,
        w: Vec3,
        phi: f32,
        cos_theta_o: f32,
        cos_theta_e: f32,
        two_sided: bool,
        area: f32,
        delta: bool,
    ) -> Self {
        let angle = |c: f32| crate::math::scalar::acos(c.clamp(-1.0, 1.0));
        Self {
            bounds,
            power: phi,
            area,
            cone: Some(LightCone::new(w, angle(cos_theta_o), angle(cos_theta_e))),
            two_sided,
            delta,
            weight: 1.0,
            light_sets: u64::MAX,
        }
    }

    /// A spherical emitter: emits in every direction from its surface.
    pub fn sphere(center: Vec3, radius: f32, power: f32) -> Self {
        Self {
            bounds: Aabb::new(center - Vec3::splat(radius), center + Vec3::splat(radius)),
            power,
            area: 4.0 * core::f32::consts::PI * radius * radius,
            cone: None,
            two_sided: false,
            delta: false,
            weight: 1.0,
            light_sets: u64::MAX,
        }
    }

    /// This emitter chosen `weight` times as often relative to the others
    /// ([`Emitters::weight`]).
    pub fn with_weight(self, weight: f32) -> Self {
        Self { weight, ..self }
    }

    /// This emitter in the light sets of `mask` only
    /// ([`Emitters::light_sets`]).
    pub fn in_light_sets(self, mask: u64) -> Self {
        Self {
            light_sets: mask,
            ..self
        }
    }
}

/// Implements [`Emitters`] for a container that derefs to `[Emitter]`.
macro_rules! emitters_for_list {
    ($($t:ty),*) => {$(
        impl Emitters for $t {
            fn len(&self) -> usize {
                <[Emitter]>::len(self)
            }
            fn bounds(&self, i: usize) -> Aabb {
                self[i].bounds
            }
            fn power(&self, i: usize) -> f32 {
                self[i].power
            }
            fn area(&self, i: usize) -> f32 {
                self[i].area
            }
            fn cone(&self, i: usize) -> Option<LightCone> {
                self[i].cone
            }
            fn two_sided(&self, i: usize) -> bool {
                self[i].two_sided
            }
            fn is_delta(&self, i: usize) -> bool {
                self[i].delta
            }
            fn weight(&self, i: usize) -> f32 {
                self[i].weight
            }
            fn light_sets(&self, i: usize) -> u64 {
                self[i].light_sets
            }
        }
    )*};
}

emitters_for_list!([Emitter], alloc::vec::Vec<Emitter>);
