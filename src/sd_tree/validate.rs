//! Checking the inputs of queries and splats.

use super::dropped::DropReason;
use glam::Vec3;

/// `dir` scaled to unit length; `None` when it has a NaN or infinite
/// component or is zero. Tiny and huge directions are rescaled before
/// normalising, so any finite non-zero vector works.
#[inline]
pub(super) fn unit_direction(dir: Vec3) -> Option<Vec3> {
    if !dir.is_finite() {
        return None;
    }
    let m = dir.abs().max_element();
    if m == 0.0 {
        return None;
    }
    let d = dir / m;
    Some(d / d.length())
}

/// The value a splat records, `radiance / pdf`, or why it is dropped.
#[inline]
pub(super) fn splat_value(radiance: f32, pdf: f32) -> Result<f32, DropReason> {
    if !(radiance >= 0.0 && radiance.is_finite()) {
        return Err(DropReason::Radiance);
    }
    if !(pdf > 0.0 && pdf.is_finite()) {
        return Err(DropReason::Pdf);
    }
    let v = radiance / pdf;
    if v.is_finite() {
        Ok(v)
    } else {
        Err(DropReason::Overflow)
    }
}
