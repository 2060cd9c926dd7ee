//! Sparse Craig-Bampton reduction (fixed-interface component mode synthesis).
//!
//! DoFs split into boundary (kept) `b` and interior `i`. With the constraint modes
//! `Psi = -K_ii^-1 K_ib` and the lowest mass-normalised fixed-interface modes `Phi`
//! (`K_ii Phi = M_ii Phi diag(lambda)`), physical DoFs are
//!
//! ```text
//! x_b = q_b,      x_i = Psi q_b + Phi p,      x = T [q_b; p]
//! ```
//!
//! and the reduced matrices `T^T K T`, `T^T M T` are dense of size `n_b + n_modes`:
//! `K_red = [K_bb + K_bi Psi, 0; 0, diag(lambda)]`,
//! `M_red = [M_bb + M_bi Psi + Psi^T (M_ib + M_ii Psi), (.)^T; Phi^T (M_ib + M_ii Psi), Phi^T M_ii Phi]`.
//! `K_ii` is factorised once (sparse Cholesky) and `Psi` is solved for in blocks of boundary
//! columns; `Psi^T (M_ib + M_ii Psi)` is `-K_bi K_ii^-1 (M_ib + M_ii Psi)` (a second solve per
//! block), so the whole `n_i x n_b` matrix `Psi` is formed only if it is kept for recovery
//! ([`CbOptions::keep_recovery`]); otherwise the working set is the factor plus
//! `n_i x (n_modes + a few hundred)` dense columns. The modes come from
//! [`super::eigen::lowest_modes`]. No `n x n` dense block is ever formed. The products of the
//! sparse blocks with the dense `n_i x BLOCK` columns gather along contiguous rows
//! ([`crate::linalg::sparse::spmm_t`], the same bits as faer's product), and each block's solve
//! splits its columns among the threads ([`SparseCholesky::solve_in_place`], the same bits as
//! faer's solve): on the refinement-15 blade (140,658 DoFs, 5,793 boundary DoFs, 50 modes)
//! 158 s at 4.2 GB (267 s with faer's solve, 573 s with faer's product as well). The
//! fixed-interface modes run alongside the first blocks (see below): 143 s at 4.7 GB. The
//! large temporaries (`Psi_B`, `X_B`, the products' transposed blocks, the solves' workspaces)
//! are allocated once and reused by every block ([`BlockBuffers`]): fresh ones cost the kernel
//! a zeroed page per 4 kB touched, 47 s of system time in that reduction: 105 to 131 s at
//! 4.9 GB over runs on this shared two-core machine (test profile), the same bits throughout.
//! The two solves of a block visit only the supernodes that matter ([`SparseCholesky::reach`]):
//! the forward half of `K_ii^-1 K_iB` those its nonzero rows reach (about 45 % of the factor's
//! values), the backward half of `K_ii^-1 X_B` those the interior DoFs coupled to the boundary
//! need (79 %), which is all `K_bi` reads. The four half solves of a block cost 3.2 instead of
//! 4 passes over the factor: 131 -> 113 s (test profile), 118.5 s (release), 135.5 -> 124.9 s
//! in `cargo bench --bench jp_blade_2k` (same bits: the reduced matrices hash as before at
//! refinements 1, 5, 8 and 15).

use crate::linalg::lanczos::{lowest_modes, RowReach, SparseCholesky};
use crate::linalg::sparse::{sparse_dense_block, sparse_dense_block_into, sparse_submatrix, sparse_transpose, spmm_by_transpose, spmm_t, MatPool, SparseMat};
use crate::error::{JpError, Result};
use faer::linalg::matmul::matmul;
use faer::{Accum, Mat, MatMut};

