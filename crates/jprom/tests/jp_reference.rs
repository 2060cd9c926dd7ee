//! The prediction on a shared reference (docs/formulation.md §8.10, issue 17) against the
//! per-pattern prediction: the same basis spans (principal angles below 1e-8 per harmonic) and
//! the same reduced sweeps, at H = 1 and 3, on the default blade (18 contacts) and the
//! refinement-5 blade (242 contacts).
//!
//! Both solve (31) by shift-invert Arnoldi: the per-pattern path on the dense `K̂`, `S` and its
//! own factorisation of `K_JC - σ M_JC` per pattern (what `Auto` does where `2 H n > 600`), the
//! shared one on the reference's factorisations and the active contacts of each pattern. The
//! dense eigen solve (`Auto`'s choice on the default blade) is compared as well.
//!
//! What limited the agreement is the accuracy of the columns, not the path: the columns (33) are
//! parts of the eigenvectors scaled to unit length, and on the default blade some come from
//! parts of 1e-4 to 1e-3 of their eigenvector (the higher-harmonic content of first-harmonic
//! modes at partial slip, the small imaginary parts of near-conjugate pairs), so an eigenvector
//! accurate to 1e-12 gave them to about 1e-8: the three paths (shared, per pattern, dense)
//! differed by up to 2.3e-7 at H = 1 and 4.9e-7 at H = 3. Since 2026-12-05 the eigenvectors of
//! problems up to `POLISH_MAX_DIM` (`2 H n` = 1,200) are polished by one step of inverse
//! iteration at their own eigenvalue (`jp::modes`), and every harmonic of both blades is held to
//! 1e-8 (measured at most 2.4e-10 on the default blade).

use faer::Mat;
use jprom::hbm::{sweep, HbmOptions, SweepOptions};
use jprom::jp::prediction::{static_solution, PatternFactorisation};
use jprom::jp::reference::ReferenceFactors;
use jprom::jp::{jp_modes, jp_modes_on_reference, predict_basis, stuck_mode, ContactJacobian, EigenSolver, JpBasis, ModeOptions, PredictionOptions};
use jprom::model::ContactCoordinates;
use jprom::rom::FrRom;
use jprom_testkit::blade::{forces_along_shape, tip_amplitude, Blade};
use std::ops::ControlFlow;

/// `sin` of the largest principal angle between the spans of the orthonormal `a` and `b`.
fn largest_angle_sin(a: &Mat<f64>, b: &Mat<f64>) -> f64 {
    if a.ncols() == 0 && b.ncols() == 0 {
        return 0.0;
    }
    let one_way = |p: &Mat<f64>, q: &Mat<f64>| {
        let r = q - p * (p.transpose() * q);
        r.singular_values().map(|s| s.first().copied().unwrap_or(0.0)).unwrap_or(f64::INFINITY)
    };
    one_way(a, b).max(one_way(b, a))
}

fn predicted(coords: &ContactCoordinates, band: (f64, f64), how: PatternFactorisation, n_samples: usize) -> JpBasis {
    let mut popts = PredictionOptions::new(band);
    popts.n_samples = n_samples;
    popts.factorisation = how;
    popts.modes.solver = EigenSolver::ShiftInvert;
    predict_basis(coords, &popts).unwrap().0
}

/// Peak tip amplitude of a reduced sweep of the band.
fn fr_peak(coords: &ContactCoordinates, basis: &JpBasis, band: (f64, f64)) -> f64 {
    let fr = FrRom::new(coords, basis).unwrap();
    let sopts = SweepOptions { max_points: 80, ..SweepOptions::band(band.0, band.1) };
    let s = sweep(&fr, &sopts, &HbmOptions::default(), &mut |_| ControlFlow::Continue(())).unwrap();
    assert!(s.reached_end(), "sweep ended early: {:?}", s.end);
    s.points.iter().map(tip_amplitude).fold(0.0, f64::max)
}

