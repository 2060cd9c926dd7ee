//! The scalar elastic elements and the 2D friction element (docs/formulation.md §4.6), as
//! [`SampleLaw`]s so that the AFT's one chain-rule loop gives their forces and Jacobians.
//!
//! * [`Polynomial`]: memoryless spring `F(w) = sum_p c_p w^p` (`p = 1..=P`) on a scalar `w`,
//!   `dF/dw = sum_p p c_p w^(p-1)`; it acts in both signs.
//! * [`Unilateral`]: `N = max(0, n0 + kn v)` on a scalar `v`, `dN/dv = kn` while closed.
//! * [`Friction2D`]: one tangential direction `u` with spring `kt` and Coulomb friction `mu`,
//!   and the unilateral normal `N = max(0, n0 + kn v)`, on `w = (u, v)`.
//!
//! The two scalar elements have no tangential direction (`TANGENTIAL = 0`): their force is the
//! loop's per-sample "normal" force, which the loop transforms and differentiates as given (it
//! does not clamp it; only the law decides whether the force may change sign).

use super::law::{Corrector, Friction3D};
use super::{ContactLaw, ContactState, SampleLaw};

/// Polynomial spring (see [`ContactLaw::Polynomial`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Polynomial<'a> {
    /// `c_1, c_2, ...`: `F(w) = sum_p c_p w^p`.
    pub coefficients: &'a [f64],
}

impl<'a> Polynomial<'a> {
    /// The parameters of a [`ContactLaw::Polynomial`]; `None` for another law.
    pub fn from_law(law: &'a ContactLaw) -> Option<Self> {
        match law {
            ContactLaw::Polynomial { coefficients } => Some(Polynomial { coefficients }),
            _ => None,
        }
    }

    /// `F(w)` and `dF/dw` (Horner).
    #[inline]
    pub fn force(&self, w: f64) -> (f64, f64) {
        // F = w (c_1 + w (c_2 + ...)),  F' = c_1 + w (2 c_2 + w (3 c_3 + ...))
        let (mut f, mut df) = (0.0, 0.0);
        for (i, &c) in self.coefficients.iter().enumerate().rev() {
            f = f * w + c;
            df = df * w + (i + 1) as f64 * c;
        }
        (f * w, df)
    }
}

/// Unilateral spring (see [`ContactLaw::Unilateral`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Unilateral {
    pub kn: f64,
    pub n0: f64,
}

impl Unilateral {
    /// The parameters of a [`ContactLaw::Unilateral`]; `None` for another law.
    pub fn from_law(law: &ContactLaw) -> Option<Self> {
        match *law {
            ContactLaw::Unilateral { kn, n0 } => Some(Unilateral { kn, n0 }),
            _ => None,
        }
    }
}

/// 2D friction element (see [`ContactLaw::Friction2D`]): the 3D element with one tangential
/// direction (its second tangential stiffness is zero and never used).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Friction2D(pub Friction3D);

impl Friction2D {
    /// The parameters of a [`ContactLaw::Friction2D`]; `None` for another law.
    pub fn from_law(law: &ContactLaw) -> Option<Self> {
        match *law {
            ContactLaw::Friction2D { kt, kn, mu, n0 } => Some(Friction2D(Friction3D { kt: [kt, 0.0], kn, mu, n0 })),
            _ => None,
        }
    }
}

/// The corrector of a law without tangential direction: no tangential force, the state only.
#[inline]
fn no_tangential(state: ContactState) -> Corrector {
    Corrector { force: [0.0; 2], state, d_predictor: [[0.0; 2]; 2], d_normal: [0.0; 2] }
}

impl SampleLaw for Polynomial<'_> {
    const TANGENTIAL: usize = 0;
    const HAS_NORMAL: bool = true;
    #[inline]
    fn tangential_stiffness(&self) -> [f64; 2] {
        [0.0; 2]
    }
    #[inline]
    fn normal(&self, v: f64) -> (f64, f64) {
        self.force(v)
    }
    /// Always [`ContactState::Stick`]: the spring acts at every sample, in both signs.
    #[inline]
    fn correct(&self, _trial: [f64; 2], _normal: f64) -> Corrector {
        no_tangential(ContactState::Stick)
    }
    #[inline]
    fn slip_work(&self, _trial: [f64; 2], _force: [f64; 2]) -> f64 {
        0.0
    }
}

impl SampleLaw for Unilateral {
    const TANGENTIAL: usize = 0;
    const HAS_NORMAL: bool = true;
    #[inline]
    fn tangential_stiffness(&self) -> [f64; 2] {
        [0.0; 2]
    }
    #[inline]
    fn normal(&self, v: f64) -> (f64, f64) {
        let n = self.n0 + self.kn * v;
        if n > 0.0 {
            (n, self.kn)
        } else {
            (0.0, 0.0)
        }
    }
    /// [`ContactState::Stick`] while closed (`N > 0`), else [`ContactState::Separated`].
    #[inline]
    fn correct(&self, _trial: [f64; 2], normal: f64) -> Corrector {
        no_tangential(if normal > 0.0 { ContactState::Stick } else { ContactState::Separated })
    }
    #[inline]
    fn slip_work(&self, _trial: [f64; 2], _force: [f64; 2]) -> f64 {
        0.0
    }
}

impl SampleLaw for Friction2D {
    const TANGENTIAL: usize = 1;
    const HAS_NORMAL: bool = true;
    #[inline]
    fn tangential_stiffness(&self) -> [f64; 2] {
        self.0.kt
    }
    #[inline]
    fn normal(&self, v: f64) -> (f64, f64) {
        self.0.normal(v)
    }
    #[inline]
    fn correct(&self, trial: [f64; 2], normal: f64) -> Corrector {
        // The second entry of the predictor is always 0 (kt2 = 0), so the cone is the
        // interval |T| <= mu N.
        self.0.correct([trial[0], 0.0], normal)
    }
    #[inline]
    fn slip_work(&self, trial: [f64; 2], force: [f64; 2]) -> f64 {
        self.0.slip_work(trial, force)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn polynomial_force_and_derivative_match_the_sum() {
        let c = [2.0, -0.5, 3.0, 0.0, 0.25];
        let p = Polynomial { coefficients: &c };
        for &w in &[-1.3f64, -0.2, 0.0, 0.7, 2.1] {
            let f: f64 = c.iter().enumerate().map(|(i, ci)| ci * w.powi(i as i32 + 1)).sum();
            let df: f64 = c.iter().enumerate().map(|(i, ci)| (i + 1) as f64 * ci * w.powi(i as i32)).sum();
            let (pf, pdf) = p.force(w);
            assert!((pf - f).abs() <= 1e-13 * (1.0 + f.abs()), "{pf} vs {f}");
            assert!((pdf - df).abs() <= 1e-13 * (1.0 + df.abs()), "{pdf} vs {df}");
        }
    }

    #[test]
    fn unilateral_opens_below_the_gap() {
        let u = Unilateral { kn: 10.0, n0: -2.0 };
        assert_eq!(u.normal(0.1), (0.0, 0.0));
        assert_eq!(u.normal(0.3), (1.0, 10.0));
        assert_eq!(u.correct([0.0; 2], 0.0).state, ContactState::Separated);
        assert_eq!(u.correct([0.0; 2], 1.0).state, ContactState::Stick);
    }
}
