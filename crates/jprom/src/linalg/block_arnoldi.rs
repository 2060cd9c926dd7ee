//! Block Arnoldi for the eigenvalues of largest magnitude of a real operator (the shift-invert
//! operator of the JP problem (31), docs/formulation.md §8.10).
//!
//! Where one application of the operator reads large factors from memory (the reference's LUs,
//! a pattern's capacitance), a block of `p` vectors costs about what one vector does: the same
//! bytes are read once for all of them. The block Krylov space
//! `span(X, A X, A^2 X, ...)` of a start block `X` (`p` columns) is built by block classical
//! Gram-Schmidt (two passes) and a QR of each new block, so that
//!
//! ```text
//! A V_m = V_m H_m + V_{m+1} R_m E_m^T,      H_m block upper Hessenberg (m p square),
//! ```
//!
//! and the Ritz pairs `(θ, V_m y)` of `H_m y = θ y` have the residual `|R_m y_m|` (`y_m` the
//! last `p` entries of `y`). No restart: the space grows until the wanted pairs converge or it
//! reaches its cap, and the caller then takes another solver.

use faer::{c64, Mat, MatMut, MatRef};

/// Settings of [`largest_eigenpairs`].
#[derive(Clone, Copy, Debug)]
pub struct BlockArnoldiOptions {
    /// Vectors per block `p`.
    pub block: usize,
    /// Largest dimension of the Krylov space (a multiple of `block` is used).
    pub max_dim: usize,
    /// Largest accepted residual `|A v - θ v|` of a wanted Ritz pair (`|v| = 1`), relative to
    /// the largest `|θ|` (an estimate of the operator's norm from below).
    pub tolerance: f64,
}

/// A deterministic start block: columns of pseudo-random entries in `[-0.5, 0.5)`, independent
/// of each other and of any structure of the operator.
fn start_block(dim: usize, p: usize) -> Mat<f64> {
    Mat::from_fn(dim, p, |i, j| {
        let mut x = (i as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15) ^ ((j as u64 + 1).wrapping_mul(0xC2B2_AE3D_27D4_EB4F));
        x ^= x >> 29;
        x = x.wrapping_mul(0xBF58_476D_1CE4_E5B9);
        x ^= x >> 32;
        (x % 1_000_003) as f64 / 1_000_003.0 - 0.5
    })
}

/// The `wanted` Ritz pairs `(θ, v)` of largest `|θ|` of `x -> apply(x)` (`dim` rows), each
/// with `|A v - θ v| <= tolerance max |θ|` and `|v| = 1` (complex, conjugates as they come), or `None`
/// when the space reaches `opts.max_dim` (or `dim`) before they converge.
pub fn largest_eigenpairs(dim: usize, wanted: usize, opts: &BlockArnoldiOptions, apply: impl Fn(MatMut<'_, f64>, MatRef<'_, f64>)) -> Option<Vec<(c64, Vec<c64>)>> {
    let p = opts.block.max(1).min(dim);
    if wanted == 0 || dim == 0 || wanted > dim {
        return None;
    }
    let max_blocks = (opts.max_dim.min(dim) / p).max(1);
    let mut blocks: Vec<Mat<f64>> = vec![start_block(dim, p).qr().compute_thin_Q()];
    let mut h = Mat::<f64>::zeros((max_blocks + 1) * p, max_blocks * p);
    for m in 0..max_blocks {
        let mut w = Mat::<f64>::zeros(dim, p);
        apply(w.as_mut(), blocks[m].as_ref());
        if !w.col_iter().all(|c| c.iter().all(|x| x.is_finite())) {
            return None;
        }
        for _ in 0..2 {
            for (i, vi) in blocks.iter().enumerate() {
                let c = crate::linalg::product(vi.transpose(), w.as_ref());
                w -= crate::linalg::product(vi.as_ref(), c.as_ref());
                let mut hb = h.as_mut().submatrix_mut(i * p, m * p, p, p);
                hb += &c;
            }
        }
        let qr = w.qr();
        let r = qr.thin_R().to_owned();
        h.as_mut().submatrix_mut((m + 1) * p, m * p, p, p).copy_from(&r);
        let k = (m + 1) * p;
        if k >= 2 * wanted {
            if let Some(found) = converged(h.as_ref(), k, p, wanted, opts.tolerance, &blocks, dim) {
                return Some(found);
            }
        }
        if k >= dim {
            return None;
        }
        blocks.push(qr.compute_thin_Q());
    }
    None
}