/// Estimated bytes of the dense parts of a Craig-Bampton reduction with `ni` interior and `nb`
/// boundary DoFs and up to `n_modes` fixed-interface modes: the reduced `K`, `M` (and `C`) and
/// `K_bb`, the modes with the Lanczos vectors (`3 n_modes` of length `ni`), the
/// `n_i x min(256, n_b)` column blocks kept across boundary blocks (`Psi_B`, one `X_B` per
/// projected matrix, the products' transposed blocks, the solves' workspaces, and one spare
/// for the products' outputs), the blocks kept while the modes are computed
/// ([`OVERLAP_BLOCKS`] per projected matrix), and with `keep_recovery` the constraint modes `Psi` (`n_i x n_b`). The sparse
/// factor of `K_ii` comes on top (its fill is known only once it is factored).
pub fn working_set_bytes(ni: usize, nb: usize, n_modes: usize, damping: bool, keep_recovery: bool) -> u128 {
    use crate::memory::{bytes_of, product};
    let nr = nb.saturating_add(n_modes);
    let reduced = product(&[3 + damping as usize, nr, nr]);
    let blocks = 4 + 1 + damping as usize;
    let vectors = product(&[ni, 3usize.saturating_mul(n_modes).saturating_add(blocks * BLOCK.min(nb))]);
    let overlap = product(&[OVERLAP_BLOCKS, 1 + damping as usize, ni, BLOCK.min(nb)]);
    let psi = if keep_recovery { product(&[ni, nb]) } else { 0 };
    bytes_of::<f64>(reduced.saturating_add(vectors).saturating_add(overlap).saturating_add(psi))
}

/// Options of the Craig-Bampton reduction.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CbOptions {
    /// Number of fixed-interface (interior) modes kept.
    pub n_modes: usize,
    /// Keep the constraint modes `Psi` (`n_i x n_b`) for recovering physical DoFs. Without them
    /// [`CraigBampton::recover`] and [`CraigBampton::reduce_force`] are unavailable, and the
    /// reduction holds no `n_i x n_b` dense block at all (the factor of `K_ii` plus a few
    /// `n_i x 256` blocks), which is what makes thousands of boundary DoFs fit.
    pub keep_recovery: bool,
    /// A cut-off frequency (Hz): keep the fixed-interface modes up to it, at most `n_modes` of
    /// them (`n_modes` is then a cap). `None`: exactly `n_modes` (or all there are).
    pub cutoff_hz: Option<f64>,
}

impl Default for CbOptions {
    fn default() -> Self {
        CbOptions { n_modes: 50, keep_recovery: true, cutoff_hz: None }
    }
}

/// A Craig-Bampton reduced model of sparse `K`, `M`: reduced coordinates are the boundary DoFs
/// (in the order given) followed by the modal coordinates.
#[derive(Clone, Debug)]
pub struct CraigBampton {
    /// Size of the full model.
    pub n_full: usize,
    /// Full-model DoFs kept, in reduced order (reduced index `k` <-> `boundary_dofs[k]`).
    pub boundary_dofs: Vec<usize>,
    /// Full-model interior DoFs, ascending (row `r` of `Psi`, `Phi` <-> `interior_dofs[r]`).
    pub interior_dofs: Vec<usize>,
    /// Reduced stiffness `T^T K T` (dense, symmetric, `n_b + n_modes`).
    pub stiffness: Mat<f64>,
    /// Reduced mass `T^T M T` (dense, symmetric, `n_b + n_modes`).
    pub mass: Mat<f64>,
    /// Reduced viscous damping `T^T C T`, when a `C` was given
    /// ([`CraigBampton::reduce_with_damping`]).
    pub damping: Option<Mat<f64>>,
    /// Fixed-interface eigenvalues `lambda = omega^2`, ascending.
    pub modal_eigenvalues: Vec<f64>,
    /// Fixed-interface modes `Phi` (`n_i x n_modes`, mass-normalised).
    pub fixed_interface_modes: Mat<f64>,
    /// Constraint modes `Psi = -K_ii^-1 K_ib` (`n_i x n_b`), if kept.
    pub constraint_modes: Option<Mat<f64>>,
}

const BLOCK: usize = 256;

