//! `GuidingSnapshot`: what a GLT or a field learned as plain-data arrays
//! for a GPU kernel (the crate's `snapshot` module; `gpu/` samples them in
//! WGSL): the C side gets each array's bytes to upload, one buffer each.

use crate::status::{Failure, GuidingStatus, get, guard, put};
use guiding::snapshot::Snapshot;

/// A snapshot (opaque): its arrays stay valid until `guiding_snapshot_free`.
pub struct GuidingSnapshot(Snapshot);

/// One array of a snapshot: `bytes` bytes at `data` holding `count`
/// elements of the layout the crate's `snapshot::layout` documents
/// (little-endian `u32`, `f32` and `i16` fields, `#[repr(C)]`).
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct GuidingSnapshotArray {
    /// The first byte (null when `count` is 0).
    pub data: *const u8,
    /// How many bytes.
    pub bytes: usize,
    /// How many elements.
    pub count: usize,
}

/// Every array of a snapshot, in the order `gpu/`'s kernel binds them.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct GuidingSnapshotArrays {
    /// The header: counts and shared rules (one element).
    pub header: GuidingSnapshotArray,
    /// The spatial tree's node words.
    pub spatial: GuidingSnapshotArray,
    /// One record per cell.
    pub cells: GuidingSnapshotArray,
    /// Every cell's cut nodes.
    pub cut_nodes: GuidingSnapshotArray,
    /// Each cell's learned fraction of every unbounded light.
    pub fractions: GuidingSnapshotArray,
    /// Each cell's learned visibilities (empty when none are learned).
    pub visibility: GuidingSnapshotArray,
    /// The light tree, as sibling pairs.
    pub tree: GuidingSnapshotArray,
    /// Per pair, where the right child's leaves start.
    pub first_right: GuidingSnapshotArray,
    /// Per pair, both nodes' bounds (empty when no rule reads importance).
    pub bounds: GuidingSnapshotArray,
    /// Per emitter, its leaf's position in depth-first leaf order.
    pub leaf_position: GuidingSnapshotArray,
}

fn array<T>(a: &[T]) -> GuidingSnapshotArray {
    GuidingSnapshotArray {
        data: if a.is_empty() {
            std::ptr::null()
        } else {
            a.as_ptr().cast()
        },
        bytes: size_of_val(a),
        count: a.len(),
    }
}

/// `snapshot` as a handle written to `out`.
pub(crate) fn hand_out(
    snapshot: Result<Snapshot, guiding::snapshot::SnapshotError>,
    out: *mut *mut GuidingSnapshot,
) -> Result<(), Failure> {
    if out.is_null() {
        return Err(Failure::null("out"));
    }
    let s = snapshot.map_err(|e| Failure::new(GuidingStatus::SnapshotFailed, e.to_string()))?;
    let handle = Box::into_raw(Box::new(GuidingSnapshot(s)));
    // SAFETY: checked non-null, writable by the exported caller's promise.
    unsafe { put(out, handle, "out") }
}

/// The arrays of `snapshot`, into `out` (pointers into the snapshot, valid
/// until it is freed).
///
/// # Safety
/// `snapshot` a live handle; `out` writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn guiding_snapshot_arrays(
    snapshot: *const GuidingSnapshot,
    out: *mut GuidingSnapshotArrays,
) -> GuidingStatus {
    guard(|| {
        // SAFETY: forwarded.
        let s = unsafe { get(snapshot, "snapshot") }?;
        let a = s.0.arrays();
        let arrays = GuidingSnapshotArrays {
            header: array(std::slice::from_ref(a.header)),
            spatial: array(a.spatial),
            cells: array(a.cells),
            cut_nodes: array(a.cut_nodes),
            fractions: array(a.fractions),
            visibility: array(a.visibility),
            tree: array(a.tree),
            first_right: array(a.first_right),
            bounds: array(a.bounds),
            leaf_position: array(a.leaf_position),
        };
        // SAFETY: forwarded.
        unsafe { put(out, arrays, "out") }
    })
}

/// The bytes of all of `snapshot`'s arrays together (what a GPU holds; 0
/// for null).
///
/// # Safety
/// `snapshot` null or a live handle.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn guiding_snapshot_bytes(snapshot: *const GuidingSnapshot) -> usize {
    // SAFETY: forwarded.
    unsafe { get(snapshot, "snapshot") }.map_or(0, |s| s.0.bytes())
}

/// Frees `snapshot` (null is allowed and does nothing).
///
/// # Safety
/// `snapshot` null or a live handle, freed once.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn guiding_snapshot_free(snapshot: *mut GuidingSnapshot) {
    if !snapshot.is_null() {
        // SAFETY: a handle from Box::into_raw, freed once (the caller's promise).
        drop(unsafe { Box::from_raw(snapshot) });
    }
}
