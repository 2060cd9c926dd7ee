//! SVD conditioning of the stacked JP modes (docs/formulation.md §8.7, paper (37)-(38)):
//! `U_h S_h V_h^T = Φ_h`, keep the columns of `U_h` whose singular value is at least
//! `s_max / gamma`. The result is orthonormal, spans the dominant part of `Φ_h`, and its size
//! `n_h` grows with `gamma`.

use crate::error::{JpError, Result};
use faer::Mat;

/// One conditioned harmonic basis.
#[derive(Clone, Debug)]
pub struct ConditionedBasis {
    /// Orthonormal columns (`n x n_h`).
    pub basis: Mat<f64>,
    /// All singular values of the raw `Φ_h`, non-increasing.
    pub singular_values: Vec<f64>,
}

/// Refuses a conditioning ratio that is not finite and at least 1.
///
/// # Errors
/// [`JpError::InvalidValue`].
pub fn check_gamma(gamma: f64) -> Result<()> {
    if !(gamma.is_finite() && gamma >= 1.0) {
        return Err(JpError::invalid("gamma", format!("must be finite and >= 1, got {gamma}")));
    }
    Ok(())
}

/// Conditions `phi` (37)-(38) with ratio `gamma >= 1`. An empty `phi` gives an empty basis.
///
/// # Errors
/// [`JpError::InvalidValue`] if `gamma < 1` or not finite, or `phi` has non-finite entries;
/// [`JpError::Eigen`] if the SVD fails.
pub fn condition(phi: &Mat<f64>, gamma: f64) -> Result<ConditionedBasis> {
    check_gamma(gamma)?;
    let (n, m) = (phi.nrows(), phi.ncols());
    if m == 0 || n == 0 {
        return Ok(ConditionedBasis { basis: Mat::zeros(n, 0), singular_values: Vec::new() });
    }
    for j in 0..m {
        for i in 0..n {
            if !phi[(i, j)].is_finite() {
                return Err(JpError::invalid("JP modes", format!("entry ({i}, {j}) is not finite")));
            }
        }
    }
    let svd = phi.thin_svd().map_err(|e| JpError::Eigen { what: format!("SVD of the JP modes (37): {e:?}") })?;
    let s = svd.S().column_vector();
    let sv: Vec<f64> = (0..s.nrows()).map(|i| s[i]).collect();
    let s_max = sv.first().copied().unwrap_or(0.0);
    if s_max == 0.0 {
        return Ok(ConditionedBasis { basis: Mat::zeros(n, 0), singular_values: sv });
    }
    let keep = sv.iter().take_while(|&&x| x >= s_max / gamma).count();
    let basis = svd.U().subcols(0, keep).to_owned();
    Ok(ConditionedBasis { basis, singular_values: sv })
}
