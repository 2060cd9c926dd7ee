//! Options structs that grow (the ABI policy in the README).
//!
//! Every options struct starts with `size_t struct_size`. A release may append fields, never
//! remove, reorder or retype one. A caller compiled against an older `jprom.h` has the older,
//! smaller struct:
//! - it fills it with `jprom_*_options_default(out)`, whose exported symbol writes the first
//!   version's fields only (it cannot know the caller's size). In the header that name is a
//!   macro for `jprom_*_options_init(out, sizeof *out)`, so code compiled against a newer
//!   header gets every field it knows;
//! - it passes the older `struct_size`: the library reads that prefix and takes the defaults for
//!   the fields the caller does not know. A size that is not the size of a released version is
//!   refused with `JPROM_BAD_SIZE`, before anything past `struct_size` is read.

use crate::status::jprom_status::JPROM_BAD_SIZE;
use crate::status::FfiError;

/// An options struct with released versions.
pub(crate) trait Versioned: Copy {
    /// The C name, for messages.
    const NAME: &'static str;
    /// `struct_size` of every released version, oldest first; the last is this version's
    /// `sizeof`.
    const SIZES: &'static [usize];
    /// The defaults, as `jprom_*_options_default` writes them.
    fn defaults() -> Self;
}

/// The message for a `struct_size` of no released version.
fn unknown_size<T: Versioned>(size: usize) -> FfiError {
    let known: Vec<String> = T::SIZES.iter().map(|s| s.to_string()).collect();
    FfiError::new(
        JPROM_BAD_SIZE,
        format!("{}.struct_size is {size}, not the size of a released version ({} bytes); fill the options with {}_default", T::NAME, known.join(", "), T::NAME),
    )
}

/// Writes the defaults of the version of size `size` at `out` (its first `size` bytes, with
/// `struct_size = size`).
///
/// # Safety
/// `out` must be NULL or point to `size` writable bytes.
pub(crate) unsafe fn write_defaults<T: Versioned>(out: *mut T, size: usize) -> Result<(), FfiError> {
    if out.is_null() {
        return Err(FfiError::null("out"));
    }
    if !T::SIZES.contains(&size) {
        return Err(unknown_size::<T>(size));
    }
    let d = T::defaults();
    std::ptr::copy_nonoverlapping((&d as *const T).cast::<u8>(), out.cast::<u8>(), size);
    std::ptr::write_unaligned(out.cast::<usize>(), size);
    Ok(())
}

/// Reads the caller's options at `p` (checked for NULL as argument `arg`): the prefix its
/// `struct_size` says it has, the defaults for the rest.
///
/// # Safety
/// If non-NULL, `p` must point to at least `struct_size` readable bytes, `struct_size` being
/// its first field.
pub(crate) unsafe fn read_options<T: Versioned>(p: *const T, arg: &str) -> Result<T, FfiError> {
    if p.is_null() {
        return Err(FfiError::null(arg));
    }
    let size = std::ptr::read_unaligned(p.cast::<usize>());
    debug_assert_eq!(T::SIZES.last(), Some(&std::mem::size_of::<T>()));
    if !T::SIZES.contains(&size) {
        return Err(unknown_size::<T>(size));
    }
    let mut out = T::defaults();
    // SAFETY: `size <= size_of::<T>()` (a released size), `p` holds `size` bytes, and every
    // field of a released prefix lies wholly inside it (checked by the offset assertions
    // next to each struct).
    std::ptr::copy_nonoverlapping(p.cast::<u8>(), (&mut out as *mut T).cast::<u8>(), size);
    Ok(out)
}
