//! Sparse matrices (compressed sparse columns, `usize` indices, full storage of symmetric
//! matrices): assembly from triplets, submatrices, products. Nothing here forms a dense matrix
//! of a full model's size.

use crate::error::{JpError, Result};
use faer::sparse::{SparseColMat, SymbolicSparseColMat};
use faer::{Accum, Mat, MatMut, MatRef};

/// The sparse matrix type of jprom: compressed sparse columns, `usize` indices.
pub type SparseMat = SparseColMat<usize, f64>;

/// Builds a CSC matrix from `(row, col, value)` triplets, summing duplicates.
///
/// # Errors
/// [`JpError::InvalidValue`] if an index is out of range or a value is not finite.
pub fn sparse_from_triplets(nrows: usize, ncols: usize, mut triplets: Vec<(usize, usize, f64)>) -> Result<SparseMat> {
    sparse_from_triplets_in(nrows, ncols, &mut triplets)
}

/// [`sparse_from_triplets`] on a caller's buffer, which it sorts in place (so that a buffer
/// reused across calls is not copied).
///
/// # Errors
/// As [`sparse_from_triplets`].
pub fn sparse_from_triplets_in(nrows: usize, ncols: usize, triplets: &mut [(usize, usize, f64)]) -> Result<SparseMat> {
    check_triplets(nrows, ncols, triplets)?;
    // Stable sort: duplicates are summed in input order, so that a symmetric set of
    // triplets gives an exactly symmetric matrix.
    triplets.sort_by(|a, b| (a.1, a.0).cmp(&(b.1, b.0)));
    let mut col_ptr = vec![0usize; ncols + 1];
    let mut row_idx = Vec::with_capacity(triplets.len());
    let mut val: Vec<f64> = Vec::with_capacity(triplets.len());
    let mut last: Option<(usize, usize)> = None;
    for &(i, j, v) in triplets.iter() {
        if last == Some((i, j)) {
            *val.last_mut().expect("nonempty") += v;
        } else {
            row_idx.push(i);
            val.push(v);
            col_ptr[j + 1] += 1;
            last = Some((i, j));
        }
    }
    for j in 0..ncols {
        col_ptr[j + 1] += col_ptr[j];
    }
    let symbolic = SymbolicSparseColMat::new_checked(nrows, ncols, col_ptr, None, row_idx);
    Ok(SparseColMat::new(symbolic, val))
}

/// Every triplet inside `nrows x ncols` and finite.
///
/// # Errors
/// [`JpError::InvalidValue`] naming the first entry that is not.
pub fn check_triplets(nrows: usize, ncols: usize, triplets: &[(usize, usize, f64)]) -> Result<()> {
    for &(i, j, v) in triplets {
        if i >= nrows || j >= ncols {
            return Err(JpError::invalid("sparse triplet", format!("entry ({i}, {j}) outside {nrows} x {ncols}")));
        }
        if !v.is_finite() {
            return Err(JpError::invalid("sparse triplet", format!("entry ({i}, {j}) is not finite ({v})")));
        }
    }
    Ok(())
}

/// The `(row, col, value)` triplets of a CSC matrix, column by column.
pub fn sparse_triplets(a: &SparseMat) -> Vec<(usize, usize, f64)> {
    let a = a.as_ref();
    let (cp, ri, v) = (a.symbolic().col_ptr(), a.symbolic().row_idx(), a.val());
    let mut out = Vec::with_capacity(v.len());
    for j in 0..a.ncols() {
        for k in cp[j]..cp[j + 1] {
            out.push((ri[k], j, v[k]));
        }
    }
    out
}

/// Submatrix `A[rows, cols]` where `row_map[g]` is the local row of global row `g` (or
/// `usize::MAX` if excluded) and `cols` lists the global columns in local order.
pub(crate) fn sparse_submatrix(a: &SparseMat, row_map: &[usize], n_rows: usize, cols: &[usize]) -> SparseMat {
    let a = a.as_ref();
    let (cp, ri, v) = (a.symbolic().col_ptr(), a.symbolic().row_idx(), a.val());
    let mut col_ptr = Vec::with_capacity(cols.len() + 1);
    col_ptr.push(0usize);
    let mut row_idx = Vec::new();
    let mut val = Vec::new();
    let mut buf: Vec<(usize, f64)> = Vec::new();
    for &j in cols {
        buf.clear();
        for k in cp[j]..cp[j + 1] {
            let r = row_map[ri[k]];
            if r != usize::MAX {
                buf.push((r, v[k]));
            }
        }
        buf.sort_unstable_by_key(|x| x.0);
        for &(r, x) in &buf {
            row_idx.push(r);
            val.push(x);
        }
        col_ptr.push(row_idx.len());
    }
    let symbolic = SymbolicSparseColMat::new_checked(n_rows, cols.len(), col_ptr, None, row_idx);
    SparseColMat::new(symbolic, val)
}

