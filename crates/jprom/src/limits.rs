//! jprom's documented caps on sizes that are legal but absurd: past them the work or memory
//! would be out of all proportion to any study, so the request is refused at once
//! ([`crate::JpError::OverLimit`], `JPROM_BAD_SIZE` in C) instead of running for hours or
//! exhausting the machine. Memory beyond these is the [`crate::memory`] budget's business.
//! The C header repeats each as a `JPROM_MAX_*` constant.

use crate::error::{JpError, Result};

/// Highest harmonic `H` of a solve (`HbmOptions.harmonics`, C `jprom_hbm_options.harmonics`).
pub const MAX_HARMONICS: usize = 64;

/// Most AFT time samples per period (`HbmOptions.nt`, study `hbm.nt`): 2^16.
pub const MAX_NT: usize = 1 << 16;

/// Most amplitude samples of a basis prediction (`PredictionOptions.n_samples`, C
/// `n_samples`, study `basis.samples`).
pub const MAX_SAMPLES: usize = 10_000;

/// Most target points of a study's sweep (`band.points`; the arclength steps are `1 / points`).
pub const MAX_BAND_POINTS: usize = 100_000;

/// Most Craig-Bampton fixed-interface modes of a study (`model.cb_modes`; the reduced model
/// is dense, `n_boundary + cb_modes` square).
pub const MAX_CB_MODES: usize = 5_000;

/// Largest contact-patch refinement of the built-in blade in a study (`model.refinement`):
/// 15 gives 1,922 contact nodes and 140,658 FE DoFs (about 4 GB for Craig-Bampton).
pub const MAX_BLADE_REFINEMENT: usize = 15;

/// Largest row or column count of a dense matrix read from a JSON file.
pub const MAX_DENSE_DIM: usize = 1 << 20;

/// Largest magnitude of any real input of a model (mass, stiffness and damping entries,
/// damping coefficients, forces, contact parameters): `1e100`. Beyond it the squares that norms
/// and energies take overflow (`1e200` squared is infinite), and a residual measured against
/// an infinite reference force reads as zero: the input is refused instead.
pub const MAX_MAGNITUDE: f64 = 1e100;

/// Largest static displacement scale of a load against the model's own stiffness,
/// `|f|_inf / max_i K_ii`: `1e50` (in the model's length unit). No structure in any unit system
/// comes near it; past it the response's squares leave the range of `f64`.
pub const MAX_DISPLACEMENT_SCALE: f64 = 1e50;

/// `Ok` if every value is finite and at most [`MAX_MAGNITUDE`] in magnitude; else
/// [`JpError::InvalidValue`] naming `what` and the first offending entry.
pub fn check_magnitude(what: &str, values: &[f64]) -> Result<()> {
    match values.iter().position(|v| !(v.abs() <= MAX_MAGNITUDE)) {
        None => Ok(()),
        Some(i) if !values[i].is_finite() => Err(JpError::invalid(what, format!("entry {i} is not finite ({})", values[i]))),
        Some(i) => Err(JpError::invalid(what, format!("entry {i} is {:e}, beyond jprom's magnitude limit of {MAX_MAGNITUDE:e}", values[i]))),
    }
}

/// `Ok` if `value <= limit`, else [`JpError::OverLimit`] naming `what`.
pub fn at_most(what: &str, value: usize, limit: usize) -> Result<()> {
    if value <= limit {
        Ok(())
    } else {
        Err(JpError::over_limit(what, value as u128, limit as u128))
    }
}
