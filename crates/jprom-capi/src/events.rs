//! The folds, branch points and gaps of a sweep from C (docs/formulation.md §6.6): counts,
//! each event's kind, frequency, tolerance, place and amplitude, each gap's ends and reason.

use super::guard::{ffi_guard, out_arg};
use super::handle;
use super::solve::jprom_sweep_result;
use super::status::jprom_status;
use super::status::FfiError;
use jprom::hbm::{BranchEvent, EventKind, SweepGap};
use std::ffi::{c_char, c_int};

/// What a branch event is (`jprom_sweep_result_event`). The values never change.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[allow(non_camel_case_types)]
pub enum jprom_event_kind {
    /// The branch turns back in frequency (the tangent's frequency component changes sign).
    JPROM_EVENT_FOLD = 0,
    /// The bordered Jacobian's determinant changes sign on a smooth piece: another branch
    /// crosses this one there.
    JPROM_EVENT_BRANCH_POINT = 1,
}

impl From<EventKind> for jprom_event_kind {
    fn from(k: EventKind) -> Self {
        match k {
            EventKind::Fold => jprom_event_kind::JPROM_EVENT_FOLD,
            EventKind::BranchPoint => jprom_event_kind::JPROM_EVENT_BRANCH_POINT,
        }
    }
}

/// A short name for a `jprom_event_kind` value ("fold", "branch_point"; "unknown" for any
/// other value). Static storage: do not free.
#[no_mangle]
pub extern "C" fn jprom_event_kind_name(kind: c_int) -> *const c_char {
    // the words of EventKind::name, in the order of jprom_event_kind's values
    crate::guard::enum_name(kind, &[c"fold", c"branch_point"])
}

/// Number of folds and branch points located along a sweep, in the order the branch meets
/// them.
#[no_mangle]
pub unsafe extern "C" fn jprom_sweep_result_n_events(sweep: *const jprom_sweep_result, out: *mut usize) -> jprom_status {
    ffi_guard!({
        *out_arg(out, "out")? = handle::get(sweep, "sweep")?.record.sweep.events.len();
        Ok(())
    })
}

unsafe fn event<'a>(sweep: *const jprom_sweep_result, index: usize) -> Result<&'a BranchEvent, FfiError> {
    crate::guard::index_arg(&handle::get(sweep, "sweep")?.record.sweep.events, index, "event")
}

/// Event `index` of a sweep: its kind, angular frequency `omega` (rad/s), `omega_tolerance`
/// (the event lies within `omega +- omega_tolerance` along the branch), `after_point` (the
/// index of the sweep's point just before it) and the first-harmonic amplitude of the first
/// output there. Any of the out pointers may be NULL.
#[no_mangle]
pub unsafe extern "C" fn jprom_sweep_result_event(
    sweep: *const jprom_sweep_result,
    index: usize,
    kind: *mut jprom_event_kind,
    omega: *mut f64,
    omega_tolerance: *mut f64,
    after_point: *mut usize,
    amplitude: *mut f64,
) -> jprom_status {
    ffi_guard!({
        let e = event(sweep, index)?;
        if let Some(k) = kind.as_mut() {
            *k = e.kind.into();
        }
        if let Some(w) = omega.as_mut() {
            *w = e.omega;
        }
        if let Some(t) = omega_tolerance.as_mut() {
            *t = e.omega_tolerance;
        }
        if let Some(a) = after_point.as_mut() {
            *a = e.after_point;
        }
        if let Some(a) = amplitude.as_mut() {
            *a = e.amplitude;
        }
        Ok(())
    })
}

/// Number of parts of the band a sweep stepped over at fixed frequency (its gaps).
#[no_mangle]
pub unsafe extern "C" fn jprom_sweep_result_n_gaps(sweep: *const jprom_sweep_result, out: *mut usize) -> jprom_status {
    ffi_guard!({
        *out_arg(out, "out")? = handle::get(sweep, "sweep")?.record.sweep.gaps.len();
        Ok(())
    })
}

unsafe fn gap<'a>(sweep: *const jprom_sweep_result, index: usize) -> Result<&'a SweepGap, FfiError> {
    crate::guard::index_arg(&handle::get(sweep, "sweep")?.record.sweep.gaps, index, "gap")
}

/// Gap `index` of a sweep: the angular frequencies (rad/s) of the last point before it and of
/// the first point after it. Either pointer may be NULL.
#[no_mangle]
pub unsafe extern "C" fn jprom_sweep_result_gap(sweep: *const jprom_sweep_result, index: usize, from: *mut f64, to: *mut f64) -> jprom_status {
    ffi_guard!({
        let g = gap(sweep, index)?;
        if let Some(f) = from.as_mut() {
            *f = g.from;
        }
        if let Some(t) = to.as_mut() {
            *t = g.to;
        }
        Ok(())
    })
}

/// Copies why the continuation could not go on at gap `index` (the corrector's last error)
/// into `buf`, with the convention of `jprom_last_error_copy`: NUL-terminated, `*written` =
/// full length, `JPROM_BAD_SIZE` if truncated.
#[no_mangle]
pub unsafe extern "C" fn jprom_sweep_result_gap_reason_copy(sweep: *const jprom_sweep_result, index: usize, buf: *mut c_char, len: usize, written: *mut usize) -> jprom_status {
    ffi_guard!({
        let text = gap(sweep, index)?.reason.as_str();
        crate::status::copy_result_text(text, buf, len, written)
    })
}
