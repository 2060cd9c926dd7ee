//! Sparse symmetric positive definite factorisation and the lowest eigenpairs of a sparse
//! generalised problem `K x = lambda M x` by shift-invert Lanczos.
//!
//! With the fill-reducing permutation `P` and `P K P^T = L L^T` (faer's supernodal sparse
//! Cholesky), the symmetric operator
//!
//! ```text
//! A = L^-1 P M P^T L^-T
//! ```
//!
//! has eigenvalues `mu = 1 / lambda`, so its largest ones are the lowest modes. faer's
//! matrix-free Krylov-Schur solver (`faer::matrix_free::eigen::partial_self_adjoint_eigen`)
//! finds them; an eigenvector `y` of `A` maps back to `x = P^T L^-T y / sqrt(mu)`, which is
//! mass-normalised (`x^T M x = 1`, `x^T K x = lambda`).

use super::sparse::SparseMat;
use crate::error::{JpError, Result};
use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::matrix_free::LinOp;
use faer::sparse::linalg::cholesky::{
    factorize_symbolic_cholesky, supernodal::SupernodalLltRef, CholeskySymbolicParams, LltRef, SymbolicCholesky,
    SymbolicCholeskyRaw, SymmetricOrdering,
};
use faer::sparse::linalg::SupernodalThreshold;
use faer::{Accum, Conj, Mat, MatMut, MatRef, Par, Side};

/// Sparse Cholesky factor `P A P^T = L L^T` of a symmetric positive definite matrix, with the
/// half solves that the symmetric shift-invert operator needs.
pub struct SparseCholesky {
    symbolic: SymbolicCholesky<usize>,
    values: Vec<f64>,
    n: usize,
    ordering: FillOrdering,
    /// Supernodal factor: the supernode of each (permuted) row, and each supernode's parent in
    /// the elimination tree (`usize::MAX` at a root). Empty for a simplicial factor.
    supernode_of_row: Vec<usize>,
    parent: Vec<usize>,
    /// Solve workspaces kept between solves (see [`SparseCholesky::with_scratch`]).
    scratch: std::sync::Mutex<Vec<(StackReq, MemBuffer)>>,
}

impl std::fmt::Debug for SparseCholesky {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("SparseCholesky").field("n", &self.n).field("ordering", &self.ordering).field("factor_nnz", &self.values.len()).finish_non_exhaustive()
    }
}

/// The fill-reducing ordering a [`SparseCholesky`] was factorised with.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FillOrdering {
    /// faer's approximate minimum degree.
    Amd,
    /// [`super::ordering::nested_dissection`].
    NestedDissection,
}

/// Most solve workspaces a factor keeps between solves (one per concurrent solve).
const KEPT_SCRATCH: usize = 4;

fn par() -> Par {
    faer::get_global_parallelism()
}

/// Threads of the global parallelism.
fn threads() -> usize {
    match par() {
        Par::Seq => 1,
        Par::Rayon(n) => n.get(),
    }
}

/// The supernodes a backward solve needs for some rows of the solution
/// ([`SparseCholesky::reach`]).
#[derive(Debug, Clone)]
pub struct RowReach {
    supernodes: Vec<bool>,
}

/// The supernode of each permuted row and each supernode's parent (the supernode holding the
/// first off-diagonal row of its pattern; `usize::MAX` at a root). Empty for a simplicial factor.
fn supernode_tree(symbolic: &SymbolicCholesky<usize>, n: usize) -> (Vec<usize>, Vec<usize>) {
    let SymbolicCholeskyRaw::Supernodal(s) = symbolic.raw() else { return (Vec::new(), Vec::new()) };
    let ns = s.n_supernodes();
    let mut of_row = vec![0usize; n];
    for k in 0..ns {
        for r in s.supernode_begin()[k]..s.supernode_end()[k] {
            of_row[r] = k;
        }
    }
    let (cp, ri) = (s.col_ptr_for_row_idx(), s.row_idx());
    let parent = (0..ns).map(|k| if cp[k] < cp[k + 1] { of_row[ri[cp[k]]] } else { usize::MAX }).collect();
    (of_row, parent)
}

/// Smallest matrix for which [`SparseCholesky::factor`] tries a nested-dissection ordering
/// beside AMD. On the blade's interior stiffness `K_ii` AMD left as little fill at 33,555
/// unknowns (18.4 M values against 18.7 M), 14 % more at 59,643 and 34 % more at 134,865;
/// below this size AMD is kept, and with it the bits of the smaller models' reductions.
pub const NESTED_DISSECTION_MIN: usize = 50_000;

/// Fewest columns per thread for which [`SparseCholesky::solve_in_place`] splits the columns
/// among the threads.
pub const SPLIT_COLUMNS: usize = 16;

impl SparseCholesky {
    /// Factorises the symmetric positive definite `a` (full or lower storage: the lower
    /// triangle is read), with a supernodal factor and the fill-reducing ordering, AMD or nested
    /// dissection ([`super::ordering`]), whose factor holds fewer values.
    ///
    /// # Errors
    /// [`JpError::BadSize`] if `a` is not square, [`JpError::SingularMatrix`] naming `what`
    /// if it is not numerically positive definite, [`JpError::InvalidValue`] if out of memory.
    pub fn factor(a: &SparseMat, what: &str) -> Result<Self> {
        Self::factor_with(a, what, a.nrows() >= NESTED_DISSECTION_MIN)
    }

