//! The one scalar the crate learns from and weighs lights by.

use glam::Vec3;

/// The luminance of linear Rec. 709 RGB (`0.2126 r + 0.7152 g + 0.0722 b`):
/// the scalar [`DirectLight::estimate`](crate::DirectLight::estimate)
/// records and [`PathRecorder`](crate::PathRecorder) delivers radiance as.
/// A renderer that records on its own (a BSDF-sampled emitter hit) or gives
/// a light's power from RGB uses the same weighting, so that what is
/// learned and what is sampled agree.
///
/// ```
/// use guiding::{glam::Vec3, luminance};
/// assert_eq!(luminance(Vec3::ONE), 1.0);
/// assert_eq!(luminance(Vec3::new(0.0, 2.0, 0.0)), 1.4304);
/// ```
#[inline]
pub fn luminance(c: Vec3) -> f32 {
    0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z
}
