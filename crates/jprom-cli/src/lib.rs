//! The `jprom` program's library: study files ([`study`]), running a study and writing its
//! CSV, JSON and tables ([`run`]) as independent work units ([`units`]), the natural modes of its model ([`modes`]), plots ([`plots`]). The numerics are the `jprom` crate's.
pub mod check;
pub mod fall_back;
pub mod labels;
pub mod locate;
#[cfg(feature = "mpi")]
pub mod mpi_run;
pub mod modes;
pub mod plots;
pub mod progress;
pub mod rows;
pub mod run;
pub mod shared;
pub mod study;
pub mod summary;
pub mod study_model;
pub mod study_plots;
pub mod units;