/// Dense copy of a (small) submatrix `A[rows, cols]`.
pub(crate) fn sparse_dense_block(a: &SparseMat, row_map: &[usize], n_rows: usize, cols: &[usize]) -> Mat<f64> {
    let mut out = Mat::zeros(n_rows, cols.len());
    sparse_dense_block_into(out.as_mut(), a, row_map, cols);
    out
}

/// [`sparse_dense_block`] written into `out` (`n_rows x cols.len()`, overwritten), so that a
/// loop over column blocks reuses one buffer.
pub(crate) fn sparse_dense_block_into(out: MatMut<'_, f64>, a: &SparseMat, row_map: &[usize], cols: &[usize]) {
    let mut out = out;
    out.fill(0.0);
    let a = a.as_ref();
    let (cp, ri, v) = (a.symbolic().col_ptr(), a.symbolic().row_idx(), a.val());
    for (lj, &j) in cols.iter().enumerate() {
        for k in cp[j]..cp[j + 1] {
            let r = row_map[ri[k]];
            if r != usize::MAX {
                out[(r, lj)] += v[k];
            }
        }
    }
}

/// `out (+)= alpha * A X` for sparse `A` and dense `X`.
pub(crate) fn spmm(out: MatMut<'_, f64>, accum: Accum, a: &SparseMat, x: MatRef<'_, f64>, alpha: f64) {
    faer::sparse::linalg::matmul::sparse_dense_matmul(out, accum, a.as_ref(), x, alpha, faer::get_global_parallelism());
}

/// The transpose of a CSC matrix, as a CSC matrix (`O(nnz)`).
pub(crate) fn sparse_transpose(a: &SparseMat) -> SparseMat {
    let a = a.as_ref();
    let (m, n) = (a.nrows(), a.ncols());
    let (cp, ri, v) = (a.symbolic().col_ptr(), a.symbolic().row_idx(), a.val());
    let mut col_ptr = vec![0usize; m + 1];
    for &i in ri {
        col_ptr[i + 1] += 1;
    }
    for i in 0..m {
        col_ptr[i + 1] += col_ptr[i];
    }
    let mut next = col_ptr.clone();
    let mut row_idx = vec![0usize; ri.len()];
    let mut val = vec![0.0; ri.len()];
    // Columns in ascending order: each transposed column's rows come out sorted.
    for j in 0..n {
        for k in cp[j]..cp[j + 1] {
            let p = next[ri[k]];
            row_idx[p] = j;
            val[p] = v[k];
            next[ri[k]] += 1;
        }
    }
    SparseColMat::new(SymbolicSparseColMat::new_checked(n, m, col_ptr, None, row_idx), val)
}

/// Columns of `X` that [`spmm_t`] gathers at a time (per thread).
const GATHER_WIDTH: usize = 64;

/// `out (+)= alpha * A^T X` for sparse `A` (`k x m`) and dense `X` (`k x w`) with many columns:
/// row `j` of the product is `sum_i a_ij X[i, :]` over column `j` of `A`, gathered from the
/// rows of `X` laid out contiguously (`X^T` in blocks of [`GATHER_WIDTH`] columns, the blocks
/// shared among the threads). faer's sparse-dense product scatters one column of `X` at a time
/// with scalar updates, on one thread; this form is vectorised along the rows of `X` (the
/// Craig-Bampton blocks of the refinement-5 blade: 4.6x faster). The sums are formed in the
/// order faer forms them for the transposed product (from zero, then `out += alpha * sum`), so
/// the result is the same to the last bit. The transposed blocks come from `scratch` and go
/// back to it, so that a loop of products reuses them.
pub(crate) fn spmm_t(out: MatMut<'_, f64>, accum: Accum, a: &SparseMat, x: MatRef<'_, f64>, alpha: f64, scratch: &MatPool) {
    gather(out, accum, a, x, alpha, false, scratch);
}

/// `out (+)= alpha * A X` from `a_t` = [`sparse_transpose`]`(A)` by the kernel of [`spmm_t`],
/// with faer's order for the product with a CSC matrix (each `a_ik (alpha x_k)` added onto
/// `out` in ascending `k`), so the result is the same to the last bit.
pub(crate) fn spmm_by_transpose(out: MatMut<'_, f64>, accum: Accum, a_t: &SparseMat, x: MatRef<'_, f64>, alpha: f64, scratch: &MatPool) {
    gather(out, accum, a_t, x, alpha, true, scratch);
}

