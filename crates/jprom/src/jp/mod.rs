//! Jacobian Projection (docs/formulation.md §8): JP modes from a set of contact boundary conditions
//! ([`modes`]), prediction of the boundary conditions along a generating shape
//! ([`prediction`]), SVD conditioning of the stacked modes ([`conditioning`]) and the resulting
//! reduction basis ([`basis`]).
//!
//! Everything works in the contact coordinates `z = [w; y]` of
//! [`crate::model::ContactCoordinates`]: the contact stiffness `K̂ = dF/dw` lives on the leading
//! `n_w x n_w` block of every harmonic coefficient pair, which keeps the static condensation (28)
//! and the condensed stiffness (30) cheap corrections of `K`.

pub mod basis;
pub mod condensed;
pub mod conditioning;
pub mod mode_selection;
pub mod modes;
pub mod prediction;
pub mod reference;
pub mod shift_invert;

pub use basis::{JpBasis, BasisOptions};
pub use conditioning::{condition, ConditionedBasis};
pub use modes::{jp_modes, jp_modes_on_reference, EigenSolver, JpModes, ModeOptions};
pub use reference::ReferenceFactors;
pub use prediction::{predict_basis, predict_modes, slipping_mode, PredictedModes, stuck_mode, GeneratingShape, PredictionOptions, PredictionReport, SlippingSamples, Spacing};


use crate::aft::ContactForces;
use crate::contact::ContactLaw;
use crate::error::{JpError, Result};
use faer::Mat;

/// Why JP cannot reduce a model without contacts: the one message of every JP entry point
/// (prediction, JP modes, bases, FR, the self-correcting sweep) on such a model.
pub const NO_CONTACTS: &str = "the model has no contact: JP reduces onto the contact coordinates and there are none (sweep the full order instead)";

/// [`JpError::InvalidValue`] with [`NO_CONTACTS`] for `what` where the model has no contact
/// coordinates.
///
/// # Errors
/// As said.
pub fn require_contacts(what: &str, n_w: usize) -> Result<()> {
    if n_w == 0 {
        return Err(JpError::invalid(what, NO_CONTACTS));
    }
    Ok(())
}

/// The boundary conditions of JP (§6): the contact stiffness `K̂ = dF/dw` of all contacts at one
/// state, assembled densely over the contact coordinates in the harmonic-major layout of
/// [`crate::aft`] (entry `(k n_w + i, l n_w + j)` is `dF_{k,i} / dw_{l,j}`), plus the part of
/// the static contact force that is not `K̂_0 w` (see [`ContactJacobian::static_offset`]).
#[derive(Clone, Debug)]
pub struct ContactJacobian {
    /// Highest harmonic `H`.
    pub harmonics: usize,
    /// Number of contact coordinates `n_w`.
    pub n_w: usize,
    /// `K̂`, `(2H + 1) n_w` square.
    pub k_hat: Mat<f64>,
    /// `g = F_0(w) - sum_l K̂_{0l} w_l` (length `n_w`): zero for laws that are positively
    /// homogeneous in `w` (no preload), otherwise the preload's share of the static force. It
    /// enters the static basis (35) so that the static solution is exactly representable.
    pub static_offset: Vec<f64>,
}

impl ContactJacobian {
    /// Fully stuck, closed contacts: `K̂ = diag(kt1, kt2, kn)` (or `kt`) on every coefficient,
    /// no coupling between coefficients.
    ///
    /// # Errors
    /// [`JpError::BadSize`] if `offsets` does not match `laws` and `n_w`.
    pub fn stuck(laws: &[ContactLaw], offsets: &[usize], n_w: usize, harmonics: usize) -> Result<Self> {
        check_offsets(laws, offsets, n_w)?;
        let nc = 2 * harmonics + 1;
        let mut k_hat = Mat::zeros(nc * n_w, nc * n_w);
        for (law, &off) in laws.iter().zip(offsets) {
            // the full block: an external law's Jacobian at w = 0 may couple its coordinates
            let d = law.dim();
            for (idx, k) in law.stuck_stiffness_block().into_iter().enumerate() {
                for c in 0..nc {
                    k_hat[(c * n_w + off + idx % d, c * n_w + off + idx / d)] = k;
                }
            }
        }
        Ok(ContactJacobian { harmonics, n_w, k_hat, static_offset: vec![0.0; n_w] })
    }

