//! The shift-invert Arnoldi path of the JP eigenproblem (31) against the dense solve: same
//! kept eigenvalues (1e-8 relative), same per-harmonic spans, same conditioned basis sizes (one
//! column apart at most, where a singular value lies near the cut), on
//! the spring-mass chain and the built-in blade, stuck and slipping, H = 1 and H = 3; and the
//! structured (Woodbury) solve of `K_JC - σ M_JC` against a dense one; and the block Arnoldi of
//! large problems against faer's Krylov-Schur.

use jprom_testkit::chain as jp_support;
use jprom_testkit::blade as blade_support;

use faer::linalg::solvers::Solve;
use faer::Mat;
use jp_support::*;
use jprom::jp::shift_invert::{problem_eigenpairs_by, shift_invert_eigenpairs, CondensedProblem, Eigenpairs, Krylov, ShiftedFactorisation, ShiftedSolve};
use jprom::jp::{jp_modes, BasisOptions, ContactJacobian, EigenSolver, JpBasis, JpModes, ModeOptions};
use jprom::model::{ContactCoordinates, Model};

/// Orthonormal basis of the columns of `a` (rank by singular values above `1e-10 s_max`).
fn orth(a: &Mat<f64>) -> Mat<f64> {
    if a.ncols() == 0 {
        return Mat::zeros(a.nrows(), 0);
    }
    let svd = a.thin_svd().unwrap();
    let s = svd.S().column_vector();
    let rank = (0..s.nrows()).filter(|&i| s[i] > 1e-10 * s[0]).count();
    svd.U().subcols(0, rank).to_owned()
}

fn chain() -> Model {
    chain_model(&ChainOptions { n_nodes: 40, n_ground: 12, pair: true, ..Default::default() })
}

fn chain_band(model: &Model) -> (f64, f64) {
    let (freqs, _) = linear_modes(&stuck_stiffness_physical(model), &model.mass);
    (0.5 * (freqs[1] + freqs[2]), 0.5 * (freqs[4] + freqs[5]))
}

/// `|(I - P_a) b|_2 / |b|_2` with `P_a` the projector on the columns of `a` (rank at 1e-12).
fn matrix_span_residual(a: &Mat<f64>, b: &Mat<f64>) -> f64 {
    if b.ncols() == 0 {
        return 0.0;
    }
    let nb = b.norm_l2();
    if a.ncols() == 0 {
        return 1.0;
    }
    let svd = a.thin_svd().unwrap();
    let s = svd.S().column_vector();
    let rank = (0..s.nrows()).filter(|&i| s[i] > 1e-12 * s[0]).count();
    let q = svd.U().subcols(0, rank).to_owned();
    let r = b - &q * (q.transpose() * b);
    let sr = r.thin_svd().unwrap().S().column_vector()[0];
    let sb = b.thin_svd().unwrap().S().column_vector()[0];
    let _ = nb;
    sr / sb
}

/// Eigenpairs as (eigenvalue, complex eigenvector), both as (re, im).
type Pairs = Vec<((f64, f64), Vec<(f64, f64)>)>;

