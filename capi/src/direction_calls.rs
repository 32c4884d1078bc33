//! PPG's directional calls, shared by the SD-tree's and the field's
//! exports: sample a direction, its pdf, the BSDF fraction, the mixture
//! pdf, and the two records (radiance, fraction).

use crate::context::{GuidingRecordOutcome, GuidingShadingContext, unit};
use crate::handle::{DirectionGuide, Handle, Learned};
use crate::light_calls::write_outcome;
use crate::status::{Failure, get, put, slice, vec3};
use guiding::glam::Vec3;
use guiding::{DirectionVertex, RecordOutcome};

/// A direction the guide sampled and its solid-angle pdf.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct GuidingDirectionSample {
    /// The unit direction (world space).
    pub direction: [f32; 3],
    /// Its solid-angle pdf (exactly what the `_direction_pdf` call gives).
    pub pdf: f32,
}

/// Runs `f` on the direction vertex at `ctx`.
///
/// # Safety
/// `ctx` null or readable.
unsafe fn at<G: DirectionGuide + Learned, R>(
    h: &Handle<G>,
    ctx: *const GuidingShadingContext,
    f: impl FnOnce(DirectionVertex<'_>) -> Result<R, Failure>,
) -> Result<R, Failure> {
    // SAFETY: forwarded.
    let ctx = unsafe { get(ctx, "ctx") }?.to_rust()?;
    let guide = h.read()?;
    let v = guide
        .direction_vertex(&ctx)
        .ok_or_else(|| Failure::invalid("ctx.position is not finite"))?;
    f(v)
}

fn direction(d: *const f32) -> Result<Vec3, Failure> {
    // SAFETY: the exported caller promises 3 readable floats or null.
    let d = unsafe { vec3(d, "direction") }?;
    if d == Vec3::ZERO {
        return Err(Failure::invalid("direction is zero"));
    }
    Ok(d)
}

/// # Safety
/// `ctx` null or readable; `u` null or 2 floats; `out` null or writable.
pub(crate) unsafe fn sample_direction<G: DirectionGuide + Learned>(
    h: &Handle<G>,
    ctx: *const GuidingShadingContext,
    u: *const f32,
    out: *mut GuidingDirectionSample,
) -> Result<(), Failure> {
    // SAFETY: forwarded.
    let u = unsafe { slice(u, 2, "u") }?;
    let u = [unit(u[0], "u[0]")?, unit(u[1], "u[1]")?];
    if out.is_null() {
        return Err(Failure::null("out"));
    }
    // SAFETY: forwarded.
    let (d, pdf) = unsafe { at(h, ctx, |v| Ok(v.sample_direction(u))) }?;
    let s = GuidingDirectionSample {
        direction: d.to_array(),
        pdf,
    };
    // SAFETY: checked non-null, writable by the caller's promise.
    unsafe { put(out, s, "out") }
}

/// # Safety
/// `ctx` null or readable; `dir` null or 3 floats; `out` null or writable.
pub(crate) unsafe fn direction_pdf<G: DirectionGuide + Learned>(
    h: &Handle<G>,
    ctx: *const GuidingShadingContext,
    dir: *const f32,
    out: *mut f32,
) -> Result<(), Failure> {
    let d = direction(dir)?;
    if out.is_null() {
        return Err(Failure::null("out"));
    }
    // SAFETY: forwarded.
    let p = unsafe { at(h, ctx, |v| Ok(v.direction_pdf(d))) }?;
    // SAFETY: checked non-null, writable by the caller's promise.
    unsafe { put(out, p, "out") }
}

/// # Safety
/// `ctx` null or readable; `out` null or writable.
pub(crate) unsafe fn bsdf_fraction<G: DirectionGuide + Learned>(
    h: &Handle<G>,
    ctx: *const GuidingShadingContext,
    out: *mut f32,
) -> Result<(), Failure> {
    if out.is_null() {
        return Err(Failure::null("out"));
    }
    // SAFETY: forwarded.
    let a = unsafe { at(h, ctx, |v| Ok(v.bsdf_fraction())) }?;
    // SAFETY: checked non-null, writable by the caller's promise.
    unsafe { put(out, a, "out") }
}

/// # Safety
/// `ctx` null or readable; `dir` null or 3 floats; `out` null or writable.
pub(crate) unsafe fn mixture_pdf<G: DirectionGuide + Learned>(
    h: &Handle<G>,
    ctx: *const GuidingShadingContext,
    dir: *const f32,
    bsdf_pdf: f32,
    out: *mut f32,
) -> Result<(), Failure> {
    let d = direction(dir)?;
    if !(bsdf_pdf.is_finite() && bsdf_pdf >= 0.0) {
        return Err(Failure::invalid(format!(
            "bsdf_pdf = {bsdf_pdf}: must be finite and >= 0"
        )));
    }
    if out.is_null() {
        return Err(Failure::null("out"));
    }
    // SAFETY: forwarded.
    let p = unsafe { at(h, ctx, |v| Ok(v.mixture_pdf(d, bsdf_pdf))) }?;
    // SAFETY: checked non-null, writable by the caller's promise.
    unsafe { put(out, p, "out") }
}

fn refused(o: GuidingRecordOutcome, what: String) -> Result<(), Failure> {
    if o == GuidingRecordOutcome::Dropped {
        Err(Failure::invalid(what))
    } else {
        Ok(())
    }
}

/// # Safety
/// `ctx` null or readable; `dir` null or 3 floats; `outcome` null or writable.
pub(crate) unsafe fn record_radiance<G: DirectionGuide + Learned>(
    h: &Handle<G>,
    ctx: *const GuidingShadingContext,
    dir: *const f32,
    radiance: f32,
    pdf: f32,
    outcome: *mut GuidingRecordOutcome,
) -> Result<(), Failure> {
    let d = direction(dir)?;
    // SAFETY: forwarded.
    let o = unsafe {
        at(h, ctx, |v| {
            Ok(GuidingRecordOutcome::from(
                v.record_radiance(d, radiance, pdf),
            ))
        })
    }?;
    write_outcome(outcome, o)?;
    refused(
        o,
        format!(
            "record_radiance: radiance = {radiance}, pdf = {pdf} was dropped (radiance finite and >= 0, pdf finite and > 0)"
        ),
    )
}

/// # Safety
/// `ctx` null or readable; `outcome` null or writable.
pub(crate) unsafe fn record_fraction<G: DirectionGuide + Learned>(
    h: &Handle<G>,
    ctx: *const GuidingShadingContext,
    bsdf_pdf: f32,
    guiding_pdf: f32,
    contribution: f32,
    outcome: *mut GuidingRecordOutcome,
) -> Result<(), Failure> {
    // SAFETY: forwarded.
    let o = unsafe {
        at(h, ctx, |v| {
            let r: RecordOutcome = v.record_fraction(bsdf_pdf, guiding_pdf, contribution);
            Ok(GuidingRecordOutcome::from(r))
        })
    }?;
    write_outcome(outcome, o)?;
    refused(
        o,
        format!(
            "record_fraction: bsdf_pdf = {bsdf_pdf}, guiding_pdf = {guiding_pdf}, contribution = {contribution} was dropped"
        ),
    )
}
