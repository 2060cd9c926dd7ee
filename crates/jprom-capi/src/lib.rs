//! The C ABI of jprom: the only place with `extern "C"`. Thin: converts arguments, calls the
//! Rust API, converts results; no numerics here.
//!
//! Conventions (also at the top of `include/jprom.h`):
//! - every function returns a [`status::jprom_status`]; on failure the thread-local last-error
//!   message says why; results come through out-parameters written only on success;
//! - opaque handles (`jprom_model`, `jprom_solution`, `jprom_sweep`, ...) are created through
//!   `T **out` and released by `*_free`, which accepts NULL; freed or foreign pointers are
//!   detected where possible ([`handle`]);
//! - matrices are column-major `double*` with explicit sizes, indices are 0-based `size_t`;
//! - no panic crosses the boundary ([`guard`]).
#![allow(clippy::missing_safety_doc)]

pub(crate) mod guard;
pub(crate) mod handle;
pub mod events;
pub mod fe;
pub mod jp;
pub mod limits;
pub mod model;
pub mod parallelism;
pub mod solve;
pub mod status;
pub mod trust;
mod versioned;

pub use events::*;
pub use fe::*;
pub use jp::*;
pub use limits::*;
pub use model::*;
pub use parallelism::*;
pub use solve::*;
pub use status::*;
pub use trust::*;

#[cfg(test)]
mod tests;

/// Number of live handles of all kinds in the process (diagnostic, e.g. for leak checks in
/// tests: it returns to its earlier value once everything created has been freed).
#[no_mangle]
pub unsafe extern "C" fn jprom_live_handle_count(out: *mut usize) -> status::jprom_status {
    guard::ffi_guard!({
        *guard::out_arg(out, "out")? = handle::live_count();
        Ok(())
    })
}
