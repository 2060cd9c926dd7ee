//! Dense LU factorisation with a singularity check, for real and complex matrices (the
//! equilibrated LU the Newton solvers use, dense or sparse, is [`super::MatrixLu`]).

use crate::error::{JpError, Result};
use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::linalg::lu::partial_pivoting::{factor, solve};
use faer::traits::ComplexField;
use faer::{c64, Conj, Mat, MatMut, Par};

/// Below this size a dense LU, its solves and [`product`] run on the calling thread: faer's
/// parallel kernels hand their blocks to rayon, whose threads then wait on each other, and at
/// this size the threads gain nothing. Measured on the demo's blade at `alpha_ST / 20` (2
/// cores): the condensed full-order sweep (319 points), whose every frequency factorises the
/// 77 x 77 complex `D_LL` and multiplies `D_NL D_LL^-1 D_LN`, took 2.5 to 2.9 s with these
/// kernels on both threads and 1.6 s on one.
pub(crate) const DENSE_PARALLEL_MIN: usize = 512;

/// The parallelism of a dense factorisation or solve of size `n`: one thread below
/// [`DENSE_PARALLEL_MIN`], faer's global setting above ([`crate::parallelism`]).
pub(crate) fn dense_parallelism(n: usize) -> Par {
    if n < DENSE_PARALLEL_MIN {
        Par::Seq
    } else {
        faer::get_global_parallelism()
    }
}

/// `a b`, on the calling thread when every dimension is below [`DENSE_PARALLEL_MIN`] (faer's
/// `*` operator takes the global parallelism whatever the size).
pub fn product<T: ComplexField>(a: faer::MatRef<'_, T>, b: faer::MatRef<'_, T>) -> Mat<T> {
    let mut out = Mat::<T>::zeros(a.nrows(), b.ncols());
    let par = dense_parallelism(a.nrows().max(a.ncols()).max(b.ncols()));
    faer::linalg::matmul::matmul(out.as_mut(), faer::Accum::Replace, a, b, T::one_impl(), par);
    out
}

/// The LU factorisation with partial pivoting `P A = L U` of a square dense matrix, its
/// factorisation and solves on the calling thread below [`DENSE_PARALLEL_MIN`].
#[derive(Debug)]
pub struct DenseLu<T> {
    /// `L` (unit lower, below the diagonal) and `U` in one matrix.
    lu: Mat<T>,
    perm: Vec<usize>,
    perm_inv: Vec<usize>,
}

impl<T: Pivot> DenseLu<T> {
    /// Factorises the square matrix `a` (no singularity check: [`lu_checked`] has one).
    ///
    /// # Panics
    /// If `a` is not square.
    pub fn new(a: &Mat<T>) -> Self {
        let n = a.nrows();
        assert_eq!(a.ncols(), n, "DenseLu needs a square matrix");
        let mut lu = Self::zeros(n);
        lu.matrix_mut().copy_from(a);
        let mut mem = MemBuffer::new(Self::scratch(n, 0));
        lu.factor_in_place(MemStack::new(&mut mem));
        lu
    }

    /// [`Self::new`] in place of `a`, which it takes (no copy: the capacitance matrices of the
    /// JP prediction are the largest dense matrices it makes).
    ///
    /// # Panics
    /// If `a` is not square.
    pub fn from_matrix(a: Mat<T>) -> Self {
        let n = a.nrows();
        assert_eq!(a.ncols(), n, "DenseLu needs a square matrix");
        let mut lu = DenseLu { lu: a, perm: vec![0; n], perm_inv: vec![0; n] };
        let mut mem = MemBuffer::new(Self::scratch(n, 0));
        lu.factor_in_place(MemStack::new(&mut mem));
        lu
    }

    /// An `n x n` workspace: write the matrix with [`Self::matrix_mut`], then
    /// [`Self::factor_in_place`] (how [`super::MatrixLu`] refactorises without allocating).
    pub(crate) fn zeros(n: usize) -> Self {
        DenseLu { lu: Mat::zeros(n, n), perm: vec![0; n], perm_inv: vec![0; n] }
    }

    /// The order `n`.
    pub(crate) fn order(&self) -> usize {
        self.lu.nrows()
    }

    /// The scratch a factorisation of order `n` and a solve of `ncols` right-hand sides need.
    pub(crate) fn scratch(n: usize, ncols: usize) -> StackReq {
        let par = dense_parallelism(n);
        StackReq::any_of(&[
            factor::lu_in_place_scratch::<usize, T>(n, n, par, Default::default()),
            solve::solve_in_place_scratch::<usize, T>(n, ncols, par),
        ])
    }