    /// [`SparseCholesky::factor`] that tries the nested dissection (of a matrix of at least
    /// `4 ordering::LEAF` rows) when `nested_dissection` is true, whatever its size, and keeps
    /// AMD's ordering when it is false.
    ///
    /// # Errors
    /// As [`SparseCholesky::factor`].
    pub fn factor_with(a: &SparseMat, what: &str, nested_dissection: bool) -> Result<Self> {
        let n = a.nrows();
        if a.ncols() != n {
            return Err(JpError::bad_size(format!("{what} (columns)"), n, a.ncols()));
        }
        let params = CholeskySymbolicParams {
            supernodal_flop_ratio_threshold: SupernodalThreshold::FORCE_SUPERNODAL,
            ..Default::default()
        };
        let symbolic_with = |ordering: SymmetricOrdering<'_, usize>| {
            factorize_symbolic_cholesky(a.as_ref().symbolic(), Side::Lower, ordering, params)
                .map_err(|e| JpError::invalid(what, format!("symbolic Cholesky failed: {e:?}")))
        };
        // the ordering of smaller fill: AMD, or (on graphs large enough to split) a nested
        // dissection (linalg::ordering)
        let amd = symbolic_with(SymmetricOrdering::Amd)?;
        let dissection = if nested_dissection && n >= 4 * super::ordering::LEAF {
            let order = super::ordering::nested_dissection(a.as_ref().symbolic());
            // its inverse; an order that is not a permutation (it should not happen) is not used
            let mut inv = vec![usize::MAX; n];
            for (k, &v) in order.iter().enumerate() {
                if v < n && inv[v] == usize::MAX {
                    inv[v] = k;
                }
            }
            if order.len() == n && inv.iter().all(|&k| k < n) {
                Some(symbolic_with(SymmetricOrdering::Custom(faer::perm::PermRef::new_checked(&order, &inv, n)))?)
            } else {
                None
            }
        } else {
            None
        };
        let (symbolic, ordering) = match dissection {
            Some(nd) if nd.len_val() < amd.len_val() => (nd, FillOrdering::NestedDissection),
            _ => (amd, FillOrdering::Amd),
        };
        let mut values = vec![0.0; symbolic.len_val()];
        {
            let req = symbolic.factorize_numeric_llt_scratch::<f64>(par(), Default::default());
            let mut mem = MemBuffer::try_new(req).map_err(|_| JpError::invalid(what, "out of memory"))?;
            symbolic
                .factorize_numeric_llt::<f64>(
                    &mut values,
                    a.as_ref(),
                    Side::Lower,
                    Default::default(),
                    par(),
                    MemStack::new(&mut mem),
                    Default::default(),
                )
                .map_err(|_| JpError::singular(format!("{what} (not positive definite)")))?;
        }
        if values.iter().any(|v| !v.is_finite()) {
            return Err(JpError::singular(format!("{what} (non-finite Cholesky factor)")));
        }
        let (supernode_of_row, parent) = supernode_tree(&symbolic, n);
        Ok(SparseCholesky { symbolic, values, n, ordering, supernode_of_row, parent, scratch: std::sync::Mutex::new(Vec::new()) })
    }

    /// Runs `f` on a workspace of `req`, reusing one that an earlier solve of the same shape
    /// left (at most [`KEPT_SCRATCH`] are kept). A solve's workspace holds an `n x k` block
    /// (the permuted right-hand sides): a fresh one per solve costs the kernel a zeroed page per
    /// 4 kB touched, which on the 140,658-DoF blade's Craig-Bampton (46 solves of 128 columns a
    /// thread) was about a sixth of the processor time. The workspace's contents are written
    /// before they are read, so reuse does not change the result.
    fn with_scratch<R>(&self, req: StackReq, f: impl FnOnce(&mut MemStack) -> R) -> R {
        let pool = || self.scratch.lock().unwrap_or_else(|e| e.into_inner());
        let kept = {
            let mut p = pool();
            p.iter().position(|(r, _)| *r == req).map(|i| p.swap_remove(i).1)
        };
        let mut mem = kept.unwrap_or_else(|| MemBuffer::new(req));
        let out = f(MemStack::new(&mut mem));
        let mut p = pool();
        if p.len() < KEPT_SCRATCH {
            p.push((req, mem));
        }
        out
    }

    /// Size of the factorised matrix.
    pub fn n(&self) -> usize {
        self.n
    }

    /// The fill-reducing ordering chosen (the one of fewer stored values of `L`).
    pub fn ordering(&self) -> FillOrdering {
        self.ordering
    }

    /// Number of stored values of `L`.
    pub fn factor_nnz(&self) -> usize {
        self.values.len()
    }

    /// Solves `A X = B` in place (any number of columns). With several threads and at least
    /// [`SPLIT_COLUMNS`] columns a thread, the columns are split among the threads, each
    /// solving its share alone: faer's operations, the same bits as faer's solve on all threads
    /// where the supernodes are small (an AMD factor), the same to rounding where faer's
    /// products on large supernodes sum in an order that depends on the number of columns (unit
    /// test below; faer's supernodal solve runs the supernodes in sequence and shares only each
    /// supernode's small products among the threads, which left them mostly waiting). The
    /// Craig-Bampton of the refinement-8 blade (61,404 DoFs, blocks of 256 boundary columns)
    /// 31.1 -> 22.2 s, of the refinement-15 blade (140,658 DoFs) 267 -> 158 s. The solves'
    /// workspaces are kept between calls ([`SparseCholesky::with_scratch`]).
    ///
    /// The forward solve visits only the supernodes that the right-hand sides reach (those of
    /// their nonzero rows and their ancestors in the elimination tree): the others would only
    /// see zeros. A Craig-Bampton block `K_iB` of the refinement-15 blade reaches about 45 % of
    /// the factor. The operations on the visited supernodes are faer's, in its order, so the
    /// bits are faer's solve's.
    pub fn solve_in_place(&self, rhs: MatMut<'_, f64>) {
        self.solve_split(rhs, threads(), None);
    }

    /// [`SparseCholesky::solve_in_place`] where only the rows of `wanted` are needed: the
    /// backward solve visits only their supernodes and those supernodes' ancestors, which give
    /// those rows exactly as the full solve does (and the other rows of those supernodes); the
    /// rows of the supernodes not visited are set to NaN. In a
    /// Craig-Bampton reduction `K_bi K_ii^-1 X` needs `K_ii^-1 X` only on the interior DoFs
    /// coupled to the boundary (about 80 % of the refinement-15 blade's factor).
    ///
    /// # Panics
    /// If `wanted` is not of this factor.
    pub fn solve_in_place_for(&self, rhs: MatMut<'_, f64>, wanted: &RowReach) {
        assert_eq!(wanted.supernodes.len(), self.parent.len(), "a RowReach of another factor");
        self.solve_split(rhs, threads(), Some(wanted));
    }

    /// The supernodes that the rows `rows` (the matrix's numbering) depend on in a backward
    /// solve (see [`SparseCholesky::solve_in_place_for`]).
    ///
    /// # Panics
    /// If a row is out of range.
    pub fn reach(&self, rows: &[usize]) -> RowReach {
        let mut supernodes = vec![false; self.parent.len()];
        let inv = self.symbolic.perm().map(|p| p.arrays().1);
        for &r in rows {
            let pr = inv.map_or(r, |inv| inv[r]);
            if !self.parent.is_empty() {
                self.mark_ancestors(&mut supernodes, self.supernode_of_row[pr]);
            }
        }
        RowReach { supernodes }
    }

    /// Fraction of the factor's values in the supernodes of `reach`.
    pub fn reached_fraction(&self, reach: &RowReach) -> f64 {
        let SymbolicCholeskyRaw::Supernodal(s) = self.symbolic.raw() else { return 1.0 };
        let cv = s.col_ptr_for_val();
        let sum: usize = (0..s.n_supernodes()).filter(|&k| reach.supernodes[k]).map(|k| cv[k + 1] - cv[k]).sum();
        sum as f64 / self.values.len().max(1) as f64
    }

    /// Marks supernode `s` and its ancestors (stopping at the first one already marked).
    fn mark_ancestors(&self, marked: &mut [bool], s: usize) {
        let mut s = s;
        while s != usize::MAX && !marked[s] {
            marked[s] = true;
            s = self.parent[s];
        }
    }

    /// The solve, with the columns split among `threads` threads when each gets at least
    /// [`SPLIT_COLUMNS`] of them.
    fn solve_split(&self, rhs: MatMut<'_, f64>, threads: usize, wanted: Option<&RowReach>) {
        let k = rhs.ncols();
        if threads > 1 && k >= 2 * SPLIT_COLUMNS {
            let left = threads / 2;
            let mid = k * left / threads;
            let (a, b) = rhs.split_at_col_mut(mid);
            rayon::join(|| self.solve_split(a, left, wanted), || self.solve_split(b, threads - left, wanted));
            return;
        }
        let inner = if threads > 1 { par() } else { Par::Seq };
        self.solve_with(rhs, inner, wanted);
    }

    /// `P^T L^-T L^-1 P` applied in place: faer's `LltRef::solve_in_place_with_conj` (the same
    /// permutation, supernode loop and dense kernels), visiting in the forward solve only the
    /// supernodes the right-hand sides reach and, with `wanted`, in the backward solve only
    /// those its rows depend on.
    fn solve_with(&self, rhs: MatMut<'_, f64>, p: Par, wanted: Option<&RowReach>) {
        use faer::linalg::matmul::matmul_with_conj;
        use faer::linalg::triangular_solve::{solve_lower_triangular_in_place_with_conj, solve_upper_triangular_in_place_with_conj};
        use faer::linalg::{temp_mat_scratch, temp_mat_uninit};
        use faer::mat::AsMatMut;
        let mut rhs = rhs;
        let (k, n) = (rhs.ncols(), self.n);
        let SymbolicCholeskyRaw::Supernodal(sym) = self.symbolic.raw() else {
            let req = self.symbolic.solve_in_place_scratch::<f64>(k, p);
            self.with_scratch(req, |stack| LltRef::new(&self.symbolic, &self.values).solve_in_place_with_conj(Conj::No, rhs, p, stack));
            return;
        };
        let req = StackReq::all_of(&[temp_mat_scratch::<f64>(n, k), sym.solve_in_place_scratch::<f64>(k, p)]);
        let l = SupernodalLltRef::new(sym, &self.values);
        let ns = sym.n_supernodes();
        let perm = self.symbolic.perm().map(|p| p.arrays());
        self.with_scratch(req, |stack| {
            // SAFETY: every entry of `x` is written (the permuted copy) before it is read.
            let (mut x, stack) = unsafe { temp_mat_uninit::<f64, _, _>(n, k, stack) };
            let mut x = x.as_mat_mut();
            match perm {
                Some((fwd, _)) => {
                    for j in 0..k {
                        for (i, &f) in fwd.iter().enumerate() {
                            x[(i, j)] = rhs[(f, j)];
                        }
                    }
                }
                None => x.copy_from(rhs.as_ref()),
            }
            // the supernodes the right-hand sides reach (any entry that is not zero, NaN included)
            let mut nonzero_row = vec![false; n];
            for j in 0..k {
                for (i, nz) in nonzero_row.iter_mut().enumerate() {
                    *nz |= x[(i, j)] != 0.0;
                }
            }
            let mut reached = vec![false; ns];
            for i in (0..n).filter(|&i| nonzero_row[i]) {
                self.mark_ancestors(&mut reached, self.supernode_of_row[i]);
            }
            for s in (0..ns).filter(|&s| reached[s]) {
                let s = l.supernode(s);
                let ls = s.val();
                let size = ls.ncols();
                let (ls_top, ls_bot) = ls.split_at_row(size);
                let mut x_top = x.as_mut().subrows_mut(s.start(), size);
                solve_lower_triangular_in_place_with_conj(ls_top, Conj::No, x_top.as_mut(), p);
                // SAFETY: `tmp` is written by the product (Accum::Replace) before it is read.
                let (mut tmp, _) = unsafe { temp_mat_uninit::<f64, _, _>(s.pattern().len(), k, stack) };
                let mut tmp = tmp.as_mat_mut();
                matmul_with_conj(tmp.as_mut(), Accum::Replace, ls_bot, Conj::No, x_top.as_ref(), Conj::No, 1.0, p);
                for j in 0..k {
                    for (idx, &i) in s.pattern().iter().enumerate() {
                        x[(i, j)] -= tmp[(idx, j)];
                    }
                }
            }
            let backward = |s: usize| wanted.is_none_or(|w| w.supernodes[s]);
            for s in (0..ns).rev().filter(|&s| backward(s)) {
                let s = l.supernode(s);
                let ls = s.val();
                let size = ls.ncols();
                let (ls_top, ls_bot) = ls.split_at_row(size);
                // SAFETY: every entry of `tmp` is written before it is read.
                let (mut tmp, _) = unsafe { temp_mat_uninit::<f64, _, _>(s.pattern().len(), k, stack) };
                let mut tmp = tmp.as_mat_mut();
                for j in 0..k {
                    for (idx, &i) in s.pattern().iter().enumerate() {
                        tmp[(idx, j)] = x[(i, j)];
                    }
                }
                let mut x_top = x.as_mut().subrows_mut(s.start(), size);
                matmul_with_conj(x_top.as_mut(), Accum::Add, ls_bot.transpose(), Conj::Yes, tmp.as_ref(), Conj::No, -1.0, p);
                solve_upper_triangular_in_place_with_conj(ls_top.transpose(), Conj::Yes, x_top.as_mut(), p);
            }
            let row_done = |pi: usize| wanted.is_none_or(|w| w.supernodes[self.supernode_of_row[pi]]);
            for j in 0..k {
                for i in 0..n {
                    let pi = perm.map_or(i, |(_, inv)| inv[i]);
                    rhs[(i, j)] = if row_done(pi) { x[(pi, j)] } else { f64::NAN };
                }
            }
        });
    }

    /// The half solve `x <- L^-1 x` (`transpose = false`) or `x <- L^-T x` in the permuted
    /// space. faer makes a supernodal factor when asked, except for matrices so small or sparse
    /// that it picks the simplicial one anyway (a Craig-Bampton interior of a few DoFs): that
    /// factor's `L` is solved column by column here.
    fn half_solve(&self, x: MatMut<'_, f64>, transpose: bool) {
        let mut x = x;
        let p = par();
        let k = x.ncols();
        match self.symbolic.raw() {
            SymbolicCholeskyRaw::Supernodal(s) => {
                let l = SupernodalLltRef::new(s, &self.values);
                self.with_scratch(s.solve_in_place_scratch::<f64>(k, p), |stack| {
                    if transpose {
                        l.l_transpose_solve_with_conj(Conj::No, x.as_mut(), p, stack);
                    } else {
                        l.l_solve_with_conj(Conj::No, x.as_mut(), p, stack);
                    }
                });
            }
            SymbolicCholeskyRaw::Simplicial(s) => {
                let (cp, ri, v) = (s.col_ptr(), s.row_idx(), &self.values);
                let n = self.n;
                let diag = |j: usize| (cp[j]..cp[j + 1]).find(|&p| ri[p] == j).map(|p| v[p]).expect("diagonal of L");
                for c in 0..k {
                    let mut col = x.as_mut().col_mut(c);
                    if transpose {
                        for j in (0..n).rev() {
                            let mut s_j = col[j];
                            for p in cp[j]..cp[j + 1] {
                                if ri[p] != j {
                                    s_j -= v[p] * col[ri[p]];
                                }
                            }
                            col[j] = s_j / diag(j);
                        }
                    } else {
                        for j in 0..n {
                            let xj = col[j] / diag(j);
                            col[j] = xj;
                            for p in cp[j]..cp[j + 1] {
                                if ri[p] != j {
                                    col[ri[p]] -= v[p] * xj;
                                }
                            }
                        }
                    }
                }
            }
        }
    }

    /// `x <- L^-1 P x` (one forward half solve, in the permuted space on output).
    pub fn l_solve_permuted(&self, x: MatMut<'_, f64>) {
        let mut x = x;
        let k = x.ncols();
        if let Some(perm) = self.symbolic.perm() {
            let fwd = perm.arrays().0;
            let tmp = Mat::from_fn(self.n, k, |i, j| x[(fwd[i], j)]);
            x.copy_from(&tmp);
        }
        self.half_solve(x, false);
    }

    /// `x <- P^T L^-T x` (one backward half solve, back to the original ordering).
    pub fn lt_solve_unpermuted(&self, x: MatMut<'_, f64>) {
        let mut x = x;
        let k = x.ncols();
        self.half_solve(x.as_mut(), true);
        if let Some(perm) = self.symbolic.perm() {
            let inv = perm.arrays().1;
            let tmp = Mat::from_fn(self.n, k, |i, j| x[(inv[i], j)]);
            x.copy_from(&tmp);
        }
    }
}

