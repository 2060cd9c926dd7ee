//! Dense LU factorisation with a singularity check, for real and complex matrices (the
//! equilibrated LU the Newton solvers use, dense or sparse, is [`super::MatrixLu`]).

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
