//! `GuidingGlt`: the Guiding Light Tree behind a C handle (the calls it
//! shares with the field are in `light_calls` and `handle`).

use crate::buffer::GuidingBuffer;
use crate::config::GuidingGltConfig;
use crate::context::{GuidingLightSample, GuidingRecordOutcome, GuidingShadingContext};
use crate::handle::Handle;
use crate::light_calls;
use crate::light_tree::GuidingLightTree;
use crate::status::{Failure, GuidingStatus, get, guard, put, slice, vec3};
use guiding::{Aabb, Glt as GltGuide, GltConfig, LightTree};
use std::sync::Arc;

/// A Guiding Light Tree (opaque). Queries and records may run from many
/// threads at once; refine, clear_records and merge wait for them.
pub struct GuidingGlt(Handle<GltGuide<Arc<LightTree>>>);

/// What a `_refine` call did to the spatial tree.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default)]
pub struct GuidingRefineOutcome {
    /// Cells split.
    pub splits: usize,
    /// Splits refused because the memory budget was reached.
    pub refused_by_budget: usize,
    /// Splits refused because a cell is too small to halve in `float`.
    pub refused_by_precision: usize,
}

fn hand_out(guide: GltGuide<Arc<LightTree>>, out: *mut *mut GuidingGlt) -> Result<(), Failure> {
    let handle = Box::into_raw(Box::new(GuidingGlt(Handle::new(guide))));
    // SAFETY: forwarded from the exported caller; the box is taken back on failure.
    unsafe { put(out, handle, "out") }.inspect_err(|_| {
        // SAFETY: `handle` came from Box::into_raw just above.
        drop(unsafe { Box::from_raw(handle) });
    })
}

/// A GLT over `tree` for shading points in the box `lower[3]`..`upper[3]`
/// (points outside are clamped onto it), with `config` (null: the
/// defaults), written to `out`.
///
/// # Safety
/// `tree` a live handle; `lower`, `upper` 3 floats each; `config` null or
/// readable; `out` writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn guiding_glt_new(
    tree: *const GuidingLightTree,
    lower: *const f32,
    upper: *const f32,
    config: *const GuidingGltConfig,
    out: *mut *mut GuidingGlt,
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
            None => GltConfig::default(),
        };
        if out.is_null() {
            return Err(Failure::null("out"));
        }
        hand_out(
            guiding::Glt::new(Arc::clone(&t.tree), Aabb::new(lo, hi), config)
                .map_err(Failure::built)?,
            out,
        )
    })
}

/// A GLT saved by `guiding_glt_save`, over `tree` (the light tree it was
/// saved over), from `len` bytes at `data`; `GUIDING_STATUS_LOAD_FAILED`
/// for bytes that are not one or another tree.
///
/// # Safety
/// `tree` a live handle; `data` `len` readable bytes; `out` writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn guiding_glt_load(
    tree: *const GuidingLightTree,
    data: *const u8,
    len: usize,
    out: *mut *mut GuidingGlt,
) -> GuidingStatus {
    guard(|| {
        // SAFETY: forwarded.
        let (t, bytes) = unsafe { (get(tree, "tree")?, slice(data, len, "data")?) };
        if out.is_null() {
            return Err(Failure::null("out"));
        }
        let glt = guiding::Glt::from_bytes(bytes, Arc::clone(&t.tree))
            .map_err(|e| Failure::new(GuidingStatus::LoadFailed, e.to_string()))?;
        hand_out(glt, out)
    })
}

/// Frees `glt` (null is allowed and does nothing).
///
/// # Safety
/// `glt` null or a live handle, freed once, with no call on it running.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn guiding_glt_free(glt: *mut GuidingGlt) {
    if !glt.is_null() {
        // SAFETY: a handle from Box::into_raw, freed once (the caller's promise).
        drop(unsafe { Box::from_raw(glt) });
    }
}

/// The refinements so far (0 for null).
///
/// # Safety
/// `glt` null or a live handle.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn guiding_glt_iteration(glt: *const GuidingGlt) -> u32 {
    // SAFETY: forwarded.
    unsafe { get(glt, "glt") }.map_or(0, |g| g.0.iteration())
}

/// The records dropped as bad input so far, every reason together (0 for
/// null).
///
/// # Safety
/// `glt` null or a live handle.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn guiding_glt_dropped_records(glt: *const GuidingGlt) -> u64 {
    // SAFETY: forwarded.
    unsafe { get(glt, "glt") }.map_or(0, |g| g.0.dropped_records())
}

/// How many lights `glt` chooses among: its emitters, then its unbounded
/// lights (0 for null).
///
/// # Safety
/// `glt` null or a live handle.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn guiding_glt_light_count(glt: *const GuidingGlt) -> u32 {
    // SAFETY: forwarded.
    unsafe { get(glt, "glt") }.map_or(0, |g| g.0.emitters + g.0.unbounded)
}

/// Chooses a light at `ctx` with `u` in [0, 1): its index and pmf in
/// `out` (`GUIDING_NO_LIGHT` and 0 when nothing can be sampled there).
///
/// # Safety
/// `glt` a live handle; `ctx` readable; `out` writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn guiding_glt_sample(
    glt: *const GuidingGlt,
    ctx: *const GuidingShadingContext,
    u: f32,
    out: *mut GuidingLightSample,
) -> GuidingStatus {
    guard(|| {
        // SAFETY: forwarded.
        unsafe { light_calls::sample(&get(glt, "glt")?.0, ctx, u, out) }
    })
}