/// Eigenvectors of the shift-invert path against an independent dense solve of
/// `M_JC^-1 K_JC`: each kept one lies in the span of the dense eigenvectors of the same
/// eigenvalue, and every dense eigenvector with an eigenvalue in the band in the span of the
/// kept ones.
fn check_eigenvectors(what: &str, coords: &ContactCoordinates, k_hat: &ContactJacobian, o: &ModeOptions) {
    let g = g_ww(coords, k_hat);
    let problem = CondensedProblem::new(coords, k_hat, &g).unwrap();
    let kjc = problem.dense_shifted(0.0);
    let dim = kjc.nrows();
    let (n, nj) = (coords.n_dof, dim / coords.n_dof);
    // Standard form L_J^-1 K_JC L_J^-T u = λ u, M = L L^T, L_J = blockdiag(h L).
    let l = coords.mass.llt(faer::Side::Lower).unwrap().L().to_owned();
    let hs = |c: usize| (c / 2 + 1) as f64;
    let mut a = kjc.clone();
    for c in 0..nj {
        let mut stripe = a.as_mut().submatrix_mut(c * n, 0, n, dim);
        l.as_ref().solve_lower_triangular_in_place(stripe.as_mut());
        stripe *= faer::Scale(1.0 / hs(c));
    }
    let mut at = a.transpose().to_owned();
    for c in 0..nj {
        let mut stripe = at.as_mut().submatrix_mut(c * n, 0, n, dim);
        l.as_ref().solve_lower_triangular_in_place(stripe.as_mut());
        stripe *= faer::Scale(1.0 / hs(c));
    }
    let evd = at.transpose().to_owned().eigen().unwrap();
    let (sd, ud) = (evd.S(), evd.U());
    let mut ure = Mat::from_fn(dim, dim, |i, k| ud[(i, k)].re);
    let mut uim = Mat::from_fn(dim, dim, |i, k| ud[(i, k)].im);
    for c in 0..nj {
        for u in [&mut ure, &mut uim] {
            let mut stripe = u.as_mut().submatrix_mut(c * n, 0, n, dim);
            l.transpose().solve_upper_triangular_in_place(stripe.as_mut());
            stripe *= faer::Scale(1.0 / hs(c));
        }
    }
    let dense: Pairs = (0..dim).map(|k| ((sd[k].re, sd[k].im), (0..dim).map(|i| (ure[(i, k)], uim[(i, k)])).collect())).collect();
    let (vals, v_re, v_im) = shift_invert_eigenpairs(coords, k_hat, &g, o).unwrap();
    let si: Pairs = vals.iter().enumerate().map(|(k, &l)| (l, (0..dim).map(|i| (v_re[(i, k)], v_im[(i, k)])).collect())).collect();
    for (lam, v) in &si {
        let nrm: f64 = v.iter().map(|z| z.0 * z.0 + z.1 * z.1).sum::<f64>().sqrt();
        assert!((nrm - 1.0).abs() < 1e-12, "{what}: eigenvector norm {nrm}");
        let same: Vec<&Vec<(f64, f64)>> = dense.iter().filter(|(l, _)| ((l.0 - lam.0).powi(2) + (l.1 - lam.1).powi(2)).sqrt() <= 1e-6 * lam.0.abs()).map(|(_, v)| v).collect();
        let r = complex_span_residual(&same, v);
        let near = dense.iter().map(|(l, _)| *l).min_by(|a, b| ((a.0 - lam.0).abs() + (a.1 - lam.1).abs()).total_cmp(&((b.0 - lam.0).abs() + (b.1 - lam.1).abs())));
        assert!(r < 1e-6, "{what}: shift-invert eigenvector of {lam:?} not in the dense eigenspace: {r:.2e} (nearest dense {near:?})");
    }
    let (lo, hi) = o.band;
    for (lam, v) in dense.iter().filter(|(l, _)| l.0.max(0.0).sqrt() >= lo && l.0.max(0.0).sqrt() <= hi) {
        let same: Vec<&Vec<(f64, f64)>> = si.iter().filter(|(l, _)| ((l.0 - lam.0).powi(2) + (l.1 - lam.1).powi(2)).sqrt() <= 1e-6 * lam.0.abs()).map(|(_, v)| v).collect();
        let r = complex_span_residual(&same, v);
        assert!(r < 1e-6, "{what}: dense in-band eigenvector of {lam:?} not found by shift-invert: {r:.2e}");
    }
}

/// Relative residual of the complex vector `v` against the span of `basis`.
fn complex_span_residual(basis: &[&Vec<(f64, f64)>], v: &[(f64, f64)]) -> f64 {
    let n = v.len();
    // Real embedding: complex span of columns x <-> real span of [x, i x].
    let mut cols: Vec<Vec<f64>> = Vec::new();
    for b in basis {
        cols.push(b.iter().map(|z| z.0).chain(b.iter().map(|z| z.1)).collect());
        cols.push(b.iter().map(|z| -z.1).chain(b.iter().map(|z| z.0)).collect());
    }
    if cols.is_empty() {
        return 1.0;
    }
    let a = Mat::from_fn(2 * n, cols.len(), |i, j| cols[j][i]);
    let x = Mat::from_fn(2 * n, 1, |i, _| if i < n { v[i].0 } else { v[i - n].1 });
    matrix_span_residual(&a, &x)
}