    /// Assembles the dense `K̂` from the per-contact blocks of an AFT evaluation
    /// ([`crate::aft::evaluate_contacts`] with `want_jacobian`) at the contact displacement
    /// `w_all` (harmonic-major, length `(2H + 1) n_w`).
    ///
    /// # Errors
    /// [`JpError::BadSize`] if the blocks, offsets or vectors do not match.
    pub fn from_forces(
        laws: &[ContactLaw],
        offsets: &[usize],
        n_w: usize,
        harmonics: usize,
        forces: &ContactForces,
        w_all: &[f64],
    ) -> Result<Self> {
        check_offsets(laws, offsets, n_w)?;
        let nc = 2 * harmonics + 1;
        if w_all.len() != nc * n_w {
            return Err(JpError::bad_size("contact displacement w", nc * n_w, w_all.len()));
        }
        if forces.force.len() != nc * n_w {
            return Err(JpError::bad_size("contact forces", nc * n_w, forces.force.len()));
        }
        if forces.jac_offsets.len() != laws.len() {
            return Err(JpError::bad_size("contact Jacobian blocks", laws.len(), forces.jac_offsets.len()));
        }
        let mut k_hat = Mat::zeros(nc * n_w, nc * n_w);
        for (c, (law, &off)) in laws.iter().zip(offsets).enumerate() {
            let d = law.dim();
            let n = d * nc;
            let start = forces.jac_offsets[c];
            if start + n * n > forces.jac.len() {
                return Err(JpError::bad_size(format!("Jacobian block of contact {c}"), start + n * n, forces.jac.len()));
            }
            let block = &forces.jac[start..start + n * n];
            for col in 0..n {
                let (l, j) = (col / d, col % d);
                for row in 0..n {
                    let (k, i) = (row / d, row % d);
                    k_hat[(k * n_w + off + i, l * n_w + off + j)] = block[row + col * n];
                }
            }
        }
        let static_offset = static_offset(laws, offsets, n_w, harmonics, forces, w_all);
        Ok(ContactJacobian { harmonics, n_w, k_hat, static_offset })
    }

    /// The `n_w x n_w` block `K̂_{kl}` between coefficients `k` and `l`.
    pub fn block(&self, k: usize, l: usize) -> faer::MatRef<'_, f64> {
        let n = self.n_w;
        self.k_hat.as_ref().submatrix(k * n, l * n, n, n)
    }

    /// True when `K̂` couples only coordinates of one and the same contact (`laws`, `offsets`
    /// as in [`ContactJacobian::from_forces`]), as every Jacobian built by
    /// [`ContactJacobian::from_forces`] or [`ContactJacobian::stuck`] does: each block `K̂_{kl}`
    /// is then block-diagonal with the contacts' `d x d` blocks, and products with it cost
    /// `O(d n_w)` per column instead of `O(n_w^2)` ([`ContactJacobian::block_times`]).
    pub fn is_per_contact(&self, laws: &[ContactLaw], offsets: &[usize]) -> bool {
        let nw = self.n_w;
        if check_offsets(laws, offsets, nw).is_err() {
            return false;
        }
        let mut owner = vec![usize::MAX; nw];
        for (c, (law, &off)) in laws.iter().zip(offsets).enumerate() {
            for o in owner[off..off + law.dim()].iter_mut() {
                if *o != usize::MAX {
                    return false;
                }
                *o = c;
            }
        }
        let nt = self.k_hat.nrows();
        (0..nt).all(|j| {
            let oj = owner[j % nw];
            let col = self.k_hat.col(j);
            (0..nt).all(|i| col[i] == 0.0 || (oj != usize::MAX && owner[i % nw] == oj))
        })
    }

    /// `K̂_{kl} X` (`X` with `n_w` rows) using only the contacts' diagonal blocks; exact when
    /// [`ContactJacobian::is_per_contact`] holds.
    pub fn block_times(&self, k: usize, l: usize, x: faer::MatRef<'_, f64>, laws: &[ContactLaw], offsets: &[usize]) -> Mat<f64> {
        let b = self.block(k, l);
        let mut out = Mat::<f64>::zeros(self.n_w, x.ncols());
        for (law, &off) in laws.iter().zip(offsets) {
            let d = law.dim();
            for j in 0..x.ncols() {
                for a in 0..d {
                    out[(off + a, j)] = (0..d).map(|c| b[(off + a, off + c)] * x[(off + c, j)]).sum();
                }
            }
        }
        out
    }

    /// `X K̂_{kl}` (`X` with `n_w` columns) using only the contacts' diagonal blocks; exact when
    /// [`ContactJacobian::is_per_contact`] holds.
    pub fn times_block(&self, x: faer::MatRef<'_, f64>, k: usize, l: usize, laws: &[ContactLaw], offsets: &[usize]) -> Mat<f64> {
        let b = self.block(k, l);
        let mut out = Mat::<f64>::zeros(x.nrows(), self.n_w);
        for (law, &off) in laws.iter().zip(offsets) {
            let d = law.dim();
            for a in 0..d {
                for c in 0..d {
                    let v = b[(off + c, off + a)];
                    if v != 0.0 {
                        for i in 0..x.nrows() {
                            out[(i, off + a)] += x[(i, off + c)] * v;
                        }
                    }
                }
            }
        }
        out
    }
}

