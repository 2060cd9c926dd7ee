//! Time-domain 3D stick/slip/separation law with its derivatives (docs/formulation.md §4.2).
//!
//! One time step of the element on `w = (u1, u2, v)`:
//! * normal `N = max(0, n0 + kn v)`, `dN/dv = kn` while `N > 0`;
//! * tangential predictor `T* = T_prev + Kt (u_k - u_{k-1})`, `Kt = diag(kt1, kt2)`;
//! * corrector: separated (`N = 0`) `T = 0`; stick (`|T*| <= mu N`) `T = T*`;
//!   slip `T = mu N T* / |T*|`.
//!
//! The corrector returns its derivatives with respect to `T*` and `N`, which the AFT chains
//! through the time samples (docs/formulation.md §4).

use super::{ContactLaw, ContactState};

/// Parameters of the 3D friction element (see [`ContactLaw::Friction3D`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Friction3D {
    /// Tangential stiffnesses `kt1`, `kt2`.
    pub kt: [f64; 2],
    /// Normal stiffness.
    pub kn: f64,
    /// Friction coefficient.
    pub mu: f64,
    /// Normal preload (`N0 = -kn g` for an initial gap `g`).
    pub n0: f64,
}

/// Result of the tangential corrector for one time sample, with its derivatives.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Corrector {
    /// Tangential force `T = (T1, T2)`.
    pub force: [f64; 2],
    /// Stick, slip or separated.
    pub state: ContactState,
    /// `dT/dT*`, row-major 2 x 2: `d_predictor[r][s] = dT_r / dT*_s`.
    pub d_predictor: [[f64; 2]; 2],
    /// `dT/dN` (nonzero only in slip).
    pub d_normal: [f64; 2],
}

impl Friction3D {
    /// The parameters of a [`ContactLaw::Friction3D`]; `None` for another law.
    pub fn from_law(law: &ContactLaw) -> Option<Self> {
        match *law {
            ContactLaw::Friction3D { kt1, kt2, kn, mu, n0 } => Some(Friction3D { kt: [kt1, kt2], kn, mu, n0 }),
            _ => None,
        }
    }

    /// Normal force `N = max(0, n0 + kn v)` and `dN/dv` (`kn` while in contact, else 0).
    #[inline]
    pub fn normal(&self, v: f64) -> (f64, f64) {
        let n = self.n0 + self.kn * v;
        if n > 0.0 {
            (n, self.kn)
        } else {
            (0.0, 0.0)
        }
    }

    /// Tangential predictor `T* = T_prev + Kt du`.
    #[inline]
    pub fn predictor(&self, t_prev: [f64; 2], du: [f64; 2]) -> [f64; 2] {
        [t_prev[0] + self.kt[0] * du[0], t_prev[1] + self.kt[1] * du[1]]
    }

    /// Work of the friction force `t` over the slip increment of one sample,
    /// `t . Kt^-1 (tstar - t)` (zero in stick, where `t = tstar`; `>= 0` in slip, where `t` is
    /// `tstar` scaled down). A direction without tangential stiffness takes no slip.
    #[inline]
    pub fn slip_work(&self, tstar: [f64; 2], t: [f64; 2]) -> f64 {
        let mut w = 0.0;
        for r in 0..2 {
            if self.kt[r] > 0.0 {
                w += t[r] * (tstar[r] - t[r]) / self.kt[r];
            }
        }
        w.max(0.0)
    }

    /// Corrector: projects the predictor `tstar` onto the friction cone of radius `mu N`.
    ///
    /// In slip, `dT/dT* = (mu N / |T*|) (I - e e^T)` and `dT/dN = mu e`, `e = T* / |T*|`.
    /// With `mu = 0` and `N > 0` every nonzero predictor slips to `T = 0`.
    #[inline]
    pub fn correct(&self, tstar: [f64; 2], normal: f64) -> Corrector {
        if normal <= 0.0 {
            return Corrector {
                force: [0.0; 2],
                state: ContactState::Separated,
                d_predictor: [[0.0; 2]; 2],
                d_normal: [0.0; 2],
            };
        }
        let limit = self.mu * normal;
        let norm = (tstar[0] * tstar[0] + tstar[1] * tstar[1]).sqrt();
        if norm <= limit {
            Corrector {
                force: tstar,
                state: ContactState::Stick,
                d_predictor: [[1.0, 0.0], [0.0, 1.0]],
                d_normal: [0.0; 2],
            }
        } else {
            // norm > limit >= 0, so norm > 0.
            let e = [tstar[0] / norm, tstar[1] / norm];
            let s = limit / norm;
            Corrector {
                force: [limit * e[0], limit * e[1]],
                state: ContactState::Slip,
                d_predictor: [
                    [s * (1.0 - e[0] * e[0]), -s * e[0] * e[1]],
                    [-s * e[1] * e[0], s * (1.0 - e[1] * e[1])],
                ],
                d_normal: [self.mu * e[0], self.mu * e[1]],
            }
        }
    }
}
