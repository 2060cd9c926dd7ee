//! Reduced models on a JP basis (method.md §9): full-DoF reduction [`FrRom`] and nonlinear-DoF
//! reduction [`NlrRom`], both [`HarmonicSystem`]s that the HBM solver and the continuation
//! use as they are, and the self-correcting sweep [`adaptive_sweep`] — the default workflow:
//! predict a basis, sweep the reduced model, check the error predictor (§10) and, where it
//! says the basis is poor, regenerate the basis from the reduced solution (39) or enlarge
//! `gamma`, and sweep again.

pub mod adaptive;
pub mod fr;
pub mod nlr;

pub use adaptive::{adaptive_sweep, adaptive_sweep_with_progress, AdaptiveOptions, AdaptiveSweep, Correction, CorrectionEnd, CorrectionKind, ErrorCheck, RomKind};
pub use fr::{band_condensed_basis, FrRom};
pub use nlr::NlrRom;

use crate::error::Result;
use crate::hbm::HarmonicSystem;

/// What the error predictor and the output recovery need from a reduced model beyond
/// [`HarmonicSystem`].
pub trait ReducedModel: HarmonicSystem {
    /// Length of the vectors of [`ReducedModel::implied_contact_force`]: `n` (FR, all DoFs)
    /// or `n_w` (NLR, the condensed system).
    fn full_size(&self) -> usize;
    /// `f*_C` of (40), per harmonic coefficient `k = 0..2H` (`0`, `2h - 1` cos, `2h` sin),
    /// each of length [`ReducedModel::full_size`] with the contact coordinates first.
    fn implied_contact_force(&self, omega: f64, z: &[f64]) -> Result<Vec<Vec<f64>>>;
    /// All z-coordinates (contact coordinates first, length `n`) of the reduced solution per
    /// harmonic coefficient.
    fn full_coefficients(&self, omega: f64, z: &[f64]) -> Result<Vec<Vec<f64>>>;
}
