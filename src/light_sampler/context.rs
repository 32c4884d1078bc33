//! [`ShadingContext`]: the shading point a light is chosen for, what every
//! light sampler's query takes.

use glam::Vec3;

/// The shading point a light is chosen for.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ShadingContext {
    /// World-space position.
    pub position: Vec3,
    /// Unit surface normal, `None` in media or when unknown: the shading
    /// normal, the one in the cosine of the renderer's estimator.
    /// Importance-based samplers discount a light by a conservative bound
    /// on `|cos|` to it, so its sign does not matter (a light behind the
    /// surface counts as one in front: transmission), and a light gets
    /// nothing from it only when all of it lies exactly in the tangent
    /// plane, where that cosine is 0 (see `crate::light_sampler::importance`).
    pub normal: Option<Vec3>,
    /// The light sets the point is lit by, one bit per set (light
    /// linking): only emitters in one of them
    /// ([`Emitters::light_sets`](crate::Emitters::light_sets)) are chosen
    /// here, every sampler's pmf exactly normalised over them. Every set
    /// (`u64::MAX`) from every constructor; see
    /// [`ShadingContext::lit_by`].
    pub receives: u64,
    /// The unbounded lights the point is lit by, one bit per light (bit
    /// `i`: [`LightId::Unbounded`](crate::LightId::Unbounded)`(i)`; those
    /// from 64 on always light it): the renderer resolves its few
    /// unbounded lights' links per object, the crate those of its many
    /// emitters. Every one (`u64::MAX`) from every constructor; see
    /// [`ShadingContext::lit_by_unbounded`].
    pub receives_unbounded: u64,
}

impl ShadingContext {
    /// A context at `position` with no normal.
    pub fn at(position: Vec3) -> Self {
        Self {
            position,
            normal: None,
            receives: u64::MAX,
            receives_unbounded: u64::MAX,
        }
    }

    /// A context on a surface with `normal` (see
    /// [`ShadingContext::normal`]; normalised here, a zero or non-finite
    /// one counts as none).
    pub fn on_surface(position: Vec3, normal: Vec3) -> Self {
        Self {
            position,
            normal: normal.try_normalize(),
            receives: u64::MAX,
            receives_unbounded: u64::MAX,
        }
    }

    /// This context lit only by the emitters of the light sets in `sets`
    /// (an object's light linking).
    ///
    /// ```
    /// use guiding::{glam::Vec3, Emitter, LightId, LightSampler, PowerSampler, ShadingContext};
    /// let lamps = [
    ///     Emitter::point(Vec3::ZERO, 1.0).in_light_sets(0b01),
    ///     Emitter::point(Vec3::X, 3.0).in_light_sets(0b10),
    /// ];
    /// let sampler = PowerSampler::new(&lamps[..]);
    /// let ctx = ShadingContext::at(Vec3::Y).lit_by(0b10);
    /// assert_eq!(sampler.pmf(&ctx, LightId::Emitter(0)), 0.0);
    /// assert_eq!(sampler.pmf(&ctx, LightId::Emitter(1)), 1.0);
    /// ```
    pub fn lit_by(self, sets: u64) -> Self {
        Self {
            receives: sets,
            ..self
        }
    }

    /// This context lit only by the unbounded lights in `lights` (bit `i`:
    /// [`LightId::Unbounded`](crate::LightId::Unbounded)`(i)`), its
    /// emitters unchanged: a sun linked away from an object.
    ///
    /// ```
    /// use guiding::{glam::Vec3, Aabb, Emitter, LightId, LightSampler, ShadingContext};
    /// use guiding::{Strategy, UnboundedLights};
    /// let lamp = [Emitter::point(Vec3::ZERO, 1.0)];
    /// let sun = UnboundedLights::new(1, 0.5)?;
    /// let scene = Aabb::new(Vec3::splat(-1.0), Vec3::splat(1.0));
    /// let sampler = Strategy::new("power", &lamp[..], sun, scene).unwrap();
    /// let indoors = ShadingContext::at(Vec3::Y).lit_by_unbounded(0);
    /// assert_eq!(sampler.pmf(&indoors, LightId::Unbounded(0)), 0.0);
    /// assert_eq!(sampler.pmf(&indoors, LightId::Emitter(0)), 1.0);
    /// # Ok::<(), guiding::ConfigError>(())
    /// ```
    pub fn lit_by_unbounded(self, lights: u64) -> Self {
        Self {
            receives_unbounded: lights,
            ..self
        }
    }

    /// Whether the light sets the point receives exclude some emitter of a
    /// hierarchy that `has_light_sets` (an emitter of one without is in
    /// every set, so only a point that receives none excludes it).
    #[inline]
    pub(crate) fn restricts(&self, has_light_sets: bool) -> bool {
        self.receives != u64::MAX && (has_light_sets || self.receives == 0)
    }

    /// Whether unbounded light `i` may light the point.
    #[inline]
    pub(crate) fn is_lit_by_unbounded(&self, i: u32) -> bool {
        i >= 64 || self.receives_unbounded & (1 << i) != 0
    }

    /// How many of unbounded lights `0..count` may light the point.
    #[inline]
    pub(crate) fn unbounded_received(&self, count: u32) -> u32 {
        let below = count.min(64);
        let mask = if below == 64 {
            u64::MAX
        } else {
            (1u64 << below) - 1
        };
        (self.receives_unbounded & mask).count_ones() + (count - below)
    }

    /// A context on a surface whose `normal` is flipped, if needed, to the
    /// side of the outgoing direction `wo` (towards the viewer). The
    /// crate's samplers do not need it (they use `|cos|`); a custom
    /// [`LightHierarchy`](crate::LightHierarchy) whose importance is
    /// one-sided would.
    ///
    /// ```
    /// use guiding::{glam::Vec3, ShadingContext};
    /// // A floor whose mesh normal points down, seen from above.
    /// let ctx = ShadingContext::facing(Vec3::ZERO, -Vec3::Y, Vec3::new(0.0, 1.0, 1.0));
    /// assert_eq!(ctx.normal, Some(Vec3::Y));
    /// ```
    pub fn facing(position: Vec3, normal: Vec3, wo: Vec3) -> Self {
        let n = if normal.dot(wo) < 0.0 {
            -normal
        } else {
            normal
        };
        Self::on_surface(position, n)
    }

    /// Whether the position is finite. Every [`LightSampler`] chooses
    /// nothing at a non-finite position: `sample` is `None` and every
    /// `pmf` is 0. (A zero or non-finite normal counts as no normal.)
    ///
    /// [`LightSampler`]: crate::LightSampler
    #[inline]
    pub fn is_finite(&self) -> bool {
        self.position.is_finite()
    }
}
