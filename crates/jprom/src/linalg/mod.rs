//! Linear algebra shared by the numerical modules: checked dense LU ([`lu`]), sparse matrices
//! ([`sparse`]), a matrix dense or sparse with one checked LU for both ([`matrix`]), dense
//! eigen solvers ([`eigen`]), restarted GMRES ([`gmres`]), sparse Cholesky and shift-invert Lanczos ([`lanczos`]) with its fill-reducing ordering ([`ordering`]), and small dense helpers (serde for faer matrices, symmetry checks, norms).

pub mod block_arnoldi;
pub mod eigen;
pub mod gmres;
pub mod lanczos;
pub mod lu;
pub mod matrix;
pub mod ordering;
pub mod sparse;

pub use lu::{check_nonsingular, lu_checked, lu_solve, mat_vec, product, solve_checked, DenseLu};
pub use matrix::{Matrix, MatrixLu};
pub use sparse::{sparse_from_triplets, sparse_matvec, sparse_to_dense, sparse_triplets, SparseMat};

use crate::error::{JpError, Result};
use faer::Mat;
use serde::{Deserialize, Deserializer, Serialize, Serializer};

/// Serde adapter for `faer::Mat<f64>`: stored as `{ nrows, ncols, data }`, column-major.
pub mod serde_mat {
    use super::*;

    #[derive(Serialize, Deserialize)]
    struct Stored {
        nrows: usize,
        ncols: usize,
        data: Vec<f64>,
    }

    pub fn serialize<S: Serializer>(m: &Mat<f64>, s: S) -> std::result::Result<S::Ok, S::Error> {
        Stored { nrows: m.nrows(), ncols: m.ncols(), data: col_major(m) }.serialize(s)
    }

    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> std::result::Result<Mat<f64>, D::Error> {
        let st = Stored::deserialize(d)?;
        // the shape is checked against the data (and the caps) before faer allocates anything:
        // `2^32 x 2^32` with no data would overflow, `0 x 2^62` would loop for ever
        let max = crate::limits::MAX_DENSE_DIM;
        if st.nrows > max || st.ncols > max {
            return Err(serde::de::Error::custom(format!(
                "matrix of {} x {} is above jprom's limit of {max} rows or columns",
                st.nrows, st.ncols
            )));
        }
        if st.nrows.checked_mul(st.ncols) != Some(st.data.len()) {
            return Err(serde::de::Error::custom(format!(
                "matrix data has {} entries, expected {} x {}",
                st.data.len(),
                st.nrows,
                st.ncols
            )));
        }
        Ok(from_col_major(st.nrows, st.ncols, &st.data))
    }
}

/// Serde adapter for `Vec<Mat<f64>>`.
pub mod serde_mat_vec {
    use super::*;

    #[derive(Serialize, Deserialize)]
    struct Wrap(#[serde(with = "serde_mat")] Mat<f64>);

    pub fn serialize<S: Serializer>(m: &[Mat<f64>], s: S) -> std::result::Result<S::Ok, S::Error> {
        let v: Vec<Wrap> = m.iter().map(|x| Wrap(x.clone())).collect();
        v.serialize(s)
    }

    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> std::result::Result<Vec<Mat<f64>>, D::Error> {
        let v: Vec<Wrap> = Vec::deserialize(d)?;
        Ok(v.into_iter().map(|w| w.0).collect())
    }
}

/// Column-major copy of a matrix.
pub fn col_major(m: &Mat<f64>) -> Vec<f64> {
    let mut v = Vec::with_capacity(m.nrows() * m.ncols());
    for j in 0..m.ncols() {
        for i in 0..m.nrows() {
            v.push(m[(i, j)]);
        }
    }
    v
}

/// Matrix from a column-major slice (length must be `nrows * ncols`).
pub fn from_col_major(nrows: usize, ncols: usize, data: &[f64]) -> Mat<f64> {
    assert_eq!(data.len(), nrows * ncols);
    Mat::from_fn(nrows, ncols, |i, j| data[i + j * nrows])
}

/// Relative tolerance of the symmetry check on `M`, `K` (and the other matrices jprom needs
/// symmetric).
pub const SYMMETRY_TOLERANCE: f64 = 1e-9;

/// Checks a square matrix for finiteness and symmetry to a relative tolerance.
pub fn check_symmetric(what: &str, m: &Mat<f64>, rel_tol: f64) -> Result<()> {
    let n = m.nrows();
    if m.ncols() != n {
        return Err(JpError::bad_size(format!("{what} (columns)"), n, m.ncols()));
    }
    let mut max_abs = 0.0f64;
    for j in 0..n {
        for i in 0..n {
            let v = m[(i, j)];
            if !v.is_finite() {
                return Err(JpError::invalid(what, format!("entry ({i}, {j}) is not finite ({v})")));
            }
            max_abs = max_abs.max(v.abs());
        }
    }
    let tol = rel_tol * max_abs.max(f64::MIN_POSITIVE);
    for j in 0..n {
        for i in 0..j {
            let d = (m[(i, j)] - m[(j, i)]).abs();
            if d > tol {
                return Err(JpError::invalid(
                    what,
                    format!("not symmetric: |a({i},{j}) - a({j},{i})| = {d:.3e} > {tol:.3e}"),
                ));
            }
        }
    }
    Ok(())
}

/// Euclidean norm.
pub fn norm2(v: &[f64]) -> f64 {
    v.iter().map(|x| x * x).sum::<f64>().sqrt()
}