impl CraigBampton {
    /// Reduces sparse symmetric `K`, `M` (full storage) onto `boundary` DoFs plus
    /// `options.n_modes` fixed-interface modes.
    ///
    /// # Errors
    /// [`JpError::BadSize`] for mismatched matrices, [`JpError::InvalidValue`] for repeated or
    /// out-of-range boundary DoFs, [`JpError::SingularMatrix`] if `K_ii` is not positive
    /// definite (the structure must be held by the boundary or by its own supports),
    /// [`JpError::Eigen`] if the modes do not converge.
    pub fn reduce(k: &SparseMat, m: &SparseMat, boundary: &[usize], options: CbOptions) -> Result<Self> {
        Self::reduce_with_damping(k, m, None, boundary, options)
    }

    /// As [`CraigBampton::reduce`], also projecting a viscous damping matrix `C` (sparse,
    /// symmetric, full storage) to `T^T C T` ([`CraigBampton::damping`]) the way `M` is.
    ///
    /// # Errors
    /// As [`CraigBampton::reduce`]; [`JpError::BadSize`] for a `C` of another size.
    pub fn reduce_with_damping(k: &SparseMat, m: &SparseMat, c: Option<&SparseMat>, boundary: &[usize], options: CbOptions) -> Result<Self> {
        let n = k.nrows();
        if k.ncols() != n {
            return Err(JpError::bad_size("stiffness (columns)", n, k.ncols()));
        }
        if m.nrows() != n || m.ncols() != n {
            return Err(JpError::bad_size("mass (rows)", n, m.nrows()));
        }
        if let Some(c) = c {
            if c.nrows() != n || c.ncols() != n {
                return Err(JpError::bad_size("damping (rows and columns)", n, if c.nrows() != n { c.nrows() } else { c.ncols() }));
            }
        }
        let mut b_map = vec![usize::MAX; n];
        for (r, &d) in boundary.iter().enumerate() {
            if d >= n {
                return Err(JpError::invalid("boundary DoFs", format!("DoF {d} >= model size {n}")));
            }
            if b_map[d] != usize::MAX {
                return Err(JpError::invalid("boundary DoFs", format!("DoF {d} listed twice")));
            }
            b_map[d] = r;
        }
        let interior: Vec<usize> = (0..n).filter(|&d| b_map[d] == usize::MAX).collect();
        let mut i_map = vec![usize::MAX; n];
        for (r, &d) in interior.iter().enumerate() {
            i_map[d] = r;
        }
        let (nb, ni) = (boundary.len(), interior.len());
        if ni == 0 {
            return Err(JpError::invalid("boundary DoFs", "no interior DoF left to reduce"));
        }
        if let Some(fc) = options.cutoff_hz {
            if !(fc.is_finite() && fc > 0.0) {
                return Err(JpError::invalid("Craig-Bampton cut-off frequency", format!("must be finite and > 0 Hz, got {fc}")));
            }
        }

        let cap = options.n_modes.min(ni);
        crate::memory::check(
            &format!(
                "the Craig-Bampton reduction ({ni} interior and {nb} boundary DoFs, up to {cap} fixed-interface modes{}; the factor of K_ii not counted)",
                if options.keep_recovery { ", constraint modes kept" } else { "" }
            ),
            working_set_bytes(ni, nb, cap, c.is_some(), options.keep_recovery),
        )?;
        let k_ii = sparse_submatrix(k, &i_map, ni, &interior);
        let k_ib = sparse_submatrix(k, &i_map, ni, boundary);
        let k_bb = sparse_dense_block(k, &b_map, nb, boundary);
        let m_ii = sparse_submatrix(m, &i_map, ni, &interior);
        let chol = SparseCholesky::factor(&k_ii, "interior stiffness K_ii")?;
        // The reduced matrices are sized for `cap` modes and cut to the modes found (fewer
        // with a cut-off frequency) once the modes are known.
        let nr_cap = nb + cap;
        // M and C are projected alike (`T^T A T`, A = M, C)
        let mut projected: Vec<MassLike> = std::iter::once(m)
            .chain(c)
            .enumerate()
            .map(|(which, a)| {
                let mut red = Mat::<f64>::zeros(nr_cap, nr_cap);
                red.as_mut().submatrix_mut(0, 0, nb, nb).copy_from(&sparse_dense_block(a, &b_map, nb, boundary));
                let a_ii_t = if which == 0 { sparse_transpose(&m_ii) } else { sparse_transpose(&sparse_submatrix(a, &i_map, ni, &interior)) };
                MassLike { a_ii_t, a_ib: sparse_submatrix(a, &i_map, ni, boundary), red }
            })
            .collect();
        let mut k_red = Mat::<f64>::zeros(nr_cap, nr_cap);
        k_red.as_mut().submatrix_mut(0, 0, nb, nb).copy_from(&k_bb);
        drop(k_bb);
        // Boundary columns in blocks B, never more than `n_i x BLOCK` dense at a time besides
        // the kept `Psi`:
        //   Psi_B = -K_ii^-1 K_iB,   X_B = A_iB + A_ii Psi_B   (A = M, C),
        //   K_red[b, B] = K_bB + K_bi Psi_B,   A_red[m, B] = Phi^T X_B,
        //   A_red[b, B] = A_bB + A_bi Psi_B + Psi^T X_B,  Psi^T X_B = -K_bi (K_ii^-1 X_B),
        // the last by a second solve, so the whole of `Psi` is never needed.
        // With `keep_recovery` the whole `Psi` is solved for first (one multi-right-hand-side
        // solve) and `Psi^T X_B` is a product, as before the blocked path existed: the blade-pair
        // stuck-limit test (tests/jp_blade_pair.rs) is sensitive to the difference.
        //
        // The fixed-interface modes (one-column shift-invert applications, which keep the
        // threads mostly waiting) run alongside the first blocks: those blocks keep their
        // `X_B` (at most `OVERLAP_BLOCKS` of them) until `Phi` is known. Every operation is the
        // one the sequential order makes, on the same data, so the bits are the same.
        let coupled = chol.reach(k_ib.symbolic().row_idx());
        let blocks = CbBlocks { nb, ni, all_i: identity_map(ni), k_ib: &k_ib, chol: &chol, coupled, keep_recovery: options.keep_recovery };
        let mut buffers = BlockBuffers { psi: Mat::new(), x: Vec::new(), gather: MatPool::default() };
        let done = std::sync::atomic::AtomicBool::new(false);
        let (modes, (psi_all, mut start, saved)) = rayon::join(
            || {
                let modes = fixed_interface_modes(&chol, &m_ii, cap, options.cutoff_hz);
                done.store(true, std::sync::atomic::Ordering::Release);
                modes
            },
            || {
                let psi_all = blocks.constraint_modes();
                let mut start = 0;
                let mut saved = Vec::new();
                let (fewest, most) = overlap_bounds();
                while start < nb
                    && saved.len() < most
                    && (saved.len() < fewest || !done.load(std::sync::atomic::Ordering::Acquire))
                {
                    let w = BLOCK.min(nb - start);
                    let xs = blocks.block(start, w, psi_all.as_ref(), &mut k_red, &mut projected, &mut buffers, None);
                    saved.push((start, w, xs));
                    start += w;
                }
                (psi_all, start, saved)
            },
        );
        let modes = modes?;
        drop(m_ii);
        let n_modes = modes.eigenvalues.len();
        let phi = modes.vectors;
        let nr = nb + n_modes;
        for (r, &lam) in modes.eigenvalues.iter().enumerate() {
            k_red[(nb + r, nb + r)] = lam;
        }
        let par = faer::get_global_parallelism();
        for (b_start, w, xs) in saved {
            for (a, x) in projected.iter_mut().zip(xs) {
                matmul(a.red.as_mut().submatrix_mut(nb, b_start, n_modes, w), Accum::Replace, phi.as_ref().transpose(), x.as_ref(), 1.0, par);
            }
        }
        while start < nb {
            let w = BLOCK.min(nb - start);
            blocks.block(start, w, psi_all.as_ref(), &mut k_red, &mut projected, &mut buffers, Some(&phi));
            start += w;
        }
        if nr < nr_cap {
            k_red = k_red.as_ref().submatrix(0, 0, nr, nr).to_owned();
            for a in projected.iter_mut() {
                a.red = a.red.as_ref().submatrix(0, 0, nr, nr).to_owned();
            }
        }
        drop(chol);
        for a in projected.iter_mut() {
            let mut aphi = Mat::<f64>::zeros(ni, n_modes);
            spmm_by_transpose(aphi.as_mut(), Accum::Replace, &a.a_ii_t, phi.as_ref(), 1.0, &buffers.gather);
            matmul(a.red.as_mut().submatrix_mut(nb, nb, n_modes, n_modes), Accum::Replace, phi.as_ref().transpose(), aphi.as_ref(), 1.0, par);
            // mode-boundary blocks: copy the lower block up, then symmetrise
            for j in nb..nr {
                for i in 0..nb {
                    a.red[(i, j)] = a.red[(j, i)];
                }
            }
            symmetrise(&mut a.red);
        }
        symmetrise(&mut k_red);
        let damping = if projected.len() > 1 { projected.pop().map(|a| a.red) } else { None };
        let m_red = projected.pop().map(|a| a.red).unwrap_or_else(|| Mat::zeros(nr, nr));
        Ok(CraigBampton {
            n_full: n,
            boundary_dofs: boundary.to_vec(),
            interior_dofs: interior,
            stiffness: k_red,
            mass: m_red,
            damping,
            modal_eigenvalues: modes.eigenvalues,
            fixed_interface_modes: phi,
            constraint_modes: psi_all,
        })
    }

