//! Checking the inputs of queries and records.

use crate::dropped::DropReason;

/// The value a radiance record adds, `radiance / pdf`, or why it is dropped.
#[inline]
pub(super) fn record_value(radiance: f32, pdf: f32) -> Result<f32, DropReason> {
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
