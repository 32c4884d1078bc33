//! The light choice's calls, shared by the GLT's and the field's exports:
//! sample, pmf (one point or a batch) and record_light.

use crate::context::{
    GUIDING_NO_LIGHT, GuidingLightSample, GuidingRecordOutcome, GuidingShadingContext, unit,
};
use crate::handle::{Handle, Learned, LightGuide};
use crate::status::{Failure, get, put, slice};
use guiding::{LightChoice, LightSample};

fn c_sample(s: Option<LightSample>, emitters: u32) -> GuidingLightSample {
    s.map_or(
        GuidingLightSample {
            light: GUIDING_NO_LIGHT,
            pmf: 0.0,
        },
        |s| GuidingLightSample {
            light: s.light.index(emitters),
            pmf: s.pmf,
        },
    )
}

/// # Safety
/// `ctx` null or readable; `out` null or writable.
pub(crate) unsafe fn sample<G: LightGuide + Learned>(
    h: &Handle<G>,
    ctx: *const GuidingShadingContext,
    u: f32,
    out: *mut GuidingLightSample,
) -> Result<(), Failure> {
    // SAFETY: forwarded.
    let ctx = unsafe { get(ctx, "ctx") }?.to_rust()?;
    let u = unit(u, "u")?;
    if out.is_null() {
        return Err(Failure::null("out"));
    }
    let s = h.read()?.light_vertex(&ctx).and_then(|v| v.sample(u));
    // SAFETY: checked non-null, writable by the caller's promise.
    unsafe { put(out, c_sample(s, h.emitters), "out") }
}

/// # Safety
/// `ctx` null or readable; `out` null or writable.
pub(crate) unsafe fn pmf<G: LightGuide + Learned>(
    h: &Handle<G>,
    ctx: *const GuidingShadingContext,
    light: u32,
    out: *mut f32,
) -> Result<(), Failure> {
    // SAFETY: forwarded.
    let ctx = unsafe { get(ctx, "ctx") }?.to_rust()?;
    let light = h.light(light)?;
    if out.is_null() {
        return Err(Failure::null("out"));
    }
    let p = h.read()?.light_vertex(&ctx).map_or(0.0, |v| v.pmf(light));
    // SAFETY: checked non-null, writable by the caller's promise.
    unsafe { put(out, p, "out") }
}

/// # Safety
/// `ctx`, `u` null or `count` readable elements; `out` null or `count`
/// writable elements.
pub(crate) unsafe fn sample_batch<G: LightGuide + Learned>(
    h: &Handle<G>,
    ctx: *const GuidingShadingContext,
    u: *const f32,
    count: usize,
    out: *mut GuidingLightSample,
) -> Result<(), Failure> {
    // SAFETY: forwarded.
    let (ctx, u) = unsafe { (slice(ctx, count, "ctx")?, slice(u, count, "u")?) };
    if count > 0 && out.is_null() {
        return Err(Failure::null("out"));
    }
    let queries = ctx
        .iter()
        .zip(u)
        .enumerate()
        .map(|(i, (c, &u))| {
            let c = c
                .to_rust()
                .map_err(|f| Failure::invalid(format!("ctx[{i}]: {}", f.message)))?;
            if !(0.0..1.0).contains(&u) {
                return Err(Failure::invalid(format!("u[{i}] = {u} is not in [0, 1)")));
            }
            Ok((c, u))
        })
        .collect::<Result<Vec<_>, Failure>>()?;
    let guide = h.read()?;
    for (i, (c, u)) in queries.iter().enumerate() {
        let s = c_sample(guide.light_vertex(c).and_then(|v| v.sample(*u)), h.emitters);
        // SAFETY: `out` holds `count` writable elements (the caller's promise), i < count.
        unsafe { out.add(i).write(s) };
    }
    Ok(())
}

/// # Safety
/// `ctx`, `light` null or `count` readable elements; `out` null or
/// `count` writable floats.
pub(crate) unsafe fn pmf_batch<G: LightGuide + Learned>(
    h: &Handle<G>,
    ctx: *const GuidingShadingContext,
    light: *const u32,
    count: usize,
    out: *mut f32,
) -> Result<(), Failure> {
    // SAFETY: forwarded.
    let (ctx, light) = unsafe { (slice(ctx, count, "ctx")?, slice(light, count, "light")?) };
    if count > 0 && out.is_null() {
        return Err(Failure::null("out"));
    }
    let queries = ctx
        .iter()
        .zip(light)
        .enumerate()
        .map(|(i, (c, &l))| {
            let c = c
                .to_rust()
                .map_err(|f| Failure::invalid(format!("ctx[{i}]: {}", f.message)))?;
            let l = h
                .light(l)
                .map_err(|f| Failure::invalid(format!("light[{i}]: {}", f.message)))?;
            Ok((c, l))
        })
        .collect::<Result<Vec<_>, Failure>>()?;
    let guide = h.read()?;
    for (i, (c, l)) in queries.iter().enumerate() {
        let p = guide.light_vertex(c).map_or(0.0, |v| v.pmf(*l));
        // SAFETY: `out` holds `count` writable floats (the caller's promise), i < count.
        unsafe { out.add(i).write(p) };
    }
    Ok(())
}

/// # Safety
/// `ctx` null or readable; `outcome` null or writable.
pub(crate) unsafe fn record_light<G: LightGuide + Learned>(
    h: &Handle<G>,
    ctx: *const GuidingShadingContext,
    light: u32,
    value: f32,
    outcome: *mut GuidingRecordOutcome,
) -> Result<(), Failure> {
    // SAFETY: forwarded.
    let ctx = unsafe { get(ctx, "ctx") }?.to_rust()?;
    let light = h.light(light)?;
    let guide = h.read()?;
    let v = guide
        .light_vertex(&ctx)
        .ok_or_else(|| Failure::invalid("ctx.position is not finite"))?;
    let o = GuidingRecordOutcome::from(v.record_light(light, value));
    write_outcome(outcome, o)?;
    if o == GuidingRecordOutcome::Dropped {
        return Err(Failure::invalid(format!(
            "record_light: value = {value} for light {} was dropped (must be finite and >= 0, the light must have power)",
            light.index(h.emitters)
        )));
    }
    Ok(())
}

/// Writes `o` through `outcome` when it is not null.
pub(crate) fn write_outcome(
    outcome: *mut GuidingRecordOutcome,
    o: GuidingRecordOutcome,
) -> Result<(), Failure> {
    if outcome.is_null() {
        return Ok(());
    }
    // SAFETY: non-null, writable by the exported caller's promise.
    unsafe { put(outcome, o, "outcome") }
}
