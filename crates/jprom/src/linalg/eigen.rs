//! Dense eigen solvers: the eigenpair of a symmetric matrix or a symmetric-definite pencil
//! nearest a target (inverse / subspace iteration, never a full eigen solve of the vectors),
//! all eigenvalues of a dense pencil, and a power-iteration norm estimate. Products and LU
//! factorisations go through [`super::product`] and [`super::DenseLu`], on the calling thread
//! below their size threshold, as the rest of the dense kernels; the QR, Cholesky and
//! eigenvalue calls take faer's global parallelism (its high-level API has no `Par` argument).

use crate::error::{JpError, Result};
use faer::Mat;

/// The eigenpair of the symmetric matrix `a` whose eigenvalue is nearest `target`: the
/// eigenvalues from faer's eigenvalue-only solver, the eigenvector by inverse iteration at
/// that eigenvalue, checked by its residual. (faer 0.24's `self_adjoint_eigen` with vectors
/// returned a NaN eigenvalue and residuals of 1e-3 on the 803-DoF Craig-Bampton blade of
/// refinement 5; its eigenvalue-only path agreed with the full model.) The vector has unit
/// Euclidean length.
///
/// # Errors
/// [`JpError::Eigen`] naming `what` if the solver fails or the residual is not small.
pub fn symmetric_eigenpair_nearest(a: &Mat<f64>, target: f64, what: &str) -> Result<(f64, Vec<f64>)> {
    use super::DenseLu;
    let n = a.nrows();
    let eig = a
        .self_adjoint_eigenvalues(faer::Side::Lower)
        .map_err(|e| JpError::Eigen { what: format!("{what}: eigenvalues: {e:?}") })?;
    let lambda = eig
        .iter()
        .copied()
        .min_by(|x, y| (x - target).abs().total_cmp(&(y - target).abs()))
        .ok_or_else(|| JpError::Eigen { what: format!("{what}: empty matrix") })?;
    let scale = a.norm_max().max(f64::MIN_POSITIVE);
    // A shift just off the eigenvalue keeps the factorisation regular and converges at once.
    let mu = lambda + 1e-10 * scale;
    let lu = DenseLu::new(&(a - Mat::<f64>::identity(n, n) * faer::Scale(mu)));
    let mut v = Mat::from_fn(n, 1, |i, _| 1.0 + ((i * 7919) % 17) as f64 / 17.0);
    for _ in 0..4 {
        v = lu.solve(&v);
        let nv = v.norm_l2();
        if !(nv.is_finite() && nv > 0.0) {
            return Err(JpError::Eigen { what: format!("{what}: inverse iteration broke down") });
        }
        v /= nv;
    }
    let av = super::product(a.as_ref(), v.as_ref());
    let rayleigh = (v.transpose() * &av)[(0, 0)];
    let residual = (&av - &v * faer::Scale(rayleigh)).norm_l2();
    if !(residual <= 1e-8 * scale) {
        return Err(JpError::Eigen { what: format!("{what}: eigenvector residual {residual:e} (matrix scale {scale:e})") });
    }
    Ok((rayleigh, (0..n).map(|i| v[(i, 0)]).collect()))
}

/// Power-iteration estimate of the largest magnitude of `x -> apply(x)` on vectors of length
/// `n` (`iterations` steps from a fixed, non-special start). Used to scale a shift-invert
/// operator to about unit norm, so that an absolute Krylov tolerance becomes relative.
pub(crate) fn operator_norm_estimate(n: usize, iterations: usize, apply: impl Fn(faer::MatMut<'_, f64>, faer::MatRef<'_, f64>)) -> f64 {
    let mut v = Mat::from_fn(n, 1, |i, _| 1.0 + ((i * 7919) % 13) as f64 / 13.0);
    let mut est = 0.0;
    for _ in 0..iterations {
        let nv = v.norm_l2();
        v /= nv;
        let mut w = Mat::zeros(n, 1);
        apply(w.as_mut(), v.as_ref());
        est = w.norm_l2();
        v = w;
    }
    est
}

/// Block size of [`generalized_eigenpair_nearest`]'s subspace iteration.
const NEAREST_BLOCK: usize = 8;

