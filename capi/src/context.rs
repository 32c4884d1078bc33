//! The plain C structs of a query: the shading point, a light sample, a
//! record's outcome.

use crate::status::{Failure, finite3};
use guiding::glam::Vec3;
use guiding::{RecordOutcome, ShadingContext};

/// `GuidingShadingContext::light_sets` and `unbounded_lights` for a point
/// lit by every light (no light linking).
pub const GUIDING_ALL_LIGHTS: u64 = u64::MAX;

/// `GuidingLightSample::light` when nothing can be sampled (its pmf is 0).
pub const GUIDING_NO_LIGHT: u32 = u32::MAX;

/// The shading point a light is chosen for (the Rust `ShadingContext`).
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct GuidingShadingContext {
    /// World-space position; must be finite.
    pub position: [f32; 3],
    /// The shading normal (normalised by the crate), or all zeros for none
    /// (in a medium, or unknown). Must be finite.
    pub normal: [f32; 3],
    /// The light sets the point is lit by, one bit per set (light
    /// linking); `GUIDING_ALL_LIGHTS` for every set.
    pub light_sets: u64,
    /// The unbounded lights the point is lit by, one bit per light;
    /// `GUIDING_ALL_LIGHTS` for every one.
    pub unbounded_lights: u64,
}

impl GuidingShadingContext {
    /// The Rust context, or a failure for a non-finite position or normal.
    pub(crate) fn to_rust(self) -> Result<ShadingContext, Failure> {
        let p = finite3(self.position, "context.position")?;
        let n = finite3(self.normal, "context.normal")?;
        let ctx = if n == Vec3::ZERO {
            ShadingContext::at(p)
        } else {
            ShadingContext::on_surface(p, n)
        };
        Ok(ctx
            .lit_by(self.light_sets)
            .lit_by_unbounded(self.unbounded_lights))
    }
}

/// A chosen light and the probability it was chosen with (exactly what
/// the matching `_pmf` call returns for it).
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GuidingLightSample {
    /// The light's index: the emitters in the order they were added, then
    /// the unbounded lights; `GUIDING_NO_LIGHT` when nothing can be
    /// sampled here.
    pub light: u32,
    /// Its probability; 0 with `GUIDING_NO_LIGHT`.
    pub pmf: f32,
}

/// What a record did (the Rust `RecordOutcome`).
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum GuidingRecordOutcome {
    /// Added to what is learned.
    Recorded = 0,
    /// A zero value: a valid observation that adds nothing to the sums.
    Zero = 1,
    /// Bad input, ignored and counted in the guide's dropped records.
    Dropped = 2,
    /// The record's kind is switched off in the configuration (checked,
    /// not counted).
    Ignored = 3,
}

impl From<RecordOutcome> for GuidingRecordOutcome {
    fn from(o: RecordOutcome) -> Self {
        match o {
            RecordOutcome::Recorded => Self::Recorded,
            RecordOutcome::Zero => Self::Zero,
            RecordOutcome::Dropped => Self::Dropped,
            _ => Self::Ignored,
        }
    }
}

/// `u` in `[0, 1)`, or an invalid-argument failure.
pub(crate) fn unit(u: f32, name: &str) -> Result<f32, Failure> {
    if (0.0..1.0).contains(&u) {
        Ok(u)
    } else {
        Err(Failure::invalid(format!("{name} = {u} is not in [0, 1)")))
    }
}
