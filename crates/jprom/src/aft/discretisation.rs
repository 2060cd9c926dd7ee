//! The harmonic-balance discretisation of a system: harmonics `0..=H` and `Nt` AFT time
//! samples per period (docs/formulation.md §2, §4). A system is built with one and owns it
//! ([`crate::hbm::HarmonicSystem::aft_samples`], its layout's `H`); solver and sweep options do
//! not repeat it.

use super::AftPlan;
use crate::error::{JpError, Result};
use serde::{Deserialize, Serialize};

/// Harmonics `0..=H` (the static term always included) and AFT samples per period.
///
/// `Discretisation::from(3)` is `H = 3` with the default `Nt` ([`default_nt`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct Discretisation {
    /// Highest harmonic `H` (default 1).
    pub harmonics: usize,
    /// AFT time samples per period; `None` (default) picks [`default_nt`]`(H)`.
    pub nt: Option<usize>,
}

/// Default AFT sample count: 64 for `H <= 3`, else the next power of two at or above
/// `16 (H + 1)` (128 for `H = 4..=7`, 256 up to 15), so that friction's higher harmonics
/// alias little into `0..=H` (docs/formulation.md §4).
pub fn default_nt(harmonics: usize) -> usize {
    if harmonics <= 3 {
        64
    } else {
        // saturating: an absurd H gets an absurd nt, which `validate` then refuses
        16usize.saturating_mul(harmonics.saturating_add(1)).checked_next_power_of_two().unwrap_or(usize::MAX)
    }
}

impl Default for Discretisation {
    fn default() -> Self {
        Discretisation { harmonics: 1, nt: None }
    }
}

impl From<usize> for Discretisation {
    /// `H = harmonics` with the default `Nt`.
    fn from(harmonics: usize) -> Self {
        Discretisation::new(harmonics)
    }
}

impl Discretisation {
    /// `H = harmonics` with the default `Nt`.
    pub fn new(harmonics: usize) -> Self {
        Discretisation { harmonics, nt: None }
    }

    /// `H = harmonics` with `nt` samples per period.
    pub fn with_nt(harmonics: usize, nt: usize) -> Self {
        Discretisation { harmonics, nt: Some(nt) }
    }

    /// The AFT sample count in effect.
    pub fn nt(&self) -> usize {
        self.nt.unwrap_or_else(|| default_nt(self.harmonics))
    }

    /// Checks `H >= 1`, `Nt` a power of two `>= 4 (H + 1)`, and both against jprom's caps
    /// ([`crate::limits::MAX_HARMONICS`], [`crate::limits::MAX_NT`]) before anything is sized
    /// by them.
    ///
    /// # Errors
    /// [`JpError::InvalidValue`] naming the bad value; [`JpError::OverLimit`] above a cap.
    pub fn validate(&self) -> Result<()> {
        if self.harmonics == 0 {
            return Err(JpError::invalid("harmonics", "must be >= 1"));
        }
        crate::limits::at_most("harmonics", self.harmonics, crate::limits::MAX_HARMONICS)?;
        let nt = self.nt();
        crate::limits::at_most("nt", nt, crate::limits::MAX_NT)?;
        if !nt.is_power_of_two() || nt < 4 * (self.harmonics + 1) {
            return Err(JpError::invalid("nt", format!("must be a power of two >= 4 (H + 1) = {}, got {nt}", 4 * (self.harmonics + 1))));
        }
        Ok(())
    }

    /// The AFT plan of this discretisation (checked as [`Discretisation::validate`], by
    /// [`AftPlan::new`]).
    ///
    /// # Errors
    /// As [`Discretisation::validate`].
    pub fn plan(&self) -> Result<AftPlan> {
        AftPlan::new(self.harmonics, self.nt())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defaults_and_checks() {
        assert_eq!(Discretisation::from(3).nt(), 64);
        assert_eq!(Discretisation::new(5).nt(), 128);
        assert!(Discretisation::new(0).validate().is_err());
        assert!(Discretisation::with_nt(3, 8).validate().is_err());
        assert!(Discretisation::with_nt(1, 48).validate().is_err());
        assert!(Discretisation::with_nt(1, 16).validate().is_ok());
        let plan = Discretisation::with_nt(2, 32).plan().unwrap();
        assert_eq!((plan.harmonics(), plan.nt()), (2, 32));
    }
}
