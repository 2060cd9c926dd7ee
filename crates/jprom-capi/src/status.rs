//! Status codes, the thread-local last-error message, and the library version.
//!
//! Every exported function returns a [`jprom_status`]. On failure a human-readable message is
//! stored per thread; [`jprom_last_error_message`] and [`jprom_last_error_copy`] read it.

use jprom::error::JpError;
use std::cell::RefCell;
use std::ffi::{c_char, c_int, CString};

/// Result of every jprom call. The numbers are part of the ABI: they are never renumbered,
/// and a retired code stays reserved.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[allow(non_camel_case_types)]
pub enum jprom_status {
    /// Success.
    JPROM_OK = 0,
    /// A required pointer argument was NULL.
    JPROM_NULL_ARGUMENT = 1,
    /// An array or matrix has the wrong size, a size overflows, exceeds a documented
    /// `JPROM_MAX_*` cap, or would need more memory than the budget (`jprom_set_memory_budget`).
    JPROM_BAD_SIZE = 2,
    /// A value is out of range: NaN, negative stiffness, DoF index too large, bad option, ...
    JPROM_INVALID_VALUE = 3,
    /// A matrix that must be factorised is singular.
    JPROM_SINGULAR_MATRIX = 4,
    /// An iterative solver did not converge.
    JPROM_NO_CONVERGENCE = 5,
    /// A file could not be read or written, or is not a jprom file of the expected kind.
    JPROM_IO = 6,
    /// A bug inside jprom (a Rust panic) was caught at the boundary. Please report it.
    JPROM_PANIC = 7,
    /// The caller's callback asked to stop.
    JPROM_CANCELLED = 8,
    /// A handle is not a live handle of the expected kind (freed, double free, wrong type).
    JPROM_INVALID_HANDLE = 9,
    /// An eigenvalue solver failed.
    JPROM_EIGEN = 10,
    /// A file is malformed (the message gives the line).
    JPROM_PARSE = 11,
    /// A user callback element (`jprom_model_add_element_callback`) returned nonzero or gave
    /// a non-finite force or Jacobian; the message names the element and the time sample
    /// ("element 2: callback returned 3 at sample 17").
    JPROM_CALLBACK_ERROR = 12,
}

/// An error at the C boundary: a status and its message.
#[derive(Debug)]
pub(crate) struct FfiError {
    pub status: jprom_status,
    pub message: String,
}

impl FfiError {
    pub fn new(status: jprom_status, message: impl Into<String>) -> Self {
        FfiError { status, message: message.into() }
    }
    pub fn null(name: &str) -> Self {
        Self::new(jprom_status::JPROM_NULL_ARGUMENT, format!("argument '{name}' is NULL"))
    }
}

/// The single mapping from the core's error type to the C status codes.
pub(crate) fn status_of(e: &JpError) -> jprom_status {
    use jprom_status::*;
    match e {
        JpError::BadSize { .. } => JPROM_BAD_SIZE,
        JpError::InvalidValue { .. } => JPROM_INVALID_VALUE,
        JpError::SingularMatrix { .. } => JPROM_SINGULAR_MATRIX,
        JpError::NoConvergence { .. } => JPROM_NO_CONVERGENCE,
        JpError::Io { .. } => JPROM_IO,
        JpError::Parse { .. } => JPROM_PARSE,
        JpError::Cancelled => JPROM_CANCELLED,
        JpError::Eigen { .. } => JPROM_EIGEN,
        JpError::TooLarge { .. } | JpError::TooLong { .. } | JpError::OverLimit { .. } => JPROM_BAD_SIZE,
        JpError::Callback { .. } => JPROM_CALLBACK_ERROR,
    }
}

impl From<JpError> for FfiError {
    fn from(e: JpError) -> Self {
        let message = match &e {
            JpError::TooLarge { .. } => format!("{e} (raise it with jprom_set_memory_budget if the machine has the memory)"),
            JpError::TooLong { .. } => format!("{e} (raise it with jprom_set_time_budget)"),
            _ => e.to_string(),
        };
        FfiError { status: status_of(&e), message }
    }
}

thread_local! {
    static LAST_ERROR: RefCell<CString> = RefCell::new(CString::default());
}

/// Replaces this thread's last-error message (interior NULs become spaces).
pub(crate) fn set_last_error(message: &str) {
    let clean = message.replace('\0', " ");
    let c = CString::new(clean).unwrap_or_default();
    LAST_ERROR.with(|m| *m.borrow_mut() = c);
}

/// Clears the message at the start of every call, so it always describes the latest call.
pub(crate) fn clear_last_error() {
    LAST_ERROR.with(|m| {
        let mut m = m.borrow_mut();
        if !m.as_bytes().is_empty() {
            *m = CString::default();
        }
    });
}

/// Turns the outcome of a guarded body into a status, recording the message on failure.
pub(crate) fn finish(outcome: std::thread::Result<Result<(), FfiError>>) -> jprom_status {
    match outcome {
        Ok(Ok(())) => {
            // a nested jprom call made by a callback during this one may have failed: the
            // message must describe this call, which succeeded
            clear_last_error();
            jprom_status::JPROM_OK
        }
        Ok(Err(e)) => {
            set_last_error(&e.message);
            e.status
        }
        Err(payload) => {
            let what = payload
                .downcast_ref::<&str>()
                .map(|s| s.to_string())
                .or_else(|| payload.downcast_ref::<String>().cloned())
                .unwrap_or_else(|| "unknown panic payload".to_string());
            set_last_error(&format!("internal error (panic) in jprom: {what}"));
            jprom_status::JPROM_PANIC
        }
    }
}