/// Compares the shared-reference prediction with the per-pattern one (shift-invert) and, if
/// `with_dense`, with the per-pattern dense eigen solve: every harmonic's span to 1e-8.
fn compare(blade: &Blade, h: usize, n_samples: usize, with_dense: bool) {
    let model = blade.at_level(blade.alpha_st / 10.0);
    let coords = ContactCoordinates::new(&model, h).unwrap();
    let per = predicted(&coords, blade.band, PatternFactorisation::PerPattern, n_samples);
    let shared = predicted(&coords, blade.band, PatternFactorisation::SharedReference, n_samples);
    let what = format!("{} contacts, H = {h}", model.contacts.len());
    assert_eq!(per.sizes, shared.sizes, "{what}: basis sizes");
    assert!(per.n_patterns > 1, "{what}: the level must give several patterns, got {}", per.n_patterns);
    assert_eq!(per.n_patterns, shared.n_patterns, "{what}");
    for (k, (a, b)) in per.phi.iter().zip(&shared.phi).enumerate() {
        let s = largest_angle_sin(a, b);
        eprintln!("{what}: harmonic {k}, n_h = {}, largest principal angle {s:.2e}", a.ncols());
        assert!(s < 1e-8, "{what}: harmonic {k}: largest principal angle {s:.3e}");
    }
    if with_dense {
        let mut popts = PredictionOptions::new(blade.band);
        popts.n_samples = n_samples;
        popts.factorisation = PatternFactorisation::PerPattern;
        popts.modes.solver = EigenSolver::Dense;
        let dense = predict_basis(&coords, &popts).unwrap().0;
        assert_eq!(dense.sizes, shared.sizes, "{what}: basis sizes, dense eigen solve");
        for (k, (a, b)) in dense.phi.iter().zip(&shared.phi).enumerate() {
            let s = largest_angle_sin(a, b);
            eprintln!("{what}: harmonic {k}, against the dense eigen solve: {s:.2e}");
            assert!(s < 1e-8, "{what}: harmonic {k}: largest principal angle against the dense eigen solve {s:.3e}");
        }
    }
    let (pa, pb) = (fr_peak(&coords, &per, blade.band), fr_peak(&coords, &shared, blade.band));
    eprintln!("{what}: FR peak tip amplitude {pa:.9e} per pattern, {pb:.9e} shared");
    assert!((pa - pb).abs() <= 1e-8 * pa, "{what}: FR peaks {pa:.12e} vs {pb:.12e}");
}

#[test]
fn shared_reference_gives_the_per_pattern_basis_on_the_default_blade() {
    let blade = Blade::build();
    compare(&blade, 1, 20, true);
    compare(&blade, 3, 20, true);
}

#[test]
fn shared_reference_gives_the_per_pattern_basis_on_the_refinement_5_blade() {
    let blade = Blade::build_refined(5);
    compare(&blade, 1, 6, false);
    compare(&blade, 3, 4, false);
}

/// `K̂` of the AFT evaluation at the static part `q0` and first-harmonic cos part `p phi`.
fn jacobian_at(coords: &ContactCoordinates, q0: &[f64], phi: &[f64], p: f64) -> ContactJacobian {
    let (w, out) = forces_along_shape(coords, q0, phi, p, true);
    ContactJacobian::from_forces(&coords.laws, &coords.offsets, coords.n_w, coords.discretisation.plan().unwrap().harmonics(), &out, &w).unwrap()
}

/// One Jacobian at a time: `jp_modes_on_reference` against `jp_modes` (eigenvalues against the
/// dense eigen solve, bases against the per-pattern shift-invert), for a slipping pattern on a
/// stuck reference and the reference itself (no active contact), with and without the static
/// correction.
/// The model's contact coordinates at `h` harmonics, the stuck Jacobian, the reference on it at
/// the band centre and the Jacobian along the stuck mode at the smallest amplitude (factors of
/// 2) at which a quarter of the contact coordinates are active.
fn quarter_slipping(blade: &Blade, model: &jprom::model::Model, h: usize) -> (ContactCoordinates, ContactJacobian, ReferenceFactors, ContactJacobian) {
    slipping_until(blade, model, h, |part, n_w| part.len() * 4 >= n_w)
}

/// As [`quarter_slipping`], at the smallest amplitude whose active part satisfies `enough`
/// (given the part and `n_w`).
fn slipping_until(blade: &Blade, model: &jprom::model::Model, h: usize, enough: impl Fn(&jprom::jp::reference::ActivePart, usize) -> bool) -> (ContactCoordinates, ContactJacobian, ReferenceFactors, ContactJacobian) {
    let coords = ContactCoordinates::new(model, h).unwrap();
    let stuck = ContactJacobian::stuck(&coords.laws, &coords.offsets, coords.n_w, h).unwrap();
    let centre = 0.5 * (blade.band.0 + blade.band.1);
    let reference = ReferenceFactors::from_jacobian(&coords, &stuck, centre * centre).unwrap();
    let q0 = static_solution(&coords).unwrap();
    let (_, phi) = stuck_mode(&coords, blade.band).unwrap();
    let mut p = 1e-9;
    let slipping = loop {
        let k = jacobian_at(&coords, &q0, &phi, p);
        if enough(&reference.active_part(&coords, &k).unwrap(), coords.n_w) {
            break k;
        }
        p *= 2.0;
        assert!(p < 1.0, "no slip along the stuck mode");
    };
    (coords, stuck, reference, slipping)
}