    /// The matrix to factorise (before [`Self::factor_in_place`]).
    pub(crate) fn matrix_mut(&mut self) -> MatMut<'_, T> {
        self.lu.as_mut()
    }

    /// `P A = L U` in place of `A`.
    pub(crate) fn factor_in_place(&mut self, stack: &mut MemStack) {
        let par = dense_parallelism(self.order());
        factor::lu_in_place(self.lu.as_mut(), &mut self.perm, &mut self.perm_inv, par, stack, Default::default());
    }

    /// Rejects a (numerically) singular factorisation: any pivot below `100 n eps` times the
    /// largest, or a non-finite pivot.
    ///
    /// # Errors
    /// [`JpError::SingularMatrix`] naming `what()`.
    pub(crate) fn check_pivots(&self, what: &dyn Fn() -> String) -> Result<()> {
        let n = self.order();
        let (mut max_p, mut min_p) = (0.0f64, f64::INFINITY);
        for i in 0..n {
            let p = self.lu[(i, i)].modulus();
            if !p.is_finite() {
                return Err(JpError::singular(format!("{}: non-finite pivot {i}", what())));
            }
            max_p = max_p.max(p);
            min_p = min_p.min(p);
        }
        if n > 0 && (max_p == 0.0 || min_p <= 100.0 * n as f64 * f64::EPSILON * max_p) {
            return Err(JpError::singular(format!("{} ({n} x {n}): smallest pivot {min_p:.3e} vs largest {max_p:.3e}", what())));
        }
        Ok(())
    }

    /// `x <- A^-1 x`.
    pub(crate) fn solve_in_place(&self, x: MatMut<'_, T>, stack: &mut MemStack) {
        let n = self.order();
        // L and U share the factored matrix: the triangular solves read only their triangle
        // SAFETY: perm and perm_inv are the inverse permutations lu_in_place wrote
        let p = unsafe { faer::perm::PermRef::new_unchecked(&self.perm, &self.perm_inv, n) };
        solve::solve_in_place_with_conj(self.lu.as_ref(), self.lu.as_ref(), p, Conj::No, x, dense_parallelism(n), stack);
    }

    /// `A^-1 rhs`.
    ///
    /// # Panics
    /// If `rhs` has another number of rows than `A`.
    pub fn solve(&self, rhs: impl faer::mat::AsMatRef<T = T, Rows = usize, Cols = usize>) -> Mat<T> {
        let rhs = rhs.as_mat_ref();
        let n = self.order();
        assert_eq!(rhs.nrows(), n, "right-hand side of another size than the factorised matrix");
        let mut x = rhs.to_owned();
        let mut mem = MemBuffer::new(Self::scratch(n, rhs.ncols()));
        self.solve_in_place(x.as_mut(), MemStack::new(&mut mem));
        x
    }
}

impl DenseLu<f64> {
    /// The sign of `det A` (`+1` or `-1`; `0` for an exactly zero pivot): the parity of the
    /// row permutation times the signs of `U`'s diagonal (`L` is unit lower).
    pub(crate) fn determinant_sign(&self) -> f64 {
        let n = self.order();
        let mut sign = permutation_parity(&self.perm);
        for i in 0..n {
            let d = &self.lu[(i, i)];
            if *d == 0.0 {
                return 0.0;
            }
            if *d < 0.0 {
                sign = -sign;
            }
        }
        sign
    }

}

/// Factorises `a` by LU with partial pivoting and rejects (numerically) singular matrices:
/// any pivot below `100 n eps` times the largest, or a non-finite pivot. Real (`f64`) or
/// complex (`c64`).
///
/// # Errors
/// [`JpError::SingularMatrix`] naming `what`.
pub fn lu_checked<T: Pivot>(a: &Mat<T>, what: &str) -> Result<DenseLu<T>> {
    if a.ncols() != a.nrows() {
        return Err(JpError::bad_size(format!("{what} (columns of a square matrix)"), a.nrows(), a.ncols()));
    }
    let lu = DenseLu::new(a);
    lu.check_pivots(&|| what.to_string())?;
    Ok(lu)
}

/// The scalars [`lu_checked`] factorises: `f64` and `c64` (and `f32`, the single-precision
/// capacitance of the JP shift-invert solves).
pub trait Pivot: ComplexField {
    /// `|x|`.
    fn modulus(&self) -> f64;
}

impl Pivot for f64 {
    fn modulus(&self) -> f64 {
        self.abs()
    }
}

impl Pivot for f32 {
    fn modulus(&self) -> f64 {
        f64::from(self.abs())
    }
}

impl Pivot for c64 {
    fn modulus(&self) -> f64 {
        self.norm()
    }
}

/// Checks that a square matrix is numerically nonsingular (see [`lu_checked`]).
///
/// # Errors
/// As [`lu_checked`].
pub fn check_nonsingular(a: &Mat<f64>, what: &str) -> Result<()> {
    lu_checked(a, what).map(|_| ())
}

/// Solves `lu x = b` for one right-hand side.
pub fn lu_solve(lu: &DenseLu<f64>, b: &[f64]) -> Vec<f64> {
    let rhs = Mat::from_fn(b.len(), 1, |i, _| b[i]);
    let x = lu.solve(&rhs);
    (0..b.len()).map(|i| x[(i, 0)]).collect()
}

