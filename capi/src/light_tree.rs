//! `GuidingLightTree`: the global light tree over a scene's emitters,
//! shared by the guides built over it.

use crate::buffer::GuidingBuffer;
use crate::emitters::GuidingEmitters;
use crate::status::{Failure, GuidingStatus, get, guard, put, slice};
use guiding::{BuildHeuristic, LightHierarchy, LightTree};
use std::sync::Arc;

/// `heuristic` of `guiding_light_tree_build`: the surface-area-radiance
/// heuristic (the paper's choice, the crate's default).
pub const GUIDING_HEURISTIC_SARH: u32 = 0;
/// Median splits by count (a balanced tree).
pub const GUIDING_HEURISTIC_BALANCED: u32 = 1;
/// The surface-area heuristic.
pub const GUIDING_HEURISTIC_SAH: u32 = 2;
/// pbrt-v4's surface-area-orientation heuristic.
pub const GUIDING_HEURISTIC_SAOH: u32 = 3;

/// A light tree (opaque). Guides built over it keep what they need: it may
/// be freed before them.
pub struct GuidingLightTree {
    pub(crate) tree: Arc<LightTree>,
}

fn heuristic(h: u32) -> Result<BuildHeuristic, Failure> {
    Ok(match h {
        GUIDING_HEURISTIC_SARH => BuildHeuristic::Sarh,
        GUIDING_HEURISTIC_BALANCED => BuildHeuristic::Balanced,
        GUIDING_HEURISTIC_SAH => BuildHeuristic::Sah,
        GUIDING_HEURISTIC_SAOH => BuildHeuristic::Saoh,
        _ => {
            return Err(Failure::invalid(format!(
                "heuristic = {h} is not a GUIDING_HEURISTIC_*"
            )));
        }
    })
}

fn hand_out(tree: LightTree, out: *mut *mut GuidingLightTree) -> Result<(), Failure> {
    let handle = Box::into_raw(Box::new(GuidingLightTree {
        tree: Arc::new(tree),
    }));
    // SAFETY: forwarded from the exported caller; the box is taken back on failure.
    unsafe { put(out, handle, "out") }.inspect_err(|_| {
        // SAFETY: `handle` came from Box::into_raw just above.
        drop(unsafe { Box::from_raw(handle) });
    })
}

/// Builds the light tree over `emitters` with `heuristic` (a
/// `GUIDING_HEURISTIC_*`) and writes its handle to `out`.
/// `GUIDING_STATUS_BUILD_FAILED` when there is nothing to build over.
///
/// # Safety
/// `emitters` a live handle; `out` writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn guiding_light_tree_build(
    emitters: *const GuidingEmitters,
    heuristic_: u32,
    out: *mut *mut GuidingLightTree,
) -> GuidingStatus {
    guard(|| {
        // SAFETY: forwarded.
        let e = unsafe { get(emitters, "emitters") }?;
        if out.is_null() {
            return Err(Failure::null("out"));
        }
        let tree = LightTree::build(&e.list, heuristic(heuristic_)?)
            .map_err(|err| Failure::new(GuidingStatus::BuildFailed, err.to_string()))?;
        hand_out(tree, out)
    })
}

/// Frees `tree` (null is allowed and does nothing).
///
/// # Safety
/// `tree` null or a live handle, freed once.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn guiding_light_tree_free(tree: *mut GuidingLightTree) {
    if !tree.is_null() {
        // SAFETY: a handle from Box::into_raw, freed once (the caller's promise).
        drop(unsafe { Box::from_raw(tree) });
    }
}

/// The number of emitters under `tree` (0 for null).
///
/// # Safety
/// `tree` null or a live handle.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn guiding_light_tree_emitter_count(tree: *const GuidingLightTree) -> u32 {
    // SAFETY: forwarded.
    unsafe { get(tree, "tree") }.map_or(0, |t| t.tree.emitter_count() as u32)
}

/// The tree as bytes (`guiding_light_tree_load` reads them back), into
/// `out` (free it with `guiding_buffer_free`).
///
/// # Safety
/// `tree` a live handle; `out` writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn guiding_light_tree_save(
    tree: *const GuidingLightTree,
    out: *mut GuidingBuffer,
) -> GuidingStatus {
    guard(|| {
        // SAFETY: forwarded.
        let t = unsafe { get(tree, "tree") }?;
        if out.is_null() {
            return Err(Failure::null("out"));
        }
        // SAFETY: checked non-null, writable by the caller's promise.
        unsafe { put(out, GuidingBuffer::from_vec(t.tree.to_bytes()), "out") }
    })
}

/// A tree saved by `guiding_light_tree_save`, from `len` bytes at `data`;
/// `GUIDING_STATUS_LOAD_FAILED` for bytes that are not one.
///
/// # Safety
/// `data` `len` readable bytes; `out` writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn guiding_light_tree_load(
    data: *const u8,
    len: usize,
    out: *mut *mut GuidingLightTree,
) -> GuidingStatus {
    guard(|| {
        // SAFETY: forwarded.
        let bytes = unsafe { slice(data, len, "data") }?;
        if out.is_null() {
            return Err(Failure::null("out"));
        }
        let tree = LightTree::from_bytes(bytes)
            .map_err(|e| Failure::new(GuidingStatus::LoadFailed, e.to_string()))?;
        hand_out(tree, out)
    })
}
