//! Predicted bases (stuck mode as generating shape, no full-order information): the basis grows
//! with gamma, the error predictor is conservative against the full-order solution, and the
//! self-correcting sweep runs and reports its corrections.

use jprom_testkit::chain as jp_support;

use jp_support::*;
use jprom::rom::error_metric::{actual_error, output_error, predicted_error};
use jprom::hbm::{solve_point, FullSystem, HbmOptions, SweepOptions};
use jprom::jp::{predict_basis, PredictionOptions};
use jprom::model::ContactCoordinates;
use jprom::hbm::SweepEnd;
use jprom::rom::{adaptive_sweep, adaptive_sweep_with_progress, AdaptiveOptions, FrRom};
use std::ops::ControlFlow;

#[test]
fn predicted_basis_grows_with_gamma_and_predictor_is_conservative() {
    let mut model = chain_model(&ChainOptions::default());
    model.excitation.dynamic_scale = 0.05;
    let hopts = HbmOptions::default();
    let coords = ContactCoordinates::new(&model, 1).unwrap();
    let (freqs, _) = linear_modes(&stuck_stiffness_physical(&model), &model.mass);
    let band = (0.9 * freqs[0], 1.02 * freqs[0]);
    let omega = 0.99 * freqs[0];
    let full = FullSystem::new(&model, 1).unwrap();
    let mut guess: Option<Vec<f64>> = None;
    for k in (0..=40).rev() {
        guess = Some(solve_point(&full, omega * (1.0 - 0.001 * k as f64), guess.as_deref(), &hopts).unwrap().z);
    }
    let fo = solve_point(&full, omega, guess.as_deref(), &hopts).unwrap();
    let mut last_sizes = vec![0, 0];
    for gamma in [1e2, 1e3, 1e4] {
        let mut opts = PredictionOptions::new(band);
        opts.gamma = gamma;
        let (basis, report) = predict_basis(&coords, &opts).unwrap();
        assert!(report.p_min <= report.p_max && report.n_patterns >= 1);
        assert!(basis.sizes[0] >= last_sizes[0] && basis.sizes[1] >= last_sizes[1], "sizes shrink with gamma");
        last_sizes = basis.sizes.clone();
        let fr = FrRom::new(&coords, &basis).unwrap();
        let s = solve_point(&fr, omega, None, &hopts).unwrap();
        let es = predicted_error(&fr, omega, &s.z).unwrap();
        let ea = actual_error(&fr, omega, &s.z, &fo).unwrap();
        println!(
            "gamma {gamma:e}: sizes {:?} patterns {} p_min {:.3e} p_max {:.3e}; X1 err {:.2e}, e*_1 {:.2e}, e_1 {:.2e}",
            basis.sizes,
            report.n_patterns,
            report.p_min,
            report.p_max,
            output_error(&s.outputs, &fo.outputs, fo.n_outputs, 1),
            es[1],
            ea[1]
        );
        // Conservative, except where both are at the full-order solution's own accuracy (the
        // band-condensed FR reaches X1 4e-8 here at gamma 1e3).
        assert!(es[1] + 1e-9 >= ea[1] || ea[1] < FO_ACCURACY, "e*_1 {} < e_1 {}", es[1], ea[1]);
    }
}

/// The chain at a slipping level, H = 1, and a band just around its first stuck mode.
fn adaptive_case() -> (jprom::model::Model, HbmOptions, (f64, f64)) {
    let mut model = chain_model(&ChainOptions::default());
    model.excitation.dynamic_scale = 0.05;
    let hopts = HbmOptions::default();
    let (freqs, _) = linear_modes(&stuck_stiffness_physical(&model), &model.mass);
    let band = (0.97 * freqs[0], 1.01 * freqs[0]);
    (model, hopts, band)
}

#[test]
fn adaptive_sweep_reports_corrections() {
    let (model, hopts, band) = adaptive_case();
    let pred = PredictionOptions::new(band);
    let sopts = SweepOptions::band(band.0, band.1);
    let out = adaptive_sweep(&model, 1, &pred, &sopts, &hopts, &AdaptiveOptions::default()).unwrap();
    let worst = out.predicted_errors.iter().map(|e| e[1]).fold(0.0, f64::max);
    println!("points {} worst e*_1 {worst:.3e} corrections {:?}", out.sweep.points.len(), out.corrections);
    assert_eq!(out.predicted_errors.len(), out.sweep.points.len());
    // Either the basis is good, or every allowed correction was tried.
    assert!(worst <= AdaptiveOptions::default().threshold || out.corrections.len() == AdaptiveOptions::default().max_corrections);
    for c in &out.corrections {
        assert!(c.worst_error_before > AdaptiveOptions::default().threshold);
    }
}

#[test]
fn adaptive_sweep_with_progress_reports_every_point_and_stops_on_request() {
    let (model, hopts, band) = adaptive_case();
    let pred = PredictionOptions::new(band);
    let sopts = SweepOptions::band(band.0, band.1);
    let aopts = AdaptiveOptions::default();
    let plain = adaptive_sweep(&model, 1, &pred, &sopts, &hopts, &aopts).unwrap();
    // every point of every pass is reported; the result is that of adaptive_sweep
    let mut seen: Vec<(usize, f64)> = Vec::new();
    let out = adaptive_sweep_with_progress(&model, 1, &pred, &sopts, &hopts, &aopts, &mut |pass, p| {
        seen.push((pass, p.omega));
        ControlFlow::Continue(())
    })
    .unwrap();
    assert_eq!(out.corrections, plain.corrections);
    assert_eq!(out.predicted_errors, plain.predicted_errors);
    // The result is the pass of the last kept correction (a correction that made the worst
    // e*_1 larger is dropped).
    let kept = (1..=out.corrections.len()).rev().find(|&k| out.corrections[k - 1].worst_error_after < out.corrections[k - 1].worst_error_before).unwrap_or(0);
    let last: Vec<f64> = seen.iter().filter(|s| s.0 == kept).map(|s| s.1).collect();
    assert_eq!(last, out.sweep.points.iter().map(|p| p.omega).collect::<Vec<_>>());
    assert_eq!(seen.iter().map(|s| s.0).max(), Some(out.corrections.len()));
    // stopping at the first point of the first pass: no correction, one point
    let stopped = adaptive_sweep_with_progress(&model, 1, &pred, &sopts, &hopts, &aopts, &mut |_, _| ControlFlow::Break(())).unwrap();
    assert_eq!(stopped.sweep.end, SweepEnd::StoppedByCaller);
    assert_eq!(stopped.sweep.points.len(), 1);
    assert!(stopped.corrections.is_empty());
    assert_eq!(stopped.predicted_errors.len(), 1);
}

#[test]
fn prediction_works_without_static_load() {
    // the C examples' model: a preloaded contact and no static force, so the static solution
    // is driven by the preload alone (its residual used to be scaled by the zero static load,
    // and never converged)
    let model = examples_model();
    let coords = ContactCoordinates::new(&model, 1).unwrap();
    let mut p = PredictionOptions::new((60.0, 160.0));
    p.n_samples = 10;
    let (basis, report) = predict_basis(&coords, &p).unwrap();
    assert!(basis.sizes[1] > 0);
    assert!(report.static_solution.iter().any(|x| *x != 0.0), "the preload moves the static solution");
}