/// The eigenpair of the symmetric-definite pencil `K x = lambda M x` (`K` symmetric, `M`
/// symmetric positive definite, dense) whose eigenvalue is nearest `target`, by shift-invert
/// subspace iteration: one LU of `K - target M`, then `V <- (K - target M)^-1 M V` on a block of
/// [`NEAREST_BLOCK`] vectors with a Rayleigh-Ritz projection onto `(K, M)` after each step,
/// until the Ritz pair nearest `target` has a relative residual
/// `|K x - lambda M x| / (|K x| + |lambda| |M x|)` below `1e-10` (at most 100 steps; each
/// gains the factor `|lambda - target| / |lambda_9 - target|`, `lambda_9` the ninth nearest).
/// Cost: the LU (`2/3 n^3`) and `O(n^2)` per step, never a full eigen solve. The vector has
/// unit Euclidean length.
///
/// # Errors
/// [`JpError::BadSize`] for mismatched sizes, [`JpError::Eigen`] naming `what` if
/// `K - target M` is singular to working precision or the iteration does not converge.
pub fn generalized_eigenpair_nearest(k: &Mat<f64>, m: &Mat<f64>, target: f64, what: &str) -> Result<(f64, Vec<f64>)> {
    let mut pairs = generalized_eigenpairs_nearest(k, m, target, 1, what)?;
    Ok(pairs.swap_remove(0))
}

/// The `count` eigenpairs of the symmetric-definite pencil `K x = lambda M x` whose eigenvalues
/// are nearest `target`, nearest first, by the subspace iteration of
/// [`generalized_eigenpair_nearest`] on a block of `max(`[`NEAREST_BLOCK`]`, 2 count)`
/// vectors, until each of the `count` has converged. Fewer when the pencil is smaller than
/// `count`. Unit Euclidean length.
///
/// # Errors
/// As [`generalized_eigenpair_nearest`]; `count = 0` is [`JpError::InvalidValue`].
pub fn generalized_eigenpairs_nearest(k: &Mat<f64>, m: &Mat<f64>, target: f64, count: usize, what: &str) -> Result<Vec<(f64, Vec<f64>)>> {
    use super::DenseLu;
    let n = k.nrows();
    if k.ncols() != n || m.nrows() != n || m.ncols() != n {
        return Err(JpError::bad_size(format!("{what}: pencil (K, M)"), n, m.nrows()));
    }
    if n == 0 {
        return Err(JpError::Eigen { what: format!("{what}: empty matrix") });
    }
    if count == 0 {
        return Err(JpError::invalid(what.to_string(), "asked for 0 eigenpairs"));
    }
    let p = NEAREST_BLOCK.max(2 * count).min(n);
    let count = count.min(p);
    let lu = DenseLu::new(&(k - m * faer::Scale(target)));
    let mut v = Mat::from_fn(n, p, |i, j| if i % p == j { 1.0 } else { 0.0 } + ((i * 7919 + j * 104729) % 23) as f64 / 230.0);
    let mut best = (f64::NAN, f64::INFINITY);
    for _ in 0..100 {
        let x = lu.solve(super::product(m.as_ref(), v.as_ref()));
        if !(0..p).all(|j| x.col(j).iter().all(|z| z.is_finite())) {
            return Err(JpError::Eigen { what: format!("{what}: K - sigma M singular at sigma = {target:e}") });
        }
        // Orthonormal basis of the new block, then Rayleigh-Ritz on (K, M).
        let q = x.qr().compute_thin_Q();
        let kq = super::product(k.as_ref(), q.as_ref());
        let mq = super::product(m.as_ref(), q.as_ref());
        let kr = super::product(q.transpose(), kq.as_ref());
        let mr = super::product(q.transpose(), mq.as_ref());
        let kr = Mat::from_fn(p, p, |i, j| 0.5 * (kr[(i, j)] + kr[(j, i)]));
        let mr = Mat::from_fn(p, p, |i, j| 0.5 * (mr[(i, j)] + mr[(j, i)]));
        let l = mr.llt(faer::Side::Lower).map_err(|_| JpError::Eigen { what: format!("{what}: projected mass not positive definite") })?;
        let l = l.L().to_owned();
        let mut a = kr;
        l.as_ref().solve_lower_triangular_in_place(a.as_mut());
        let mut at = a.transpose().to_owned();
        l.as_ref().solve_lower_triangular_in_place(at.as_mut());
        let a = Mat::from_fn(p, p, |i, j| 0.5 * (at[(i, j)] + at[(j, i)]));
        let (s, mut y) = symmetric_eigen(&a, &format!("{what}: Ritz values"))?;
        l.transpose().solve_upper_triangular_in_place(y.as_mut());
        let mut order: Vec<usize> = (0..p).collect();
        order.sort_by(|&a, &b| (s[a] - target).abs().total_cmp(&(s[b] - target).abs()));
        let mut pairs = Vec::with_capacity(count);
        let mut converged = true;
        for &j in &order[..count] {
            let lambda = s[j];
            let yj = y.as_ref().subcols(j, 1);
            let kx = super::product(kq.as_ref(), yj);
            let mx = super::product(mq.as_ref(), yj);
            let res = (&kx - &mx * faer::Scale(lambda)).norm_l2() / (kx.norm_l2() + lambda.abs() * mx.norm_l2()).max(f64::MIN_POSITIVE);
            if !(res.is_finite() && res < 1e-10) {
                converged = false;
                best = (lambda, res);
                break;
            }
            let xv = super::product(q.as_ref(), yj);
            let nx = xv.norm_l2();
            pairs.push((lambda, (0..n).map(|i| xv[(i, 0)] / nx).collect()));
        }
        if converged {
            return Ok(pairs);
        }
        v = super::product(q.as_ref(), y.as_ref());
    }
    Err(JpError::Eigen { what: format!("{what}: subspace iteration nearest {target:e} stopped at lambda = {:e}, residual {:e}", best.0, best.1) })
}

