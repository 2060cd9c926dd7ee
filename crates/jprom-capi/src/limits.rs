//! Size caps and the memory budget from C. Sizes passed in by the caller (options, array
//! lengths) and read from files are checked against these before anything is allocated;
//! past them a call returns `JPROM_BAD_SIZE` with the size, the cap or the estimate.

use super::guard::{ffi_guard, out_arg};
use super::status::jprom_status;
use jprom::memory::MemoryBudget;
use jprom::time_budget::TimeBudget;

/// Highest harmonic `H` accepted in `jprom_hbm_options.harmonics`.
pub const JPROM_MAX_HARMONICS: usize = 64;
/// Most AFT samples per period accepted in `jprom_hbm_options.nt` (2^16).
pub const JPROM_MAX_NT: usize = 65536;
/// Most amplitude samples of a basis prediction (`n_samples` of `jprom_basis_predict` and
/// `jprom_jp_options`).
pub const JPROM_MAX_SAMPLES: usize = 10000;
/// Largest magnitude of any real input of a model: entries of `M`, `K` and the damping, the
/// damping coefficients, forces (the harmonic ones times their scale) and contact
/// parameters. Beyond it, or with a load whose static displacement scale
/// `|f|_inf / max_i K_ii` exceeds 1e50, a setter returns `JPROM_INVALID_VALUE` and leaves
/// the model unchanged.
pub const JPROM_MAX_MAGNITUDE: f64 = 1e100;

/// Sets the memory budget in bytes: the ceiling for what one request sized by the caller
/// (options, array lengths, file contents) may need. A request estimated above it returns
/// `JPROM_BAD_SIZE` with the estimate instead of allocating. `bytes = 0` restores the
/// default, 70 % of the machine's memory (or of the cgroup limit). Process-wide.
#[no_mangle]
pub extern "C" fn jprom_set_memory_budget(bytes: usize) -> jprom_status {
    ffi_guard!({
        MemoryBudget::set_global((bytes > 0).then(|| MemoryBudget::new(bytes)));
        Ok(())
    })
}

/// Sets the time budget in seconds: the ceiling for the estimated time of one stage whose
/// cost grows as a power of sizes from the caller (a JP prediction's dense eigenproblems of
/// order `2 H n` at a high harmonic count `H`). The estimate counts floating-point
/// operations at an assumed 1e10 per second, before any of that work; a stage estimated above
/// the budget returns `JPROM_BAD_SIZE` with the estimate. `seconds = 0` restores the default
/// of 3600 s; a negative or non-finite value is `JPROM_INVALID_VALUE` and changes nothing.
/// Process-wide.
#[no_mangle]
pub extern "C" fn jprom_set_time_budget(seconds: f64) -> jprom_status {
    ffi_guard!({
        TimeBudget::set_global((seconds != 0.0).then_some(TimeBudget { seconds }))?;
        Ok(())
    })
}

/// The time budget in force, in seconds (see `jprom_set_time_budget`).
#[no_mangle]
pub unsafe extern "C" fn jprom_time_budget(out: *mut f64) -> jprom_status {
    ffi_guard!({
        *out_arg(out, "out")? = TimeBudget::global().seconds;
        Ok(())
    })
}

/// The memory budget in force, in bytes (see `jprom_set_memory_budget`).
#[no_mangle]
pub unsafe extern "C" fn jprom_memory_budget(out: *mut usize) -> jprom_status {
    ffi_guard!({
        *out_arg(out, "out")? = MemoryBudget::global().bytes;
        Ok(())
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use jprom::limits;

    #[test]
    fn the_c_caps_are_the_library_caps() {
        assert_eq!(JPROM_MAX_HARMONICS, limits::MAX_HARMONICS);
        assert_eq!(JPROM_MAX_NT, limits::MAX_NT);
        assert_eq!(JPROM_MAX_SAMPLES, limits::MAX_SAMPLES);
        assert_eq!(JPROM_MAX_MAGNITUDE, limits::MAX_MAGNITUDE);
    }
}
