//! A real matrix stored dense or sparse, with the few operations the harmonic balance needs
//! (products, column norms, a bordered copy) and one checked, equilibrated LU for either
//! storage. The full-order system of a sparse model (an FE model, a chain) keeps its linear part
//! and its HBM Jacobian sparse: `J = D + W^T K̂ W` has `O(n (2H+1))` nonzeros per row band of
//! `K` plus one `d (2H+1)` square block per contact, where the dense form has `(n (2H+1))^2`.

use super::lu::{zero_column, DenseLu};
use super::sparse::SparseMat;
use crate::error::{JpError, Result};
use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::sparse::linalg::lu::{factorize_symbolic_lu, LuRef, NumericLu, SymbolicLu};
use faer::sparse::SparseColMatRef;
use faer::{Conj, Mat};

/// A real matrix, dense or sparse (compressed columns).
#[derive(Clone, Debug)]
pub enum Matrix {
    Dense(Mat<f64>),
    Sparse(SparseMat),
}

impl From<Mat<f64>> for Matrix {
    fn from(m: Mat<f64>) -> Self {
        Matrix::Dense(m)
    }
}

impl From<SparseMat> for Matrix {
    fn from(m: SparseMat) -> Self {
        Matrix::Sparse(m)
    }
}

impl Matrix {
    pub fn nrows(&self) -> usize {
        match self {
            Matrix::Dense(m) => m.nrows(),
            Matrix::Sparse(m) => m.nrows(),
        }
    }

    pub fn ncols(&self) -> usize {
        match self {
            Matrix::Dense(m) => m.ncols(),
            Matrix::Sparse(m) => m.ncols(),
        }
    }

    /// Whether the storage is sparse.
    pub fn is_sparse(&self) -> bool {
        matches!(self, Matrix::Sparse(_))
    }

    /// Stored entries (`nrows * ncols` when dense).
    pub fn stored_entries(&self) -> usize {
        match self {
            Matrix::Dense(m) => m.nrows() * m.ncols(),
            Matrix::Sparse(m) => m.val().len(),
        }
    }

    /// Calls `f(i, j, a_ij)` for every stored entry (every entry when dense).
    pub fn for_each_entry(&self, mut f: impl FnMut(usize, usize, f64)) {
        match self {
            Matrix::Dense(m) => {
                for j in 0..m.ncols() {
                    for (i, &v) in m.col(j).iter().enumerate() {
                        f(i, j, v);
                    }
                }
            }
            Matrix::Sparse(m) => {
                let s = m.as_ref();
                let (cp, ri, v) = (s.symbolic().col_ptr(), s.symbolic().row_idx(), s.val());
                for j in 0..s.ncols() {
                    for k in cp[j]..cp[j + 1] {
                        f(ri[k], j, v[k]);
                    }
                }
            }
        }
    }

    /// `y += alpha A x`.
    pub fn mul_add(&self, x: &[f64], alpha: f64, y: &mut [f64]) {
        match self {
            Matrix::Dense(m) => {
                for j in 0..m.ncols() {
                    let xj = alpha * x[j];
                    if xj != 0.0 {
                        for (o, a) in y.iter_mut().zip(m.col(j).iter()) {
                            *o += a * xj;
                        }
                    }
                }
            }
            Matrix::Sparse(_) => self.for_each_entry(|i, j, v| y[i] += alpha * v * x[j]),
        }
    }

    /// `A x`.
    pub fn mat_vec(&self, x: &[f64]) -> Vec<f64> {
        let mut y = vec![0.0; self.nrows()];
        self.mat_vec_into(x, &mut y);
        y
    }

    /// `y = A x`.
    pub fn mat_vec_into(&self, x: &[f64], y: &mut [f64]) {
        y.iter_mut().for_each(|v| *v = 0.0);
        self.mul_add(x, 1.0, y);
    }

    /// `A^T x`.
    pub fn mat_t_vec(&self, x: &[f64]) -> Vec<f64> {
        let mut y = vec![0.0; self.ncols()];
        self.mat_t_vec_into(x, &mut y);
        y
    }

