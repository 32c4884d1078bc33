//! `GuidingBuffer`: bytes the crate hands out (a saved light tree or
//! guide), freed with `guiding_buffer_free`.

use crate::status::{GuidingStatus, guard};

/// Bytes owned by the crate: `len` bytes at `data`. Free with
/// `guiding_buffer_free`; copy them out first to keep them.
#[repr(C)]
#[derive(Debug)]
pub struct GuidingBuffer {
    /// The bytes (null when `len` is 0).
    pub data: *mut u8,
    /// How many.
    pub len: usize,
}

impl GuidingBuffer {
    pub(crate) fn from_vec(bytes: Vec<u8>) -> Self {
        let len = bytes.len();
        if len == 0 {
            return Self {
                data: std::ptr::null_mut(),
                len: 0,
            };
        }
        let data = Box::into_raw(bytes.into_boxed_slice()).cast::<u8>();
        Self { data, len }
    }
}

/// Frees the bytes of `buffer` and sets it to empty (null, or an empty
/// buffer, is allowed and does nothing).
///
/// # Safety
/// `buffer` null or a buffer a `guiding_*_save` call filled, not freed yet.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn guiding_buffer_free(buffer: *mut GuidingBuffer) -> GuidingStatus {
    guard(|| {
        // SAFETY: forwarded.
        let Some(b) = (unsafe { buffer.as_mut() }) else {
            return Ok(());
        };
        if !b.data.is_null() {
            let slice = std::ptr::slice_from_raw_parts_mut(b.data, b.len);
            // SAFETY: `data`/`len` came from `from_vec`'s Box::into_raw.
            drop(unsafe { Box::from_raw(slice) });
        }
        b.data = std::ptr::null_mut();
        b.len = 0;
        Ok(())
    })
}
