//! `GuidingField`: the SD-tree and the GLT in one spatial tree behind a C
//! handle: one lookup per vertex answers both the light choice and the
//! directions (the calls are the GLT's and the SD-tree's, in
//! `light_calls`, `direction_calls` and `handle`).

use crate::buffer::GuidingBuffer;
use crate::config::GuidingFieldConfig;
use crate::context::{GuidingLightSample, GuidingRecordOutcome, GuidingShadingContext};
use crate::direction_calls::{self, GuidingDirectionSample};
use crate::glt::GuidingRefineOutcome;
use crate::handle::Handle;
use crate::light_calls;
use crate::light_tree::GuidingLightTree;
use crate::status::{Failure, GuidingStatus, get, guard, put, slice, vec3};
use guiding::{Aabb, FieldConfig, GuidingField as FieldGuide, LightTree};
use std::sync::Arc;

/// The combined field (opaque): a light choice and directional guiding per
/// region. Queries and records may run from many threads at once; refine,
/// clear_records and merge wait for them.
pub struct GuidingField(Handle<FieldGuide<Arc<LightTree>>>);

fn hand_out(guide: FieldGuide<Arc<LightTree>>, out: *mut *mut GuidingField) -> Result<(), Failure> {
    let handle = Box::into_raw(Box::new(GuidingField(Handle::new(guide))));
    // SAFETY: forwarded from the exported caller; the box is taken back on failure.
    unsafe { put(out, handle, "out") }.inspect_err(|_| {
        // SAFETY: `handle` came from Box::into_raw just above.
        drop(unsafe { Box::from_raw(handle) });
    })
}

/// A field over `tree` for shading points in the box `lower[3]`..`upper[3]`,
/// with `config` (null: the defaults), written to `out`.
///
/// # Safety
/// `tree` a live handle; `lower`, `upper` 3 floats each; `config` null or
/// readable; `out` writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn guiding_field_new(
    tree: *const GuidingLightTree,
    lower: *const f32,
    upper: *const f32,
    config: *const GuidingFieldConfig,
    out: *mut *mut GuidingField,
) -> GuidingStatus {
    guard(|| {
        // SAFETY: forwarded.
        let (t, lo, hi) = unsafe {
            (
                get(tree, "tree")?,
                vec3(lower, "lower")?,
                vec3(upper, "upper")?,
            )
        };
        // SAFETY: forwarded.
        let config = match unsafe { config.as_ref() } {
            Some(c) => c.to_rust()?,
            None => FieldConfig::default(),
        };
        if out.is_null() {
            return Err(Failure::null("out"));
        }
        hand_out(
            FieldGuide::new(Arc::clone(&t.tree), Aabb::new(lo, hi), config)
                .map_err(Failure::built)?,
            out,
        )
    })
}

/// A field saved by `guiding_field_save`, over `tree` (the light tree it
/// was saved over), from `len` bytes at `data`;
/// `GUIDING_STATUS_LOAD_FAILED` for bytes that are not one or another tree.
///
/// # Safety
/// `tree` a live handle; `data` `len` readable bytes; `out` writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn guiding_field_load(
    tree: *const GuidingLightTree,
    data: *const u8,
    len: usize,
    out: *mut *mut GuidingField,
) -> GuidingStatus {
    guard(|| {
        // SAFETY: forwarded.
        let (t, bytes) = unsafe { (get(tree, "tree")?, slice(data, len, "data")?) };
        if out.is_null() {
            return Err(Failure::null("out"));
        }
        let f = FieldGuide::from_bytes(bytes, Arc::clone(&t.tree))
            .map_err(|e| Failure::new(GuidingStatus::LoadFailed, e.to_string()))?;
        hand_out(f, out)
    })
}

/// Frees `field` (null is allowed and does nothing).
///
/// # Safety
/// `field` null or a live handle, freed once, with no call on it running.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn guiding_field_free(field: *mut GuidingField) {
    if !field.is_null() {
        // SAFETY: a handle from Box::into_raw, freed once (the caller's promise).
        drop(unsafe { Box::from_raw(field) });
    }
}

