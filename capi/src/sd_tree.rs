//! `GuidingSdTree`: Practical Path Guiding's SD-tree behind a C handle
//! (the calls it shares with the field are in `direction_calls` and
//! `handle`).

use crate::buffer::GuidingBuffer;
use crate::config::GuidingSdTreeConfig;
use crate::context::{GuidingRecordOutcome, GuidingShadingContext};
use crate::direction_calls::{self, GuidingDirectionSample};
use crate::glt::GuidingRefineOutcome;
use crate::handle::Handle;
use crate::status::{Failure, GuidingStatus, get, guard, put, slice, vec3};
use guiding::{Aabb, SdTree, SdTreeConfig};

/// An SD-tree (opaque): learned directional distributions per region.
/// Queries and records may run from many threads at once; refine,
/// clear_records and merge wait for them.
pub struct GuidingSdTree(Handle<SdTree>);

fn hand_out(guide: SdTree, out: *mut *mut GuidingSdTree) -> Result<(), Failure> {
    let handle = Box::into_raw(Box::new(GuidingSdTree(Handle::new(guide))));
    // SAFETY: forwarded from the exported caller; the box is taken back on failure.
    unsafe { put(out, handle, "out") }.inspect_err(|_| {
        // SAFETY: `handle` came from Box::into_raw just above.
        drop(unsafe { Box::from_raw(handle) });
    })
}

/// An SD-tree for shading points in the box `lower[3]`..`upper[3]`, with
/// `config` (null: the defaults), written to `out`.
///
/// # Safety
/// `lower`, `upper` 3 floats each; `config` null or readable; `out`
/// writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn guiding_sd_tree_new(
    lower: *const f32,
    upper: *const f32,
    config: *const GuidingSdTreeConfig,
    out: *mut *mut GuidingSdTree,
) -> GuidingStatus {
    guard(|| {
        // SAFETY: forwarded.
        let (lo, hi) = unsafe { (vec3(lower, "lower")?, vec3(upper, "upper")?) };
        // SAFETY: forwarded.
        let config = match unsafe { config.as_ref() } {
            Some(c) => c.to_rust()?,
            None => SdTreeConfig::default(),
        };
        if out.is_null() {
            return Err(Failure::null("out"));
        }
        hand_out(
            SdTree::new(Aabb::new(lo, hi), config).map_err(Failure::built)?,
            out,
        )
    })
}

/// An SD-tree saved by `guiding_sd_tree_save`, from `len` bytes at `data`;
/// `GUIDING_STATUS_LOAD_FAILED` for bytes that are not one.
///
/// # Safety
/// `data` `len` readable bytes; `out` writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn guiding_sd_tree_load(
    data: *const u8,
    len: usize,
    out: *mut *mut GuidingSdTree,
) -> GuidingStatus {
    guard(|| {
        // SAFETY: forwarded.
        let bytes = unsafe { slice(data, len, "data") }?;
        if out.is_null() {
            return Err(Failure::null("out"));
        }
        let sd = SdTree::from_bytes(bytes)
            .map_err(|e| Failure::new(GuidingStatus::LoadFailed, e.to_string()))?;
        hand_out(sd, out)
    })
}

/// Frees `sd_tree` (null is allowed and does nothing).
///
/// # Safety
/// `sd_tree` null or a live handle, freed once, with no call on it running.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn guiding_sd_tree_free(sd_tree: *mut GuidingSdTree) {
    if !sd_tree.is_null() {
        // SAFETY: a handle from Box::into_raw, freed once (the caller's promise).
        drop(unsafe { Box::from_raw(sd_tree) });
    }
}

/// The refinements so far (0 for null).
///
/// # Safety
/// `sd_tree` null or a live handle.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn guiding_sd_tree_iteration(sd_tree: *const GuidingSdTree) -> u32 {
    // SAFETY: forwarded.
    unsafe { get(sd_tree, "sd_tree") }.map_or(0, |g| g.0.iteration())
}

/// The records dropped as bad input so far, every reason together (0 for
/// null).
///
/// # Safety
/// `sd_tree` null or a live handle.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn guiding_sd_tree_dropped_records(sd_tree: *const GuidingSdTree) -> u64 {
    // SAFETY: forwarded.
    unsafe { get(sd_tree, "sd_tree") }.map_or(0, |g| g.0.dropped_records())
}

/// A direction from the guide's distribution at `ctx` with `u[2]` in
/// [0, 1): the unit direction and its solid-angle pdf in `out`.
///
/// # Safety
/// `sd_tree` a live handle; `ctx` readable; `u` 2 floats; `out` writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn guiding_sd_tree_sample_direction(
    sd_tree: *const GuidingSdTree,
    ctx: *const GuidingShadingContext,
    u: *const f32,
    out: *mut GuidingDirectionSample,
) -> GuidingStatus {
    guard(|| {
        // SAFETY: forwarded.
        unsafe { direction_calls::sample_direction(&get(sd_tree, "sd_tree")?.0, ctx, u, out) }
    })
}

