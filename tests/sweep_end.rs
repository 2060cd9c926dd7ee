//! Issue 11, acceptance 3: a sweep forced to stall (`max_iterations = 1` and no room to shorten
//! the step, `min_step = max_step`: the band starts in stick, where one Newton step is exact,
//! and the corrector cannot follow the contact into slip) reports why and where it stopped, in Rust, C, Fortran and the `jprom` program (exit
//! code, message, and the summary flags it). Also the continuation's other endings and the
//! hardening cases of issue 12 that belong to it: a point's iterations stay within
//! `max_iterations`, the point cap has its words, a reversed band is swept by the adaptive sweep
//! too, and a self-correcting sweep with an unreachable threshold and no correction limit ends.

#[path = "support/native.rs"]
mod native;
mod jp_support;

use jp_support::examples_model;
use jprom::condensation::CondensedSystem;
use jprom::hbm::{solve_point, sweep, HbmOptions, SweepEnd, SweepOptions};
use jprom::jp::PredictionOptions;
use jprom::rom::{adaptive_sweep, AdaptiveOptions, CorrectionEnd, RomKind};
use native::*;
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
    let normal = HbmOptions::with_harmonics(1);
    let sys = CondensedSystem::new(&model, &normal).unwrap();
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
fn forced_stall_reports_its_reason_in_c_and_fortran() {
    let c = compile_c(&[&root().join("tests/c/sweep_end.c")], "sweep_end_c", &[]);
    let out = std::process::Command::new(&c).output().unwrap();
    let text = String::from_utf8_lossy(&out.stdout);
    println!("{text}");
    assert!(out.status.success(), "C: {text}{}", String::from_utf8_lossy(&out.stderr));
    assert!(text.contains("end reached_end: \n") && text.contains("end stalled: stalled at omega"), "{text}");
    if have_gfortran() {
        let f = compile_fortran(&[&root().join("examples-fortran/jprom_mod.f90"), &root().join("tests/fortran/sweep_end.f90")], "sweep_end_f90");
        let out = std::process::Command::new(&f).output().unwrap();
        let text = String::from_utf8_lossy(&out.stdout);
        println!("{text}");
        assert!(out.status.success(), "Fortran: {text}{}", String::from_utf8_lossy(&out.stderr));
        assert!(text.contains("end 0: \n") && text.contains("end 1: stalled at omega"), "{text}");
    }
}

#[test]
fn a_points_iterations_stay_within_max_iterations() {
    // from zero at the resonance the first attempt fails and load stepping takes over
    let model = examples_model();
    for max in [3, 10, 50] {
        let opts = HbmOptions { max_iterations: max, ..HbmOptions::with_harmonics(3) };
        let sys = CondensedSystem::new(&model, &opts).unwrap();
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
    let opts = HbmOptions::with_harmonics(1);
    let sys = CondensedSystem::new(&model, &opts).unwrap();
    let r = sweep(&sys, &SweepOptions { max_points: 5, ..SweepOptions::band(BAND.0, BAND.1) }, &opts, &mut |_| ControlFlow::Continue(())).unwrap();
    assert_eq!(r.end, SweepEnd::MaxPoints);
    assert_eq!(r.points.len(), 5);
    let text = r.failure.unwrap();
    assert!(text.contains("max_points = 5") && text.contains("at omega"), "{text}");
}

#[test]
fn a_reversed_band_is_swept_downwards_by_both_sweeps() {
    let model = examples_model();
    let opts = HbmOptions::with_harmonics(1);
    let sys = CondensedSystem::new(&model, &opts).unwrap();
    let down = SweepOptions::band(BAND.1, BAND.0);
    let fo = sweep(&sys, &down, &opts, &mut |_| ControlFlow::Continue(())).unwrap();
    assert_eq!(fo.end, SweepEnd::ReachedEnd);
    assert!(fo.points.windows(2).all(|w| w[1].omega < w[0].omega), "strictly downwards");
    let a = adaptive_sweep(&model, &PredictionOptions::new(BAND), &down, &opts, &AdaptiveOptions { kind: RomKind::Nlr, ..Default::default() }).unwrap();
    assert_eq!(a.sweep.end, SweepEnd::ReachedEnd);
    assert_eq!(a.sweep.points.first().unwrap().omega, BAND.1);
    assert_eq!(a.sweep.points.last().unwrap().omega, BAND.0);
}

#[test]
fn an_unreachable_threshold_without_a_correction_limit_ends() {
    let model = examples_model();
    let opts = HbmOptions::with_harmonics(1);
    let mut pred = PredictionOptions::new(BAND);
    pred.n_samples = 20;
    let aopts = AdaptiveOptions { kind: RomKind::Nlr, threshold: 1e-300, max_corrections: usize::MAX, ..Default::default() };
    let t = std::time::Instant::now();
    let a = adaptive_sweep(&model, &pred, &SweepOptions::band(BAND.0, BAND.1), &opts, &aopts).unwrap();
    println!("{} corrections in {:?}, end {:?}", a.corrections.len(), t.elapsed(), a.end);
    assert_eq!(a.end, CorrectionEnd::NoProgress);
    assert!(a.corrections.len() < 50);
}

mod slip_onset;

/// The twisted plate's study (tests/slip_onset) at the stuck limit with `max_iterations = 1`
/// and no room to shorten the step: `jprom run` exits with 3 and says which sweep stopped where,
/// the summary flags it, the CSV carries the end, and `--keep-partial` accepts it.
#[test]
fn forced_stall_is_reported_by_the_jprom_program() {
    let fe = jprom::fe::PlateFe::build(&slip_onset::plate_params()).unwrap();
    let dir = slip_onset::scratch("cli-stall");
    let path = slip_onset::export_plate(&fe, &dir, (307.7, 345.4), 1);
    let study = std::fs::read_to_string(&path).unwrap();
    let study = study
        .replace("nt = 64", "nt = 64\nmax_iterations = 1")
        .replace("points = 100", "points = 100\nmin_step = 0.05\nmax_step = 0.05")
        .replace("levels = [1.0]", "levels = [0.5]")
        + "[solvers]\nfull_order = true\nfr = false\nnlr = false\n[output]\ndir = \"out\"\nplots = false\n";
    std::fs::write(&path, study).unwrap();
    let run = |extra: &[&str]| std::process::Command::new(env!("CARGO_BIN_EXE_jprom")).arg("run").arg(&path).args(extra).output().unwrap();
    let out = run(&[]);
    let (stdout, stderr) = (String::from_utf8_lossy(&out.stdout), String::from_utf8_lossy(&out.stderr));
    println!("{stdout}\n{stderr}");
    assert_eq!(out.status.code(), Some(3), "exit code");
    assert!(stderr.contains("did not cover the band") && stderr.contains("stalled at omega"), "{stderr}");
    assert!(stdout.contains("stalled (!)") && stdout.contains("read with care"), "{stdout}");
    let csv = std::fs::read_to_string(dir.join("out/alpha_ST_x5e-1_fo.csv")).unwrap();
    assert!(csv.lines().next().unwrap().ends_with(",sweep_end") && csv.lines().skip(1).all(|l| l.ends_with(",stalled")), "{csv}");
    let summary: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(dir.join("out/summary.json")).unwrap()).unwrap();
    assert_eq!(summary["rows"][0]["end"], "stalled");
    assert_eq!(summary["rows"][0]["complete"], false);
    assert_eq!(summary["incomplete"].as_array().unwrap().len(), 1);
    assert_eq!(run(&["--keep-partial"]).status.code(), Some(0));
}
