//! A real matrix stored dense or sparse, with the few operations the harmonic balance needs
//! (products, column norms, a bordered copy) and one checked, equilibrated LU for either
//! storage. The full-order system of a sparse model (an FE model, a chain) keeps its linear part
//! and its HBM Jacobian sparse: `J = D + W^T K̂ W` has `O(n (2H+1))` nonzeros per row band of
//! `K` plus one `d (2H+1)` square block per contact, where the dense form has `(n (2H+1))^2`.

use super::lu::{zero_column, EquilibratedLu};
use super::sparse::{sparse_from_triplets, SparseMat};
use crate::error::{JpError, Result};
use faer::linalg::solvers::SolveCore;
use faer::sparse::linalg::solvers::{Lu, SymbolicLu};
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
        self.mul_add(x, 1.0, &mut y);
        y
    }

    /// `A^T x`.
    pub fn mat_t_vec(&self, x: &[f64]) -> Vec<f64> {
        let mut y = vec![0.0; self.ncols()];
        match self {
            Matrix::Dense(m) => {
                for (j, o) in y.iter_mut().enumerate() {
                    *o = m.col(j).iter().zip(x).map(|(a, b)| a * b).sum();
                }
            }
            Matrix::Sparse(_) => self.for_each_entry(|i, j, v| y[j] += v * x[i]),
        }
        y
    }

    /// Euclidean norm of every column.
    pub fn column_norms(&self) -> Vec<f64> {
        let mut s = vec![0.0; self.ncols()];
        self.for_each_entry(|_, j, v| s[j] += v * v);
        s.iter_mut().for_each(|v| *v = v.sqrt());
        s
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
        let n = self.nrows();
        if self.ncols() != n || col.len() != n || row.len() != n + 1 {
            return Err(JpError::bad_size("bordered matrix border", n, col.len()));
        }
        Ok(match self {
            Matrix::Dense(a) => Matrix::Dense(Mat::from_fn(n + 1, n + 1, |i, j| {
                if i == n {
                    row[j]
                } else if j == n {
                    col[i]
                } else {
                    a[(i, j)]
                }
            })),
            Matrix::Sparse(a) => {
                let mut t = Vec::with_capacity(a.val().len() + 2 * n + 1);
                self.for_each_entry(|i, j, v| t.push((i, j, v)));
                t.extend(col.iter().enumerate().map(|(i, &v)| (i, n, v)));
                t.extend(row.iter().enumerate().map(|(j, &v)| (n, j, v)));
                Matrix::Sparse(sparse_from_triplets(n + 1, n + 1, t)?)
            }
        })
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

/// The symbolic analysis (fill-reducing ordering, elimination structure) of the last sparse
/// matrix factorised, kept for the next one with the same pattern: the Newton iterations of
/// one solve all have the same pattern, so only the first pays for the analysis.
#[derive(Default)]
pub struct SymbolicCache {
    pattern: Option<(Vec<usize>, Vec<usize>)>,
    symbolic: Option<SymbolicLu<usize>>,
}

impl SymbolicCache {
    pub fn new() -> Self {
        Self::default()
    }

    fn for_matrix(&mut self, a: &SparseMat) -> Result<SymbolicLu<usize>> {
        let s = a.as_ref().symbolic();
        let same = self.pattern.as_ref().is_some_and(|(cp, ri)| cp.as_slice() == s.col_ptr() && ri.as_slice() == s.row_idx());
        if !same || self.symbolic.is_none() {
            let sym = SymbolicLu::try_new(s).map_err(|e| JpError::singular(format!("sparse LU analysis failed: {e:?}")))?;
            self.pattern = Some((s.col_ptr().to_vec(), s.row_idx().to_vec()));
            self.symbolic = Some(sym);
        }
        Ok(self.symbolic.clone().expect("set above"))
    }
}

/// A sparse LU with the same equilibration and the same "name the zero column" check as
/// [`EquilibratedLu`]. Its singularity test: the factors must reproduce a known solution
/// (`B x = B 1`, `B` the equilibrated matrix) to `1e-6`, i.e. a condition number far below
/// `1 / eps`; a factorisation with a zero or non-finite pivot fails that test too.
pub struct SparseEquilibratedLu {
    lu: Lu<usize, f64>,
    row: Vec<f64>,
    col: Vec<f64>,
}

impl SparseEquilibratedLu {
    /// Factorises `a`, reusing `cache`'s analysis when the pattern is the same.
    ///
    /// # Errors
    /// [`JpError::SingularMatrix`] naming `what`.
    pub fn new(a: &SparseMat, what: &str, cache: &mut SymbolicCache) -> Result<Self> {
        let n = a.nrows();
        if a.ncols() != n {
            return Err(JpError::bad_size(format!("{what} (columns)"), n, a.ncols()));
        }
        let norms: Vec<f64> = {
            let (cp, v) = (a.as_ref().symbolic().col_ptr(), a.val());
            (0..n).map(|j| v[cp[j]..cp[j + 1]].iter().map(|x| x * x).sum::<f64>().sqrt()).collect()
        };
        if let Some(j) = norms.iter().position(|&s| s == 0.0) {
            return Err(zero_column(what, j));
        }
        let one_or = |s: f64| if s > 0.0 && s.is_finite() { s } else { 1.0 };
        let col: Vec<f64> = norms.iter().map(|&s| 1.0 / one_or(s)).collect();
        // B = R A C on A's own pattern (a view: the pattern is not copied)
        let sym = a.as_ref().symbolic();
        let (cp, ri) = (sym.col_ptr(), sym.row_idx());
        let mut v = a.val().to_vec();
        for j in 0..n {
            for k in cp[j]..cp[j + 1] {
                v[k] *= col[j];
            }
        }
        let mut rs = vec![0.0; n];
        for k in 0..v.len() {
            rs[ri[k]] += v[k] * v[k];
        }
        let row: Vec<f64> = rs.iter().map(|s| 1.0 / one_or(s.sqrt())).collect();
        for k in 0..v.len() {
            v[k] *= row[ri[k]];
        }
        let symbolic = cache.for_matrix(a)?;
        let b = SparseColMatRef::new(sym, &v);
        let lu = Lu::try_new_with_symbolic(symbolic, b).map_err(|e| JpError::singular(format!("{what} ({n} x {n}, sparse): {e:?}")))?;
        let this = SparseEquilibratedLu { lu, row, col };
        // known-solution check on the equilibrated matrix: B y = B 1 must give y = 1
        let mut rhs = vec![0.0; n];
        for k in 0..v.len() {
            rhs[ri[k]] += v[k];
        }
        let x = this.solve_scaled(&rhs);
        let err = x.iter().map(|v| (v - 1.0).abs()).fold(0.0f64, |m, e| if e.is_finite() { m.max(e) } else { f64::INFINITY });
        if !(err <= 1e-6) {
            return Err(JpError::singular(format!(
                "{what} ({n} x {n}, sparse): the LU does not reproduce a known solution (error {err:.3e}): numerically singular"
            )));
        }
        Ok(this)
    }

    /// Solves the equilibrated system `B y = b`.
    fn solve_scaled(&self, b: &[f64]) -> Vec<f64> {
        let mut rhs = Mat::from_fn(b.len(), 1, |i, _| b[i]);
        self.lu.solve_in_place_with_conj(Conj::No, rhs.as_mut());
        (0..b.len()).map(|i| rhs[(i, 0)]).collect()
    }

    /// Solves `a x = rhs`.
    pub fn solve(&self, rhs: &[f64]) -> Vec<f64> {
        let b: Vec<f64> = rhs.iter().zip(&self.row).map(|(v, r)| v * r).collect();
        self.solve_scaled(&b).iter().zip(&self.col).map(|(y, c)| y * c).collect()
    }
}

/// The checked LU of a [`Matrix`] in its own storage.
pub enum MatrixLu {
    Dense(EquilibratedLu),
    Sparse(SparseEquilibratedLu),
}

impl MatrixLu {
    /// Factorises `a` (a sparse `a` reuses `cache`'s analysis when its pattern is the same).
    ///
    /// # Errors
    /// [`JpError::SingularMatrix`] naming `what`.
    pub fn new(a: &Matrix, what: &str, cache: &mut SymbolicCache) -> Result<Self> {
        Ok(match a {
            Matrix::Dense(m) => MatrixLu::Dense(EquilibratedLu::new(m, what)?),
            Matrix::Sparse(m) => MatrixLu::Sparse(SparseEquilibratedLu::new(m, what, cache)?),
        })
    }

    /// Solves `a x = rhs`.
    pub fn solve(&self, rhs: &[f64]) -> Vec<f64> {
        match self {
            MatrixLu::Dense(lu) => lu.solve(rhs),
            MatrixLu::Sparse(lu) => lu.solve(rhs),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

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
        let mut cache = SymbolicCache::new();
        let rhs: Vec<f64> = (0..=n).map(|i| (i as f64).cos()).collect();
        let xd = MatrixLu::new(&bd, "dense", &mut cache).unwrap().solve(&rhs);
        let xs = MatrixLu::new(&bs, "sparse", &mut cache).unwrap().solve(&rhs);
        assert!(diff(&xd, &xs) < 1e-12, "{}", diff(&xd, &xs));
        assert!(diff(&bs.mat_vec(&xs), &rhs) < 1e-12);
        // the cached analysis is reused for the same pattern and gives the same answer
        let xs2 = MatrixLu::new(&bs, "sparse", &mut cache).unwrap().solve(&rhs);
        assert_eq!(xs, xs2);
    }

    #[test]
    fn singular_sparse_matrices_are_refused_with_a_reason() {
        let n = 10;
        let mut cache = SymbolicCache::new();
        // a zero column
        let t: Vec<(usize, usize, f64)> = (0..n).filter(|&i| i != 4).map(|i| (i, i, 1.0)).collect();
        let a = sparse_from_triplets(n, n, t).unwrap();
        let e = SparseEquilibratedLu::new(&a, "zero column", &mut cache).err().expect("singular").to_string();
        assert!(e.contains("unknown 4 appears in no equation"), "{e}");
        // two equal columns: structurally fine, numerically singular
        let mut t: Vec<(usize, usize, f64)> = (0..n).map(|i| (i, i, 2.0)).collect();
        t.push((1, 0, 1.0));
        t.push((0, 1, 2.0));
        t.push((1, 1, -1.0)); // column 1 = column 0 now: (2, 1) in rows 0 and 1
        let a = sparse_from_triplets(n, n, t).unwrap();
        assert!(SparseEquilibratedLu::new(&a, "equal columns", &mut SymbolicCache::new()).is_err());
    }
}
