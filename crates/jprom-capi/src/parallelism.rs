//! Results that do not depend on the thread count, from C ([`jprom::parallelism`]).

use super::guard::{ffi_guard, out_arg};
use super::status::jprom_status;
use std::ffi::c_int;

/// With `on` nonzero, every dense and sparse kernel (LU, Cholesky, eigen solves, products)
/// runs on one thread, so that results are the same on any number of threads
/// (`RAYON_NUM_THREADS`); the independent tasks above them (the contact patterns of a JP
/// prediction) still run in parallel. With `on` = 0, kernels run on rayon's threads (the
/// default). Without it, a JP basis can differ between thread counts: its contact patterns
/// switch between stick and slip at thresholds, and the kernels' round-off differs with the
/// thread count (README, "Reproducibility"). Process-wide, like the memory budget; set it
/// before the calls it should govern. Since 0.3.
#[no_mangle]
pub extern "C" fn jprom_set_reproducible(on: c_int) -> jprom_status {
    ffi_guard!({
        jprom::parallelism::set_reproducible(on != 0);
        Ok(())
    })
}

/// Writes 1 to `*out` if kernels run on one thread (`jprom_set_reproducible`), else 0.
/// Since 0.3.
#[no_mangle]
pub unsafe extern "C" fn jprom_reproducible(out: *mut c_int) -> jprom_status {
    ffi_guard!({
        *out_arg(out, "out")? = c_int::from(jprom::parallelism::reproducible());
        Ok(())
    })
}