#[test]
fn modes_on_a_reference_match_the_dense_modes() {
    let blade = Blade::build();
    let model = blade.at_level(blade.alpha_st / 10.0);
    for h in [1, 3] {
        let (coords, stuck, reference, slipping) = quarter_slipping(&blade, &model, h);
        let part = reference.active_part(&coords, &slipping).unwrap();
        assert!(part.len() < coords.n_w, "a partly slipping pattern: {} of {} active", part.len(), coords.n_w);
        // a slipping contact that stays closed keeps its normal row: its leading rows are the
        // tangential ones, so the capacitances shrink to 2/3
        assert!(part.lead.len() < part.len() && !part.lead.is_empty(), "H = {h}: {} leading of {} active rows", part.lead.len(), part.len());
        assert!(reference.active_part(&coords, &stuck).unwrap().is_empty());
        for (name, k_hat) in [("stuck", &stuck), ("slipping", &slipping)] {
            for static_correction in [false, true] {
                let opts = ModeOptions { band: blade.band, extra_outside: 2, static_correction, solver: EigenSolver::Dense };
                let dense = jp_modes(&coords, k_hat, &opts).unwrap();
                let on_ref = jp_modes_on_reference(&coords, k_hat, &opts, &reference).unwrap();
                assert_eq!(dense.eigenvalues.len(), on_ref.eigenvalues.len(), "H = {h}: kept eigenvalues");
                for (a, b) in dense.eigenvalues.iter().zip(&on_ref.eigenvalues) {
                    assert!((a.0 - b.0).abs() <= 1e-9 * a.0.abs(), "H = {h}: eigenvalue {a:?} vs {b:?}");
                }
                let dense = jp_modes(&coords, k_hat, &ModeOptions { solver: EigenSolver::ShiftInvert, ..opts }).unwrap();
                let gamma = 1e3;
                let bd = JpBasis::from_modes(&[dense], gamma, coords.n_w).unwrap();
                let br = JpBasis::from_modes(&[on_ref], gamma, coords.n_w).unwrap();
                assert_eq!(bd.sizes, br.sizes, "H = {h}, static correction {static_correction}");
                let angles: Vec<f64> = bd.phi.iter().zip(&br.phi).map(|(a, b)| largest_angle_sin(a, b)).collect();
                eprintln!("{name}, H = {h}, static correction {static_correction}: sizes {:?}, angles {:?}", bd.sizes, angles.iter().map(|a| format!("{a:.1e}")).collect::<Vec<_>>());
                for (k, s) in angles.iter().enumerate() {
                    assert!(*s < 1e-8, "{name}, H = {h}, static correction {static_correction}, harmonic {k}: angle {s:.3e}");
                }
            }
        }
    }
}



/// The static corrections' shift-0 solves by GMRES on the band-centre factorisation
/// (`ShiftedSolve::solve_unshifted`, docs/formulation.md §8.10) equal the solves of a second
/// factorisation at shift 0, on a pattern with a quarter of its contact coordinates slipping, at
/// H = 1 and 3; and `K_JC x = b` holds to round-off.
#[test]
fn static_corrections_by_gmres_match_the_shift_0_factorisation() {
    use jprom::jp::reference::active_statics;
    use jprom::jp::shift_invert::{CondensedProblem, ShiftedFactorisation, ShiftedSolve};
    let blade = Blade::build();
    let model = blade.at_level(blade.alpha_st / 10.0);
    for h in [1, 3] {
        let (coords, _, reference, slipping) = quarter_slipping(&blade, &model, h);
        let part = reference.active_part(&coords, &slipping).unwrap();
        let st = active_statics(&coords, &reference, &part).unwrap();
        let problem = CondensedProblem::on_reference(&coords, &reference, &part, &st.g_aa);
        let at_shift = ShiftedSolve::new(&problem, reference.shift(), ShiftedFactorisation::Woodbury).unwrap();
        let at_zero = ShiftedSolve::new(&problem, 0.0, ShiftedFactorisation::Woodbury).unwrap();
        let dim = problem.dim();
        // a harmonic load on every DoF and one on the contact coordinates of harmonic 1 only
        let b = Mat::from_fn(dim, 2, |i, j| if j == 0 { 1.0 + (i % 7) as f64 } else if i < coords.n_w { ((i % 5) as f64 - 2.0) * 1e3 } else { 0.0 });
        let by_gmres = at_shift.solve_unshifted(b.as_ref()).expect("GMRES reaches the accepted residual");
        let direct = at_zero.solve(b.as_ref());
        for j in 0..2 {
            let diff = (by_gmres.col(j) - direct.col(j)).norm_l2() / direct.col(j).norm_l2();
            let res = (problem.apply_shifted(by_gmres.as_ref(), 0.0).col(j) - b.col(j)).norm_l2() / b.col(j).norm_l2();
            eprintln!("H = {h}, {} active, column {j}: GMRES vs direct {diff:.2e}, residual {res:.2e}", part.len());
            assert!(diff < 1e-9, "H = {h}, column {j}: {diff:.3e}");
            assert!(res < 1e-11, "H = {h}, column {j}: residual {res:.3e}");
        }
    }
}

