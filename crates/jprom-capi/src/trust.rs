//! Whether a self-correcting sweep's result can be trusted, and the error it judged at each
//! point (docs/formulation.md §10.7): what a host code reads before it reports a reduced
//! sweep's peak as the resonance.

use super::guard::{ffi_guard, out_arg};
use super::handle;
use super::solve::jprom_sweep_result;
use super::status::jprom_status::{self, *};
use super::status::FfiError;
use libc::{c_char, c_int};

fn not_self_correcting() -> FfiError {
    FfiError::new(JPROM_INVALID_VALUE, "this sweep is not a self-correcting sweep's result (or was saved without its verdict)")
}

/// Whether the result of `jprom_rom_sweep_adaptive` can be trusted: `*out` = 1 when its final
/// pass covered the band and every point's judged error (`jprom_sweep_result_point_judged_error`)
/// is within `jprom_jp_options.threshold`, else 0 (`jprom_sweep_result_trust_reason_copy` says
/// why). The peak of a sweep that is not trusted is not the reduced model's resonance.
/// `JPROM_INVALID_VALUE` for any other sweep and for one loaded from a file saved without the
/// verdict (before 0.3); nothing is written then. Since 0.3.
#[no_mangle]
pub unsafe extern "C" fn jprom_sweep_result_trusted(sweep: *const jprom_sweep_result, out: *mut c_int) -> jprom_status {
    ffi_guard!({
        let out = out_arg(out, "out")?;
        *out = c_int::from(handle::get(sweep, "sweep")?.record.trust.as_ref().ok_or_else(not_self_correcting)?.trusted);
        Ok(())
    })
}

/// Copies why a self-correcting sweep's result is not trusted (empty if it is) into `buf`, with
/// the convention of `jprom_last_error_copy`: NUL-terminated, `*written` = full length,
/// `JPROM_BAD_SIZE` if truncated. `JPROM_INVALID_VALUE` as `jprom_sweep_result_trusted`.
/// Since 0.3.
#[no_mangle]
pub unsafe extern "C" fn jprom_sweep_result_trust_reason_copy(sweep: *const jprom_sweep_result, buf: *mut c_char, len: usize, written: *mut usize) -> jprom_status {
    ffi_guard!({
        let t = handle::get(sweep, "sweep")?.record.trust.as_ref().ok_or_else(not_self_correcting)?;
        crate::status::copy_result_text(t.reason.as_deref().unwrap_or_default(), buf, len, written)
    })
}

/// The judged error `e_1` at point `index` of a self-correcting sweep: the checked error where
/// the point was checked against the condensed full order (a bound on the actual error (44)
/// where the full-order Newton iteration from it contracts, the actual error against the
/// full-order solution reached from it elsewhere, `+inf` where none was reached), `e*_1`
/// elsewhere. Above the threshold the point is not good. `JPROM_INVALID_VALUE` for any other
/// sweep, one saved without it, or `index` out of range; nothing is written then. Since 0.3.
#[no_mangle]
pub unsafe extern "C" fn jprom_sweep_result_point_judged_error(sweep: *const jprom_sweep_result, index: usize, out: *mut f64) -> jprom_status {
    ffi_guard!({
        let out = out_arg(out, "out")?;
        let s = handle::get(sweep, "sweep")?;
        s.record.trust.as_ref().ok_or_else(not_self_correcting)?;
        crate::guard::index_arg(&s.record.sweep.points, index, "point")?;
        *out = s.record.judged_error(index).ok_or_else(not_self_correcting)?;
        Ok(())
    })
}