/// The probability that `guiding_glt_sample` at `ctx` chooses `light` (for
/// MIS with a BSDF sample that hit it), in `out`; exactly the sample's pmf.
///
/// # Safety
/// `glt` a live handle; `ctx` readable; `out` writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn guiding_glt_pmf(
    glt: *const GuidingGlt,
    ctx: *const GuidingShadingContext,
    light: u32,
    out: *mut f32,
) -> GuidingStatus {
    guard(|| {
        // SAFETY: forwarded.
        unsafe { light_calls::pmf(&get(glt, "glt")?.0, ctx, light, out) }
    })
}

/// `guiding_glt_sample` for `count` points at once: `ctx[i]` with `u[i]` into
/// `out[i]` (a wavefront's batch; the guide's lock taken once). Every input
/// is checked before anything is written; the message names the first bad
/// element.
///
/// # Safety
/// `glt` a live handle; `ctx`, `u` `count` readable elements; `out` `count` writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn guiding_glt_sample_batch(
    glt: *const GuidingGlt,
    ctx: *const GuidingShadingContext,
    u: *const f32,
    count: usize,
    out: *mut GuidingLightSample,
) -> GuidingStatus {
    guard(|| {
        // SAFETY: forwarded.
        unsafe { light_calls::sample_batch(&get(glt, "glt")?.0, ctx, u, count, out) }
    })
}

/// `guiding_glt_pmf` for `count` points at once: the pmf of `light[i]` at
/// `ctx[i]` into `out[i]`. Every input is checked before anything is written.
///
/// # Safety
/// `glt` a live handle; `ctx`, `light` `count` readable elements; `out` `count` writable floats.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn guiding_glt_pmf_batch(
    glt: *const GuidingGlt,
    ctx: *const GuidingShadingContext,
    light: *const u32,
    count: usize,
    out: *mut f32,
) -> GuidingStatus {
    guard(|| {
        // SAFETY: forwarded.
        unsafe { light_calls::pmf_batch(&get(glt, "glt")?.0, ctx, light, count, out) }
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
/// `glt` a live handle; `ctx` readable; `outcome` null or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn guiding_glt_record_light(
    glt: *const GuidingGlt,
    ctx: *const GuidingShadingContext,
    light: u32,
    value: f32,
    outcome: *mut GuidingRecordOutcome,
) -> GuidingStatus {
    guard(|| {
        // SAFETY: forwarded.
        unsafe { light_calls::record_light(&get(glt, "glt")?.0, ctx, light, value, outcome) }
    })
}

/// Ends an iteration: refines what was learned from the records and
/// splits cells. Waits for running queries on the handle, and they for it.
/// `outcome` may be null.
///
/// # Safety
/// `glt` a live handle; `outcome` null or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn guiding_glt_refine(
    glt: *const GuidingGlt,
    outcome: *mut GuidingRefineOutcome,
) -> GuidingStatus {
    guard(|| {
        // SAFETY: forwarded.
        unsafe { get(glt, "glt") }?.0.refine(outcome)
    })
}

/// Forgets this iteration's records (a farm's worker, after loading the
/// coordinator's guide), keeping what was learned.
///
/// # Safety
/// `glt` a live handle.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn guiding_glt_clear_records(glt: *const GuidingGlt) -> GuidingStatus {
    guard(|| {
        // SAFETY: forwarded.
        unsafe { get(glt, "glt") }?.0.clear_records()
    })
}

/// Adds `other`'s records into `glt` (a farm: both copies of one guide
/// after the same refinements); `GUIDING_STATUS_INCOMPATIBLE` otherwise,
/// with `glt` unchanged.
///
/// # Safety
/// `glt`, `other` live handles.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn guiding_glt_merge(
    glt: *const GuidingGlt,
    other: *const GuidingGlt,
) -> GuidingStatus {
    guard(|| {
        // SAFETY: forwarded.
        let (a, b) = unsafe { (get(glt, "glt")?, get(other, "other")?) };
        a.0.merge(&b.0)
    })
}

/// What `glt` learned, as bytes (`guiding_glt_load` reads them back over the same light tree), into
/// `out` (free it with `guiding_buffer_free`).
///
/// # Safety
/// `glt` a live handle; `out` writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn guiding_glt_save(
    glt: *const GuidingGlt,
    out: *mut GuidingBuffer,
) -> GuidingStatus {
    guard(|| {
        // SAFETY: forwarded.
        unsafe { get(glt, "glt") }?.0.save(out)
    })
}
/// What `glt` learned as a GPU snapshot's plain-data arrays (read them
/// with `guiding_snapshot_arrays`), written to `out`;
/// `GUIDING_STATUS_SNAPSHOT_FAILED` when it cannot be written as one.
///
/// # Safety
/// `glt` a live handle; `out` writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn guiding_glt_snapshot(
    glt: *const GuidingGlt,
    out: *mut *mut crate::snapshot::GuidingSnapshot,
) -> GuidingStatus {
    guard(|| {
        // SAFETY: forwarded.
        let g = unsafe { get(glt, "glt") }?;
        let snapshot = g.0.read()?.snapshot();
        crate::snapshot::hand_out(snapshot, out)
    })
}
