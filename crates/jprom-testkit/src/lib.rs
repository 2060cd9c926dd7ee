//! Models and helpers shared by the tests and benches of jprom's crates: small spring-mass
//! chains with contacts ([`chain`]), the built-in blade at its levels ([`blade`]), linear
//! harmonic-balance references ([`hbm`]), and building C, C++ and Fortran programs against
//! libjprom ([`native`]). Not part of any published API.

#![allow(dead_code)]

pub mod blade;
pub mod campaign;
pub mod chain;
pub mod hbm;
pub mod native;
