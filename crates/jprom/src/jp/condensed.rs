//! The condensed stiffness of the JP eigenproblem (paper (28)-(30)): `K_JC` on the harmonic
//! coefficients `1..=2H` after the static condensation, and its contact part `S`, shared by
//! the dense and the shift-invert eigen solvers.

use super::ContactJacobian;
use crate::model::ContactCoordinates;
use faer::Mat;

/// The condensed stiffness `K_JC` (30) on the coefficients `1..=2H` (block `c - 1` of size `n`):
/// `δ_ij K + K̂_ij - K̂_i0 A_0^-1|_ww K̂_0j`, dense; the contact-coordinate part is
/// [`contact_condensation`].
pub(crate) fn condensed_stiffness(coords: &ContactCoordinates, k_hat: &ContactJacobian, g_ww: &Mat<f64>) -> Mat<f64> {
    let (n, nw) = (coords.n_dof, coords.n_w);
    let nj = 2 * k_hat.harmonics;
    let mut kjc = Mat::<f64>::zeros(nj * n, nj * n);
    for c in 0..nj {
        kjc.as_mut().submatrix_mut(c * n, c * n, n, n).copy_from(&coords.stiffness);
    }
    let s = contact_condensation(coords, k_hat, g_ww);
    for ci in 0..nj {
        for cj in 0..nj {
            for j in 0..nw {
                for i in 0..nw {
                    kjc[(ci * n + i, cj * n + j)] += s[(ci * nw + i, cj * nw + j)];
                }
            }
        }
    }
    kjc
}

/// `S_ij = K̂_ij - K̂_i0 g_ww K̂_0j` on the contact coordinates of the coefficients `1..=2H`
/// (block `c - 1` of size `n_w`), `g_ww = A_0^-1|_ww` the contact block of the static
/// condensation (28): the part of `K_JC` (30) that the contacts add, shared by the dense and the
/// shift-invert paths. When `K̂` is block-diagonal by contact (checked) the products cost
/// `O(n_w^2)`, not `O(n_w^3)`.
pub(crate) fn contact_condensation(coords: &ContactCoordinates, k_hat: &ContactJacobian, g_ww: &Mat<f64>) -> Mat<f64> {
    let nw = coords.n_w;
    let nj = 2 * k_hat.harmonics;
    let (laws, offsets) = (&coords.laws, &coords.offsets);
    let per_contact = k_hat.is_per_contact(laws, offsets);
    let mut s = Mat::<f64>::zeros(nj * nw, nj * nw);
    for ci in 1..=nj {
        // K̂_i0 A0^-1|_ww
        let left = if per_contact { k_hat.block_times(ci, 0, g_ww.as_ref(), laws, offsets) } else { k_hat.block(ci, 0) * g_ww };
        for cj in 1..=nj {
            let corr = if per_contact { k_hat.times_block(left.as_ref(), 0, cj, laws, offsets) } else { &left * k_hat.block(0, cj) };
            let kij = k_hat.block(ci, cj);
            for j in 0..nw {
                for i in 0..nw {
                    s[((ci - 1) * nw + i, (cj - 1) * nw + j)] = kij[(i, j)] - corr[(i, j)];
                }
            }
        }
    }
    s
}
