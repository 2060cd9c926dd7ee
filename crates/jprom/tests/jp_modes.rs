//! JP modes in full stick (closed form: the linear modes of K + stuck contact springs, in equal
//! pairs per harmonic) and SVD conditioning against a constructed SVD.

use jprom_testkit::chain as jp_support;

use faer::Mat;
use jp_support::*;
use jprom::jp::{condition, jp_modes, ContactJacobian, JpBasis, ModeOptions};
use jprom::model::ContactCoordinates;
use rand::{rngs::StdRng, Rng, SeedableRng};

/// Orthonormal physical-coordinate basis of the columns of a z-coordinate matrix.
fn physical_span(coords: &ContactCoordinates, phi: &Mat<f64>) -> Mat<f64> {
    let n = coords.n_dof;
    let cols: Vec<Vec<f64>> = (0..phi.ncols())
        .map(|j| coords.to_physical(&(0..n).map(|i| phi[(i, j)]).collect::<Vec<_>>()))
        .collect();
    let x = Mat::from_fn(n, cols.len(), |i, j| cols[j][i]);
    let svd = x.thin_svd().unwrap();
    let s = svd.S().column_vector();
    let rank = (0..s.nrows()).filter(|&i| s[i] > 1e-10 * s[0]).count();
    svd.U().subcols(0, rank).to_owned()
}

fn check_full_stick(harmonics: usize, pair: bool) {
    let model = chain_model(&ChainOptions { pair, ..Default::default() });
    let coords = ContactCoordinates::new(&model, harmonics).unwrap();
    let (freqs, modes) = linear_modes(&stuck_stiffness_physical(&model), &model.mass);
    // Band around modes 2 and 3 (0-based 1, 2).
    let lo = 0.5 * (freqs[0] + freqs[1]);
    let hi = 0.5 * (freqs[2] + freqs[3]);
    let k_hat = ContactJacobian::stuck(&coords.laws, &coords.offsets, coords.n_w, harmonics).unwrap();
    let jp = jp_modes(&coords, &k_hat, &ModeOptions { band: (lo, hi), extra_outside: 0, static_correction: false, solver: jprom::jp::EigenSolver::Auto }).unwrap();

    // Expected eigenvalues: for every h, every linear mode with omega_k / h in the band, twice.
    let mut expected: Vec<f64> = Vec::new();
    for h in 1..=harmonics {
        for &w in &freqs {
            let f = w / h as f64;
            if f >= lo && f <= hi {
                expected.push(f * f);
                expected.push(f * f);
            }
        }
    }
    expected.sort_by(f64::total_cmp);
    assert_eq!(jp.eigenvalues.len(), expected.len(), "H={harmonics}: {:?} vs {expected:?}", jp.eigenvalues);
    for (&(re, im), e) in jp.eigenvalues.iter().zip(&expected) {
        assert!((re - e).abs() <= 1e-8 * e, "eigenvalue {re} vs {e}");
        assert!(im.abs() <= 1e-8 * e, "stuck eigenvalue should be real, im = {im}");
    }

    // Per harmonic, the basis spans exactly the linear modes resonant at h * omega in the band.
    for h in 1..=harmonics {
        let idx: Vec<usize> = (0..freqs.len()).filter(|&k| freqs[k] / h as f64 >= lo && freqs[k] / h as f64 <= hi).collect();
        let b = physical_span(&coords, &jp.phi[h]);
        assert_eq!(b.ncols(), idx.len(), "harmonic {h} basis rank");
        let reference = Mat::from_fn(coords.n_dof, idx.len(), |i, j| modes[(i, idx[j])]);
        assert!(span_residual(&b, &reference) < 1e-7, "harmonic {h} span");
    }
    // Static basis: only the linear static response (K + K_stuck)^-1 f_E^0 (no coupling in stick).
    let b0 = physical_span(&coords, &jp.phi[0]);
    assert_eq!(b0.ncols(), 1);
    let ks = stuck_stiffness_physical(&model);
    let f0 = Mat::from_fn(coords.n_dof, 1, |i, _| model.excitation.static_force[i]);
    let x0 = ks.partial_piv_lu().solve(&f0);
    assert!(span_residual(&b0, &x0) < 1e-9);

    // The conditioned basis is orthonormal and of the expected sizes.
    let basis = JpBasis::from_modes(&[jp], 1e3, coords.n_w).unwrap();
    for (h, p) in basis.phi.iter().enumerate() {
        let g = p.transpose() * p;
        let eye = Mat::<f64>::identity(p.ncols(), p.ncols());
        assert!((&g - &eye).norm_max() < 1e-12, "harmonic {h} not orthonormal");
    }
    assert_eq!(basis.sizes[0], 1);
}