    /// `y = A^T x`.
    pub fn mat_t_vec_into(&self, x: &[f64], y: &mut [f64]) {
        match self {
            Matrix::Dense(m) => {
                for (j, o) in y.iter_mut().enumerate() {
                    *o = m.col(j).iter().zip(x).map(|(a, b)| a * b).sum();
                }
            }
            Matrix::Sparse(_) => {
                y.iter_mut().for_each(|v| *v = 0.0);
                self.for_each_entry(|i, j, v| y[j] += v * x[i]);
            }
        }
    }

    /// Euclidean norm of every column.
    pub fn column_norms(&self) -> Vec<f64> {
        let mut s = vec![0.0; self.ncols()];
        self.column_norms_into(&mut s);
        s
    }

    /// Euclidean norm of every column, into `s`.
    pub fn column_norms_into(&self, s: &mut [f64]) {
        s.iter_mut().for_each(|v| *v = 0.0);
        self.for_each_entry(|_, j, v| s[j] += v * v);
        s.iter_mut().for_each(|v| *v = v.sqrt());
    }

    /// `A *= s`.
    pub fn scale(&mut self, s: f64) {
        match self {
            Matrix::Dense(m) => *m *= faer::Scale(s),
            Matrix::Sparse(m) => m.val_mut().iter_mut().for_each(|v| *v *= s),
        }
    }

    /// The bordered square matrix `[A  col; row^T]` (`A` is `n x n`, `col` has `n` entries,
    /// `row` has `n + 1`): the continuation's systems. Sparse stays sparse (the border is
    /// stored whole, zeros included, so its pattern does not change between iterations).
    ///
    /// # Errors
    /// [`JpError::BadSize`] on mismatched lengths; a non-finite border entry in sparse storage.
    pub fn bordered(&self, col: &[f64], row: &[f64]) -> Result<Matrix> {
        let mut out = None;
        self.bordered_into(col, row, &mut out)?;
        Ok(out.expect("bordered_into sets it"))
    }

    /// [`Matrix::bordered`] into `out`, refilled in place when it already has the bordered
    /// storage and pattern (the corrector's iterations).
    ///
    /// # Errors
    /// As [`Matrix::bordered`].
    pub fn bordered_into(&self, col: &[f64], row: &[f64], out: &mut Option<Matrix>) -> Result<()> {
        let n = self.nrows();
        if self.ncols() != n || col.len() != n || row.len() != n + 1 {
            return Err(JpError::bad_size("bordered matrix border", n, col.len()));
        }
        match self {
            Matrix::Dense(a) => {
                if !matches!(out, Some(Matrix::Dense(b)) if b.nrows() == n + 1 && b.ncols() == n + 1) {
                    *out = Some(Matrix::Dense(Mat::zeros(n + 1, n + 1)));
                }
                let Some(Matrix::Dense(b)) = out.as_mut() else { unreachable!("set above") };
                b.as_mut().submatrix_mut(0, 0, n, n).copy_from(a);
                for i in 0..n {
                    b[(i, n)] = col[i];
                }
                for j in 0..=n {
                    b[(n, j)] = row[j];
                }
            }
            Matrix::Sparse(a) => {
                if let Some((i, v)) = col.iter().chain(row).enumerate().find(|(_, v)| !v.is_finite()) {
                    let (r, c) = if i < n { (i, n) } else { (n, i - n) };
                    return Err(JpError::invalid("sparse triplet", format!("entry ({r}, {c}) is not finite ({v})")));
                }
                let s = a.as_ref().symbolic();
                let (cp, ri) = (s.col_ptr(), s.row_idx());
                // column j < n: A's entries, then row[j] in row n; column n: col, then row[n]
                let fits = match out {
                    Some(Matrix::Sparse(b)) => {
                        let t = b.as_ref().symbolic();
                        let (bp, bi) = (t.col_ptr(), t.row_idx());
                        t.nrows() == n + 1
                            && t.ncols() == n + 1
                            && (0..n).all(|j| bp[j] == cp[j] + j && bi[bp[j]..bp[j + 1] - 1] == ri[cp[j]..cp[j + 1]] && bi[bp[j + 1] - 1] == n)
                            && bp[n] == cp[n] + n
                            && bp[n + 1] == bp[n] + n + 1
                            && bi[bp[n]..].iter().enumerate().all(|(k, &i)| i == k)
                    }
                    _ => false,
                };
                if !fits {
                    let mut bp = Vec::with_capacity(n + 2);
                    let mut bi = Vec::with_capacity(ri.len() + 2 * n + 1);
                    for j in 0..n {
                        bp.push(bi.len());
                        bi.extend_from_slice(&ri[cp[j]..cp[j + 1]]);
                        bi.push(n);
                    }
                    bp.push(bi.len());
                    bi.extend(0..=n);
                    bp.push(bi.len());
                    let pattern = faer::sparse::SymbolicSparseColMat::new_checked(n + 1, n + 1, bp, None, bi);
                    let nnz = pattern.row_idx().len();
                    *out = Some(Matrix::Sparse(faer::sparse::SparseColMat::new(pattern, vec![0.0; nnz])));
                }
                let Some(Matrix::Sparse(b)) = out.as_mut() else { unreachable!("set above") };
                let v = b.val_mut();
                let av = a.val();
                let mut pos = 0;
                for j in 0..n {
                    let len = cp[j + 1] - cp[j];
                    v[pos..pos + len].copy_from_slice(&av[cp[j]..cp[j + 1]]);
                    v[pos + len] = row[j];
                    pos += len + 1;
                }
                v[pos..pos + n].copy_from_slice(col);
                v[pos + n] = row[n];
            }
        }
        Ok(())
    }

