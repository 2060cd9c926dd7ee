//! The `jprom` program's library: study files ([`study`]), running a study and writing its
//! CSV, JSON and tables ([`run`]) as independent work units ([`units`]), the natural modes of its model ([`modes`]), plots ([`plots`]). The numerics are the `jprom` crate's.
pub mod check;
pub mod fall_back;
pub mod locate;
#[cfg(feature = "mpi")]
pub mod mpi_run;
pub mod modes;
pub mod plots;
pub mod progress;
pub mod run;
pub mod study;
pub mod units;
