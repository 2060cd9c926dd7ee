//! Dense LU factorisation with a singularity check, for real and complex matrices, and its
//! row- and column-equilibrated variant (the one check every solver in jprom uses).

use crate::error::{JpError, Result};
use faer::linalg::solvers::{PartialPivLu, Solve};
use faer::traits::ComplexField;
use faer::{c64, Mat};

/// Factorises `a` by LU with partial pivoting and rejects (numerically) singular matrices:
/// any pivot below `100 n eps` times the largest, or a non-finite pivot. Real (`f64`) or
/// complex (`c64`).
///
/// # Errors
/// [`JpError::SingularMatrix`] naming `what`.
pub fn lu_checked<T: Pivot>(a: &Mat<T>, what: &str) -> Result<PartialPivLu<T>> {
    let lu = a.partial_piv_lu();
    let u = lu.U();
    let n = u.nrows();
    let mut max_p = 0.0f64;
    let mut min_p = f64::INFINITY;
    for i in 0..n {
        let p = u[(i, i)].modulus();
        if !p.is_finite() {
            return Err(JpError::singular(format!("{what}: non-finite pivot {i}")));
        }
        max_p = max_p.max(p);
        min_p = min_p.min(p);
    }
    if n > 0 && (max_p == 0.0 || min_p <= 100.0 * n as f64 * f64::EPSILON * max_p) {
        return Err(JpError::singular(format!(
            "{what} ({n} x {n}): smallest pivot {min_p:.3e} vs largest {max_p:.3e}"
        )));
    }
    Ok(lu)
}

/// The scalars [`lu_checked`] factorises: `f64` and `c64`.
pub trait Pivot: ComplexField {
    /// `|x|`.
    fn modulus(&self) -> f64;
}

impl Pivot for f64 {
    fn modulus(&self) -> f64 {
        self.abs()
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
pub fn lu_solve(lu: &PartialPivLu<f64>, b: &[f64]) -> Vec<f64> {
    let rhs = Mat::from_fn(b.len(), 1, |i, _| b[i]);
    let x = lu.solve(&rhs);
    (0..b.len()).map(|i| x[(i, 0)]).collect()
}

/// Solves `a x = b` (several right-hand sides) by LU and checks the solution instead of the
/// pivots: the relative residual `|a x - b| / (|a| |x| + |b|)` must be below `1e-8`, so a
/// badly scaled but solvable system passes and a singular one does not.
///
/// # Errors
/// [`JpError::SingularMatrix`] naming `what`.
pub fn solve_checked(what: &str, a: &Mat<f64>, b: &Mat<f64>) -> Result<Mat<f64>> {
    let lu = a.partial_piv_lu();
    let x = lu.solve(b);
    let finite = (0..x.ncols()).all(|j| (0..x.nrows()).all(|i| x[(i, j)].is_finite()));
    if !finite {
        return Err(JpError::singular(what));
    }
    let r = a * &x - b;
    let scale = a.norm_l2() * x.norm_l2() + b.norm_l2();
    if r.norm_l2() > 1e-8 * scale.max(f64::MIN_POSITIVE) {
        return Err(JpError::singular(what));
    }
    Ok(x)
}

/// LU of a row- and column-equilibrated copy of `a` (`B = R A C` with `C` scaling every column
/// to unit norm, then `R` every row), so that the singularity test of [`lu_checked`] judges
/// the matrix and not its units: a bordered continuation system mixes displacement columns,
/// a frequency column and an arclength row of very different sizes.
pub struct EquilibratedLu {
    lu: PartialPivLu<f64>,
    row: Vec<f64>,
    col: Vec<f64>,
}

impl EquilibratedLu {
    /// Factorises `a`.
    ///
    /// # Errors
    /// As [`lu_checked`], on the equilibrated matrix.
    pub fn new(a: &Mat<f64>, what: &str) -> Result<Self> {
        let norm_or_one = |s: f64| if s > 0.0 && s.is_finite() { s } else { 1.0 };
        let norms: Vec<f64> = (0..a.ncols()).map(|j| a.col(j).iter().map(|v| v * v).sum::<f64>().sqrt()).collect();
        // a zero column is an unknown no equation holds (e.g. a mass held only by an open
        // contact): say so instead of the NaN pivot it would give
        if let Some(j) = norms.iter().position(|&s| s == 0.0) {
            return Err(zero_column(what, j));
        }
        let col: Vec<f64> = norms.iter().map(|&s| 1.0 / norm_or_one(s)).collect();
        let mut b = Mat::from_fn(a.nrows(), a.ncols(), |i, j| a[(i, j)] * col[j]);
        let row: Vec<f64> = (0..b.nrows()).map(|i| 1.0 / norm_or_one((0..b.ncols()).map(|j| b[(i, j)] * b[(i, j)]).sum::<f64>().sqrt())).collect();
        for j in 0..b.ncols() {
            for (i, v) in b.col_mut(j).iter_mut().enumerate() {
                *v *= row[i];
            }
        }
        Ok(EquilibratedLu { lu: lu_checked(&b, what)?, row, col })
    }

    /// Solves `a x = rhs`.
    pub fn solve(&self, rhs: &[f64]) -> Vec<f64> {
        let b: Vec<f64> = rhs.iter().zip(&self.row).map(|(v, r)| v * r).collect();
        lu_solve(&self.lu, &b).iter().zip(&self.col).map(|(y, c)| y * c).collect()
    }
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
mod equilibrated_tests {
    use super::*;

    #[test]
    fn a_zero_column_is_named_not_a_nan_pivot() {
        let a = Mat::from_fn(3, 3, |i, j| if j == 1 { 0.0 } else if i == j { 2.0 } else { 0.5 });
        let e = EquilibratedLu::new(&a, "Jacobian of the test").err().expect("singular");
        let text = e.to_string();
        assert!(text.contains("unknown 1 appears in no equation"), "{text}");
        let ok = Mat::from_fn(3, 3, |i, j| if i == j { 2.0 } else { 0.5 });
        let x = EquilibratedLu::new(&ok, "ok").unwrap().solve(&[1.0, 2.0, 3.0]);
        let r = mat_vec(&ok, &x);
        assert!((r[0] - 1.0).abs() + (r[1] - 2.0).abs() + (r[2] - 3.0).abs() < 1e-12);
    }
}