    /// Overwrites the last row of a matrix made by [`Matrix::bordered`] (its border row,
    /// stored whole in either storage).
    ///
    /// # Errors
    /// [`JpError::BadSize`] if `row` is not as long as the matrix is wide.
    pub fn set_border_row(&mut self, row: &[f64]) -> Result<()> {
        let n1 = self.nrows();
        if self.ncols() != n1 || row.len() != n1 || n1 == 0 {
            return Err(JpError::bad_size("bordered matrix border row", n1, row.len()));
        }
        match self {
            Matrix::Dense(b) => {
                for (j, &v) in row.iter().enumerate() {
                    b[(n1 - 1, j)] = v;
                }
            }
            Matrix::Sparse(b) => {
                // bordered_into stores the border row as the last entry of every column
                let cp = b.as_ref().symbolic().col_ptr().to_vec();
                let ri = b.as_ref().symbolic().row_idx().to_vec();
                let v = b.val_mut();
                for j in 0..n1 {
                    let last = cp[j + 1] - 1;
                    if cp[j + 1] == cp[j] || ri[last] != n1 - 1 {
                        return Err(JpError::invalid("bordered matrix", format!("column {j} does not end in the border row")));
                    }
                    v[last] = row[j];
                }
            }
        }
        Ok(())
    }

    /// Dense copy.
    pub fn to_dense(&self) -> Mat<f64> {
        match self {
            Matrix::Dense(m) => m.clone(),
            Matrix::Sparse(m) => m.as_ref().to_dense(),
        }
    }

    /// Dense form, without a copy when already dense.
    pub fn into_dense(self) -> Mat<f64> {
        match self {
            Matrix::Dense(m) => m,
            Matrix::Sparse(m) => m.as_ref().to_dense(),
        }
    }
}

/// The checked, equilibrated LU of a [`Matrix`] in its own storage, kept for the next
/// factorisation: a Newton solve refactorises its Jacobian every iteration into the same
/// buffers (dense: the factors, the row permutation, faer's scratch; sparse: the fill-reducing
/// analysis, kept while the pattern is the same, the numeric factors, the scaled values and
/// the scratch), so that after the first iteration neither [`MatrixLu::factor`] nor
/// [`MatrixLu::solve_into`] allocates.
///
/// **Equilibration.** `B = R A C`, `C` scaling every column of `A` to unit norm, then `R` every
/// row of `A C`; the singularity test judges `B`, so it judges the matrix and not its units (a
/// bordered continuation system mixes displacement columns, a frequency column and an
/// arclength row of very different sizes). A zero column of `A` is named (an unknown no
/// equation holds) instead of the NaN pivot it would give.
///
/// **Singularity test.** Dense: every pivot of `B` finite and above `100 n eps` times the
/// largest. Sparse: the factors must reproduce a known solution (`B y = B 1` gives `y = 1` to
/// `1e-6`, i.e. a condition number far below `1 / eps`); a zero or non-finite pivot fails it too.
#[derive(Default)]
pub struct MatrixLu {
    row: Vec<f64>,
    col: Vec<f64>,
    factors: Option<Factors>,
}


