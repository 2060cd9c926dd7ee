//! The panic boundary and the argument checks run before any dereference.

use super::status::FfiError;
use super::status::jprom_status::*;
use std::ffi::{c_char, CStr};

/// Runs an export's body (a block evaluating to `Result<(), FfiError>`) behind
/// `catch_unwind`, clears the thread's last error first, and returns a `jprom_status`.
/// Every `extern "C"` function of jprom (except the message readers) goes through it.
macro_rules! ffi_guard {
    ($body:block) => {{
        $crate::status::clear_last_error();
        let outcome = ::std::panic::catch_unwind(::std::panic::AssertUnwindSafe(
            || -> ::std::result::Result<(), $crate::status::FfiError> { $body },
        ));
        $crate::status::finish(outcome)
    }};
}
pub(crate) use ffi_guard;

/// The name for logs of the value `value` of a C enum whose values are `0..names.len()`, from
/// `names` in value order; "unknown" for any other value (a newer library's value read by an
/// older caller, or garbage). Static storage: the caller must not free it.
pub(crate) fn enum_name(value: std::ffi::c_int, names: &[&'static CStr]) -> *const c_char {
    usize::try_from(value).ok().and_then(|i| names.get(i)).copied().unwrap_or(c"unknown").as_ptr()
}

/// Largest element count accepted for one array (keeps `len * size_of` far from overflow).
const MAX_LEN: usize = (isize::MAX as usize) / 16;

/// Borrows `len` elements at `ptr`. A zero length may come with a NULL pointer.
///
/// # Safety
/// If non-NULL, `ptr` must point to `len` readable, initialised elements that outlive `'a`.
pub(crate) unsafe fn slice_arg<'a, T>(ptr: *const T, len: usize, name: &str) -> Result<&'a [T], FfiError> {
    if len == 0 {
        return Ok(&[]);
    }
    if ptr.is_null() {
        return Err(FfiError::null(name));
    }
    if len > MAX_LEN {
        return Err(FfiError::new(JPROM_BAD_SIZE, format!("size of '{name}' ({len}) is too large")));
    }
    Ok(std::slice::from_raw_parts(ptr, len))
}

/// Mutable counterpart of [`slice_arg`], for caller-owned output buffers.
///
/// # Safety
/// If non-NULL, `ptr` must point to `len` writable elements that outlive `'a`.
pub(crate) unsafe fn slice_out<'a, T>(ptr: *mut T, len: usize, name: &str) -> Result<&'a mut [T], FfiError> {
    if len == 0 {
        return Ok(&mut []);
    }
    if ptr.is_null() {
        return Err(FfiError::null(name));
    }
    if len > MAX_LEN {
        return Err(FfiError::new(JPROM_BAD_SIZE, format!("size of '{name}' ({len}) is too large")));
    }
    Ok(std::slice::from_raw_parts_mut(ptr, len))
}

/// Checks an output pointer for NULL.
pub(crate) fn out_arg<'a, T>(ptr: *mut T, name: &str) -> Result<&'a mut T, FfiError> {
    // SAFETY: non-NULL output pointers are valid by the API contract.
    unsafe { ptr.as_mut() }.ok_or_else(|| FfiError::null(name))
}

/// Item `index` of a result's list of `what`s (`point`, `event`, ...), or `JPROM_INVALID_VALUE`
/// ("`what` index `index` >= `len`").
pub(crate) fn index_arg<'a, T>(items: &'a [T], index: usize, what: &str) -> Result<&'a T, FfiError> {
    items.get(index).ok_or_else(|| FfiError::new(JPROM_INVALID_VALUE, format!("{what} index {index} >= {}", items.len())))
}

/// A caller buffer must hold at least `needed` elements.
pub(crate) fn check_capacity(name: &str, needed: usize, got: usize) -> Result<(), FfiError> {
    if got < needed {
        return Err(FfiError::new(
            JPROM_BAD_SIZE,
            format!("buffer '{name}' holds {got} elements, {needed} are needed"),
        ));
    }
    Ok(())
}

/// `a * b` or `JPROM_BAD_SIZE`.
pub(crate) fn mul_size(name: &str, a: usize, b: usize) -> Result<usize, FfiError> {
    a.checked_mul(b)
        .filter(|&n| n <= MAX_LEN)
        .ok_or_else(|| FfiError::new(JPROM_BAD_SIZE, format!("size of '{name}' overflows ({a} x {b})")))
}

/// A NUL-terminated UTF-8 path.
///
/// # Safety
/// If non-NULL, `ptr` must point to a NUL-terminated string.
pub(crate) unsafe fn path_arg(ptr: *const c_char, name: &str) -> Result<std::path::PathBuf, FfiError> {
    if ptr.is_null() {
        return Err(FfiError::null(name));
    }
    let s = CStr::from_ptr(ptr)
        .to_str()
        .map_err(|_| FfiError::new(JPROM_INVALID_VALUE, format!("'{name}' is not valid UTF-8")))?;
    if s.is_empty() {
        return Err(FfiError::new(JPROM_INVALID_VALUE, format!("'{name}' is empty")));
    }
    Ok(std::path::PathBuf::from(s))
}

/// A finite scalar, or `JPROM_INVALID_VALUE` naming it.
pub(crate) fn finite_arg(name: &str, v: f64) -> Result<f64, FfiError> {
    if v.is_finite() {
        Ok(v)
    } else {
        Err(FfiError::new(JPROM_INVALID_VALUE, format!("'{name}' must be finite, got {v}")))
    }
}

/// A caller's compressed-sparse-column `n x n` matrix `name` (`{name}_colptr[n + 1]` from 0,
/// non-decreasing; `{name}_rowind` and `{name}_values` of `colptr[n]` entries, rows `< n`),
/// checked, as its entries `(row, column, value)` in column order.
///
/// # Safety
/// As [`slice_arg`] for each of the three arrays.
pub(crate) unsafe fn csc_entries<'a>(
    name: &str,
    n: usize,
    colptr: *const usize,
    rowind: *const usize,
    values: *const f64,
) -> Result<Vec<(usize, usize, f64)>, FfiError> {
    let cp: &'a [usize] = slice_arg(colptr, n + 1, &format!("{name}_colptr"))?;
    if cp[0] != 0 || cp.windows(2).any(|w| w[1] < w[0]) {
        return Err(FfiError::new(JPROM_INVALID_VALUE, format!("{name}_colptr must start at 0 and be non-decreasing")));
    }
    let nnz = cp[n];
    jprom::memory::check(&format!("the {name} matrix ({nnz} entries)"), jprom::memory::bytes_of::<(usize, usize, f64)>(nnz as u128))?;
    let ri = slice_arg(rowind, nnz, &format!("{name}_rowind"))?;
    let va = slice_arg(values, nnz, &format!("{name}_values"))?;
    let mut entries = Vec::with_capacity(nnz);
    for j in 0..n {
        for p in cp[j]..cp[j + 1] {
            if ri[p] >= n {
                return Err(FfiError::new(JPROM_INVALID_VALUE, format!("{name}_rowind[{p}] = {} is >= n = {n}", ri[p])));
            }
            entries.push((ri[p], j, va[p]));
        }
    }
    Ok(entries)
}
