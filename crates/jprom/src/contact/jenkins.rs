//! The 1D Jenkins element (spring in series with a Coulomb slider), a special case of §4.
//!
//! Spring `kt` in series with a slider of limit `Fs = mu * normal_load` (constant, so the
//! element never separates). Predictor `T* = T_prev + kt du`; stick `|T*| <= Fs`, `T = T*`;
//! slip `T = Fs sign(T*)`, for which `dT/dT* = 0`.

use super::{ContactLaw, ContactState};

/// Parameters of the Jenkins element (see [`ContactLaw::Jenkins`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Jenkins {
    /// Spring stiffness.
    pub kt: f64,
    /// Slip limit `Fs = mu * normal_load`.
    pub slip_force: f64,
}

impl Jenkins {
    /// The parameters of a [`ContactLaw::Jenkins`]; `None` for another law.
    pub fn from_law(law: &ContactLaw) -> Option<Self> {
        match *law {
            ContactLaw::Jenkins { kt, mu, normal_load } => Some(Jenkins { kt, slip_force: mu * normal_load }),
            _ => None,
        }
    }

    /// Predictor `T* = T_prev + kt du`.
    #[inline]
    pub fn predictor(&self, t_prev: f64, du: f64) -> f64 {
        t_prev + self.kt * du
    }

    /// Work of the slider force `t` over the slip increment `(tstar - t) / kt` of one sample
    /// (zero in stick, `>= 0` in slip).
    #[inline]
    pub fn slip_work(&self, tstar: f64, t: f64) -> f64 {
        if self.kt > 0.0 {
            (t * (tstar - t) / self.kt).max(0.0)
        } else {
            0.0
        }
    }

    /// Corrector: force, state and `dT/dT*` (1 in stick, 0 in slip).
    #[inline]
    pub fn correct(&self, tstar: f64) -> (f64, ContactState, f64) {
        if tstar.abs() <= self.slip_force {
            (tstar, ContactState::Stick, 1.0)
        } else {
            (self.slip_force * tstar.signum(), ContactState::Slip, 0.0)
        }
    }
}
