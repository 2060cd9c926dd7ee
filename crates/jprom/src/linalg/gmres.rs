//! Restarted GMRES with right preconditioning (Saad, *Iterative Methods for Sparse Linear
//! Systems*, 2nd ed., Algorithm 9.5): solves `A x = b` by minimising `|b - A M^-1 u|` over a
//! Krylov space of `A M^-1`, `x = M^-1 u`. The Arnoldi vectors are orthogonalised twice
//! (classical Gram-Schmidt with one re-orthogonalisation), the least-squares problem is
//! reduced by Givens rotations. Used where a factorisation of a nearby matrix is at hand and a
//! few right-hand sides of the matrix itself are wanted (the static corrections of the JP modes
//! from the band-centre factorisation, docs/formulation.md §8.10).

/// Settings of [`gmres`].
#[derive(Clone, Copy, Debug)]
pub struct GmresOptions {
    /// Stop when the true residual `|b - A x|` is at most `tolerance |b|` (a cycle ends when its
    /// least-squares residual gets there; the next starts from the true residual, so the
    /// rounding of an ill-conditioned preconditioner is corrected as by iterative refinement),
    /// or when a cycle no longer halves the true residual (its rounding floor).
    pub tolerance: f64,
    /// Krylov dimension before a restart.
    pub restart: usize,
    /// Most applications of `A` in all.
    pub max_iterations: usize,
}

