//! Acceptance 1 (small model): a JP basis built from a full-order solution's own contact
//! Jacobian reproduces that solution (FR and NLR), at a stuck and a slipping level, H = 1 and
//! H = 3, with node-to-ground and node-pair contacts; the error falls as modes are added, and
//! the error predictor is conservative (e* >= e) for jprom's FR and NLR; for the paper's FR (JP
//! rows) with the smallest basis it is not (measured e*_1 = 0.024 < e_1 = 0.036 at H = 1,
//! 0.030 < 0.032 at H = 3, near the resonance, see `error_metric`). The linearised error, which
//! the self-correcting sweep judges by, equals e to a few per cent on every case.

use jprom_testkit::chain as jp_support;

use jp_support::*;
use jprom::aft::{evaluate_contacts, AftPlan, ContactForces};
use jprom::condensation::CondensedSystem;
use jprom::rom::error_metric::{actual_error, full_order_contact_displacement, linearised_error, output_error, predicted_error};
use jprom::hbm::{solve_point, FullSystem, HbmOptions, PointSolution};
use jprom::jp::{BasisOptions, ContactJacobian, JpBasis, ModeOptions};
use jprom::model::{ContactCoordinates, Model};
use jprom::rom::{FrRom, NlrRom, ReducedModel};

/// Full-order solution near the stuck resonance (a short continuation in omega from below).
fn full_order(model: &Model, harmonics: usize, hopts: &HbmOptions, omega: f64) -> PointSolution {
    let full = FullSystem::new(model, harmonics).unwrap();
    let mut guess: Option<Vec<f64>> = None;
    for k in (0..=40).rev() {
        let om = omega * (1.0 - 0.001 * k as f64);
        let s = solve_point(&full, om, guess.as_deref(), hopts).unwrap();
        guess = Some(s.z);
    }
    solve_point(&full, omega, guess.as_deref(), hopts).unwrap()
}

struct Case {
    /// Per extra setting: (X0, X1) errors of FR (band-condensed rows, `FrRom::new`), FR with
    /// the JP modes' own rows (the paper's, `FrRom::with_jp_rows`) and NLR.
    errors: Vec<[(f64, f64); 3]>,
}

fn run(harmonics: usize, scale: f64, extras: &[usize]) -> Case {
    let mut model = chain_model(&ChainOptions::default());
    model.excitation.dynamic_scale = scale;
    let hopts = HbmOptions::default();
    let coords = ContactCoordinates::new(&model, harmonics).unwrap();
    let (freqs, _) = linear_modes(&stuck_stiffness_physical(&model), &model.mass);
    let omega = 0.99 * freqs[0];
    let band = (0.9 * freqs[0], 1.02 * freqs[0]);
    let fo = full_order(&model, harmonics, &hopts, omega);
    let plan = AftPlan::new(harmonics, jprom::hbm::default_nt(harmonics)).unwrap();
    let w = full_order_contact_displacement(&fo, coords.n_w).unwrap();
    let mut forces = ContactForces::default();
    evaluate_contacts(&plan, &coords.laws, &coords.offsets, coords.n_w, &w, true, false, &mut forces);
    let k_hat = ContactJacobian::from_forces(&coords.laws, &coords.offsets, coords.n_w, harmonics, &forces, &w).unwrap();
    let condensed = CondensedSystem::new(&model, harmonics).unwrap();
    let mut errors = Vec::new();
    for &extra in extras {
        let opts = BasisOptions { modes: ModeOptions { band, extra_outside: extra, static_correction: true, solver: jprom::jp::EigenSolver::Auto }, gamma: 1e10 };
        let basis = JpBasis::from_jacobian(&coords, &k_hat, &opts).unwrap();
        let fr = FrRom::new(&coords, &basis).unwrap();
        let fr_jp = FrRom::with_jp_rows(&coords, &basis).unwrap();
        let nlr = NlrRom::new(&condensed, &basis).unwrap();
        let mut row = Vec::new();
        for rom in [&fr as &dyn ReducedModel, &fr_jp, &nlr] {
            let s = solve_point(rom, omega, None, &hopts).unwrap();
            row.push((output_error(&s.outputs, &fo.outputs, fo.n_outputs, 0), output_error(&s.outputs, &fo.outputs, fo.n_outputs, 1)));
            let es = predicted_error(rom, omega, &s.z).unwrap();
            let ea = actual_error(rom, omega, &s.z, &fo).unwrap();
            let el = linearised_error(rom, &condensed, omega, &s.z).unwrap();
            // The linearised error is the actual error to first order (none asked below the
            // full-order solution's own accuracy) ...
            assert!(ea[1] < FO_ACCURACY || (el[1] - ea[1]).abs() <= 0.05 * ea[1], "H={harmonics} scale={scale} extra={extra}: e_lin_1 {} vs e_1 {}", el[1], ea[1]);
            // ... and e* is conservative (with a round-off allowance for exact bases) except for
            // the paper's FR (see the module doc).
            let papers_fr = std::ptr::eq(rom as *const dyn ReducedModel as *const u8, &fr_jp as *const FrRom as *const u8);
            assert!(es[1] + 1e-9 >= ea[1] || ea[1] < FO_ACCURACY || papers_fr, "H={harmonics} scale={scale} extra={extra}: e*_1 {} < e_1 {}", es[1], ea[1]);
            println!(
                "H={harmonics} scale={scale} extra={extra} sizes {:?}: X0 err {:.2e} X1 err {:.2e} e*_1 {:.2e} e_1 {:.2e} e_lin_1 {:.2e}",
                rom.layout().sizes, row[row.len() - 1].0, row[row.len() - 1].1, es[1], ea[1], el[1]
            );
        }
        errors.push([row[0], row[1], row[2]]);
    }
    Case { errors }
}

fn check(harmonics: usize, scale: f64) {
    let n_dof = 24;
    let all = 2 * harmonics * n_dof; // every eigenpair of (31): a complete basis
    let case = run(harmonics, scale, &[0, 12, all]);
    for (rom, (e0, e1)) in ["FR", "FR (JP rows)", "NLR"].iter().zip(case.errors[2]) {
        assert!(e0 < 1e-3 && e1 < 1e-3, "H={harmonics} scale={scale}: {rom} X0 {e0:.3e} X1 {e1:.3e}, not within 0.1 %");
    }
    // Fewer modes, larger error (first harmonic).
    for k in 0..3 {
        assert!(case.errors[1][k].1 <= case.errors[0][k].1 * 1.0001);
    }
}

#[test]
fn own_jacobian_basis_reproduces_full_order_stuck_h1() {
    check(1, 1e-3);
}

#[test]
fn own_jacobian_basis_reproduces_full_order_slipping_h1() {
    check(1, 0.05);
}

#[test]
fn own_jacobian_basis_reproduces_full_order_slipping_h3() {
    check(3, 0.05);
}