/// The refinements so far (0 for null).
///
/// # Safety
/// `field` null or a live handle.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn guiding_field_iteration(field: *const GuidingField) -> u32 {
    // SAFETY: forwarded.
    unsafe { get(field, "field") }.map_or(0, |g| g.0.iteration())
}

/// The records dropped as bad input so far, every reason together (0 for
/// null).
///
/// # Safety
/// `field` null or a live handle.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn guiding_field_dropped_records(field: *const GuidingField) -> u64 {
    // SAFETY: forwarded.
    unsafe { get(field, "field") }.map_or(0, |g| g.0.dropped_records())
}

/// How many lights `field` chooses among: its emitters, then its unbounded
/// lights (0 for null).
///
/// # Safety
/// `field` null or a live handle.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn guiding_field_light_count(field: *const GuidingField) -> u32 {
    // SAFETY: forwarded.
    unsafe { get(field, "field") }.map_or(0, |g| g.0.emitters + g.0.unbounded)
}

/// Chooses a light at `ctx` with `u` in [0, 1): its index and pmf in
/// `out` (`GUIDING_NO_LIGHT` and 0 when nothing can be sampled there).
///
/// # Safety
/// `field` a live handle; `ctx` readable; `out` writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn guiding_field_sample(
    field: *const GuidingField,
    ctx: *const GuidingShadingContext,
    u: f32,
    out: *mut GuidingLightSample,
) -> GuidingStatus {
    guard(|| {
        // SAFETY: forwarded.
        unsafe { light_calls::sample(&get(field, "field")?.0, ctx, u, out) }
    })
}

/// The probability that `guiding_field_sample` at `ctx` chooses `light` (for
/// MIS with a BSDF sample that hit it), in `out`; exactly the sample's pmf.
///
/// # Safety
/// `field` a live handle; `ctx` readable; `out` writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn guiding_field_pmf(
    field: *const GuidingField,
    ctx: *const GuidingShadingContext,
    light: u32,
    out: *mut f32,
) -> GuidingStatus {
    guard(|| {
        // SAFETY: forwarded.
        unsafe { light_calls::pmf(&get(field, "field")?.0, ctx, light, out) }
    })
}

/// `guiding_field_sample` for `count` points at once: `ctx[i]` with `u[i]` into
/// `out[i]` (a wavefront's batch; the guide's lock taken once). Every input
/// is checked before anything is written; the message names the first bad
/// element.
///
/// # Safety
/// `field` a live handle; `ctx`, `u` `count` readable elements; `out` `count` writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn guiding_field_sample_batch(
    field: *const GuidingField,
    ctx: *const GuidingShadingContext,
    u: *const f32,
    count: usize,
    out: *mut GuidingLightSample,
) -> GuidingStatus {
    guard(|| {
        // SAFETY: forwarded.
        unsafe { light_calls::sample_batch(&get(field, "field")?.0, ctx, u, count, out) }
    })
}

/// `guiding_field_pmf` for `count` points at once: the pmf of `light[i]` at
/// `ctx[i]` into `out[i]`. Every input is checked before anything is written.
///
/// # Safety
/// `field` a live handle; `ctx`, `light` `count` readable elements; `out` `count` writable floats.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn guiding_field_pmf_batch(
    field: *const GuidingField,
    ctx: *const GuidingShadingContext,
    light: *const u32,
    count: usize,
    out: *mut f32,
) -> GuidingStatus {
    guard(|| {
        // SAFETY: forwarded.
        unsafe { light_calls::pmf_batch(&get(field, "field")?.0, ctx, light, count, out) }
    })
}