/// The guide's solid-angle pdf of `direction[3]` (any length but 0) at
/// `ctx`, in `out`.
///
/// # Safety
/// `sd_tree` a live handle; `ctx` readable; `direction` 3 floats; `out` writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn guiding_sd_tree_direction_pdf(
    sd_tree: *const GuidingSdTree,
    ctx: *const GuidingShadingContext,
    direction: *const f32,
    out: *mut f32,
) -> GuidingStatus {
    guard(|| {
        // SAFETY: forwarded.
        unsafe { direction_calls::direction_pdf(&get(sd_tree, "sd_tree")?.0, ctx, direction, out) }
    })
}

/// The probability of sampling the BSDF rather than the guide at `ctx`
/// (PPG's one-sample mixture), in `out`.
///
/// # Safety
/// `sd_tree` a live handle; `ctx` readable; `out` writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn guiding_sd_tree_bsdf_fraction(
    sd_tree: *const GuidingSdTree,
    ctx: *const GuidingShadingContext,
    out: *mut f32,
) -> GuidingStatus {
    guard(|| {
        // SAFETY: forwarded.
        unsafe { direction_calls::bsdf_fraction(&get(sd_tree, "sd_tree")?.0, ctx, out) }
    })
}

/// The mixture's pdf of `direction[3]` at `ctx` given the BSDF's
/// `bsdf_pdf` of it: `a bsdf_pdf + (1 - a) guide_pdf`, in `out`.
///
/// # Safety
/// `sd_tree` a live handle; `ctx` readable; `direction` 3 floats; `out` writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn guiding_sd_tree_mixture_pdf(
    sd_tree: *const GuidingSdTree,
    ctx: *const GuidingShadingContext,
    direction: *const f32,
    bsdf_pdf: f32,
    out: *mut f32,
) -> GuidingStatus {
    guard(|| {
        // SAFETY: forwarded.
        unsafe {
            direction_calls::mixture_pdf(&get(sd_tree, "sd_tree")?.0, ctx, direction, bsdf_pdf, out)
        }
    })
}

/// PPG's record: `radiance` (one scalar, finite and >= 0) arrived at
/// `ctx` along `direction[3]`, which was sampled with solid-angle `pdf`
/// (finite and > 0; the mixture's). A dropped record is
/// `GUIDING_STATUS_INVALID_ARGUMENT` and counted; `outcome` may be null.
///
/// # Safety
/// `sd_tree` a live handle; `ctx` readable; `direction` 3 floats; `outcome` null or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn guiding_sd_tree_record_radiance(
    sd_tree: *const GuidingSdTree,
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
                &get(sd_tree, "sd_tree")?.0,
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
/// `sd_tree` a live handle; `ctx` readable; `outcome` null or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn guiding_sd_tree_record_fraction(
    sd_tree: *const GuidingSdTree,
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
                &get(sd_tree, "sd_tree")?.0,
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
/// `sd_tree` a live handle; `outcome` null or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn guiding_sd_tree_refine(
    sd_tree: *const GuidingSdTree,
    outcome: *mut GuidingRefineOutcome,
) -> GuidingStatus {
    guard(|| {
        // SAFETY: forwarded.
        unsafe { get(sd_tree, "sd_tree") }?.0.refine(outcome)
    })
}

/// Forgets this iteration's records (a farm's worker, after loading the
/// coordinator's guide), keeping what was learned.
///
/// # Safety
/// `sd_tree` a live handle.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn guiding_sd_tree_clear_records(
    sd_tree: *const GuidingSdTree,
) -> GuidingStatus {
    guard(|| {
        // SAFETY: forwarded.
        unsafe { get(sd_tree, "sd_tree") }?.0.clear_records()
    })
}

/// Adds `other`'s records into `sd_tree` (a farm: both copies of one guide
/// after the same refinements); `GUIDING_STATUS_INCOMPATIBLE` otherwise,
/// with `sd_tree` unchanged.
///
/// # Safety
/// `sd_tree`, `other` live handles.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn guiding_sd_tree_merge(
    sd_tree: *const GuidingSdTree,
    other: *const GuidingSdTree,
) -> GuidingStatus {
    guard(|| {
        // SAFETY: forwarded.
        let (a, b) = unsafe { (get(sd_tree, "sd_tree")?, get(other, "other")?) };
        a.0.merge(&b.0)
    })
}

/// What `sd_tree` learned, as bytes (`guiding_sd_tree_load` reads them back), into
/// `out` (free it with `guiding_buffer_free`).
///
/// # Safety
/// `sd_tree` a live handle; `out` writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn guiding_sd_tree_save(
    sd_tree: *const GuidingSdTree,
    out: *mut GuidingBuffer,
) -> GuidingStatus {
    guard(|| {
        // SAFETY: forwarded.
        unsafe { get(sd_tree, "sd_tree") }?.0.save(out)
    })
}