    /// Number of reduced coordinates `n_b + n_modes`.
    pub fn n_reduced(&self) -> usize {
        self.boundary_dofs.len() + self.modal_eigenvalues.len()
    }

    /// Fixed-interface natural frequencies in Hz.
    pub fn modal_frequencies_hz(&self) -> Vec<f64> {
        self.modal_eigenvalues.iter().map(|l| l.sqrt() / (2.0 * std::f64::consts::PI)).collect()
    }

    /// Reduced force `T^T f` of a full-size force `f`.
    ///
    /// # Errors
    /// [`JpError::BadSize`] if `f` is not full size; [`JpError::InvalidValue`] if the
    /// constraint modes were not kept and `f` loads interior DoFs.
    pub fn reduce_force(&self, f: &[f64]) -> Result<Vec<f64>> {
        if f.len() != self.n_full {
            return Err(JpError::bad_size("full force", self.n_full, f.len()));
        }
        let nb = self.boundary_dofs.len();
        let mut out: Vec<f64> = self.boundary_dofs.iter().map(|&d| f[d]).collect();
        let fi = Mat::from_fn(self.interior_dofs.len(), 1, |r, _| f[self.interior_dofs[r]]);
        let loaded = fi.col(0).iter().any(|v| *v != 0.0);
        if loaded {
            let psi = self.constraint_modes.as_ref().ok_or_else(|| {
                JpError::invalid("reduce_force", "interior DoFs are loaded but constraint modes were not kept")
            })?;
            let pb = psi.transpose() * &fi;
            for r in 0..nb {
                out[r] += pb[(r, 0)];
            }
        }
        let pm = self.fixed_interface_modes.transpose() * &fi;
        out.extend((0..self.modal_eigenvalues.len()).map(|r| pm[(r, 0)]));
        Ok(out)
    }