/// Dense matrices kept for reuse: a loop that needs the same large temporaries on every pass
/// takes them from here and gives them back, instead of asking the system for fresh pages (each
/// zeroed by the kernel on first touch: on the 140,658-DoF blade's Craig-Bampton the fresh
/// `X^T` blocks of [`spmm_t`] and the solves' workspaces cost about a sixth of the processor
/// time). Holds what was given back until dropped.
#[derive(Default)]
pub(crate) struct MatPool(std::sync::Mutex<Vec<Mat<f64>>>);

impl MatPool {
    /// A `rows x cols` matrix of unspecified contents: one given back earlier, or a new one.
    pub(crate) fn take(&self, rows: usize, cols: usize) -> Mat<f64> {
        let mut kept = self.0.lock().unwrap_or_else(|e| e.into_inner());
        match kept.iter().position(|m| m.nrows() == rows && m.ncols() == cols) {
            Some(i) => kept.swap_remove(i),
            None => {
                drop(kept);
                Mat::zeros(rows, cols)
            }
        }
    }

    /// Gives `m` back for a later [`MatPool::take`].
    pub(crate) fn give(&self, m: Mat<f64>) {
        self.0.lock().unwrap_or_else(|e| e.into_inner()).push(m);
    }
}

/// The kernel of [`spmm_t`] and [`spmm_by_transpose`] (`onto`: start from `out` and add
/// `a (alpha x)` term by term). Each block of [`GATHER_WIDTH`] columns is written into its own
/// columns of `out`.
fn gather(out: MatMut<'_, f64>, accum: Accum, a: &SparseMat, x: MatRef<'_, f64>, alpha: f64, onto: bool, scratch: &MatPool) {
    let a = a.as_ref();
    let (k, m, w) = (a.nrows(), a.ncols(), x.ncols());
    assert!(x.nrows() == k && out.nrows() == m && out.ncols() == w, "sparse gather product: A^T is {m} x {k}, X {} x {w}, out {} x {}", x.nrows(), out.nrows(), out.ncols());
    let (cp, ri, v) = (a.symbolic().col_ptr(), a.symbolic().row_idx(), a.val());
    let block = |c0: usize, mut o: MatMut<'_, f64>| {
        let cw = o.ncols();
        let mut xt = scratch.take(cw, k);
        xt.copy_from(x.subcols(c0, cw).transpose());
        let mut yt = scratch.take(cw, m);
        if onto && accum == Accum::Add {
            yt.copy_from(o.as_ref().transpose());
        } else {
            yt.fill(0.0);
        }
        if onto {
            xt *= faer::Scale(alpha);
        }
        for j in 0..m {
            let yj = &mut yt.col_as_slice_mut(j)[..cw];
            for p in cp[j]..cp[j + 1] {
                let s = v[p];
                for (y, xi) in yj.iter_mut().zip(&xt.col_as_slice(ri[p])[..cw]) {
                    *y += s * xi;
                }
            }
        }
        if onto {
            o.copy_from(yt.transpose());
        } else {
            match accum {
                Accum::Replace => o.copy_from(yt.transpose() * faer::Scale(alpha)),
                Accum::Add => o += yt.transpose() * faer::Scale(alpha),
            }
        }
        scratch.give(xt);
        scratch.give(yt);
    };
    let mut chunks = Vec::with_capacity(w.div_ceil(GATHER_WIDTH));
    let mut rest = out;
    let mut c0 = 0;
    while c0 < w {
        let cw = GATHER_WIDTH.min(w - c0);
        let (head, tail) = rest.split_at_col_mut(cw);
        chunks.push((c0, head));
        rest = tail;
        c0 += cw;
    }
    if chunks.len() > 1 && faer::get_global_parallelism() != faer::Par::Seq {
        use rayon::prelude::*;
        chunks.into_par_iter().for_each(|(c0, o)| block(c0, o));
    } else {
        chunks.into_iter().for_each(|(c0, o)| block(c0, o));
    }
}

/// `y = A x` for sparse `A` and a vector.
pub fn sparse_matvec(a: &SparseMat, x: &[f64]) -> Vec<f64> {
    let a = a.as_ref();
    let (cp, ri, v) = (a.symbolic().col_ptr(), a.symbolic().row_idx(), a.val());
    let mut y = vec![0.0; a.nrows()];
    for j in 0..a.ncols() {
        let xj = x[j];
        if xj != 0.0 {
            for k in cp[j]..cp[j + 1] {
                y[ri[k]] += v[k] * xj;
            }
        }
    }
    y
}

/// Dense copy of a sparse matrix (for tests and small models only).
pub fn sparse_to_dense(a: &SparseMat) -> Mat<f64> {
    a.as_ref().to_dense()
}