enum Factors {
    Dense(DenseFactors),
    Sparse(Box<SparseFactors>),
}

struct DenseFactors {
    /// `B`, then its `L` (unit lower) and `U` in place
    lu: DenseLu<f64>,
    mem: MemBuffer,
    rhs: Mat<f64>,
}

struct SparseFactors {
    pattern: (Vec<usize>, Vec<usize>),
    symbolic: SymbolicLu<usize>,
    numeric: NumericLu<usize, f64>,
    /// `B`'s values on `A`'s pattern
    values: Vec<f64>,
    mem: MemBuffer,
    rhs: Mat<f64>,
}

impl MatrixLu {
    /// An empty workspace (buffers are sized by the first [`MatrixLu::factor`]).
    pub fn empty() -> Self {
        Self::default()
    }

    /// Factorises `a` once.
    ///
    /// # Errors
    /// [`JpError::SingularMatrix`] naming `what`.
    pub fn new(a: &Matrix, what: &str) -> Result<Self> {
        let mut lu = Self::empty();
        lu.factor(a, || what.to_string())?;
        Ok(lu)
    }

    /// Factorises `a` into this workspace's buffers (`what` names the matrix in an error, and
    /// is only called then). After an error the workspace holds no factors until the next
    /// successful call.
    ///
    /// # Errors
    /// [`JpError::SingularMatrix`] naming `what()`; [`JpError::BadSize`] for a non-square `a`.
    pub fn factor(&mut self, a: &Matrix, what: impl Fn() -> String) -> Result<()> {
        let n = a.nrows();
        if a.ncols() != n {
            return Err(JpError::bad_size(format!("{} (columns)", what()), n, a.ncols()));
        }
        // column scaling from A's column norms; a zero column is named
        self.col.clear();
        self.col.resize(n, 0.0);
        a.for_each_entry(|_, j, v| self.col[j] += v * v);
        if let Some(j) = self.col.iter().position(|&s| s == 0.0) {
            self.factors = None;
            return Err(zero_column(&what(), j));
        }
        let one_or = |s: f64| if s > 0.0 && s.is_finite() { s } else { 1.0 };
        self.col.iter_mut().for_each(|s| *s = 1.0 / one_or(s.sqrt()));
        // row scaling from the column-scaled matrix's row norms
        self.row.clear();
        self.row.resize(n, 0.0);
        let col = &self.col;
        let row = &mut self.row;
        a.for_each_entry(|i, j, v| {
            let b = v * col[j];
            row[i] += b * b;
        });
        self.row.iter_mut().for_each(|s| *s = 1.0 / one_or(s.sqrt()));
        let result = match a {
            Matrix::Dense(m) => self.factor_dense(m, &what),
            Matrix::Sparse(m) => self.factor_sparse(m, &what),
        };
        if result.is_err() {
            self.factors = None;
        }
        result
    }

    fn factor_dense(&mut self, a: &Mat<f64>, what: &dyn Fn() -> String) -> Result<()> {
        let n = a.nrows();
        let fits = matches!(&self.factors, Some(Factors::Dense(f)) if f.lu.order() == n);
        if !fits {
            self.factors = Some(Factors::Dense(DenseFactors {
                lu: DenseLu::zeros(n),
                mem: MemBuffer::try_new(DenseLu::<f64>::scratch(n, 1)).map_err(|_| JpError::singular(format!("{}: no memory for the LU scratch", what())))?,
                rhs: Mat::zeros(n, 1),
            }));
        }
        let Some(Factors::Dense(f)) = self.factors.as_mut() else { unreachable!("dense factors set above") };
        let (row, col) = (&self.row, &self.col);
        let mut b = f.lu.matrix_mut();
        for j in 0..n {
            for i in 0..n {
                b[(i, j)] = a[(i, j)] * col[j] * row[i];
            }
        }
        f.lu.factor_in_place(MemStack::new(&mut f.mem));
        f.lu.check_pivots(what)
    }