/// Eigenvalues (ascending) of the dense symmetric-definite problem `K x = lambda M x`, by
/// `M = L L^T` and the symmetric `L^-1 K L^-T`.
///
/// # Errors
/// [`JpError::SingularMatrix`] if `M` is not positive definite, [`JpError::Eigen`] otherwise.
pub fn dense_generalized_eigenvalues(k: &faer::Mat<f64>, m: &faer::Mat<f64>) -> Result<Vec<f64>> {
    let (a, _) = cholesky_reduced(k, m)?;
    let s = a
        .self_adjoint_eigenvalues(faer::Side::Lower)
        .map_err(|e| JpError::Eigen { what: format!("dense symmetric eigenvalues: {e:?}") })?;
    let mut s: Vec<f64> = s.into_iter().collect();
    s.sort_by(|a, b| a.partial_cmp(b).unwrap_or(std::cmp::Ordering::Equal));
    Ok(s)
}

/// All eigenpairs of the dense symmetric-definite problem `K x = lambda M x`: eigenvalues
/// ascending and mass-normalised vectors (`Phi^T M Phi = I`, columns in the same order).
///
/// # Errors
/// As [`dense_generalized_eigenvalues`].
pub fn dense_generalized_modes(k: &faer::Mat<f64>, m: &faer::Mat<f64>) -> Result<(Vec<f64>, faer::Mat<f64>)> {
    let (a, llt) = cholesky_reduced(k, m)?;
    let (lambda, mut phi) = symmetric_eigen(&a, "dense symmetric eigenpairs")?;
    // x = L^-T y
    faer::linalg::triangular_solve::solve_upper_triangular_in_place(llt.L().transpose(), phi.as_mut(), faer::get_global_parallelism());
    Ok((lambda, phi))
}

/// All eigenpairs of a dense symmetric matrix: eigenvalues ascending, orthonormal vectors in the
/// same order. The matrix is scaled to unit largest entry first: faer 0.24's
/// `self_adjoint_eigen` returned eigenpairs with a relative residual of 1e-3 on a symmetric
/// `720 x 720` matrix of norm 3e14 (the reduced pencil of tests/data/calculix/block), and
/// exact ones on the same matrix scaled (tests/damping_frf.rs found it).
///
/// # Errors
/// [`JpError::Eigen`] if the decomposition fails.
pub fn symmetric_eigen(a: &faer::Mat<f64>, what: &str) -> Result<(Vec<f64>, faer::Mat<f64>)> {
    let n = a.nrows();
    let scale = a.norm_max();
    let scale = if scale.is_finite() && scale > 0.0 { scale } else { 1.0 };
    let scaled = a * faer::Scale(1.0 / scale);
    let evd = scaled.self_adjoint_eigen(faer::Side::Lower).map_err(|e| JpError::Eigen { what: format!("{what}: {e:?}") })?;
    let s = evd.S().column_vector();
    let mut order: Vec<usize> = (0..n).collect();
    order.sort_by(|&i, &j| s[i].total_cmp(&s[j]));
    let u = evd.U();
    Ok((order.iter().map(|&i| s[i] * scale).collect(), faer::Mat::from_fn(n, n, |i, c| u[(i, order[c])])))
}

