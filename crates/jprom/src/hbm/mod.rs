//! Harmonic balance (docs/formulation.md §2): the unknowns' layout, the linear part of a harmonic
//! system, the residual and Jacobian with AFT contact forces, Newton/trust-region
//! solution of one frequency point, and pseudo-arclength continuation over a band.
//!
//! Every solver in jprom (full order, condensed full order, FR and NLR ROMs) is a
//! [`HarmonicSystem`]: per harmonic `h` it has `n_h` unknowns (the same for cos and sin), a
//! linear part `D_h(omega)` and force `f_h(omega)`, and a map `W_h` from its unknowns to the
//! contact coordinates `w`. The residual is `r = D z - f + W^T F(W z)` and the Jacobian
//! `D + W^T K̂ W`, in the real cos/sin form
//!
//! ```text
//! [ Re D_h   Im D_h ] [z_hc]   [f_hc]
//! [-Im D_h   Re D_h ] [z_hs] = [f_hs]      (complex D_h, z = z_c - i z_s, f = f_c - i f_s)
//! ```

pub mod layout;
pub mod options;
pub mod residual;
pub mod solution;
pub mod solve;
mod newton;
pub mod continuation;
pub mod document;
pub mod full;

pub use continuation::{sweep, sweep_from};
pub use full::{FullSystem, Storage};
pub use layout::HarmonicLayout;
pub use crate::aft::Discretisation;
pub use options::{default_nt, ContinuationMethod, HbmOptions, SweepOptions};
pub use solution::{BranchEvent, EventKind, PointSolution, SweepEnd, SweepGap, SweepResult, LEFT_BAND_EXCURSION, LEFT_BAND_MARGIN};
pub use solve::solve_point;

use crate::contact::{ContactLaw, Contacts};
use crate::error::Result;
use crate::linalg::Matrix;
use faer::MatRef;

/// How a system's harmonic-`h` unknowns map onto the contact coordinates `w` (length `n_w`).
#[derive(Clone, Copy, Debug)]
pub enum ContactMap<'a> {
    /// `w` is the first `n_w` unknowns of the harmonic (full and condensed full-order systems).
    Leading,
    /// `w = W_h z_h` with a dense `n_w x n_h` matrix (reduced models).
    Dense(MatRef<'a, f64>),
}

/// The linear part of a harmonic system at one frequency. Its matrices are dense for reduced
/// and condensed systems and sparse for the full-order system of a sparse model
/// ([`full::Storage`]); when `D_0` is sparse, every `D_h` is, and the HBM Jacobian is built
/// and factorised sparse.
#[derive(Clone, Debug)]
pub struct LinearPart {
    /// `D_0` (`n_0 x n_0`) and the static force `f_0`.
    pub d0: Matrix,
    pub f0: Vec<f64>,
    /// For `h = 1..=H` (index `h - 1`): real and imaginary parts of the complex `D_h`
    /// (`n_h x n_h`), and the cos and sin parts of the force.
    pub dh_re: Vec<Matrix>,
    pub dh_im: Vec<Matrix>,
    pub fh_cos: Vec<Vec<f64>>,
    pub fh_sin: Vec<Vec<f64>>,
}

impl LinearPart {
    /// The same linear part with the harmonic forces `f_h`, `h >= 1`, times `lambda` (the static
    /// force kept): the forcing level of the point solver's load stepping and continuation.
    pub fn with_harmonic_forces_scaled(&self, lambda: f64) -> LinearPart {
        let mut l = self.clone();
        for f in l.fh_cos.iter_mut().chain(l.fh_sin.iter_mut()) {
            f.iter_mut().for_each(|v| *v *= lambda);
        }
        l
    }
}

/// A system that the HBM solver, the continuation and the error metric can work on.
pub trait HarmonicSystem: Sync {
    /// Harmonics and unknowns per harmonic.
    fn layout(&self) -> &HarmonicLayout;
    /// AFT time samples per period `Nt`, given when the system was built (with its `H`, the
    /// system's [`Discretisation`]).
    fn aft_samples(&self) -> usize {
        self.contacts().nt
    }
    /// `H` (the layout's) and `Nt`.
    fn discretisation(&self) -> Discretisation {
        Discretisation::with_nt(self.layout().harmonics, self.aft_samples())
    }
    /// The contacts: laws, offsets in `w`, `n_w`.
    fn contacts(&self) -> Contacts<'_>;
    /// Laws of the contacts, in order.
    fn contact_laws(&self) -> &[ContactLaw] {
        self.contacts().laws
    }
    /// Offset of each contact's coordinates in `w`.
    fn contact_offsets(&self) -> &[usize] {
        self.contacts().offsets
    }
    /// Number of contact coordinates `n_w`.
    fn n_contact_coords(&self) -> usize {
        self.contacts().n_w
    }
    /// `W_h` for harmonic `h = 0..=H`; by default the contact coordinates lead the unknowns
    /// of every harmonic ([`ContactMap::Leading`], the full and condensed systems).
    fn contact_map(&self, _h: usize) -> ContactMap<'_> {
        ContactMap::Leading
    }
    /// `D_h(omega)` and `f_h(omega)` for all harmonics.
    fn linear_part(&self, omega: f64) -> Result<LinearPart>;
    /// [`HarmonicSystem::linear_part`] into `out`, reusing its storage where the system can
    /// (the full-order system refills matrices of its own storage and pattern in place, so the
    /// continuation corrector's iterations do not allocate); by default a new one.
    fn linear_part_into(&self, omega: f64, out: &mut Option<LinearPart>) -> Result<()> {
        *out = Some(self.linear_part(omega)?);
        Ok(())
    }
    /// The linear part at `omega` into `out` and, where the system has it in closed form, its
    /// derivative with respect to omega into `derivative` (`D_0' = 0`, `f_0' = 0`; `D_h'`,
    /// `f_h'` for `h >= 1`): then `true`, and the continuation's `dR/domega` is
    /// `D' z - f'`. By default `false` and `derivative` untouched: the continuation differences
    /// [`HarmonicSystem::linear_part`] at `omega +- delta`. The condensed systems give it
    /// (docs/formulation.md §7), from the factorisation of their linear part at `omega`.
    fn linear_part_with_derivative_into(&self, omega: f64, out: &mut Option<LinearPart>, _derivative: &mut Option<LinearPart>) -> Result<bool> {
        self.linear_part_into(omega, out)?;
        Ok(false)
    }
    /// Physical response at the output DoFs, per harmonic coefficient: entry `k * n_out + j`
    /// (`k = 0`, `2h - 1`, `2h` as in [`crate::aft`]).
    fn output_harmonics(&self, omega: f64, z: &[f64]) -> Result<Vec<f64>>;
    /// Number of output DoFs.
    fn n_outputs(&self) -> usize;
}