    /// Physical (full-size) displacement `x = T q` of reduced coordinates `q`.
    ///
    /// # Errors
    /// [`JpError::BadSize`] for a wrong length, [`JpError::InvalidValue`] if the constraint
    /// modes were not kept.
    pub fn recover(&self, q: &[f64]) -> Result<Vec<f64>> {
        let nb = self.boundary_dofs.len();
        if q.len() != self.n_reduced() {
            return Err(JpError::bad_size("reduced coordinates", self.n_reduced(), q.len()));
        }
        let psi = self
            .constraint_modes
            .as_ref()
            .ok_or_else(|| JpError::invalid("recover", "constraint modes were not kept"))?;
        let qb = Mat::from_fn(nb, 1, |r, _| q[r]);
        let p = Mat::from_fn(self.modal_eigenvalues.len(), 1, |r, _| q[nb + r]);
        let xi = psi * &qb + &self.fixed_interface_modes * &p;
        let mut x = vec![0.0; self.n_full];
        for (r, &d) in self.boundary_dofs.iter().enumerate() {
            x[d] = q[r];
        }
        for (r, &d) in self.interior_dofs.iter().enumerate() {
            x[d] = xi[(r, 0)];
        }
        Ok(x)
    }
}

/// The lowest `cap` fixed-interface modes, or with a cut-off those up to `cutoff_hz` (at most
/// `cap`): computed in batches that double until one reaches past the cut-off.
fn fixed_interface_modes(chol: &SparseCholesky, m_ii: &SparseMat, cap: usize, cutoff_hz: Option<f64>) -> Result<crate::linalg::lanczos::SparseEigen> {
    let Some(fc) = cutoff_hz else {
        return lowest_modes(chol, m_ii, cap);
    };
    let lambda_cut = (2.0 * std::f64::consts::PI * fc).powi(2);
    let mut k = cap.min(20);
    loop {
        let modes = lowest_modes(chol, m_ii, k)?;
        let below = modes.eigenvalues.iter().take_while(|&&l| l <= lambda_cut).count();
        if below < modes.eigenvalues.len() || k >= cap {
            let n = modes.vectors.nrows();
            return Ok(crate::linalg::lanczos::SparseEigen {
                eigenvalues: modes.eigenvalues[..below].to_vec(),
                vectors: modes.vectors.as_ref().submatrix(0, 0, n, below).to_owned(),
            });
        }
        k = (2 * k).min(cap);
    }
}

