//! The command-line application: study files, report files and plots.
pub mod study;
pub mod plots;
pub mod run;