/// The `wanted` Ritz pairs of largest `|θ|` of the first `k` columns of `h` if all have
/// converged (residual `|R_m y_m|` below `tolerance`), with their vectors `V_m y`.
fn converged(h: MatRef<'_, f64>, k: usize, p: usize, wanted: usize, tolerance: f64, blocks: &[Mat<f64>], dim: usize) -> Option<Vec<(c64, Vec<c64>)>> {
    let hk = h.submatrix(0, 0, k, k).to_owned();
    let evd = hk.eigen().ok()?;
    let (theta, y) = (evd.S(), evd.U());
    let mut order: Vec<usize> = (0..k).collect();
    let mag = |i: usize| theta[i].re.hypot(theta[i].im);
    order.sort_by(|&a, &b| mag(b).total_cmp(&mag(a)));
    let r = h.submatrix(k, k - p, p, p);
    let largest = order.first().map_or(0.0, |&i| mag(i));
    let mut out = Vec::with_capacity(wanted);
    for &i in order.iter().take(wanted) {
        let ny = (0..k).map(|row| y[(row, i)].re.powi(2) + y[(row, i)].im.powi(2)).sum::<f64>().sqrt();
        if !(ny > 0.0 && mag(i).is_finite()) {
            return None;
        }
        // |R y_m| of the unit Ritz vector
        let mut res = 0.0;
        for row in 0..p {
            let (mut re, mut im) = (0.0, 0.0);
            for col in 0..p {
                let yc = y[(k - p + col, i)];
                re += r[(row, col)] * yc.re;
                im += r[(row, col)] * yc.im;
            }
            res += re * re + im * im;
        }
        if !(res.sqrt() / ny <= tolerance * largest) {
            return None;
        }
        out.push(i);
    }
    // the vectors V_m y, real and imaginary parts by two real products
    let yre = Mat::from_fn(k, out.len(), |row, j| y[(row, out[j])].re);
    let yim = Mat::from_fn(k, out.len(), |row, j| y[(row, out[j])].im);
    let mut v = Mat::<f64>::zeros(dim, k);
    for (b, q) in blocks.iter().enumerate().take(k / p) {
        v.as_mut().submatrix_mut(0, b * p, dim, p).copy_from(q);
    }
    let (xre, xim) = (crate::linalg::product(v.as_ref(), yre.as_ref()), crate::linalg::product(v.as_ref(), yim.as_ref()));
    Some(
        out.iter()
            .enumerate()
            .map(|(j, &i)| {
                let norm = (0..dim).map(|row| xre[(row, j)].powi(2) + xim[(row, j)].powi(2)).sum::<f64>().sqrt();
                (theta[i], (0..dim).map(|row| c64::new(xre[(row, j)] / norm, xim[(row, j)] / norm)).collect())
            })
            .collect(),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A non-symmetric operator with known eigenvalues: `S D S^-1`, `D` block diagonal with real
    /// eigenvalues and 2x2 rotation-scaling blocks (complex pairs), `S = I + 0.3 N`, `N` strictly
    /// upper triangular (so `S^-1` is cheap and exact to round-off).
    #[test]
    fn finds_the_largest_eigenvalues_of_a_non_symmetric_operator() {
        let dim = 400;
        // eigenvalues: 1/(1 + i) decaying, a complex pair at 0.9 +- 0.2 i, a close pair 0.7, 0.6999
        let mut d = Mat::<f64>::zeros(dim, dim);
        for i in 0..dim {
            d[(i, i)] = 0.5 / (1.0 + i as f64);
        }
        d[(0, 0)] = 0.9;
        d[(1, 1)] = 0.9;
        d[(0, 1)] = 0.2;
        d[(1, 0)] = -0.2;
        d[(2, 2)] = 0.7;
        d[(3, 3)] = 0.6999;
        let s = Mat::from_fn(dim, dim, |i, j| if i == j { 1.0 } else if j > i && j < i + 4 { 0.3 / (1.0 + (j - i) as f64) } else { 0.0 });
        // A = S D S^-1 as (S^-T (S D)^T)^T: one solve with S^T
        let sd_t = (&s * &d).transpose().to_owned();
        let a = crate::linalg::DenseLu::new(&s.transpose().to_owned()).solve(&sd_t).transpose().to_owned();
        let opts = BlockArnoldiOptions { block: 4, max_dim: 200, tolerance: 1e-12 };
        let found = largest_eigenpairs(dim, 6, &opts, |mut w, v| w.copy_from(&a * v)).expect("converges");
        let mut mags: Vec<f64> = found.iter().map(|(t, _)| t.re.hypot(t.im)).collect();
        mags.sort_by(|x, y| y.total_cmp(x));
        let exact = [0.9f64.hypot(0.2), 0.9f64.hypot(0.2), 0.7, 0.6999, 0.5 / 5.0, 0.5 / 6.0];
        for (m, e) in mags.iter().zip(exact) {
            assert!((m - e).abs() < 1e-10, "{mags:?}");
        }
        for (theta, v) in &found {
            // |A v - θ v|
            let vr = Mat::from_fn(dim, 1, |i, _| v[i].re);
            let vi = Mat::from_fn(dim, 1, |i, _| v[i].im);
            let (ar, ai) = (&a * &vr, &a * &vi);
            let res: f64 = (0..dim).map(|i| (ar[(i, 0)] - (theta.re * vr[(i, 0)] - theta.im * vi[(i, 0)])).powi(2) + (ai[(i, 0)] - (theta.re * vi[(i, 0)] + theta.im * vr[(i, 0)])).powi(2)).sum::<f64>().sqrt();
            assert!(res < 1e-10, "theta {theta:?}: residual {res:e}");
        }
        // a space too small for them: None, not a wrong answer
        let small = BlockArnoldiOptions { block: 2, max_dim: 12, tolerance: 1e-14 };
        assert!(largest_eigenpairs(dim, 6, &small, |mut w, v| w.copy_from(&a * v)).is_none());
    }
}