/// A matrix projected the way `M` is: its interior and interior-boundary blocks, and `T^T A T`.
struct MassLike {
    /// `A_ii^T` (products `A_ii X` by [`spmm_by_transpose`]).
    a_ii_t: SparseMat,
    a_ib: SparseMat,
    red: Mat<f64>,
}

/// Most boundary blocks processed alongside the fixed-interface modes, each keeping its `X_B`
/// (`n_i x BLOCK` per projected matrix) until the modes are known (see
/// [`CraigBampton::reduce_with_damping`]).
const OVERLAP_BLOCKS: usize = 4;

/// `(fewest, most)` blocks processed alongside the modes: `(0, OVERLAP_BLOCKS)`, as many as
/// fit before the modes are done.
#[cfg(not(test))]
fn overlap_bounds() -> (usize, usize) {
    (0, OVERLAP_BLOCKS)
}

/// The test build sets both bounds, to compare the reduction with and without the overlap (the
/// same bits either way).
#[cfg(test)]
static OVERLAP_BOUNDS: std::sync::Mutex<(usize, usize)> = std::sync::Mutex::new((0, OVERLAP_BLOCKS));

#[cfg(test)]
fn overlap_bounds() -> (usize, usize) {
    *OVERLAP_BOUNDS.lock().unwrap_or_else(|e| e.into_inner())
}

/// The dense `n_i x BLOCK` columns of one boundary block, allocated once and reused by every
/// block: a fresh `n_i x BLOCK` matrix per block costs the kernel a zeroed page per 4 kB
/// (see [`SparseCholesky::solve_in_place`]'s workspace, which is kept the same way).
struct BlockBuffers {
    /// `Psi_B`.
    psi: Mat<f64>,
    /// `X_B`, one per projected matrix.
    x: Vec<Mat<f64>>,
    /// The transposed column blocks of the sparse products ([`spmm_t`]).
    gather: MatPool,
}

/// The first `w` columns of `buf`, which is made `rows x cols` first if it is not.
fn columns(buf: &mut Mat<f64>, rows: usize, cols: usize, w: usize) -> MatMut<'_, f64> {
    if buf.nrows() != rows || buf.ncols() != cols {
        *buf = Mat::zeros(rows, cols);
    }
    buf.as_mut().subcols_mut(0, w)
}

