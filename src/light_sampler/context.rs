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
}

impl ShadingContext {
    /// A context at `position` with no normal.
    pub fn at(position: Vec3) -> Self {
        Self {
            position,
            normal: None,
            receives: u64::MAX,
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
        }
    }

    /// This context lit only by the emitters of the light sets in `mask`
    /// (an object's light linking).
    pub fn lit_by(self, mask: u64) -> Self {
        Self {
            receives: mask,
            ..self
        }
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
