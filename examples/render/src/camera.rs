//! A pinhole camera.

use glam::Vec3;

/// A pinhole camera looking from `eye` to `target`.
#[derive(Clone, Copy, Debug)]
pub struct Camera {
    /// Position.
    pub eye: Vec3,
    right: Vec3,
    up: Vec3,
    forward: Vec3,
    tan_half: f32,
}

impl Camera {
    /// A camera with a vertical field of view of `vfov_deg` degrees.
    pub fn look_at(eye: Vec3, target: Vec3, vfov_deg: f32) -> Self {
        let forward = (target - eye).normalize();
        let right = forward.cross(Vec3::Y).normalize();
        let up = right.cross(forward);
        Self {
            eye,
            right,
            up,
            forward,
            tan_half: (0.5 * vfov_deg.to_radians()).tan(),
        }
    }

    /// The unit direction through image position `(x, y)` (pixels, y down)
    /// of a `width` x `height` image.
    #[inline]
    pub fn direction(&self, x: f32, y: f32, width: u32, height: u32) -> Vec3 {
        let aspect = width as f32 / height as f32;
        let sx = (2.0 * x / width as f32 - 1.0) * self.tan_half * aspect;
        let sy = (1.0 - 2.0 * y / height as f32) * self.tan_half;
        (self.forward + sx * self.right + sy * self.up).normalize()
    }
}