/// `L^-1 K L^-T` (symmetrised) and the Cholesky factor of `M = L L^T`.
fn cholesky_reduced(k: &faer::Mat<f64>, m: &faer::Mat<f64>) -> Result<(faer::Mat<f64>, faer::linalg::solvers::Llt<f64>)> {
    let n = k.nrows();
    let llt = m.llt(faer::Side::Lower).map_err(|_| JpError::singular("mass (dense Cholesky)"))?;
    let l = llt.L();
    let mut a = k.clone();
    faer::linalg::triangular_solve::solve_lower_triangular_in_place(l, a.as_mut(), faer::get_global_parallelism());
    let mut at = a.transpose().to_owned();
    faer::linalg::triangular_solve::solve_lower_triangular_in_place(l, at.as_mut(), faer::get_global_parallelism());
    let a = faer::Mat::from_fn(n, n, |i, j| 0.5 * (at[(i, j)] + at[(j, i)]));
    Ok((a, llt))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A symmetric-definite pencil with known eigenvalues `1..=n` (scaled) and a dense `M`:
    /// `K = M^(1/2)... ` built as `K = B^T D B`, `M = B^T B` with a well-conditioned `B`.
    fn pencil(n: usize) -> (Mat<f64>, Mat<f64>, Vec<f64>) {
        let b = Mat::from_fn(n, n, |i, j| if i == j { 2.0 } else { 0.0 } + (((i * 31 + j * 17) % 11) as f64 - 5.0) / (10.0 * n as f64));
        let lams: Vec<f64> = (0..n).map(|i| (1.0 + i as f64) * 1e6).collect();
        let d = Mat::from_fn(n, n, |i, j| if i == j { lams[i] } else { 0.0 });
        let k = b.transpose() * &d * &b;
        let m = b.transpose() * &b;
        (Mat::from_fn(n, n, |i, j| 0.5 * (k[(i, j)] + k[(j, i)])), Mat::from_fn(n, n, |i, j| 0.5 * (m[(i, j)] + m[(j, i)])), lams)
    }

    #[test]
    fn nearest_generalized_eigenpair_matches_the_known_spectrum() {
        for (n, target) in [(5usize, 3.3e6), (40, 17.6e6), (120, 0.2e6), (120, 119.8e6), (120, 60.45e6)] {
            let (k, m, lams) = pencil(n);
            let (lambda, x) = generalized_eigenpair_nearest(&k, &m, target, "test").unwrap();
            let want = lams.iter().copied().min_by(|a, b| (a - target).abs().total_cmp(&(b - target).abs())).unwrap();
            assert!((lambda - want).abs() <= 1e-9 * want, "n = {n}, target {target}: {lambda} vs {want}");
            let xv = Mat::from_fn(n, 1, |i, _| x[i]);
            let r = (&k * &xv - &m * &xv * faer::Scale(lambda)).norm_l2() / (&k * &xv).norm_l2();
            assert!(r < 1e-9, "n = {n}: residual {r}");
            assert!((xv.norm_l2() - 1.0).abs() < 1e-12);
        }
    }

    #[test]
    fn dense_modes_are_mass_normalised_eigenpairs_of_the_known_spectrum() {
        let (k, m, lams) = pencil(30);
        let (lambda, phi) = dense_generalized_modes(&k, &m).unwrap();
        for (got, want) in lambda.iter().zip(&lams) {
            assert!((got - want).abs() <= 1e-9 * want, "{got} vs {want}");
        }
        let r = (&k * &phi - &m * &phi * Mat::from_fn(30, 30, |i, j| if i == j { lambda[i] } else { 0.0 })).norm_l2() / (&k * &phi).norm_l2();
        assert!(r < 1e-10, "residual {r}");
        let g = phi.transpose() * &m * &phi;
        let e = (&g - Mat::<f64>::identity(30, 30)).norm_l2();
        assert!(e < 1e-10, "Phi^T M Phi - I: {e}");
    }
}