    fn factor_sparse(&mut self, a: &SparseMat, what: &dyn Fn() -> String) -> Result<()> {
        let n = a.nrows();
        let sym = a.as_ref().symbolic();
        let (cp, ri) = (sym.col_ptr(), sym.row_idx());
        let same = matches!(&self.factors, Some(Factors::Sparse(f)) if f.pattern.0.as_slice() == cp && f.pattern.1.as_slice() == ri);
        if !same {
            let symbolic = factorize_symbolic_lu(sym, Default::default())
                .map_err(|e| JpError::singular(format!("{}: sparse LU analysis failed: {e:?}", what())))?;
            let par = faer::get_global_parallelism();
            let scratch = StackReq::any_of(&[
                symbolic.factorize_numeric_lu_scratch::<f64>(par, Default::default()),
                symbolic.solve_in_place_scratch::<f64>(1, par),
            ]);
            let mem = MemBuffer::try_new(scratch).map_err(|_| JpError::singular(format!("{}: no memory for the sparse LU scratch", what())))?;
            self.factors = Some(Factors::Sparse(Box::new(SparseFactors {
                pattern: (cp.to_vec(), ri.to_vec()),
                symbolic,
                numeric: NumericLu::new(),
                values: vec![0.0; a.val().len()],
                mem,
                rhs: Mat::zeros(n, 1),
            })));
        }
        let Some(Factors::Sparse(f)) = self.factors.as_mut() else { unreachable!("sparse factors set above") };
        // B = R A C on A's own pattern
        for j in 0..n {
            for k in cp[j]..cp[j + 1] {
                f.values[k] = a.val()[k] * self.col[j] * self.row[ri[k]];
            }
        }
        let par = faer::get_global_parallelism();
        let b = SparseColMatRef::new(sym, &f.values);
        f.symbolic
            .factorize_numeric_lu(&mut f.numeric, b, par, MemStack::new(&mut f.mem), Default::default())
            .map_err(|e| JpError::singular(format!("{} ({n} x {n}, sparse): {e:?}", what())))?;
        // known-solution check on the equilibrated matrix: B y = B 1 must give y = 1
        let rhs = f.rhs.col_mut(0).try_as_col_major_mut().expect("a one-column Mat is contiguous").as_slice_mut();
        rhs.iter_mut().for_each(|v| *v = 0.0);
        for k in 0..f.values.len() {
            rhs[ri[k]] += f.values[k];
        }
        LuRef::new_unchecked(&f.symbolic, &f.numeric).solve_in_place_with_conj(Conj::No, f.rhs.as_mut(), par, MemStack::new(&mut f.mem));
        let err = (0..n).map(|i| (f.rhs[(i, 0)] - 1.0).abs()).fold(0.0f64, |m, e| if e.is_finite() { m.max(e) } else { f64::INFINITY });
        if !(err <= 1e-6) {
            return Err(JpError::singular(format!(
                "{} ({n} x {n}, sparse): the LU does not reproduce a known solution (error {err:.3e}): numerically singular",
                what()
            )));
        }
        Ok(())
    }

    /// Solves `a x = rhs` into `x` with the latest factors.
    ///
    /// # Panics
    /// If no factorisation succeeded since the last error, or on mismatched lengths.
    pub fn solve_into(&mut self, rhs: &[f64], x: &mut [f64]) {
        let n = self.row.len();
        assert!(rhs.len() == n && x.len() == n, "right-hand side and solution must have the factorised size");
        let (row, col) = (&self.row, &self.col);
        match self.factors.as_mut().expect("solve_into needs a successful factor") {
            Factors::Dense(f) => {
                for i in 0..n {
                    f.rhs[(i, 0)] = rhs[i] * row[i];
                }
                f.lu.solve_in_place(f.rhs.as_mut(), MemStack::new(&mut f.mem));
                for i in 0..n {
                    x[i] = f.rhs[(i, 0)] * col[i];
                }
            }
            Factors::Sparse(f) => {
                for i in 0..n {
                    f.rhs[(i, 0)] = rhs[i] * row[i];
                }
                let par = faer::get_global_parallelism();
                LuRef::new_unchecked(&f.symbolic, &f.numeric).solve_in_place_with_conj(Conj::No, f.rhs.as_mut(), par, MemStack::new(&mut f.mem));
                for i in 0..n {
                    x[i] = f.rhs[(i, 0)] * col[i];
                }
            }
        }
    }