/// The message of the last failed jprom call on this thread, NUL-terminated UTF-8; the empty
/// string if the last call succeeded. Never NULL. Owned by the library: valid until the next
/// jprom call on the same thread; copy it to keep it.
#[no_mangle]
pub extern "C" fn jprom_last_error_message() -> *const c_char {
    LAST_ERROR.with(|m| m.borrow().as_ptr())
}

/// Copies the last error message of this thread into `buf` (capacity `len` bytes), always
/// NUL-terminating when `len > 0`, like `snprintf`. If `written` is not NULL it receives the
/// full message length in bytes (without the NUL), so truncation is `*written >= len`.
/// Does not change the stored message.
///
/// Returns `JPROM_OK`, `JPROM_BAD_SIZE` if the message was truncated, or
/// `JPROM_NULL_ARGUMENT` if `buf` is NULL while `len > 0`.
#[no_mangle]
pub unsafe extern "C" fn jprom_last_error_copy(buf: *mut c_char, len: usize, written: *mut usize) -> jprom_status {
    let outcome = std::panic::catch_unwind(|| LAST_ERROR.with(|m| unsafe { copy_text(m.borrow().as_bytes(), buf, len, written) }));
    outcome.unwrap_or(jprom_status::JPROM_PANIC)
}

/// The one convention of every text-copying function (`jprom_*_copy`), like `snprintf`:
/// `*written` (if not NULL) receives the full length in bytes without the NUL; when `len > 0`
/// the first `len - 1` bytes at most are written and NUL-terminated. Returns `JPROM_OK` if the
/// whole text fitted, `JPROM_BAD_SIZE` if it was truncated (`*written >= len`), and
/// `JPROM_NULL_ARGUMENT` if `buf` is NULL while `len > 0`. Sets no error message.
///
/// # Safety
/// `buf` must hold `len` writable bytes (or be NULL), `written` be valid or NULL.
pub(crate) unsafe fn copy_text(text: &[u8], buf: *mut c_char, len: usize, written: *mut usize) -> jprom_status {
    if !written.is_null() {
        *written = text.len();
    }
    if len == 0 {
        return if text.is_empty() { jprom_status::JPROM_OK } else { jprom_status::JPROM_BAD_SIZE };
    }
    if buf.is_null() {
        return jprom_status::JPROM_NULL_ARGUMENT;
    }
    let n = text.len().min(len - 1);
    std::ptr::copy_nonoverlapping(text.as_ptr() as *const c_char, buf, n);
    *buf.add(n) = 0;
    if n < text.len() {
        jprom_status::JPROM_BAD_SIZE
    } else {
        jprom_status::JPROM_OK
    }
}

/// [`copy_text`] of a result's text as an [`FfiError`]: `JPROM_NULL_ARGUMENT` for a NULL
/// `buf`, `JPROM_BAD_SIZE` with how much of the text `buf` holds when truncated.
///
/// # Safety
/// As [`copy_text`].
pub(crate) unsafe fn copy_result_text(text: &str, buf: *mut c_char, len: usize, written: *mut usize) -> Result<(), FfiError> {
    match copy_text(text.as_bytes(), buf, len, written) {
        jprom_status::JPROM_OK => Ok(()),
        jprom_status::JPROM_NULL_ARGUMENT => Err(FfiError::null("buf")),
        status => Err(FfiError::new(status, format!("buf: {len} bytes hold {} of the text's {} (and the NUL)", len.saturating_sub(1), text.len()))),
    }
}

/// Name of a status code ("JPROM_OK", ...), or "JPROM_UNKNOWN_STATUS". Static storage.
#[no_mangle]
pub extern "C" fn jprom_status_name(status: c_int) -> *const c_char {
    let s: &'static [u8] = match status {
        0 => b"JPROM_OK\0",
        1 => b"JPROM_NULL_ARGUMENT\0",
        2 => b"JPROM_BAD_SIZE\0",
        3 => b"JPROM_INVALID_VALUE\0",
        4 => b"JPROM_SINGULAR_MATRIX\0",
        5 => b"JPROM_NO_CONVERGENCE\0",
        6 => b"JPROM_IO\0",
        7 => b"JPROM_PANIC\0",
        8 => b"JPROM_CANCELLED\0",
        9 => b"JPROM_INVALID_HANDLE\0",
        10 => b"JPROM_EIGEN\0",
        11 => b"JPROM_PARSE\0",
        12 => b"JPROM_CALLBACK_ERROR\0",
        _ => b"JPROM_UNKNOWN_STATUS\0",
    };
    s.as_ptr() as *const c_char
}

/// Major version of the library this header was generated for (checked against Cargo.toml by
/// tests/ffi_header.rs).
pub const JPROM_VERSION_MAJOR: u32 = 0;
/// Minor version.
pub const JPROM_VERSION_MINOR: u32 = 3;
/// Patch version.
pub const JPROM_VERSION_PATCH: u32 = 0;

/// Version of the linked library, "MAJOR.MINOR.PATCH", static storage. Compare with the
/// `JPROM_VERSION_*` macros to detect a header/library mismatch.
#[no_mangle]
pub extern "C" fn jprom_version() -> *const c_char {
    concat!(env!("CARGO_PKG_VERSION"), "\0").as_ptr() as *const c_char
}