use faer::linalg::solvers::Solve;

#[test]
fn full_stick_jp_modes_are_linear_modes_h1() {
    check_full_stick(1, true);
}

#[test]
fn full_stick_jp_modes_are_linear_modes_h2_ground_only() {
    check_full_stick(2, false);
}

#[test]
fn full_stick_jp_modes_are_linear_modes_h3() {
    check_full_stick(3, true);
}

#[test]
fn extra_outside_adds_nearest_modes() {
    let model = chain_model(&ChainOptions::default());
    let coords = ContactCoordinates::new(&model, 1).unwrap();
    let (freqs, _) = linear_modes(&stuck_stiffness_physical(&model), &model.mass);
    let lo = 0.5 * (freqs[1] + freqs[2]);
    let hi = 0.5 * (freqs[2] + freqs[3]);
    let k_hat = ContactJacobian::stuck(&coords.laws, &coords.offsets, coords.n_w, 1).unwrap();
    let jp = jp_modes(&coords, &k_hat, &ModeOptions { band: (lo, hi), extra_outside: 4, static_correction: false, solver: jprom::jp::EigenSolver::Auto }).unwrap();
    // Mode 2 in band (a pair) plus the 4 nearest eigenvalues outside: modes 1 and 3 (or 4), pairs.
    let f = jp.frequencies();
    assert_eq!(f.len(), 6);
    let d2 = (freqs[2] - freqs[1]).min(freqs[3] - freqs[2]);
    let far = if freqs[2] - freqs[1] < freqs[3] - freqs[2] { freqs[3] } else { freqs[1] };
    let near = if freqs[2] - freqs[1] < freqs[3] - freqs[2] { freqs[1] } else { freqs[3] };
    let _ = d2;
    let count = |target: f64| f.iter().filter(|&&x| (x - target).abs() < 1e-8 * target).count();
    assert_eq!(count(freqs[2]), 2);
    assert_eq!(count(near), 2);
    // The last pair is the next nearest of the remaining candidates.
    let others: Vec<f64> = freqs.iter().copied().filter(|&x| x != freqs[2] && x != near).collect();
    let next = others
        .iter()
        .copied()
        .min_by(|a, b| (lo - a).max(a - hi).total_cmp(&(lo - b).max(b - hi)))
        .unwrap();
    assert_eq!(count(next), 2, "far {far}, next {next}");
}

#[test]
fn svd_conditioning_keeps_singular_values_above_ratio() {
    let mut rng = StdRng::seed_from_u64(11);
    let (n, m) = (30, 12);
    let rand_orth = |rows: usize, cols: usize, rng: &mut StdRng| {
        let a = Mat::from_fn(rows, cols, |_, _| rng.gen_range(-1.0..1.0));
        a.qr().compute_thin_Q()
    };
    let u = rand_orth(n, m, &mut rng);
    let v = rand_orth(m, m, &mut rng);
    let s: Vec<f64> = (0..m).map(|i| 10f64.powf(-(i as f64) * 0.5)).collect();
    let phi = &u * Mat::from_fn(m, m, |i, j| if i == j { s[i] } else { 0.0 }) * v.transpose();
    for gamma in [1.0, 5.0, 1e2, 1e4, 1e7] {
        let c = condition(&phi, gamma).unwrap();
        let expected = s.iter().filter(|&&x| x >= s[0] / gamma * (1.0 - 1e-12)).count();
        // Values exactly at the threshold are ambiguous up to round-off; avoid them.
        assert_eq!(c.basis.ncols(), expected, "gamma {gamma}");
        for j in 0..expected {
            let dot: f64 = (0..n).map(|i| c.basis[(i, j)] * u[(i, j)]).sum();
            assert!((dot.abs() - 1.0).abs() < 1e-8, "column {j}: |u_j . basis_j| = {}", dot.abs());
            assert!((c.singular_values[j] - s[j]).abs() < 1e-10 * s[0]);
        }
    }
    assert!(condition(&phi, 0.5).is_err());
    assert_eq!(condition(&Mat::zeros(5, 0), 10.0).unwrap().basis.ncols(), 0);
}

