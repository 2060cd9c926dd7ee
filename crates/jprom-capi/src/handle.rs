//! Opaque handles: a `Box` tagged with a per-kind magic number and recorded in a registry of
//! live handles.
//!
//! Every call looks the pointer up in the registry *before* dereferencing it, so a freed
//! handle, a double free, or a handle of another kind is reported as `JPROM_INVALID_HANDLE`
//! without touching freed memory. This is best-effort: once the allocator reuses a freed
//! handle's address for a new handle of the same kind, the stale pointer aliases the new one.
//! The magic number inside the handle is checked too and overwritten on free.
//!
//! Adding a kind (e.g. `jprom_basis`) takes a struct with a `magic` field and an
//! `impl Handle` with a fresh magic value.

use super::status::jprom_status::*;
use super::status::FfiError;
use std::collections::BTreeMap;
use std::sync::Mutex;

/// Live handles: address -> magic of their kind.
static LIVE: Mutex<BTreeMap<usize, u64>> = Mutex::new(BTreeMap::new());

fn live() -> std::sync::MutexGuard<'static, BTreeMap<usize, u64>> {
    LIVE.lock().unwrap_or_else(|poisoned| poisoned.into_inner())
}

/// Value stored in a freed handle's magic field.
const FREED_MAGIC: u64 = 0xDEAD_F4EE_DEAD_F4EE;

/// A kind of opaque handle.
pub(crate) trait Handle: Sized + Send + 'static {
    /// Distinct per kind, never `FREED_MAGIC`.
    const MAGIC: u64;
    /// Type name shown in messages.
    const KIND: &'static str;
    fn magic_mut(&mut self) -> &mut u64;
    fn magic(&self) -> u64;
}

/// Moves `value` to the heap, registers it, and returns the pointer handed to C.
pub(crate) fn into_raw<T: Handle>(value: T) -> *mut T {
    let p = Box::into_raw(Box::new(value));
    live().insert(p as usize, T::MAGIC);
    p
}

fn check<T: Handle>(p: *const T, name: &str) -> Result<(), FfiError> {
    if p.is_null() {
        return Err(FfiError::null(name));
    }
    let entry = live().get(&(p as usize)).copied();
    registry_verdict::<T>(entry, name)
}

fn registry_verdict<T: Handle>(entry: Option<u64>, name: &str) -> Result<(), FfiError> {
    match entry {
        Some(m) if m == T::MAGIC => Ok(()),
        Some(_) => Err(FfiError::new(JPROM_INVALID_HANDLE, format!("'{name}' is a handle of another kind, not a {}", T::KIND))),
        None => Err(FfiError::new(JPROM_INVALID_HANDLE, format!("'{name}' is not a live {} (freed or never created)", T::KIND))),
    }
}

/// Shared access to a live handle.
///
/// # Safety
/// The handle must not be mutated or freed concurrently (see the header's thread-safety note).
pub(crate) unsafe fn get<'a, T: Handle>(p: *const T, name: &str) -> Result<&'a T, FfiError> {
    check(p, name)?;
    let r = &*p;
    if r.magic() != T::MAGIC {
        return Err(FfiError::new(JPROM_INVALID_HANDLE, format!("'{name}' is corrupted (bad magic)")));
    }
    Ok(r)
}

/// Exclusive access to a live handle.
///
/// # Safety
/// As [`get`]; additionally no other reference to the handle may be in use.
pub(crate) unsafe fn get_mut<'a, T: Handle>(p: *mut T, name: &str) -> Result<&'a mut T, FfiError> {
    check(p, name)?;
    let r = &mut *p;
    if r.magic() != T::MAGIC {
        return Err(FfiError::new(JPROM_INVALID_HANDLE, format!("'{name}' is corrupted (bad magic)")));
    }
    Ok(r)
}

/// Frees a handle: NULL is a no-op, a pointer that is not a live handle of this kind is
/// `JPROM_INVALID_HANDLE` (nothing is freed).
///
/// # Safety
/// No other thread may use the handle during or after the call.
pub(crate) unsafe fn free<T: Handle>(p: *mut T, name: &str) -> Result<(), FfiError> {
    if p.is_null() {
        return Ok(());
    }
    {
        let mut reg = live();
        let entry = reg.get(&(p as usize)).copied();
        registry_verdict::<T>(entry, name)?;
        reg.remove(&(p as usize));
    }
    let mut b = Box::from_raw(p);
    *b.magic_mut() = FREED_MAGIC;
    drop(b);
    Ok(())
}

/// Number of live handles of all kinds (for leak tests).
pub(crate) fn live_count() -> usize {
    live().len()
}
