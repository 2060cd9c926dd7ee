//! # jprom
//!
//! Steady-state forced response of structures with friction contacts by harmonic balance
//! (HBM) with alternating frequency-time (AFT) contact forces, and its reduction by
//! Jacobian Projection (JP). The formulation is written down in `docs/formulation.md` (shipped in the
//! repository's shared notes); equation numbers `(n)` in doc comments refer to the JP paper.
//!
//! Map of the crate, following the method:
//! - [`linalg`]: checked LU, sparse matrices, dense and sparse eigen solvers.
//! - [`model`]: `M`, `K`, damping, excitation, contact elements, output DoFs (§1).
//! - [`contact`]: the time-domain 3D stick/slip/separation law and the 1D Jenkins element (§4).
//! - [`aft`]: inverse FFT, contact law, FFT, and the analytical Jacobian `K̂` (§3).
//! - [`hbm`]: harmonic layout, dynamic stiffness, residual, Newton/trust-region, continuation (§2).
//! - [`condensation`]: condensation onto the contact DoFs (§5).
//! - [`fe`]: FE models: hexahedral element, the built-in blade, the blade pair, the twisted
//!   plate, and sparse Craig-Bampton reduction.
//! - [`io`]: Matrix Market and node/DoF-map import.
//! - [`jp`]: JP modes, boundary-condition prediction, SVD conditioning (§6-8).
//! - [`rom`]: full-DoF (FR) and nonlinear-DoF (NLR) reduced models (§9), the error measures
//!   `e*`, `e` and `e_lin` (§10) and the self-correcting sweep.
//! - [`level`]: excitation levels, `alpha_ST` and the stuck limit (§11).
//! - [`memory`], [`limits`]: the memory budget and the documented caps that sizes from
//!   outside are checked against before anything is allocated.
//!
//! Units are the caller's; the built-in blade uses mm, tonne, s (so N and MPa). Frequencies in
//! the library are angular (`omega`, rad/s) unless a name says `_hz`.

pub mod error;
pub mod limits;
pub mod memory;
pub mod linalg;
pub mod model;
pub mod contact;
pub mod aft;
pub mod hbm;
pub mod condensation;
pub mod fe;
pub mod io;
pub mod jp;
pub mod rom;
pub mod level;

pub use error::{JpError, Result};