/// The symmetric shift-invert operator `A = L^-1 P M P^T L^-T`, times `scale`.
#[derive(Debug)]
struct ShiftInvert<'a> {
    chol: &'a SparseCholesky,
    mass: &'a SparseMat,
    scale: f64,
}

impl ShiftInvert<'_> {
    fn apply_to(&self, out: MatMut<'_, f64>, rhs: MatRef<'_, f64>) {
        let mut x = rhs.to_owned();
        self.chol.lt_solve_unpermuted(x.as_mut());
        let mut out = out;
        super::sparse::spmm(out.as_mut(), faer::Accum::Replace, self.mass, x.as_ref(), self.scale);
        self.chol.l_solve_permuted(out);
    }
}

impl LinOp<f64> for ShiftInvert<'_> {
    fn apply_scratch(&self, _rhs_ncols: usize, _par: Par) -> StackReq {
        StackReq::EMPTY
    }
    fn nrows(&self) -> usize {
        self.chol.n
    }
    fn ncols(&self) -> usize {
        self.chol.n
    }
    fn apply(&self, out: MatMut<'_, f64>, rhs: MatRef<'_, f64>, _par: Par, _stack: &mut MemStack) {
        self.apply_to(out, rhs);
    }
    fn conj_apply(&self, out: MatMut<'_, f64>, rhs: MatRef<'_, f64>, _par: Par, _stack: &mut MemStack) {
        self.apply_to(out, rhs);
    }
}