/// Records a light sample's estimate at `ctx`: `value` is what the sample
/// of `light` contributed, MIS-weighted and divided by its pdf, without the
/// BSDF and the cosine (from NEE `Le * T * w_mis / (pmf *
/// pdf_solid_angle)`, 0 when occluded; from a BSDF sample that hit the
/// emitter `Le * w_mis / pdf_direction`), one scalar such as luminance,
/// finite and >= 0. What the record did goes to `outcome` (null allowed).
/// A NaN, infinite or negative `value` is `GUIDING_STATUS_INVALID_ARGUMENT`,
/// and the guide counts it among its dropped records.
///
/// # Safety
/// `field` a live handle; `ctx` readable; `outcome` null or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn guiding_field_record_light(
    field: *const GuidingField,
    ctx: *const GuidingShadingContext,
    light: u32,
    value: f32,
    outcome: *mut GuidingRecordOutcome,
) -> GuidingStatus {
    guard(|| {
        // SAFETY: forwarded.
        unsafe { light_calls::record_light(&get(field, "field")?.0, ctx, light, value, outcome) }
    })
}

/// A direction from the guide's distribution at `ctx` with `u[2]` in
/// [0, 1): the unit direction and its solid-angle pdf in `out`.
///
/// # Safety
/// `field` a live handle; `ctx` readable; `u` 2 floats; `out` writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn guiding_field_sample_direction(
    field: *const GuidingField,
    ctx: *const GuidingShadingContext,
    u: *const f32,
    out: *mut GuidingDirectionSample,
) -> GuidingStatus {
    guard(|| {
        // SAFETY: forwarded.
        unsafe { direction_calls::sample_direction(&get(field, "field")?.0, ctx, u, out) }
    })
}

/// The guide's solid-angle pdf of `direction[3]` (any length but 0) at
/// `ctx`, in `out`.
///
/// # Safety
/// `field` a live handle; `ctx` readable; `direction` 3 floats; `out` writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn guiding_field_direction_pdf(
    field: *const GuidingField,
    ctx: *const GuidingShadingContext,
    direction: *const f32,
    out: *mut f32,
) -> GuidingStatus {
    guard(|| {
        // SAFETY: forwarded.
        unsafe { direction_calls::direction_pdf(&get(field, "field")?.0, ctx, direction, out) }
    })
}

/// The probability of sampling the BSDF rather than the guide at `ctx`
/// (PPG's one-sample mixture), in `out`.
///
/// # Safety
/// `field` a live handle; `ctx` readable; `out` writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn guiding_field_bsdf_fraction(
    field: *const GuidingField,
    ctx: *const GuidingShadingContext,
    out: *mut f32,
) -> GuidingStatus {
    guard(|| {
        // SAFETY: forwarded.
        unsafe { direction_calls::bsdf_fraction(&get(field, "field")?.0, ctx, out) }
    })
}

/// The mixture's pdf of `direction[3]` at `ctx` given the BSDF's
/// `bsdf_pdf` of it: `a bsdf_pdf + (1 - a) guide_pdf`, in `out`.
///
/// # Safety
/// `field` a live handle; `ctx` readable; `direction` 3 floats; `out` writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn guiding_field_mixture_pdf(
    field: *const GuidingField,
    ctx: *const GuidingShadingContext,
    direction: *const f32,
    bsdf_pdf: f32,
    out: *mut f32,
) -> GuidingStatus {
    guard(|| {
        // SAFETY: forwarded.
        unsafe {
            direction_calls::mixture_pdf(&get(field, "field")?.0, ctx, direction, bsdf_pdf, out)
        }
    })
}

/// PPG's record: `radiance` (one scalar, finite and >= 0) arrived at
/// `ctx` along `direction[3]`, which was sampled with solid-angle `pdf`
/// (finite and > 0; the mixture's). A dropped record is
/// `GUIDING_STATUS_INVALID_ARGUMENT` and counted; `outcome` may be null.
///
/// # Safety
/// `field` a live handle; `ctx` readable; `direction` 3 floats; `outcome` null or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn guiding_field_record_radiance(
    field: *const GuidingField,
    ctx: *const GuidingShadingContext,
    direction: *const f32,
    radiance: f32,
    pdf: f32,
    outcome: *mut GuidingRecordOutcome,
) -> GuidingStatus {
    guard(|| {
        // SAFETY: forwarded.
        unsafe {
            direction_calls::record_radiance(
                &get(field, "field")?.0,
                ctx,
                direction,
                radiance,
                pdf,
                outcome,
            )
        }
    })
}

