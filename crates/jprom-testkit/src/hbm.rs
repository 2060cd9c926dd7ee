// Shared helpers for the hbm_* tests (included with `#[path]`, not a test target itself).
#![allow(dead_code)]

use faer::linalg::solvers::Solve;
use faer::{c64, Mat};
use jprom::model::{Damping, Excitation, HarmonicForce, Model};
use jprom::contact::Contact;
use rand::{Rng, SeedableRng};

/// Chain of `n` masses with ground springs at both ends plus a random SPD perturbation.
pub fn chain_matrices(n: usize, k: f64, m: f64, seed: u64) -> (Mat<f64>, Mat<f64>) {
    let mut rng = rand::rngs::StdRng::seed_from_u64(seed);
    let mut kk = Mat::<f64>::zeros(n, n);
    for i in 0..n {
        kk[(i, i)] += 2.0 * k;
        if i + 1 < n {
            kk[(i, i + 1)] -= k;
            kk[(i + 1, i)] -= k;
        }
    }
    // + 0.1 k B B^T with random B (SPD perturbation).
    let b = Mat::from_fn(n, n, |_, _| rng.gen_range(-1.0..1.0) / (n as f64).sqrt());
    for i in 0..n {
        for j in 0..n {
            let s: f64 = (0..n).map(|l| b[(i, l)] * b[(j, l)]).sum();
            kk[(i, j)] += 0.1 * k * s;
        }
    }
    let mm = Mat::from_fn(n, n, |i, j| if i == j { m * (1.0 + 0.5 * rng.gen_range(0.0..1.0)) } else { 0.0 });
    (kk, mm)
}

pub fn harmonic_force(cos: Vec<f64>, sin: Vec<f64>) -> HarmonicForce {
    HarmonicForce { cos, sin }
}

pub fn model(
    k: Mat<f64>,
    m: Mat<f64>,
    damping: Damping,
    f0: Vec<f64>,
    harmonics: Vec<HarmonicForce>,
    contacts: Vec<Contact>,
    outputs: Vec<usize>,
) -> Model {
    let exc = Excitation { static_force: f0, harmonics, dynamic_scale: 1.0 };
    Model::new(m, k, damping, exc, contacts, outputs).expect("valid model")
}

/// Dense complex solve `(K - w^2 M + i w C) x = f_c - i f_s`; returns (cos, sin) parts.
pub fn linear_frf(k: &Mat<f64>, m: &Mat<f64>, c: &Mat<f64>, w: f64, fc: &[f64], fs: &[f64]) -> (Vec<f64>, Vec<f64>) {
    let n = k.nrows();
    let d = Mat::from_fn(n, n, |i, j| c64::new(k[(i, j)] - w * w * m[(i, j)], w * c[(i, j)]));
    let rhs = Mat::from_fn(n, 1, |i, _| c64::new(fc[i], -fs[i]));
    let x = d.partial_piv_lu().solve(&rhs);
    ((0..n).map(|i| x[(i, 0)].re).collect(), (0..n).map(|i| -x[(i, 0)].im).collect())
}

/// Real solve `K x = f`.
pub fn static_solve(k: &Mat<f64>, f: &[f64]) -> Vec<f64> {
    let rhs = Mat::from_fn(f.len(), 1, |i, _| f[i]);
    let x = k.partial_piv_lu().solve(&rhs);
    (0..f.len()).map(|i| x[(i, 0)]).collect()
}

pub fn rel_diff(a: &[f64], b: &[f64]) -> f64 {
    let d: f64 = a.iter().zip(b).map(|(x, y)| (x - y).powi(2)).sum::<f64>().sqrt();
    let s: f64 = b.iter().map(|y| y * y).sum::<f64>().sqrt();
    d / s.max(f64::MIN_POSITIVE)
}
