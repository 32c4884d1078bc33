//! Status codes, the thread-local error message, and the guard every
//! exported function runs its body in (no panic crosses the boundary).

use std::cell::RefCell;
use std::ffi::{CString, c_char};
use std::panic::{AssertUnwindSafe, catch_unwind};

/// What a call did. `GUIDING_STATUS_OK` is 0; on anything else
/// [`guiding_last_error`] holds the reason and the outputs are left as
/// they were (but for `guiding_glt_record_light`'s outcome, which says
/// the record was dropped).
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum GuidingStatus {
    /// The call did what it says.
    Ok = 0,
    /// A required pointer was null.
    NullPointer = 1,
    /// A number was NaN, infinite or out of range, or an array's length
    /// impossible.
    InvalidArgument = 2,
    /// A configuration field was out of range (the crate's `ConfigError`).
    InvalidConfig = 3,
    /// No light tree can be built from the emitters, or the scene's bounds
    /// are empty or not finite.
    BuildFailed = 4,
    /// The bytes are not a saved light tree or guide of this kind, or were
    /// saved over another light tree.
    LoadFailed = 5,
    /// Two guides that cannot be merged (not copies of one guide after the
    /// same refinements).
    Incompatible = 6,
    /// A panic inside the crate, caught at the boundary (a bug: please
    /// report it). A guide that panicked while refining answers this from
    /// then on.
    Panic = 7,
    /// The guide cannot be written as a GPU snapshot (the message says
    /// why).
    SnapshotFailed = 8,
}

/// A failure: its status and message.
pub(crate) struct Failure {
    pub status: GuidingStatus,
    pub message: String,
}

impl Failure {
    pub fn new(status: GuidingStatus, message: impl Into<String>) -> Self {
        Self {
            status,
            message: message.into(),
        }
    }
    pub fn invalid(message: impl Into<String>) -> Self {
        Self::new(GuidingStatus::InvalidArgument, message)
    }
    pub fn null(name: &str) -> Self {
        Self::new(GuidingStatus::NullPointer, format!("{name} is null"))
    }
    /// A guide's constructor's error: its configuration's, or its build's.
    pub fn built(e: guiding::Error) -> Self {
        match e {
            guiding::Error::Config(c) => Self::new(GuidingStatus::InvalidConfig, c.to_string()),
            e => Self::new(GuidingStatus::BuildFailed, e.to_string()),
        }
    }
}

thread_local! {
    static LAST_ERROR: RefCell<CString> = RefCell::new(CString::default());
}

fn set_last_error(message: &str) {
    let text = CString::new(message.replace('\0', " ")).unwrap_or_default();
    LAST_ERROR.with(|e| *e.borrow_mut() = text);
}

/// Runs `body`, catching panics: the status to return, with the message
/// left in [`guiding_last_error`] on failure.
pub(crate) fn guard(body: impl FnOnce() -> Result<(), Failure>) -> GuidingStatus {
    match catch_unwind(AssertUnwindSafe(body)) {
        Ok(Ok(())) => GuidingStatus::Ok,
        Ok(Err(f)) => {
            set_last_error(&f.message);
            f.status
        }
        Err(payload) => {
            let what = payload
                .downcast_ref::<&str>()
                .map(|s| s.to_string())
                .or_else(|| payload.downcast_ref::<String>().cloned())
                .unwrap_or_else(|| "a panic".into());
            set_last_error(&format!("panic inside the guiding crate: {what}"));
            GuidingStatus::Panic
        }
    }
}

/// This thread's message for its last failed call (an empty string before
/// any). Valid until this thread's next failing call; never null.
#[unsafe(no_mangle)]
pub extern "C" fn guiding_last_error() -> *const c_char {
    LAST_ERROR.with(|e| e.borrow().as_ptr())
}

/// `p` as a reference, or a null-pointer failure naming it.
///
/// # Safety
/// A non-null `p` must point to a live, aligned `T` for `'a`.
pub(crate) unsafe fn get<'a, T>(p: *const T, name: &str) -> Result<&'a T, Failure> {
    // SAFETY: the caller promises a non-null `p` is valid for 'a.
    unsafe { p.as_ref() }.ok_or_else(|| Failure::null(name))
}

/// `p` as a mutable reference, or a null-pointer failure naming it.
///
/// # Safety
/// A non-null `p` must point to a live, aligned `T` for `'a`, used by no
/// one else meanwhile.
pub(crate) unsafe fn get_mut<'a, T>(p: *mut T, name: &str) -> Result<&'a mut T, Failure> {
    // SAFETY: as above, and exclusive.
    unsafe { p.as_mut() }.ok_or_else(|| Failure::null(name))
}

/// `len` elements from `p` (null allowed when `len` is 0).
///
/// # Safety
/// A non-null `p` must point to `len` live, initialised `T`s.
pub(crate) unsafe fn slice<'a, T>(p: *const T, len: usize, name: &str) -> Result<&'a [T], Failure> {
    if len == 0 {
        return Ok(&[]);
    }
    if p.is_null() {
        return Err(Failure::null(name));
    }
    if len > isize::MAX as usize / size_of::<T>().max(1) {
        return Err(Failure::invalid(format!(
            "{name}: {len} elements cannot be an array"
        )));
    }
    // SAFETY: non-null, and the caller promises `len` valid elements.
    Ok(unsafe { std::slice::from_raw_parts(p, len) })
}

/// Writes `value` through `out`.
///
/// # Safety
/// A non-null `out` must point to writable memory for a `T`.
pub(crate) unsafe fn put<T>(out: *mut T, value: T, name: &str) -> Result<(), Failure> {
    if out.is_null() {
        return Err(Failure::null(name));
    }
    // SAFETY: non-null and writable by the caller's promise; `write` does
    // not read (or drop) what was there.
    unsafe { out.write(value) };
    Ok(())
}

/// Three finite floats from `p`.
///
/// # Safety
/// A non-null `p` must point to 3 floats.
pub(crate) unsafe fn vec3(p: *const f32, name: &str) -> Result<guiding::glam::Vec3, Failure> {
    // SAFETY: forwarded.
    let s = unsafe { slice(p, 3, name) }?;
    finite3([s[0], s[1], s[2]], name)
}

/// The vector of `a`, or an invalid-argument failure when it is not finite.
pub(crate) fn finite3(a: [f32; 3], name: &str) -> Result<guiding::glam::Vec3, Failure> {
    if a.iter().all(|x| x.is_finite()) {
        Ok(guiding::glam::Vec3::from(a))
    } else {
        Err(Failure::invalid(format!("{name} = {a:?} is not finite")))
    }
}
