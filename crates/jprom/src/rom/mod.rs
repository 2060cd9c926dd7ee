//! Reduced models on a JP basis (docs/formulation.md §9): full-DoF reduction [`FrRom`] and nonlinear-DoF
//! reduction [`NlrRom`], both [`HarmonicSystem`]s that the HBM solver and the continuation
//! use as they are, and the self-correcting sweep [`adaptive_sweep`] — the default workflow:
//! predict a basis, sweep the reduced model, check the error predictor (§10) and, where it
//! says the basis is poor, regenerate the basis from the reduced solution (39) or enlarge
//! `gamma`, and sweep again.

pub mod adaptive;
pub mod error_metric;
pub mod fr;
pub mod nlr;
pub mod record;
pub mod tangent_peak;

pub use adaptive::{adaptive_sweep, adaptive_sweep_from, adaptive_sweep_with_progress, AdaptiveOptions, AdaptiveSweep, Correction, CorrectionEnd, CorrectionKind, ErrorCheck, Trust, REGENERATION_SAMPLES};
pub use fr::{band_condensed_basis, FrRom};
pub use nlr::NlrRom;
pub use record::{CorrectionOutcome, SweepRecord};

use crate::condensation::CondensedSystem;
use crate::error::{JpError, Result};
use crate::hbm::{sweep, HarmonicSystem, HbmOptions, PointSolution, SweepOptions, SweepResult};
use crate::jp::JpBasis;
use crate::model::ContactCoordinates;
use serde::{Deserialize, Serialize};
use std::ops::ControlFlow;

/// Which reduced model.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum RomKind {
    /// Full-DoF reduction (cheaper per iteration).
    Fr,
    /// Nonlinear-DoF reduction on the condensed system (more accurate at equal size).
    Nlr,
}

/// The reduced model of `kind` on `basis`: FR on the contact coordinates `coords`
/// ([`FrRom::new`], band-condensed rows when the basis knows its band), NLR on the condensed
/// system ([`NlrRom::new`]).
///
/// # Errors
/// [`JpError::InvalidValue`] for NLR without `condensed`; the reduced models' own errors.
pub fn reduced_model(kind: RomKind, coords: &ContactCoordinates, condensed: Option<&CondensedSystem>, basis: &JpBasis) -> Result<Box<dyn ReducedModel>> {
    Ok(match kind {
        RomKind::Fr => Box::new(FrRom::new(coords, basis)?),
        RomKind::Nlr => {
            let c = condensed.ok_or_else(|| JpError::invalid("reduced model", "NLR needs the condensed system"))?;
            Box::new(NlrRom::new(c, basis)?)
        }
    })
}

/// Sweeps a reduced model ([`crate::hbm::sweep`]) and evaluates the error predictor `e*_h`
/// ([`error_metric::predicted_error`]) at every point: the sweep and `e*` per point.
///
/// # Errors
/// As [`crate::hbm::sweep`] and [`error_metric::predicted_error`].
pub fn sweep_with_predicted_error(
    rom: &dyn ReducedModel,
    sopts: &SweepOptions,
    hopts: &HbmOptions,
    on_point: &mut dyn FnMut(&PointSolution) -> ControlFlow<()>,
) -> Result<(SweepResult, Vec<Vec<f64>>)> {
    let result = sweep(rom, sopts, hopts, on_point)?;
    let plan = rom.discretisation().plan()?;
    let errors = result.points.iter().map(|p| error_metric::predicted_error_with(rom, &plan, p.omega, &p.z)).collect::<Result<Vec<_>>>()?;
    Ok((result, errors))
}

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