fn opts(band: (f64, f64), extra: usize, solver: EigenSolver, static_correction: bool) -> ModeOptions {
    ModeOptions { band, extra_outside: extra, static_correction, solver }
}

fn compare_modes(what: &str, dense: &JpModes, si: &JpModes) {
    let sorted = |m: &JpModes| {
        let mut e = m.eigenvalues.clone();
        e.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.total_cmp(&b.1)));
        e
    };
    let (ed, es) = (sorted(dense), sorted(si));
    assert_eq!(ed.len(), es.len(), "{what}: dense {ed:?}\n vs shift-invert {es:?}");
    for (a, b) in ed.iter().zip(&es) {
        let d = ((a.0 - b.0).powi(2) + (a.1 - b.1).powi(2)).sqrt();
        let s = (a.0 * a.0 + a.1 * a.1).sqrt();
        assert!(d <= 1e-8 * s, "{what}: eigenvalue {a:?} vs {b:?} (rel {:.2e})", d / s);
    }
    // Per-harmonic spans, in the spectral norm relative to the largest singular value (the
    // columns have singular values down to round-off, so a numerical rank is not comparable).
    for h in 0..dense.phi.len() {
        let r1 = matrix_span_residual(&dense.phi[h], &si.phi[h]);
        let r2 = matrix_span_residual(&si.phi[h], &dense.phi[h]);
        assert!(r1 < 1e-6 && r2 < 1e-6, "{what}: span of Phi_{h}: {r1:.2e} {r2:.2e}");
    }
    println!("{what}: {} eigenvalues agree, Phi ranks {:?}", ed.len(), dense.phi.iter().map(|p| orth(p).ncols()).collect::<Vec<_>>());
}

fn check_case(what: &str, model: &Model, band: (f64, f64), harmonics: usize, factor: f64, extra: usize) {
    let coords = ContactCoordinates::new(model, harmonics).unwrap();
    let k_hat = slipping_jacobian(&coords, harmonics, band, factor);
    let what = format!("{what} H={harmonics} factor={factor} extra={extra} (2Hn = {})", 2 * harmonics * coords.n_dof);
    let dense = jp_modes(&coords, &k_hat, &opts(band, extra, EigenSolver::Dense, false)).unwrap();
    let si = jp_modes(&coords, &k_hat, &opts(band, extra, EigenSolver::ShiftInvert, false)).unwrap();
    compare_modes(&what, &dense, &si);
    check_eigenvectors(&what, &coords, &k_hat, &opts(band, extra, EigenSolver::ShiftInvert, false));
    for gamma in [1e3, 1e8] {
        let bd = JpBasis::from_jacobian(&coords, &k_hat, &BasisOptions { modes: opts(band, extra, EigenSolver::Dense, true), gamma }).unwrap();
        let bs = JpBasis::from_jacobian(&coords, &k_hat, &BasisOptions { modes: opts(band, extra, EigenSolver::ShiftInvert, true), gamma }).unwrap();
        // Equal sizes, or one column apart where a singular value of either raw stack lies
        // within a factor 1.5 of the cut `s_max / gamma`: the raw columns of a complex pair are
        // the real and imaginary parts of an eigenvector of arbitrary phase, so the two solvers'
        // stacks (of equal spans, checked above to 1e-6) have different singular values, and
        // one near the cut may fall on either side (the chain at H = 3: 1.15 x the cut in the
        // dense stack, 0.82 x in the shift-invert one).
        for h in 0..bd.sizes.len() {
            if bd.sizes[h] != bs.sizes[h] {
                let on_cut = |sv: &[f64]| {
                    let cut = sv.iter().copied().fold(0.0f64, f64::max) / gamma;
                    sv.iter().any(|&x| x >= cut / 1.5 && x <= 1.5 * cut)
                };
                assert!(
                    bd.sizes[h].abs_diff(bs.sizes[h]) == 1 && (on_cut(&bd.singular_values[h]) || on_cut(&bs.singular_values[h])),
                    "{what}: basis sizes at gamma {gamma:e}: {:?} vs {:?}, harmonic {h} has no singular value near the cut",
                    bd.sizes,
                    bs.sizes
                );
                println!("{what}: harmonic {h} at gamma {gamma:e}: {} vs {} columns, a singular value near the cut", bd.sizes[h], bs.sizes[h]);
            }
        }
    }
}