/// The boundary-column blocks of the reduction (the loop of
/// [`CraigBampton::reduce_with_damping`]).
struct CbBlocks<'a> {
    nb: usize,
    ni: usize,
    /// `0..n_i`, the row map of the interior blocks.
    all_i: Vec<usize>,
    k_ib: &'a SparseMat,
    chol: &'a SparseCholesky,
    /// The interior DoFs coupled to the boundary (the rows of `K_ib`), which are all that
    /// `K_bi (K_ii^-1 X_B)` reads, with the supernodes their solve needs.
    coupled: RowReach,
    keep_recovery: bool,
}

impl CbBlocks<'_> {
    /// With `keep_recovery`, the whole `Psi = -K_ii^-1 K_ib` (one multi-right-hand-side solve).
    fn constraint_modes(&self) -> Option<Mat<f64>> {
        if !self.keep_recovery {
            return None;
        }
        let mut all = sparse_dense_block(self.k_ib, &self.all_i, self.ni, &identity_map(self.nb));
        self.chol.solve_in_place(all.as_mut());
        all *= faer::Scale(-1.0);
        Some(all)
    }

    /// Block `B = start..start + w`: `K_red[b, B]`, `A_red[b, B]` and, with `phi`,
    /// `A_red[m, B] = Phi^T X_B`; without `phi` the `X_B` are returned (one per projected
    /// matrix) for that product later.
    fn block(
        &self,
        start: usize,
        w: usize,
        psi_all: Option<&Mat<f64>>,
        k_red: &mut Mat<f64>,
        projected: &mut [MassLike],
        buffers: &mut BlockBuffers,
        phi: Option<&Mat<f64>>,
    ) -> Vec<Mat<f64>> {
        let (nb, ni) = (self.nb, self.ni);
        let par = faer::get_global_parallelism();
        let all_i = &self.all_i;
        let cols: Vec<usize> = (start..start + w).collect();
        let width = BLOCK.min(nb);
        let mut psi = columns(&mut buffers.psi, ni, width, w);
        match psi_all {
            Some(all) => psi.copy_from(all.as_ref().subcols(start, w)),
            None => {
                sparse_dense_block_into(psi.as_mut(), self.k_ib, all_i, &cols);
                self.chol.solve_in_place(psi.as_mut());
                psi *= faer::Scale(-1.0);
            }
        }
        let psi = psi.as_ref();
        spmm_t(k_red.as_mut().submatrix_mut(0, start, nb, w), Accum::Add, self.k_ib, psi, 1.0, &buffers.gather);
        let mut kept = Vec::new();
        buffers.x.resize_with(projected.len(), Mat::new);
        for (a, x_buf) in projected.iter_mut().zip(buffers.x.iter_mut()) {
            let mut x = columns(x_buf, ni, width, w);
            sparse_dense_block_into(x.as_mut(), &a.a_ib, all_i, &cols);
            spmm_by_transpose(x.as_mut(), Accum::Add, &a.a_ii_t, psi, 1.0, &buffers.gather);
            spmm_t(a.red.as_mut().submatrix_mut(0, start, nb, w), Accum::Add, &a.a_ib, psi, 1.0, &buffers.gather);
            match phi {
                Some(phi) => {
                    let n_modes = phi.ncols();
                    matmul(a.red.as_mut().submatrix_mut(nb, start, n_modes, w), Accum::Replace, phi.as_ref().transpose(), x.as_ref(), 1.0, par);
                }
                None => kept.push(x.to_owned()),
            }
            match psi_all {
                Some(all) => matmul(a.red.as_mut().submatrix_mut(0, start, nb, w), Accum::Add, all.as_ref().transpose(), x.as_ref(), 1.0, par),
                None => {
                    self.chol.solve_in_place_for(x.as_mut(), &self.coupled);
                    spmm_t(a.red.as_mut().submatrix_mut(0, start, nb, w), Accum::Add, self.k_ib, x.as_ref(), -1.0, &buffers.gather);
                }
            }
        }
        kept
    }
}

