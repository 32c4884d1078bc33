//! The cube a spatial tree starts from, and the error for bounds it cannot
//! start from.

use crate::math::Aabb;
use glam::Vec3;

/// Why a spatial tree could not be built.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub enum SpatialError {
    /// The scene bounds are empty (`min > max` on some axis).
    EmptyBounds,
    /// The scene bounds, or the cube around them, are not finite.
    NonFiniteBounds,
}

impl core::fmt::Display for SpatialError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            Self::EmptyBounds => f.write_str("scene bounds are empty"),
            Self::NonFiniteBounds => f.write_str("scene bounds are not finite"),
        }
    }
}

#[cfg(feature = "std")]
impl std::error::Error for SpatialError {}

/// Relative padding around the scene so points on its boundary are inside.
const PAD: f32 = 1.0 / 1024.0;

/// The cube a spatial tree covers for scene bounds `scene`: centred on the
/// scene, with side `longest extent * (1 + 2^-10)`. Flat, line-like and
/// point scenes get a non-zero cube: when the longest extent is 0 the side is
/// `2^-10 * max(1, largest |centre coordinate|)`, so every axis can be split.
pub fn root_cube(scene: &Aabb) -> Result<Aabb, SpatialError> {
    if !(scene.min.is_finite() && scene.max.is_finite()) {
        return if scene.is_empty() && *scene == Aabb::EMPTY {
            Err(SpatialError::EmptyBounds)
        } else {
            Err(SpatialError::NonFiniteBounds)
        };
    }
    if scene.is_empty() {
        return Err(SpatialError::EmptyBounds);
    }
    // Halves first, so huge opposite-signed corners do not overflow.
    let center = scene.min * 0.5 + scene.max * 0.5;
    let extent = (scene.max - scene.min).max_element();
    let side = if extent > 0.0 {
        extent * (1.0 + PAD)
    } else {
        PAD * center.abs().max_element().max(1.0)
    };
    let half = Vec3::splat(side * 0.5);
    let cube = Aabb {
        min: center - half,
        max: center + half,
    };
    // The cube must be finite, hold the scene and be splittable on every
    // axis (guaranteed unless the scene lies near f32::MAX).
    if !cube.is_finite() || !cube.min.cmplt(cube.max).all() {
        return Err(SpatialError::NonFiniteBounds);
    }
    let cube = cube.union(scene);
    Ok(cube)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cube_holds_scene_and_is_cubic() {
        let s = Aabb::new(Vec3::new(-1.0, 0.0, 2.0), Vec3::new(3.0, 1.0, 2.5));
        let c = root_cube(&s).unwrap();
        assert_eq!(c.union(&s), c);
        let d = c.diagonal();
        assert!((d.x - d.y).abs() < 1e-5 && (d.y - d.z).abs() < 1e-5);
        assert!(d.x > 4.0);
    }

    #[test]
    fn degenerate_scenes_get_a_real_cube() {
        for s in [
            Aabb::from_point(Vec3::ZERO),
            Aabb::from_point(Vec3::splat(1.0e6)),
            Aabb::new(Vec3::ZERO, Vec3::new(1.0, 0.0, 0.0)),
        ] {
            let c = root_cube(&s).unwrap();
            assert!(c.min.cmplt(c.max).all(), "{c:?}");
            assert!(c.contains(s.min) && c.contains(s.max));
        }
    }

    #[test]
    fn bad_bounds_are_errors() {
        assert_eq!(root_cube(&Aabb::EMPTY), Err(SpatialError::EmptyBounds));
        let nan = Aabb {
            min: Vec3::new(0.0, f32::NAN, 0.0),
            max: Vec3::ONE,
        };
        assert_eq!(root_cube(&nan), Err(SpatialError::NonFiniteBounds));
        let inf = Aabb::new(Vec3::ZERO, Vec3::splat(f32::INFINITY));
        assert_eq!(root_cube(&inf), Err(SpatialError::NonFiniteBounds));
        let huge = Aabb::new(Vec3::splat(-f32::MAX), Vec3::splat(f32::MAX));
        assert_eq!(root_cube(&huge), Err(SpatialError::NonFiniteBounds));
        let inverted = Aabb {
            min: Vec3::ONE,
            max: Vec3::ZERO,
        };
        assert_eq!(root_cube(&inverted), Err(SpatialError::EmptyBounds));
    }
}
