//! The static term at gross slip (docs/formulation.md §10.6): the first harmonic of a JP ROM
//! converges with a few dozen modes, its static contact displacement only when the basis is
//! nearly complete; the contact forces' error `e_lin_0` does not see it, the linearised static
//! displacement error `e_w0` does (`error_metric::linearised_errors`).
//!
//! The built-in blade (18 contact nodes, 54 contact coordinates) at `alpha_ST / 3000` (every
//! contact slides), at its full-order resonance; JP bases generated from the full-order solution
//! itself (the paper's "bases from the full-order boundary conditions"; the contact Jacobian
//! depends on the contact displacement alone), NLR and FR solved there. The full-order static
//! solution is unique: Newton from the reduced solution returns to it.

use jprom::condensation::CondensedSystem;
use jprom::hbm::{solve_point, HbmOptions, PointSolution};
use jprom::jp::{predict_basis, GeneratingShape, PredictionOptions};
use jprom::model::ContactCoordinates;
use jprom::rom::error_metric::{linearised_errors, reduced_contact_displacement};
use jprom::rom::{reduced_model, RomKind};
use jprom_testkit::blade::Blade;
use std::f64::consts::PI;

/// Flap direction of the tip node.
const TIP_FLAP: usize = 25;

fn norm(v: &[f64]) -> f64 {
    v.iter().map(|x| x * x).sum::<f64>().sqrt()
}

struct Row {
    sizes: Vec<usize>,
    x1_error: f64,
    /// `|w_0 ROM - w_0 FO| / |w_0 FO|`.
    w0_error: f64,
    /// The linearised `e_w0` and `e_lin_0`, `e_lin_1`.
    w0_linearised: f64,
    force: Vec<f64>,
    tip_x0: f64,
}

#[test]
fn static_term_at_gross_slip_needs_the_whole_static_space_and_e_w0_says_so() {
    let blade = Blade::build();
    let model = blade.at_level(blade.alpha_st / 3000.0);
    let band = (2.0 * PI * 1620.0, 2.0 * PI * 2200.0);
    let hopts = HbmOptions::default();
    let cond = CondensedSystem::new(&model, 1).unwrap();
    let coords = ContactCoordinates::new(&model, 1).unwrap();
    let nw = coords.n_w;
    let omega = 2.0 * PI * 1671.89;
    let fo = solve_point(&cond, omega, None, &hopts).unwrap();
    let fo_x1 = fo.output_amplitude(1, TIP_FLAP);
    let fo_w0 = &fo.z[..nw];

    let shape = |k: usize| {
        let mut x = vec![0.0; coords.n_dof];
        x[..nw].copy_from_slice(&fo.z[k * nw..(k + 1) * nw]);
        x
    };
    let mut rows = Vec::new();
    for gamma in [1e3, 1e4, 1e6, 1e8, 1e12] {
        let popts = PredictionOptions {
            gamma,
            shape: GeneratingShape::Given { static_part: Some(shape(0)), cos: shape(1), sin: shape(2) },
            p_max: None,
            ..PredictionOptions::new(band)
        };
        let (basis, _) = predict_basis(&coords, &popts).unwrap();
        for kind in [RomKind::Nlr, RomKind::Fr] {
            let rom = reduced_model(kind, &coords, Some(&cond), &basis).unwrap();
            let r: PointSolution = solve_point(rom.as_ref(), omega, None, &hopts).unwrap();
            let w = reduced_contact_displacement(rom.as_ref(), omega, &r.z).unwrap();
            let d: Vec<f64> = w[..nw].iter().zip(fo_w0).map(|(a, b)| a - b).collect();
            let lin = linearised_errors(rom.as_ref(), &cond, omega, &r.z).unwrap();
            let row = Row {
                sizes: basis.sizes.clone(),
                x1_error: (r.output_amplitude(1, TIP_FLAP) / fo_x1 - 1.0).abs(),
                w0_error: norm(&d) / norm(fo_w0),
                w0_linearised: lin.static_displacement,
                force: lin.force.clone(),
                tip_x0: r.output_coeff(0, TIP_FLAP),
            };
            println!(
                "gamma {gamma:.0e} {kind:?} sizes {:?}: X1 error {:.1e}, w0 error {:.2e} (e_w0 {:.2e}), e_lin {:.1e} {:.1e}, tip X0 {:.3e} (full order {:.3e})",
                row.sizes, row.x1_error, row.w0_error, row.w0_linearised, row.force[0], row.force[1], row.tip_x0, fo.output_coeff(0, TIP_FLAP)
            );
            rows.push((gamma, kind, row));
        }
    }
    let at = |g: f64, k: RomKind| &rows.iter().find(|(gg, kk, _)| *gg == g && *kk == k).unwrap().2;

    // The bases at a given gamma depend on round-off here (the thread count changes them: at
    // 1e3, [22, 8] on two threads and [34, 15] on one), so what is asserted holds for each.
    // e_w0 flags exactly the poor static terms, and is the static error to first order.
    for (g, k, r) in &rows {
        assert_eq!(r.w0_linearised > 0.05, r.w0_error > 0.05, "gamma {g:e} {k:?}: e_w0 {:e} vs actual {:e}", r.w0_linearised, r.w0_error);
        if r.w0_error > 1e-6 && r.w0_error <= 3.0 {
            assert!((r.w0_linearised / r.w0_error - 1.0).abs() < 0.3, "gamma {g:e} {k:?}: e_w0 {:e} vs actual {:e}", r.w0_linearised, r.w0_error);
        }
    }
    for kind in [RomKind::Nlr, RomKind::Fr] {
        // At 1e4 and 1e6 the first harmonic is within 0.2 % and the static contact forces within
        // the threshold (e_lin_0 sees nothing wrong), while the static contact displacement is
        // off by more than a third of its size and the tip's X0 by orders of magnitude.
        for g in [1e4, 1e6] {
            let r = at(g, kind);
            assert!(r.x1_error < 2e-3, "gamma {g:e} {kind:?}: X1 error {:e}", r.x1_error);
            assert!(r.force[0] < 0.05, "gamma {g:e} {kind:?}: e_lin_0 {:e}", r.force[0]);
            assert!(r.w0_error > 0.3, "gamma {g:e} {kind:?}: w0 error {:e}", r.w0_error);
            assert!((r.tip_x0 / fo.output_coeff(0, TIP_FLAP)).abs() > 10.0, "gamma {g:e} {kind:?}: tip X0 {:e}", r.tip_x0);
        }
    }
    // With a nearly complete basis the static term is right (NLR exactly; FR, which also
    // projects the non-contact DoFs, within its own truncation), and e_w0 says so.
    let nlr = at(1e12, RomKind::Nlr);
    assert!(nlr.w0_error < 1e-6 && nlr.w0_linearised < 1e-6, "NLR: w0 error {:e}, e_w0 {:e}", nlr.w0_error, nlr.w0_linearised);
    assert!((nlr.tip_x0 / fo.output_coeff(0, TIP_FLAP) - 1.0).abs() < 0.01, "NLR: tip X0 {:e}", nlr.tip_x0);
    let fr = at(1e12, RomKind::Fr);
    assert!(fr.w0_error < 1e-3 && fr.w0_linearised < 1e-3, "FR: w0 error {:e}, e_w0 {:e}", fr.w0_error, fr.w0_linearised);
}