fn check_offsets(laws: &[ContactLaw], offsets: &[usize], n_w: usize) -> Result<()> {
    if laws.len() != offsets.len() {
        return Err(JpError::bad_size("contact offsets", laws.len(), offsets.len()));
    }
    for (c, (law, &off)) in laws.iter().zip(offsets).enumerate() {
        if off + law.dim() > n_w {
            return Err(JpError::invalid("contact offsets", format!("contact {c} ends past n_w = {n_w}")));
        }
    }
    Ok(())
}

/// `g = F_0(w) - sum_l K̂_{0l} w_l` (see [`ContactJacobian::static_offset`]) from the
/// contacts' Jacobian blocks of an AFT evaluation (sizes checked by the caller); zero when it is
/// only the round-off of a homogeneous law.
pub(crate) fn static_offset(laws: &[ContactLaw], offsets: &[usize], n_w: usize, harmonics: usize, forces: &ContactForces, w_all: &[f64]) -> Vec<f64> {
    let nc = 2 * harmonics + 1;
    let mut g = forces.force[..n_w].to_vec();
    let mut scale = crate::linalg::norm2(&g);
    for (c, (law, &off)) in laws.iter().zip(offsets).enumerate() {
        let d = law.dim();
        let m = d * nc;
        let block = &forces.jac[forces.jac_offsets[c]..forces.jac_offsets[c] + m * m];
        for i in 0..d {
            let mut kw = 0.0;
            for col in 0..m {
                let (l, j) = (col / d, col % d);
                kw += block[i + col * m] * w_all[l * n_w + off + j];
            }
            g[off + i] -= kw;
            scale += kw.abs();
        }
    }
    // Round-off of a homogeneous law is not an offset.
    if crate::linalg::norm2(&g) <= 1e-10 * scale {
        g.iter_mut().for_each(|x| *x = 0.0);
    }
    g
}

pub(crate) use crate::linalg::solve_checked as lu_solve;

/// Euclidean norm of column `j`.
pub(crate) fn col_norm(m: &Mat<f64>, j: usize) -> f64 {
    (0..m.nrows()).map(|i| m[(i, j)] * m[(i, j)]).sum::<f64>().sqrt()
}

/// Stacks column vectors into an `n x m` matrix (`m` may be 0).
pub(crate) fn stack_columns(n: usize, cols: &[Vec<f64>]) -> Mat<f64> {
    Mat::from_fn(n, cols.len(), |i, j| cols[j][i])
}