/// The first entry (by column) where square `a` differs from its transpose by more than
/// `rel_tol` times its largest entry: `(i, j, a_ij, a_ji)`, or `None` if `a` is symmetric.
pub fn first_asymmetry(a: &SparseMat, rel_tol: f64) -> Option<(usize, usize, f64, f64)> {
    let tr = sparse_triplets(a);
    let max = tr.iter().fold(0.0f64, |m, t| m.max(t.2.abs()));
    let tol = rel_tol * max;
    let at = sparse_from_triplets(a.ncols(), a.nrows(), tr.iter().map(|&(i, j, v)| (j, i, v)).collect()).ok()?;
    let at = at.as_ref();
    let (cp, ri, v) = (at.symbolic().col_ptr(), at.symbolic().row_idx(), at.val());
    // entries present only in the transpose are covered: (i, j) missing means a(j, i) != 0 is
    // met as its own triplet, against a(i, j) = 0
    tr.into_iter().find_map(|(i, j, a_ij)| {
        let a_ji = (cp[j]..cp[j + 1]).find(|&k| ri[k] == i).map_or(0.0, |k| v[k]);
        ((a_ij - a_ji).abs() > tol).then_some((i, j, a_ij, a_ji))
    })
}

/// The edges `(i, j)`, `i < j`, of the 7-point stencil of an `nx x ny x nz` grid, the vertex
/// `(x, y, z)` numbered `(x ny + y) nz + z`: the sparse test models of the factor, the
/// orderings and the Craig-Bampton reduction.
#[cfg(test)]
pub(crate) fn grid_edges([nx, ny, nz]: [usize; 3]) -> Vec<(usize, usize)> {
    let id = |x: usize, y: usize, z: usize| (x * ny + y) * nz + z;
    let mut edges = Vec::with_capacity(3 * nx * ny * nz);
    for x in 0..nx {
        for y in 0..ny {
            for z in 0..nz {
                let i = id(x, y, z);
                for (a, b, c) in [(x + 1, y, z), (x, y + 1, z), (x, y, z + 1)] {
                    if a < nx && b < ny && c < nz {
                        edges.push((i, id(a, b, c)));
                    }
                }
            }
        }
    }
    edges
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A random-ish sparse `k x m` matrix with empty columns and rows.
    fn sample(k: usize, m: usize) -> SparseMat {
        let mut t = Vec::new();
        for j in 0..m {
            if j % 7 == 3 {
                continue;
            }
            for i in 0..k {
                if (i * 31 + j * 17) % 5 == 0 && i % 11 != 4 {
                    t.push((i, j, ((i * 13 + j * 7) % 19) as f64 - 9.0));
                }
            }
        }
        sparse_from_triplets(k, m, t).unwrap()
    }

    #[test]
    fn spmm_t_equals_the_dense_product() {
        let (k, m) = (57, 41);
        let a = sample(k, m);
        let ad = sparse_to_dense(&a);
        // One pool for all widths: later products reuse (dirty) blocks of earlier ones.
        let pool = MatPool::default();
        for w in [1, 63, 64, 65, 150] {
            let x = Mat::from_fn(k, w, |i, j| ((i * 3 + j * 5) % 23) as f64 - 11.0);
            let y0 = Mat::from_fn(m, w, |i, j| (i + 2 * j) as f64);
            let mut y = y0.clone();
            spmm_t(y.as_mut(), Accum::Add, &a, x.as_ref(), -0.5, &pool);
            let want = &y0 + ad.transpose() * &x * faer::Scale(-0.5);
            assert!((&y - &want).norm_max() <= 1e-12 * want.norm_max(), "w = {w}");
            // A X through the transpose.
            let at = sparse_transpose(&a);
            assert_eq!(sparse_to_dense(&at), ad.transpose().to_owned());
            let xm = Mat::from_fn(m, w, |i, j| ((i * 7 + j) % 13) as f64);
            let z0 = Mat::from_fn(k, w, |i, j| (i * j % 5) as f64 * 0.1);
            let mut z = z0.clone();
            spmm_by_transpose(z.as_mut(), Accum::Add, &at, xm.as_ref(), 2.0, &pool);
            let want = &z0 + &ad * &xm * faer::Scale(2.0);
            assert!((&z - &want).norm_max() <= 1e-12 * want.norm_max(), "w = {w}");
            // The same bits as faer's products.
            let mut f = z0.clone();
            faer::sparse::linalg::matmul::sparse_dense_matmul(f.as_mut(), Accum::Add, a.as_ref(), xm.as_ref(), 2.0, faer::Par::Seq);
            assert!(f == z, "w = {w}: A X differs from faer's");
            let mut f = y0.clone();
            faer::sparse::linalg::matmul::sparse_dense_matmul(f.as_mut(), Accum::Add, a.as_ref().transpose(), x.as_ref(), -0.5, faer::Par::Seq);
            assert!(f == y, "w = {w}: A^T X differs from faer's");
        }
    }
}