/// One direction sample for the learned BSDF fraction: the two
/// techniques' pdfs of the sampled direction and the sample's estimate
/// `|f cos| L / mixture_pdf`. `GUIDING_RECORD_OUTCOME_IGNORED` when the
/// configuration learns no fraction; a dropped record is
/// `GUIDING_STATUS_INVALID_ARGUMENT`.
///
/// # Safety
/// `field` a live handle; `ctx` readable; `outcome` null or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn guiding_field_record_fraction(
    field: *const GuidingField,
    ctx: *const GuidingShadingContext,
    bsdf_pdf: f32,
    guiding_pdf: f32,
    contribution: f32,
    outcome: *mut GuidingRecordOutcome,
) -> GuidingStatus {
    guard(|| {
        // SAFETY: forwarded.
        unsafe {
            direction_calls::record_fraction(
                &get(field, "field")?.0,
                ctx,
                bsdf_pdf,
                guiding_pdf,
                contribution,
                outcome,
            )
        }
    })
}

/// Ends an iteration: refines what was learned from the records and
/// splits cells. Waits for running queries on the handle, and they for it.
/// `outcome` may be null.
///
/// # Safety
/// `field` a live handle; `outcome` null or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn guiding_field_refine(
    field: *const GuidingField,
    outcome: *mut GuidingRefineOutcome,
) -> GuidingStatus {
    guard(|| {
        // SAFETY: forwarded.
        unsafe { get(field, "field") }?.0.refine(outcome)
    })
}

/// Forgets this iteration's records (a farm's worker, after loading the
/// coordinator's guide), keeping what was learned.
///
/// # Safety
/// `field` a live handle.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn guiding_field_clear_records(field: *const GuidingField) -> GuidingStatus {
    guard(|| {
        // SAFETY: forwarded.
        unsafe { get(field, "field") }?.0.clear_records()
    })
}

/// Adds `other`'s records into `field` (a farm: both copies of one guide
/// after the same refinements); `GUIDING_STATUS_INCOMPATIBLE` otherwise,
/// with `field` unchanged.
///
/// # Safety
/// `field`, `other` live handles.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn guiding_field_merge(
    field: *const GuidingField,
    other: *const GuidingField,
) -> GuidingStatus {
    guard(|| {
        // SAFETY: forwarded.
        let (a, b) = unsafe { (get(field, "field")?, get(other, "other")?) };
        a.0.merge(&b.0)
    })
}

/// What `field` learned, as bytes (`guiding_field_load` reads them back over the same light tree), into
/// `out` (free it with `guiding_buffer_free`).
///
/// # Safety
/// `field` a live handle; `out` writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn guiding_field_save(
    field: *const GuidingField,
    out: *mut GuidingBuffer,
) -> GuidingStatus {
    guard(|| {
        // SAFETY: forwarded.
        unsafe { get(field, "field") }?.0.save(out)
    })
}
/// What `field` learned as a GPU snapshot's plain-data arrays (read them
/// with `guiding_snapshot_arrays`), written to `out`;
/// `GUIDING_STATUS_SNAPSHOT_FAILED` when it cannot be written as one.
///
/// # Safety
/// `field` a live handle; `out` writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn guiding_field_snapshot(
    field: *const GuidingField,
    out: *mut *mut crate::snapshot::GuidingSnapshot,
) -> GuidingStatus {
    guard(|| {
        // SAFETY: forwarded.
        let g = unsafe { get(field, "field") }?;
        let snapshot = g.0.read()?.snapshot();
        crate::snapshot::hand_out(snapshot, out)
    })
}