/// Solves `a x = b` (several right-hand sides) by LU and checks the solution instead of the
/// pivots: the relative residual `|a x - b| / (|a| |x| + |b|)` must be below `1e-8`, so a
/// badly scaled but solvable system passes and a singular one does not. With more than
/// [`PROBES`] right-hand sides the residual is taken of [`PROBES`] fixed combinations of the
/// columns (`a (x v) - b v`), which costs `O(n^2)` per probe instead of the product `a x`,
/// as much as the solve itself.
///
/// # Errors
/// [`JpError::SingularMatrix`] naming `what`.
pub fn solve_checked(what: &str, a: &Mat<f64>, b: &Mat<f64>) -> Result<Mat<f64>> {
    if a.ncols() != a.nrows() || b.nrows() != a.nrows() {
        return Err(JpError::bad_size(format!("{what} (a square matrix and its right-hand sides)"), a.nrows(), if a.ncols() != a.nrows() { a.ncols() } else { b.nrows() }));
    }
    let x = DenseLu::new(a).solve(b);
    let finite = (0..x.ncols()).all(|j| (0..x.nrows()).all(|i| x[(i, j)].is_finite()));
    if !finite {
        return Err(JpError::singular(what));
    }
    let (r, scale) = if b.ncols() <= PROBES {
        (product(a.as_ref(), x.as_ref()) - b, a.norm_l2() * x.norm_l2() + b.norm_l2())
    } else {
        let v = probes(b.ncols());
        let (xv, bv) = (product(x.as_ref(), v.as_ref()), product(b.as_ref(), v.as_ref()));
        (product(a.as_ref(), xv.as_ref()) - &bv, a.norm_l2() * xv.norm_l2() + bv.norm_l2())
    };
    if r.norm_l2() > 1e-8 * scale.max(f64::MIN_POSITIVE) {
        return Err(JpError::singular(what));
    }
    Ok(x)
}

/// Number of column combinations [`solve_checked`] checks when there are more columns.
pub const PROBES: usize = 3;

/// `k x PROBES` fixed combinations with entries of mixed sign and size (`1..j + 2`), so that
/// no column's error cancels out of all of them.
pub(crate) fn probes(k: usize) -> Mat<f64> {
    Mat::from_fn(k, PROBES, |i, j| if (i * (j + 3) + j) % 5 < 2 { -1.0 } else { 1.0 } * (1.0 + (i % (j + 2)) as f64))
}

/// The error of a matrix whose column `j` is zero.
pub(crate) fn zero_column(what: &str, j: usize) -> JpError {
    JpError::singular(format!(
        "{what}: unknown {j} appears in no equation (its column is zero: nothing holds it, e.g. a DoF held only by an open contact or a free rigid-body motion)"
    ))
}

/// `a v`.
pub fn mat_vec(a: &Mat<f64>, v: &[f64]) -> Vec<f64> {
    let mut out = vec![0.0; a.nrows()];
    for j in 0..a.ncols() {
        let vj = v[j];
        if vj != 0.0 {
            for (o, x) in out.iter_mut().zip(a.col(j).iter()) {
                *o += x * vj;
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `solve_checked` with few and with many right-hand sides (the probed residual): a
    /// solvable system passes with the LU's solution, a singular one (two equal rows) and one
    /// whose solution is garbage in a single column are refused.
    #[test]
    fn solve_checked_refuses_singular_systems_with_few_and_many_columns() {
        let n = 40;
        let a = Mat::from_fn(n, n, |i, j| if i == j { 5.0 + i as f64 } else { ((i * 7 + j * 3) % 5) as f64 * 0.1 });
        for k in [1, PROBES, PROBES + 1, 50] {
            let b = Mat::from_fn(n, k, |i, j| 1.0 + ((i + 2 * j) % 9) as f64);
            let x = solve_checked("a", &a, &b).unwrap();
            assert!((product(a.as_ref(), x.as_ref()) - &b).norm_l2() < 1e-12 * b.norm_l2());
            let mut s = a.clone();
            for j in 0..n {
                s[(1, j)] = s[(0, j)];
            }
            let err = solve_checked("the singular matrix", &s, &b).unwrap_err();
            assert!(err.to_string().contains("the singular matrix"), "{err}");
        }
        // the probes see an error in any one column
        let b = Mat::from_fn(n, 50, |i, j| 1.0 + ((i + 2 * j) % 9) as f64);
        let x = DenseLu::new(&a).solve(&b);
        let v = probes(50);
        for bad in [0, 17, 49] {
            let mut y = x.clone();
            y[(3, bad)] += 1e-3;
            let r = product(a.as_ref(), product(y.as_ref(), v.as_ref()).as_ref()) - product(b.as_ref(), v.as_ref());
            assert!(r.norm_l2() > 1e-3, "column {bad}: {}", r.norm_l2());
        }
    }
}

/// `+1` for an even permutation, `-1` for an odd one (`n` minus the number of cycles is the
/// number of transpositions).
pub(crate) fn permutation_parity(perm: &[usize]) -> f64 {
    let mut seen = vec![false; perm.len()];
    let mut transpositions = 0usize;
    for start in 0..perm.len() {
        let mut i = start;
        let mut length = 0usize;
        while !seen[i] {
            seen[i] = true;
            i = perm[i];
            length += 1;
        }
        transpositions += length.saturating_sub(1);
    }
    if transpositions % 2 == 0 {
        1.0
    } else {
        -1.0
    }
}