/// The single-precision capacitance with refined solves (`ShiftedFactorisation::WoodburyMixed`,
/// the path of the large patterns, docs/formulation.md §8.10) on a reference: a pattern with a
/// quarter of its coordinates active (`Y_h,l` copied) and one with at least half of them leading
/// (`Y_h,l` read in the reference's `Y_h`), H = 1 and 3. The solves equal the double
/// capacitance's to 1e-10 with residuals at round-off, and the eigenpairs of (31) by block
/// Arnoldi are the same (eigenvalues 1e-8 relative, spans 1e-8).
#[test]
fn mixed_precision_capacitance_on_a_reference() {
    use jprom::jp::reference::active_statics;
    use jprom::jp::shift_invert::{problem_eigenpairs_by, CondensedProblem, Krylov, ShiftedFactorisation, ShiftedSolve};
    let blade = Blade::build();
    let model = blade.at_level(blade.alpha_st / 10.0);
    for h in [1, 3] {
        let quarter = slipping_until(&blade, &model, h, |part, n_w| part.len() * 4 >= n_w);
        let half_leading = slipping_until(&blade, &model, h, |part, n_w| part.lead.len() * 2 >= n_w);
        for (name, (coords, _, reference, slipping)) in [("quarter active", quarter), ("half leading", half_leading)] {
            let what = format!("H = {h}, {name}");
            let part = reference.active_part(&coords, &slipping).unwrap();
            let st = active_statics(&coords, &reference, &part).unwrap();
            let problem = CondensedProblem::on_reference(&coords, &reference, &part, &st.g_aa);
            let double = ShiftedSolve::new(&problem, reference.shift(), ShiftedFactorisation::Woodbury).unwrap();
            let mixed = ShiftedSolve::new(&problem, reference.shift(), ShiftedFactorisation::WoodburyMixed).unwrap();
            assert!(!double.single_precision_capacitance() && mixed.single_precision_capacitance(), "{what}");
            let dim = problem.dim();
            let b = Mat::from_fn(dim, 2, |i, j| if j == 0 { 1.0 + (i % 7) as f64 } else { ((i * 13) % 11) as f64 - 5.0 });
            let (xd, xm) = (double.solve(b.as_ref()), mixed.solve(b.as_ref()));
            for j in 0..2 {
                let diff = (xm.col(j) - xd.col(j)).norm_l2() / xd.col(j).norm_l2();
                let ax = problem.apply_shifted(xm.as_ref(), reference.shift());
                let scale = problem.apply_shifted(xm.as_ref(), 0.0).col(j).norm_l2() + reference.shift() * problem.apply_mass(xm.as_ref()).col(j).norm_l2();
                let res = (ax.col(j) - b.col(j)).norm_l2() / scale;
                eprintln!("{what} ({} active, {} leading): column {j}: mixed vs double {diff:.1e}, residual {res:.1e}", part.len(), part.lead.len());
                assert!(diff < 1e-10 && res < 1e-12, "{what}, column {j}: mixed vs double {diff:.2e}, residual {res:.2e}");
            }
            let o = ModeOptions { band: blade.band, extra_outside: 2, static_correction: false, solver: EigenSolver::ShiftInvert };
            let ed = problem_eigenpairs_by(&problem, &o, ShiftedFactorisation::Woodbury, Krylov::Block).unwrap();
            let em = problem_eigenpairs_by(&problem, &o, ShiftedFactorisation::WoodburyMixed, Krylov::Block).unwrap();
            assert_eq!(ed.0.len(), em.0.len(), "{what}: {:?} vs {:?}", ed.0, em.0);
            for (a, c) in ed.0.iter().zip(&em.0) {
                assert!((a.0 - c.0).hypot(a.1 - c.1) <= 1e-8 * a.0.hypot(a.1), "{what}: eigenvalue {a:?} vs {c:?}");
            }
            let span = |e: &(Vec<(f64, f64)>, Mat<f64>, Mat<f64>)| {
                let m = e.1.ncols();
                let a = Mat::from_fn(e.1.nrows(), 2 * m, |i, j| if j < m { e.1[(i, j)] } else { e.2[(i, j - m)] });
                let svd = a.thin_svd().unwrap();
                let sv = svd.S().column_vector();
                let rank = (0..sv.nrows()).filter(|&i| sv[i] > 1e-10 * sv[0]).count();
                svd.U().subcols(0, rank).to_owned()
            };
            let angle = largest_angle_sin(&span(&ed), &span(&em));
            eprintln!("{what}: {} eigenvalues, largest principal angle {angle:.1e}", ed.0.len());
            assert!(angle < 1e-8, "{what}: largest principal angle {angle:.2e}");
        }
    }
}
