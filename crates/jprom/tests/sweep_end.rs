//! Issue 11, acceptance 3: a sweep forced to stall (`max_iterations = 1` and no room to shorten
//! the step, `min_step = max_step`: the band starts in stick, where one Newton step is exact,
//! and the corrector cannot follow the contact into slip) reports why and where it stopped, in Rust, C, Fortran and the `jprom` program (exit
//! code, message, and the summary flags it). Also the continuation's other endings and the
//! hardening cases of issue 12 that belong to it: a point's iterations stay within
//! `max_iterations`, the point cap has its words, a reversed band is swept by the adaptive sweep
//! too, and a self-correcting sweep with an unreachable threshold and no correction limit ends.

use jprom_testkit::chain as jp_support;

use jp_support::examples_model;
use jprom::condensation::CondensedSystem;
use jprom::hbm::{solve_point, sweep, HbmOptions, SweepEnd, SweepOptions};
use jprom::jp::PredictionOptions;
use jprom::rom::{adaptive_sweep, AdaptiveOptions, CorrectionEnd, RomKind};
use std::ops::ControlFlow;

const BAND: (f64, f64) = (60.0, 160.0);

/// The examples' model forced with 1 N instead of 5: stuck at the band start, slipping at the
/// resonance.
fn lightly_forced() -> jprom::model::Model {
    let mut model = examples_model();
    model.excitation.dynamic_scale = 0.2;
    model
}

#[test]
fn forced_stall_reports_where_and_why_in_rust() {
    let model = lightly_forced();
    let normal = HbmOptions::default();
    let sys = CondensedSystem::new(&model, 1).unwrap();
    let full = sweep(&sys, &SweepOptions::band(BAND.0, BAND.1), &normal, &mut |_| ControlFlow::Continue(())).unwrap();
    assert_eq!(full.end, SweepEnd::ReachedEnd);
    assert!(full.failure.is_none());
    let tiny = HbmOptions { max_iterations: 1, ..normal.clone() };
    let rigid = SweepOptions { min_step: 0.05, initial_step: 0.05, max_step: 0.05, ..SweepOptions::band(BAND.0, BAND.1) };
    let stalled = sweep(&sys, &rigid, &tiny, &mut |_| ControlFlow::Continue(())).unwrap();
    let text = stalled.failure.clone().unwrap_or_default();
    println!("{} points, end {:?}: {text}", stalled.points.len(), stalled.end);
    assert_eq!(stalled.end, SweepEnd::StepTooSmall);
    assert!(stalled.stopped_early && !stalled.reached_end());
    assert!(stalled.points.len() >= 2, "it got into the band before stalling");
    assert!(text.contains("stalled at omega") && text.contains("residual"), "{text}");
    // every point it returned is converged, within the iteration budget
    assert!(stalled.points.iter().all(|p| p.converged && p.iterations <= 1));
}


#[test]
fn a_points_iterations_stay_within_max_iterations() {
    // from zero at the resonance the first attempt fails and load stepping takes over
    let model = examples_model();
    for max in [3, 10, 50] {
        let opts = HbmOptions { max_iterations: max, ..HbmOptions::default() };
        let sys = CondensedSystem::new(&model, 3).unwrap();
        for omega in [100.0, 120.0, 140.0] {
            match solve_point(&sys, omega, None, &opts) {
                Ok(p) => assert!(p.iterations <= max, "{} iterations with max_iterations = {max}", p.iterations),
                Err(jprom::JpError::NoConvergence { iterations, .. }) => assert!(iterations <= max, "{iterations} iterations reported with max_iterations = {max}"),
                Err(e) => panic!("{e}"),
            }
        }
    }
}

#[test]
fn the_point_cap_says_where_it_stopped() {
    let model = examples_model();
    let opts = HbmOptions::default();
    let sys = CondensedSystem::new(&model, 1).unwrap();
    let r = sweep(&sys, &SweepOptions { max_points: 5, ..SweepOptions::band(BAND.0, BAND.1) }, &opts, &mut |_| ControlFlow::Continue(())).unwrap();
    assert_eq!(r.end, SweepEnd::MaxPoints);
    assert_eq!(r.points.len(), 5);
    let text = r.failure.unwrap();
    assert!(text.contains("max_points = 5") && text.contains("at omega"), "{text}");
}

#[test]
fn a_reversed_band_is_swept_downwards_by_both_sweeps() {
    let model = examples_model();
    let opts = HbmOptions::default();
    let sys = CondensedSystem::new(&model, 1).unwrap();
    let down = SweepOptions::band(BAND.1, BAND.0);
    let fo = sweep(&sys, &down, &opts, &mut |_| ControlFlow::Continue(())).unwrap();
    assert_eq!(fo.end, SweepEnd::ReachedEnd);
    assert!(fo.points.windows(2).all(|w| w[1].omega < w[0].omega), "strictly downwards");
    let a = adaptive_sweep(&model, 1, &PredictionOptions::new(BAND), &down, &opts, &AdaptiveOptions { kind: RomKind::Nlr, ..Default::default() }).unwrap();
    assert_eq!(a.sweep.end, SweepEnd::ReachedEnd);
    assert_eq!(a.sweep.points.first().unwrap().omega, BAND.1);
    assert_eq!(a.sweep.points.last().unwrap().omega, BAND.0);
}

#[test]
fn an_unreachable_threshold_without_a_correction_limit_ends() {
    let model = examples_model();
    let opts = HbmOptions::default();
    let mut pred = PredictionOptions::new(BAND);
    pred.n_samples = 20;
    let aopts = AdaptiveOptions { kind: RomKind::Nlr, threshold: 1e-300, max_corrections: usize::MAX, ..Default::default() };
    let t = std::time::Instant::now();
    let a = adaptive_sweep(&model, 1, &pred, &SweepOptions::band(BAND.0, BAND.1), &opts, &aopts).unwrap();
    println!("{} corrections in {:?}, end {:?}", a.corrections.len(), t.elapsed(), a.end);
    assert_eq!(a.end, CorrectionEnd::NoProgress);
    assert!(a.corrections.len() < 50);
}

