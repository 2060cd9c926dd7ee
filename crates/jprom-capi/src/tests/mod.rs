//! The C API driven from Rust (the C, C++ and Fortran programs are in `tests/`): files,
//! reduced models, threads, hostile input.

// the deprecated functions are tested as well: they stay in the ABI
#![allow(deprecated)]

mod ffi_callback;
mod ffi_damping;
mod ffi_elements;
mod ffi_events;
mod ffi_fe;
mod ffi_files;
mod ffi_hardening;
mod ffi_rom;
mod ffi_solve_from;
mod ffi_threads;