#[test]
fn chain_stuck_and_slipping() {
    let model = chain();
    let band = chain_band(&model);
    for h in [1, 3] {
        check_case("chain stuck", &model, band, h, 0.0, 0);
        check_case("chain slip", &model, band, h, 4.0, 0);
        check_case("chain slip", &model, band, h, 4.0, 3);
        check_case("chain gross slip", &model, band, h, 100.0, 0);
    }
}

#[test]
fn blade_stuck_and_slipping() {
    let b = blade_support::Blade::build();
    for h in [1, 3] {
        check_case("blade stuck", &b.model, b.band, h, 0.0, 0);
        check_case("blade slip", &b.model, b.band, h, 1.5, 0);
        check_case("blade slip", &b.model, b.band, h, 5.0, 4);
    }
}

/// Block Arnoldi (what `Auto` takes from `BLOCK_KRYLOV_MIN_DIM` unknowns) against faer's
/// Krylov-Schur on the built-in blade, stuck, slipping and in gross slip, H = 1 and 3: the same
/// kept eigenvalues (1e-8 relative, as against the dense solve: on these stiff contacts an
/// eigenvector exact to 1e-13 moves its Rayleigh quotient by about 1e-10) and the same span of
/// their eigenvectors (sine of the largest principal angle below 1e-8). `Krylov::Block` does not fall back: an unconverged
/// block space is an error, so the comparison is with the blocks' own pairs.
#[test]
fn block_arnoldi_matches_krylov_schur() {
    for_each_blade_problem(|what, b, _, problem| {
        let o = opts(b.band, 2, EigenSolver::ShiftInvert, false);
        let single = problem_eigenpairs_by(problem, &o, ShiftedFactorisation::Auto, Krylov::Single).unwrap();
        let block = problem_eigenpairs_by(problem, &o, ShiftedFactorisation::Auto, Krylov::Block).unwrap();
        let (_, sine) = assert_same_eigenpairs(what, &single, &block);
        println!("{what}: {} eigenvalues, largest principal angle {sine:.1e}", single.0.len());
    });
}