    /// The sign of `det a` of the latest factorisation (the equilibration's scalings are
    /// positive and do not change it): `Some(+1.0)` or `Some(-1.0)` for dense factors, `None`
    /// for sparse ones (faer's supernodal factors do not expose `U`'s diagonal).
    pub fn determinant_sign(&self) -> Option<f64> {
        match self.factors.as_ref()? {
            Factors::Dense(f) => Some(f.lu.determinant_sign()),
            Factors::Sparse(_) => None,
        }
    }

    /// Solves `a x = rhs`.
    pub fn solve(&mut self, rhs: &[f64]) -> Vec<f64> {
        let mut x = vec![0.0; rhs.len()];
        self.solve_into(rhs, &mut x);
        x
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::linalg::sparse::sparse_from_triplets;

    fn tridiagonal(n: usize, diag: f64) -> (Mat<f64>, SparseMat) {
        let d = Mat::from_fn(n, n, |i, j| if i == j { diag + i as f64 } else if i.abs_diff(j) == 1 { -1.0 - 0.1 * j as f64 } else { 0.0 });
        let mut t = Vec::new();
        for j in 0..n {
            for i in 0..n {
                if d[(i, j)] != 0.0 {
                    t.push((i, j, d[(i, j)]));
                }
            }
        }
        let s = sparse_from_triplets(n, n, t).unwrap();
        (d, s)
    }

    #[test]
    fn sparse_and_dense_agree_on_products_borders_and_solves() {
        let n = 30;
        let (d, s) = tridiagonal(n, 3.0);
        let (dm, sm) = (Matrix::Dense(d), Matrix::Sparse(s));
        let x: Vec<f64> = (0..n).map(|i| (i as f64 * 0.37).sin()).collect();
        let diff = |a: &[f64], b: &[f64]| a.iter().zip(b).map(|(p, q)| (p - q).abs()).fold(0.0f64, f64::max);
        assert!(diff(&dm.mat_vec(&x), &sm.mat_vec(&x)) < 1e-14);
        assert!(diff(&dm.mat_t_vec(&x), &sm.mat_t_vec(&x)) < 1e-14);
        assert!(diff(&dm.column_norms(), &sm.column_norms()) < 1e-14);
        let col: Vec<f64> = (0..n).map(|i| 0.01 * i as f64).collect();
        let row: Vec<f64> = (0..=n).map(|i| 1.0 + 0.02 * i as f64).collect();
        let (bd, bs) = (dm.bordered(&col, &row).unwrap(), sm.bordered(&col, &row).unwrap());
        assert!((&bd.to_dense() - &bs.to_dense()).norm_l2() < 1e-14);
        let rhs: Vec<f64> = (0..=n).map(|i| (i as f64).cos()).collect();
        let xd = MatrixLu::new(&bd, "dense").unwrap().solve(&rhs);
        let mut lu = MatrixLu::new(&bs, "sparse").unwrap();
        let xs = lu.solve(&rhs);
        assert!(diff(&xd, &xs) < 1e-12, "{}", diff(&xd, &xs));
        assert!(diff(&bs.mat_vec(&xs), &rhs) < 1e-12);
        // refactorised in place (the analysis kept for the same pattern): the same answer
        lu.factor(&bs, || "sparse again".into()).unwrap();
        assert_eq!(xs, lu.solve(&rhs));
        // a dense workspace refactorised with another matrix solves that one
        let mut lu = MatrixLu::new(&bd, "dense").unwrap();
        let mut b2 = bd.to_dense();
        b2[(0, 0)] += 1.0;
        lu.factor(&Matrix::Dense(b2.clone()), || "dense again".into()).unwrap();
        let x2 = lu.solve(&rhs);
        assert!(diff(&Matrix::Dense(b2).mat_vec(&x2), &rhs) < 1e-12);
    }

    /// The determinant's sign against a product of known signs: a diagonal matrix with
    /// negative entries, permuted rows (each transposition flips the sign), and a rotation.
    #[test]
    fn determinant_signs_follow_the_permutations_and_pivots() {
        let sign_of = |m: Mat<f64>| MatrixLu::new(&Matrix::Dense(m), "test").unwrap().determinant_sign().unwrap();
        let diag = |d: &[f64]| Mat::from_fn(d.len(), d.len(), |i, j| if i == j { d[i] } else { 0.0 });
        assert_eq!(sign_of(diag(&[1.0, 2.0, 3.0])), 1.0);
        assert_eq!(sign_of(diag(&[1.0, -2.0, 3.0])), -1.0);
        assert_eq!(sign_of(diag(&[-1.0, -2.0, 3.0])), 1.0);
        // rows 0 and 2 swapped: one transposition
        let p = Mat::from_fn(3, 3, |i, j| if (i == 0 && j == 2) || (i == 2 && j == 0) || (i == 1 && j == 1) { 1.0 } else { 0.0 });
        assert_eq!(sign_of(p.clone()), -1.0);
        // a 3-cycle is even
        let c = Mat::from_fn(3, 3, |i, j| if j == (i + 1) % 3 { 1.0 } else { 0.0 });
        assert_eq!(sign_of(c), 1.0);
        // random matrices against the sign of faer's determinant
        let mut seed = 7u64;
        let mut next = || {
            seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            ((seed >> 11) as f64 / (1u64 << 53) as f64) - 0.5
        };
        for n in [2, 5, 17, 40] {
            for _ in 0..5 {
                let m = Mat::from_fn(n, n, |_, _| next());
                let det = m.determinant();
                assert_eq!(sign_of(m), det.signum(), "n = {n}, det = {det:e}");
            }
        }
        assert_eq!(MatrixLu::new(&Matrix::Sparse(tridiagonal(5, 3.0).1), "sparse").unwrap().determinant_sign(), None);
    }

    #[test]
    fn singular_sparse_matrices_are_refused_with_a_reason() {
        let n = 10;
        // a zero column
        let t: Vec<(usize, usize, f64)> = (0..n).filter(|&i| i != 4).map(|i| (i, i, 1.0)).collect();
        let a = sparse_from_triplets(n, n, t).unwrap();
        let e = MatrixLu::new(&Matrix::Sparse(a), "zero column").err().expect("singular").to_string();
        assert!(e.contains("unknown 4 appears in no equation"), "{e}");
        // two equal columns: structurally fine, numerically singular
        let mut t: Vec<(usize, usize, f64)> = (0..n).map(|i| (i, i, 2.0)).collect();
        t.push((1, 0, 1.0));
        t.push((0, 1, 2.0));
        t.push((1, 1, -1.0)); // column 1 = column 0 now: (2, 1) in rows 0 and 1
        let a = sparse_from_triplets(n, n, t).unwrap();
        assert!(MatrixLu::new(&Matrix::Sparse(a), "equal columns").is_err());
    }

    #[test]
    fn a_zero_dense_column_is_named_not_a_nan_pivot() {
        let a = Mat::from_fn(3, 3, |i, j| if j == 1 { 0.0 } else if i == j { 2.0 } else { 0.5 });
        let text = MatrixLu::new(&Matrix::Dense(a), "Jacobian of the test").err().expect("singular").to_string();
        assert!(text.contains("unknown 1 appears in no equation"), "{text}");
        let ok = Mat::from_fn(3, 3, |i, j| if i == j { 2.0 } else { 0.5 });
        let x = MatrixLu::new(&Matrix::Dense(ok.clone()), "ok").unwrap().solve(&[1.0, 2.0, 3.0]);
        let r = Matrix::Dense(ok).mat_vec(&x);
        assert!((r[0] - 1.0).abs() + (r[1] - 2.0).abs() + (r[2] - 3.0).abs() < 1e-12);
        // two equal columns
        let s = Mat::from_fn(3, 3, |i, j| if j == 2 { (i + 1) as f64 } else if j == 1 { (i + 1) as f64 } else { 1.0 + (i * i) as f64 });
        assert!(MatrixLu::new(&Matrix::Dense(s), "singular").is_err());
    }
}
