//! Ray casting over the scene's primitives with obvhs' compressed wide BVH.

use crate::geometry::{NO_EMITTER, Primitive};
use glam::{Vec3, Vec3A};
use obvhs::BvhBuildParams;
use obvhs::cwbvh::CwBvh;
use obvhs::cwbvh::builder::build_cwbvh;
use obvhs::ray::{Ray, RayHit};
use std::time::Duration;

/// A closest hit.
#[derive(Clone, Copy, Debug)]
pub struct Hit {
    /// Distance along the (unit) ray direction.
    pub t: f32,
    /// The primitive, as an index into [`Bvh::primitives`].
    pub primitive: u32,
}

/// The primitives, reordered for the BVH's leaves, and the BVH.
pub struct Bvh {
    bvh: CwBvh,
    prims: Vec<Primitive>,
}

impl Bvh {
    /// Builds the BVH (obvhs' medium preset).
    pub fn build(prims: Vec<Primitive>) -> Self {
        let bvh = build_cwbvh(
            &prims,
            BvhBuildParams::medium_build(),
            &mut Duration::default(),
        );
        let ordered = bvh
            .primitive_indices
            .iter()
            .map(|&i| prims[i as usize])
            .collect();
        Self {
            bvh,
            prims: ordered,
        }
    }

    /// The primitives in BVH order.
    pub fn primitives(&self) -> &[Primitive] {
        &self.prims
    }

    /// The closest hit along `origin + t dir`, `t` in `(0, tmax)`.
    #[inline]
    pub fn intersect(&self, origin: Vec3, dir: Vec3, tmax: f32) -> Option<Hit> {
        let ray = Ray::new(Vec3A::from(origin), Vec3A::from(dir), 0.0, tmax);
        let mut hit = RayHit::none();
        let found = self.bvh.ray_traverse(ray, &mut hit, |r, id| {
            self.prims[id].intersect(r.origin.into(), r.direction.into(), r.tmin, r.tmax)
        });
        found.then_some(Hit {
            t: hit.t,
            primitive: hit.primitive_id,
        })
    }

    /// True when something other than emitter `skip`'s own primitives lies
    /// along `origin + t dir` for `t` in `(0, tmax)` (`skip` =
    /// [`NO_EMITTER`]: anything). Skipping the target
    /// light lets a shadow ray run all the way to the sampled point, so an
    /// occluder just in front of the light (another light, a lamp shade) is
    /// never missed.
    #[inline]
    pub fn occluded_except(&self, origin: Vec3, dir: Vec3, tmax: f32, skip: u32) -> bool {
        let ray = Ray::new(Vec3A::from(origin), Vec3A::from(dir), 0.0, tmax);
        !self.bvh.ray_traverse_miss(ray, |r, id| {
            let p = &self.prims[id];
            if p.emitter == skip && skip != NO_EMITTER {
                f32::INFINITY
            } else {
                p.intersect(r.origin.into(), r.direction.into(), r.tmin, r.tmax)
            }
        })
    }
}