/// The built-in blade's condensed problems (31) stuck (factor 0), slipping (1.5, 5) and in
/// gross slip (100), at H = 1 and 3: `f(what, blade, factor, problem)`.
fn for_each_blade_problem(mut f: impl FnMut(&str, &blade_support::Blade, f64, &CondensedProblem<'_>)) {
    let b = blade_support::Blade::build();
    for h in [1, 3] {
        let coords = ContactCoordinates::new(&b.model, h).unwrap();
        for factor in [0.0, 1.5, 5.0, 100.0] {
            let k_hat = slipping_jacobian(&coords, h, b.band, factor);
            let g = g_ww(&coords, &k_hat);
            let problem = CondensedProblem::new(&coords, &k_hat, &g).unwrap();
            f(&format!("H = {h}, factor {factor}"), &b, factor, &problem);
        }
    }
}

/// Asserts that two solves of (31) kept the same eigenvalues (1e-8 relative) and the same span
/// of eigenvectors (sine of the largest principal angle below 1e-8); returns the largest
/// relative eigenvalue difference and that sine.
fn assert_same_eigenpairs(what: &str, a: &Eigenpairs, b: &Eigenpairs) -> (f64, f64) {
    assert_eq!(a.0.len(), b.0.len(), "{what}: {:?} vs {:?}", a.0, b.0);
    let mut worst = 0.0f64;
    for (x, y) in a.0.iter().zip(&b.0) {
        let d = (x.0 - y.0).hypot(x.1 - y.1) / x.0.hypot(x.1);
        worst = worst.max(d);
        assert!(d <= 1e-8, "{what}: eigenvalue {x:?} vs {y:?}");
    }
    let span = |e: &Eigenpairs| {
        let m = e.1.ncols();
        orth(&Mat::from_fn(e.1.nrows(), 2 * m, |i, j| if j < m { e.1[(i, j)] } else { e.2[(i, j - m)] }))
    };
    let (qa, qb) = (span(a), span(b));
    assert_eq!(qa.ncols(), qb.ncols(), "{what}: span dimensions");
    let sine = (&qb - &qa * (qa.transpose() * &qb)).thin_svd().unwrap().S().column_vector().iter().fold(0.0f64, |m, &x| m.max(x));
    assert!(sine < 1e-8, "{what}: largest principal angle {sine:.2e}");
    (worst, sine)
}

/// The Woodbury capacitance in single precision with refined solves
/// ([`ShiftedFactorisation::WoodburyMixed`], the large patterns' path) gives the eigenpairs of
/// the double-precision capacitance on the built-in blade, from stick to gross slip, H = 1 and
/// 3: eigenvalues within 1e-8 relative and spans within 1e-8, the bounds of the other
/// comparisons (the refined solves reach the double LU's residual; measured differences are
/// rounding, 1e-15 to 7e-11 and 6e-14 to 4e-10). A shift 1e-9 from an eigenvalue makes the
/// capacitance too ill-conditioned for single precision: it is factorised in double instead,
/// and the solve stays exact.
#[test]
fn mixed_precision_capacitance_matches_double() {
    for_each_blade_problem(|what, b, factor, problem| {
        let o = opts(b.band, 2, EigenSolver::ShiftInvert, false);
        let sigma = (0.5 * (b.band.0 + b.band.1)).powi(2);
        assert!(ShiftedSolve::new(problem, sigma, ShiftedFactorisation::WoodburyMixed).unwrap().single_precision_capacitance(), "{what}: the single-precision capacitance was refused");
        let double = problem_eigenpairs_by(problem, &o, ShiftedFactorisation::Woodbury, Krylov::Block).unwrap();
        let mixed = problem_eigenpairs_by(problem, &o, ShiftedFactorisation::WoodburyMixed, Krylov::Block).unwrap();
        let (worst, sine) = assert_same_eigenpairs(what, &double, &mixed);
        println!("{what}: {} eigenvalues (largest relative difference {worst:.1e}), largest principal angle {sine:.1e}", double.0.len());
        if factor == 0.0 {
            // stuck: real eigenvalues; a shift next to one
            let lambda = double.0[0].0;
            let near = lambda * (1.0 + 1e-9);
            let s = ShiftedSolve::new(problem, near, ShiftedFactorisation::WoodburyMixed).unwrap();
            assert!(!s.single_precision_capacitance(), "{what}: shift 1e-9 from the eigenvalue {lambda}: the single-precision capacitance was kept");
            let dim = problem.dim();
            let rhs = Mat::from_fn(dim, 1, |i, _| ((i * 37) % 19) as f64 / 19.0 - 0.5);
            let x = s.solve(rhs.as_ref());
            let res = (problem.apply_shifted(x.as_ref(), near) - &rhs).norm_l2() / (problem.apply_shifted(x.as_ref(), 0.0).norm_l2() + near * problem.apply_mass(x.as_ref()).norm_l2());
            println!("{what}: shift next to {lambda:.6e}: capacitance in double, relative residual {res:.1e}");
            assert!(res < 1e-13, "{what}: near-singular solve, residual {res:.2e}");
        }
    });
}

/// `g_ww = (K + K̂_00)^-1 |_ww`.
fn g_ww(coords: &ContactCoordinates, k_hat: &ContactJacobian) -> Mat<f64> {
    let (n, nw) = (coords.n_dof, coords.n_w);
    let mut a0 = coords.stiffness.clone();
    for j in 0..nw {
        for i in 0..nw {
            a0[(i, j)] += k_hat.k_hat[(i, j)];
        }
    }
    let e = Mat::from_fn(n, nw, |i, j| if i == j { 1.0 } else { 0.0 });
    a0.partial_piv_lu().solve(&e).subrows(0, nw).to_owned()
}

#[test]
fn woodbury_solve_matches_dense() {
    for (name, model, band) in [("chain", chain(), None), ("blade", blade_support::Blade::build().model, Some(blade_support::Blade::build().band))] {
        let band = band.unwrap_or_else(|| chain_band(&model));
        for harmonics in [1, 3] {
            let coords = ContactCoordinates::new(&model, harmonics).unwrap();
            let k_hat = slipping_jacobian(&coords, harmonics, band, 5.0);
            let g = g_ww(&coords, &k_hat);
            let problem = CondensedProblem::new(&coords, &k_hat, &g).unwrap();
            let (n, nw, nj) = (coords.n_dof, coords.n_w, 2 * harmonics);
            // K_JC by its definition (30).
            let mut kjc = Mat::<f64>::zeros(nj * n, nj * n);
            for c in 0..nj {
                kjc.as_mut().submatrix_mut(c * n, c * n, n, n).copy_from(&coords.stiffness);
            }
            for ci in 1..=nj {
                for cj in 1..=nj {
                    let corr = k_hat.block(ci, 0) * &g * k_hat.block(0, cj);
                    for j in 0..nw {
                        for i in 0..nw {
                            kjc[((ci - 1) * n + i, (cj - 1) * n + j)] += k_hat.block(ci, cj)[(i, j)] - corr[(i, j)];
                        }
                    }
                }
            }
            let sigma = (0.5 * (band.0 + band.1)).powi(2);
            let mut a = kjc.clone();
            for c in 0..nj {
                let h = (c / 2 + 1) as f64;
                let mut blk = a.as_mut().submatrix_mut(c * n, c * n, n, n);
                blk -= faer::Scale(sigma * h * h) * &coords.mass;
            }
            let diff = (&problem.dense_shifted(sigma) - &a).norm_l2() / a.norm_l2();
            assert!(diff < 1e-13, "{name} H={harmonics}: structured K_JC - sigma M_JC differs by {diff:.2e}");
            let rhs = Mat::from_fn(nj * n, 3, |i, j| ((i * 31 + j * 17) % 23) as f64 / 23.0 - 0.4);
            let x_ref = a.partial_piv_lu().solve(&rhs);
            for how in [ShiftedFactorisation::Woodbury, ShiftedFactorisation::WoodburyMixed, ShiftedFactorisation::Dense, ShiftedFactorisation::Auto] {
                let s = ShiftedSolve::new(&problem, sigma, how).unwrap();
                // these capacitances are well conditioned: the single-precision LU is kept
                assert_eq!(s.single_precision_capacitance(), how == ShiftedFactorisation::WoodburyMixed, "{name} H={harmonics} {how:?}");
                let x = s.solve(rhs.as_ref());
                let err = (&x - &x_ref).norm_l2() / x_ref.norm_l2();
                let res = (&a * &x - &rhs).norm_l2() / rhs.norm_l2();
                println!("{name} H={harmonics} {how:?}: |x - x_dense| / |x| = {err:.2e}, residual {res:.2e}");
                assert!(err < 1e-8 && res < 1e-10, "{name} H={harmonics} {how:?}: error {err:.2e}, residual {res:.2e}");
            }
            // The structured products.
            let x = Mat::from_fn(nj * n, 2, |i, j| ((i * 13 + j * 7) % 11) as f64 - 5.0);
            let d = (&problem.apply_shifted(x.as_ref(), sigma) - &a * &x).norm_l2() / (&a * &x).norm_l2();
            assert!(d < 1e-12, "{name} H={harmonics}: structured product differs by {d:.2e}");
        }
    }
}

#[test]
fn auto_resolves_by_size() {
    assert_eq!(EigenSolver::Auto.resolve(600), EigenSolver::Dense);
    assert_eq!(EigenSolver::Auto.resolve(601), EigenSolver::ShiftInvert);
    assert_eq!(EigenSolver::Dense.resolve(10_000), EigenSolver::Dense);
    assert_eq!(EigenSolver::ShiftInvert.resolve(10), EigenSolver::ShiftInvert);
    // Old option files without the field read as Auto.
    let o: ModeOptions = serde_json::from_str(r#"{"band":[1.0,2.0],"extra_outside":0}"#).unwrap();
    assert_eq!(o.solver, EigenSolver::Auto);
}

/// The blade with the band centred on this mesh's stuck first bending (the band of
/// benches/jp_modes.rs): at H = 3 a harmonic-2 mode is in the band as well.
#[test]
fn blade_band_on_stuck_mode() {
    let b = blade_support::Blade::build();
    let f = b.omega_stuck / (2.0 * std::f64::consts::PI);
    let band = (2.0 * std::f64::consts::PI * (f - 25.0), 2.0 * std::f64::consts::PI * (f + 25.0));
    for h in [1, 3] {
        check_case("blade centred band stuck", &b.model, band, h, 0.0, 0);
    }
}