#[test]
fn basis_save_load_roundtrip() {
    let model = chain_model(&ChainOptions::default());
    let coords = ContactCoordinates::new(&model, 1).unwrap();
    let (freqs, _) = linear_modes(&stuck_stiffness_physical(&model), &model.mass);
    let k_hat = ContactJacobian::stuck(&coords.laws, &coords.offsets, coords.n_w, 1).unwrap();
    let opts = jprom::jp::BasisOptions { modes: ModeOptions { band: (0.0, freqs[3]), extra_outside: 0, static_correction: false, solver: jprom::jp::EigenSolver::Auto }, gamma: 1e3 };
    let basis = JpBasis::from_jacobian(&coords, &k_hat, &opts).unwrap();
    let dir = std::env::temp_dir().join(format!("jprom_basis_{}.json", std::process::id()));
    basis.save_json(&dir).unwrap();
    let back = JpBasis::load_json(&dir).unwrap();
    std::fs::remove_file(&dir).ok();
    // serde_json without `float_roundtrip` may differ in the last bit.
    assert_eq!(back.sizes, basis.sizes);
    assert_eq!(back.n_w, basis.n_w);
    for (a, b) in back.phi.iter().zip(&basis.phi) {
        assert!((a - b).norm_max() <= 1e-15 * b.norm_max().max(1.0));
    }
}

/// The per-contact products of `K̂` blocks equal the dense ones on a slipping Jacobian (node
/// pair and ground contacts, H = 2), and a `K̂` with a coupling between two contacts is not
/// taken as per-contact (the JP solves then use the dense products).
#[test]
fn per_contact_products_match_dense_and_coupling_is_detected() {
    let model = chain_model(&ChainOptions::default());
    let harmonics = 2;
    let coords = ContactCoordinates::new(&model, harmonics).unwrap();
    let (freqs, _) = linear_modes(&stuck_stiffness_physical(&model), &model.mass);
    let band = (0.9 * freqs[0], 1.1 * freqs[0]);
    let k_hat = slipping_jacobian(&coords, harmonics, band, 3.0);
    let (laws, offsets) = (&coords.laws, &coords.offsets);
    assert!(k_hat.is_per_contact(laws, offsets));
    let nw = coords.n_w;
    let mut rng = StdRng::seed_from_u64(5);
    let x = Mat::from_fn(nw, 4, |_, _| rng.gen_range(-1.0..1.0));
    let xt = x.transpose().to_owned();
    let mut checked = 0;
    for k in 0..2 * harmonics + 1 {
        for l in 0..2 * harmonics + 1 {
            let dense = k_hat.block(k, l) * &x;
            let err = (k_hat.block_times(k, l, x.as_ref(), laws, offsets) - &dense).norm_l2();
            assert!(err <= 1e-14 * (1.0 + dense.norm_l2()), "K̂_{k}{l} X: {err:.2e}");
            let dense_r = &xt * k_hat.block(k, l);
            let err = (k_hat.times_block(xt.as_ref(), k, l, laws, offsets) - &dense_r).norm_l2();
            assert!(err <= 1e-14 * (1.0 + dense_r.norm_l2()), "X K̂_{k}{l}: {err:.2e}");
            checked += (dense.norm_l2() > 0.0) as usize;
        }
    }
    assert!(checked > 2 * harmonics + 1, "the slipping Jacobian couples harmonics ({checked} non-zero blocks)");
    let mut coupled = k_hat.clone();
    let (a, b) = (offsets[0], offsets[1]);
    coupled.k_hat[(nw + a, 2 * nw + b)] = 1.0;
    assert!(!coupled.is_per_contact(laws, offsets));
}