/// What [`gmres`] found.
#[derive(Clone, Debug)]
pub struct GmresOutcome {
    /// The last iterate.
    pub x: Vec<f64>,
    /// Applications of `A` (and of `M^-1`) made.
    pub iterations: usize,
    /// The true relative residual `|b - A x| / |b|` of `x` (recomputed, not the recurrence's).
    pub residual: f64,
    /// Whether the true residual reached the tolerance.
    pub converged: bool,
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

fn norm(a: &[f64]) -> f64 {
    dot(a, a).sqrt()
}

/// `A x = b` by restarted, right-preconditioned GMRES from `x = 0`. `a(v)` applies `A`,
/// `m_inv(v)` the preconditioner `M^-1`. Never fails: the outcome says whether it converged
/// and gives the true residual, which the caller judges.
pub fn gmres(a: impl Fn(&[f64]) -> Vec<f64>, m_inv: impl Fn(&[f64]) -> Vec<f64>, b: &[f64], opts: &GmresOptions) -> GmresOutcome {
    let n = b.len();
    let b_norm = norm(b);
    let mut x = vec![0.0; n];
    if b_norm == 0.0 || !b_norm.is_finite() {
        let residual = if b_norm == 0.0 { 0.0 } else { f64::NAN };
        return GmresOutcome { x, iterations: 0, residual, converged: b_norm == 0.0 };
    }
    let restart = opts.restart.max(1);
    let target = opts.tolerance * b_norm;
    let mut iterations = 0;
    let mut converged = false;
    let mut r = b.to_vec();
    let mut previous = f64::INFINITY;
    while iterations < opts.max_iterations {
        let beta = norm(&r);
        if !beta.is_finite() {
            break;
        }
        if beta <= target {
            converged = true;
            break;
        }
        if beta > 0.5 * previous {
            break; // stagnation at the rounding floor
        }
        previous = beta;
        let mut v: Vec<Vec<f64>> = vec![r.iter().map(|x| x / beta).collect()];
        // h[j] is column j of the Hessenberg matrix (j + 2 entries), rotated in place
        let mut h: Vec<Vec<f64>> = Vec::new();
        let mut rot: Vec<(f64, f64)> = Vec::new();
        let mut g = vec![beta];
        for j in 0..restart.min(opts.max_iterations - iterations) {
            let mut w = a(&m_inv(&v[j]));
            iterations += 1;
            let mut col = vec![0.0; j + 2];
            for _ in 0..2 {
                for (i, vi) in v.iter().enumerate() {
                    let c = dot(vi, &w);
                    col[i] += c;
                    for (wk, vk) in w.iter_mut().zip(vi) {
                        *wk -= c * vk;
                    }
                }
            }
            let wn = norm(&w);
            col[j + 1] = wn;
            for (i, &(c, s)) in rot.iter().enumerate() {
                let (p, q) = (col[i], col[i + 1]);
                col[i] = c * p + s * q;
                col[i + 1] = -s * p + c * q;
            }
            let (p, q) = (col[j], col[j + 1]);
            let d = p.hypot(q);
            let (c, s) = if d == 0.0 { (1.0, 0.0) } else { (p / d, q / d) };
            col[j] = d;
            col[j + 1] = 0.0;
            rot.push((c, s));
            g.push(-s * g[j]);
            g[j] *= c;
            h.push(col);
            let breakdown = !(wn.is_finite() && wn > 0.0);
            if !breakdown {
                v.push(w.into_iter().map(|x| x / wn).collect());
            }
            if g[j + 1].abs() <= target || breakdown {
                break;
            }
        }
        // y = H^-1 g (upper triangular), x += M^-1 (V y)
        let m = h.len();
        let mut y = vec![0.0; m];
        for i in (0..m).rev() {
            let s: f64 = (i + 1..m).map(|k| h[k][i] * y[k]).sum();
            y[i] = if h[i][i] != 0.0 { (g[i] - s) / h[i][i] } else { 0.0 };
        }
        let mut u = vec![0.0; n];
        for (vi, yi) in v.iter().zip(&y) {
            for (uk, vk) in u.iter_mut().zip(vi) {
                *uk += yi * vk;
            }
        }
        for (xk, dk) in x.iter_mut().zip(m_inv(&u)) {
            *xk += dk;
        }
        let ax = a(&x);
        r = b.iter().zip(&ax).map(|(bk, ak)| bk - ak).collect();
    }
    let residual = norm(&r) / b_norm;
    converged = converged || residual <= opts.tolerance;
    GmresOutcome { x, iterations, residual, converged }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A non-symmetric, diagonally dominated `n x n` matrix (dense, row-major) with a few
    /// eigenvalues near zero, and its exact solve by Gaussian elimination.
    fn matrix(n: usize) -> Vec<f64> {
        let mut a = vec![0.0; n * n];
        for i in 0..n {
            for j in 0..n {
                a[i * n + j] = ((i * 31 + j * 17) % 11) as f64 / 11.0 - 0.5;
            }
            a[i * n + i] += 4.0 + i as f64;
        }
        a
    }

    fn times(a: &[f64], n: usize, x: &[f64]) -> Vec<f64> {
        (0..n).map(|i| (0..n).map(|j| a[i * n + j] * x[j]).sum()).collect()
    }

    #[test]
    fn solves_with_and_without_a_preconditioner() {
        let n = 60;
        let a = matrix(n);
        let b: Vec<f64> = (0..n).map(|i| 1.0 + (i % 7) as f64).collect();
        let opts = GmresOptions { tolerance: 1e-13, restart: 20, max_iterations: 400 };
        // the diagonal as the preconditioner, and none
        let jacobi = |v: &[f64]| v.iter().enumerate().map(|(i, x)| x / a[i * n + i]).collect::<Vec<_>>();
        for out in [gmres(|v| times(&a, n, v), jacobi, &b, &opts), gmres(|v| times(&a, n, v), |v| v.to_vec(), &b, &opts)] {
            assert!(out.converged, "{out:?}");
            let r: f64 = times(&a, n, &out.x).iter().zip(&b).map(|(p, q)| (p - q).powi(2)).sum::<f64>().sqrt();
            assert!(r < 1e-11 * norm(&b), "residual {r}");
            assert!((out.residual - r / norm(&b)).abs() < 1e-14);
        }
        // the preconditioner that is the inverse converges in one step
        let exact = |v: &[f64]| {
            let o = gmres(|w| times(&a, n, w), |w| w.to_vec(), v, &GmresOptions { tolerance: 1e-15, restart: n, max_iterations: n });
            o.x
        };
        let out = gmres(|v| times(&a, n, v), exact, &b, &opts);
        assert!(out.converged && out.iterations <= 2, "{out:?}");
    }

    #[test]
    fn says_when_it_does_not_converge() {
        let n = 60;
        let a = matrix(n);
        let b = vec![1.0; n];
        let out = gmres(|v| times(&a, n, v), |v| v.to_vec(), &b, &GmresOptions { tolerance: 1e-14, restart: 3, max_iterations: 4 });
        assert!(!out.converged);
        assert!(out.iterations <= 4);
        assert!(out.residual > 1e-14);
        // a singular matrix (a zero row) and a right-hand side outside its range
        let mut s = a.clone();
        for j in 0..n {
            s[j] = 0.0;
        }
        let out = gmres(|v| times(&s, n, v), |v| v.to_vec(), &b, &GmresOptions { tolerance: 1e-12, restart: 30, max_iterations: 90 });
        assert!(!out.converged && out.residual > 1e-3, "{out:?}");
        // zero right-hand side
        let out = gmres(|v| times(&a, n, v), |v| v.to_vec(), &vec![0.0; n], &GmresOptions { tolerance: 1e-12, restart: 5, max_iterations: 5 });
        assert!(out.converged && out.x.iter().all(|&x| x == 0.0));
    }
}