/// `A <- (A + A^T) / 2`.
fn symmetrise(a: &mut Mat<f64>) {
    for j in 0..a.ncols() {
        for i in 0..j {
            let s = 0.5 * (a[(i, j)] + a[(j, i)]);
            a[(i, j)] = s;
            a[(j, i)] = s;
        }
    }
}

fn identity_map(n: usize) -> Vec<usize> {
    (0..n).collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::linalg::sparse::sparse_from_triplets;

    /// The modes computed alongside the first blocks give the same bits as the modes first:
    /// a 3D grid of 5,832 DoFs with one face (324 DoFs) and an edge as the boundary, two
    /// blocks of 256 columns, with and without constraint modes and damping, and with a
    /// cut-off frequency that keeps fewer modes than the cap.
    #[test]
    fn modes_alongside_the_blocks_give_the_same_bits() {
        let g = 18usize;
        let n = g * g * g;
        let id = |x: usize, y: usize, z: usize| (x * g + y) * g + z;
        let mut tk: Vec<(usize, usize, f64)> = (0..n).map(|i| (i, i, 6.0 + 0.01 * (i % 7) as f64)).collect();
        let mut tm: Vec<(usize, usize, f64)> = (0..n).map(|i| (i, i, 1.0 + 0.001 * (i % 3) as f64)).collect();
        let tc: Vec<(usize, usize, f64)> = (0..n).map(|i| (i, i, 0.02)).collect();
        for (i, j) in crate::linalg::sparse::grid_edges([g, g, g]) {
            tk.extend([(i, j, -1.0), (j, i, -1.0)]);
            tm.extend([(i, j, 0.05), (j, i, 0.05)]);
        }
        let k = sparse_from_triplets(n, n, tk).unwrap();
        let m = sparse_from_triplets(n, n, tm).unwrap();
        let c = sparse_from_triplets(n, n, tc).unwrap();
        let mut boundary: Vec<usize> = (0..g * g).map(|r| id(0, r / g, r % g)).collect();
        boundary.extend((1..g).map(|x| id(x, 0, 0)));
        assert!(boundary.len() > BLOCK, "two blocks at least");
        let bits = |cb: &CraigBampton| {
            let mut v = Vec::new();
            for a in [Some(&cb.stiffness), Some(&cb.mass), cb.damping.as_ref(), cb.constraint_modes.as_ref()].into_iter().flatten() {
                for j in 0..a.ncols() {
                    v.extend((0..a.nrows()).map(|i| a[(i, j)].to_bits()));
                }
            }
            v.extend(cb.modal_eigenvalues.iter().map(|l| l.to_bits()));
            v
        };
        let mut cut = None;
        for (keep_recovery, damping, with_cutoff) in [(false, false, false), (true, true, false), (false, true, true)] {
            let cutoff_hz = if with_cutoff { cut } else { None };
            let options = CbOptions { n_modes: 12, keep_recovery, cutoff_hz };
            let run = |bounds: (usize, usize)| {
                *OVERLAP_BOUNDS.lock().unwrap() = bounds;
                let cb = CraigBampton::reduce_with_damping(&k, &m, damping.then_some(&c), &boundary, options).unwrap();
                *OVERLAP_BOUNDS.lock().unwrap() = (0, OVERLAP_BLOCKS);
                cb
            };
            let first = run((0, 0));
            let alongside = run((2, 2));
            if !with_cutoff {
                let f = first.modal_frequencies_hz();
                cut = Some(0.5 * (f[5] + f[6]));
            } else {
                let kept = first.modal_eigenvalues.len();
                assert!(kept > 0 && kept < 12, "the cut-off must keep some but not all modes, kept {kept}");
            }
            assert_eq!(first.n_reduced(), alongside.n_reduced());
            let (a, b) = (bits(&first), bits(&alongside));
            assert_eq!(a.len(), b.len());
            let differ = a.iter().zip(&b).filter(|(x, y)| x != y).count();
            assert_eq!(differ, 0, "keep_recovery {keep_recovery}, damping {damping}, cut-off {cutoff_hz:?}: {differ} of {} values differ", a.len());
        }
    }
}