/// Lowest eigenpairs of `K x = lambda M x`: eigenvalues ascending, mass-normalised vectors.
#[derive(Clone, Debug)]
pub struct SparseEigen {
    /// Eigenvalues `lambda = omega^2`, ascending.
    pub eigenvalues: Vec<f64>,
    /// Mass-normalised eigenvectors as columns (`n x n_modes`).
    pub vectors: Mat<f64>,
}

/// Relative tolerance of the Lanczos residual (on the operator scaled to unit norm).
pub const LANCZOS_TOLERANCE: f64 = 1e-11;

/// Above this many interior DoFs the Krylov-Schur subspace of [`lowest_modes`] holds
/// `3 n_modes` vectors instead of `2 n_modes` (at least 64 either way). Measured on the hex8
/// plates of `benches/fe_cb.rs` (2 cores, 50 modes): at 200,385 DoFs, where one shift-invert
/// application takes 0.3 s, the 50 lowest modes had not converged after 14 min of restarts
/// with `2 n_modes`, and the whole Craig-Bampton takes 87 s with `3 n_modes`; at 60,147 DoFs
/// `2 n_modes` is the faster (13.5 s against 17.0 s). Models up to this size (every test
/// model, the blade to refinement 15) keep `2 n_modes`.
pub const LARGE_MODEL_DOFS: usize = 150_000;

/// `max_dim / n_modes` of the Krylov-Schur subspace for a problem of `n` DoFs (see
/// [`LARGE_MODEL_DOFS`]).
fn krylov_subspace_factor(n: usize) -> usize {
    if n > LARGE_MODEL_DOFS {
        3
    } else {
        2
    }
}

/// Computes the `n_modes` lowest eigenpairs of `K x = lambda M x` with `K` already factorised
/// (`chol`), `M` symmetric positive (semi-)definite. Small problems (`n <= max(2 n_modes, 64)
/// + 1`) fall back to a dense solve.
///
/// # Errors
/// [`JpError::BadSize`] for mismatched sizes, [`JpError::Eigen`] if fewer than `n_modes`
/// eigenpairs converge.
pub fn lowest_modes(chol: &SparseCholesky, mass: &SparseMat, n_modes: usize) -> Result<SparseEigen> {
    lowest_modes_in_subspace(chol, mass, n_modes, krylov_subspace_factor(chol.n))
}

/// [`lowest_modes`] with a Krylov-Schur subspace of `max(factor n_modes, 64)` vectors.
fn lowest_modes_in_subspace(chol: &SparseCholesky, mass: &SparseMat, n_modes: usize, factor: usize) -> Result<SparseEigen> {
    let n = chol.n;
    if mass.nrows() != n || mass.ncols() != n {
        return Err(JpError::bad_size("mass (rows)", n, mass.nrows()));
    }
    let n_modes = n_modes.min(n);
    if n_modes == 0 {
        return Ok(SparseEigen { eigenvalues: Vec::new(), vectors: Mat::zeros(n, 0) });
    }
    let max_dim = (factor * n_modes).max(64);
    // Dense operator for small problems (faer's Krylov-Schur needs n > its subspace size).
    let op0 = ShiftInvert { chol, mass, scale: 1.0 };
    let (mus, ys): (Vec<f64>, Mat<f64>) = if n <= max_dim + 1 {
        let mut a = Mat::<f64>::identity(n, n);
        let id = a.clone();
        op0.apply_to(a.as_mut(), id.as_ref());
        let a = Mat::from_fn(n, n, |i, j| 0.5 * (a[(i, j)] + a[(j, i)]));
        let (s, u) = crate::linalg::eigen::symmetric_eigen(&a, "dense fallback")?;
        // ascending mu -> take the largest n_modes, largest first
        let mus: Vec<f64> = (0..n_modes).map(|k| s[n - 1 - k]).collect();
        let ys = Mat::from_fn(n, n_modes, |i, k| u[(i, n - 1 - k)]);
        (mus, ys)
    } else {
        // Normalise the operator by its largest eigenvalue (power iteration estimate) so the
        // absolute Lanczos tolerance becomes relative.
        let est = crate::linalg::eigen::operator_norm_estimate(n, 30, |w, v| op0.apply_to(w, v));
        if !(est.is_finite() && est > 0.0) {
            return Err(JpError::Eigen { what: format!("shift-invert operator norm estimate {est}") });
        }
        let op = ShiftInvert { chol, mass, scale: 1.0 / est };
        let params = faer::matrix_free::eigen::PartialEigenParams { max_dim, ..Default::default() };
        let req = faer::matrix_free::eigen::partial_self_adjoint_eigen_scratch::<f64>(&op, n_modes, par(), params);
        let mut mem = MemBuffer::new(req);
        let mut vecs = Mat::<f64>::zeros(n, n_modes);
        let mut vals = vec![0.0; n_modes];
        let v0 = faer::Col::<f64>::from_fn(n, |i| 1.0 + ((i * 104729) % 17) as f64 / 17.0);
        let info = faer::matrix_free::eigen::partial_self_adjoint_eigen(
            vecs.as_mut(),
            &mut vals,
            &op,
            v0.as_ref(),
            LANCZOS_TOLERANCE,
            par(),
            MemStack::new(&mut mem),
            params,
        );
        if info.n_converged_eigen < n_modes {
            return Err(JpError::Eigen {
                what: format!("Lanczos converged {} of {n_modes} modes", info.n_converged_eigen),
            });
        }
        (vals.iter().map(|m| m * est).collect(), vecs)
    };
    // Sort descending mu (= ascending lambda) and map back.
    let mut order: Vec<usize> = (0..n_modes).collect();
    order.sort_by(|&a, &b| mus[b].partial_cmp(&mus[a]).unwrap_or(std::cmp::Ordering::Equal));
    let mut x = Mat::from_fn(n, n_modes, |i, k| ys[(i, order[k])]);
    chol.lt_solve_unpermuted(x.as_mut());
    let mut eigenvalues = Vec::with_capacity(n_modes);
    for (k, &o) in order.iter().enumerate() {
        let mu = mus[o];
        if !(mu.is_finite() && mu > 0.0) {
            return Err(JpError::Eigen { what: format!("non-positive shift-invert eigenvalue {mu:.3e}") });
        }
        let yn = ys.col(o).norm_l2();
        // x = L^-T y: x^T M x = y^T A y = mu |y|^2
        let s = 1.0 / (mu.sqrt() * yn);
        for i in 0..n {
            x[(i, k)] *= s;
        }
        eigenvalues.push(1.0 / mu);
    }
    Ok(SparseEigen { eigenvalues, vectors: x })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::linalg::sparse::sparse_from_triplets;

    /// `P^T L^-T L^-1 P x = A^-1 x` through the half solves, and the lowest eigenvalues against
    /// the dense ones, for a matrix small enough that faer picks its simplicial factor, and one
    /// large enough for the supernodal one.
    #[test]
    fn half_solves_compose_to_the_inverse_for_both_factor_kinds() {
        for (n, want_simplicial) in [(3usize, true), (400, false)] {
            let mut t = Vec::new();
            for i in 0..n {
                t.push((i, i, 4.0 + i as f64 * 0.01));
                // the small one diagonal (as a Craig-Bampton interior of one node's x, y, z)
                if i + 1 < n && n > 3 {
                    t.push((i, i + 1, -1.0));
                    t.push((i + 1, i, -1.0));
                }
            }
            let a = sparse_from_triplets(n, n, t).unwrap();
            let chol = SparseCholesky::factor(&a, "test").unwrap();
            let simplicial = matches!(chol.symbolic.raw(), SymbolicCholeskyRaw::Simplicial(_));
            if n == 3 {
                assert_eq!(simplicial, want_simplicial, "faer's choice for a 3 x 3 matrix changed: the simplicial path is then untested");
            }
            let b = Mat::from_fn(n, 2, |i, j| (i + 1) as f64 * if j == 0 { 1.0 } else { -0.5 });
            let mut x = b.clone();
            chol.l_solve_permuted(x.as_mut());
            chol.lt_solve_unpermuted(x.as_mut());
            let dense = crate::linalg::sparse_to_dense(&a);
            let back = &dense * &x;
            let err = (0..n).flat_map(|i| (0..2).map(move |j| (i, j))).map(|(i, j)| (back[(i, j)] - b[(i, j)]).abs()).fold(0.0, f64::max);
            assert!(err < 1e-10, "n = {n} (simplicial {simplicial}): |A x - b| = {err:e}");
        }
    }
    /// Both subspace sizes (`2 n_modes`, the default, and `3 n_modes` above
    /// [`LARGE_MODEL_DOFS`]) give the closed-form modes of a fixed-fixed spring chain, `K`
    /// tridiagonal (2, -1), `M = I`: `lambda_k = 2 - 2 cos(k pi / (n + 1))`, with `M`-normalised
    /// vectors.
    #[test]
    fn both_subspace_sizes_give_the_chain_modes() {
        let (n, n_modes) = (3000usize, 40usize);
        let mut t = Vec::new();
        for i in 0..n {
            t.push((i, i, 2.0));
            if i + 1 < n {
                t.push((i, i + 1, -1.0));
                t.push((i + 1, i, -1.0));
            }
        }
        let k = sparse_from_triplets(n, n, t).unwrap();
        let m = sparse_from_triplets(n, n, (0..n).map(|i| (i, i, 1.0)).collect()).unwrap();
        let chol = SparseCholesky::factor(&k, "chain").unwrap();
        assert_eq!(krylov_subspace_factor(n), 2);
        assert_eq!(krylov_subspace_factor(LARGE_MODEL_DOFS + 1), 3);
        for factor in [2, 3] {
            let e = lowest_modes_in_subspace(&chol, &m, n_modes, factor).unwrap();
            for (j, &lambda) in e.eigenvalues.iter().enumerate() {
                let exact = 2.0 - 2.0 * ((j + 1) as f64 * std::f64::consts::PI / (n + 1) as f64).cos();
                assert!((lambda - exact).abs() <= 1e-8 * exact, "factor {factor}, mode {j}: {lambda:e} vs {exact:e}");
                let norm = e.vectors.col(j).norm_l2();
                assert!((norm - 1.0).abs() < 1e-8, "factor {factor}, mode {j}: |x|_M = {norm}");
            }
        }
    }
    /// A 3D grid Laplacian large enough for supernodes with dense updates (`g^3` unknowns).
    fn grid(g: usize) -> SparseMat {
        let n = g * g * g;
        let mut t: Vec<(usize, usize, f64)> = (0..n).map(|i| (i, i, 6.0 + 0.01 * (i % 7) as f64)).collect();
        for (i, j) in crate::linalg::sparse::grid_edges([g, g, g]) {
            let v = -1.0 - 0.001 * (j % 5) as f64;
            t.extend([(i, j, v), (j, i, v)]);
        }
        sparse_from_triplets(n, n, t).unwrap()
    }

    /// faer's own solve of `chol` on `p`.
    fn faer_solve(chol: &SparseCholesky, b: &mut Mat<f64>, p: Par) {
        let mut mem = MemBuffer::new(chol.symbolic.solve_in_place_scratch::<f64>(b.ncols(), p));
        LltRef::new(&chol.symbolic, &chol.values).solve_in_place_with_conj(Conj::No, b.as_mut(), p, MemStack::new(&mut mem));
    }

    /// The solve (split among the threads, visiting only the supernodes the right-hand sides
    /// reach) gives the same bits as faer's solve on all threads, on the grid's AMD factor, for widths below and above
    /// the split, with dense right-hand sides and with ones nonzero on one face of the grid
    /// only (as a Craig-Bampton `K_iB`), on a 3D grid Laplacian (17,576 unknowns). (A
    /// one-column half solve on one thread does not: it differs in the last bit from faer's on
    /// two, so the half solves keep faer's threading.) On the grid's nested-dissection factor,
    /// whose top separators are supernodes of hundreds of columns, faer's products sum in an
    /// order that depends on how many right-hand sides they see, so a split solve agrees with
    /// faer's to rounding there, and in bits where it is not split.
    #[test]
    fn solve_gives_faer_bits() {
        let g = 26usize;
        let n = g * g * g;
        let a = grid(g);
        let pool = rayon::ThreadPoolBuilder::new().num_threads(2).build().unwrap();
        for nd in [false, true] {
            let chol = SparseCholesky::factor_with(&a, "grid", nd).unwrap();
            assert_eq!(chol.ordering() == FillOrdering::NestedDissection, nd);
            let face: Vec<usize> = (0..g * g).collect(); // x = 0
            let reached = chol.reached_fraction(&chol.reach(&face));
            assert!(reached < 0.9, "one face should reach part of the factor only: {reached}");
            for sparse in [false, true] {
                for k in [1usize, 17, 33, 64, 256] {
                    let b = Mat::from_fn(n, k, |i, j| {
                        if sparse && i >= g * g {
                            0.0
                        } else {
                            ((i * 31 + j * 17) % 101) as f64 / 50.0 - 1.0
                        }
                    });
                    let mut want = b.clone();
                    let mut got = b.clone();
                    pool.install(|| {
                        faer_solve(&chol, &mut want, Par::rayon(2));
                        chol.solve_in_place(got.as_mut());
                    });
                    for j in 0..k {
                        for i in 0..n {
                            let what = format!("nested dissection {nd}, sparse {sparse}, k = {k}: entry ({i}, {j})");
                            if nd && k >= 2 * SPLIT_COLUMNS {
                                assert!((want[(i, j)] - got[(i, j)]).abs() <= 1e-14 * (1.0 + want[(i, j)].abs()), "{what}");
                            } else {
                                assert_eq!(want[(i, j)].to_bits(), got[(i, j)].to_bits(), "{what}");
                            }
                        }
                    }
                }
            }
        }
    }

    /// A solve for some rows only gives faer's bits on those rows and NaN on rows it did not
    /// compute (there are some: the backward solve was pruned).
    #[test]
    fn solve_for_rows_gives_faer_bits_on_them() {
        let g = 26usize;
        let n = g * g * g;
        let a = grid(g);
        let chol = SparseCholesky::factor(&a, "grid").unwrap();
        let face: Vec<usize> = (n - g * g..n).collect(); // x = g - 1
        let reach = chol.reach(&face);
        let pool = rayon::ThreadPoolBuilder::new().num_threads(2).build().unwrap();
        for k in [1usize, 64] {
            let b = Mat::from_fn(n, k, |i, j| ((i * 13 + j * 7) % 89) as f64 / 40.0 - 1.0);
            let mut want = b.clone();
            let mut got = b.clone();
            pool.install(|| {
                faer_solve(&chol, &mut want, Par::rayon(2));
                chol.solve_in_place_for(got.as_mut(), &reach);
            });
            for j in 0..k {
                for &i in &face {
                    assert_eq!(want[(i, j)].to_bits(), got[(i, j)].to_bits(), "k = {k}: entry ({i}, {j})");
                }
            }
            let skipped = (0..n).filter(|&i| got[(i, 0)].is_nan()).count();
            assert!(skipped > 0 && skipped < n - face.len(), "k = {k}: {skipped} rows not computed");
            for i in (0..n).filter(|&i| !got[(i, 0)].is_nan()) {
                assert_eq!(want[(i, 0)].to_bits(), got[(i, 0)].to_bits(), "k = {k}: computed row {i}");
            }
        }
    }

    #[test]
    fn the_cholesky_factor_takes_the_smaller_fill_and_solves_right() {
        use crate::linalg::sparse::sparse_matvec;
        let a = grid(20);
        let n = a.nrows();
        let chol = SparseCholesky::factor_with(&a, "grid", true).unwrap();
        assert_eq!(chol.ordering(), FillOrdering::NestedDissection);
        let amd = faer::sparse::linalg::cholesky::factorize_symbolic_cholesky(
            a.symbolic(),
            faer::Side::Lower,
            faer::sparse::linalg::cholesky::SymmetricOrdering::Amd,
            faer::sparse::linalg::cholesky::CholeskySymbolicParams {
                supernodal_flop_ratio_threshold: faer::sparse::linalg::SupernodalThreshold::FORCE_SUPERNODAL,
                ..Default::default()
            },
        )
        .unwrap()
        .len_val();
        assert!(chol.factor_nnz() < amd, "{} values against AMD's {amd}", chol.factor_nnz());
        let x: Vec<f64> = (0..n).map(|i| ((i * 7919) % 101) as f64 / 101.0 - 0.5).collect();
        let b = sparse_matvec(&a, &x);
        let mut y = faer::Mat::from_fn(n, 1, |i, _| b[i]);
        chol.solve_in_place(y.as_mut());
        let err = (0..n).map(|i| (y[(i, 0)] - x[i]).abs()).fold(0.0, f64::max);
        assert!(err < 1e-12, "solve error {err:e}");
        // below NESTED_DISSECTION_MIN the factor keeps AMD
        assert_eq!(SparseCholesky::factor(&a, "grid").unwrap().ordering(), FillOrdering::Amd);
    }

    /// The nested-dissection factor and its solves give the same bits on every run (its large
    /// separator supernodes are where faer's kernels run on several threads).
    #[test]
    fn nested_dissection_factor_and_solves_are_reproducible() {
        let g = 26usize;
        let n = g * g * g;
        let a = grid(g);
        let pool = rayon::ThreadPoolBuilder::new().num_threads(2).build().unwrap();
        let run = || {
            pool.install(|| {
                let chol = SparseCholesky::factor_with(&a, "grid", true).unwrap();
                assert_eq!(chol.ordering(), FillOrdering::NestedDissection);
                let mut x = Mat::from_fn(n, 1, |i, _| ((i * 31) % 101) as f64 / 50.0 - 1.0);
                chol.solve_in_place(x.as_mut());
                let mut y = Mat::from_fn(n, 40, |i, j| ((i * 31 + j * 17) % 101) as f64 / 50.0 - 1.0);
                chol.solve_in_place(y.as_mut());
                (chol.values.clone(), x, y)
            })
        };
        let first = run();
        for attempt in 0..6 {
            let again = run();
            let same_factor = first.0.iter().zip(&again.0).all(|(a, b)| a.to_bits() == b.to_bits());
            assert!(same_factor, "attempt {attempt}: the factor differs");
            for (m, (p, q)) in [(&first.1, &again.1), (&first.2, &again.2)].into_iter().enumerate() {
                for j in 0..p.ncols() {
                    for i in 0..n {
                        assert_eq!(p[(i, j)].to_bits(), q[(i, j)].to_bits(), "attempt {attempt}, solve {m}: entry ({i}, {j})");
                    }
                }
            }
        }
    }
}
